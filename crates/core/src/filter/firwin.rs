//! Windowed-sinc FIR low-pass design, equal to SciPy's
//! `signal.firwin(numtaps, cutoff, window=..., fs=fs)` (low-pass, `scale=True`).
//!
//! The ideal low-pass with cutoff `fc` (normalised `c = fc/(fs/2)`) has the
//! impulse response `c·sinc(c·m)`, `sinc(x) = sin(πx)/(πx)`. It is truncated
//! to `L` taps centred on `α = (L − 1)/2`, multiplied by a *symmetric*
//! window and scaled to unit gain at DC:
//!
//! ```text
//! h[n] = w[n] · c · sinc(c (n − α)) / Σ_j w[j] · c · sinc(c (j − α)),   n = 0 … L−1
//! ```
//!
//! The filter is linear-phase (symmetric taps, delay `α` samples). The
//! window sets the transition width and stopband level (Hamming, the SciPy
//! default: ≈ −53 dB; see [`super::window`]).
//!
//! Reference: SciPy reference guide, `scipy.signal.firwin`; Oppenheim &
//! Schafer, *Discrete-Time Signal Processing*, §7.5.

use super::validate::{check_positive, invalid};
use super::window::{Symmetry, Window};
use crate::error::Result;
use std::f64::consts::PI;

/// NumPy's normalised `sinc(x) = sin(πx)/(πx)` (with `x = 0` replaced by 1e-20).
fn sinc(x: f64) -> f64 {
    let y = PI * if x == 0.0 { 1.0e-20 } else { x };
    y.sin() / y
}

/// Low-pass FIR taps: `numtaps` coefficients, cutoff `cutoff_hz` (Hz, −6 dB
/// point), sampling rate `fs_hz` (Hz), window `window` (symmetric variant),
/// DC gain 1.
///
/// Errors (`InvalidArgument`): `numtaps = 0`, `fs_hz` not finite and > 0,
/// `cutoff_hz` not in `(0, fs/2)`, an invalid window parameter.
pub fn firwin_lowpass(
    numtaps: usize,
    cutoff_hz: f64,
    fs_hz: f64,
    window: Window,
) -> Result<Vec<f64>> {
    if numtaps == 0 {
        return Err(invalid("numtaps", "must be ≥ 1"));
    }
    check_positive("fs_hz", fs_hz)?;
    let nyq = 0.5 * fs_hz;
    let c = cutoff_hz / nyq;
    if !(cutoff_hz.is_finite() && c > 0.0 && c < 1.0) {
        return Err(invalid(
            "cutoff_hz",
            format!(
                "must lie strictly between 0 and the Nyquist frequency {nyq} Hz, got {cutoff_hz}"
            ),
        ));
    }
    let win = window.samples(numtaps, Symmetry::Symmetric)?;
    let alpha = 0.5 * (numtaps as f64 - 1.0);
    let mut h: Vec<f64> = win
        .iter()
        .enumerate()
        .map(|(n, w)| {
            let m = n as f64 - alpha;
            c * sinc(c * m) * w
        })
        .collect();
    let s: f64 = h.iter().sum();
    for v in &mut h {
        *v /= s;
    }
    Ok(h)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_dc_gain_and_symmetry() {
        let h = firwin_lowpass(31, 1.0, 10.0, Window::Hamming).unwrap();
        assert!((h.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        for n in 0..31 {
            assert!((h[n] - h[30 - n]).abs() < 1e-16);
        }
        // half-amplitude at the cutoff (windowed-sinc property), to within
        // the ripple of a 31-tap Hamming design
        let w = 2.0 * PI * 1.0 / 10.0;
        let resp: f64 = h
            .iter()
            .enumerate()
            .map(|(n, v)| v * (w * (n as f64 - 15.0)).cos())
            .sum();
        assert!((resp - 0.5).abs() < 0.01, "{resp}");
    }

    #[test]
    fn invalid_designs() {
        assert!(firwin_lowpass(0, 1.0, 10.0, Window::Hamming).is_err());
        assert!(firwin_lowpass(11, 5.0, 10.0, Window::Hamming).is_err());
        assert!(firwin_lowpass(11, 0.0, 10.0, Window::Hamming).is_err());
        assert!(firwin_lowpass(11, 1.0, 0.0, Window::Hamming).is_err());
        assert!(
            firwin_lowpass(
                11,
                1.0,
                10.0,
                Window::Chebyshev {
                    attenuation_db: -3.0
                }
            )
            .is_err()
        );
        assert_eq!(
            firwin_lowpass(1, 1.0, 10.0, Window::Hamming).unwrap(),
            vec![1.0]
        );
    }
}
