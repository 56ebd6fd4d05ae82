//! The time variation of the external field ("diurnal"): a smooth random
//! process plus micropulsations.
//!
//! `d(t) = s(t) + μ(t) − s(0) − μ(0)` (nT, zero at the start of the flight),
//! applied as a vector along the main-field direction, `d(t) B_IGRF/|B_IGRF|`
//! (a simplification: real Sq and pulsation fields have their own
//! polarisation; to first order only the projection on the main field
//! reaches a scalar magnetometer).
//!
//! * **Smooth variation** `s(t)`: stationary Gaussian process with PSD
//!   `∝ (1 + (f/f_c)²)^(−p/2)`, `p = spectral_exponent` (default 3: the
//!   `f^−3` continuum of geomagnetic variations between ~10⁻⁴ and 10⁻² Hz),
//!   `f_c = 1/(2π τ_c)`, `τ_c = correlation_time_s`. Its scale is set by the
//!   RMS change over one hour, `√E[(s(t+3600) − s(t))²] = drift_nt_per_hour`
//!   (default 20 nT: a moderately active day's Sq variation, "tens of nT per
//!   hour" of spec `simulator.md`).
//! * **Micropulsations** `μ(t)` (Pc3–Pc5): band-limited Gaussian noise with
//!   PSD `∝ 1/f` between `1/max_period` and `1/min_period` (defaults 300 s and
//!   10 s) with cosine tapers over 20 % of the band edges in `log f`, scaled
//!   to `micropulsation_rms_nt` (default 0.3 nT).
//!
//! Both are drawn by FFT synthesis ([`crate::random::spectral`]) and scaled
//! by their *theoretical* statistics, so a record is a fair draw of the
//! process, not forced to a sample RMS.

use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::error::{Result, invalid, require_non_negative, require_positive};
use crate::random::spectral::{coloured_noise, synthesize};

/// Parameters of the diurnal variation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DiurnalConfig {
    /// RMS change of the smooth variation over one hour, nT. Default 20.
    pub drift_nt_per_hour: f64,
    /// Correlation time `τ_c` of the smooth variation, s. Default 10 800 (3 h).
    pub correlation_time_s: f64,
    /// Spectral exponent `p` of the smooth variation. Default 3.
    pub spectral_exponent: f64,
    /// RMS of the micropulsations, nT. Default 0.3.
    pub micropulsation_rms_nt: f64,
    /// Shortest micropulsation period, s. Default 10.
    pub micropulsation_min_period_s: f64,
    /// Longest micropulsation period, s. Default 300.
    pub micropulsation_max_period_s: f64,
}

impl Default for DiurnalConfig {
    fn default() -> Self {
        Self {
            drift_nt_per_hour: 20.0,
            correlation_time_s: 10_800.0,
            spectral_exponent: 3.0,
            micropulsation_rms_nt: 0.3,
            micropulsation_min_period_s: 10.0,
            micropulsation_max_period_s: 300.0,
        }
    }
}

impl DiurnalConfig {
    /// Check the values.
    pub fn validate(&self, p: &str) -> Result<()> {
        require_non_negative(&format!("{p}.drift_nt_per_hour"), self.drift_nt_per_hour)?;
        require_positive(&format!("{p}.correlation_time_s"), self.correlation_time_s)?;
        require_positive(&format!("{p}.spectral_exponent"), self.spectral_exponent)?;
        require_non_negative(
            &format!("{p}.micropulsation_rms_nt"),
            self.micropulsation_rms_nt,
        )?;
        require_positive(
            &format!("{p}.micropulsation_min_period_s"),
            self.micropulsation_min_period_s,
        )?;
        if self.micropulsation_max_period_s.is_nan()
            || self.micropulsation_max_period_s <= self.micropulsation_min_period_s
        {
            return Err(invalid(
                format!("{p}.micropulsation_max_period_s"),
                "must be larger than micropulsation_min_period_s",
            ));
        }
        Ok(())
    }

    /// `n` samples at step `dt_s` of `d(t)` (nT), zero at the first sample.
    pub fn generate(&self, n: usize, dt_s: f64, rng: &mut ChaCha8Rng) -> Result<Vec<f64>> {
        if n == 0 {
            return Ok(Vec::new());
        }
        let fc = 1.0 / (std::f64::consts::TAU * self.correlation_time_s);
        let p = self.spectral_exponent;
        let smooth = synthesize(rng, n, dt_s, |f| (1.0 + (f / fc).powi(2)).powf(-p / 4.0))?;
        let inc = smooth.increment_variance(3600.0);
        let scale = if inc > 0.0 {
            self.drift_nt_per_hour / inc.sqrt()
        } else {
            0.0
        };
        let s = smooth.scaled(scale);

        let (f_lo, f_hi) = (
            1.0 / self.micropulsation_max_period_s,
            1.0 / self.micropulsation_min_period_s,
        );
        let (l_lo, l_hi) = (f_lo.ln(), f_hi.ln());
        let taper = 0.2 * (l_hi - l_lo);
        let band = move |f: f64| {
            if f <= 0.0 {
                return 0.0;
            }
            let l = f.ln();
            if l < l_lo || l > l_hi {
                return 0.0;
            }
            let edge = (l - l_lo).min(l_hi - l);
            let w = if edge < taper {
                0.5 * (1.0 - (std::f64::consts::PI * edge / taper).cos())
            } else {
                1.0
            };
            w / f.sqrt()
        };
        let mu = coloured_noise(rng, n, dt_s, self.micropulsation_rms_nt, band)?;
        let (s0, m0) = (s[0], mu[0]);
        Ok(s.iter().zip(&mu).map(|(a, b)| a - s0 + b - m0).collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::{Stream, rng_for};

    #[test]
    fn hourly_drift_and_micropulsation_levels() {
        let cfg = DiurnalConfig::default();
        let dt = 5.0; // Nyquist 0.1 Hz = the shortest micropulsation period
        let n = 4 * 3600 / 5;
        // Hourly changes over many independent records.
        let mut rng = rng_for(2, Stream::Diurnal);
        let (mut s2, mut cnt) = (0.0, 0.0);
        for _ in 0..200 {
            let d = cfg.generate(n, dt, &mut rng).unwrap();
            assert_eq!(d[0], 0.0);
            for k in (0..n - 720).step_by(360) {
                s2 += (d[k + 720] - d[k]).powi(2);
                cnt += 1.0;
            }
        }
        let rms = (s2 / cnt).sqrt();
        // The micropulsations add 2·0.3² nT² to the increment variance.
        let expect = (20f64.powi(2) + 2.0 * 0.09).sqrt();
        assert!((rms / expect - 1.0).abs() < 0.1, "hourly change {rms} nT");
    }

    #[test]
    fn micropulsations_live_in_their_band() {
        let cfg = DiurnalConfig {
            drift_nt_per_hour: 0.0,
            ..Default::default()
        };
        let dt = 0.1;
        let d = cfg
            .generate(36_000, dt, &mut rng_for(3, Stream::Diurnal))
            .unwrap();
        let m = d.iter().sum::<f64>() / d.len() as f64;
        let rms = (d.iter().map(|x| (x - m).powi(2)).sum::<f64>() / d.len() as f64).sqrt();
        assert!(rms > 0.15 && rms < 0.45, "rms {rms}");
        // Nothing above 1/10 s: the sample-to-sample change is tiny compared
        // with a white process of the same RMS.
        let diff = (d.windows(2).map(|w| (w[1] - w[0]).powi(2)).sum::<f64>()
            / (d.len() - 1) as f64)
            .sqrt();
        assert!(diff < 0.05 * rms, "{diff}");
    }
}
