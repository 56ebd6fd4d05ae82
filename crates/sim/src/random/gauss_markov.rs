//! First-order Gauss–Markov process (exponentially correlated noise).
//!
//! `dx/dt = −x/τ + w`, stationary standard deviation `σ`, autocorrelation
//! `R(Δ) = σ² exp(−|Δ|/τ)`. Exact discretisation at step `Δt`:
//!
//! ```text
//! x_{k+1} = a x_k + σ √(1 − a²) n_k,   a = exp(−Δt/τ),   n_k ~ N(0, 1)
//! x_0 = σ n_0                                   (stationary start)
//! ```
//!
//! Used for the slowly varying GNSS/INS errors (spec `simulator.md`,
//! "GNSS/INS: position, velocity and attitude with realistic noise").

use rand_chacha::ChaCha8Rng;

use super::normal;

/// `n` samples at step `dt_s` (s) of a stationary first-order Gauss–Markov
/// process with standard deviation `sigma` (any unit) and correlation time
/// `tau_s` (s). `sigma = 0` gives zeros without consuming draws; `tau_s ≤ 0`
/// gives white noise.
pub fn gauss_markov(rng: &mut ChaCha8Rng, n: usize, dt_s: f64, sigma: f64, tau_s: f64) -> Vec<f64> {
    if sigma == 0.0 || n == 0 {
        return vec![0.0; n];
    }
    let a = if tau_s > 0.0 {
        (-dt_s / tau_s).exp()
    } else {
        0.0
    };
    let b = sigma * (1.0 - a * a).sqrt();
    let mut x = sigma * normal(rng);
    let mut out = Vec::with_capacity(n);
    out.push(x);
    for _ in 1..n {
        x = a * x + b * normal(rng);
        out.push(x);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::{Stream, rng_for};

    #[test]
    fn variance_and_lag_one_correlation_match_theory() {
        let (dt, tau, sigma) = (0.1, 2.0, 3.0);
        let x = gauss_markov(&mut rng_for(1, Stream::Navigation), 400_000, dt, sigma, tau);
        let n = x.len() as f64;
        let var = x.iter().map(|v| v * v).sum::<f64>() / n;
        let c1 = x.windows(2).map(|w| w[0] * w[1]).sum::<f64>() / (n - 1.0) / var;
        // Standard error of the variance estimate with ~ n·dt/(2τ) = 1e4
        // independent samples is ≈ 1.4 %; allow 4σ.
        assert!((var / (sigma * sigma) - 1.0).abs() < 0.06, "var {var}");
        assert!(
            (c1 - (-dt / tau).exp()).abs() < 2e-3,
            "lag-1 correlation {c1}"
        );
    }
}

/// Smooth stationary coloured noise generated sample by sample: white noise
/// through two cascaded first-order lags with the same time constant `τ`
/// (PSD ∝ 1/(1 + (2π f τ)²)², the shape of the Dryden turbulence spectra).
///
/// Exact discretisation with `a = exp(−Δt/τ)`:
///
/// ```text
/// x1_{k+1} = a x1_k + √(1 − a²) n_k          (unit-variance Gauss–Markov)
/// x2_{k+1} = a x2_k + (1 − a) x1_k
/// Var x2 = (1 + a²)/(1 + a)²,   Cov(x1, x2) = a/(1 + a)     (stationary)
/// ```
///
/// The output `σ x2/√Var x2` has standard deviation `σ`. The start is drawn
/// from the joint stationary distribution, so the process has no transient.
/// Generating on the fly lets the trajectory integrator draw exactly as many
/// samples as the flight needs.
#[derive(Debug, Clone)]
pub struct SmoothNoise {
    a: f64,
    b: f64,
    x1: f64,
    x2: f64,
    scale: f64,
}

impl SmoothNoise {
    /// A process with standard deviation `sigma` and time constant `tau_s`
    /// (> 0) sampled at `dt_s`, started in its stationary distribution.
    pub fn new(rng: &mut ChaCha8Rng, dt_s: f64, sigma: f64, tau_s: f64) -> Self {
        let a = if tau_s > 0.0 {
            (-dt_s / tau_s).exp()
        } else {
            0.0
        };
        let var2 = (1.0 + a * a) / ((1.0 + a) * (1.0 + a));
        let c = a / (1.0 + a);
        let x1 = normal(rng);
        let x2 = c * x1 + (var2 - c * c).max(0.0).sqrt() * normal(rng);
        Self {
            a,
            b: (1.0 - a * a).sqrt(),
            x1,
            x2,
            scale: sigma / var2.sqrt(),
        }
    }

    /// The current value (σ-scaled).
    pub fn value(&self) -> f64 {
        self.scale * self.x2
    }

    /// Advance one step and return the new value.
    pub fn step(&mut self, rng: &mut ChaCha8Rng) -> f64 {
        let x1 = self.a * self.x1 + self.b * normal(rng);
        self.x2 = self.a * self.x2 + (1.0 - self.a) * self.x1;
        self.x1 = x1;
        self.value()
    }
}

#[cfg(test)]
mod smooth_tests {
    use super::*;
    use crate::random::{Stream, rng_for};

    #[test]
    fn smooth_noise_has_the_requested_variance_from_the_first_sample() {
        // Ensemble over many independent starts: the first sample already has
        // the stationary variance (no transient), and so does a later one.
        let mut rng = rng_for(11, Stream::Turbulence);
        let (mut s0, mut s50) = (0.0, 0.0);
        let runs = 20_000;
        for _ in 0..runs {
            let mut p = SmoothNoise::new(&mut rng, 0.1, 2.0, 1.5);
            s0 += p.value().powi(2);
            for _ in 0..50 {
                p.step(&mut rng);
            }
            s50 += p.value().powi(2);
        }
        for s in [s0, s50] {
            let sd = (s / runs as f64).sqrt();
            // standard error of a variance from 2e4 samples: 1 %; allow 4σ
            assert!((sd / 2.0 - 1.0).abs() < 0.02, "sd {sd}");
        }
    }
}
