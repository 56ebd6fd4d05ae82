//! Levenberg–Marquardt polish of a pose on the full model (spec
//! `em-positioning.md`: "Polish with a few Gauss–Newton/LM steps on the full
//! model with all measured vectors").
//!
//! Unknowns `p = (r, φ)`: position `r` (m) and a rotation vector `φ` (rad)
//! perturbing the starting rotation, `R(φ) = exp([φ]×) R₀`. Residuals (nine,
//! dimensionless)
//!
//! ```text
//! ε(p) = vec( H_meas − R(φ) Ω(r) M ) / ‖H_meas‖_F
//! ```
//!
//! Step: `(JᵀJ + μ diag(JᵀJ)) δ = −Jᵀε`, `μ` divided by 3 on success and
//! multiplied by 4 on failure; `J` by central differences.

use super::{Pose, field_matrix};
use crate::{EmError, Result};
use nalgebra::{Matrix3, Rotation3, SMatrix, SVector, Vector3};

type Vec6 = SVector<f64, 6>;
type Vec9 = SVector<f64, 9>;

/// Options of the LM polish.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PolishOptions {
    /// Maximum number of accepted or rejected steps.
    pub max_iterations: usize,
    /// Stop when the step in position is below this fraction of the range
    /// and the rotation step below this many radians.
    pub tolerance: f64,
}

impl Default for PolishOptions {
    fn default() -> Self {
        Self {
            max_iterations: 20,
            tolerance: 1e-10,
        }
    }
}

/// Polished pose and its fit quality.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Polished {
    /// The refined pose.
    pub pose: Pose,
    /// RMS of the nine relative residuals `ε` at the solution.
    pub rms_residual: f64,
    /// Number of LM iterations taken.
    pub iterations: usize,
}

fn residual(h: &Matrix3<f64>, scale: f64, moments: &Matrix3<f64>, base: &Pose, p: &Vec6) -> Vec9 {
    let r = Vector3::new(p[0], p[1], p[2]);
    let rot = Rotation3::new(Vector3::new(p[3], p[4], p[5])).into_inner() * base.rotation;
    let d = (h - field_matrix(&r, &rot, moments)) / scale;
    Vec9::from_iterator(d.iter().copied())
}

/// Refine `start` against the measured field matrix `h` (T) with moments
/// `moments` (A·m²).
///
/// Errors with [`EmError::InvalidData`] for a zero or non-finite `h`.
pub fn polish(
    h: &Matrix3<f64>,
    moments: &Matrix3<f64>,
    start: &Pose,
    options: &PolishOptions,
) -> Result<Polished> {
    let scale = h.norm();
    if !crate::positive_finite(scale) {
        return Err(EmError::InvalidData {
            reason: "zero or non-finite field matrix".into(),
        });
    }
    let mut base = *start;
    let mut p = Vec6::new(
        base.position_m[0],
        base.position_m[1],
        base.position_m[2],
        0.0,
        0.0,
        0.0,
    );
    let mut eps = residual(h, scale, moments, &base, &p);
    let mut cost = eps.norm_squared();
    let mut mu = 1e-3;
    let mut iterations = 0;
    while iterations < options.max_iterations {
        iterations += 1;
        let range = Vector3::new(p[0], p[1], p[2]).norm().max(1e-3);
        let mut jac = SMatrix::<f64, 9, 6>::zeros();
        for k in 0..6 {
            let step = if k < 3 { 1e-6 * range } else { 1e-7 };
            let mut pp = p;
            let mut pm = p;
            pp[k] += step;
            pm[k] -= step;
            let col = (residual(h, scale, moments, &base, &pp)
                - residual(h, scale, moments, &base, &pm))
                / (2.0 * step);
            jac.set_column(k, &col);
        }
        let jtj = jac.transpose() * jac;
        let g = jac.transpose() * eps;
        let mut a = jtj;
        for k in 0..6 {
            a[(k, k)] += mu * jtj[(k, k)].max(1e-30);
        }
        let Some(delta) = a.cholesky().map(|c| c.solve(&(-g))) else {
            mu *= 4.0;
            continue;
        };
        let trial = p + delta;
        let eps_t = residual(h, scale, moments, &base, &trial);
        let cost_t = eps_t.norm_squared();
        if cost_t < cost {
            p = trial;
            eps = eps_t;
            cost = cost_t;
            mu = (mu / 3.0).max(1e-12);
            // Fold the rotation increment into the base rotation.
            base.rotation =
                Rotation3::new(Vector3::new(p[3], p[4], p[5])).into_inner() * base.rotation;
            p[3] = 0.0;
            p[4] = 0.0;
            p[5] = 0.0;
            let dpos = Vector3::new(delta[0], delta[1], delta[2]).norm() / range;
            let drot = Vector3::new(delta[3], delta[4], delta[5]).norm();
            if dpos < options.tolerance && drot < options.tolerance {
                break;
            }
        } else {
            mu *= 4.0;
            if mu > 1e12 {
                break;
            }
        }
    }
    base.position_m = Vector3::new(p[0], p[1], p[2]);
    Ok(Polished {
        pose: base,
        rms_residual: (cost / 9.0).sqrt(),
        iterations,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::positioning::closed_form::tests::{moments, random_pose};
    use crate::positioning::{Hemisphere, angle_between, closed_form, rotation_angle_between};
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, Normal};

    /// RMS (relative range, direction rad, attitude rad) errors of
    /// (closed form, polished) for relative component noise `sigma` at
    /// ranges drawn by `random_pose`.
    fn errors(sigma: f64, n: usize, seed: u64) -> ([f64; 3], [f64; 3]) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let normal = Normal::new(0.0, 1.0).unwrap();
        let m = moments();
        let mut cf = [0.0; 3];
        let mut po = [0.0; 3];
        for _ in 0..n {
            let truth = random_pose(&mut rng);
            let h0 = field_matrix(&truth.position_m, &truth.rotation, &m);
            let s = sigma * h0.norm() / 3.0;
            let h = h0 + Matrix3::from_fn(|_, _| s * normal.sample(&mut rng));
            let mut hemi = Hemisphere::new(Vector3::new(-1.0, 0.0, 1.0));
            let c = closed_form(&h, &m, &mut hemi).unwrap();
            let p = polish(&h, &m, &c.pose, &PolishOptions::default()).unwrap();
            for (acc, pose) in [(&mut cf, &c.pose), (&mut po, &p.pose)] {
                acc[0] += ((pose.range_m() - truth.range_m()) / truth.range_m()).powi(2);
                acc[1] += angle_between(&pose.position_m, &truth.position_m).powi(2);
                acc[2] += rotation_angle_between(&pose.rotation, &truth.rotation).powi(2);
            }
        }
        let f = |a: [f64; 3]| a.map(|v| (v / n as f64).sqrt());
        (f(cf), f(po))
    }

    #[test]
    fn noise_free_polish_stays_exact() {
        let (cf, po) = errors(0.0, 50, 3);
        for v in cf.iter().chain(po.iter()) {
            assert!(*v < 1e-8, "{cf:?} {po:?}");
        }
    }

    #[test]
    fn error_grows_linearly_with_noise_and_polish_helps() {
        let (cf1, po1) = errors(1e-4, 400, 7);
        let (cf2, po2) = errors(1e-3, 400, 7);
        eprintln!("sigma 1e-4: closed {cf1:?} polished {po1:?}");
        eprintln!("sigma 1e-3: closed {cf2:?} polished {po2:?}");
        for k in 0..3 {
            let ratio = po2[k] / po1[k];
            assert!((7.0..14.0).contains(&ratio), "component {k}: ratio {ratio}");
            // Polish (ML on all nine components) is not worse than closed form.
            assert!(
                po2[k] <= cf2[k] * 1.02,
                "component {k}: {} vs {}",
                po2[k],
                cf2[k]
            );
        }
        // At 1e-4 relative field noise the spec's figures (0.1 % of range,
        // 0.1° = 1.75e-3 rad) are met with a wide margin.
        assert!(
            po1[0] < 1e-3 && po1[1] < 1.75e-3 && po1[2] < 1.75e-3,
            "{po1:?}"
        );
    }

    #[test]
    fn zero_field_errors() {
        let m = moments();
        let p = Pose {
            position_m: Vector3::new(-50.0, 0.0, 20.0),
            rotation: Matrix3::identity(),
        };
        assert!(polish(&Matrix3::zeros(), &m, &p, &PolishOptions::default()).is_err());
    }
}
