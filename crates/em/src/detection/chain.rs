//! The detection chain from ADC samples to complex field vectors (seed
//! `001_…` part II, eqs. 2–4 and `H̃ = χ⁻¹ ξ⁻¹ U0`).
//!
//! Per block and working frequency `ω_i` (detector layout: for each `i`,
//! frequencies `ω_i`, `ω_i − δ`, `ω_i + δ`):
//!
//! ```text
//! ξ_c      = (U_R,c/E_R,c + U_L,c/E_L,c)/2            pilot (or 1 without pilot correction)
//! H̃_i      = χ_i⁻¹ (U0/ξ) / (−iω_i g)                 T, complex, receiver axes
//! E_±,c    = (χ_i (−i(ω_i±δ) g) P)_c                   ideal detected pilot
//! ```
//!
//! with `χ_i` the bench-measured cross-coupling, `g` the coil gain (V per
//! T/s) and `P` the pilot field in bird axes (T).

use super::{Complex64, PilotCorrection, Spike, SyncDetector};
use crate::{EmError, Result};
use nalgebra::{Matrix3, Vector3};
use std::f64::consts::TAU;

/// Complex 3×3 matrix.
type CMatrix3 = Matrix3<Complex64>;

/// One block's complex field vectors and channel sensitivities.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FieldEpoch {
    /// Time of the block centre, s (absolute sample index / rate).
    pub time_s: f64,
    /// `h[i][c]`: field of dipole `i`, receiver channel `c`, T (complex).
    pub h: [[Complex64; 3]; 3],
    /// Channel sensitivity `ξ_c(ω_i)` used, per frequency `i`.
    pub xi: [[Complex64; 3]; 3],
}

/// Detector plus the known receiver constants.
#[derive(Debug, Clone)]
pub struct FieldChain {
    detector: SyncDetector,
    chi_inv: [CMatrix3; 3],
    pilots: [PilotCorrection; 3],
    transfer: [Complex64; 3],
    use_pilot: bool,
}

impl FieldChain {
    /// Build the chain. `detector` must detect exactly nine frequencies in
    /// the layout above; `chi` is the cross-coupling per working frequency,
    /// `coil_gain_v_per_t_s` the coil gain, `pilot_field_t` the pilot field
    /// in bird axes; `use_pilot = false` assumes `ξ = 1` (to show the drift).
    ///
    /// Errors: wrong detector layout, singular `χ`, zero gain.
    pub fn new(
        detector: SyncDetector,
        chi: &[CMatrix3; 3],
        coil_gain_v_per_t_s: f64,
        pilot_field_t: &Vector3<f64>,
        use_pilot: bool,
    ) -> Result<Self> {
        let f = detector.config().frequencies_hz.clone();
        if f.len() != 9 {
            return Err(EmError::InvalidArgument {
                reason: "detector must have 9 frequencies (3 × working, −δ, +δ)".into(),
            });
        }
        if !crate::positive_finite(coil_gain_v_per_t_s.abs()) {
            return Err(EmError::InvalidArgument {
                reason: "coil gain must be non-zero".into(),
            });
        }
        let mut chi_inv = [CMatrix3::identity(); 3];
        let mut pilots = [PilotCorrection::from_amplitudes([1.0; 3]); 3];
        let mut transfer = [Complex64::new(0.0, 0.0); 3];
        let p = pilot_field_t.map(|v| Complex64::new(v, 0.0));
        for i in 0..3 {
            chi_inv[i] = chi[i].try_inverse().ok_or_else(|| EmError::Singular {
                what: format!("χ at frequency {i}"),
            })?;
            let ideal = |freq: f64| -> [Complex64; 3] {
                let v = chi[i] * p * Complex64::new(0.0, -TAU * freq * coil_gain_v_per_t_s);
                [v[0], v[1], v[2]]
            };
            pilots[i] = PilotCorrection {
                expected_left: ideal(f[3 * i + 1]),
                expected_right: ideal(f[3 * i + 2]),
            };
            transfer[i] = Complex64::new(0.0, -TAU * f[3 * i] * coil_gain_v_per_t_s);
        }
        Ok(Self {
            detector,
            chi_inv,
            pilots,
            transfer,
            use_pilot,
        })
    }

    /// Process interleaved three-channel samples (V) whose first frame has
    /// absolute index `start_index`; one [`FieldEpoch`] per complete block.
    ///
    /// Errors from detection or from a vanishing pilot.
    pub fn process(&self, data: &[f32], start_index: u64) -> Result<Vec<FieldEpoch>> {
        Ok(self.process_with_spikes(data, start_index)?.0)
    }

    /// [`Self::process`], with the impulsive spikes repaired before
    /// detection ([`super::impulse`]) in time order.
    ///
    /// Errors from detection or from a vanishing pilot.
    pub fn process_with_spikes(
        &self,
        data: &[f32],
        start_index: u64,
    ) -> Result<(Vec<FieldEpoch>, Vec<Spike>)> {
        let epochs = self.detector.detect_interleaved(data, 3, start_index)?;
        let spikes = epochs
            .iter()
            .flat_map(|e| e.spikes.iter().copied())
            .collect();
        let fields = epochs
            .iter()
            .map(|e| {
                let v = |k: usize| [e.values[k * 3], e.values[k * 3 + 1], e.values[k * 3 + 2]];
                let mut h = [[Complex64::new(0.0, 0.0); 3]; 3];
                let mut xi = [[Complex64::new(1.0, 0.0); 3]; 3];
                for i in 0..3 {
                    if self.use_pilot {
                        xi[i] = self.pilots[i].sensitivity(&v(3 * i + 1), &v(3 * i + 2))?;
                    }
                    let u0 = v(3 * i);
                    let u = nalgebra::Vector3::from_fn(|c, _| u0[c] / xi[i][c]);
                    let hv = self.chi_inv[i] * u / self.transfer[i];
                    h[i] = [hv[0], hv[1], hv[2]];
                }
                Ok(FieldEpoch {
                    time_s: e.centre_time_s,
                    h,
                    xi,
                })
            })
            .collect::<Result<_>>()?;
        Ok((fields, spikes))
    }
}
