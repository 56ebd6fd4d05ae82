//! Closed-form range, direction and attitude from one field matrix (seed
//! `001_…` part I; spec `em-positioning.md`, "Base algorithm").
//!
//! With `W = M⁻ᵀ HᵀH M⁻¹ = Ω²` ([`super::gram`]) and `Ω = K (3 e eᵀ − I)`,
//! `K = μ0/(4π L³)`:
//!
//! ```text
//! eig(W) = {4K², K², K²}           (e is the eigenvector of 4K²)
//! K²     = (4 λ1 + λ2 + λ3)/18     (least-squares fit of (4,1,1)K² to λ1 ≥ λ2 ≥ λ3)
//! L      = (μ0/(4π K))^{1/3}
//! R      = proj_SO(3)( H (Ω M)⁻¹ )
//! ```
//!
//! `Ω(e) = Ω(−e)`, so `R` is unambiguous and only the sign of `e` comes from
//! the [`Hemisphere`] prior.

use super::{Hemisphere, Pose, project_to_so3, whitened_gram};
use crate::{EmError, Result};
use aeromag_core::MU0_OVER_4PI;
use nalgebra::{Matrix3, Vector3};

/// Closed-form solution with its quality figures.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ClosedForm {
    /// Position and attitude.
    pub pose: Pose,
    /// Eigenvalues of `W`, descending, T²/(A·m²)².
    pub eigenvalues: [f64; 3],
    /// `λ1 / ((λ2 + λ3)/2)`; 4 for a pure dipole field (dimensionless).
    pub eigen_ratio: f64,
    /// `|λ2 − λ3| / (λ2 + λ3)`; 0 for a pure dipole field (dimensionless).
    pub eigen_split: f64,
    /// `‖AᵀA − I‖_F` of the unprojected `A = H (Ω M)⁻¹`; 0 without noise.
    pub orthogonality_defect: f64,
}

/// Closed-form pose from the field matrix `h` (T; columns = dipoles, receiver
/// axes) and the moments `moments` (A·m², columns = dipoles). The sign of the
/// direction is resolved (and remembered) by `hemisphere`.
///
/// Errors: [`EmError::InvalidData`] for non-finite or zero fields,
/// [`EmError::Singular`] for a singular moment matrix.
pub fn closed_form(
    h: &Matrix3<f64>,
    moments: &Matrix3<f64>,
    hemisphere: &mut Hemisphere,
) -> Result<ClosedForm> {
    if h.iter().any(|v| !v.is_finite()) {
        return Err(EmError::InvalidData {
            reason: "non-finite field matrix".into(),
        });
    }
    let w = whitened_gram(h, moments)?;
    let eig = w.symmetric_eigen();
    let mut idx = [0usize, 1, 2];
    idx.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
    let lam = [
        eig.eigenvalues[idx[0]],
        eig.eigenvalues[idx[1]],
        eig.eigenvalues[idx[2]],
    ];
    let k2 = (4.0 * lam[0] + lam[1] + lam[2]) / 18.0;
    if !crate::positive_finite(k2) {
        return Err(EmError::InvalidData {
            reason: "zero field: range undefined".into(),
        });
    }
    let k = k2.sqrt();
    let range = (MU0_OVER_4PI / k).cbrt();
    let e0: Vector3<f64> = eig.eigenvectors.column(idx[0]).into_owned().normalize();
    let e = hemisphere.resolve(&e0);
    let omega = (e * e.transpose() * 3.0 - Matrix3::identity()) * k;
    let om_inv = (omega * moments)
        .try_inverse()
        .ok_or_else(|| EmError::Singular {
            what: "Ω M".into()
        })?;
    let a = h * om_inv;
    let rotation = project_to_so3(&a)?;
    let lower = lam[1] + lam[2];
    Ok(ClosedForm {
        pose: Pose {
            position_m: e * range,
            rotation,
        },
        eigenvalues: lam,
        eigen_ratio: if lower > 0.0 {
            2.0 * lam[0] / lower
        } else {
            f64::INFINITY
        },
        eigen_split: if lower > 0.0 {
            (lam[1] - lam[2]).abs() / lower
        } else {
            f64::INFINITY
        },
        orthogonality_defect: (a.transpose() * a - Matrix3::identity()).norm(),
    })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::positioning::{angle_between, field_matrix, rotation_angle_between};
    use nalgebra::Rotation3;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// A non-orthogonal, realistic moment matrix (A·m²).
    pub(crate) fn moments() -> Matrix3<f64> {
        Matrix3::new(
            2.0e4, 1.5e3, -0.8e3, 0.5e3, 1.8e4, 1.2e3, -1.0e3, 0.7e3, 2.2e4,
        )
    }

    /// Random towed-bird pose: behind (−x) and below (+z), 30–100 m.
    pub(crate) fn random_pose(rng: &mut ChaCha8Rng) -> Pose {
        let range = rng.random_range(30.0..100.0);
        let az: f64 = rng.random_range(-0.6..0.6);
        let dep: f64 = rng.random_range(0.2..1.2);
        let e = Vector3::new(-dep.cos() * az.cos(), dep.cos() * az.sin(), dep.sin());
        let rot = Rotation3::from_euler_angles(
            rng.random_range(-3.1..3.1),
            rng.random_range(-1.5..1.5),
            rng.random_range(-3.1..3.1),
        );
        Pose {
            position_m: e * range,
            rotation: rot.into_inner(),
        }
    }

    #[test]
    fn exact_recovery_noise_free() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let m = moments();
        let mut worst = (0.0f64, 0.0f64, 0.0f64);
        for _ in 0..500 {
            let truth = random_pose(&mut rng);
            let h = field_matrix(&truth.position_m, &truth.rotation, &m);
            let mut hemi = Hemisphere::new(Vector3::new(-1.0, 0.0, 1.0));
            let sol = closed_form(&h, &m, &mut hemi).unwrap();
            let dr = (sol.pose.range_m() - truth.range_m()).abs() / truth.range_m();
            let da = angle_between(&sol.pose.position_m, &truth.position_m);
            let dq = rotation_angle_between(&sol.pose.rotation, &truth.rotation);
            worst = (worst.0.max(dr), worst.1.max(da), worst.2.max(dq));
            assert!((sol.eigen_ratio - 4.0).abs() < 1e-9);
            assert!(sol.eigen_split < 1e-6);
            assert!(sol.orthogonality_defect < 1e-9);
        }
        assert!(worst.0 < 1e-11, "relative range error {}", worst.0);
        assert!(worst.1 < 1e-7, "direction error {} rad", worst.1);
        assert!(worst.2 < 1e-7, "attitude error {} rad", worst.2);
    }

    #[test]
    fn bad_input_errors() {
        let mut hemi = Hemisphere::new(Vector3::new(-1.0, 0.0, 1.0));
        let m = moments();
        assert!(closed_form(&Matrix3::zeros(), &m, &mut hemi).is_err());
        assert!(closed_form(&Matrix3::from_element(f64::NAN), &m, &mut hemi).is_err());
    }
}
