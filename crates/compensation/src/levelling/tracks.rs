//! The survey samples seen by levelling, their segmentation into tracks, and
//! the along-track time derivative `Ḃ` of the measured field (the regressor
//! of the `k·d|B0|/dt` term, seed `000_…` §9).
//!
//! A *track segment* is a maximal run of consecutive rows with the same
//! line label (> 0), finite time and value, and no time step larger than
//! `max_gap_factor` × the median step (the same rule as the Tolles-Lawson
//! fits, [`crate::tolles_lawson::segments::split_segments`]).
//!
//! **Derivative.** At row `i` of a segment, `Ḃ_i` is the slope of the
//! least-squares straight line through the samples `(t_j, m_j)` of the same
//! segment with `|t_j − t_i| ≤ w` (`w` = `derivative_half_window_s`), always
//! including the immediate neighbours:
//!
//! ```text
//! Ḃ_i = Σ (t_j − t̄)(m_j − m̄) / Σ (t_j − t̄)²      (nT/s)
//! ```
//!
//! The series differentiated is [`SurveyTracks::sensed`] when given, else
//! the levelled value. A lag of the scalar channel (the physical origin of
//! the term, [`super`]) acts on everything the sensor sees, the aircraft's
//! own interference included, so the regressor is the derivative of the
//! uncompensated reading: the compensated series lacks the interference's
//! rate, whose lag stays in it. On the demo surveys (lag `τ` = 0.1 s) the
//! true lag term differs from `−τ·Ḃ` by 0.048–0.051 nT RMS at the
//! crossovers with `Ḃ` from the compensated series and by 0.008 nT with `Ḃ`
//! from the uncompensated one (demo seeds 1 and 5); over 25 simulated
//! surveys the spread of `k` drops from 6.0 to 4.9 % and the worst error
//! from 13 to 9.6 % (measured with the simulator's truth columns, which
//! this code never reads).
//!
//! With `w` below one sample step this is the central difference
//! `(m_{i+1} − m_{i−1})/(t_{i+1} − t_{i−1})` (one-sided at segment ends).
//! Wider windows reduce the noise (variance `σ²/Σ(t_j − t̄)²`, 5× lower than
//! the central difference for 5 samples) at the cost of a bias on short
//! wavelengths: for a sinusoid of angular frequency `ω` and a symmetric
//! window of half-width `w` the slope is multiplied by
//! `3 (sin ωw − ωw cos ωw)/(ωw)³ ≈ 1 − (ωw)²/10`. The default `w = 0.2 s`
//! (5 samples at 10 Hz; 14 m at 70 m/s) keeps that below 1 % for
//! along-track wavelengths above 300 m, which is the shortest wavelength of
//! an anomaly seen from 100 m above its sources.

use crate::error::{CompError, Result};
use crate::tolles_lawson::segments::split_segments;
use aeromag_core::frames::{Attitude, Geodetic};
use nalgebra::Vector3;
use std::ops::Range;

/// The survey samples used by levelling: `N` rows, all slices of length `N`.
#[derive(Debug, Clone, Copy)]
pub struct SurveyTracks<'a> {
    /// Time, s (increasing within a line).
    pub time: &'a [f64],
    /// Latitude, degrees (WGS84).
    pub lat: &'a [f64],
    /// Longitude, degrees.
    pub lon: &'a [f64],
    /// Altitude, m (reported at the crossovers; may be NaN).
    pub alt: &'a [f64],
    /// Line label: an integer > 0 on survey and tie lines, 0 (or NaN) in
    /// turns and transits.
    pub line: &'a [f64],
    /// The (compensated) field to level, nT.
    pub value: &'a [f64],
    /// The total field the sensor saw, nT (normally the uncompensated
    /// `mag`), whose along-track derivative is the regressor `Ḃ` of the
    /// `k·d|B0|/dt` term; `None`: the derivative of `value`. See the module
    /// docs for why the uncompensated reading is the right one.
    pub sensed: Option<&'a [f64]>,
}

/// Track segmentation, derivative and crossover geometry settings.
#[derive(Debug, Clone, PartialEq)]
pub struct TrackConfig {
    /// A time step larger than this multiple of the median step is a gap.
    /// Default 5.
    pub max_gap_factor: f64,
    /// Half-width `w` of the derivative window, s (see module docs).
    /// Default 0.2.
    pub derivative_half_window_s: f64,
    /// Crossings at an angle below this (deg, 0–90) are skipped: the
    /// interpolated values are too sensitive to position errors. Default 20.
    pub min_crossing_angle_deg: f64,
    /// Which pairs of lines are crossed. Default: any two different labels.
    pub pairing: Pairing,
}

/// Which crossings of two track segments are crossovers.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum Pairing {
    /// Any two segments of different labels (lines whose type is unknown).
    #[default]
    AnyTwoLines,
    /// Only a survey line with a tie line: the labels in `tie_ids` are
    /// ties, all others survey lines.
    LineWithTie {
        /// Labels of the tie lines.
        tie_ids: Vec<i64>,
    },
}

impl Pairing {
    /// Whether segments labelled `a` and `b` (`a ≠ b`) are crossed.
    pub fn crosses(&self, a: i64, b: i64) -> bool {
        match self {
            Pairing::AnyTwoLines => true,
            Pairing::LineWithTie { tie_ids } => tie_ids.contains(&a) != tie_ids.contains(&b),
        }
    }
}

impl Default for TrackConfig {
    fn default() -> Self {
        Self {
            max_gap_factor: 5.0,
            derivative_half_window_s: 0.2,
            min_crossing_angle_deg: 20.0,
            pairing: Pairing::AnyTwoLines,
        }
    }
}

impl TrackConfig {
    pub(crate) fn validate(&self) -> Result<()> {
        if !(self.max_gap_factor.is_finite() && self.max_gap_factor > 1.0) {
            return Err(bad(format!(
                "max_gap_factor {} must be finite and > 1",
                self.max_gap_factor
            )));
        }
        if !(self.derivative_half_window_s.is_finite() && self.derivative_half_window_s >= 0.0) {
            return Err(bad(format!(
                "derivative_half_window_s {} must be finite and ≥ 0",
                self.derivative_half_window_s
            )));
        }
        if !(0.0..90.0).contains(&self.min_crossing_angle_deg) {
            return Err(bad(format!(
                "min_crossing_angle_deg {} must be in [0, 90)",
                self.min_crossing_angle_deg
            )));
        }
        Ok(())
    }
}

impl SurveyTracks<'_> {
    /// Number of rows.
    pub fn len(&self) -> usize {
        self.time.len()
    }

    /// Whether there are no rows.
    pub fn is_empty(&self) -> bool {
        self.time.is_empty()
    }

    /// Check that every slice has the same length and that every finite line
    /// label is an integer (error naming the first bad row).
    pub fn validate(&self) -> Result<()> {
        let n = self.len();
        for (name, s) in [
            ("lat", self.lat),
            ("lon", self.lon),
            ("alt", self.alt),
            ("line", self.line),
            ("value", self.value),
            ("sensed", self.sensed.unwrap_or(self.value)),
        ] {
            if s.len() != n {
                return Err(bad(format!(
                    "column `{name}` has {} rows, `time` has {n}",
                    s.len()
                )));
            }
        }
        if let Some(i) = self
            .line
            .iter()
            .position(|&l| l.is_finite() && (l.fract() != 0.0 || l.abs() > 9.0e15))
        {
            return Err(bad(format!(
                "row {i}: line label {} is not an integer",
                self.line[i]
            )));
        }
        Ok(())
    }

    /// The line label of row `i`: `Some(label)` for a finite label > 0.
    pub fn label(&self, i: usize) -> Option<i64> {
        let l = self.line[i];
        (l.is_finite() && l >= 1.0).then_some(l as i64)
    }

    /// Track segments (see module docs): row ranges on one line each. A row
    /// whose value or sensed reading is missing ends a segment, so it never
    /// enters a neighbour's derivative window.
    pub fn segments(&self, cfg: &TrackConfig) -> Vec<Range<usize>> {
        let usable: Vec<bool> = (0..self.len())
            .map(|i| {
                self.time[i].is_finite()
                    && self.value[i].is_finite()
                    && self.sensed.is_none_or(|s| s[i].is_finite())
                    && self.label(i).is_some()
            })
            .collect();
        split_segments(self.time, Some(self.line), &usable, cfg.max_gap_factor, 1).0
    }
}

/// Positions of a sensor mounted at `lever_arm_m` (body frame: x forward,
/// y right wing, z down; m) from the navigation reference point whose
/// positions (`lat`, `lon` in degrees, `alt` in m) and attitude (degrees,
/// Z-Y-X) are recorded: `p_sensor = p_nav + C_nb r_b` (NED), returned as
/// `[lat, lon, alt]` (NaN where an input is missing).
///
/// Crossovers must be computed at the *sensor's* positions: with the
/// reference point's positions, a lever arm `ℓ` along the track shifts the
/// sample `ℓ/v` in time and appears as an extra derivative term,
/// `k_apparent = k + ℓ_x/v` (−0.14 s for a stinger 9.5 m behind the
/// reference at 70 m/s), which changes with the ground speed.
pub fn sensor_positions(
    lat: &[f64],
    lon: &[f64],
    alt: &[f64],
    roll_deg: &[f64],
    pitch_deg: &[f64],
    yaw_deg: &[f64],
    lever_arm_m: [f64; 3],
) -> Result<[Vec<f64>; 3]> {
    crate::reference_field::check_lever_arm(lever_arm_m)?;
    let n = lat.len();
    for (name, c) in [
        ("lon", lon),
        ("alt", alt),
        ("roll", roll_deg),
        ("pitch", pitch_deg),
        ("yaw", yaw_deg),
    ] {
        if c.len() != n {
            return Err(bad(format!(
                "column `{name}` has {} rows, `lat` has {n}",
                c.len()
            )));
        }
    }
    if lever_arm_m.iter().any(|v| !v.is_finite()) {
        return Err(bad(format!("lever arm {lever_arm_m:?} is not finite")));
    }
    let r_b = Vector3::from(lever_arm_m);
    let mut out = [vec![f64::NAN; n], vec![f64::NAN; n], vec![f64::NAN; n]];
    for i in 0..n {
        let r_n = Attitude::from_degrees(roll_deg[i], pitch_deg[i], yaw_deg[i]).body_to_ned(&r_b);
        let p = Geodetic::new(lat[i], lon[i], alt[i]).offset_by(r_n[0], r_n[1], alt[i] - r_n[2]);
        if p.lat_deg.is_finite() && p.lon_deg.is_finite() {
            out[0][i] = p.lat_deg;
            out[1][i] = p.lon_deg;
            out[2][i] = p.alt_m;
        }
    }
    Ok(out)
}

/// The along-track time derivative `Ḃ` of `tracks.sensed` (else
/// `tracks.value`), nT/s, one value per row: NaN off lines, at non-finite
/// values and on single-sample segments (module docs give the estimator).
pub fn track_derivative(tracks: &SurveyTracks, cfg: &TrackConfig) -> Result<Vec<f64>> {
    tracks.validate()?;
    cfg.validate()?;
    let (t, m) = (tracks.time, tracks.sensed.unwrap_or(tracks.value));
    let w = cfg.derivative_half_window_s;
    let mut d = vec![f64::NAN; tracks.len()];
    for seg in tracks.segments(cfg) {
        if seg.len() < 2 {
            continue;
        }
        let (mut lo, mut hi) = (seg.start, seg.start);
        for i in seg.clone() {
            // Window [lo, hi): |t_j − t_i| ≤ w (with a relative tolerance for
            // sampled times), and at least the neighbours i − 1 and i + 1.
            let tol = 1e-9 * (1.0 + w + t[i].abs() * 1e-3);
            while lo < i && t[i] - t[lo] > w + tol {
                lo += 1;
            }
            let lo_i = lo.min(i.saturating_sub(1).max(seg.start));
            hi = hi.max(i + 1);
            while hi < seg.end && t[hi] - t[i] <= w + tol {
                hi += 1;
            }
            let hi_i = hi.max((i + 2).min(seg.end));
            d[i] = slope(&t[lo_i..hi_i], &m[lo_i..hi_i]);
        }
    }
    Ok(d)
}

/// Least-squares slope of `y` against `x` (NaN if `x` has no spread).
fn slope(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    let xm = x.iter().sum::<f64>() / n;
    let ym = y.iter().sum::<f64>() / n;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (a, b) in x.iter().zip(y) {
        sxy += (a - xm) * (b - ym);
        sxx += (a - xm) * (a - xm);
    }
    if sxx > 0.0 { sxy / sxx } else { f64::NAN }
}

pub(crate) fn bad(msg: String) -> CompError {
    CompError::data(format!("levelling: {msg}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tracks<'a>(
        t: &'a [f64],
        line: &'a [f64],
        v: &'a [f64],
        zeros: &'a [f64],
    ) -> SurveyTracks<'a> {
        SurveyTracks {
            time: t,
            lat: zeros,
            lon: zeros,
            alt: zeros,
            line,
            value: v,
            sensed: None,
        }
    }

    #[test]
    fn derivative_of_a_quadratic_is_exact_inside_and_respects_lines_and_gaps() {
        // 10 Hz; line 1 for 3 s, a gap of 2 s, line 1 again, then turn (0), then line 2.
        let mut t = Vec::new();
        let mut line = Vec::new();
        for k in 0..30 {
            t.push(k as f64 * 0.1);
            line.push(1.0);
        }
        for k in 0..30 {
            t.push(5.0 + k as f64 * 0.1);
            line.push(1.0);
        }
        for k in 0..10 {
            t.push(8.0 + k as f64 * 0.1);
            line.push(0.0);
        }
        for k in 0..30 {
            t.push(9.0 + k as f64 * 0.1);
            line.push(2.0);
        }
        // A quadratic: the symmetric LS slope is exact, dm/dt = 3 + 0.8 t.
        let v: Vec<f64> = t.iter().map(|&x| 7.0 + 3.0 * x + 0.4 * x * x).collect();
        let zeros = vec![0.0; t.len()];
        let tr = tracks(&t, &line, &v, &zeros);
        let d = track_derivative(&tr, &TrackConfig::default()).unwrap();
        for i in 0..t.len() {
            let interior = [2..28, 32..58, 72..98].iter().any(|r| r.contains(&i));
            if interior {
                assert!(
                    (d[i] - (3.0 + 0.8 * t[i])).abs() < 1e-9,
                    "row {i}: {}",
                    d[i]
                );
            }
        }
        // Turn rows have no derivative; segment ends are one-sided but finite.
        assert!(d[60..70].iter().all(|x| x.is_nan()));
        for i in [0, 29, 30, 59, 70, 99] {
            assert!(d[i].is_finite());
            assert!((d[i] - (3.0 + 0.8 * t[i])).abs() < 0.2, "row {i}");
        }
        // The derivative never reaches across the gap: the end of the first
        // part only uses its own samples (the value jump is not seen).
        let mut v2 = v.clone();
        for x in &mut v2[30..60] {
            *x += 100.0;
        }
        let d2 =
            track_derivative(&tracks(&t, &line, &v2, &zeros), &TrackConfig::default()).unwrap();
        assert!((d[29] - d2[29]).abs() < 1e-9 && (d[30] - d2[30]).abs() < 1e-9);
    }

    #[test]
    fn narrow_window_is_the_central_difference() {
        let t: Vec<f64> = (0..20).map(|k| k as f64 * 0.1).collect();
        let v: Vec<f64> = t.iter().map(|&x| x.powi(3)).collect();
        let line = vec![5.0; 20];
        let zeros = vec![0.0; 20];
        let cfg = TrackConfig {
            derivative_half_window_s: 0.0,
            ..TrackConfig::default()
        };
        let d = track_derivative(&tracks(&t, &line, &v, &zeros), &cfg).unwrap();
        for i in 1..19 {
            let c = (v[i + 1] - v[i - 1]) / (t[i + 1] - t[i - 1]);
            assert!((d[i] - c).abs() < 1e-12);
        }
        assert!((d[0] - (v[1] - v[0]) / 0.1).abs() < 1e-12);
    }

    #[test]
    fn sensor_positions_follow_the_lever_arm() {
        // Flying east, level: a sensor 9.5 m behind and 0.6 m above (z up is −z).
        let (lat, lon, alt) = ([56.0, 56.0], [38.0, f64::NAN], [100.0, 100.0]);
        let [sl, so, sa] = sensor_positions(
            &lat,
            &lon,
            &alt,
            &[0.0; 2],
            &[0.0; 2],
            &[90.0; 2],
            [-9.5, 0.0, -0.6],
        )
        .unwrap();
        let o = Geodetic::new(56.0, 38.0, 100.0);
        let [n, e, _] = o.ned_offset_to(&Geodetic::new(sl[0], so[0], 100.0));
        assert!(n.abs() < 1e-6 && (e + 9.5).abs() < 1e-6, "{n} {e}");
        assert!((sa[0] - 100.6).abs() < 1e-9);
        assert!(sl[1].is_nan() && so[1].is_nan() && sa[1].is_nan());
        // Nose up 90°: the stinger points down.
        let [_, _, sa] = sensor_positions(
            &lat,
            &lon,
            &alt,
            &[0.0; 2],
            &[90.0; 2],
            &[0.0; 2],
            [-9.5, 0.0, 0.0],
        )
        .unwrap();
        assert!((sa[0] - 90.5).abs() < 1e-9);
        assert!(
            sensor_positions(
                &lat,
                &lon[..1],
                &alt,
                &[0.0; 2],
                &[0.0; 2],
                &[0.0; 2],
                [0.0; 3]
            )
            .is_err()
        );
    }

    #[test]
    fn bad_input_is_an_error() {
        let t = [0.0, 1.0];
        let z = [0.0, 0.0];
        let short = [0.0];
        assert!(track_derivative(&tracks(&t, &short, &z, &z), &TrackConfig::default()).is_err());
        let frac = [1.0, 1.5];
        let e = track_derivative(&tracks(&t, &frac, &z, &z), &TrackConfig::default()).unwrap_err();
        assert!(e.to_string().contains("row 1"), "{e}");
        let cfg = TrackConfig {
            max_gap_factor: f64::NAN,
            ..TrackConfig::default()
        };
        assert!(track_derivative(&tracks(&t, &z, &z, &z), &cfg).is_err());
    }
}
