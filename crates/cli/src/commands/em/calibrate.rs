//! `aeromag em calibrate`: the three calibration stages from detected
//! vectors and a KNOWN file (library: [`aeromag::em::calibrate`]).

use super::HalfSpaceArg;
use aeromag::em::files::{load_table, read_detected, read_system};
use aeromag::em::{calibrate, known_points};
use std::path::PathBuf;

/// Fit the three-stage calibration from detected vectors and known points.
///
/// The three calibration stages of seed 001:
///   1. polarisation: detection phases and imaginary couplings that make each
///      dipole's field linearly polarised, by least squares over ALL epochs
///      (no external information; needs ≥ 8 epochs at varied attitudes);
///   2. transmitter geometry: the 6 coefficients of the symmetric
///      transmitter distortion from the epochs whose position (range and
///      direction) KNOWN.csv gives (≥ 2);
///   3. attitude: the small rotation Q from the epoch(s) whose attitude
///      KNOWN.csv gives (one suffices).
///
/// `em locate` applies them in the same order.
///
/// KNOWN.csv (CSV, `#` comments allowed), one row per known point:
///   time_s                 time of the point, s; must fall within half an
///                          epoch spacing of a detected epoch's time_s
///   x_m, y_m, z_m          receiver position in the transmitter frame, m
///                          (all three, or all three empty)
///   roll_deg, pitch_deg,   receiver attitude relative to the transmitter
///   yaw_deg                frame, Z-Y-X Euler angles, deg (all three, or
///                          all three empty; the columns may be omitted)
/// A row gives a position, an attitude or both. Example:
///   time_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg
///   0.07999,-52.1,1.9,39.2,12.5,-3.1,0.2
///   0.23999,-52.2,2.4,39.1,,,
///
/// The calibration file (JSON) holds "format": "aeromag-em-calibration",
/// "version": 1, the nominal moments, the three stages and the fit counts.
///
/// Example:
///   aeromag em calibrate --input em/detected.csv --known em/em.known.csv \
///       --system em/em.system.json --out em/cal.json
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
#[command(mut_arg("input", |a| a.value_name("DETECTED.csv").help("Detected-vector CSV (`aeromag em detect`)")))]
#[command(mut_arg("file", |a| a.value_name("DETECTED.csv")))]
pub struct CalibrateArgs {
    #[command(flatten)]
    input: crate::input::InputFile,
    /// Known positions and attitude (format above).
    #[arg(long, value_name = "KNOWN.csv")]
    known: PathBuf,
    /// Instrument constants (nominal moments): em.system.json.
    #[arg(long, value_name = "FILE.json")]
    system: PathBuf,
    /// Calibration file to write (JSON).
    #[arg(long, value_name = "CAL.json")]
    out: PathBuf,
    #[command(flatten)]
    half_space: HalfSpaceArg,
}

pub fn run(a: CalibrateArgs) -> anyhow::Result<()> {
    crate::output::check_files(
        [a.out.as_path()],
        &[a.input.path(), a.known.as_path(), a.system.as_path()],
    )?;
    let system = read_system(&a.system)?;
    let epochs = read_detected(a.input.path())?;
    let known = known_points(&load_table(&a.known)?, &epochs)?;
    let cal = calibrate(&epochs, &known, &system, &a.half_space.half_space).map_err(|e| {
        anyhow::Error::new(e).context(format!(
            "calibration from '{}', '{}' and '{}' failed",
            a.input.path().display(),
            a.known.display(),
            a.system.display()
        ))
    })?;
    aeromag::io::atomic::write_file(&a.out, cal.file.to_json()?)
        .map_err(|e| aeromag::Error::write(&a.out, e))?;
    let c = &cal.file.fit;
    println!(
        "calibrated from {} epochs, {} known positions, {} known attitude(s)",
        c.epochs, c.known_positions, c.known_attitudes
    );
    let (rb, ra) = (cal.polarization_ratio_before, cal.polarization_ratio_after);
    println!(
        "  polarisation ratio RMS {rb:.3e} → {ra:.3e} ({:.0}×)",
        rb / ra.max(f64::MIN_POSITIVE)
    );
    println!(
        "  transmitter distortion |S| = {:.3e}, attitude correction {:.4} deg",
        cal.transmitter_distortion, cal.attitude_correction_deg
    );
    println!("  calibration {}", a.out.display());
    Ok(())
}
