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

/// The rotation from a rotor's hub frame to body axes, as columns
/// `[x_h y_h z_h]`: `z_h` along `spin_axis` (the direction of the rotor's
/// angular velocity, so `ω = (0, 0, Ω)` in the hub frame), `x_h` the part of
/// `zero_azimuth` (the body direction of a blade at azimuth 0) orthogonal
/// to it, `y_h = z_h × x_h`. The main rotor of the body frame (x forward,
/// z down, turning clockwise seen from above) has `spin_axis = (0, 0, 1)`,
/// `zero_azimuth = (1, 0, 0)` and the identity. `None` when either vector
/// is zero or not finite, or they are parallel.
pub fn body_from_hub(spin_axis: [f64; 3], zero_azimuth: [f64; 3]) -> Option<Matrix3<f64>> {
    let z = Vector3::from(spin_axis);
    let x = Vector3::from(zero_azimuth);
    let (nz, nx) = (z.norm(), x.norm());
    if !(nz.is_finite() && nx.is_finite() && nz > 0.0 && nx > 0.0) {
        return None;
    }
    let z = z / nz;
    let x = x / nx - z * z.dot(&(x / nx));
    let n = x.norm();
    if n.is_nan() || n <= 1e-6 {
        return None;
    }
    let x = x / n;
    Some(Matrix3::from_columns(&[x, z.cross(&x), z]))
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

    #[test]
    fn hub_frame_is_a_rotation_and_the_main_rotor_is_the_identity() {
        assert_eq!(
            body_from_hub([0.0, 0.0, 1.0], [1.0, 0.0, 0.0]),
            Some(Matrix3::identity())
        );
        let c = body_from_hub([0.0, 2.0, 0.0], [0.3, 0.1, -1.0]).unwrap();
        assert!((c * c.transpose() - Matrix3::identity()).norm() < 1e-14);
        assert!((c.determinant() - 1.0).abs() < 1e-14);
        assert!((c.column(2) - Vector3::new(0.0, 1.0, 0.0)).norm() < 1e-15);
        assert!(body_from_hub([0.0, 1.0, 0.0], [0.0, -3.0, 0.0]).is_none());
        assert!(body_from_hub([0.0, 0.0, 0.0], [1.0, 0.0, 0.0]).is_none());
        assert!(body_from_hub([f64::NAN, 0.0, 1.0], [1.0, 0.0, 0.0]).is_none());
    }
}
