//! Rotor frequency and phase from the data when no phase channel exists
//! (spec `helicopter.md` part A: "spectral peak, then a nonlinear
//! refinement"), and the rotor speed from a phase channel.
//!
//! 1. **Spectral peak.** The blade-passing frequency `f_bp = N f_r` is the
//!    largest peak of the Welch spectrum (Hann, 20 s segments) of the
//!    high-passed scalar data inside `[N f_min, N f_max]`, refined by a
//!    parabola through the log-power of the three bins around the peak.
//! 2. **Phase tracking.** Complex demodulation at `f_bp`:
//!    `z(t) = LP[x(t) e^{−i 2π f_bp t}]` (4th-order zero-phase low-pass at
//!    `0.25 f_r`, which keeps the ±1 % speed wander and rejects the
//!    neighbouring rotor harmonics); `N ψ(t) + φ0 = unwrap(arg z) + 2π f_bp t`.
//!    This requires `f_bp` below the Nyquist frequency. The mean rotor
//!    frequency is then the slope of `ψ(t)` (finer than the Welch bin).
//! 3. **Nonlinear refinement.** The offset `φ0/N ∈ [0, 2π/N)` (which blade
//!    is "blade 0" does not matter with per-blade parameters) is found by
//!    minimising the rotor-model fit residual over a grid and a
//!    golden-section search ([`super::refine_phase_offset`]).

use aeromag_core::error::{fixed, shown};
use aeromag_core::filter::{Band, butter, sosfiltfilt};
use aeromag_core::spectrum::welch::{WelchConfig, welch};

use super::linear::highpass;
use crate::error::{CompError, Result};

/// Unwrap a recorded phase channel (deg, any wrap) into radians.
pub fn unwrap_deg(phase_deg: &[f64]) -> Vec<f64> {
    unwrap_rad(&phase_deg.iter().map(|d| d.to_radians()).collect::<Vec<_>>())
}

/// Unwrap a phase series (rad): add multiples of 2π so that consecutive
/// samples differ by less than π.
pub fn unwrap_rad(phase: &[f64]) -> Vec<f64> {
    let mut out: Vec<f64> = Vec::with_capacity(phase.len());
    let mut offset: f64 = 0.0;
    for (k, &p) in phase.iter().enumerate() {
        if k > 0 {
            let d: f64 = p + offset - out[k - 1];
            offset -= std::f64::consts::TAU * (d / std::f64::consts::TAU).round();
        }
        out.push(p + offset);
    }
    out
}

/// Rotor speed `dψ/dt` (rad/s) from an unwrapped phase: central differences
/// low-passed at `cutoff_hz` (zero phase, 4th order).
pub fn rotor_speed(phase_rad: &[f64], fs_hz: f64, cutoff_hz: f64) -> Result<Vec<f64>> {
    let n = phase_rad.len();
    if n < 3 {
        return Err(CompError::data("rotor phase: fewer than 3 samples"));
    }
    let d: Vec<f64> = (0..n)
        .map(|k| {
            let (a, b) = (k.saturating_sub(1), (k + 1).min(n - 1));
            (phase_rad[b] - phase_rad[a]) * fs_hz / (b - a) as f64
        })
        .collect();
    let sos = butter(4, Band::Lowpass { cutoff_hz }, fs_hz)?;
    Ok(sosfiltfilt(&sos, &d)?)
}

/// A recorded rotor phase (unwrapped, rad) with its white noise filtered
/// out: the linear trend plus the detrended phase low-passed at
/// `cutoff_hz` (zero phase, 4th order). The rotor's speed changes over
/// seconds, so a cutoff of 1–2 Hz keeps its phase and divides white
/// recording noise by `√(fs / 2 f_c)`. What the tail rotor's phase is
/// derived from: the gear ratio multiplies the channel's noise.
pub fn smooth_phase(phase_rad: &[f64], fs_hz: f64, cutoff_hz: f64) -> Result<Vec<f64>> {
    let n = phase_rad.len();
    if n < 3 {
        return Err(CompError::data("rotor phase: fewer than 3 samples"));
    }
    let slope = (phase_rad[n - 1] - phase_rad[0]) / (n - 1) as f64;
    let trend = |k: usize| phase_rad[0] + slope * k as f64;
    let detrended: Vec<f64> = (0..n).map(|k| phase_rad[k] - trend(k)).collect();
    let sos = butter(4, Band::Lowpass { cutoff_hz }, fs_hz)?;
    Ok(sosfiltfilt(&sos, &detrended)?
        .iter()
        .enumerate()
        .map(|(k, d)| trend(k) + d)
        .collect())
}

/// A rotor phase estimated from the scalar data.
#[derive(Debug, Clone, PartialEq)]
pub struct PhaseEstimate {
    /// Mean rotor frequency, Hz.
    pub rotor_hz: f64,
    /// `ψ(t)` up to a constant in `[0, 2π/N)`, rad, unwrapped.
    pub phase_rad: Vec<f64>,
}

/// Steps 1–2 of the module docs: rotor frequency from the spectral peak of
/// the blade-passing harmonic in `[blades·f_min_hz, blades·f_max_hz]`, then
/// phase tracking by complex demodulation.
pub fn estimate_phase(
    mag_nt: &[f64],
    fs_hz: f64,
    blades: usize,
    f_min_hz: f64,
    f_max_hz: f64,
) -> Result<PhaseEstimate> {
    let nb = blades as f64;
    if blades < 2 || !(f_min_hz > 0.0 && f_max_hz > f_min_hz) {
        return Err(CompError::setting(format!(
            "rotor phase: {blades} blades and the rotor band {}–{} Hz: need at least 2 blades and 0 < f_min < f_max",
            shown(f_min_hz),
            shown(f_max_hz)
        )));
    }
    if nb * f_max_hz >= 0.5 * fs_hz {
        return Err(CompError::setting(format!(
            "rotor phase: {blades} blades of a rotor turning at up to {} Hz pass at up to {} Hz, \
             at or above the Nyquist frequency ({} Hz of the {} Hz sampling): the blade passing \
             cannot be found in data sampled this slowly",
            shown(f_max_hz),
            fixed(nb * f_max_hz, 2),
            fixed(0.5 * fs_hz, 2),
            fixed(fs_hz, 2)
        )));
    }
    let x = highpass(mag_nt, fs_hz, 0.5 * f_min_hz)?;
    let nper = ((20.0 * fs_hz) as usize).min(x.len());
    let psd = welch(&x, &WelchConfig::new(fs_hz, nper))?;
    let (lo, hi) = (nb * f_min_hz, nb * f_max_hz);
    let best = psd
        .freqs_hz
        .iter()
        .enumerate()
        .filter(|(_, f)| **f >= lo && **f <= hi)
        .max_by(|a, b| psd.values[a.0].total_cmp(&psd.values[b.0]))
        .map(|(i, _)| i)
        .ok_or_else(|| CompError::data("rotor phase: no spectral bin in the search band"))?;
    // The band's largest power must be a peak, not the flank of a line
    // outside the band (a band below the rotor's found its second
    // harmonic's flank at the band's edge, and the tracking then followed
    // that line out of the band).
    if let Some(up) = [best.wrapping_sub(1), best + 1]
        .into_iter()
        .filter(|&i| i < psd.values.len() && psd.values[i] > psd.values[best])
        .max_by(|&a, &b| psd.values[a].total_cmp(&psd.values[b]))
    {
        return Err(CompError::data(format!(
            "rotor phase: no blade-passing peak between {} and {} Hz ({blades} blades × the rotor band \
             {}–{} Hz): the spectrum of the reading rises towards {} Hz, outside the band; is the \
             rotor's frequency within the band?",
            fixed(lo, 2),
            fixed(hi, 2),
            shown(f_min_hz),
            shown(f_max_hz),
            fixed(psd.freqs_hz[up], 2)
        )));
    }
    let df = psd.freqs_hz[1] - psd.freqs_hz[0];
    let mut f_bp = psd.freqs_hz[best];
    if best > 0 && best + 1 < psd.values.len() {
        let l = |i: usize| psd.values[i].max(1e-300).ln();
        let (a, b, c) = (l(best - 1), l(best), l(best + 1));
        let den = a - 2.0 * b + c;
        if den < 0.0 {
            f_bp += 0.5 * (a - c) / den * df;
        }
    }
    let f_r = f_bp / nb;
    let sos = butter(
        4,
        Band::Lowpass {
            cutoff_hz: 0.25 * f_r,
        },
        fs_hz,
    )?;
    let w = std::f64::consts::TAU * f_bp / fs_hz;
    let re: Vec<f64> = x
        .iter()
        .enumerate()
        .map(|(k, v)| v * (w * k as f64).cos())
        .collect();
    let im: Vec<f64> = x
        .iter()
        .enumerate()
        .map(|(k, v)| -v * (w * k as f64).sin())
        .collect();
    let (re, im) = (sosfiltfilt(&sos, &re)?, sosfiltfilt(&sos, &im)?);
    let arg: Vec<f64> = re.iter().zip(&im).map(|(r, i)| i.atan2(*r)).collect();
    let phase: Vec<f64> = unwrap_rad(&arg)
        .iter()
        .enumerate()
        .map(|(k, p)| (p + w * k as f64) / nb)
        .collect();
    // Mean frequency from the tracked phase (finer than the spectral bin),
    // ignoring a tenth of the record at each end (filter transients).
    let (a, b) = (phase.len() / 10, phase.len() - 1 - phase.len() / 10);
    let rotor_hz = if b > a {
        (phase[b] - phase[a]) * fs_hz / ((b - a) as f64 * std::f64::consts::TAU)
    } else {
        f_r
    };
    // The tracking follows the strongest line near f_bp; one Welch bin of
    // blade passing is the spectral peak's own resolution.
    let slack = df / nb;
    if !(rotor_hz >= f_min_hz - slack && rotor_hz <= f_max_hz + slack) {
        return Err(CompError::data(format!(
            "rotor phase: the rotor tracked from the blade-passing peak at {} Hz turns at {} Hz, \
             outside the rotor band {}–{} Hz: the peak is not this rotor's blade passing",
            fixed(f_bp, 2),
            fixed(rotor_hz, 4),
            shown(f_min_hz),
            shown(f_max_hz)
        )));
    }
    Ok(PhaseEstimate {
        rotor_hz,
        phase_rad: phase,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn demodulation_tracks_a_wandering_rotor() {
        // Four blades, 4.8 Hz ± 1 %, a blade-passing pulse train + 1/rev.
        let fs = 100.0;
        let n = 6000;
        let mut psi = 0.3;
        let mut truth = Vec::with_capacity(n);
        let mut x = Vec::with_capacity(n);
        for k in 0..n {
            let t = k as f64 / fs;
            let f = 4.8 * (1.0 + 0.01 * (0.2 * t).sin());
            psi += std::f64::consts::TAU * f / fs;
            truth.push(psi);
            x.push(
                3.0 * (4.0 * psi + 0.7).cos()
                    + 1.0 * (psi + 0.2).cos()
                    + 0.4 * (8.0 * psi).cos()
                    + 0.01 * t,
            );
        }
        let est = estimate_phase(&x, fs, 4, 4.5, 5.1).unwrap();
        let mean_hz =
            (truth[n - 601] - truth[600]) * fs / ((n - 1201) as f64 * std::f64::consts::TAU);
        assert!(
            (est.rotor_hz - mean_hz).abs() < 2e-3,
            "{} vs {mean_hz}",
            est.rotor_hz
        );
        // ψ̂ − ψ is constant (modulo the blade ambiguity) away from the ends.
        let d: Vec<f64> = (500..n - 500)
            .map(|k| est.phase_rad[k] - truth[k])
            .collect();
        let m = d.iter().sum::<f64>() / d.len() as f64;
        let dev = d.iter().map(|v| (v - m).abs()).fold(0.0, f64::max);
        assert!(dev < 0.01, "phase wander {dev} rad");
        assert!(estimate_phase(&x, fs, 4, 5.1, 4.5).is_err());
    }

    #[test]
    fn unwrap_and_speed() {
        let fs = 100.0;
        let p: Vec<f64> = (0..1000)
            .map(|k| (30.0 * k as f64 / fs).to_degrees().rem_euclid(360.0))
            .collect();
        let u = unwrap_deg(&p);
        let w = rotor_speed(&u, fs, 1.0).unwrap();
        assert!(w[100..900].iter().all(|v| (v - 30.0).abs() < 1e-6));
    }
}
