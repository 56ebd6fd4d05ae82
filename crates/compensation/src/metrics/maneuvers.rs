//! Detection of calibration manoeuvres (roll, pitch, yaw oscillations) from
//! the attitude record.
//!
//! A figure-of-merit flight flies 4 headings, and on each heading a series of
//! roll (±10°), pitch (±5°) and yaw (±5°) oscillations with periods of 4–6 s
//! (seed `000_…`, chapter 1; spec `compensation.md`, "Metrics"). Each angle
//! is detrended by subtracting its centred running mean over
//! [`ManeuverDetection::detrend_s`] seconds (yaw unwrapped first); the running
//! RMS of the remainder over [`ManeuverDetection::rms_window_s`] seconds says
//! how hard each axis is being exercised. A sample is a candidate for the
//! axis whose RMS, divided by that axis' threshold, is largest and above 1.
//!
//! A run of one axis is a manoeuvre only if the angle oscillates there: it
//! must have at least [`ManeuverDetection::min_extrema`] alternating extrema
//! whose swings exceed the axis threshold (a turn between legs is a ramp in
//! heading and is rejected). The window is then tightened to the oscillation
//! itself — from a quarter period before the first extremum to a quarter
//! period after the last — and kept if it lasts at least
//! [`ManeuverDetection::min_duration_s`]. Each window gets the circular mean
//! heading of its samples.

use crate::tolles_lawson::segments::median_step;
use serde::{Deserialize, Serialize};

/// Attitude axis of a manoeuvre.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, PartialOrd, Ord)]
#[serde(rename_all = "lowercase")]
pub enum Axis {
    /// Roll oscillation.
    Roll,
    /// Pitch oscillation.
    Pitch,
    /// Yaw oscillation.
    Yaw,
}

impl Axis {
    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            Axis::Roll => "roll",
            Axis::Pitch => "pitch",
            Axis::Yaw => "yaw",
        }
    }
}

/// Detector settings; defaults suit the standard FOM pattern.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ManeuverDetection {
    /// Running-mean length used to detrend the angles, s.
    pub detrend_s: f64,
    /// Running-RMS length, s.
    pub rms_window_s: f64,
    /// RMS thresholds (and minimum swings) for roll, pitch and yaw, degrees.
    pub threshold_deg: [f64; 3],
    /// Shortest window kept, s.
    pub min_duration_s: f64,
    /// Fewest alternating extrema (peaks and troughs) that make an oscillation.
    pub min_extrema: usize,
}

impl Default for ManeuverDetection {
    fn default() -> Self {
        // A ±10° sinusoid has RMS 7.1°, ±5° has 3.5°; straight flight in
        // light turbulence stays well below a third of these.
        Self {
            detrend_s: 12.0,
            rms_window_s: 6.0,
            threshold_deg: [2.5, 1.2, 1.2],
            min_duration_s: 8.0,
            min_extrema: 4,
        }
    }
}

/// One detected manoeuvre window (sample indices `start..end`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Maneuver {
    /// Axis exercised.
    pub axis: Axis,
    /// First sample.
    pub start: usize,
    /// One past the last sample.
    pub end: usize,
    /// Circular mean heading over the window, degrees in [0, 360).
    pub heading_deg: f64,
}

/// Centred running mean with window `w` samples (shrinking at the ends).
pub(crate) fn running_mean(x: &[f64], w: usize) -> Vec<f64> {
    let n = x.len();
    let h = w / 2;
    let mut prefix = vec![0.0; n + 1];
    for i in 0..n {
        prefix[i + 1] = prefix[i] + x[i];
    }
    (0..n)
        .map(|i| {
            let a = i.saturating_sub(h);
            let b = (i + h + 1).min(n);
            (prefix[b] - prefix[a]) / (b - a) as f64
        })
        .collect()
}

fn unwrap_deg(x: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(x.len());
    let mut offset = 0.0;
    for (i, &v) in x.iter().enumerate() {
        if i > 0 {
            let d = v - x[i - 1];
            if d > 180.0 {
                offset -= 360.0;
            } else if d < -180.0 {
                offset += 360.0;
            }
        }
        out.push(v + offset);
    }
    out
}

/// Find the manoeuvre windows in an attitude record (`time` s; angles in
/// degrees). Samples with a non-finite angle belong to no window.
pub fn detect_maneuvers(
    time: &[f64],
    roll_deg: &[f64],
    pitch_deg: &[f64],
    yaw_deg: &[f64],
    cfg: &ManeuverDetection,
) -> Vec<Maneuver> {
    let n = time.len();
    if n < 3 || roll_deg.len() != n || pitch_deg.len() != n || yaw_deg.len() != n {
        return Vec::new();
    }
    let dt = median_step(time);
    if dt.is_nan() || dt <= 0.0 {
        return Vec::new();
    }
    let samples = |s: f64| ((s / dt).round() as usize).max(1);
    let yaw_u = unwrap_deg(yaw_deg);
    let clean: [Vec<f64>; 3] = [roll_deg, pitch_deg, yaw_u.as_slice()].map(|a| {
        a.iter()
            .map(|v| if v.is_finite() { *v } else { 0.0 })
            .collect()
    });
    let finite =
        |i: usize| roll_deg[i].is_finite() && pitch_deg[i].is_finite() && yaw_deg[i].is_finite();
    let mut score = vec![[0.0f64; 3]; n];
    for (k, a) in clean.iter().enumerate() {
        let trend = running_mean(a, samples(cfg.detrend_s));
        let sq: Vec<f64> = a
            .iter()
            .zip(&trend)
            .map(|(v, t)| (v - t) * (v - t))
            .collect();
        let ms = running_mean(&sq, samples(cfg.rms_window_s));
        for i in 0..n {
            score[i][k] = if finite(i) {
                ms[i].sqrt() / cfg.threshold_deg[k]
            } else {
                0.0
            };
        }
    }
    let label = |s: &[f64; 3]| -> Option<Axis> {
        let (k, v) = s
            .iter()
            .enumerate()
            .fold((0, f64::MIN), |b, (k, &v)| if v > b.1 { (k, v) } else { b });
        (v > 1.0).then_some([Axis::Roll, Axis::Pitch, Axis::Yaw][k])
    };
    let mut out = Vec::new();
    let min_len = samples(cfg.min_duration_s);
    let smooth = samples(0.5);
    let mut i = 0;
    while i < n {
        let Some(axis) = label(&score[i]) else {
            i += 1;
            continue;
        };
        let start = i;
        while i < n && label(&score[i]) == Some(axis) {
            i += 1;
        }
        let k = axis as usize;
        let smoothed = running_mean(&clean[k][start..i], smooth);
        let ext = alternating_extrema(&smoothed, cfg.threshold_deg[k]);
        if ext.len() < cfg.min_extrema {
            continue;
        }
        let quarter = median_gap(&ext) / 2;
        let a = start + ext[0].saturating_sub(quarter);
        let b = (start + ext[ext.len() - 1] + quarter + 1).min(i);
        if b - a >= min_len {
            out.push(Maneuver {
                axis,
                start: a,
                end: b,
                heading_deg: circular_mean_deg(&yaw_deg[a..b]),
            });
        }
    }
    out
}

/// Indices of alternating extrema of `x` whose swing from the previous
/// extremum exceeds `swing` (peak detection with hysteresis; the starting
/// level is not counted).
fn alternating_extrema(x: &[f64], swing: f64) -> Vec<usize> {
    let mut ext = Vec::new();
    if x.is_empty() {
        return ext;
    }
    let (mut lo, mut hi) = (0usize, 0usize);
    let mut dir = 0i8; // +1 looking for a peak, −1 for a trough, 0 undecided
    for i in 0..x.len() {
        match dir {
            0 => {
                if x[i] < x[lo] {
                    lo = i;
                }
                if x[i] > x[hi] {
                    hi = i;
                }
                if x[hi] - x[lo] > swing {
                    // The starting level is not an extremum; look for the
                    // turning point in the direction of the first swing.
                    dir = if lo < hi { 1 } else { -1 };
                }
            }
            1 => {
                if x[i] > x[hi] {
                    hi = i;
                } else if x[hi] - x[i] > swing {
                    ext.push(hi);
                    dir = -1;
                    lo = i;
                }
            }
            _ => {
                if x[i] < x[lo] {
                    lo = i;
                } else if x[i] - x[lo] > swing {
                    ext.push(lo);
                    dir = 1;
                    hi = i;
                }
            }
        }
    }
    ext
}

fn median_gap(idx: &[usize]) -> usize {
    let mut g: Vec<usize> = idx.windows(2).map(|w| w[1] - w[0]).collect();
    if g.is_empty() {
        return 0;
    }
    g.sort_unstable();
    g[g.len() / 2]
}

/// Circular mean of angles in degrees, result in [0, 360).
pub fn circular_mean_deg(a: &[f64]) -> f64 {
    let (s, c) = a
        .iter()
        .filter(|v| v.is_finite())
        .fold((0.0, 0.0), |(s, c), v| {
            let r = v.to_radians();
            (s + r.sin(), c + r.cos())
        });
    s.atan2(c).to_degrees().rem_euclid(360.0)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Time, attitude series and the manoeuvres flown (axis, first and
    /// last sample, amplitude).
    type Fom = (Vec<f64>, [Vec<f64>; 3], Vec<(Axis, usize, usize, f64)>);

    /// A synthetic FOM flight at 10 Hz: 4 headings joined by standard-rate
    /// turns; on each heading straight flight, roll, pitch and yaw
    /// oscillations (5 s period, 4 cycles) separated by straight flight.
    pub(crate) fn synthetic_fom() -> Fom {
        let dt = 0.1;
        let (mut t, mut r, mut p, mut y) = (vec![], vec![], vec![], vec![]);
        let mut truth = vec![];
        let mut k = 0usize;
        for (h, heading) in [0.0, 90.0, 180.0, 270.0].into_iter().enumerate() {
            if h > 0 {
                // A standard-rate turn (3°/s, 25° bank) from the previous heading.
                for j in 0..300 {
                    t.push(k as f64 * dt);
                    r.push(25.0);
                    p.push(2.0);
                    y.push((heading - 90.0 + 0.3 * j as f64 + 360.0f64) % 360.0);
                    k += 1;
                }
            }
            let legs = [
                (None, 0.0),
                (Some(Axis::Roll), 10.0),
                (None, 0.0),
                (Some(Axis::Pitch), 5.0),
                (None, 0.0),
                (Some(Axis::Yaw), 5.0),
                (None, 0.0),
            ];
            for (axis, amp) in legs {
                let len = if axis.is_some() { 200 } else { 300 };
                let start = k;
                for j in 0..len {
                    let s = (2.0 * std::f64::consts::PI * j as f64 * dt / 5.0).sin() * amp;
                    let jitter = 0.3 * ((k as f64) * 0.37).sin();
                    t.push(k as f64 * dt);
                    r.push(if axis == Some(Axis::Roll) { s } else { jitter });
                    p.push(if axis == Some(Axis::Pitch) {
                        s
                    } else {
                        2.0 + 0.5 * jitter
                    });
                    y.push(
                        (heading + if axis == Some(Axis::Yaw) { s } else { jitter } + 360.0f64)
                            % 360.0,
                    );
                    k += 1;
                }
                if let Some(a) = axis {
                    truth.push((a, start, k, heading));
                }
            }
        }
        (t, [r, p, y], truth)
    }

    #[test]
    fn finds_the_twelve_windows_and_ignores_turns() {
        let (t, [r, p, y], truth) = synthetic_fom();
        let found = detect_maneuvers(&t, &r, &p, &y, &ManeuverDetection::default());
        assert_eq!(found.len(), 12, "{found:?}");
        for (m, (axis, s, e, h)) in found.iter().zip(&truth) {
            assert_eq!(m.axis, *axis);
            // Windows are found within a second of the truth.
            assert!((m.start as i64 - *s as i64).abs() <= 10, "{m:?} vs {s}");
            assert!((m.end as i64 - *e as i64).abs() <= 10, "{m:?} vs {e}");
            let dh = ((m.heading_deg - h + 540.0) % 360.0) - 180.0;
            assert!(dh.abs() < 2.0);
        }
    }

    #[test]
    fn straight_flight_has_no_windows() {
        let t: Vec<f64> = (0..3000).map(|i| i as f64 * 0.1).collect();
        let r: Vec<f64> = t.iter().map(|v| 0.5 * (v * 0.7).sin()).collect();
        let p = vec![1.0; 3000];
        let y = vec![359.9; 3000];
        assert!(detect_maneuvers(&t, &r, &p, &y, &ManeuverDetection::default()).is_empty());
    }

    #[test]
    fn extrema_with_hysteresis() {
        let x: Vec<f64> = (0..100).map(|i| (i as f64 * 0.2).sin() * 3.0).collect();
        let e = alternating_extrema(&x, 1.0);
        // sin(0.2 i) has extrema at i ≈ 8, 24, 39, 55, 71, 86.
        assert_eq!(e.len(), 6, "{e:?}");
        for (got, want) in e.iter().zip([8, 24, 39, 55, 71, 86]) {
            assert!((*got as i64 - want).abs() <= 1, "{e:?}");
        }
        assert!(alternating_extrema(&[1.0; 10], 0.1).is_empty());
    }

    #[test]
    fn circular_mean_across_north() {
        let m = circular_mean_deg(&[350.0, 10.0]);
        assert!(m.min(360.0 - m) < 1e-9);
        assert!((circular_mean_deg(&[80.0, 100.0]) - 90.0).abs() < 1e-9);
    }
}
