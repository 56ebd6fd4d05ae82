//! The known external field at the scalar sensor rather than at the
//! navigation point.
//!
//! A main-field channel (`igrf`) is normally computed at the recorded
//! GNSS/INS position, but the scalar sensor sits at a lever arm `r_b` (body
//! frame, m) from that point — a stinger puts it ~10 m behind. During a pitch
//! manoeuvre of ±5° the sensor moves ±0.8 m vertically against the antenna,
//! and the main field's vertical gradient (≈ −3F/r ≈ 0.024 nT/m downward)
//! makes that a ±0.02 nT signal at the manoeuvre frequency: inside the
//! calibration band, correlated with the attitude, so the fit takes it for
//! interference. To first order the field at the sensor is
//!
//! ```text
//! F(p + C_nb r_b) = F(p) + ∇F · (C_nb r_b),     ∇F_j = Σ_i B_i G_ij / |B|
//! ```
//!
//! with `B` the main field (nT, NED) and `G_ij = ∂B_i/∂x_j` its gradient
//! tensor (nT/m) from IGRF at the flight's mean position ([`LeverArm`]). The
//! second-order term is below 1e-5 nT for a 10 m arm. `∇F` changes by less
//! than 0.3 % per year and 2 % per 100 km, so one value per flight serves.

use crate::error::{CompError, Result};
use aeromag_core::field::igrf::IgrfModel;
use aeromag_core::frames::{Attitude, Geodetic};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// The longest lever arm taken, m: towed birds and pods hang some tens of
/// metres from the aircraft; beyond a kilometre the numbers are not metres
/// (`--lever-arm 1e300,0,0` moved every position off the survey and left
/// "no crossovers to level").
pub const MAX_LEVER_ARM_M: f64 = 1000.0;

/// A lever arm (body frame, m) is finite and at most [`MAX_LEVER_ARM_M`]
/// long (bad input otherwise).
pub fn check_lever_arm(arm_m: [f64; 3]) -> Result<()> {
    let len = Vector3::from(arm_m).norm();
    if len <= MAX_LEVER_ARM_M {
        return Ok(());
    }
    let shown = arm_m.map(aeromag_core::error::shown).join(", ");
    // A NaN component was "longer than 1000 m".
    if arm_m.iter().any(|v| !v.is_finite()) {
        return Err(CompError::setting(format!(
            "lever arm ({shown}) m: every component must be a finite number of metres (body frame X,Y,Z)"
        )));
    }
    Err(CompError::setting(format!(
        "lever arm ({shown}) m is longer than {MAX_LEVER_ARM_M} m: no sensor is that far from the navigation point (metres expected, body frame X,Y,Z)"
    )))
}

/// Where the scalar sensor is relative to the navigation point.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LeverArm {
    /// Sensor position from the navigation point, body frame (x forward,
    /// y right, z down), m.
    pub arm_m: [f64; 3],
    /// Date of the main-field model used for the gradient, decimal year.
    pub decimal_year: f64,
}

/// Gradient of the main field's magnitude `∇F` (nT/m, NED: ∂F/∂north,
/// ∂F/∂east, ∂F/∂down) at `pos` from IGRF at `decimal_year`.
pub fn total_field_gradient_ned(pos: &Geodetic, decimal_year: f64) -> Result<[f64; 3]> {
    let model = IgrfModel::new(decimal_year)?;
    let b = model.field_geodetic(pos).ned_nt();
    let g = model.gradient_ned_nt_per_m(pos);
    let grad = g.transpose() * b / b.norm();
    if grad.iter().all(|v| v.is_finite()) {
        Ok([grad[0], grad[1], grad[2]])
    } else {
        Err(CompError::data(format!(
            "main-field gradient not finite at {pos:?}"
        )))
    }
}

/// Correction `∇F · (C_nb r_b)` (nT) to add to a main-field channel computed
/// at the navigation point so that it refers to the sensor, per sample, from
/// the attitude (deg) and the flight's positions (deg, deg, m) — their mean
/// gives the gradient. A sample with a non-finite attitude gets NaN.
pub fn lever_arm_correction_nt(
    lever: &LeverArm,
    lat_deg: &[f64],
    lon_deg: &[f64],
    alt_m: &[f64],
    roll_deg: &[f64],
    pitch_deg: &[f64],
    yaw_deg: &[f64],
) -> Result<Vec<f64>> {
    check_lever_arm(lever.arm_m)?;
    let n = roll_deg.len();
    if [
        lat_deg.len(),
        lon_deg.len(),
        alt_m.len(),
        pitch_deg.len(),
        yaw_deg.len(),
    ]
    .iter()
    .any(|&l| l != n)
    {
        return Err(CompError::data(
            "position and attitude columns of unequal length",
        ));
    }
    if lever.arm_m.iter().any(|v| !v.is_finite()) {
        return Err(CompError::data(format!(
            "lever arm {:?} m is not finite",
            lever.arm_m
        )));
    }
    let mean = |x: &[f64]| {
        let (s, k) = x
            .iter()
            .filter(|v| v.is_finite())
            .fold((0.0, 0usize), |(s, k), v| (s + v, k + 1));
        if k > 0 { Some(s / k as f64) } else { None }
    };
    let (Some(lat), Some(lon), Some(alt)) = (mean(lat_deg), mean(lon_deg), mean(alt_m)) else {
        return Err(CompError::data(
            "no finite position to evaluate the main-field gradient",
        ));
    };
    let grad = Vector3::from(total_field_gradient_ned(
        &Geodetic::new(lat, lon, alt),
        lever.decimal_year,
    )?);
    let r_b = Vector3::from(lever.arm_m);
    Ok((0..n)
        .map(|i| {
            grad.dot(
                &Attitude::from_degrees(roll_deg[i], pitch_deg[i], yaw_deg[i]).body_to_ned(&r_b),
            )
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A lever arm is finite and at most a kilometre (1e300 m moved every
    /// position off the survey); both uses refuse it.
    #[test]
    fn lever_arms_beyond_a_kilometre_or_not_finite_are_refused() {
        assert!(check_lever_arm([-9.5, 0.0, -0.6]).is_ok());
        assert!(check_lever_arm([0.0, 0.0, 1000.0]).is_ok());
        for (arm, says) in [
            ([1e300, 0.0, 0.0], "longer than 1000 m"),
            ([0.0, 600.0, 900.0], "longer than 1000 m"),
            ([f64::NAN, 0.0, 0.0], "must be a finite number"),
            ([0.0, f64::INFINITY, 0.0], "must be a finite number"),
        ] {
            let e = check_lever_arm(arm).unwrap_err();
            assert!(
                e.is_bad_input()
                    && e.to_string().contains("lever arm")
                    && e.to_string().contains(says),
                "{e}"
            );
        }
        let lever = LeverArm {
            arm_m: [5000.0, 0.0, 0.0],
            decimal_year: 2025.0,
        };
        let one = [0.0];
        assert!(
            lever_arm_correction_nt(&lever, &[56.0], &[38.0], &[300.0], &one, &one, &one).is_err()
        );
        let pos = crate::levelling::sensor_positions(
            &[56.0],
            &[38.0],
            &[300.0],
            &one,
            &one,
            &one,
            lever.arm_m,
        );
        assert!(pos.is_err());
    }

    /// ∇F against a finite difference of F itself, and the size of the
    /// vertical gradient against the dipole estimate 3F/r.
    #[test]
    fn gradient_matches_finite_differences_of_the_magnitude() {
        let pos = Geodetic::new(45.3, -75.7, 3000.0);
        let year = 2025.5;
        let g = total_field_gradient_ned(&pos, year).unwrap();
        let m = IgrfModel::new(year).unwrap();
        let f = |p: &Geodetic| m.field_geodetic(p).f_nt();
        let h = 50.0;
        let fd = [
            (f(&pos.offset_by(h, 0.0, pos.alt_m)) - f(&pos.offset_by(-h, 0.0, pos.alt_m)))
                / (2.0 * h),
            (f(&pos.offset_by(0.0, h, pos.alt_m)) - f(&pos.offset_by(0.0, -h, pos.alt_m)))
                / (2.0 * h),
            (f(&Geodetic::new(pos.lat_deg, pos.lon_deg, pos.alt_m - h))
                - f(&Geodetic::new(pos.lat_deg, pos.lon_deg, pos.alt_m + h)))
                / (2.0 * h),
        ];
        for k in 0..3 {
            assert!(
                (g[k] - fd[k]).abs() < 2e-6,
                "component {k}: {} vs {}",
                g[k],
                fd[k]
            );
        }
        let dipole = 3.0 * f(&pos) / (6_371_000.0 + pos.alt_m);
        assert!(
            g[2] > 0.0 && (g[2] / dipole - 1.0).abs() < 0.15,
            "∂F/∂down {} vs 3F/r {dipole}",
            g[2]
        );
    }

    /// Level flight: the arm's vertical part only; a 10° nose-up pitch moves
    /// a tail sensor (x = −9.5 m) down by 9.5 sin 10°.
    #[test]
    fn correction_follows_the_attitude() {
        let lever = LeverArm {
            arm_m: [-9.5, 0.0, 0.0],
            decimal_year: 2025.0,
        };
        let (lat, lon, alt) = (vec![45.0; 3], vec![-75.0; 3], vec![3000.0; 3]);
        let c = lever_arm_correction_nt(
            &lever,
            &lat,
            &lon,
            &alt,
            &[0.0; 3],
            &[0.0, 10.0, f64::NAN],
            &[90.0; 3],
        )
        .unwrap();
        let g = total_field_gradient_ned(&Geodetic::new(45.0, -75.0, 3000.0), 2025.0).unwrap();
        // Heading east: the tail points west.
        assert!((c[0] + g[1] * 9.5).abs() < 1e-12);
        let down = 9.5 * 10f64.to_radians().sin();
        let west = -9.5 * 10f64.to_radians().cos();
        assert!((c[1] - (g[2] * down + g[1] * west)).abs() < 1e-12);
        assert!(c[2].is_nan());
        assert!(
            lever_arm_correction_nt(
                &LeverArm {
                    arm_m: [f64::NAN, 0.0, 0.0],
                    ..lever
                },
                &lat,
                &lon,
                &alt,
                &[0.0; 3],
                &[0.0; 3],
                &[0.0; 3]
            )
            .is_err()
        );
        assert!(
            lever_arm_correction_nt(&lever, &[f64::NAN], &[1.0], &[1.0], &[0.0], &[0.0], &[0.0])
                .is_err()
        );
    }
}
