//! Axes of a rotating, flapping rotor blade (helicopter main rotor).
//!
//! In the hub frame (x forward, y right, z down, as the body frame), a blade
//! at azimuth `ψ` (from the x axis towards y) flapped up by `β` points along
//! `r_p = (cos β cos ψ, cos β sin ψ, −sin β)`; `e_l = (−sin ψ, cos ψ, 0)` is
//! the lead direction and `e_u = e_l × r_p` points up out of the rotor disc
//! (`−z` for an unflapped blade); the columns `[r_p e_l e_u]` are
//! orthonormal and, in this order, left-handed (determinant −1).
//! Seed `000_…` §15 (the unit blade vector `r_p` of the rotor model).

use nalgebra::{Matrix3, Vector3};

/// Blade axes `[r_p e_l e_u]` (columns) at azimuth `psi_rad` and flap angle
/// `beta_rad` (both rad). Orthonormal, determinant −1 (module docs).
pub fn blade_axes(psi_rad: f64, beta_rad: f64) -> Matrix3<f64> {
    let (sp, cp) = psi_rad.sin_cos();
    let (sb, cb) = beta_rad.sin_cos();
    let r = Vector3::new(cb * cp, cb * sp, -sb);
    let l = Vector3::new(-sp, cp, 0.0);
    let u = l.cross(&r);
    Matrix3::from_columns(&[r, l, u])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axes_are_a_rotation_and_flap_lifts_the_tip() {
        let a = blade_axes(0.7, 0.05);
        assert!((a * a.transpose() - Matrix3::identity()).norm() < 1e-14);
        assert!((a.determinant() + 1.0).abs() < 1e-14);
        assert!(
            blade_axes(0.0, 0.0).column(2)[2] < -0.99,
            "e_u is up (−z) for a level blade"
        );
        assert!(a[(2, 0)] < 0.0, "a positive flap points the blade up (−z)");
    }
}
