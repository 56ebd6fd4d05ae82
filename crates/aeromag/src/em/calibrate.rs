//! The three calibration stages of seed 001 from detected vectors and a
//! KNOWN file.
//!
//! KNOWN.csv (CSV, `#` comments allowed), one row per known point:
//!
//! | column | meaning |
//! |---|---|
//! | `time_s` | time of the point, s; within half an epoch spacing of a detected epoch's `time_s` |
//! | `x_m, y_m, z_m` | receiver position in the transmitter frame, m (all three, or all three empty), 1 m to 10 km from the transmitter ([`KNOWN_RANGE_M`]) |
//! | `roll_deg, pitch_deg, yaw_deg` | receiver attitude relative to the transmitter frame, Z-Y-X, deg, each within ±360 (all three, or all three empty; the columns may be omitted) |
//!
//! A row gives a position, an attitude or both; each detected epoch takes
//! at most one position and one attitude.

use super::HalfSpace;
use crate::error::{Error, Result};
use crate::flight::Flight;
use aeromag_core::error::shown;
use aeromag_core::frames::Attitude;
use aeromag_em::calibration::{Calibration, CalibrationFile, FitCounts, KnownPoints};
use aeromag_em::detection::{EmSystem, FieldEpoch};
use aeromag_em::positioning::Hemisphere;
use aeromag_em::study::rms;
use nalgebra::Vector3;

/// Largest |roll|, |pitch|, |yaw| of a known attitude, deg: one turn
/// either way (the rotation is the same modulo 360°; beyond that a value
/// is a corrupted cell, not an angle).
pub const MAX_ANGLE_DEG: f64 = 360.0;

/// Range of a known position from the transmitter, m: a bird is towed
/// tens to hundreds of metres behind (the simulated scenario 30–100 m).
/// Below 1 m the point is the transmitter itself, where the dipole model
/// has no meaning (0,0,0 made stage 2 singular); beyond 10 km the
/// transmitter's field (≈ 4·10⁻¹⁵ T) is below any receiver's noise (1e300
/// also made stage 2 singular).
pub const KNOWN_RANGE_M: (f64, f64) = (1.0, 1e4);

/// A known position `p` (m, transmitter frame) within [`KNOWN_RANGE_M`] of
/// the transmitter, or the message saying how far it is. [`known_points`]
/// applies it to the KNOWN rows it reads and `em simulate` to the positions
/// it writes.
pub fn check_known_position(p: [f64; 3]) -> std::result::Result<(), String> {
    // Scaled by the largest component: 1e300 does not overflow.
    let big = p.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let range = if big > 0.0 {
        big * Vector3::new(p[0] / big, p[1] / big, p[2] / big).norm()
    } else {
        0.0
    };
    if (KNOWN_RANGE_M.0..=KNOWN_RANGE_M.1).contains(&range) {
        return Ok(());
    }
    Err(format!(
        "position {}, {}, {} m is {} m from the transmitter, expected {} … {} m (a towed bird; positions in metres)",
        shown(p[0]),
        shown(p[1]),
        shown(p[2]),
        shown(range),
        KNOWN_RANGE_M.0,
        KNOWN_RANGE_M.1
    ))
}

/// The known points of a KNOWN.csv table (module docs) against the
/// detected epochs' times: each row's time must fall within half an epoch
/// spacing of a detected epoch.
pub fn known_points(t: &Flight, epochs: &[FieldEpoch]) -> Result<KnownPoints> {
    let time = t.finite("time_s")?;
    let group = |names: [&str; 3], required: bool| -> Result<Option<[&[f64]; 3]>> {
        let present = names.iter().filter(|n| t.get(n).is_some()).count();
        if present == 0 && !required {
            return Ok(None);
        }
        Ok(Some([
            t.require(names[0])?,
            t.require(names[1])?,
            t.require(names[2])?,
        ]))
    };
    let pos = group(["x_m", "y_m", "z_m"], true)?;
    let att = group(["roll_deg", "pitch_deg", "yaw_deg"], false)?;
    let names = |g: [&'static str; 3]| g;
    let spacing = if epochs.len() > 1 {
        let mut d: Vec<f64> = epochs
            .windows(2)
            .map(|w| w[1].time_s - w[0].time_s)
            .collect();
        d.sort_by(f64::total_cmp);
        d[d.len() / 2]
    } else {
        f64::INFINITY
    };
    let mut known = KnownPoints::default();
    // The row that gave each epoch's position and attitude: two rows on one
    // epoch (times in ms against seconds, a time column shifted) counted
    // one epoch several times.
    let mut given_at: Vec<[Option<usize>; 2]> = vec![[None, None]; epochs.len()];
    for row in 0..t.n_rows() {
        let tk = time[row];
        let k = epochs.partition_point(|e| e.time_s < tk);
        let nearest = [k.checked_sub(1), Some(k)]
            .into_iter()
            .flatten()
            .filter(|&j| j < epochs.len())
            .min_by(|&a, &b| {
                (epochs[a].time_s - tk)
                    .abs()
                    .total_cmp(&(epochs[b].time_s - tk).abs())
            });
        let epoch = nearest
            .filter(|&j| (epochs[j].time_s - tk).abs() <= 0.5 * spacing)
            .ok_or_else(|| {
                t.bad_value(
                    row,
                    "time_s",
                    format!(
                        "{} s is not within half an epoch ({:.4} s) of any detected epoch ({} … {} s)",
                        shown(tk),
                        0.5 * spacing,
                        shown(epochs.first().map_or(f64::NAN, |e| e.time_s)),
                        shown(epochs.last().map_or(f64::NAN, |e| e.time_s))
                    ),
                )
            })?;
        let mut any = false;
        for (cols, g) in [
            (pos, names(["x_m", "y_m", "z_m"])),
            (att, names(["roll_deg", "pitch_deg", "yaw_deg"])),
        ] {
            let Some(c) = cols else { continue };
            let v = [c[0][row], c[1][row], c[2][row]];
            let given = v.map(|x| !x.is_nan());
            if given.iter().all(|&g| !g) {
                continue;
            }
            if let Some(j) = (0..3).find(|&j| !given[j] || !v[j].is_finite()) {
                return Err(t.bad_value(
                    row,
                    g[j],
                    format!(
                        "value missing or not finite while {} are given (give all three or none)",
                        g.iter()
                            .filter(|&&n| n != g[j])
                            .copied()
                            .collect::<Vec<_>>()
                            .join(" and ")
                    ),
                ));
            }
            if g[0] == "roll_deg"
                && let Some(j) = (0..3).find(|&j| v[j].abs() > MAX_ANGLE_DEG)
            {
                return Err(t.bad_value(
                    row,
                    g[j],
                    format!(
                        "{} deg is not an angle (within ±{MAX_ANGLE_DEG})",
                        shown(v[j])
                    ),
                ));
            }
            if g[0] == "x_m"
                && let Err(m) = check_known_position([v[0], v[1], v[2]])
            {
                // Named at the largest component.
                let j = (1..3).fold(0, |a, b| if v[b].abs() > v[a].abs() { b } else { a });
                return Err(t.bad_value(row, g[j], m));
            }
            let kind = usize::from(g[0] != "x_m");
            if let Some(prev) = given_at[epoch][kind] {
                return Err(t.bad_value(
                    row,
                    "time_s",
                    format!(
                        "{} s falls on the detected epoch at {} s, whose {} data row {} already gives: each epoch takes one (times in another unit than the detected file's?)",
                        shown(tk),
                        shown(epochs[epoch].time_s),
                        ["position", "attitude"][kind],
                        prev + 1
                    ),
                ));
            }
            given_at[epoch][kind] = Some(row);
            any = true;
            if g[0] == "x_m" {
                known
                    .positions
                    .push((epoch, Vector3::new(v[0], v[1], v[2])));
            } else {
                let c_nb =
                    Attitude::new(v[0].to_radians(), v[1].to_radians(), v[2].to_radians()).c_nb();
                known.attitudes.push((epoch, c_nb.transpose()));
            }
        }
        if !any {
            return Err(t.bad_value(
                row,
                "x_m",
                "the row gives neither a position (x_m, y_m, z_m) nor an attitude (roll_deg, pitch_deg, yaw_deg)",
            ));
        }
    }
    let file = t.file_label();
    if known.positions.len() < 2 {
        return Err(Error::bad_file(
            file,
            format!(
                "{} known position(s); calibration stage 2 needs at least 2",
                known.positions.len()
            ),
        ));
    }
    if known.attitudes.is_empty() {
        return Err(Error::bad_file(
            file,
            "no known attitude (roll_deg, pitch_deg, yaw_deg); calibration stage 3 needs one",
        ));
    }
    Ok(known)
}
/// A fitted calibration and the figures that show what it did.
#[derive(Debug, Clone)]
pub struct EmCalibration {
    /// The calibration file (nominal moments, the three stages, counts).
    pub file: CalibrationFile,
    /// RMS polarisation ratio before calibration.
    pub polarization_ratio_before: f64,
    /// … after stage 1.
    pub polarization_ratio_after: f64,
    /// Size of the transmitter distortion |S|.
    pub transmitter_distortion: f64,
    /// Angle of the attitude correction, deg.
    pub attitude_correction_deg: f64,
}

/// The known positions against the prior half-space: each known
/// position's direction `e` must lie clearly on the half-space's side,
/// `e·n/|n| ≥ margin` ([`Hemisphere`]); one within the continuity margin
/// or beyond the plane is bad input. Then the half-space stored in the
/// calibration file decides the sign at the known positions. A scenario's
/// birds ahead of the transmitter (mean direction `1,0,0`) with the
/// default `-1,0,1` were calibrated without a word and then located 84 m
/// off; birds 4–9° beyond the plane (`e·n` = −0.08 … −0.16, mean direction
/// `0.8,0,0.6`, or `--half-space=1,0,1.2` on the default flight) were
/// calibrated too, and `em locate` mirrored every one (87 m off, exit 0).
fn check_known_side(
    epochs: &[FieldEpoch],
    known: &KnownPoints,
    hemisphere: &Hemisphere,
    half_space: &HalfSpace,
) -> Result<()> {
    let n = hemisphere.normal.normalize();
    let side = |r: &Vector3<f64>| r.normalize().dot(&n);
    let Some(&(k, r)) = known
        .positions
        .iter()
        .find(|(_, r)| side(r) < hemisphere.margin)
    else {
        return Ok(());
    };
    let mean: Vector3<f64> = known.positions.iter().map(|(_, r)| r.normalize()).sum();
    let hint = if mean.norm() > 0.0 {
        let e = mean.normalize();
        format!(
            "; the known positions' mean direction is {:.2},{:.2},{:.2}: pass the bird's half-space as --half-space=NX,NY,NZ to both `em calibrate` and `em locate`",
            e.x, e.y, e.z
        )
    } else {
        String::new()
    };
    let s = side(&r);
    let margin = hemisphere.margin;
    let place = if s < 0.0 {
        format!("lies in the half-space opposite to --half-space={half_space}")
    } else {
        format!("lies within the continuity margin of the plane of --half-space={half_space}")
    };
    Err(Error::bad_input(format!(
        "the known position at {} s ({}, {}, {} m from the transmitter) {place} (its direction makes e·n = {s:.2}; known positions must be clearly on the half-space's side, e·n ≥ {margin}, ≈ 11.5° from the plane, for the half-space to decide the sign of r): `em locate` would mirror the bird to −r{hint}",
        shown(epochs.get(k).map_or(f64::NAN, |e| e.time_s)),
        shown(r.x),
        shown(r.y),
        shown(r.z),
    )))
}

/// Fit the three stages: (1) polarisation, from all epochs (no external
/// data; ≥ 8 epochs at varied attitudes); (2) transmitter geometry, from the
/// epochs whose position `known` gives (≥ 2); (3) attitude, from the
/// epoch(s) whose attitude it gives. `system` gives the nominal moments;
/// the sign of r is taken from the half-space.
///
/// Errors (bad input) when the fitted `|S|` or `Q` exceeds
/// [`MAX_TRANSMITTER_S`](aeromag_em::calibration::MAX_TRANSMITTER_S) or
/// [`MAX_ATTITUDE_Q_DEG`](aeromag_em::calibration::MAX_ATTITUDE_Q_DEG):
/// such corrections come from wrong units, swapped channels or signs.
pub fn calibrate(
    epochs: &[FieldEpoch],
    known: &KnownPoints,
    system: &EmSystem,
    half_space: &HalfSpace,
) -> Result<EmCalibration> {
    if epochs.len() < 8 {
        return Err(Error::bad_input(format!(
            "{} epochs; calibration stage 1 needs at least 8 at varied attitudes",
            epochs.len()
        )));
    }
    let hemisphere = Hemisphere::new(half_space.normal());
    check_known_side(epochs, known, &hemisphere, half_space)?;
    let data: Vec<_> = epochs.iter().map(|e| e.h).collect();
    let m = system.moments_am2;
    let cal = Calibration::fit(&data, known, &m, &hemisphere)?;
    if let Some(what) = cal.implausible() {
        return Err(Error::bad_input(format!(
            "the calibration corrects small mounting and transmitter errors, but {what}"
        )));
    }
    let before: Vec<f64> = data
        .iter()
        .flat_map(|e| aeromag_em::calibration::uncalibrated(e, &cal.polarisation.phase_rad).1)
        .collect();
    let after: Vec<f64> = data
        .iter()
        .flat_map(|e| cal.polarisation.apply(e).1)
        .collect();
    let file = CalibrationFile::new(
        cal,
        m,
        FitCounts {
            epochs: data.len(),
            known_positions: known.positions.len(),
            known_attitudes: known.attitudes.len(),
        },
    )
    .with_half_space(half_space.normal().into());
    Ok(EmCalibration {
        polarization_ratio_before: rms(&before),
        polarization_ratio_after: rms(&after),
        transmitter_distortion: cal.transmitter_s.norm(),
        attitude_correction_deg: aeromag_em::positioning::rotation_angle_between(
            &cal.attitude_q,
            &nalgebra::Matrix3::identity(),
        )
        .to_degrees(),
        file,
    })
}
