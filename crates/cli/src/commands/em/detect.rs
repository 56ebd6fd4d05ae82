//! `aeromag em detect`: raw ADC record → detected complex field vectors
//! (library: [`aeromag::em::detect`]).

use crate::progress::Bars;
use aeromag::core::filter::Window;
use aeromag::em::files::read_system;
use aeromag::em::sim::detected_csv;
use aeromag::em::{DetectOptions, detect};
use std::path::PathBuf;

/// Detect the complex field vectors of a raw EM record (pilot-corrected).
///
/// Synchronous detection (seed 001 eq. 2): for each
/// non-overlapping block of N samples and each channel, the FIR-weighted
/// complex amplitude at the three working frequencies and at the six pilot
/// tones f ± δ; the pilots give the channel sensitivity ξ (eq. 4), which is
/// divided out together with the bench cross-coupling χ and the coil
/// transfer −iωg, leaving the complex field of each dipole in receiver axes.
/// Frequencies, pilot offset, coil gain and χ come from the raw header
/// (or --system).
///
/// Frequency plan: with a 4-term window (Blackman–Harris, Nuttall) every
/// tone on the bin grid f_s/N at least 4 bins from a detector is rejected
/// exactly; the command warns when the plan is off the grid.
///
/// Output CSV, one row per block: time_s (block centre), h{i}_{x,y,z}_re_t /
/// _im_t (field of dipole i = 1..3, T), xi{i}_{x,y,z}_re / _im (pilot-measured
/// sensitivity, detected pilot / nominal; 1 with --no-pilot), pol_ratio_{i}
/// (polarisation ratio, minor/major axis, before calibration).
///
/// Example: `aeromag em detect --input em/em.raw --out em/detected.csv`
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
#[command(mut_arg("input", |a| a.value_name("RAW").help("Raw record (`aeromag em simulate` writes DIR/em.raw)")))]
#[command(mut_arg("file", |a| a.value_name("RAW")))]
pub struct DetectArgs {
    #[command(flatten)]
    input: crate::input::InputFile,
    /// Detected-vector CSV to write.
    #[arg(long, value_name = "DETECTED.csv")]
    out: PathBuf,
    /// Skip the pilot correction (ξ = 1): shows the channel drift.
    #[arg(long)]
    no_pilot: bool,
    /// Detector block length N, samples (output rate f_s/N).
    #[arg(long, value_name = "N", default_value_t = DetectOptions::default().window_len)]
    window_len: usize,
    /// Weighting window: blackman-harris or nuttall (4-term: zeros at ≥ 4 bins).
    #[arg(long, value_name = "NAME", default_value_t = WindowName(DetectOptions::default().window),
          value_parser = window)]
    window: WindowName,
    /// Instrument constants (JSON, as em.system.json) instead of the raw
    /// header's.
    #[arg(long, value_name = "FILE.json")]
    system: Option<PathBuf>,
}

/// The detector windows by their names on the command line.
const WINDOWS: [(&str, Window); 2] = [
    ("blackman-harris", Window::BlackmanHarris),
    ("nuttall", Window::Nuttall),
];

/// A detector window as named on the command line.
#[derive(Debug, Clone, Copy)]
struct WindowName(Window);

impl std::fmt::Display for WindowName {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let name = WINDOWS
            .iter()
            .find(|(_, w)| *w == self.0)
            .map_or("?", |(n, _)| n);
        f.write_str(name)
    }
}

fn window(name: &str) -> Result<WindowName, String> {
    WINDOWS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|&(_, w)| WindowName(w))
        .ok_or_else(|| "expected blackman-harris or nuttall".into())
}

pub fn run(a: DetectArgs) -> anyhow::Result<()> {
    crate::output::check_files([a.out.as_path()], &[a.input.path()])?;
    let opts = DetectOptions {
        window_len: a.window_len,
        window: a.window.0,
        pilot: !a.no_pilot,
        system: a.system.as_deref().map(read_system).transpose()?,
    };
    let d = detect(a.input.path(), &opts, &mut Bars::new())?;
    aeromag::io::atomic::write_file(&a.out, detected_csv(&d.epochs))
        .map_err(|e| aeromag::Error::write(&a.out, e))?;
    let n = d.window_len;
    println!(
        "detected {} epochs of {n} samples ({:.3} s, {:.2} Hz output) from '{}'{}; polarisation ratio RMS {:.3e} (before calibration)",
        d.epochs.len(),
        n as f64 / d.sample_rate_hz,
        d.sample_rate_hz / n as f64,
        a.input.path().display(),
        if a.no_pilot {
            ", no pilot correction"
        } else {
            ""
        },
        d.polarization_ratio_rms
    );
    println!("  detected  {}", a.out.display());
    Ok(())
}
