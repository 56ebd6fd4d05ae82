//! Dolph–Chebyshev window: the window of length `M` whose DFT has all
//! sidelobes at exactly `−A` dB, i.e. the narrowest main lobe for a given
//! sidelobe level (Dolph 1946; Harris 1978, §V-G). Equal to SciPy's
//! `windows.chebwin(M, at, sym)`.
//!
//! With `N = M − 1`, `r = 10^{A/20}` and `β = cosh(acosh(r)/N)`, the window's
//! DFT samples are the Chebyshev polynomial values
//!
//! ```text
//! W[k] = T_N(β cos(π k/M)),   k = 0 … M−1
//! T_N(x) = cos(N acos x)            |x| ≤ 1
//!        = cosh(N acosh x)           x > 1
//!        = (−1)^N cosh(N acosh(−x))  x < −1
//! ```
//!
//! and the window is the real part of their DFT (with a half-sample phase
//! shift `e^{iπk/M}` for even `M`), rearranged to be centred and normalised
//! to a maximum of 1. The periodic variant is the length-`M + 1` window
//! without its last sample.

use super::validate::invalid;
use super::window::{Symmetry, extended_len};
use crate::error::Result;
use rustfft::FftPlanner;
use rustfft::num_complex::Complex;
use std::f64::consts::PI;

/// Dolph–Chebyshev window of `len` samples with sidelobes `attenuation_db`
/// (dB, > 0) below the main lobe.
///
/// Errors (`InvalidArgument`) when `attenuation_db` is not finite and > 0.
pub fn chebwin(len: usize, attenuation_db: f64, symmetry: Symmetry) -> Result<Vec<f64>> {
    if !(attenuation_db.is_finite() && attenuation_db > 0.0) {
        return Err(invalid(
            "attenuation_db",
            format!("must be finite and > 0, got {attenuation_db}"),
        ));
    }
    if len <= 1 {
        return Ok(vec![1.0; len]);
    }
    let m = extended_len(len, symmetry);
    let order = m as f64 - 1.0;
    let r = 10f64.powf(attenuation_db / 20.0);
    let beta = (r.acosh() / order).cosh();
    let odd = m % 2 == 1;
    let mut spec: Vec<Complex<f64>> = (0..m)
        .map(|k| {
            let x = beta * (PI * k as f64 / m as f64).cos();
            let t = if x > 1.0 {
                (order * x.acosh()).cosh()
            } else if x < -1.0 {
                let sign = if odd { 1.0 } else { -1.0 };
                sign * (order * (-x).acosh()).cosh()
            } else {
                (order * x.acos()).cos()
            };
            if odd {
                Complex::new(t, 0.0)
            } else {
                // half-sample shift e^{iπk/M}
                let ph = PI / m as f64 * k as f64;
                Complex::new(t * ph.cos(), t * ph.sin())
            }
        })
        .collect();
    FftPlanner::new().plan_fft_forward(m).process(&mut spec);
    let re: Vec<f64> = spec.iter().map(|c| c.re).collect();
    let mut w: Vec<f64> = if odd {
        let h = m.div_ceil(2);
        re[1..h].iter().rev().chain(&re[..h]).copied().collect()
    } else {
        let h = m / 2 + 1;
        re[1..h].iter().rev().chain(&re[1..h]).copied().collect()
    };
    let max = w.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    for v in &mut w {
        *v /= max;
    }
    w.truncate(len);
    Ok(w)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn symmetric_and_normalised() {
        for len in [7, 8, 31, 64] {
            let w = chebwin(len, 60.0, Symmetry::Symmetric).unwrap();
            assert_eq!(w.len(), len);
            let max = w.iter().copied().fold(0.0, f64::max);
            assert_eq!(max, 1.0);
            for n in 0..len {
                assert!((w[n] - w[len - 1 - n]).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn sidelobes_sit_at_the_requested_level() {
        // DFT magnitude (zero-padded) outside the main lobe ≤ −A dB, and
        // reaches it.
        let (len, att) = (31, 50.0);
        let w = chebwin(len, att, Symmetry::Symmetric).unwrap();
        let nfft = 4096;
        let mut buf: Vec<Complex<f64>> = (0..nfft)
            .map(|i| Complex::new(if i < len { w[i] } else { 0.0 }, 0.0))
            .collect();
        FftPlanner::new().plan_fft_forward(nfft).process(&mut buf);
        let mag: Vec<f64> = buf.iter().map(|c| c.norm()).collect();
        let peak = mag[0];
        // first null: first local minimum
        let first_null = (1..nfft / 2).find(|&i| mag[i] < mag[i + 1]).unwrap();
        let side = mag[first_null..nfft / 2]
            .iter()
            .copied()
            .fold(0.0, f64::max);
        let db = 20.0 * (side / peak).log10();
        assert!((db + att).abs() < 0.05, "sidelobe {db} dB");
    }

    #[test]
    fn rejects_bad_attenuation() {
        assert!(chebwin(8, 0.0, Symmetry::Symmetric).is_err());
        assert!(chebwin(8, f64::NAN, Symmetry::Periodic).is_err());
        assert_eq!(chebwin(1, 50.0, Symmetry::Periodic).unwrap(), vec![1.0]);
    }
}
