//! Projection of a 3×3 matrix onto the rotation group SO(3) (seed `001_…`
//! part I: the attitude `R = H (Ω M)⁻¹` is orthogonal only without noise).
//!
//! With the SVD `A = U Σ Vᵀ`, the nearest rotation in the Frobenius norm is
//! `R = U diag(1, 1, det(U Vᵀ)) Vᵀ` (orthogonal Procrustes with the
//! determinant constraint).

use crate::{EmError, Result};
use nalgebra::Matrix3;

/// Nearest proper rotation to `a` in the Frobenius norm.
///
/// Errors with [`EmError::InvalidData`] for non-finite input or a failed SVD.
pub fn project_to_so3(a: &Matrix3<f64>) -> Result<Matrix3<f64>> {
    if a.iter().any(|v| !v.is_finite()) {
        return Err(EmError::InvalidData {
            reason: "non-finite matrix to project onto SO(3)".into(),
        });
    }
    let svd = a.svd(true, true);
    let (u, vt) = match (svd.u, svd.v_t) {
        (Some(u), Some(vt)) => (u, vt),
        _ => {
            return Err(EmError::InvalidData {
                reason: "SVD failed".into(),
            });
        }
    };
    let d = (u * vt).determinant().signum();
    let s = Matrix3::from_diagonal(&nalgebra::Vector3::new(1.0, 1.0, d));
    Ok(u * s * vt)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Rotation3;

    #[test]
    fn rotation_is_fixed_point_and_perturbation_is_removed() {
        let r = Rotation3::from_euler_angles(0.3, -1.1, 2.0).into_inner();
        assert!((project_to_so3(&r).unwrap() - r).norm() < 1e-14);
        // A symmetric perturbation (not a rotation) is removed to first order.
        let s = Matrix3::new(0.0, 1e-3, 2e-3, 1e-3, 3e-3, 0.0, 2e-3, 0.0, -1e-3);
        let p = project_to_so3(&(r * (Matrix3::identity() + s))).unwrap();
        assert!((p - r).norm() < 1e-5, "{}", (p - r).norm());
        assert!((p.determinant() - 1.0).abs() < 1e-12);
        // A reflection is mapped to a proper rotation.
        let refl = r * Matrix3::from_diagonal(&nalgebra::Vector3::new(1.0, 1.0, -1.0));
        assert!((project_to_so3(&refl).unwrap().determinant() - 1.0).abs() < 1e-12);
        assert!(project_to_so3(&Matrix3::from_element(f64::NAN)).is_err());
    }
}
