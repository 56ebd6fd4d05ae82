//! The field of a point magnetic dipole, its gradient tensor, and the
//! gradient of the field modulus.
//!
//! With `r` the vector from the dipole to the observation point, `ρ = |r|`,
//! `e = r/ρ` and moment `m` (A·m²):
//!
//! ```text
//! B(r)   = μ0/(4π ρ³) · (3 e eᵀ − I) m                                    [T]
//! G_ij   = ∂B_i/∂r_j
//!        = 3μ0/(4π ρ⁵) · [ (m·r) δ_ij + m_i r_j + r_i m_j − 5 (m·r) r_i r_j / ρ² ]   [T/m]
//! ∇|B|   = G B / |B|                                                      [T/m]
//! ```
//!
//! `G` is symmetric and traceless (the field is curl- and divergence-free
//! outside the source). Conventions of `spec/README.md`; used by every
//! subsystem (aircraft parts, rotor blades, gradiometry objects).

use crate::MU0_OVER_4PI;
use nalgebra::{Matrix3, Vector3};

/// Below this distance (m) a dipole field is treated as undefined.
pub const MIN_DISTANCE_M: f64 = 1e-9;

/// Flux density `B` (T) at displacement `r` (m, from dipole to observer) of a
/// dipole with moment `m` (A·m²). Returns zero for `|r|` below
/// [`MIN_DISTANCE_M`] (the field inside a source is not a dipole field).
pub fn dipole_field(m: &Vector3<f64>, r: &Vector3<f64>) -> Vector3<f64> {
    let rho2 = r.norm_squared();
    if rho2 < MIN_DISTANCE_M * MIN_DISTANCE_M {
        return Vector3::zeros();
    }
    let rho = rho2.sqrt();
    let k = MU0_OVER_4PI / (rho2 * rho);
    let mr = m.dot(r) / rho2;
    (r * (3.0 * mr) - m) * k
}

/// The 3×3 matrix `D(r)` with `B = D(r) m`, T per A·m². Useful when the moment
/// is itself a linear function of other quantities (induced magnetization).
pub fn dipole_matrix(r: &Vector3<f64>) -> Matrix3<f64> {
    let rho2 = r.norm_squared();
    if rho2 < MIN_DISTANCE_M * MIN_DISTANCE_M {
        return Matrix3::zeros();
    }
    let rho = rho2.sqrt();
    let k = MU0_OVER_4PI / (rho2 * rho);
    (r * r.transpose() * (3.0 / rho2) - Matrix3::identity()) * k
}

/// Gradient tensor `G_ij = ∂B_i/∂r_j` (T/m) of a dipole `m` (A·m²) at
/// displacement `r` (m). Symmetric and traceless.
pub fn dipole_gradient(m: &Vector3<f64>, r: &Vector3<f64>) -> Matrix3<f64> {
    let rho2 = r.norm_squared();
    if rho2 < MIN_DISTANCE_M * MIN_DISTANCE_M {
        return Matrix3::zeros();
    }
    let rho = rho2.sqrt();
    let k = 3.0 * MU0_OVER_4PI / (rho2 * rho2 * rho);
    let mr = m.dot(r);
    let sym = m * r.transpose() + r * m.transpose();
    (Matrix3::identity() * mr + sym - r * r.transpose() * (5.0 * mr / rho2)) * k
}

/// Gradient of the field modulus `∇|B| = G B/|B|` (T/m) for a total field
/// `b_total` (T) whose gradient tensor is `g` (T/m). Zero when `|B| = 0`.
pub fn modulus_gradient(b_total: &Vector3<f64>, g: &Matrix3<f64>) -> Vector3<f64> {
    let n = b_total.norm();
    if n == 0.0 {
        Vector3::zeros()
    } else {
        g * b_total / n
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    /// magpylib's published golden value: dipole m = (1,2,3) A·m² at
    /// (1,2,3) m, sensor at the origin.
    #[test]
    fn magpylib_golden_value() {
        let m = Vector3::new(1.0, 2.0, 3.0);
        let r = Vector3::zeros() - Vector3::new(1.0, 2.0, 3.0);
        let b = dipole_field(&m, &r);
        let expect = Vector3::new(3.81801774e-9, 7.63603548e-9, 1.14540532e-8);
        assert_relative_eq!(b, expect, max_relative = 1e-8);
        assert_relative_eq!(dipole_matrix(&r) * m, b, max_relative = 1e-14);
    }

    #[test]
    fn axial_field_is_twice_equatorial() {
        let m = Vector3::new(0.0, 0.0, 1.0);
        let axial = dipole_field(&m, &Vector3::new(0.0, 0.0, 2.0));
        let equat = dipole_field(&m, &Vector3::new(2.0, 0.0, 0.0));
        assert_relative_eq!(axial.z, -2.0 * equat.z, max_relative = 1e-14);
        assert_relative_eq!(axial.z, 2.0 * 1e-7 / 8.0, max_relative = 1e-14);
    }

    #[test]
    fn at_the_source_is_zero_not_nan() {
        let m = Vector3::new(1.0, 0.0, 0.0);
        assert_eq!(dipole_field(&m, &Vector3::zeros()), Vector3::zeros());
        assert_eq!(dipole_gradient(&m, &Vector3::zeros()), Matrix3::zeros());
    }

    fn fd_gradient(m: &Vector3<f64>, r: &Vector3<f64>) -> Matrix3<f64> {
        let h = 1e-5 * r.norm();
        let mut g = Matrix3::zeros();
        for j in 0..3 {
            let mut dr = Vector3::zeros();
            dr[j] = h;
            let d = (dipole_field(m, &(r + dr)) - dipole_field(m, &(r - dr))) / (2.0 * h);
            g.set_column(j, &d);
        }
        g
    }

    proptest! {
        #[test]
        fn gradient_matches_finite_differences(
            mx in -100.0f64..100.0, my in -100.0f64..100.0, mz in -100.0f64..100.0,
            x in 0.5f64..20.0, y in -20.0f64..20.0, z in -20.0f64..20.0) {
            let m = Vector3::new(mx, my, mz);
            let r = Vector3::new(x, y, z);
            let g = dipole_gradient(&m, &r);
            let fd = fd_gradient(&m, &r);
            let scale = g.norm().max(1e-30);
            prop_assert!((g - fd).norm() / scale < 1e-7);
            prop_assert!((g - g.transpose()).norm() <= 1e-15 * scale);
            prop_assert!(g.trace().abs() <= 1e-13 * scale);
        }

        #[test]
        fn modulus_gradient_matches_finite_differences(
            mx in -100.0f64..100.0, my in -100.0f64..100.0, mz in -100.0f64..100.0,
            x in 0.5f64..20.0, y in -20.0f64..20.0, z in -20.0f64..20.0) {
            let m = Vector3::new(mx, my, mz);
            let r = Vector3::new(x, y, z);
            let b0 = Vector3::new(2e-5, 1e-6, 4.5e-5); // uniform background field, T
            let bt = |r: &Vector3<f64>| (b0 + dipole_field(&m, r)).norm();
            let grad = modulus_gradient(&(b0 + dipole_field(&m, &r)), &dipole_gradient(&m, &r));
            let h = 1e-5 * r.norm();
            for j in 0..3 {
                let mut dr = Vector3::zeros();
                dr[j] = h;
                let fd = (bt(&(r + dr)) - bt(&(r - dr))) / (2.0 * h);
                // Truncation error plus the round-off of differencing |B| ≈ 5e-5 T.
                let roundoff = 4.0 * f64::EPSILON * bt(&r) / h;
                prop_assert!((grad[j] - fd).abs() <= 1e-6 * grad.norm() + roundoff);
            }
        }
    }
}
