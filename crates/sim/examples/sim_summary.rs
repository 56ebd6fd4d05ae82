//! Print a summary of a simulated scenario: `cargo run --release -p
//! aeromag-sim --example sim_summary -- survey [seed]`.

use aeromag_sim::{ScenarioKind, simulate};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let kind: ScenarioKind = args
        .next()
        .unwrap_or_else(|| "calibration".into())
        .parse()?;
    let seed = args.next().map(|s| s.parse()).transpose()?;
    let t0 = std::time::Instant::now();
    let sim = simulate(kind, None, seed)?;
    let el = t0.elapsed();
    println!(
        "{kind}: {} samples ({:.1} min) in {:.3} s",
        sim.n_rows(),
        sim.n_rows() as f64 / 600.0,
        el.as_secs_f64()
    );
    for name in sim.column_names() {
        let v = sim.column(name).unwrap_or(&[]);
        let n = v.len() as f64;
        let mean = v.iter().sum::<f64>() / n;
        let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n).sqrt();
        let min = v.iter().copied().fold(f64::INFINITY, f64::min);
        let max = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        println!("{name:>22} mean {mean:>14.4} sd {sd:>11.4} min {min:>14.4} max {max:>14.4}");
    }
    Ok(())
}
