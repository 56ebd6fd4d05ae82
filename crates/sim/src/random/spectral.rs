//! Stationary Gaussian processes of a prescribed power spectral density by
//! FFT synthesis.
//!
//! White noise `w_j ~ N(0, 1)`, `j = 0…M−1`, is transformed (`W = FFT w`,
//! `E|W_k|² = M`), multiplied by a real amplitude response `g(f_k) ≥ 0`,
//! `f_k = k/(M Δt)`, and transformed back (`x = IFFT(g W)/M`). The result is a
//! periodic (period `M Δt`) stationary Gaussian sequence with
//!
//! ```text
//! Var x            = (1/M) Σ_k g_k²                        (sum over all M bins)
//! E[(x(t+T)−x(t))²] = (2/M) Σ_k g_k² (1 − cos 2π f_k T)
//! ```
//!
//! so its two-sided PSD is `g(f)² Δt / M·M = g² Δt` per unit white variance.
//! The first `n` samples are returned from a record of length `M ≥ 2n`
//! (rounded up to a 5-smooth length), so that the wrap-around of the periodic
//! record does not correlate the end of the output with its beginning.
//!
//! Used for atmospheric turbulence (coloured noise in attitude and altitude),
//! the diurnal variation and micropulsations (spec `simulator.md`, "Fields",
//! "Scenarios").

use rand_chacha::ChaCha8Rng;
use realfft::RealFftPlanner;
use realfft::num_complex::Complex;

use super::normals;
use crate::error::{Result, SimError};
use crate::numerics::next_fast_len;

/// A synthesised record and the statistics of the process it was drawn from.
#[derive(Debug, Clone)]
pub struct Synthesis {
    /// The first `n` samples of the record (unit white-noise input, not scaled).
    pub values: Vec<f64>,
    /// `g(f_k)²` for the half spectrum `k = 0…M/2`.
    gains2: Vec<f64>,
    /// Record length `M`.
    m: usize,
    /// Frequency step `1/(M Δt)`, Hz.
    df_hz: f64,
}

impl Synthesis {
    /// Sum over all `M` bins of `g_k² · weight(f_k)` (uses the Hermitian
    /// symmetry of the half spectrum).
    fn full_sum(&self, weight: impl Fn(f64) -> f64) -> f64 {
        let half = self.m / 2;
        let mut s = 0.0;
        for (k, g2) in self.gains2.iter().enumerate() {
            let mult = if k == 0 || (self.m.is_multiple_of(2) && k == half) {
                1.0
            } else {
                2.0
            };
            s += mult * g2 * weight(k as f64 * self.df_hz);
        }
        s
    }

    /// Theoretical variance of the process (ensemble value, not the sample
    /// variance of this record).
    pub fn variance(&self) -> f64 {
        self.full_sum(|_| 1.0) / self.m as f64
    }

    /// Theoretical mean square increment `E[(x(t+T) − x(t))²]` at lag `lag_s`.
    pub fn increment_variance(&self, lag_s: f64) -> f64 {
        let w = std::f64::consts::TAU * lag_s;
        2.0 * self.full_sum(|f| 1.0 - (w * f).cos()) / self.m as f64
    }

    /// The values multiplied by `factor`.
    pub fn scaled(self, factor: f64) -> Vec<f64> {
        let mut v = self.values;
        v.iter_mut().for_each(|x| *x *= factor);
        v
    }
}

/// Synthesise `n` samples at step `dt_s` (s) of the process whose amplitude
/// response is `amplitude(f)` (f in Hz, `0 ≤ f ≤ 1/(2Δt)`), driven by unit
/// white noise (module docs).
pub fn synthesize(
    rng: &mut ChaCha8Rng,
    n: usize,
    dt_s: f64,
    amplitude: impl Fn(f64) -> f64,
) -> Result<Synthesis> {
    let m = next_fast_len((2 * n).max(16));
    let df_hz = 1.0 / (m as f64 * dt_s);
    let mut planner = RealFftPlanner::<f64>::new();
    let fwd = planner.plan_fft_forward(m);
    let inv = planner.plan_fft_inverse(m);
    let mut w = normals(rng, m);
    let mut spec = fwd.make_output_vec();
    fwd.process(&mut w, &mut spec)
        .map_err(|e| SimError::Numerics(e.to_string()))?;
    let mut gains2 = Vec::with_capacity(spec.len());
    for (k, c) in spec.iter_mut().enumerate() {
        let g = amplitude(k as f64 * df_hz);
        let g = if g.is_finite() && g > 0.0 { g } else { 0.0 };
        gains2.push(g * g);
        *c *= g;
    }
    // DC and (even M) Nyquist bins are real for a real input; keep them so.
    spec[0].im = 0.0;
    if m.is_multiple_of(2) {
        let last = spec.len() - 1;
        spec[last] = Complex::new(spec[last].re, 0.0);
    }
    let mut out = inv.make_output_vec();
    inv.process(&mut spec, &mut out)
        .map_err(|e| SimError::Numerics(e.to_string()))?;
    let inv_m = 1.0 / m as f64;
    out.truncate(n);
    out.iter_mut().for_each(|x| *x *= inv_m);
    Ok(Synthesis {
        values: out,
        gains2,
        m,
        df_hz,
    })
}

/// `n` samples of a zero-mean stationary process with standard deviation
/// `sigma` (ensemble value) and spectral shape `amplitude(f)`.
pub fn coloured_noise(
    rng: &mut ChaCha8Rng,
    n: usize,
    dt_s: f64,
    sigma: f64,
    amplitude: impl Fn(f64) -> f64,
) -> Result<Vec<f64>> {
    if sigma == 0.0 || n == 0 {
        return Ok(vec![0.0; n]);
    }
    let s = synthesize(rng, n, dt_s, amplitude)?;
    let var = s.variance();
    if var <= 0.0 {
        return Ok(vec![0.0; n]);
    }
    Ok(s.scaled(sigma / var.sqrt()))
}

/// Amplitude response of a second-order low-pass (two cascaded first-order
/// lags with time constant `tau_s`): `|H(f)| = 1/(1 + (2π f τ)²)`. Gives
/// smooth (mean-square differentiable) coloured noise with correlation time
/// ≈ `tau_s`; the model used for turbulence.
pub fn second_order_lowpass(tau_s: f64) -> impl Fn(f64) -> f64 {
    move |f: f64| {
        let x = std::f64::consts::TAU * f * tau_s;
        1.0 / (1.0 + x * x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::{Stream, rng_for};

    #[test]
    fn sample_variance_matches_the_requested_sigma() {
        let x = coloured_noise(
            &mut rng_for(3, Stream::Turbulence),
            200_000,
            0.1,
            2.5,
            second_order_lowpass(1.0),
        )
        .unwrap();
        let var = x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64;
        // ≈ 2e4·0.1/(2·1 s) = 1e4 independent samples: 1.4 % standard error.
        assert!((var.sqrt() / 2.5 - 1.0).abs() < 0.04, "std {}", var.sqrt());
    }

    #[test]
    fn increment_variance_of_white_noise_is_twice_the_variance() {
        let s = synthesize(&mut rng_for(3, Stream::Turbulence), 1000, 1.0, |_| 1.0).unwrap();
        assert!((s.variance() - 1.0).abs() < 1e-12);
        // lag of one sample: cos terms sum to zero over all bins.
        assert!((s.increment_variance(1.0) - 2.0).abs() < 1e-9);
    }

    #[test]
    fn a_single_frequency_gives_a_sinusoid() {
        // Only the bin nearest 0.05 Hz passes: the output is a pure cosine of
        // that frequency (checked by the second difference relation).
        let dt = 1.0;
        let s = synthesize(&mut rng_for(5, Stream::Diurnal), 500, dt, |f| {
            if (f - 0.05).abs() < 4e-4 { 1.0 } else { 0.0 }
        })
        .unwrap();
        let m = next_fast_len(1000) as f64;
        let k = (0.05 * m).round();
        let w = std::f64::consts::TAU * k / m;
        let x = &s.values;
        for i in 1..x.len() - 1 {
            let lhs = x[i + 1] + x[i - 1];
            assert!((lhs - 2.0 * w.cos() * x[i]).abs() < 1e-12, "at {i}");
        }
    }
}
