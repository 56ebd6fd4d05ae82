//! Baseline (c): rotor-phase synchronous averaging (spec `helicopter.md`
//! part A). In consecutive blocks of `block_s`, the high-passed data are
//! averaged in `bins` bins of the rotor phase `ψ mod 2π`; the bin means
//! (linearly interpolated in phase, periodic) form the block's template,
//! which is subtracted. It removes everything locked to the rotor phase in
//! the block — but not the slow part of the rotor field, nor its changes
//! within a block (coning, rotor speed, heading).

use super::linear::highpass;
use crate::error::{CompError, Result};

/// The template `x̂(ψ)` of every sample (the baseline's interference
/// estimate), from data `x` and the unwrapped phase `phase_rad`.
pub fn synchronous_template(
    x: &[f64],
    phase_rad: &[f64],
    fs_hz: f64,
    bins: usize,
    block_s: f64,
    highpass_hz: f64,
) -> Result<Vec<f64>> {
    let n = x.len();
    if phase_rad.len() != n || bins < 2 || block_s.is_nan() || block_s <= 0.0 {
        return Err(CompError::data(
            "synchronous averaging: lengths differ, < 2 bins or block ≤ 0",
        ));
    }
    let y = highpass(x, fs_hz, highpass_hz)?;
    let block = ((block_s * fs_hz).round() as usize).max(bins);
    let tau = std::f64::consts::TAU;
    let pos = |p: f64| p.rem_euclid(tau) / tau * bins as f64;
    let mut out = vec![0.0; n];
    let mut start = 0;
    while start < n {
        let end = (start + block).min(n);
        let (mut sum, mut cnt) = (vec![0.0; bins], vec![0usize; bins]);
        for k in start..end {
            let b = (pos(phase_rad[k]) as usize).min(bins - 1);
            sum[b] += y[k];
            cnt[b] += 1;
        }
        let mut mean: Vec<Option<f64>> = sum
            .iter()
            .zip(&cnt)
            .map(|(s, c)| (*c > 0).then(|| s / *c as f64))
            .collect();
        // Empty bins (a rotor speed nearly commensurate with the sampling)
        // take the nearest filled bin's mean.
        let filled: Vec<usize> = (0..bins).filter(|b| mean[*b].is_some()).collect();
        if filled.is_empty() {
            mean.iter_mut().for_each(|m| *m = Some(0.0));
        }
        let mean: Vec<f64> = (0..bins)
            .map(|b| {
                mean[b].unwrap_or_else(|| {
                    let near = filled
                        .iter()
                        .min_by_key(|f| {
                            let d = f.abs_diff(b);
                            d.min(bins - d)
                        })
                        .copied()
                        .unwrap_or(b);
                    mean[near].unwrap_or(0.0)
                })
            })
            .collect();
        for k in start..end {
            // bin centres at (b + 0.5); periodic linear interpolation
            let u = pos(phase_rad[k]) - 0.5;
            let i0 = u.floor();
            let w = u - i0;
            let a = (i0 as i64).rem_euclid(bins as i64) as usize;
            let b = (a + 1) % bins;
            out[k] = (1.0 - w) * mean[a] + w * mean[b];
        }
        start = end;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_phase_locked_waveform_is_removed() {
        let fs = 100.0;
        let n = 6000;
        let phase: Vec<f64> = (0..n).map(|k| 30.0 * k as f64 / fs).collect();
        let wave = |p: f64| (4.0 * p).cos() + 0.3 * (p + 1.0).sin();
        let x: Vec<f64> = phase.iter().map(|p| wave(*p)).collect();
        let t = synchronous_template(&x, &phase, fs, 64, 10.0, 2.0).unwrap();
        let rms = |f: &dyn Fn(usize) -> f64| {
            ((500..n - 500).map(|k| f(k).powi(2)).sum::<f64>() / (n - 1000) as f64).sqrt()
        };
        let left = rms(&|k| x[k] - t[k]) / rms(&|k| x[k]);
        // ≥ 97 % of the phase-locked waveform removed (bin width limits it)
        assert!(left < 0.03, "{left}");
        assert!(synchronous_template(&x, &phase[1..], fs, 128, 10.0, 2.0).is_err());
    }
}
