//! `aeromag demo`: the whole chain on built-in simulated data (library:
//! [`aeromag::studies::Demo`]).

use crate::progress::Bars;
use aeromag::io::atomic::Staging;
use aeromag::observer::{Note, Observer};
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

/// The command's own files in DIR, beside the studies' ([`Demo::outputs`]).
const SUMMARY: &str = "summary.json";
const INDEX: &str = "index.html";

pub fn run(a: Args) -> anyhow::Result<()> {
    let size = StudySize::quick_if(a.quick);
    // Every file of the run checked before minutes of work (a folder in
    // the place of maps/levelled.tif failed after 40 s, with a mix of old
    // and new files).
    let mut files = Demo::outputs(size);
    files.extend([SUMMARY, INDEX].map(PathBuf::from));
    crate::output::check_folder(&a.out)?;
    let targets: Vec<PathBuf> = files.iter().map(|f| a.out.join(f)).collect();
    crate::output::check_files(targets.iter().map(|p| p.as_path()), &[])?;
    let start = Instant::now();
    if a.quick {
        eprintln!("--quick: the truncated calibration pattern is used");
    }
    // The run writes into a staging folder in DIR, whose files replace the
    // old ones together at the end: an error or an interruption on the way
    // leaves the old set whole (data and models were replaced as the run
    // went, the summary, report and maps at the end).
    let staging = Staging::new(&a.out).map_err(|e| aeromag::Error::write(&a.out, e))?;
    let demo = Demo {
        seed: a.seed,
        out: staging.path().to_path_buf(),
    };
    let mut bars = Bars::new();
    let mut observer = Staged {
        inner: &mut bars,
        staging: staging.path().display().to_string(),
        out: a.out.display().to_string(),
    };
    let out = demo.run(size, &mut observer)?;
    aeromag::model_file::write_files(&[
        (
            &staging.path().join(SUMMARY),
            out.summary.to_json()?.as_bytes(),
        ),
        (
            &staging.path().join(INDEX),
            out.report().to_html().as_bytes(),
        ),
    ])?;
    staging
        .commit()
        .map_err(|(path, e)| aeromag::Error::write(path, e))?;
    println!(
        "aeromag demo (seed {}, {:.1} s)",
        a.seed,
        start.elapsed().as_secs_f64()
    );
    println!("{:<56} {:>12}", "figure", "value");
    for row in out.summary.printed() {
        println!("{:<56} {:>12}", row.key, row.value);
    }
    println!("results in {}/ ({SUMMARY}, {INDEX})", a.out.display());
    Ok(())
}

/// The run's observer, its notes naming the files where they end up
/// (`DIR/data/…`), not in the staging folder where the run writes them.
struct Staged<'a> {
    inner: &'a mut dyn Observer,
    staging: String,
    out: String,
}

impl Observer for Staged<'_> {
    fn stage(&mut self, name: &str) {
        self.inner.stage(name);
    }

    fn progress(&mut self, done: u64, total: u64) {
        self.inner.progress(done, total);
    }

    fn note(&mut self, note: &Note) {
        let mut note = note.clone();
        note.message = note.message.replace(&self.staging, &self.out);
        self.inner.note(&note);
    }
}
