//! `aeromag em locate`: calibrated per-epoch pose of the bird.

use super::HalfSpaceArg;
use super::files::read_detected;
use crate::exit::bad_input;
use aeromag_em::calibration::CalibrationFile;
use aeromag_em::positioning::Hemisphere;
use std::fmt::Write;
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
/// Example:
///   aeromag em locate --input em/detected.csv --calibration em/cal.json --out em/poses.csv
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct LocateArgs {
    /// Detected-vector CSV (`aeromag em detect`).
    #[arg(long, short = 'i', value_name = "DETECTED.csv")]
    input: PathBuf,
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
    let normal = a.half_space.normal()?;
    let text = std::fs::read_to_string(&a.calibration)
        .map_err(|e| bad_input!("cannot read '{}': {e}", a.calibration.display()))?;
    let file = CalibrationFile::from_json(&text)
        .map_err(|e| bad_input!("'{}': {e}", a.calibration.display()))?;
    let epochs = read_detected(&a.input)?;
    let mut hemi = Hemisphere::new(normal);
    let mut s = String::from(
        "time_s,x_m,y_m,z_m,range_m,roll_deg,pitch_deg,yaw_deg,pol_ratio_1,pol_ratio_2,pol_ratio_3,residual_rel,hemisphere_by_continuity,status\n",
    );
    let mut failed = 0usize;
    let mut by_continuity = 0usize;
    for e in &epochs {
        match file.calibration.locate(&e.h, &file.moments_am2, &mut hemi) {
            Ok(l) => {
                let p = &l.pose.position_m;
                let att = l.pose.attitude();
                let q = l.polarisation_ratio;
                by_continuity += usize::from(hemi.by_continuity);
                let _ = writeln!(
                    s,
                    "{},{},{},{},{},{},{},{},{},{},{},{},{},0",
                    e.time_s,
                    p[0],
                    p[1],
                    p[2],
                    l.pose.range_m(),
                    att.roll.to_degrees(),
                    att.pitch.to_degrees(),
                    att.yaw.to_degrees(),
                    q[0],
                    q[1],
                    q[2],
                    l.rms_residual,
                    u8::from(hemi.by_continuity)
                );
            }
            Err(err) => {
                failed += 1;
                if failed == 1 {
                    eprintln!("warning: epoch at {} s not located: {err}", e.time_s);
                }
                let _ = writeln!(s, "{},,,,,,,,,,,,,1", e.time_s);
            }
        }
    }
    std::fs::write(&a.out, s)?;
    println!(
        "located {} of {} epochs ({} by continuity near the half-space plane)",
        epochs.len() - failed,
        epochs.len(),
        by_continuity
    );
    if failed > 0 {
        eprintln!("warning: {failed} epochs could not be located (status = 1)");
    }
    println!("  poses {}", a.out.display());
    Ok(())
}
