//! The Gram matrix of the measured field vectors and its whitened form
//! (seed `001_…` part I; spec `em-positioning.md`, "Base algorithm").
//!
//! `G = HᵀH = Mᵀ Ω(r)ᵀ Rᵀ R Ω(r) M = Mᵀ Ω(r)² M` because `RᵀR = I` and
//! `Ω` is symmetric: the receiver attitude drops out. Whitening by the
//! known moments gives `W = M⁻ᵀ G M⁻¹ = Ω(r)²`.

use crate::{EmError, Result};
use nalgebra::Matrix3;

/// `G = HᵀH` (T²): entries `G_ij = H_i · H_j`, rotation-invariant.
pub fn gram_matrix(h: &Matrix3<f64>) -> Matrix3<f64> {
    h.transpose() * h
}

/// `W = M⁻ᵀ HᵀH M⁻¹ = Ω(r)²` (T²/(A·m²)²), symmetrised.
///
/// Errors with [`EmError::Singular`] if the moment matrix is not invertible.
pub fn whitened_gram(h: &Matrix3<f64>, moments: &Matrix3<f64>) -> Result<Matrix3<f64>> {
    let m_inv = moments.try_inverse().ok_or_else(|| EmError::Singular {
        what: "transmitter moment matrix M".into(),
    })?;
    let w = m_inv.transpose() * gram_matrix(h) * m_inv;
    Ok((w + w.transpose()) * 0.5)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::positioning::field_matrix;
    use aeromag_core::field::dipole::dipole_matrix;
    use nalgebra::{Rotation3, Vector3};
    use proptest::prelude::*;

    fn moments() -> Matrix3<f64> {
        Matrix3::new(1000.0, 50.0, -30.0, 20.0, 900.0, 40.0, -10.0, 60.0, 1100.0)
    }

    proptest! {
        /// The Gram matrix is the same for any receiver attitude.
        #[test]
        fn gram_independent_of_attitude(
            x in -100.0..-20.0f64, y in -40.0..40.0f64, z in 5.0..60.0f64,
            a1 in -3.1..3.1f64, a2 in -3.1..3.1f64, a3 in -3.1..3.1f64,
            b1 in -3.1..3.1f64, b2 in -3.1..3.1f64, b3 in -3.1..3.1f64,
        ) {
            let r = Vector3::new(x, y, z);
            let ra = Rotation3::from_euler_angles(a1, a2, a3).into_inner();
            let rb = Rotation3::from_euler_angles(b1, b2, b3).into_inner();
            let ga = gram_matrix(&field_matrix(&r, &ra, &moments()));
            let gb = gram_matrix(&field_matrix(&r, &rb, &moments()));
            let scale = ga.norm();
            prop_assert!((ga - gb).norm() <= 1e-12 * scale);
            // And it whitens to Ω².
            let w = whitened_gram(&field_matrix(&r, &ra, &moments()), &moments()).unwrap();
            let o = dipole_matrix(&r);
            prop_assert!((w - o * o).norm() <= 1e-10 * (o * o).norm());
        }
    }

    #[test]
    fn singular_moments_error() {
        let h = Matrix3::identity();
        let m = Matrix3::new(1.0, 2.0, 3.0, 2.0, 4.0, 6.0, 0.0, 0.0, 1.0);
        assert!(matches!(
            whitened_gram(&h, &m),
            Err(EmError::Singular { what: _ })
        ));
    }
}
