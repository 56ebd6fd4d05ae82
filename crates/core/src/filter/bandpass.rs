//! The zero-phase Butterworth band-pass used by the band-pass least-squares
//! compensation (spec `compensation.md`, "Method 1": order 4, `filtfilt`,
//! default 0.1–0.9 Hz): designed once, applied to many columns.
//!
//! The response applied to the data is `|H(e^{iΩ})|²` of the order-`N`
//! Butterworth band-pass (see [`super::filtfilt`](mod@super::filtfilt)): unity at the geometric
//! band centre, −6 dB at `low_hz` and `high_hz`, zero at DC and Nyquist.

use super::butterworth::{Band, butter};
use super::filtfilt::{zero_phase, zero_phase_in_place};
use super::sos::Sos;
use crate::error::Result;

/// A designed zero-phase Butterworth band-pass filter.
#[derive(Debug, Clone, PartialEq)]
pub struct BandPass {
    order: usize,
    low_hz: f64,
    high_hz: f64,
    fs_hz: f64,
    sos: Sos,
}

impl BandPass {
    /// Filter order of the compensation default (spec "Method 1").
    pub const DEFAULT_ORDER: usize = 4;
    /// Lower band edge of the compensation default, Hz.
    pub const DEFAULT_LOW_HZ: f64 = 0.1;
    /// Upper band edge of the compensation default, Hz.
    pub const DEFAULT_HIGH_HZ: f64 = 0.9;

    /// Designs an order-`order` Butterworth band-pass `low_hz…high_hz` (Hz)
    /// for data sampled at `fs_hz` (Hz). Errors as [`butter`].
    pub fn new(order: usize, low_hz: f64, high_hz: f64, fs_hz: f64) -> Result<Self> {
        let sos = butter(order, Band::Bandpass { low_hz, high_hz }, fs_hz)?;
        Ok(BandPass {
            order,
            low_hz,
            high_hz,
            fs_hz,
            sos,
        })
    }

    /// The compensation default: order 4, 0.1–0.9 Hz at sampling rate
    /// `fs_hz` (errors when `fs_hz ≤ 1.8` Hz, i.e. 0.9 Hz is not below Nyquist).
    pub fn compensation_default(fs_hz: f64) -> Result<Self> {
        Self::new(
            Self::DEFAULT_ORDER,
            Self::DEFAULT_LOW_HZ,
            Self::DEFAULT_HIGH_HZ,
            fs_hz,
        )
    }

    /// Butterworth order `N` (the zero-phase response has order `2N`).
    pub fn order(&self) -> usize {
        self.order
    }

    /// Lower band edge, Hz.
    pub fn low_hz(&self) -> f64 {
        self.low_hz
    }

    /// Upper band edge, Hz.
    pub fn high_hz(&self) -> f64 {
        self.high_hz
    }

    /// Sampling rate, Hz.
    pub fn fs_hz(&self) -> f64 {
        self.fs_hz
    }

    /// The designed second-order sections.
    pub fn sos(&self) -> &Sos {
        &self.sos
    }

    /// Shortest series the filter accepts: `padlen + 1` samples.
    pub fn min_len(&self) -> usize {
        self.sos.padlen() + 1
    }

    /// Zero-phase filtered copy of `x` (SciPy `sosfiltfilt`). Errors:
    /// `TooShort` below [`BandPass::min_len`], `NonFinite` with the index.
    pub fn filter(&self, x: &[f64]) -> Result<Vec<f64>> {
        zero_phase(&self.sos, x)
    }

    /// Zero-phase filters `x` in place (one scratch buffer of
    /// `x.len() + 2·padlen` samples). On error `x` is unchanged.
    pub fn filter_in_place(&self, x: &mut [f64]) -> Result<()> {
        zero_phase_in_place(&self.sos, x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn passes_band_centre_and_removes_dc_and_fast_signals() {
        let fs = 10.0;
        let bp = BandPass::compensation_default(fs).unwrap();
        assert_eq!(bp.order(), 4);
        assert_eq!(bp.sos().n_sections(), 4);
        let centre = (0.1f64 * 0.9).sqrt();
        let n = 4000;
        let x: Vec<f64> = (0..n)
            .map(|k| {
                let t = k as f64 / fs;
                5.0 + (2.0 * PI * centre * t).sin() + (2.0 * PI * 4.0 * t).sin()
            })
            .collect();
        let y = bp.filter(&x).unwrap();
        // interior: each component scaled by the zero-phase gain |H|²
        let (g0, g1, g4) = (
            bp.sos().gain(0.0, fs),
            bp.sos().gain(centre, fs),
            bp.sos().gain(4.0, fs),
        );
        assert!(
            g0 < 1e-12 && (g1 - 1.0).abs() < 1e-2 && g4 < 1e-3,
            "{g0} {g1} {g4}"
        );
        let mut worst: f64 = 0.0;
        for (k, yk) in y.iter().enumerate().take(3000).skip(1000) {
            let t = k as f64 / fs;
            let expect = 5.0 * g0 * g0
                + g1 * g1 * (2.0 * PI * centre * t).sin()
                + g4 * g4 * (2.0 * PI * 4.0 * t).sin();
            worst = worst.max((yk - expect).abs());
        }
        assert!(worst < 1e-9, "worst {worst}");
        let mut z = x.clone();
        bp.filter_in_place(&mut z).unwrap();
        assert_eq!(y, z);
    }

    #[test]
    fn bad_specs_are_errors() {
        assert!(BandPass::compensation_default(1.8).is_err());
        assert!(BandPass::new(4, 0.9, 0.1, 10.0).is_err());
        let bp = BandPass::new(2, 0.5, 1.0, 10.0).unwrap();
        assert!(bp.filter(&vec![0.0; bp.min_len() - 1]).is_err());
        assert!(bp.filter(&vec![0.0; bp.min_len()]).is_ok());
    }
}
