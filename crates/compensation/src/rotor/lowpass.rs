//! Baseline (a): low-pass filtering below the blade-passing frequency
//! (spec `helicopter.md` part A, "What to show"). A zero-phase Butterworth
//! low-pass (`sosfiltfilt`, order `2 × order` in effect) at `cutoff_hz`;
//! the removed part `x − LP(x)` is the baseline's interference estimate.

use aeromag_core::filter::{Band, butter, sosfiltfilt};

use crate::error::Result;

/// `LP(x)`: the data low-passed at `cutoff_hz` (order `order`, zero phase).
pub fn lowpass(x: &[f64], fs_hz: f64, cutoff_hz: f64, order: usize) -> Result<Vec<f64>> {
    let sos = butter(order, Band::Lowpass { cutoff_hz }, fs_hz)?;
    Ok(sosfiltfilt(&sos, x)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn passes_slow_signals_and_rejects_the_blade_passing_frequency() {
        let fs = 100.0;
        let x: Vec<f64> = (0..10_000)
            .map(|k| {
                let t = k as f64 / fs;
                3.0 + (0.3 * t).sin() + (std::f64::consts::TAU * 19.3 * t).cos()
            })
            .collect();
        // order 6 at 10 Hz, zero phase: gain 1/(1 + (19.3/10)^12) ≈ 4·10⁻⁴ at 19.3 Hz
        let y = lowpass(&x, fs, 10.0, 6).unwrap();
        let err = (1000..9000)
            .map(|k| (y[k] - 3.0 - (0.3 * k as f64 / fs).sin()).abs())
            .fold(0.0, f64::max);
        assert!(err < 0.02, "{err}");
    }
}
