//! `aeromag demo`: the whole chain on built-in simulated data (library:
//! [`aeromag::studies::Demo`]).

use crate::progress::Bars;
use aeromag::studies::{Demo, PrintedSummary, Study, StudySize};
use std::path::PathBuf;
use std::time::Instant;

/// Run aeromag end to end on simulated data with known truth.
///
/// Simulates a calibration box (four headings with roll, pitch and yaw
/// manoeuvres) over a quiet area and over realistic geology, and an
/// independent survey flight with the same aircraft; fits the Tolles-Lawson
/// model on each calibration flight by band-pass least squares and by the
/// Kalman method, compensates the survey, scores the result
/// against the simulator's truth, levels the survey, runs the helicopter
/// rotor, towed-pod, EM positioning and gradiometry studies, prints a
/// summary table, and writes DIR/summary.json, DIR/index.html (single-file
/// report, plots inline), the model files and the simulated and
/// compensated data.
///
/// Example: `aeromag demo --out demo-out`
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct Args {
    /// Output folder.
    #[arg(long, default_value = "demo-out", value_name = "DIR")]
    out: PathBuf,
    /// Seed of the simulated flights (the survey uses seed + 1).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Smaller, faster run (same steps).
    #[arg(long)]
    quick: bool,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let [summary, index] =
        crate::output::check_folder_files(&a.out, ["summary.json", "index.html"], &[])?;
    let start = Instant::now();
    std::fs::create_dir_all(a.out.join("data"))
        .map_err(|e| aeromag::Error::write(a.out.join("data"), e))?;
    if a.quick {
        eprintln!("--quick: the truncated calibration pattern is used");
    }
    let demo = Demo {
        seed: a.seed,
        out: a.out.clone(),
    };
    let out = demo.run(StudySize::quick_if(a.quick), &mut Bars::new())?;
    // The summary and the report as a set: both old or both new.
    aeromag::model_file::write_files(&[
        (&summary, out.summary.to_json()?.as_bytes()),
        (&index, out.report().to_html().as_bytes()),
    ])?;
    println!(
        "aeromag demo (seed {}, {:.1} s)",
        a.seed,
        start.elapsed().as_secs_f64()
    );
    println!("{:<56} {:>12}", "figure", "value");
    for row in out.summary.printed() {
        println!("{:<56} {:>12}", row.key, row.value);
    }
    println!("results in {}/ (summary.json, index.html)", a.out.display());
    Ok(())
}
