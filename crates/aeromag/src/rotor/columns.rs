//! The columns a rotor fit or application runs on, and what makes them fit
//! to run on: the checks of the flight (truth columns, a phase channel that
//! turns like a rotor, uniform sampling, a usable stretch) and the repairs
//! of short faults (dropouts, spikes of `mag`, glitches of the phase
//! channel), shared by [`fit_rotor`](super::fit_rotor) and `rotor apply`.

use super::MIN_SEGMENT_S;
use crate::error::{Error, Result};
use crate::flight::{Flight, GAP_FACTOR, SegmentRule, finite_segments};
use crate::observer::Note;
use aeromag_compensation::rotor::{RotorFitOptions, TailRotor};
use aeromag_compensation::tolles_lawson::segments::median_step;
use aeromag_core::error::{figure, fixed, shown};
use nalgebra::Vector3;
use std::ops::Range;

/// The columns a rotor fit or application reads: `time` (s), `mag` (nT),
/// `flux_x/y/z` (nT, body axes) and the phase channel (deg) when used.
pub(super) struct RotorColumns<'a> {
    pub time: &'a [f64],
    pub mag: &'a [f64],
    pub flux: [&'a [f64]; 3],
    pub phase: Option<&'a [f64]>,
}

impl<'a> RotorColumns<'a> {
    /// The columns of `flight` (the phase channel `phase` when used). A
    /// simulation truth column (`true_…`) is refused, whether named as the
    /// phase channel or mapped onto another (`--columns flux_x=true_flux_x`
    /// was taken).
    pub fn of(flight: &'a Flight, phase: Option<&str>) -> Result<Self> {
        let names: Vec<&str> = ["time", "mag", "flux_x", "flux_y", "flux_z"]
            .into_iter()
            .chain(phase)
            .collect();
        for (canonical, column) in flight.column_map_of(&names) {
            if column.starts_with("true_") {
                return Err(Error::bad_file(
                    flight.label(),
                    format!(
                        "`{column}` (as {canonical}) is a simulation truth column; the rotor model never reads truth"
                    ),
                ));
            }
        }
        // An infinite phase was taken as missing (bridged), while an
        // infinite `mag` or flux is refused on reading.
        if let Some(p) = phase {
            let v = flight.require(p)?;
            if let Some(k) = v.iter().position(|x| x.is_infinite()) {
                return Err(flight.bad_value(k, p, "the rotor phase is infinite"));
            }
        }
        let flux = [
            flight.require("flux_x")?,
            flight.require("flux_y")?,
            flight.require("flux_z")?,
        ];
        // A dropout written as zeros on the three axes: the field has no
        // direction there ("rotor input: field at sample 5000 is zero"
        // named neither the file nor the row).
        if let Some(k) = (0..flight.n_rows()).find(|&k| flux.iter().all(|c| c[k] == 0.0)) {
            return Err(flight.bad_row(
                k,
                "flux_x, flux_y and flux_z are all 0 nT: the field has no direction here \
                 (a dropout written as zeros? leave the cells empty for missing values)",
            ));
        }
        Ok(Self {
            time: flight.require("time")?,
            mag: flight.require("mag")?,
            flux,
            phase: phase.map(|p| flight.require(p)).transpose()?,
        })
    }

    /// `mag`, the flux components and the phase (when used), in that order.
    pub fn all(&self) -> Vec<&'a [f64]> {
        let mut v = vec![self.mag, self.flux[0], self.flux[1], self.flux[2]];
        v.extend(self.phase);
        v
    }

    /// The field vectors of rows `r`.
    pub fn field(&self, r: &Range<usize>) -> Vec<Vector3<f64>> {
        r.clone()
            .map(|k| Vector3::new(self.flux[0][k], self.flux[1][k], self.flux[2][k]))
            .collect()
    }

    /// The stretches without gaps or missing values of at least
    /// [`MIN_SEGMENT_S`] at sampling rate `fs` (Hz).
    pub fn stretches(&self, fs: f64) -> Vec<Range<usize>> {
        let min_len = (MIN_SEGMENT_S * fs).ceil() as usize;
        let rule = SegmentRule::ignoring_lines().min_len(min_len);
        finite_segments(self.time, None, &self.all(), &rule).1.kept
    }

    /// [`Self::stretches`], at least one, each sampled uniformly: bad input
    /// naming the file otherwise. The rotor model runs on the sample index
    /// (its filters and windows at `fs`), so steps alternating 0.01 and
    /// 0.02 s were taken as 50 Hz and the rotor as turning at 3.62 Hz
    /// instead of 4.83 (exit 0), and a float32 time (steps quantised to
    /// a few ms) likewise; every step of a stretch must be within
    /// [`MAX_STEP_DEVIATION`] of the median.
    pub fn usable_stretches(&self, flight: &Flight, fs: f64) -> Result<Vec<Range<usize>>> {
        // The fit high-passes at 2 Hz: a slower sampling (a time in ms
        // reads as 0.1 Hz) gave messages naming the library's `cutoff_hz`
        // or `window_s`.
        let cutoff = RotorFitOptions::default().highpass_hz;
        if fs <= 2.0 * cutoff {
            return Err(Error::bad_file(
                flight.label(),
                format!(
                    "sample rate {} Hz: the rotor model needs more than {} Hz (its high-pass is at \
                     {cutoff} Hz, and the blades pass at tens of Hz); is the time in seconds?",
                    figure(fs),
                    2.0 * cutoff
                ),
            ));
        }
        let segs = self.stretches(fs);
        if segs.is_empty() {
            return Err(Error::bad_file(
                flight.label(),
                format!(
                    "no stretch of ≥ {MIN_SEGMENT_S} s without gaps or missing values in time, mag, \
                     flux_x/y/z{} at {} Hz: nothing to fit or compensate",
                    if self.phase.is_some() {
                        " and the phase channel"
                    } else {
                        ""
                    },
                    fixed(fs, 3)
                ),
            ));
        }
        let dt = 1.0 / fs;
        for r in &segs {
            if let Some(k) = (r.start + 1..r.end).find(|&k| {
                let step = self.time[k] - self.time[k - 1];
                (step / dt - 1.0).abs() > MAX_STEP_DEVIATION
            }) {
                return Err(flight.bad_value(
                    k,
                    "time",
                    format!(
                        "a step of {} ms after the previous row, where the median step is {} ms: \
                         the rotor model needs uniform sampling (every step within {} % of the median); \
                         resample the flight (or is the time stored in float32?)",
                        figure(1e3 * (self.time[k] - self.time[k - 1])),
                        figure(1e3 * dt),
                        100.0 * MAX_STEP_DEVIATION
                    ),
                ));
            }
        }
        Ok(segs)
    }

    /// The columns with their dropouts bridged and the spikes of `mag`
    /// left out ([`Bridged`]).
    pub fn bridged(&self, fs: f64) -> Bridged {
        let max_fill = (MAX_FILL_S * fs).round().max(1.0) as usize;
        let raw = self.all();
        let mag_spikes = spikes(self.mag, 0.0);
        let without = |x: &[f64], at: &[usize]| {
            let mut x = x.to_vec();
            at.iter().for_each(|&k| x[k] = f64::NAN);
            x
        };
        let mag = without(self.mag, &mag_spikes);
        // A glitch of the phase channel (a corrupted cell) stands out of
        // its unwrapped line by up to 180°; a block of samples offset from
        // the rest (a step and a step back) is off the level most samples
        // keep. Levels are sorted out between time gaps (a time step beyond
        // the gap rule, or not a number): the phase across one is unknown,
        // and each stretch is tracked alone.
        let dt = median_step(self.time);
        let regular = |k: usize| (self.time[k] - self.time[k - 1]) <= dt * GAP_FACTOR;
        let phase_spikes = self.phase.map_or_else(Vec::new, |p| {
            let u = unwrapped_deg(p);
            let mut at = spikes(&u, PHASE_GLITCH_DEG);
            let mut start = 0;
            for k in 1..=u.len() {
                if k == u.len() || !regular(k) {
                    at.extend(
                        off_level(&u[start..k], PHASE_GLITCH_DEG)
                            .iter()
                            .map(|i| i + start),
                    );
                    start = k;
                }
            }
            at.sort_unstable();
            at.dedup();
            at
        });
        let phase = self.phase.map(|p| without(p, &phase_spikes));
        let columns: Vec<Vec<f64>> = raw
            .iter()
            .enumerate()
            .map(|(k, c)| {
                let period = (k == 4).then_some(360.0);
                let c = match k {
                    0 => &mag[..],
                    4 => phase.as_deref().unwrap_or(c),
                    _ => c,
                };
                bridge_dropouts(self.time, dt, c, max_fill, period)
            })
            .collect();
        let rows = (0..self.time.len())
            .filter(|&i| {
                raw.iter().any(|c| !c[i].is_finite()) && columns.iter().all(|c| c[i].is_finite())
            })
            .count();
        Bridged {
            columns,
            rows,
            spikes: mag_spikes,
            phase_spikes,
        }
    }

    /// These columns with `filled` ([`Bridged::columns`]) in place of
    /// `mag`, the flux and the phase.
    pub fn with<'b>(&self, filled: &'b [Vec<f64>]) -> RotorColumns<'b>
    where
        'a: 'b,
    {
        RotorColumns {
            time: self.time,
            mag: &filled[0],
            flux: [&filled[1], &filled[2], &filled[3]],
            phase: self.phase.map(|_| filled[4].as_slice()),
        }
    }
}

/// [`RotorColumns`] made fit to run on: runs of at most [`MAX_FILL_S`] of
/// missing values (no time gap) bridged by linear interpolation in every
/// column (the phase the short way round 360°), and the spikes of `mag`
/// ([`spikes`]) bridged likewise, so that one bad sample does not corrupt
/// the fit or the slowly varying angles of its window.
pub(super) struct Bridged {
    /// `mag`, the flux and the phase (as [`RotorColumns::all`]).
    pub columns: Vec<Vec<f64>>,
    /// Rows with a missing value that are bridged.
    pub rows: usize,
    /// The rows (0-based) whose `mag` is a spike.
    pub spikes: Vec<usize>,
    /// The rows (0-based) whose phase is a glitch ([`PHASE_GLITCH_DEG`]).
    pub phase_spikes: Vec<usize>,
}

impl Bridged {
    /// What was bridged, as notes for `flight` (`purpose`: "for the fit").
    pub fn notes(&self, flight: &Flight, purpose: &str) -> Vec<Note> {
        let mut notes = Vec::new();
        if self.rows > 0 {
            notes.push(Note::note(format!(
                "{} rows with a missing value in a dropout of at most {MAX_FILL_S} s are bridged by linear interpolation {purpose}",
                self.rows
            )));
        }
        if let Some(&first) = self.spikes.first() {
            let n = self.spikes.len();
            notes.push(Note::warning(format!(
                "{}: {n} {} of mag {} out from {} neighbours by more than {SPIKE_SIGMAS} times the \
                 flight's typical second difference (spikes; the first at data row {}, {} nT): \
                 bridged {purpose}, left as they are in the output",
                flight.label(),
                if n == 1 { "sample" } else { "samples" },
                if n == 1 { "stands" } else { "stand" },
                if n == 1 { "its" } else { "their" },
                flight.file_row(first) + 1,
                fixed(flight.require("mag").map_or(f64::NAN, |m| m[first]), 1)
            )));
        }
        if let Some(&first) = self.phase_spikes.first() {
            let n = self.phase_spikes.len();
            notes.push(Note::warning(format!(
                "{}: {n} {} of the rotor phase {} from the line of the other samples by more \
                 than {PHASE_GLITCH_DEG}° (glitches, or blocks stepped away and back; the first \
                 at data row {}): bridged {purpose} where at most {MAX_FILL_S} s long, left out \
                 otherwise",
                flight.label(),
                if n == 1 { "sample" } else { "samples" },
                if n == 1 { "jumps" } else { "jump" },
                flight.file_row(first) + 1,
            )));
        }
        notes
    }
}

/// The smallest glitch of the phase channel that is bridged, deg (with
/// [`SPIKE_SIGMAS`] times the channel's own scale, when larger): the
/// phase of a rotor turning steadily is a straight line whose second
/// differences are a fraction of a degree, and one corrupted cell (1e300)
/// turned the fitted rotor to 3.62 Hz instead of 4.83.
pub const PHASE_GLITCH_DEG: f64 = 10.0;

/// A phase in degrees unwrapped (each step taken the short way round
/// 360°, between the values reduced to [0°, 360°) first, so that a
/// corrupted 1e300 is a spike of the line and not a step of it); a
/// missing value stays missing and the next one follows the last present.
/// For finding glitches only: the model's phase is
/// [`unwrap_deg`](aeromag_compensation::rotor::unwrap_deg)'s, which
/// carries a NaN into every later sample and a 1e300 into a step.
fn unwrapped_deg(p: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(p.len());
    let mut last: Option<(f64, f64)> = None;
    for &x in p {
        if !x.is_finite() {
            out.push(f64::NAN);
            continue;
        }
        let x = x.rem_euclid(360.0);
        let u = match last {
            None => x,
            Some((raw, u)) => u + ((x - raw) + 180.0).rem_euclid(360.0) - 180.0,
        };
        last = Some((x, u));
        out.push(u);
    }
    out
}

/// The samples of an unwrapped phase `u` (deg) off the level most of its
/// samples keep, by more than `step` (deg, wrapped to ±180°): a block of
/// samples stepped away and back (+90° on 100 rows made the fitted mean
/// coning 0.3° instead of 3.9°, the two steps alone taken as glitches).
///
/// Each step from the last present sample is compared with the median
/// step of its block of [`LEVEL_BLOCK`] steps (the rotor's speed, which
/// changes slowly); a step off it by more than `step` changes the level by
/// its excess. The reference level is the one the most samples keep.
fn off_level(u: &[f64], step: f64) -> Vec<usize> {
    // (row, step from the last present sample, rows since it).
    let mut steps: Vec<(usize, f64, f64)> = Vec::new();
    let mut last: Option<usize> = None;
    for (k, &x) in u.iter().enumerate() {
        if !x.is_finite() {
            continue;
        }
        if let Some(j) = last {
            steps.push((k, x - u[j], (k - j) as f64));
        }
        last = Some(k);
    }
    // Per block of steps, the median step per row.
    let typical: Vec<f64> = steps
        .chunks(LEVEL_BLOCK)
        .map(|b| {
            let mut v: Vec<f64> = b.iter().map(|(_, d, n)| d / n).collect();
            let mid = v.len() / 2;
            *v.select_nth_unstable_by(mid, f64::total_cmp).1
        })
        .collect();
    let wrapped = |x: f64| (x + 180.0).rem_euclid(360.0) - 180.0;
    // The level from each row on: (first row, level), a new one at each step.
    let mut levels: Vec<(usize, f64)> = vec![(0, 0.0)];
    let mut level = 0.0;
    for (i, &(k, d, n)) in steps.iter().enumerate() {
        let excess = d - typical[i / LEVEL_BLOCK] * n;
        if excess.abs() > step {
            level += excess;
            levels.push((k, level));
        }
    }
    // One level; or a channel stepping all the time, which is no block
    // offset (its spikes are found as such).
    if levels.len() == 1 || levels.len() > MAX_LEVELS {
        return Vec::new();
    }
    // Rows per level (levels within `step` of each other are one).
    let span = |i: usize| levels.get(i + 1).map_or(u.len(), |l| l.0) - levels[i].0;
    let held = |l: f64| -> usize {
        (0..levels.len())
            .filter(|&i| wrapped(levels[i].1 - l).abs() <= step)
            .map(span)
            .sum()
    };
    let reference = levels
        .iter()
        .map(|l| l.1)
        .max_by_key(|&l| held(l))
        .unwrap_or(0.0);
    (0..levels.len())
        .filter(|&i| wrapped(levels[i].1 - reference).abs() > step)
        .flat_map(|i| levels[i].0..levels[i].0 + span(i))
        .filter(|&k| u[k].is_finite())
        .collect()
}

/// Steps of the phase whose median is the typical step of each
/// ([`off_level`]): half a second at 128 Hz; a step's excess is then
/// measured against the rotor's speed of that half second.
const LEVEL_BLOCK: usize = 64;

/// Most levels of the phase [`off_level`] sorts out (each is compared
/// with each); a channel with more steps than this is not one offset by
/// blocks.
const MAX_LEVELS: usize = 1000;

/// Spikes of `mag`: a sample whose second difference
/// `m[k] − (m[k−1] + m[k+1])/2` exceeds this many times the flight's
/// robust scale of it (1.4826 × its median absolute value). The rotor's
/// own signal gives second differences of about its amplitude at the
/// blade-passing frequency, so a spike must stand out by tens of times
/// the rotor's interference: one sample of 0 nT (a logger's dummy) made
/// the fit's residual 362 nT instead of 0.07, and a good model's applied
/// interference wrong by up to 230 nT over 5 s. None is found on the
/// simulated helicopter flights.
pub const SPIKE_SIGMAS: f64 = 50.0;

/// The rows of `mag` (or another series) that are spikes
/// ([`SPIKE_SIGMAS`], and at least `floor` in its unit): samples far from
/// the mean of their neighbours, and farther than either neighbour is
/// from its own.
fn spikes(mag: &[f64], floor: f64) -> Vec<usize> {
    let n = mag.len();
    if n < 3 {
        return Vec::new();
    }
    let second = |k: usize| mag[k] - 0.5 * (mag[k - 1] + mag[k + 1]);
    let mut d: Vec<f64> = (1..n - 1)
        .map(|k| second(k).abs())
        .filter(|x| x.is_finite())
        .collect();
    if d.is_empty() {
        return Vec::new();
    }
    let mid = d.len() / 2;
    let (_, &mut median, _) = d.select_nth_unstable_by(mid, f64::total_cmp);
    let limit = (SPIKE_SIGMAS * 1.4826 * median).max(floor);
    if limit.is_nan() || limit <= 0.0 {
        return Vec::new();
    }
    // A spike's neighbours have half its second difference: the spike is
    // the largest of the three.
    let size = |k: usize| {
        if (1..n - 1).contains(&k) {
            second(k).abs()
        } else {
            0.0
        }
    };
    (1..n - 1)
        .filter(|&k| {
            let d = size(k);
            d > limit && d >= size(k - 1) && d >= size(k + 1)
        })
        .collect()
}

/// Longest dropout (consecutive rows with a missing value, time steps
/// regular) that a fit or an application bridges by linear interpolation,
/// s.
const MAX_FILL_S: f64 = 0.1;

/// Largest relative deviation of a time step from the median within a
/// stretch the rotor model runs on (`rotor fit` and `rotor apply` check it):
/// 2 %, far above a logger's clock jitter and below the 5 % of steps
/// alternating 0.0105 and 0.0095 s (taken as 95.2 Hz, the rotor at 4.60
/// Hz instead of 4.83).
pub const MAX_STEP_DEVIATION: f64 = 0.02;

/// The mean rotor frequency (Hz) of the rotor speeds `omega_rad_s`.
pub(super) fn mean_rotor_hz(omega_rad_s: &[f64]) -> f64 {
    omega_rad_s.iter().sum::<f64>() / omega_rad_s.len() as f64 / std::f64::consts::TAU
}

/// Bridge runs of at most `max_len` non-finite values between finite ones
/// by linear interpolation in time (`period`: interpolate the shortest way
/// round, for a phase in degrees), when the time steps across the run are
/// regular (no gap: [`GAP_FACTOR`] times `dt`, the median step, s).
fn bridge_dropouts(
    time: &[f64],
    dt: f64,
    x: &[f64],
    max_len: usize,
    period: Option<f64>,
) -> Vec<f64> {
    let mut out = x.to_vec();
    let n = x.len();
    let mut k = 0;
    while k < n {
        if x[k].is_finite() {
            k += 1;
            continue;
        }
        let start = k;
        while k < n && !x[k].is_finite() {
            k += 1;
        }
        let (a, b) = (start.wrapping_sub(1), k);
        if start == 0 || b >= n || b - start > max_len {
            continue;
        }
        let span = time[b] - time[a];
        if !(span > 0.0 && span <= (b - a) as f64 * dt * GAP_FACTOR) {
            continue;
        }
        let mut d = x[b] - x[a];
        if let Some(p) = period {
            d = (d + 0.5 * p).rem_euclid(p) - 0.5 * p;
        }
        for i in start..b {
            out[i] = x[a] + d * (time[i] - time[a]) / span;
        }
    }
    out
}

/// Check the mean rotor frequency `f_r` (Hz) found on a stretch (the
/// fitted one, or one `rotor apply` tracks): above the high-pass cutoff of
/// the fit (a slower "rotor" is removed with the manoeuvres: a heading or
/// time column given as the phase channel turns at mHz and was fitted with
/// exit 0) and with the blade-passing frequency below Nyquist; for a tail
/// rotor, `gear_ratio × f_r` between the cutoff and Nyquist (a gear ratio
/// of 2⁶³ failed with a singular system, one of 10⁶ was fitted on aliased
/// garbage with exit 0).
pub(super) fn check_rotor_speed(
    f_r: f64,
    fs: f64,
    blades: usize,
    phase_col: Option<&str>,
    tail: Option<&TailRotor>,
    file: &str,
) -> Result<()> {
    let cutoff = RotorFitOptions::default().highpass_hz;
    let nyquist = fs / 2.0;
    let ok = |f: f64, n: usize| f > cutoff && n as f64 * f < nyquist;
    if !ok(f_r, blades) {
        let source = match phase_col {
            Some(c) => format!("the phase channel `{c}` (deg) turns"),
            None => "the rotor phase estimated from the data turns".to_string(),
        };
        // A plausible rotor under a sampling too slow for its blades: say
        // so, rather than doubt the phase channel.
        let hint = if f_r > cutoff && f_r.is_finite() {
            format!(
                "the flight is sampled too slowly for this rotor (at least {} Hz needed)",
                fixed(2.0 * blades as f64 * f_r, 1)
            )
        } else {
            "is it the rotor phase channel, in degrees?".to_string()
        };
        return Err(Error::bad_file(
            file,
            format!(
                "{source} at {} Hz on a stretch of the flight: a rotor's frequency must be above {cutoff} Hz \
                 (the fit's high-pass cutoff) and its {blades} blades must pass below Nyquist \
                 ({} Hz); {hint}",
                figure(f_r),
                fixed(nyquist, 3)
            ),
        ));
    }
    if let Some(t) = tail {
        // The tail's own turn, not its blade passing: with its phase geared
        // from the channel, the blade passing may alias (the simulator's
        // 3 blades at 21 Hz, 100 Hz sampling).
        let f_t = t.gear_ratio * f_r;
        if !ok(f_t, 1) {
            return Err(Error::bad_file(
                file,
                format!(
                    "tail rotor gear ratio {} (gear_ratio, --gear-ratio) makes the tail rotor turn at {} Hz \
                     (main rotor {f_r:.4} Hz): it must be above {cutoff} Hz (the fit's high-pass cutoff) \
                     and below Nyquist ({nyquist:.3} Hz)",
                    shown(t.gear_ratio),
                    figure(f_t)
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dropouts_are_bridged_but_not_time_gaps_or_long_runs() {
        let t: Vec<f64> = (0..10).map(|k| k as f64 * 0.01).collect();
        let nan = f64::NAN;
        let x = [0.0, 1.0, nan, 3.0, nan, nan, nan, 7.0, 8.0, nan];
        let y = bridge_dropouts(&t, median_step(&t), &x, 2, None);
        assert_eq!(y[2], 2.0);
        assert!(
            y[4].is_nan() && y[5].is_nan() && y[6].is_nan(),
            "a run of 3 > 2 stays"
        );
        assert!(y[9].is_nan(), "no value after the run");
        // A phase in degrees is interpolated the short way round 360°.
        let p = bridge_dropouts(
            &t[..3],
            median_step(&t[..3]),
            &[350.0, nan, 10.0],
            1,
            Some(360.0),
        );
        assert!((p[1] - 360.0).abs() < 1e-9, "{}", p[1]);
        // A time gap across the run: left alone.
        let tg = [0.0, 0.01, 0.02, 0.5, 0.51];
        assert!(
            bridge_dropouts(&tg, median_step(&tg), &[0.0, 1.0, nan, 3.0, 4.0], 2, None)[2].is_nan()
        );
    }
}
