//! Tools to compare with other Tolles-Lawson implementations (e.g. MagNav.jl).
//!
//! `cargo run --release -p aeromag-compensation --example tl_matrix -- design IN.csv OUT.csv [terms] [convention]`
//!   IN.csv has columns flux_x, flux_y, flux_z (and time for the physical
//!   convention); writes the design matrix (no header), full precision.
//! `cargo run --release -p aeromag-compensation --example tl_matrix -- ridge A.csv y.csv LAMBDA`
//!   solves (AᵀA + λI) c = Aᵀy with the crate's scaled normal equations and
//!   prints c, one value per line.

use aeromag_compensation::tolles_lawson::{Convention, DEFAULT_BT_SCALE_NT, Design, TermSet};
use aeromag_estimation::least_squares::NormalEquations;
use std::error::Error;

/// A file's column names and its rows.
type Rows = (Vec<String>, Vec<Vec<f64>>);

fn read_rows(path: &str) -> Result<Rows, Box<dyn Error>> {
    let text = std::fs::read_to_string(path)?;
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    let first = lines.next().ok_or("empty file")?;
    let mut rows = Vec::new();
    let header: Vec<String> = if first.split(',').all(|c| c.trim().parse::<f64>().is_ok()) {
        rows.push(
            first
                .split(',')
                .map(|c| c.trim().parse())
                .collect::<Result<Vec<f64>, _>>()?,
        );
        Vec::new()
    } else {
        first.split(',').map(|s| s.trim().to_string()).collect()
    };
    for l in lines {
        rows.push(
            l.split(',')
                .map(|c| c.trim().parse())
                .collect::<Result<Vec<f64>, _>>()?,
        );
    }
    Ok((header, rows))
}

fn main() -> Result<(), Box<dyn Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("design") => {
            let (h, rows) = read_rows(&args[1])?;
            let col = |name: &str| -> Result<Vec<f64>, Box<dyn Error>> {
                let k = h.iter().position(|c| c == name).ok_or(format!("no column {name}"))?;
                Ok(rows.iter().map(|r| r[k]).collect())
            };
            let terms = TermSet::parse(args.get(3).map_or("p3,i6,e9", String::as_str))?;
            let conv: Convention = args.get(4).map_or("magnav", String::as_str).parse()?;
            let (x, y, z) = (col("flux_x")?, col("flux_y")?, col("flux_z")?);
            let t = col("time").unwrap_or_else(|_| (0..x.len()).map(|i| i as f64).collect());
            let design = Design {
                terms: terms.clone(),
                convention: conv,
                bt_scale_nt: DEFAULT_BT_SCALE_NT,
                ..Design::default()
            };
            let cols = design.columns(&t, [&x, &y, &z]);
            let mut out = String::new();
            for i in 0..x.len() {
                let row: Vec<String> = cols.iter().map(|c| format!("{:e}", c[i])).collect();
                out.push_str(&row.join(","));
                out.push('\n');
            }
            std::fs::write(&args[2], out)?;
        }
        Some("ridge") => {
            let (_, a) = read_rows(&args[1])?;
            let (_, y) = read_rows(&args[2])?;
            let lambda: f64 = args[3].parse()?;
            let n = a.first().ok_or("empty A")?.len();
            let mut ne = NormalEquations::new(n);
            for (r, yv) in a.iter().zip(&y) {
                ne.add_row(r, yv[0], 1.0)?;
            }
            for c in ne.solve(lambda)?.coef.iter() {
                println!("{c:e}");
            }
        }
        _ => return Err("usage: tl_matrix design IN.csv OUT.csv [terms] [convention] | ridge A.csv y.csv LAMBDA".into()),
    }
    Ok(())
}
