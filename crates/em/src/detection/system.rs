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
use aeromag_core::error::shown;
use aeromag_core::filter::Window;
use nalgebra::{Matrix3, Vector3};

/// Working frequencies of the dipoles, Hz: 1 Hz to 1 MHz (induction
/// coils are used from a few Hz to some hundred kHz).
pub const FREQUENCY_RANGE_HZ: (f64, f64) = (1.0, 1e6);

/// Pilot offset δ, Hz: 1 mHz (a tone the detector can still resolve within
/// a flight) to 100 kHz (pilots beyond the working frequencies' band).
pub const PILOT_OFFSET_RANGE_HZ: (f64, f64) = (1e-3, 1e5);

/// Induction-coil gain, V per (T/s): positive (the polarity is in `χ`),
/// 10⁻⁶ to 10¹⁰.
pub const COIL_GAIN_RANGE: (f64, f64) = (1e-6, 1e10);

/// Pilot field amplitude per axis, T: positive, at most 100 µT (twice the
/// Earth's field; a pilot is a small calibration field).
pub const PILOT_FIELD_RANGE_T: (f64, f64) = (0.0, 1e-4);

/// Least separation of two tones of different dipoles, in bins `f_s/N`:
/// the 4-term windows reject exactly every tone on the bin grid at least 4
/// bins from a detector; closer, a tone leaks into the other's detector
/// (the default plan's nearest tones of different dipoles are 1050 and
/// 2050 Hz, 160 bins of 6.25 Hz apart).
pub const MIN_TONE_SEPARATION_BINS: f64 = 4.0;

/// Instrument constants of a three-dipole EM positioning system.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EmSystem {
    /// Working frequencies `f_i` of the three dipoles, Hz; distinct,
    /// within [`FREQUENCY_RANGE_HZ`].
    pub frequencies_hz: [f64; 3],
    /// Pilot offset `δ`, Hz (pilot tones at `f_i ± δ`, eq. 4); within
    /// [`PILOT_OFFSET_RANGE_HZ`].
    pub pilot_offset_hz: f64,
    /// Induction-coil gain `g`, V per (T/s) (the coil voltage ∝ dB/dt);
    /// within [`COIL_GAIN_RANGE`].
    pub coil_gain_v_per_t_s: f64,
    /// Pilot field amplitude in bird axes, T (the seed's `A`); each
    /// component positive and at most [`PILOT_FIELD_RANGE_T`]`.1`.
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
    /// Check a system read from a file: every number finite; frequencies
    /// distinct; frequencies, pilot offset, coil gain and pilot field
    /// positive and within their ranges (the constants above); moments and
    /// every `χ_i` invertible.
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
        let out_of = |field: &str, v: f64, (lo, hi): (f64, f64), unit: &str| {
            Err(EmError::InvalidData {
                reason: format!(
                    "field '{field}' is {}, expected {}…{} {unit}",
                    shown(v),
                    shown(lo),
                    shown(hi)
                ),
            })
        };
        for (k, &f) in self.frequencies_hz.iter().enumerate() {
            if !(FREQUENCY_RANGE_HZ.0..=FREQUENCY_RANGE_HZ.1).contains(&f) {
                return out_of(&format!("frequencies_hz[{k}]"), f, FREQUENCY_RANGE_HZ, "Hz");
            }
            if self.frequencies_hz[..k].contains(&f) {
                return bad(&format!(
                    "field 'frequencies_hz' holds {} Hz twice: the three dipoles need distinct frequencies",
                    shown(f)
                ));
            }
        }
        let checks = [
            (
                "pilot_offset_hz",
                self.pilot_offset_hz,
                PILOT_OFFSET_RANGE_HZ,
                "Hz",
            ),
            (
                "coil_gain_v_per_t_s",
                self.coil_gain_v_per_t_s,
                COIL_GAIN_RANGE,
                "V/(T/s)",
            ),
        ];
        for (field, v, range, unit) in checks {
            if !(range.0..=range.1).contains(&v) {
                return out_of(field, v, range, unit);
            }
        }
        for (k, &a) in self.pilot_field_t.iter().enumerate() {
            if !(a > 0.0 && a <= PILOT_FIELD_RANGE_T.1) {
                return out_of(&format!("pilot_field_t[{k}]"), a, PILOT_FIELD_RANGE_T, "T");
            }
        }
        // |det| < 1e-12 ‖M‖³ on M scaled by its largest entry (both sides
        // scale alike): unscaled, the norm's cube overflowed for a moment
        // of 1e308, and the stage-2 fit then failed on it (exit 1).
        let largest = self.moments_am2.amax();
        let m = self.moments_am2 / largest;
        if largest == 0.0 || m.determinant().abs() < 1e-12 * m.norm().powi(3) {
            return bad(
                "field 'moments_am2' is singular, expected three linearly independent dipole moments (|det| ≥ 1e-12 ‖M‖³, scaled by the largest entry)",
            );
        }
        if self.chi.iter().any(|m| m.try_inverse().is_none()) {
            return bad("field 'chi' holds a singular matrix");
        }
        Ok(())
    }

    /// The nine tones (each dipole's working frequency and its pilots at
    /// `f ± δ`) against each other for detector blocks of `window_len`
    /// samples at `sample_rate_hz`: tones of different dipoles must lie at
    /// least [`MIN_TONE_SEPARATION_BINS`] bins `f_s/N` apart.
    ///
    /// Errors ([`EmError::InvalidData`]) naming the two tones and the bin
    /// width. `frequencies_hz = [2000, 3000, 5000]` with `δ = 1000` (a
    /// pilot on another dipole's carrier) or `δ = 525` (1025 + 525 =
    /// 2075 − 525) were simulated and detected without a word, and
    /// calibration then found a transmitter distortion |S| of 1.5 and 0.67
    /// and blamed the known positions' unit.
    pub fn check_tone_plan(&self, sample_rate_hz: f64, window_len: usize) -> Result<()> {
        let bin = sample_rate_hz / window_len as f64;
        let d = self.pilot_offset_hz;
        let tones = |i: usize| {
            let f = self.frequencies_hz[i];
            [(f, "working"), (f - d, "pilot"), (f + d, "pilot")]
        };
        for i in 0..3 {
            for j in i + 1..3 {
                for (a, ka) in tones(i) {
                    for (b, kb) in tones(j) {
                        if (a - b).abs() < MIN_TONE_SEPARATION_BINS * bin {
                            return Err(EmError::InvalidData {
                                reason: format!(
                                    "the {ka} tone {} Hz of dipole {} and the {kb} tone {} Hz of dipole {} are {} bins apart (bin f_s/N = {} Hz): the detector cannot separate tones less than {MIN_TONE_SEPARATION_BINS} bins apart; change 'frequencies_hz' or 'pilot_offset_hz'",
                                    shown(a),
                                    i + 1,
                                    shown(b),
                                    j + 1,
                                    shown((a - b).abs() / bin),
                                    shown(bin)
                                ),
                            });
                        }
                    }
                }
            }
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
        // Values the fuzzer found accepted, each refused naming its field.
        let refused = |edit: &dyn Fn(&mut super::EmSystem), field: &str| {
            let mut s = good.clone();
            edit(&mut s);
            let e = s.validate().unwrap_err().to_string();
            assert!(e.contains(field) && e.len() < 200, "{field}: {e}");
        };
        refused(&|s| s.frequencies_hz = [1025.0; 3], "frequencies_hz");
        refused(&|s| s.coil_gain_v_per_t_s = -1.0, "coil_gain_v_per_t_s");
        refused(&|s| s.pilot_field_t[1] = -1e-9, "pilot_field_t[1]");
        refused(&|s| s.pilot_field_t[0] = 1e308, "pilot_field_t[0]");
        refused(&|s| s.pilot_offset_hz = 1e-308, "pilot_offset_hz");
        refused(&|s| s.pilot_offset_hz = 1e308, "pilot_offset_hz");
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
