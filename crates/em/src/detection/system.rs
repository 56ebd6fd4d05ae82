//! The instrument constants the detection chain needs (seed `001_…` part II,
//! eqs. 3–4): frequency plan, coil gain, pilot field, the bench-measured
//! receiver cross-coupling `χ(ω_i)` and the nominal transmitter moments.
//!
//! These are what a survey crew knows about its system before the flight;
//! they travel in the raw file's header ([`crate::sim::RawHeader`]) so that
//! `aeromag em detect` needs nothing but the raw record. Nothing here is
//! truth of a flight: the drifting channel sensitivity `ξ(ω, t)`, the
//! transmitter distortion and the bird's pose are not part of it.

use super::{Complex64, DetectorConfig, FieldChain, SyncDetector};
use crate::{EmError, Result};
use aeromag_core::filter::Window;
use nalgebra::{Matrix3, Vector3};

/// Instrument constants of a three-dipole EM positioning system.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EmSystem {
    /// Working frequencies `f_i` of the three dipoles, Hz.
    pub frequencies_hz: [f64; 3],
    /// Pilot offset `δ`, Hz (pilot tones at `f_i ± δ`, eq. 4).
    pub pilot_offset_hz: f64,
    /// Induction-coil gain `g`, V per (T/s) (the coil voltage ∝ dB/dt).
    pub coil_gain_v_per_t_s: f64,
    /// Pilot field amplitude in bird axes, T (the seed's `A`).
    pub pilot_field_t: Vector3<f64>,
    /// Bench-measured receiver cross-coupling `χ(ω_i)` per working
    /// frequency (complex, unit diagonal, eq. 3); in JSON each matrix is a
    /// flat column-major list of 9 `[re, im]` pairs.
    pub chi: [Matrix3<Complex64>; 3],
    /// Nominal transmitter moments (columns = dipoles), A·m²; in JSON a flat
    /// column-major list of 9.
    pub moments_am2: Matrix3<f64>,
}

impl EmSystem {
    /// Check a system read from a file: every number finite, pilot offset
    /// and coil gain non-zero, moments and every `χ_i` invertible.
    ///
    /// Errors ([`EmError::InvalidData`]) naming the offending field.
    pub fn validate(&self) -> Result<()> {
        let bad = |m: &str| Err(EmError::InvalidData { reason: m.into() });
        let finite = self.frequencies_hz.iter().all(|v| v.is_finite())
            && self.pilot_offset_hz.is_finite()
            && self.coil_gain_v_per_t_s.is_finite()
            && self.pilot_field_t.iter().all(|v| v.is_finite())
            && self.moments_am2.iter().all(|v| v.is_finite())
            && self
                .chi
                .iter()
                .flat_map(|m| m.iter())
                .all(|c| c.re.is_finite() && c.im.is_finite());
        if !finite {
            return bad("non-finite number in the system description");
        }
        if self.coil_gain_v_per_t_s == 0.0 || self.pilot_offset_hz <= 0.0 {
            return bad(
                "fields 'coil_gain_v_per_t_s' and 'pilot_offset_hz' must be non-zero and positive",
            );
        }
        // |det| < 1e-12 ‖M‖³ on M scaled by its largest entry (both sides
        // scale alike): unscaled, the norm's cube overflowed for a moment
        // of 1e308, and the stage-2 fit then failed on it (exit 1).
        let largest = self.moments_am2.amax();
        let m = self.moments_am2 / largest;
        if largest == 0.0 || m.determinant().abs() < 1e-12 * m.norm().powi(3) {
            return bad("field 'moments_am2' is singular");
        }
        if self.chi.iter().any(|m| m.try_inverse().is_none()) {
            return bad("field 'chi' holds a singular matrix");
        }
        Ok(())
    }

    /// The detection chain of this system for an ADC rate `sample_rate_hz`
    /// (Hz) and detector blocks of `window_len` samples weighted by `window`
    /// ([`DetectorConfig::three_frequency_plan`] layout); `use_pilot = false`
    /// assumes `ξ = 1` (to show the drift).
    ///
    /// Errors: frequencies outside `(0, f_s/2)`, a window shorter than 8
    /// samples, singular `χ`, zero coil gain.
    pub fn chain(
        &self,
        sample_rate_hz: f64,
        window_len: usize,
        window: Window,
        use_pilot: bool,
    ) -> Result<FieldChain> {
        let plan = DetectorConfig {
            window,
            ..DetectorConfig::three_frequency_plan(
                sample_rate_hz,
                window_len,
                self.frequencies_hz,
                self.pilot_offset_hz,
            )
        };
        FieldChain::new(
            SyncDetector::new(plan)?,
            &self.chi,
            self.coil_gain_v_per_t_s,
            &self.pilot_field_t,
            use_pilot,
        )
    }
}

#[cfg(test)]
mod tests {
    use crate::sim::{EmScenario, EmSimConfig};

    #[test]
    fn validate_names_the_bad_field() {
        let good = EmScenario::new(EmSimConfig::default()).unwrap().system();
        assert!(good.validate().is_ok());
        let refused_for_moments = |edit: &dyn Fn(&mut super::EmSystem)| {
            let mut s = good.clone();
            edit(&mut s);
            let e = s.validate().unwrap_err().to_string();
            assert!(e.contains("moments_am2"), "{e}");
        };
        refused_for_moments(&|s| {
            s.moments_am2
                .set_column(2, &s.moments_am2.column(0).into_owned())
        });
        // One moment of 1e308 (a corrupted file): as singular as it is, for
        // all that the unscaled test overflowed.
        refused_for_moments(&|s| s.moments_am2[(1, 2)] = -1e308);
        let mut s = good.clone();
        s.moments_am2 *= 1e300;
        assert!(
            s.validate().is_ok(),
            "a well-conditioned matrix at any scale"
        );
        let mut s = good.clone();
        s.chi[1] = nalgebra::Matrix3::zeros();
        assert!(s.validate().unwrap_err().to_string().contains("chi"));
        let mut s = good.clone();
        s.pilot_field_t[0] = f64::NAN;
        assert!(s.validate().is_err());
        let mut s = good;
        s.coil_gain_v_per_t_s = 0.0;
        assert!(s.validate().is_err());
    }
}
