//! `aeromag dipole`: dipole parameters from gradiometer differences.

use aeromag_gradiometry::convergence::{convergence_map, ConvergenceCase, ConvergenceMap, Initialisation};
use aeromag_report::{Heatmap, Report};
use std::path::PathBuf;

/// Magnetic dipole (object) parameters from tensor or scalar gradiometer
/// differences with a square-root iterated EKF (seed 004).
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    command: Sub,
}

#[derive(Debug, clap::Subcommand)]
enum Sub {
    Convergence(ConvergenceArgs),
}

/// Convergence map of the IEKF from a grid of starting positions: the seed's
/// fig. 2 case (tensor gradiometer, tetrahedron of 1 m baseline, dipole of
/// 100 A·m² at (5, 0, 0.306) m, 1 nT noise, zero initial moment, starts on an
/// n³ grid over [−20, 20]³ m). Runs the plain IEKF (converges from about the
/// half-space facing the source) and the multi-start initialisation
/// (converges from every start), prints the fractions, and writes slices of
/// the iteration counts as heatmaps to DIR/index.html.
///
/// Example: `aeromag dipole convergence --grid 40 --out conv/`
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
struct ConvergenceArgs {
    /// Starts per axis (n³ in all).
    #[arg(long, default_value_t = 40)]
    grid: usize,
    /// Worker threads (the result does not depend on it).
    #[arg(long, default_value_t = 2)]
    threads: usize,
    /// Output folder for the report.
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    match a.command {
        Sub::Convergence(c) => convergence(c),
    }
}

/// A slice through the source of the iteration counts (NaN = no convergence).
fn slice_heatmap(case: &ConvergenceCase, map: &ConvergenceMap, axis: usize, value: f64, tag: &str) -> Heatmap {
    let coords: Vec<f64> = (0..case.grid_n).map(|i| case.start(i, 0, 0).x).collect();
    let k = (0..case.grid_n).min_by(|&a, &b| (coords[a] - value).abs().total_cmp(&(coords[b] - value).abs())).unwrap_or(0);
    let values = map.slice(axis, k).into_iter().map(|v| v.map_or(f64::NAN, f64::from)).collect();
    let (name, xl, yl) = if axis == 1 { ("y", "x start (m)", "z start (m)") } else { ("z", "x start (m)", "y start (m)") };
    let mut h = Heatmap::new(
        format!("IEKF iterations ({tag}), slice {name} = {:.2} m", coords[k]),
        xl,
        yl,
        coords.clone(),
        coords,
        values,
        "iterations",
    );
    h.equal_aspect = true;
    h
}

fn convergence(a: ConvergenceArgs) -> anyhow::Result<()> {
    if !(2..=200).contains(&a.grid) {
        return Err(crate::exit::bad_input!("--grid {} must be in 2…200", a.grid));
    }
    let case = ConvergenceCase::seed_fig2(a.grid);
    let toward = case.position_m.normalize();
    let mut r = Report::new("aeromag — IEKF convergence map (seed 004, fig. 2 case)");
    r.section("Convergence map").paragraph(format!(
        "Tensor gradiometer, dipole at ({:.2}, {:.2}, {:.3}) m, {} starts on a {}³ grid over [−20, 20]³ m. \
         Grey cells: the IEKF did not reach the source.",
        case.position_m.x,
        case.position_m.y,
        case.position_m.z,
        a.grid.pow(3),
        a.grid
    ));
    let mut rows = Vec::new();
    for (init, tag) in [(Initialisation::None, "plain IEKF"), (Initialisation::MultiStart, "multi-start")] {
        let t = std::time::Instant::now();
        let map = convergence_map(&case, init, a.threads.max(1))?;
        let secs = t.elapsed().as_secs_f64();
        let near = map.fraction_where(&case, |s| s.dot(&toward) > 1.0);
        let far = map.fraction_where(&case, |s| s.dot(&toward) < -1.0);
        println!(
            "{tag:<12} converged from {:6.2} % of {} starts (facing the source {:6.2} %, opposite {:6.2} %) in {secs:.2} s",
            100.0 * map.converged_fraction(),
            map.outcomes.len(),
            100.0 * near,
            100.0 * far
        );
        rows.push(vec![tag.to_string(), format!("{:.2}", 100.0 * map.converged_fraction()), format!("{:.2}", 100.0 * near), format!("{:.2}", 100.0 * far)]);
        for (axis, v) in [(2, case.position_m.z), (1, case.position_m.y)] {
            r.figure(slice_heatmap(&case, &map, axis, v, tag).to_svg()?, format!("{tag}: iterations per start."));
        }
    }
    r.table(aeromag_report::Table::new(
        ["initialisation", "converged (%)", "facing the source (%)", "opposite (%)"].map(String::from).to_vec(),
        rows,
        "Converged fraction of the starts.",
    ));
    let path = a.out.join("index.html");
    r.write_html(&path)?;
    println!("report written to {}", path.display());
    Ok(())
}
