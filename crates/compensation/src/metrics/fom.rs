//! Figure of merit (FOM).
//!
//! The FOM is the sum, over the manoeuvre windows of a calibration flight
//! (normally 4 headings × roll, pitch, yaw = 12 windows), of the peak-to-peak
//! amplitude of the (compensated) signal within each window after removing
//! the window's least-squares linear trend (spec `compensation.md`,
//! "Metrics"). Units: those of the signal (nT).
//!
//! What goes in matters: the compensated reading still contains the external
//! field, whose variation within a 20 s window (micropulsations, the main
//! field's vertical gradient during pitch manoeuvres, geology) is not
//! interference. As in acceptance practice, callers pass the signal reduced
//! by the known external channels (base station, IGRF) and band-passed with
//! the fit's band ([`super::band_pass_segments`]); the CLI does so.

use super::maneuvers::{Axis, Maneuver};
use serde::{Deserialize, Serialize};

/// One window's contribution.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FomWindow {
    /// The manoeuvre.
    pub maneuver: Maneuver,
    /// Peak-to-peak of the detrended signal, nT.
    pub peak_to_peak_nt: f64,
}

/// The FOM and its parts.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FomReport {
    /// Sum of the windows' peak-to-peak amplitudes, nT.
    pub fom_nt: f64,
    /// Each window.
    pub windows: Vec<FomWindow>,
}

impl FomReport {
    /// Sum of the windows of one axis, nT.
    pub fn axis_sum_nt(&self, axis: Axis) -> f64 {
        self.windows
            .iter()
            .filter(|w| w.maneuver.axis == axis)
            .map(|w| w.peak_to_peak_nt)
            .sum()
    }
}

/// Peak-to-peak of `y` after removing its least-squares line over `t`
/// (non-finite samples skipped). `None` with fewer than 3 finite samples.
pub fn detrended_peak_to_peak(t: &[f64], y: &[f64]) -> Option<f64> {
    let pts: Vec<(f64, f64)> = t
        .iter()
        .zip(y)
        .filter(|(a, b)| a.is_finite() && b.is_finite())
        .map(|(a, b)| (*a, *b))
        .collect();
    if pts.len() < 3 {
        return None;
    }
    let n = pts.len() as f64;
    let tm = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let ym = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let stt: f64 = pts.iter().map(|p| (p.0 - tm) * (p.0 - tm)).sum();
    let sty: f64 = pts.iter().map(|p| (p.0 - tm) * (p.1 - ym)).sum();
    let slope = if stt > 0.0 { sty / stt } else { 0.0 };
    let (lo, hi) = pts
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            let r = p.1 - ym - slope * (p.0 - tm);
            (lo.min(r), hi.max(r))
        });
    Some(hi - lo)
}

/// FOM of `signal` (nT) over the given windows (sample indices into `time`).
pub fn figure_of_merit(time: &[f64], signal: &[f64], windows: &[Maneuver]) -> FomReport {
    let windows: Vec<FomWindow> = windows
        .iter()
        .filter(|m| m.end <= time.len() && m.end <= signal.len() && m.start < m.end)
        .filter_map(|m| {
            detrended_peak_to_peak(&time[m.start..m.end], &signal[m.start..m.end]).map(|pp| {
                FomWindow {
                    maneuver: *m,
                    peak_to_peak_nt: pp,
                }
            })
        })
        .collect();
    FomReport {
        fom_nt: windows.iter().map(|w| w.peak_to_peak_nt).sum(),
        windows,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::maneuvers::{ManeuverDetection, detect_maneuvers, tests::synthetic_fom};

    #[test]
    fn trend_is_removed() {
        let t: Vec<f64> = (0..100).map(|i| i as f64).collect();
        let y: Vec<f64> = t.iter().map(|v| 3.0 * v + 7.0).collect();
        assert!(detrended_peak_to_peak(&t, &y).unwrap() < 1e-9);
        let z: Vec<f64> = t
            .iter()
            .map(|v| 3.0 * v + if *v == 50.0 { 1.0 } else { 0.0 })
            .collect();
        assert!((detrended_peak_to_peak(&t, &z).unwrap() - 1.0).abs() < 0.02);
    }

    #[test]
    fn fom_of_an_interference_tied_to_roll() {
        let (t, [r, p, y], truth) = synthetic_fom();
        let windows = detect_maneuvers(&t, &r, &p, &y, &ManeuverDetection::default());
        // Signal = 0.2 nT per degree of roll: only roll windows contribute,
        // as much as over the true windows (each ≈ 4 nT, a little more
        // because a line fitted to whole sine cycles has a slope).
        let s: Vec<f64> = r.iter().map(|v| 0.2 * v).collect();
        let fom = figure_of_merit(&t, &s, &windows);
        let expect: f64 = truth
            .iter()
            .filter(|w| w.0 == Axis::Roll)
            .map(|w| detrended_peak_to_peak(&t[w.1..w.2], &s[w.1..w.2]).unwrap())
            .sum();
        assert!((16.0..20.0).contains(&expect));
        let got = fom.axis_sum_nt(Axis::Roll);
        assert!((got - expect).abs() < 0.02 * expect, "{got} vs {expect}");
        assert!(fom.axis_sum_nt(Axis::Pitch) < 0.5);
        assert_eq!(fom.windows.len(), 12);
    }
}
