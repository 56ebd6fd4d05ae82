//! Welch's power spectral density estimate: the average of modified
//! (windowed) periodograms of overlapping segments (Welch 1967, "The use of
//! fast Fourier transform for the estimation of power spectra: a method
//! based on time averaging over short, modified periodograms", IEEE Trans.
//! Audio Electroacoustics 15(2)). Equal to SciPy's
//! `signal.welch(x, fs, window, nperseg, noverlap, nfft, detrend,
//! return_onesided=True, scaling)` with `average='mean'`.
//!
//! The signal is cut into `K = ⌊(N − D)/S⌋` segments of `L = nperseg`
//! samples, hop `S = L − D` (`D = noverlap`); segment `p` is
//! `x[pS … pS + L − 1]` (samples after the last full segment are unused).
//! Each segment is detrended (`d_p`), multiplied by the periodic window
//! `w`, zero-padded to `nfft` and transformed:
//!
//! ```text
//! X_p[k] = Σ_{n<L} w[n] d_p[n] e^{−2πi kn/nfft},      f_k = k·fs/nfft,  k = 0 … ⌊nfft/2⌋
//! P[k]   = c_k · s · (1/K) Σ_p |X_p[k]|²
//! ```
//!
//! with the scaling `s`
//!
//! * density (`x_units²/Hz`): `s = 1/(fs Σ w²)` — a white noise of variance
//!   σ² gives `P = 2σ²/fs` one-sided, and `Σ_k P[k]·fs/nfft ≈ σ²`;
//! * spectrum (`x_units²`): `s = 1/(Σ w)²` — a sinusoid of amplitude `A` on
//!   a bin gives a peak `A²/2` (its mean square);
//!
//! and the one-sided factor `c_k = 2` except at DC and, for even `nfft`, at
//! Nyquist (`c = 1`), which folds the negative frequencies onto the positive
//! ones. Averaging `K` periodograms divides the variance of the estimate by
//! about `K` (less with overlap) at the price of resolution `fs/L`.
//!
//! Differences from SciPy: `nperseg > len(x)` is an error here (SciPy warns
//! and shrinks the segment); only one-sided spectra of real data.

use super::detrend::{Detrend, detrend_in_place};
use crate::error::Result;
use crate::filter::Window;
use crate::filter::validate::{check_finite, check_len, check_positive, invalid};
use crate::filter::window::Symmetry;
use realfft::RealFftPlanner;
use serde::{Deserialize, Serialize};

/// Scaling of the Welch estimate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Scaling {
    /// Power spectral density, `x_units²/Hz` (SciPy `'density'`).
    Density,
    /// Power spectrum, `x_units²` (SciPy `'spectrum'`).
    Spectrum,
}

/// Parameters of [`welch`] (SciPy's argument names).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WelchConfig {
    /// Sampling rate, Hz.
    pub fs_hz: f64,
    /// Segment length `L`, samples (≥ 1).
    pub nperseg: usize,
    /// Overlap `D` between segments, samples (`< nperseg`).
    pub noverlap: usize,
    /// FFT length (`≥ nperseg`; zero-padding when larger).
    pub nfft: usize,
    /// Window family; its periodic variant is used (SciPy `get_window`).
    pub window: Window,
    /// Trend removed from each segment.
    pub detrend: Detrend,
    /// Density or spectrum scaling.
    pub scaling: Scaling,
}

impl WelchConfig {
    /// SciPy's defaults for a given segment length: Hann window,
    /// `noverlap = nperseg/2`, `nfft = nperseg`, constant detrend, density.
    pub fn new(fs_hz: f64, nperseg: usize) -> Self {
        WelchConfig {
            fs_hz,
            nperseg,
            noverlap: nperseg / 2,
            nfft: nperseg,
            window: Window::Hann,
            detrend: Detrend::Constant,
            scaling: Scaling::Density,
        }
    }
}

/// A one-sided spectrum estimate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Psd {
    /// Frequencies `f_k = k·fs/nfft`, Hz, `k = 0 … ⌊nfft/2⌋`.
    pub freqs_hz: Vec<f64>,
    /// `P[k]`: `x_units²/Hz` (density) or `x_units²` (spectrum).
    pub values: Vec<f64>,
    /// Number of averaged segments `K`.
    pub n_segments: usize,
}

/// Welch PSD of the real series `x` (see the module docs for the equations).
///
/// Errors: `InvalidArgument` for `fs_hz` not finite and > 0, `nperseg = 0`,
/// `noverlap ≥ nperseg`, `nfft < nperseg`, an invalid window parameter;
/// `TooShort` when `x.len() < nperseg`; `NonFinite` naming the first
/// non-finite sample.
pub fn welch(x: &[f64], cfg: &WelchConfig) -> Result<Psd> {
    check_positive("fs_hz", cfg.fs_hz)?;
    let (l, d, nfft) = (cfg.nperseg, cfg.noverlap, cfg.nfft);
    if l == 0 {
        return Err(invalid("nperseg", "must be ≥ 1"));
    }
    if d >= l {
        return Err(invalid(
            "noverlap",
            format!("must be < nperseg = {l}, got {d}"),
        ));
    }
    if nfft < l {
        return Err(invalid(
            "nfft",
            format!("must be ≥ nperseg = {l}, got {nfft}"),
        ));
    }
    check_len("x", x.len(), l)?;
    check_finite("x", x)?;

    let win = cfg.window.samples(l, Symmetry::Periodic)?;
    let scale = match cfg.scaling {
        Scaling::Density => 1.0 / (cfg.fs_hz * win.iter().map(|w| w * w).sum::<f64>()),
        Scaling::Spectrum => 1.0 / win.iter().sum::<f64>().powi(2),
    };
    let hop = l - d;
    let n_segments = (x.len() - d) / hop;

    let r2c = RealFftPlanner::<f64>::new().plan_fft_forward(nfft);
    let mut seg = r2c.make_input_vec();
    let mut spec = r2c.make_output_vec();
    let mut scratch = r2c.make_scratch_vec();
    let mut acc = vec![0.0; spec.len()];
    for p in 0..n_segments {
        let (head, tail) = seg.split_at_mut(l);
        head.copy_from_slice(&x[p * hop..p * hop + l]);
        detrend_in_place(head, cfg.detrend);
        for (v, w) in head.iter_mut().zip(&win) {
            *v *= w;
        }
        tail.fill(0.0);
        r2c.process_with_scratch(&mut seg, &mut spec, &mut scratch)
            .map_err(|e| invalid("nfft", format!("FFT failed: {e}")))?;
        for (a, c) in acc.iter_mut().zip(&spec) {
            *a += c.norm_sqr();
        }
    }
    let nfreq = acc.len();
    let unpaired_nyquist = nfft % 2 == 0;
    let df = 1.0 / (nfft as f64 * (1.0 / cfg.fs_hz));
    let values = acc
        .iter()
        .enumerate()
        .map(|(k, a)| {
            let one_sided = if k == 0 || (unpaired_nyquist && k == nfreq - 1) {
                1.0
            } else {
                2.0
            };
            a * scale * one_sided / n_segments as f64
        })
        .collect();
    Ok(Psd {
        freqs_hz: (0..nfreq).map(|k| k as f64 * df).collect(),
        values,
        n_segments,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::CoreError;
    use std::f64::consts::PI;

    #[test]
    fn sinusoid_on_a_bin_has_power_a2_over_2() {
        // spectrum scaling, rectangular window: peak = A²/2 exactly on-bin
        let (fs, l) = (100.0, 200);
        let f0 = 10.0; // bin 20
        let a = 3.0;
        let x: Vec<f64> = (0..2000)
            .map(|n| a * (2.0 * PI * f0 * n as f64 / fs).sin())
            .collect();
        let mut cfg = WelchConfig::new(fs, l);
        cfg.window = Window::Rectangular;
        cfg.scaling = Scaling::Spectrum;
        let p = welch(&x, &cfg).unwrap();
        assert_eq!(p.freqs_hz[20], 10.0);
        assert!((p.values[20] - a * a / 2.0).abs() < 1e-10);
        assert_eq!(p.n_segments, (2000 - 100) / 100);
    }

    #[test]
    fn parseval_for_density() {
        // Σ P·df equals the mean square of the (zero-mean) segments for a
        // rectangular window without overlap.
        let x: Vec<f64> = (0..1024)
            .map(|n| ((n * 7919) % 113) as f64 / 113.0 - 0.5)
            .collect();
        let mut cfg = WelchConfig::new(8.0, 256);
        cfg.window = Window::Rectangular;
        cfg.noverlap = 0;
        cfg.detrend = Detrend::None;
        let p = welch(&x, &cfg).unwrap();
        let df = p.freqs_hz[1];
        let total: f64 = p.values.iter().sum::<f64>() * df;
        let ms = x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64;
        assert!((total - ms).abs() < 1e-12 * ms.max(1.0), "{total} vs {ms}");
    }

    #[test]
    fn invalid_arguments() {
        let x = vec![0.0; 100];
        let base = WelchConfig::new(1.0, 32);
        let mut c = base;
        c.noverlap = 32;
        assert!(matches!(
            welch(&x, &c),
            Err(CoreError::InvalidArgument {
                name: "noverlap",
                ..
            })
        ));
        let mut c = base;
        c.nfft = 16;
        assert!(matches!(
            welch(&x, &c),
            Err(CoreError::InvalidArgument { name: "nfft", .. })
        ));
        let mut c = base;
        c.nperseg = 0;
        assert!(welch(&x, &c).is_err());
        let mut c = base;
        c.fs_hz = 0.0;
        assert!(welch(&x, &c).is_err());
        assert_eq!(
            welch(&x[..10], &base),
            Err(CoreError::TooShort {
                name: "x",
                len: 10,
                min: 32
            })
        );
        let mut y = x.clone();
        y[40] = f64::NAN;
        assert_eq!(
            welch(&y, &base),
            Err(CoreError::NonFinite {
                name: "x",
                index: 40
            })
        );
    }
}
