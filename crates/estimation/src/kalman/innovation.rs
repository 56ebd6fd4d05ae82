//! Innovations of a scalar measurement and their Gaussian log-likelihood.
//!
//! For a scalar measurement `y = hᵀx + v`, `v ~ N(0, r)`, processed with the
//! prior (predicted) estimate `x⁻, P⁻`, the innovation is
//!
//! ```text
//! ν = y − hᵀx⁻,        σ² = hᵀP⁻h + r.
//! ```
//!
//! When the model is right the innovations are independent, `ν ~ N(0, σ²)`,
//! and the log-likelihood of the whole record is the sum of
//!
//! ```text
//! ℓ = −½ (ln 2π + ln σ² + ν²/σ²)
//! ```
//!
//! (the prediction-error decomposition, Schweppe 1965; Harvey,
//! *Forecasting, structural time series models and the Kalman filter*, 1989,
//! §3.4). Maximising it over the noise intensities tunes the model; the mean
//! of the normalised squares `ν²/σ²` should be close to 1.

/// The innovation of one scalar measurement update.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Innovation {
    /// `ν = y − hᵀx⁻`, in the units of the measurement.
    pub value: f64,
    /// `σ² = hᵀP⁻h + r`, in measurement units squared (always > 0).
    pub variance: f64,
}

impl Innovation {
    /// Log-likelihood contribution `−½ (ln 2π + ln σ² + ν²/σ²)`.
    pub fn log_likelihood(&self) -> f64 {
        -0.5 * ((2.0 * std::f64::consts::PI * self.variance).ln()
            + self.value * self.value / self.variance)
    }

    /// The normalised innovation `ν/σ` (standard normal under the model).
    pub fn normalized(&self) -> f64 {
        self.value / self.variance.sqrt()
    }

    /// Standard deviation `σ` of the innovation.
    pub fn std(&self) -> f64 {
        self.variance.sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_likelihood_is_the_normal_log_density() {
        let i = Innovation {
            value: 0.3,
            variance: 0.04,
        };
        let sigma = 0.2f64;
        let density =
            (-(0.3f64 * 0.3) / (2.0 * 0.04)).exp() / (sigma * (2.0 * std::f64::consts::PI).sqrt());
        assert!((i.log_likelihood() - density.ln()).abs() < 1e-14);
        assert!((i.normalized() - 1.5).abs() < 1e-15);
    }
}
