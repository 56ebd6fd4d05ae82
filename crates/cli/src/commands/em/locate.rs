//! `aeromag em locate`: calibrated per-epoch pose of the bird (library:
//! [`aeromag::em::locate`]).

use super::HalfSpaceArg;
use crate::progress::Bars;
use aeromag::em::files::{read_calibration, read_detected};
use aeromag::em::locate;
use std::path::PathBuf;

/// Locate the bird per epoch: position, range, Euler angles, quality figures.
///
/// At every detected epoch the calibration's
/// stage 1 turns the complex fields into real major-axis vectors, the closed
/// form (Gram matrix eigen-decomposition; rotation by SVD projection onto
/// SO(3)) uses the stage-2 moments, a Levenberg–Marquardt polish fits all
/// nine components, and the stage-3 rotation corrects the attitude.
///
/// r and −r give the same data: the sign is taken from the prior half-space
/// r·n > 0 (--half-space) unless the direction is within ≈ 11.5° of the
/// dividing plane, where the previous epoch's direction decides
/// (hemisphere_by_continuity = 1).
///
/// Output CSV, one row per epoch:
///   time_s; x_m, y_m, z_m (transmitter frame); range_m; roll_deg,
///   pitch_deg, yaw_deg (receiver attitude relative to the transmitter
///   frame, Z-Y-X); pol_ratio_1..3 (polarisation ratio after calibration,
///   ≈ 0 for a clean field); residual_rel (RMS relative misfit of the nine
///   field components); hemisphere_by_continuity (0/1); status (0 located,
///   1 failed: pose columns empty).
///
/// An epoch whose residual_rel exceeds 1e-3 (15× the largest of 2560
/// simulated epochs) is not explained by the dipoles at one pose and is
/// failed, with a warning; when no epoch is located the command fails
/// (exit 1) and writes nothing.
///
/// Example:
///   aeromag em locate --input em/detected.csv --calibration em/cal.json --out em/poses.csv
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
#[command(mut_arg("input", |a| a.value_name("DETECTED.csv").help("Detected-vector CSV (`aeromag em detect`)")))]
#[command(mut_arg("file", |a| a.value_name("DETECTED.csv")))]
pub struct LocateArgs {
    #[command(flatten)]
    input: crate::input::InputFile,
    /// Calibration file (`aeromag em calibrate`).
    #[arg(long, value_name = "CAL.json")]
    calibration: PathBuf,
    /// Pose CSV to write.
    #[arg(long, value_name = "POSES.csv")]
    out: PathBuf,
    #[command(flatten)]
    half_space: HalfSpaceArg,
}

pub fn run(a: LocateArgs) -> anyhow::Result<()> {
    crate::output::check_files(
        [a.out.as_path()],
        &[a.input.path(), a.calibration.as_path()],
    )?;
    let file = read_calibration(&a.calibration)?;
    let epochs = read_detected(a.input.path())?;
    let poses =
        locate(&epochs, &file, &a.half_space.half_space, &mut Bars::new()).map_err(|e| {
            anyhow::Error::new(e).context(format!(
                "locating '{}' with '{}' failed",
                a.input.path().display(),
                a.calibration.display()
            ))
        })?;
    aeromag::io::atomic::write_file(&a.out, poses.to_csv())
        .map_err(|e| aeromag::Error::write(&a.out, e))?;
    println!(
        "located {} of {} epochs ({} by continuity near the half-space plane)",
        epochs.len() - poses.failed(),
        epochs.len(),
        poses.by_continuity()
    );
    println!("  poses {}", a.out.display());
    Ok(())
}
