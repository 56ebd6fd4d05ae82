//! Baseline (b): notch filters at the rotor harmonics (spec
//! `helicopter.md` part A). For every harmonic `h f_r`, `h = 1 … max`, its
//! alias in `(0, fs/2)` is rejected by a zero-phase 2nd-order Butterworth
//! band-stop of half width `max(min_half_width_hz, rel_half_width · h f_r)`
//! (the relative width covers the ±1 % rotor-speed wander, which grows with
//! the harmonic number). Aliases closer than the half width to 0 or to the
//! Nyquist frequency are skipped.

use aeromag_core::filter::{Band, butter, sosfiltfilt_in_place};

use crate::error::Result;

/// Options of the notch bank.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NotchOptions {
    /// Highest harmonic of the rotor frequency rejected.
    pub max_harmonic: usize,
    /// Minimum half width of a notch, Hz.
    pub min_half_width_hz: f64,
    /// Half width relative to the harmonic's frequency.
    pub rel_half_width: f64,
}

impl Default for NotchOptions {
    fn default() -> Self {
        Self {
            max_harmonic: 16,
            min_half_width_hz: 0.15,
            rel_half_width: 0.015,
        }
    }
}

/// The data with every rotor harmonic notched out.
pub fn notch_harmonics(
    x: &[f64],
    fs_hz: f64,
    rotor_hz: f64,
    opts: &NotchOptions,
) -> Result<Vec<f64>> {
    let mut y = x.to_vec();
    let nyq = 0.5 * fs_hz;
    for h in 1..=opts.max_harmonic {
        let f = h as f64 * rotor_hz;
        let hw = opts.min_half_width_hz.max(opts.rel_half_width * f);
        let mut a = f.rem_euclid(fs_hz);
        if a > nyq {
            a = fs_hz - a;
        }
        if a - hw <= 0.0 || a + hw >= nyq {
            continue;
        }
        let sos = butter(
            2,
            Band::Bandstop {
                low_hz: a - hw,
                high_hz: a + hw,
            },
            fs_hz,
        )?;
        sosfiltfilt_in_place(&sos, &mut y)?;
    }
    Ok(y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotor_harmonics_and_their_aliases_are_removed_and_slow_signal_kept() {
        let (fs, fr) = (100.0, 4.83);
        let n = 20_000;
        let slow = |t: f64| 2.0 * (0.05 * t).sin();
        // harmonics 1, 4 and 12 (58 Hz, aliased to 42 Hz)
        let x: Vec<f64> = (0..n)
            .map(|k| {
                let t = k as f64 / fs;
                let w = std::f64::consts::TAU * fr * t;
                slow(t) + w.cos() + 0.5 * (4.0 * w + 0.3).cos() + 0.3 * (12.0 * w).sin()
            })
            .collect();
        let y = notch_harmonics(&x, fs, fr, &NotchOptions::default()).unwrap();
        let err = (2000..n - 2000)
            .map(|k| (y[k] - slow(k as f64 / fs)).abs())
            .fold(0.0, f64::max);
        assert!(err < 0.01, "{err}");
    }
}
