//! Pilot-signal correction of the channel sensitivity (seed `001_…` part II,
//! eq. 4; spec `em-positioning.md`, "Signal chain" item 3).
//!
//! A small coil fixed near the receiver emits
//! `H_p(t) = A [cos(ω0−δ)t + cos(ω0+δ)t]` at two nulls of the working
//! detector. Detecting at `ω0 ∓ δ` gives `U_L = ξ(ω0−δ) E_L`,
//! `U_R = ξ(ω0+δ) E_R`, with `E` the values an ideal channel (`ξ = 1`) would
//! give (the seed's `A`, here complex per channel so that the known coil
//! transfer, e.g. `−iω` of an induction coil, and the known cross-coupling of
//! the pilot field can be included). With `ξ(ω)` linear across
//! `[ω0−δ, ω0+δ]`:
//!
//! ```text
//! ξ_c(ω0) ≈ (U_R,c/E_R,c + U_L,c/E_L,c)/2      (= G (U_R + U_L)/2 for E_L = E_R = A)
//! Ũ0,c    = U0,c / ξ_c(ω0)
//! ```

use super::Complex64;
use crate::{EmError, Result};

/// Expected ideal-channel pilot values `E_L`, `E_R` per channel (the
/// `G = diag(1/A)` of eq. 4), in the units of the detected values.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PilotCorrection {
    /// Ideal detected pilot at `ω0 − δ`, per channel.
    pub expected_left: [Complex64; 3],
    /// Ideal detected pilot at `ω0 + δ`, per channel.
    pub expected_right: [Complex64; 3],
}

impl PilotCorrection {
    /// The seed's form: real amplitudes `A_c`, the same at both pilots.
    pub fn from_amplitudes(a: [f64; 3]) -> Self {
        let e = a.map(|v| Complex64::new(v, 0.0));
        Self {
            expected_left: e,
            expected_right: e,
        }
    }

    /// Channel sensitivity `ξ_c(ω0)` (dimensionless, complex).
    ///
    /// Errors ([`EmError::InvalidData`]) for a zero expected pilot or a
    /// vanishing or non-finite detected pilot.
    pub fn sensitivity(
        &self,
        u_left: &[Complex64; 3],
        u_right: &[Complex64; 3],
    ) -> Result<[Complex64; 3]> {
        let mut xi = [Complex64::new(0.0, 0.0); 3];
        for c in 0..3 {
            let (el, er) = (self.expected_left[c], self.expected_right[c]);
            if !(crate::positive_finite(el.norm()) && crate::positive_finite(er.norm())) {
                return Err(EmError::InvalidData {
                    reason: format!("expected pilot of channel {c} is zero"),
                });
            }
            xi[c] = (u_right[c] / er + u_left[c] / el) * 0.5;
            if !crate::positive_finite(xi[c].norm() - 1e-12) {
                return Err(EmError::InvalidData {
                    reason: format!("pilot not detected on channel {c}"),
                });
            }
        }
        Ok(xi)
    }

    /// Pilot-corrected working amplitudes `Ũ0,c = U0,c / ξ_c(ω0)`.
    ///
    /// Errors as [`PilotCorrection::sensitivity`].
    pub fn correct(
        &self,
        u0: &[Complex64; 3],
        u_left: &[Complex64; 3],
        u_right: &[Complex64; 3],
    ) -> Result<[Complex64; 3]> {
        let xi = self.sensitivity(u_left, u_right)?;
        Ok([u0[0] / xi[0], u0[1] / xi[1], u0[2] / xi[2]])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_sensitivity_is_removed_exactly() {
        // ξ(ω) = ξ0 + ξ1 (ω − ω0), complex, different per channel.
        let xi0 = [
            Complex64::from_polar(1.04, 0.03),
            Complex64::from_polar(0.96, -0.05),
            Complex64::from_polar(1.01, 0.02),
        ];
        let slope = [
            Complex64::new(1e-3, 2e-4),
            Complex64::new(-5e-4, 1e-4),
            Complex64::new(2e-4, -3e-4),
        ];
        let delta = 25.0;
        let a = [0.01, 0.02, 0.015];
        let h = [
            Complex64::new(0.3, 0.01),
            Complex64::new(-0.2, 0.0),
            Complex64::new(0.5, -0.02),
        ];
        let mut u0 = [Complex64::new(0.0, 0.0); 3];
        let mut ul = u0;
        let mut ur = u0;
        for c in 0..3 {
            u0[c] = xi0[c] * h[c];
            ul[c] = (xi0[c] - slope[c] * delta) * a[c];
            ur[c] = (xi0[c] + slope[c] * delta) * a[c];
        }
        let p = PilotCorrection::from_amplitudes(a);
        let out = p.correct(&u0, &ul, &ur).unwrap();
        for c in 0..3 {
            assert!((out[c] - h[c]).norm() < 1e-14);
        }
        let zero = PilotCorrection::from_amplitudes([0.0, 1.0, 1.0]);
        assert!(zero.correct(&u0, &ul, &ur).is_err());
        let none = [Complex64::new(0.0, 0.0); 3];
        assert!(p.correct(&u0, &none, &none).is_err());
    }
}
