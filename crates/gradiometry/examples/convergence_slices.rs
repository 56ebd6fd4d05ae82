//! Convergence map of the seed's fig. 2 case (40³ starts over [−20, 20]³ m)
//! for the plain IEKF and the multi-start initialisation; prints the
//! converged fractions and writes slices through the source (z = 0.306 m
//! and y = 0) as heatmap SVGs (and PNGs) of the iterations (grey = no convergence).
//!
//! `cargo run --release -p aeromag-gradiometry --example convergence_slices -- [out_dir]`

use aeromag_gradiometry::convergence::{
    ConvergenceCase, ConvergenceMap, Initialisation, convergence_map,
};
use aeromag_report::Heatmap;
use std::time::Instant;

fn nearest(case: &ConvergenceCase, value: f64) -> usize {
    (0..case.grid_n)
        .min_by(|&a, &b| {
            let da = (case.start(a, 0, 0).x - value).abs();
            let db = (case.start(b, 0, 0).x - value).abs();
            da.total_cmp(&db)
        })
        .unwrap_or(0)
}

fn write_slice(
    case: &ConvergenceCase,
    map: &ConvergenceMap,
    axis: usize,
    value: f64,
    tag: &str,
    dir: &str,
) -> Result<(), Box<dyn std::error::Error>> {
    let k = nearest(case, value);
    let coords: Vec<f64> = (0..case.grid_n).map(|i| case.start(i, 0, 0).x).collect();
    let values = map
        .slice(axis, k)
        .into_iter()
        .map(|v| v.map_or(f64::NAN, f64::from))
        .collect();
    let (name, xl, yl) = match axis {
        1 => ("y", "x start (m)", "z start (m)"),
        _ => ("z", "x start (m)", "y start (m)"),
    };
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
    let path = format!("{dir}/convergence_{tag}_{name}.svg");
    std::fs::write(&path, h.to_svg()?)?;
    h.to_png(path.replace(".svg", ".png"), 800, 600)?;
    println!("wrote {path}");
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args().nth(1).unwrap_or_else(|| ".".into());
    std::fs::create_dir_all(&dir)?;
    let case = ConvergenceCase::seed_fig2(40);
    let dir_src = case.position_m.normalize();
    for (init, tag) in [
        (Initialisation::None, "plain"),
        (Initialisation::MultiStart, "multistart"),
    ] {
        let t = Instant::now();
        let map = convergence_map(&case, init, 2)?;
        let secs = t.elapsed().as_secs_f64();
        let near = map.fraction_where(&case, |s| s.dot(&dir_src) > 1.0);
        let far = map.fraction_where(&case, |s| s.dot(&dir_src) < -1.0);
        println!(
            "{tag}: {} starts in {secs:.2} s, converged {:.4} (source side {near:.4}, other side {far:.4})",
            map.outcomes.len(),
            map.converged_fraction()
        );
        write_slice(&case, &map, 2, case.position_m.z, tag, &dir)?;
        write_slice(&case, &map, 1, case.position_m.y, tag, &dir)?;
    }
    Ok(())
}
