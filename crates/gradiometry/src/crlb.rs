//! Cramér–Rao lower bound of the dipole parameters and Monte-Carlo
//! efficiency (spec `gradiometry.md`, "Accuracy against the physical
//! limit").
//!
//! The white contrasts of epoch `j` are `z_j = h_j(x_j) + v_j`,
//! `v_j ~ N(0, σ² I)`, and the state moves deterministically,
//! `x_j = F_j x_{j−1} + u_j` (known motion, no process noise). The Fisher
//! information about the final state accumulates as
//!
//! ```text
//! J_0 = H_0ᵀ H_0 / σ²,   J_j = F_j⁻ᵀ J_{j−1} F_j⁻¹ + H_jᵀ H_j / σ²,
//! ```
//!
//! `H_j` the analytic Jacobian at the true state; `CRLB = J⁻¹`. The
//! efficiency of an estimator is `RMS / CRLB`, for a block of components
//! `√(mean ‖x̂_b − x_b‖²) / √(trace CRLB_bb)` (1 = efficient).

use crate::error::{GradiometryError, Result, positive};
use crate::forward::Forward;
use nalgebra::{SMatrix, SVector};

/// Fisher information and its inverse (the CRLB) at the last epoch for
/// models `models[j]` at true states `truth[j]` with transitions
/// `transitions[j]` into epoch `j` (the first is ignored); noise σ (nT).
pub fn crlb<const N: usize, const Z: usize, F: Forward<N, Z>>(
    models: &[F],
    truth: &[SVector<f64, N>],
    transitions: &[SMatrix<f64, N, N>],
    sigma_nt: f64,
) -> Result<SMatrix<f64, N, N>> {
    positive("sigma_nt", sigma_nt)?;
    if truth.len() != models.len() || transitions.len() != models.len() {
        return Err(GradiometryError::LengthMismatch {
            what: "truth/transitions",
            got: truth.len(),
            expected: models.len(),
        });
    }
    let mut j = SMatrix::<f64, N, N>::zeros();
    for (k, (m, x)) in models.iter().zip(truth).enumerate() {
        if k > 0 {
            let finv = transitions[k]
                .try_inverse()
                .ok_or(GradiometryError::Singular("transition"))?;
            j = finv.transpose() * j * finv;
        }
        let (_, h) = m.eval(x);
        j += h.transpose() * h / (sigma_nt * sigma_nt);
    }
    let j = (j + j.transpose()) * 0.5;
    j.cholesky()
        .map(|c| c.inverse())
        .ok_or(GradiometryError::Singular("Fisher information"))
}

/// `RMS / √trace(CRLB_bb)` over components `start..start+len` of the
/// errors `errors` (estimate − truth).
pub fn efficiency<const N: usize>(
    errors: &[SVector<f64, N>],
    crlb: &SMatrix<f64, N, N>,
    start: usize,
    len: usize,
) -> Result<f64> {
    if errors.is_empty() || start + len > N || len == 0 {
        return Err(GradiometryError::LengthMismatch {
            what: "errors/block",
            got: errors.len(),
            expected: N,
        });
    }
    let ms = errors
        .iter()
        .map(|e| e.rows(start, len).norm_squared())
        .sum::<f64>()
        / errors.len() as f64;
    let bound: f64 = (start..start + len).map(|i| crlb[(i, i)]).sum();
    Ok((ms / bound).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::forward::{Background, TensorForward};
    use crate::geometry::{Geometry, Layout};
    use crate::motion::{Motion, MotionNoise, motion_mt};
    use nalgebra::Vector3;

    fn model() -> TensorForward {
        TensorForward {
            geometry: Geometry::new(Layout::Tetrahedron, 1.0).unwrap(),
            background: Background::zero(),
        }
    }

    #[test]
    fn two_epoch_bound_equals_the_batch_information_mapped_to_the_last_epoch() {
        let f = model();
        let x0 = SVector::<f64, 6>::from([6.0, 2.0, 1.0, 300.0, -200.0, 100.0]);
        let m = Motion {
            v_object: Vector3::new(2.0, 0.0, 0.0),
            v_system: Vector3::zeros(),
            w_object: Vector3::zeros(),
            w_system: Vector3::new(0.0, 0.0, 0.05),
            dt_s: 1.0,
        };
        let noise = MotionNoise {
            position_m_per_sqrt_s: 0.0,
            moment_am2_per_sqrt_s: 0.0,
            induced_per_rad: 0.0,
        };
        let (phi, u, _) = motion_mt(&m, &noise, &Vector3::zeros());
        let x1 = phi * x0 + u;
        let sigma = 0.7;
        let c = crlb(&[f, f], &[x0, x1], &[SMatrix::identity(), phi], sigma).unwrap();
        // Batch: information about x0 from both epochs, x1 = Φ x0 + u.
        let (_, h0) = f.eval(&x0);
        let (_, h1) = f.eval(&x1);
        let h1p = h1 * phi;
        let j0 = (h0.transpose() * h0 + h1p.transpose() * h1p) / (sigma * sigma);
        let expected = phi * j0.try_inverse().unwrap() * phi.transpose();
        let rel = (c - expected).norm() / expected.norm();
        assert!(rel < 1e-8, "{rel:e}");
    }

    #[test]
    fn single_epoch_bound_scales_with_the_noise_variance_and_errors_are_reported() {
        let f = model();
        let x = SVector::<f64, 6>::from([4.0, -1.0, 2.0, 100.0, 50.0, -80.0]);
        let i = SMatrix::<f64, 6, 6>::identity();
        let c1 = crlb(&[f], &[x], &[i], 1.0).unwrap();
        let c2 = crlb(&[f], &[x], &[i], 2.0).unwrap();
        assert!((c2 - c1 * 4.0).norm() < 1e-9 * c2.norm());
        assert!(crlb(&[f], &[x], &[i], 0.0).is_err());
        assert!(crlb(&[f, f], &[x], &[i, i], 1.0).is_err());
        // A zero moment hides the position: singular information.
        let x0 = SVector::<f64, 6>::from([4.0, -1.0, 2.0, 0.0, 0.0, 0.0]);
        assert!(crlb(&[f], &[x0], &[i], 1.0).is_err());
        // efficiency of errors equal to ±√CRLB per component is 1
        let e: Vec<_> = [1.0, -1.0]
            .iter()
            .map(|s| c1.diagonal().map(f64::sqrt) * *s)
            .collect();
        assert!((efficiency(&e, &c1, 0, 3).unwrap() - 1.0).abs() < 1e-12);
        assert!(efficiency(&e, &c1, 4, 3).is_err());
    }
}
