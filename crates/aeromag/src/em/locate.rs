//! The calibrated per-epoch pose of the bird.

use super::HalfSpace;
use crate::error::Result;
use crate::observer::{Note, Notes, Observer};
use aeromag_em::calibration::CalibrationFile;
use aeromag_em::detection::FieldEpoch;
use aeromag_em::positioning::Hemisphere;
use std::fmt::Write;

/// The pose of one epoch (`None` fields when it could not be located).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Epoch time, s.
    pub time_s: f64,
    /// Position in the transmitter frame, m, range m, attitude (roll,
    /// pitch, yaw, deg; receiver relative to the transmitter frame, Z-Y-X),
    /// polarisation ratio of each dipole after calibration, RMS relative
    /// misfit of the nine field components, and whether the hemisphere was
    /// decided by continuity; `None` if the epoch was not located.
    pub located: Option<Located>,
}

/// A located epoch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Located {
    /// Position, transmitter frame, m.
    pub position_m: [f64; 3],
    /// Range, m.
    pub range_m: f64,
    /// Roll, pitch, yaw, deg.
    pub attitude_deg: [f64; 3],
    /// Polarisation ratio of each dipole after calibration (≈ 0 for a
    /// clean field).
    pub polarisation_ratio: [f64; 3],
    /// RMS relative misfit of the nine field components.
    pub residual_rel: f64,
    /// The ±r choice was made by continuity (the direction within ≈ 11.5°
    /// of the half-space's plane).
    pub by_continuity: bool,
}

/// The poses of a pass.
#[derive(Debug, Clone)]
pub struct Poses {
    /// One per epoch, in order.
    pub poses: Vec<Pose>,
    /// Warnings (the first epoch that failed).
    pub notes: Vec<Note>,
}

impl Poses {
    /// Epochs not located.
    pub fn failed(&self) -> usize {
        self.poses.iter().filter(|p| p.located.is_none()).count()
    }

    /// Epochs whose hemisphere was decided by continuity.
    pub fn by_continuity(&self) -> usize {
        self.poses
            .iter()
            .filter(|p| p.located.is_some_and(|l| l.by_continuity))
            .count()
    }

    /// The pose CSV: `time_s, x_m, y_m, z_m, range_m, roll_deg, pitch_deg,
    /// yaw_deg, pol_ratio_1..3, residual_rel, hemisphere_by_continuity,
    /// status` (0 located, 1 failed: pose columns empty).
    pub fn to_csv(&self) -> String {
        let mut s = String::from(
            "time_s,x_m,y_m,z_m,range_m,roll_deg,pitch_deg,yaw_deg,pol_ratio_1,pol_ratio_2,pol_ratio_3,residual_rel,hemisphere_by_continuity,status\n",
        );
        for p in &self.poses {
            match p.located {
                Some(l) => {
                    let (r, a, q) = (l.position_m, l.attitude_deg, l.polarisation_ratio);
                    let _ = writeln!(
                        s,
                        "{},{},{},{},{},{},{},{},{},{},{},{},{},0",
                        p.time_s,
                        r[0],
                        r[1],
                        r[2],
                        l.range_m,
                        a[0],
                        a[1],
                        a[2],
                        q[0],
                        q[1],
                        q[2],
                        l.residual_rel,
                        u8::from(l.by_continuity)
                    );
                }
                None => {
                    let _ = writeln!(s, "{},,,,,,,,,,,,,1", p.time_s);
                }
            }
        }
        s
    }
}

/// Locate the bird at every epoch: the calibration's stage 1 turns the
/// complex fields into real major-axis vectors, the closed form (Gram
/// matrix eigen-decomposition; rotation by SVD projection onto SO(3)) uses
/// the stage-2 moments, a Levenberg–Marquardt polish fits all nine
/// components, and the stage-3 rotation corrects the attitude. r and −r
/// give the same data: the sign comes from the half-space unless the
/// direction is within ≈ 11.5° of its plane, where the previous epoch's
/// direction decides. An epoch that fails is kept (`located: None`); the
/// first failure is a warning.
pub fn locate(
    epochs: &[FieldEpoch],
    file: &CalibrationFile,
    half_space: &HalfSpace,
    observer: &mut dyn Observer,
) -> Result<Poses> {
    let mut notes = Notes::new(observer);
    let mut hemi = Hemisphere::new(half_space.normal());
    let mut poses = Vec::with_capacity(epochs.len());
    let mut failed = 0usize;
    for e in epochs {
        let located = match file.calibration.locate(&e.h, &file.moments_am2, &mut hemi) {
            Ok(l) => {
                let p = &l.pose.position_m;
                let att = l.pose.attitude();
                Some(Located {
                    position_m: [p[0], p[1], p[2]],
                    range_m: l.pose.range_m(),
                    attitude_deg: [
                        att.roll.to_degrees(),
                        att.pitch.to_degrees(),
                        att.yaw.to_degrees(),
                    ],
                    polarisation_ratio: l.polarisation_ratio,
                    residual_rel: l.rms_residual,
                    by_continuity: hemi.by_continuity,
                })
            }
            Err(err) => {
                failed += 1;
                if failed == 1 {
                    notes.warn(format!("epoch at {} s not located: {err}", e.time_s));
                }
                None
            }
        };
        poses.push(Pose {
            time_s: e.time_s,
            located,
        });
    }
    if failed > 0 {
        notes.warn(format!("{failed} epochs could not be located (status = 1)"));
    }
    Ok(Poses {
        poses,
        notes: notes.into_notes(),
    })
}
