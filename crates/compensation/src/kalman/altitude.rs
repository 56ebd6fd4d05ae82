//! The altitude of the field model's vertical-gradient term.
//!
//! The measurement of the Kalman method is `mag = H₁X₁ + B^h + Δz B_z + r`
//! with `Δz = alt − z0` (spec `compensation.md`, Method 2). The model takes
//! `Δz` as exact, so an error `ε` in the altitude enters the reading as
//! `ε B_z`. Over a calibration area with anomaly gradients this is not
//! small: the pitch manoeuvres move the sensor up and down by ±5–6 m, and a
//! GNSS altitude with 0.2 m of white noise (the simulator's default,
//! the navigation error model of `aeromag-sim`) times a vertical gradient of 0.05–0.15
//! nT/m is 0.01–0.03 nT of noise on a regressor that the likelihood uses to
//! tell the vertical gradient from the eddy-current terms. Measured on
//! simulated calibrations at 600 m over geology of 10 and 30 nT/100 m (seed
//! 1, survey interference-model error, ×10⁻³ nT): recorded altitude 15.5
//! and 206; the true altitude 5.7 and 6.9.
//!
//! The aircraft's height changes slowly (periods of seconds) while the
//! noise of a GNSS altitude is broad-band, so the altitude can be cleaned
//! without losing the manoeuvres:
//!
//! * **Blended with the vertical velocity** (when a down-velocity channel
//!   `vd` is recorded and agrees with the altitude): `Z(t) = −∫ v_d dt`
//!   (trapezoid) carries the fast motion, the altitude the slow one:
//!   `alt' = LP_fc(alt − Z) + Z`, `LP_fc` a zero-phase Butterworth low-pass
//!   of order 2 at the crossover `fc` (default 0.02 Hz). The velocity's
//!   white noise integrates to a few centimetres over `1/fc`. Same case as
//!   above: 7.2 and 7.2·10⁻³ nT.
//! * **Low-passed** otherwise: a zero-phase Butterworth low-pass of order 4
//!   at 1 Hz (the manoeuvres, 0.15–0.25 Hz, pass unchanged to 10⁻⁵). Same
//!   case: 6.1 and 11.0·10⁻³ nT.
//!
//! The velocity channel is used only when it agrees with the altitude
//! ([`check_down_velocity`]): over the band 0.02–0.5 Hz the altitude change
//! must follow `Z` with a slope within [0.8, 1.25] and a correlation of at
//! least 0.9 (a velocity recorded *up*, in other units or delayed fails
//! this).

use aeromag_core::filter::{Band, BandPass, butter, sosfiltfilt};

use crate::tolles_lawson::segments::{median_step, split_segments};

/// How the altitude is cleaned (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AltitudeSmoothing {
    /// Cutoff of the low-pass used without a velocity channel, Hz (default
    /// 1). Applied only where it is below 0.4× the sampling rate.
    pub lowpass_hz: f64,
    /// Crossover of the blend with the vertical velocity, Hz (default 0.02).
    pub crossover_hz: f64,
    /// Band of the agreement check, Hz (default 0.02–0.5).
    pub check_band_hz: (f64, f64),
    /// Accepted slope of the altitude change on `Z` (default 0.8–1.25).
    pub slope_range: (f64, f64),
    /// Least accepted correlation (default 0.9).
    pub min_correlation: f64,
}

impl Default for AltitudeSmoothing {
    fn default() -> Self {
        Self {
            lowpass_hz: 1.0,
            crossover_hz: 0.02,
            check_band_hz: (0.02, 0.5),
            slope_range: (0.8, 1.25),
            min_correlation: 0.9,
        }
    }
}

/// One contiguous stretch of navigation data.
#[derive(Debug, Clone, Copy)]
pub struct NavRun<'a> {
    /// Time, s (increasing, near-uniform steps).
    pub time: &'a [f64],
    /// Altitude, m.
    pub alt_m: &'a [f64],
    /// Down velocity, m/s (positive when descending), if recorded.
    pub down_velocity_m_s: Option<&'a [f64]>,
}

/// Agreement of the altitude with the integrated down velocity over the
/// check band.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VelocityCheck {
    /// Least-squares slope of the band-passed altitude on the band-passed
    /// `Z = −∫ v_d dt` (1 when they agree).
    pub slope: f64,
    /// Their correlation.
    pub correlation: f64,
    /// Samples compared.
    pub samples: usize,
    /// Whether the velocity is used (slope and correlation accepted).
    pub accepted: bool,
}

/// What [`smooth_altitude`] did to a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AltitudeSource {
    /// Left as recorded (too short or too low a sampling rate to filter).
    AsRecorded,
    /// Zero-phase low-pass at this cutoff, Hz.
    LowPass(f64),
    /// Blended with the integrated vertical velocity at this crossover, Hz.
    Blended(f64),
}

/// `Z_k = −∫₀^{t_k} v_d dt` by the trapezoid rule, m.
fn climb(time: &[f64], vd: &[f64]) -> Vec<f64> {
    let mut z = Vec::with_capacity(time.len());
    let mut acc = 0.0;
    for k in 0..time.len() {
        if k > 0 {
            acc -= 0.5 * (vd[k] + vd[k - 1]) * (time[k] - time[k - 1]);
        }
        z.push(acc);
    }
    z
}

/// Maximal stretches of `time` where `ok` holds (no split at time gaps: the
/// caller's runs are already split there).
fn usable_runs(time: &[f64], n: usize, ok: impl Fn(usize) -> bool) -> Vec<std::ops::Range<usize>> {
    let usable: Vec<bool> = (0..n).map(ok).collect();
    split_segments(&time[..n], None, &usable, f64::INFINITY, 1).0
}

/// Compare the altitude with the integrated down velocity over all `runs`
/// that record one (module docs). `None` when no run has a velocity channel
/// long enough to band-pass.
pub fn check_down_velocity(runs: &[NavRun<'_>], cfg: &AltitudeSmoothing) -> Option<VelocityCheck> {
    // Each run's band-passed climb and altitude (on the cores), then the
    // sums over every sample in run order.
    let filtered =
        aeromag_core::parallel::parallel_map(runs.len(), aeromag_core::parallel::threads(), |i| {
            let run = &runs[i];
            let mut out = Vec::new();
            let Some(vd) = run.down_velocity_m_s else {
                return out;
            };
            let n = run.time.len().min(run.alt_m.len()).min(vd.len());
            let ok =
                |k: usize| run.time[k].is_finite() && run.alt_m[k].is_finite() && vd[k].is_finite();
            for r in usable_runs(run.time, n, ok) {
                let t = &run.time[r.clone()];
                let dt = median_step(t);
                if dt <= 0.0 || cfg.check_band_hz.1 >= 0.45 / dt {
                    continue;
                }
                let Ok(bp) = BandPass::new(2, cfg.check_band_hz.0, cfg.check_band_hz.1, 1.0 / dt)
                else {
                    continue;
                };
                let z = climb(t, &vd[r.clone()]);
                if let (Ok(x), Ok(y)) = (bp.filter(&z), bp.filter(&run.alt_m[r.clone()])) {
                    out.push((x, y));
                }
            }
            out
        });
    let (mut sxy, mut sxx, mut syy, mut samples) = (0.0, 0.0, 0.0, 0usize);
    for (x, y) in filtered.iter().flatten() {
        for (a, b) in x.iter().zip(y) {
            sxy += a * b;
            sxx += a * a;
            syy += b * b;
        }
        samples += x.len();
    }
    if samples == 0 || sxx <= 0.0 || syy <= 0.0 {
        return None;
    }
    let slope = sxy / sxx;
    let correlation = sxy / (sxx * syy).sqrt();
    let accepted = (cfg.slope_range.0..=cfg.slope_range.1).contains(&slope)
        && correlation >= cfg.min_correlation;
    Some(VelocityCheck {
        slope,
        correlation,
        samples,
        accepted,
    })
}

/// The cleaned altitude of one run (module docs): blended with the down
/// velocity when `use_velocity` and the run records one, else low-passed.
/// Samples where the altitude (or the velocity, when blending) is not
/// finite keep their recorded value, and each finite stretch is filtered on
/// its own. Returns the altitude (m) and what was done to the longest
/// stretch.
pub fn smooth_altitude(
    run: &NavRun<'_>,
    use_velocity: bool,
    cfg: &AltitudeSmoothing,
) -> (Vec<f64>, AltitudeSource) {
    let n = run.time.len().min(run.alt_m.len());
    let mut out = run.alt_m[..n].to_vec();
    let vd = run.down_velocity_m_s.filter(|_| use_velocity);
    let ok = |k: usize| {
        run.time[k].is_finite()
            && run.alt_m[k].is_finite()
            && vd.is_none_or(|v| v.get(k).is_some_and(|x| x.is_finite()))
    };
    let mut longest = (0, AltitudeSource::AsRecorded);
    for r in usable_runs(run.time, n, ok) {
        let t = &run.time[r.clone()];
        let dt = median_step(t);
        if dt <= 0.0 {
            continue;
        }
        let fs = 1.0 / dt;
        let done = match vd {
            Some(vd) => butter(
                2,
                Band::Lowpass {
                    cutoff_hz: cfg.crossover_hz,
                },
                fs,
            )
            .ok()
            .and_then(|sos| {
                let z = climb(t, &vd[r.clone()]);
                let d: Vec<f64> = out[r.clone()].iter().zip(&z).map(|(a, z)| a - z).collect();
                let lp = sosfiltfilt(&sos, &d).ok()?;
                for (o, (l, z)) in out[r.clone()].iter_mut().zip(lp.iter().zip(&z)) {
                    *o = l + z;
                }
                Some(AltitudeSource::Blended(cfg.crossover_hz))
            }),
            None if cfg.lowpass_hz < 0.4 * fs => butter(
                4,
                Band::Lowpass {
                    cutoff_hz: cfg.lowpass_hz,
                },
                fs,
            )
            .ok()
            .and_then(|sos| {
                let lp = sosfiltfilt(&sos, &out[r.clone()]).ok()?;
                out[r.clone()].copy_from_slice(&lp);
                Some(AltitudeSource::LowPass(cfg.lowpass_hz))
            }),
            None => None,
        };
        if r.len() > longest.0 {
            longest = (r.len(), done.unwrap_or(AltitudeSource::AsRecorded));
        }
    }
    (out, longest.1)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 10 Hz run: pitch-like height oscillation (±6 m, 5 s period) on a
    /// slow climb, with the exact down velocity.
    fn run_truth(n: usize) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let w = std::f64::consts::TAU / 5.0;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 0.1).collect();
        let h: Vec<f64> = t
            .iter()
            .map(|&t| 600.0 + 0.05 * t + 6.0 * (w * t).sin())
            .collect();
        let vd: Vec<f64> = t
            .iter()
            .map(|&t| -(0.05 + 6.0 * w * (w * t).cos()))
            .collect();
        (t, h, vd)
    }

    /// Deterministic pseudo-random white noise in [−a√3, a√3] (RMS `a`).
    fn noise(n: usize, a: f64, seed: u64) -> Vec<f64> {
        let mut s = seed;
        (0..n)
            .map(|_| {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) * a * 3f64.sqrt()
            })
            .collect()
    }

    fn rms_error(a: &[f64], b: &[f64], skip: usize) -> f64 {
        let e: Vec<f64> = a.iter().zip(b).map(|(x, y)| x - y).collect();
        let e = &e[skip..e.len() - skip];
        (e.iter().map(|v| v * v).sum::<f64>() / e.len() as f64).sqrt()
    }

    #[test]
    fn blending_removes_white_altitude_noise_and_keeps_the_manoeuvres() {
        let n = 3000;
        let (t, h, vd) = run_truth(n);
        let alt: Vec<f64> = h.iter().zip(noise(n, 0.2, 1)).map(|(h, e)| h + e).collect();
        let vd_noisy: Vec<f64> = vd
            .iter()
            .zip(noise(n, 0.05, 2))
            .map(|(v, e)| v + e)
            .collect();
        let cfg = AltitudeSmoothing::default();
        let run = NavRun {
            time: &t,
            alt_m: &alt,
            down_velocity_m_s: Some(&vd_noisy),
        };
        let check = check_down_velocity(&[run], &cfg).unwrap();
        assert!(check.accepted, "{check:?}");
        assert!((check.slope - 1.0).abs() < 0.02, "{check:?}");
        let (blend, how) = smooth_altitude(&run, true, &cfg);
        assert_eq!(how, AltitudeSource::Blended(0.02));
        let (lp, how) = smooth_altitude(&run, false, &cfg);
        assert_eq!(how, AltitudeSource::LowPass(1.0));
        let raw = rms_error(&alt, &h, 100);
        let e_blend = rms_error(&blend, &h, 100);
        let e_lp = rms_error(&lp, &h, 100);
        // White 0.2 m; the 1 Hz low-pass keeps a fifth of the band
        // (0.2/√5 ≈ 0.09 m); the blend keeps far less.
        assert!((raw - 0.2).abs() < 0.01, "{raw}");
        assert!(e_lp < 0.11 && e_lp > 0.07, "{e_lp}");
        assert!(e_blend < 0.05, "{e_blend}");
    }

    #[test]
    fn noise_free_altitude_passes_unchanged() {
        let (t, h, vd) = run_truth(2000);
        let cfg = AltitudeSmoothing::default();
        let run = NavRun {
            time: &t,
            alt_m: &h,
            down_velocity_m_s: Some(&vd),
        };
        // The 5 s oscillation (0.2 Hz) passes both. The low-pass is exact to
        // 1 mm; the blend carries the trapezoid rule's gain error
        // (ωΔt)²/12 = 1.3·10⁻³ of the 6 m swing, ≈ 6 mm RMS.
        for (v, tol) in [(true, 7e-3), (false, 1e-3)] {
            let (s, _) = smooth_altitude(&run, v, &cfg);
            assert!(
                rms_error(&s, &h, 50) < tol,
                "{v}: {}",
                rms_error(&s, &h, 50)
            );
        }
    }

    #[test]
    fn a_velocity_recorded_up_is_rejected() {
        let (t, h, vd) = run_truth(2000);
        let up: Vec<f64> = vd.iter().map(|v| -v).collect();
        let cfg = AltitudeSmoothing::default();
        let run = NavRun {
            time: &t,
            alt_m: &h,
            down_velocity_m_s: Some(&up),
        };
        let c = check_down_velocity(&[run], &cfg).unwrap();
        assert!(!c.accepted && c.slope < -0.9, "{c:?}");
        let no_vd = NavRun {
            down_velocity_m_s: None,
            ..run
        };
        assert!(check_down_velocity(&[no_vd], &cfg).is_none());
    }

    #[test]
    fn gaps_are_kept_and_each_stretch_is_filtered_alone() {
        let (t, mut h, _) = run_truth(1000);
        h[500] = f64::NAN;
        let run = NavRun {
            time: &t,
            alt_m: &h,
            down_velocity_m_s: None,
        };
        let (s, how) = smooth_altitude(&run, false, &AltitudeSmoothing::default());
        assert!(s[500].is_nan());
        assert_eq!(s.iter().filter(|v| v.is_nan()).count(), 1);
        assert_eq!(how, AltitudeSource::LowPass(1.0));
        // 2 Hz sampling: a 1 Hz low-pass is not applied.
        let t2: Vec<f64> = (0..200).map(|k| k as f64 * 0.5).collect();
        let h2 = vec![600.0; 200];
        let run2 = NavRun {
            time: &t2,
            alt_m: &h2,
            down_velocity_m_s: None,
        };
        let (s2, how2) = smooth_altitude(&run2, false, &AltitudeSmoothing::default());
        assert_eq!(how2, AltitudeSource::AsRecorded);
        assert_eq!(s2, h2);
    }
}
