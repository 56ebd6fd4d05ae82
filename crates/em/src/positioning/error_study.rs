//! Monte-Carlo study of positioning errors versus range and field noise
//! (spec `em-positioning.md`: "report how they grow with range and noise").
//!
//! For each range `L` and absolute noise `σ` (T per field component), random
//! poses at range `L` (direction uniform in the prior half-space, attitude
//! uniform on SO(3)) give `H = R Ω(r) M + N(0, σ²)`; the closed form plus LM
//! polish is compared with the truth. Since `|H| ∝ L⁻³`, a constant `σ`
//! makes the relative error grow as `L³`.

use super::{
    Hemisphere, PolishOptions, Pose, angle_between, closed_form, field_matrix, polish,
    rotation_angle_between,
};
use crate::{EmError, Result};
use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// RMS errors at one (range, noise) point.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ErrorPoint {
    /// Range, m.
    pub range_m: f64,
    /// Field noise per component, T.
    pub noise_t: f64,
    /// RMS relative range error (dimensionless).
    pub range_rms_rel: f64,
    /// RMS direction error, deg.
    pub direction_rms_deg: f64,
    /// RMS attitude error (rotation angle), deg.
    pub attitude_rms_deg: f64,
}

/// Random pose at range `range_m`: direction uniform on the half-space
/// `e · normal > 0.2`, attitude uniform on SO(3) (normalised Gaussian
/// quaternion).
fn random_pose(
    rng: &mut ChaCha8Rng,
    normal: &Normal<f64>,
    range_m: f64,
    half_space: &Vector3<f64>,
) -> Pose {
    let n = half_space.normalize();
    let e = loop {
        let v = Vector3::from_fn(|_, _| normal.sample(rng));
        let v = if v.dot(&n) < 0.0 { -v } else { v };
        let norm = v.norm();
        if norm > 1e-6 && v.dot(&n) / norm > 0.2 {
            break v / norm;
        }
    };
    let q = nalgebra::Quaternion::new(
        normal.sample(rng),
        normal.sample(rng),
        normal.sample(rng),
        normal.sample(rng),
    );
    let rotation = UnitQuaternion::from_quaternion(q)
        .to_rotation_matrix()
        .into_inner();
    Pose {
        position_m: e * range_m,
        rotation,
    }
}

/// RMS errors for every combination of `ranges_m` × `noises_t`, `trials`
/// poses each, moments `moments` (A·m²), prior half-space `half_space`,
/// seeded by `seed`.
///
/// Errors: `trials == 0`, non-positive ranges or negative noise, or a
/// singular moment matrix.
pub fn error_study(
    moments: &Matrix3<f64>,
    ranges_m: &[f64],
    noises_t: &[f64],
    trials: usize,
    half_space: &Vector3<f64>,
    seed: u64,
) -> Result<Vec<ErrorPoint>> {
    if trials == 0
        || ranges_m.iter().any(|&r| !crate::positive_finite(r))
        || noises_t.iter().any(|&s| !(s.is_finite() && s >= 0.0))
    {
        return Err(EmError::InvalidArgument {
            reason: "need trials > 0, ranges > 0 and noise ≥ 0".into(),
        });
    }
    if half_space.norm() == 0.0 {
        return Err(EmError::InvalidArgument {
            reason: "zero half-space normal".into(),
        });
    }
    let mut rng = aeromag_core::random::stream(seed, 0);
    let normal = Normal::new(0.0, 1.0).map_err(|e| EmError::InvalidArgument {
        reason: e.to_string(),
    })?;
    let mut out = Vec::with_capacity(ranges_m.len() * noises_t.len());
    for &range_m in ranges_m {
        for &noise_t in noises_t {
            let mut acc = [0.0f64; 3];
            for _ in 0..trials {
                let truth = random_pose(&mut rng, &normal, range_m, half_space);
                let h = field_matrix(&truth.position_m, &truth.rotation, moments)
                    + Matrix3::from_fn(|_, _| noise_t * normal.sample(&mut rng));
                let mut hemi = Hemisphere::new(*half_space);
                let cf = closed_form(&h, moments, &mut hemi)?;
                let p = polish(&h, moments, &cf.pose, &PolishOptions::default())?.pose;
                acc[0] += ((p.range_m() - range_m) / range_m).powi(2);
                acc[1] += angle_between(&p.position_m, &truth.position_m)
                    .to_degrees()
                    .powi(2);
                acc[2] += rotation_angle_between(&p.rotation, &truth.rotation)
                    .to_degrees()
                    .powi(2);
            }
            let [r, d, a] = acc.map(|v| (v / trials as f64).sqrt());
            out.push(ErrorPoint {
                range_m,
                noise_t,
                range_rms_rel: r,
                direction_rms_deg: d,
                attitude_rms_deg: a,
            });
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::positioning::closed_form::tests::moments;

    #[test]
    fn errors_scale_with_noise_and_range_cubed() {
        let n = Vector3::new(-1.0, 0.0, 1.0);
        let pts = error_study(&moments(), &[30.0, 60.0], &[1e-14, 1e-13], 300, &n, 9).unwrap();
        for p in &pts {
            eprintln!("{p:?}");
        }
        // [L=30 σ=1e-14, L=30 σ=1e-13, L=60 σ=1e-14, L=60 σ=1e-13]
        let ratio_noise = pts[1].range_rms_rel / pts[0].range_rms_rel;
        let ratio_range = pts[2].range_rms_rel / pts[0].range_rms_rel;
        assert!(
            (7.0..14.0).contains(&ratio_noise),
            "noise ×10 → error ×{ratio_noise}"
        );
        // Doubling the range at fixed absolute noise: ×8 expected.
        assert!(
            (5.5..11.0).contains(&ratio_range),
            "range ×2 → error ×{ratio_range}"
        );
        let ratio_att = pts[2].attitude_rms_deg / pts[0].attitude_rms_deg;
        assert!(
            (5.5..11.0).contains(&ratio_att),
            "attitude: range ×2 → error ×{ratio_att}"
        );
        assert!(error_study(&moments(), &[30.0], &[1e-14], 0, &n, 1).is_err());
        assert!(error_study(&moments(), &[-1.0], &[1e-14], 5, &n, 1).is_err());
    }
}
