//! `aeromag em`: low-frequency EM relative positioning of a towed bird
//! (spec `em-positioning.md`, seed 001; library `aeromag-em`).
//!
//! On files, as a survey crew would chain them:
//! `em simulate` (raw ADC record, system, KNOWN, truth) → `em detect`
//! (detected vectors CSV) → `em calibrate` (CAL.json) → `em locate`
//! (poses CSV); `em study` runs the whole chain in memory over a 5-hour
//! flight and writes the report.

mod calibrate;
mod detect;
mod locate;
mod simulate;

use crate::progress::Bars;
use aeromag::em::HalfSpace;
use aeromag::report::Report;
use aeromag::studies::{EmStudy, Study, StudyOutcome, StudySize};
use serde_json::json;
use std::path::PathBuf;

/// Low-frequency EM positioning of a towed receiver bird in the field of a
/// three-dipole transmitter on the aircraft.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    command: Sub,
}

#[derive(Debug, clap::Subcommand)]
enum Sub {
    Simulate(simulate::SimulateArgs),
    Detect(detect::DetectArgs),
    Calibrate(calibrate::CalibrateArgs),
    Locate(locate::LocateArgs),
    Study(StudyArgs),
}

/// Full-chain study over a simulated 5-hour flight: ADC-level coil voltages
/// with every distortion (gain/phase drift, cross-coupling, transmitter
/// distortion, noise, 400 Hz, sferics) → synchronous detection with pilot
/// correction → three-stage calibration (polarisation; transmitter geometry
/// from known positions; attitude from one known attitude) → positioning.
/// Prints the RMS range, direction and attitude errors and the polarisation
/// ratio before/after calibration and without pilot correction, and the
/// errors of the calibrated chain versus range and coil-noise level; writes
/// DIR/summary.json, DIR/calibration.json, DIR/curves.json and DIR/index.html
/// (error and ratio versus flight time, error versus range and SNR, detector
/// frequency response).
///
/// Example: `aeromag em study --out em-study`
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
struct StudyArgs {
    /// Output folder.
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// Seed of the simulated scenario.
    #[arg(long, default_value_t = EmStudy::default().config.seed)]
    seed: u64,
    /// Fewer epochs (36 calibration / 16 known positions / 12 evaluation
    /// instead of 120 / 40 / 40, same flight) and fewer curve points.
    #[arg(long)]
    quick: bool,
}

/// The prior half-space of the bird (`--half-space`), shared by `em
/// calibrate` and `em locate`.
#[derive(Debug, Clone, clap::Args)]
pub struct HalfSpaceArg {
    /// Prior half-space normal NX,NY,NZ (transmitter frame) for the ±r
    /// choice: the bird is where r·n > 0 (default: behind and below, x
    /// forward, z down). Give the same to `em calibrate` and `em locate`;
    /// `em calibrate` refuses known positions on the other side.
    #[arg(
        long = "half-space",
        value_name = "NX,NY,NZ",
        default_value_t = HalfSpace::default(),
        allow_hyphen_values = true,
        value_parser = crate::args::parsed::<HalfSpace>
    )]
    pub half_space: HalfSpace,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    match a.command {
        Sub::Simulate(s) => simulate::run(s),
        Sub::Detect(s) => detect::run(s),
        Sub::Calibrate(s) => calibrate::run(s),
        Sub::Locate(s) => locate::run(s),
        Sub::Study(s) => study(s),
    }
}

/// The files `em study` writes into its folder, as a set.
const STUDY_FILES: [&str; 4] = [
    "summary.json",
    "calibration.json",
    "curves.json",
    "index.html",
];

fn study(a: StudyArgs) -> anyhow::Result<()> {
    let paths = crate::output::check_folder_files(&a.out, STUDY_FILES, &[])?;
    let mut run = EmStudy::default();
    run.config.seed = a.seed;
    let out = run.run(StudySize::quick_if(a.quick), &mut Bars::new())?;
    let (s, c) = (&out.study, &out.curves);
    println!(
        "RMS range error          {:.3e} (relative)",
        s.range_err_rel
    );
    println!("RMS direction error      {:.4} deg", s.angle_err_deg);
    println!("RMS attitude error       {:.4} deg", s.attitude_err_deg);
    println!(
        "polarisation ratio RMS   before {:.3e}, after {:.3e} ({:.0}×), after without pilot {:.3e}",
        s.polarization_ratio_before,
        s.polarization_ratio_after,
        s.polarization_ratio_before / s.polarization_ratio_after,
        s.ratio_without_pilot
    );
    // Everything computed first, then the four files written as a set: an
    // interruption leaves an earlier study's files or the new ones.
    let summary = serde_json::to_string_pretty(&json!({ "em": out.summary() }))?;
    let calibration = s.calibration.to_json()?;
    let curves = serde_json::to_string_pretty(c)?;
    let mut r = Report::new("aeromag — EM relative positioning study");
    out.section()?.append_to(&mut r);
    let html = r.to_html();
    let texts = [summary, calibration, curves, html];
    let files: Vec<(&std::path::Path, &[u8])> = paths
        .iter()
        .zip(&texts)
        .map(|(p, t)| (p.as_path(), t.as_bytes()))
        .collect();
    aeromag::model_file::write_files(&files)?;
    for p in c.versus_range.iter().chain(&c.versus_noise) {
        println!(
            "range {:>5.1} m, coil noise ×{:<6} SNR {:>5.1} dB: range {:.2e}, direction {:.4} deg, attitude {:.4} deg",
            p.range_m,
            p.noise_scale,
            p.snr_db,
            p.range_err_rel,
            p.angle_err_deg,
            p.attitude_err_deg
        );
    }
    println!("report written to {}", paths[3].display());
    Ok(())
}
