//! Orthonormal decorrelating transform of the exact sensor differences
//! (seed `004_…`, eqs. 13–16 and 28; spec `gradiometry.md`, "Noise
//! decorrelation").
//!
//! The differences against common sensors, e.g. `(z_12, z_23, z_24)` with
//! `z_ij = b_i − b_j`, carry correlated noise (block covariance with
//! `2σ²` on the diagonal, `±σ²` off it). The seed replaces them by three
//! orthonormal contrasts of the four readings `b_1 … b_4`:
//!
//! ```text
//! c_1 = (b_1 + b_2 + b_3 − 3 b_4) / √12
//! c_2 = (b_2 − b_3)               / √2
//! c_3 = (b_2 + b_3 − 2 b_1)       / √6
//! ```
//!
//! The rows of `T` are orthonormal and orthogonal to `(1,1,1,1)`, so with
//! independent sensor noise of variance `σ²` the contrasts have covariance
//! `σ² I` (white, one scalar update each) and any disturbance common to the
//! four sensors (natural variations, a uniform background) cancels exactly.
//! Because the contrasts are linear combinations of the differences, they
//! carry exactly the information of the 3 independent differences:
//! `c = A z` with `A = T Dᵀ (D Dᵀ)⁻¹`, `D` the difference operator.

use nalgebra::{Matrix3, SMatrix, Vector3};

/// The 3×4 contrast matrix `T` (dimensionless, orthonormal rows).
pub fn contrast_matrix() -> SMatrix<f64, 3, 4> {
    let a = 1.0 / 12f64.sqrt();
    let b = 1.0 / 2f64.sqrt();
    let c = 1.0 / 6f64.sqrt();
    SMatrix::<f64, 3, 4>::new(
        a,
        a,
        a,
        -3.0 * a, //
        0.0,
        b,
        -b,
        0.0, //
        -2.0 * c,
        c,
        c,
        0.0,
    )
}

/// The 3×4 difference operator of the seed's independent differences
/// `(z_12, z_23, z_24)` (eq. 8 per axis, eq. 23 uses `(z_12, z_13, z_14)`,
/// which carries the same information).
pub fn difference_matrix() -> SMatrix<f64, 3, 4> {
    SMatrix::<f64, 3, 4>::new(
        1.0, -1.0, 0.0, 0.0, //
        0.0, 1.0, -1.0, 0.0, //
        0.0, 1.0, 0.0, -1.0,
    )
}

/// `A` with `c = A z`: maps the differences `(z_12, z_23, z_24)` of one
/// axis (or of the moduli) to the white contrasts.
pub fn differences_to_contrasts() -> Matrix3<f64> {
    let t = contrast_matrix();
    let d = difference_matrix();
    let ddt = d * d.transpose();
    // D Dᵀ = [[2,-1,-1],[-1,2,1],[-1,1,2]] is positive definite (det 4).
    let inv = ddt.try_inverse().unwrap_or_else(Matrix3::zeros);
    t * d.transpose() * inv
}

/// Contrasts of four scalar readings (same unit as the readings).
pub fn contrasts_scalar(b: &[f64; 4]) -> Vector3<f64> {
    contrast_matrix() * nalgebra::Vector4::from_column_slice(b)
}

/// Contrasts of four vector readings: `c[j][k] = Σ_i T_ji b_i[k]`, returned
/// as a 9-vector in the order `3 j + k` (contrast j, axis k).
pub fn contrasts_vector(b: &[Vector3<f64>; 4]) -> SMatrix<f64, 9, 1> {
    let t = contrast_matrix();
    let mut out = SMatrix::<f64, 9, 1>::zeros();
    for j in 0..3 {
        for (i, bi) in b.iter().enumerate() {
            for k in 0..3 {
                out[3 * j + k] += t[(j, i)] * bi[k];
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn contrasts_are_orthonormal_and_blind_to_common_mode() {
        let t = contrast_matrix();
        assert!((t * t.transpose() - Matrix3::identity()).norm() < 1e-15);
        let ones = nalgebra::Vector4::repeat(1.0);
        assert!((t * ones).norm() < 1e-15);
    }

    #[test]
    fn transform_whitens_the_difference_covariance() {
        let d = difference_matrix();
        let sigma2 = 2.5;
        let r = d * d.transpose() * sigma2; // covariance of the differences
        let a = differences_to_contrasts();
        let w = a * r * a.transpose() / sigma2;
        assert!((w - Matrix3::identity()).norm() < 1e-14, "{w}");
        // and A D = T: the contrasts are exactly those of the readings.
        assert!((a * d - contrast_matrix()).norm() < 1e-14);
        // the seed's block (13) for differences against a common sensor
        let common = SMatrix::<f64, 3, 4>::new(
            1.0, -1.0, 0.0, 0.0, 1.0, 0.0, -1.0, 0.0, 1.0, 0.0, 0.0, -1.0,
        );
        let r13 = common * common.transpose();
        assert_eq!(
            r13,
            Matrix3::new(2.0, 1.0, 1.0, 1.0, 2.0, 1.0, 1.0, 1.0, 2.0)
        );
    }
}
