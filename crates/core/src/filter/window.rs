//! Window functions for FIR design and spectral estimation, equal to
//! `scipy.signal.windows.*` (symmetric) and `scipy.signal.get_window`
//! (periodic, `fftbins=True`).
//!
//! **Cosine-sum windows** (Harris 1978, "On the use of windows for harmonic
//! analysis with the discrete Fourier transform", Proc. IEEE 66(1)):
//!
//! ```text
//! w[n] = Σ_k a_k cos(k φ_n),   φ_n = −π + 2π n/(M − 1),   n = 0 … M−1
//! ```
//!
//! (equivalently `Σ_k (−1)^k a_k cos(2π k n/(M−1))`), with
//!
//! | window | `a_k` |
//! |---|---|
//! | Hann | 0.5, 0.5 |
//! | Hamming | 0.54, 0.46 |
//! | Blackman | 0.42, 0.50, 0.08 |
//! | Blackman–Harris (4-term, −92 dB) | 0.35875, 0.48829, 0.14128, 0.01168 |
//! | Nuttall (4-term, SciPy `nuttall`) | 0.3635819, 0.4891775, 0.1365995, 0.0106411 |
//!
//! **Symmetric vs periodic.** The symmetric window (`sym=True`, for FIR
//! design) satisfies `w[n] = w[M−1−n]`. The periodic window (`sym=False`,
//! `get_window`'s default, for spectral analysis) is the symmetric window of
//! length `M + 1` with its last sample dropped, so that its `M`-point DFT
//! has the ideal sidelobe structure. Lengths 0 and 1 give `[]` and `[1]`.
//!
//! Dolph–Chebyshev and Kaiser windows are in [`super::chebwin`](mod@super::chebwin) and
//! [`super::kaiser`](mod@super::kaiser).

use super::chebwin::chebwin;
use super::kaiser::kaiser;
use crate::error::Result;
use std::f64::consts::PI;

/// Hann coefficients `a_k`.
pub const HANN: [f64; 2] = [0.5, 0.5];
/// Hamming coefficients `a_k`.
pub const HAMMING: [f64; 2] = [0.54, 0.46];
/// Blackman coefficients `a_k`.
pub const BLACKMAN: [f64; 3] = [0.42, 0.50, 0.08];
/// 4-term Blackman–Harris coefficients `a_k` (Harris 1978, −92 dB sidelobes).
pub const BLACKMAN_HARRIS: [f64; 4] = [0.35875, 0.48829, 0.14128, 0.01168];
/// 4-term Nuttall coefficients `a_k` (Nuttall 1981; SciPy's `nuttall`).
pub const NUTTALL: [f64; 4] = [0.3635819, 0.4891775, 0.1365995, 0.0106411];

/// Symmetric (filter design) or periodic (DFT, `fftbins=True`) variant.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Symmetry {
    /// `w[n] = w[M−1−n]` (SciPy `sym=True`).
    Symmetric,
    /// First `M` samples of the symmetric window of length `M + 1`
    /// (SciPy `sym=False`, `get_window(..., fftbins=True)`).
    Periodic,
}

/// A window family (SciPy names in parentheses).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Window {
    /// All ones (`boxcar`).
    Rectangular,
    /// Hann (`hann`).
    Hann,
    /// Hamming (`hamming`).
    Hamming,
    /// Blackman (`blackman`).
    Blackman,
    /// 4-term Blackman–Harris (`blackmanharris`).
    BlackmanHarris,
    /// 4-term Nuttall (`nuttall`).
    Nuttall,
    /// Dolph–Chebyshev with the given sidelobe attenuation in dB (`chebwin`).
    Chebyshev {
        /// Sidelobe attenuation, dB (> 0).
        attenuation_db: f64,
    },
    /// Kaiser with shape parameter β (`kaiser`).
    Kaiser {
        /// Shape parameter β ≥ 0 (0 = rectangular, 8.6 ≈ Blackman).
        beta: f64,
    },
}

impl Window {
    /// The `len` samples of this window.
    ///
    /// Errors (`InvalidArgument`) only for an invalid Chebyshev attenuation
    /// or Kaiser β.
    pub fn samples(&self, len: usize, symmetry: Symmetry) -> Result<Vec<f64>> {
        Ok(match *self {
            Window::Rectangular => vec![1.0; len],
            Window::Hann => cosine_sum(len, &HANN, symmetry),
            Window::Hamming => cosine_sum(len, &HAMMING, symmetry),
            Window::Blackman => cosine_sum(len, &BLACKMAN, symmetry),
            Window::BlackmanHarris => cosine_sum(len, &BLACKMAN_HARRIS, symmetry),
            Window::Nuttall => cosine_sum(len, &NUTTALL, symmetry),
            Window::Chebyshev { attenuation_db } => chebwin(len, attenuation_db, symmetry)?,
            Window::Kaiser { beta } => kaiser(len, beta, symmetry)?,
        })
    }
}

/// Length of the symmetric window to compute: `M` or `M + 1` (periodic).
pub(crate) fn extended_len(len: usize, symmetry: Symmetry) -> usize {
    match symmetry {
        Symmetry::Symmetric => len,
        Symmetry::Periodic => len + 1,
    }
}

/// Windows at least twice this long are computed on all cores, in parts of
/// a multiple of it.
const WINDOW_PART: usize = 4096;

/// General cosine-sum window `w[n] = Σ_k a_k cos(k φ_n)`,
/// `φ_n = −π + 2π n/(M−1)` (SciPy `general_cosine`).
pub fn cosine_sum(len: usize, coeffs: &[f64], symmetry: Symmetry) -> Vec<f64> {
    if len <= 1 {
        return vec![1.0; len];
    }
    let m = extended_len(len, symmetry);
    // NumPy linspace(−π, π, m): n·step − π, last point exactly π.
    let step = 2.0 * PI / (m - 1) as f64;
    let value = |n: usize| {
        let phi = if n == m - 1 {
            PI
        } else {
            n as f64 * step + -PI
        };
        // cos(0 · φ) is exactly 1: the term k = 0 without the call.
        coeffs.iter().enumerate().fold(0.0, |acc, (k, a)| {
            acc + a * if k == 0 { 1.0 } else { (k as f64 * phi).cos() }
        })
    };
    // A long window (an EM detector's 16 000 samples: 48 000 cosines,
    // about a millisecond) in parts on the cores; each value is the same
    // bits wherever it is computed.
    let mut w = vec![0.0; m];
    crate::parallel::for_each_part_mut(
        &mut w,
        crate::parallel::threads(),
        WINDOW_PART,
        |start, part| {
            for (i, v) in part.iter_mut().enumerate() {
                *v = value(start + i);
            }
        },
    );
    w.truncate(len);
    w
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A window long enough to be computed on the cores, and a short one,
    /// are the bits of the defining sum evaluated one value at a time
    /// (with the call `cos(0 · φ)` the shortcut leaves out).
    #[test]
    fn windows_are_the_bits_of_the_sum_one_value_at_a_time() {
        for (len, symmetry) in [
            (20_000, Symmetry::Periodic),
            (9_001, Symmetry::Symmetric),
            (300, Symmetry::Periodic),
        ] {
            let m = extended_len(len, symmetry);
            let step = 2.0 * PI / (m - 1) as f64;
            let want: Vec<u64> = (0..len)
                .map(|n| {
                    let phi = if n == m - 1 {
                        PI
                    } else {
                        n as f64 * step + -PI
                    };
                    BLACKMAN_HARRIS
                        .iter()
                        .enumerate()
                        .fold(0.0, |acc, (k, a)| acc + a * (k as f64 * phi).cos())
                        .to_bits()
                })
                .collect();
            let got: Vec<u64> = cosine_sum(len, &BLACKMAN_HARRIS, symmetry)
                .iter()
                .map(|v| v.to_bits())
                .collect();
            assert!(got == want, "{len} {symmetry:?}");
        }
    }

    #[test]
    fn hann_closed_form() {
        let w = Window::Hann.samples(9, Symmetry::Symmetric).unwrap();
        for (n, v) in w.iter().enumerate() {
            let expect = 0.5 - 0.5 * (2.0 * PI * n as f64 / 8.0).cos();
            assert!((v - expect).abs() < 1e-15);
        }
        let p = Window::Hann.samples(8, Symmetry::Periodic).unwrap();
        assert_eq!(p, w[..8]);
    }

    #[test]
    fn symmetric_windows_are_symmetric_and_peak_at_one() {
        for win in [
            Window::Hann,
            Window::Hamming,
            Window::Blackman,
            Window::BlackmanHarris,
            Window::Nuttall,
        ] {
            for len in [5, 16, 33] {
                let w = win.samples(len, Symmetry::Symmetric).unwrap();
                for n in 0..len {
                    assert!((w[n] - w[len - 1 - n]).abs() < 1e-15);
                }
                if len % 2 == 1 {
                    assert!((w[len / 2] - 1.0).abs() < 1e-6, "{win:?}");
                }
            }
        }
    }

    #[test]
    fn degenerate_lengths() {
        assert!(
            Window::Hann
                .samples(0, Symmetry::Periodic)
                .unwrap()
                .is_empty()
        );
        assert_eq!(
            Window::Nuttall.samples(1, Symmetry::Symmetric).unwrap(),
            vec![1.0]
        );
        assert_eq!(
            Window::Rectangular.samples(3, Symmetry::Periodic).unwrap(),
            vec![1.0; 3]
        );
    }
}
