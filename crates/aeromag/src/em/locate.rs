//! The calibrated per-epoch pose of the bird.

use super::HalfSpace;
use crate::error::{Error, Result};
use crate::observer::{Note, Notes, Observer};
use aeromag_em::EmError;
use aeromag_em::calibration::CalibrationFile;
use aeromag_em::detection::FieldEpoch;
use aeromag_em::positioning::Hemisphere;
use nalgebra::Vector3;
use std::fmt::Write;

/// The pose of one epoch (`None` fields when it could not be located).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
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
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
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

/// The largest RMS relative misfit ([`Located::residual_rel`]) of a
/// located epoch: above it the nine field components do not fit one
/// dipole pose, and the epoch is failed (status 1).
///
/// Measured on simulated records (`em simulate` → `detect` →
/// `calibrate` → `locate`, default scenario, seeds 1–10 each started at
/// 0, 150, 300 and 450 s, i.e. ranges 30–100 m: 40 records, 2560 epochs):
/// median 5.9·10⁻⁶, 99th percentile 4.2·10⁻⁵, largest 6.8·10⁻⁵. The
/// bound is 15× that largest value. Records that do not fit give
/// 3.8·10⁻³ to 0.333: channels x and y swapped 0.22–0.33 (ranges to
/// 2 km), a record of pure noise (coil noise 2 V) 0.034–0.29, an
/// asymmetric `transmitter_s` 0.054–0.072, detector windows too short to
/// resolve the pilots (N = 1600, 4000, 12000 of 16000) 0.0038–0.33 with
/// position errors of 10 m to 5·10¹⁰ m.
pub const MAX_RESIDUAL_REL: f64 = 1e-3;

/// The poses of a pass.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
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

/// Epochs located between two progress reports and Ctrl-C checks of
/// [`locate`].
const LOCATE_STEP: usize = 1024;

/// Locate the bird at every epoch: the calibration's stage 1 turns the
/// complex fields into real major-axis vectors, the closed form (Gram
/// matrix eigen-decomposition; rotation by SVD projection onto SO(3)) uses
/// the stage-2 moments, a Levenberg–Marquardt polish fits all nine
/// components, and the stage-3 rotation corrects the attitude. r and −r
/// give the same data: the sign comes from the half-space unless the
/// direction is within ≈ 11.5° of its plane, where the neighbouring
/// epoch's direction decides (continuity). The sign is anchored at the
/// first epoch the half-space decides; epochs before it take theirs by
/// continuity backwards from it. An epoch that fails, or whose misfit exceeds
/// [`MAX_RESIDUAL_REL`], is kept (`located: None`) and warned about with
/// the counts.
///
/// Errors ([`EmError::Failed`], not bad input) when epochs were given and
/// none was located; bad input when no epoch's direction is decisively on
/// one side of `half_space` (the sign of r would be a guess).
pub fn locate(
    epochs: &[FieldEpoch],
    file: &CalibrationFile,
    half_space: &HalfSpace,
    observer: &mut dyn Observer,
) -> Result<Poses> {
    let mut notes = Notes::new(observer);
    notes.stage("locating");
    if let Some(fitted) = file.half_space.map(Vector3::from)
        && let Ok(fitted) = HalfSpace::new(fitted)
        && fitted
            .normal()
            .normalize()
            .dot(&half_space.normal().normalize())
            < 1.0 - 1e-9
    {
        notes.warn(format!(
            "the calibration was fitted with --half-space={fitted} (its known positions on that side) and the bird is located with --half-space={half_space}: a bird on the calibration's side but not on this one comes out mirrored to −r; give both commands the same half-space"
        ));
    }
    let hemi0 = Hemisphere::new(half_space.normal());
    // Each epoch's fit and whether continuity decided its sign.
    let fit = |e: &FieldEpoch, hemi: &mut Hemisphere| {
        let got = file.calibration.locate(&e.h, &file.moments_am2, hemi);
        (got, hemi.by_continuity)
    };
    let mut fits: Vec<Option<_>> = epochs.iter().map(|_| None).collect();
    // The sign is anchored at the first epoch whose direction the
    // half-space decides (outside the margin), fitted as if it were the
    // first: an undecided first epoch took its sign from the half-space
    // alone and continuity carried a wrong hemisphere through the record
    // (birds 4–9° beyond the plane all mirrored, 87 m off, exit 0).
    let mut anchor = None;
    // The epoch whose direction is furthest from the plane, |e·n|, time.
    let mut nearest_decisive = (f64::NEG_INFINITY, f64::NAN);
    for (k, e) in epochs.iter().enumerate() {
        let mut probe = hemi0;
        let got = fit(e, &mut probe);
        let Some(dir) = probe.previous else { continue };
        if probe.decisive(&dir) {
            fits[k] = Some(got);
            anchor = Some((k, probe));
            break;
        }
        let side = probe.side(&dir).abs();
        if side > nearest_decisive.0 {
            nearest_decisive = (side, e.time_s);
        }
    }
    let (start, mut forward) = match anchor {
        Some((k, hemi)) => (k + 1, hemi),
        // No epoch gave a direction at all: each fails below.
        None if nearest_decisive.0.is_infinite() => (0, hemi0),
        None => {
            let stored = file
                .half_space
                .map(|n| {
                    format!(
                        " (the calibration was fitted with --half-space={},{},{})",
                        n[0], n[1], n[2]
                    )
                })
                .unwrap_or_default();
            return Err(Error::bad_input(format!(
                "--half-space={half_space}{stored}: no epoch of {} has its direction decisively on one side (|e·n| ≥ {} of the plane; the largest is {:.3}, at {} s), so the sign of r cannot be chosen: pass the bird's half-space as --half-space=NX,NY,NZ",
                epochs.len(),
                hemi0.margin,
                nearest_decisive.0,
                nearest_decisive.1
            )));
        }
    };
    // Progress and Ctrl-C every LOCATE_STEP epochs (each fit takes tens
    // of microseconds).
    let total = epochs.len() as u64;
    let step = |done: usize, notes: &mut Notes| -> Result<()> {
        if done.is_multiple_of(LOCATE_STEP) {
            notes.progress(done as u64, total);
            notes.check_cancelled()?;
        }
        Ok(())
    };
    for k in start..epochs.len() {
        step(k - start, &mut notes)?;
        fits[k] = Some(fit(&epochs[k], &mut forward));
    }
    // Continuity from the anchor backwards over the undecided epochs before it.
    if let Some((k, hemi)) = anchor {
        let mut backward = Hemisphere {
            previous: hemi.previous,
            ..hemi0
        };
        for j in (0..k).rev() {
            step(epochs.len() - start + (k - j), &mut notes)?;
            fits[j] = Some(fit(&epochs[j], &mut backward));
        }
    }
    let mut poses = Vec::with_capacity(epochs.len());
    let mut failed = 0usize;
    // Epochs whose fit does not explain the field: count, first time, range.
    let mut misfit = 0usize;
    let mut misfit_first = 0.0;
    let (mut misfit_lo, mut misfit_hi) = (f64::INFINITY, 0.0f64);
    // Every epoch is fitted, in one of the three passes above.
    for (e, (got, by_continuity)) in epochs.iter().zip(fits.into_iter().flatten()) {
        let located = match got {
            Ok(l) if l.rms_residual.is_nan() || l.rms_residual > MAX_RESIDUAL_REL => {
                misfit += 1;
                if misfit == 1 {
                    misfit_first = e.time_s;
                }
                misfit_lo = misfit_lo.min(l.rms_residual);
                misfit_hi = misfit_hi.max(l.rms_residual);
                None
            }
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
                    by_continuity,
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
    let misfit_text = (misfit > 0).then(|| {
        format!(
            "{misfit} of {} epochs (the first at {misfit_first} s) fit with an RMS relative residual of {} to {}, above {MAX_RESIDUAL_REL:e}: the field is not that of the transmitter's dipoles at one pose (swapped or mislabelled channels, a record without signal, a detector window too short to resolve the pilots, or a calibration that does not belong to this record)",
            epochs.len(),
            aeromag_core::error::figure(misfit_lo),
            aeromag_core::error::figure(misfit_hi),
        )
    });
    if failed + misfit == epochs.len() && !epochs.is_empty() {
        let mut what = format!("no epoch of {} located", epochs.len());
        if failed > 0 {
            what.push_str(&format!("; {failed} could not be located"));
        }
        if let Some(t) = misfit_text {
            what.push_str(&format!("; {t}"));
        }
        return Err(EmError::Failed { what }.into());
    }
    if let Some(t) = misfit_text {
        notes.warn(format!("{t} (status = 1)"));
    }
    if failed > 0 {
        notes.warn(format!("{failed} epochs could not be located (status = 1)"));
    }
    Ok(Poses {
        poses,
        notes: notes.into_notes(),
    })
}
