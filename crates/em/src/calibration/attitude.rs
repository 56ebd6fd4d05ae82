//! Calibration stage 3: small-rotation attitude correction from points with
//! known attitude (seed `001_…` part II; spec `em-positioning.md`,
//! "Calibration in three stages" item 3).
//!
//! At a point where the true rotation `R` (transmitter → receiver axes) is
//! known and the positioning gives `R'`, the correction is
//! `Qᵀ = R' Rᵀ`; at run time `R_corrected = Q R'`, i.e. `Q = R R'ᵀ`. With
//! several points the estimate is the SO(3) projection of `Σ_k R_k R'_kᵀ`
//! (one point suffices without noise).

use crate::positioning::project_to_so3;
use crate::{EmError, Result};
use nalgebra::Matrix3;

/// `Q = proj_SO(3)(Σ_k R_k R'_kᵀ)` from known rotations `truth` and computed
/// rotations `computed` (equal, non-zero counts).
pub fn fit_attitude_correction(
    truth: &[Matrix3<f64>],
    computed: &[Matrix3<f64>],
) -> Result<Matrix3<f64>> {
    if truth.len() != computed.len() || truth.is_empty() {
        return Err(EmError::InvalidArgument {
            reason: format!(
                "{} known and {} computed attitudes",
                truth.len(),
                computed.len()
            ),
        });
    }
    let sum: Matrix3<f64> = truth
        .iter()
        .zip(computed)
        .map(|(r, rp)| r * rp.transpose())
        .sum();
    project_to_so3(&sum)
}
