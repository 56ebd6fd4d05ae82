//! Contiguous stretches of a flight: the one gap rule of every workflow.

use aeromag_compensation::tolles_lawson::segments::{median_step, split_segments_with};
use std::ops::Range;

/// A time step longer than this multiple of the median step is a gap: the
/// rule of every zero-phase filter, derivative and fit on flight data
/// (Tolles-Lawson fits and compensation, scoring, rotor and pod models).
/// Levelling keeps its own, looser rule
/// ([`aeromag_compensation::levelling::TrackConfig::max_gap_factor`]): its
/// derivatives are local fits that tolerate a few missing samples.
pub const GAP_FACTOR: f64 = 1.5;

/// How a flight is cut into segments: at time gaps (steps over
/// `gap_factor` × the median step), at rows that are not usable, and at
/// changes of the `line` label when `split_lines` holds. Segments shorter
/// than `min_len` rows are set aside (and reported: nothing is dropped
/// silently).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentRule {
    /// Gap threshold as a multiple of the median time step.
    pub gap_factor: f64,
    /// Split at changes of the line label.
    pub split_lines: bool,
    /// Shortest segment kept, rows.
    pub min_len: usize,
}

impl Default for SegmentRule {
    /// [`GAP_FACTOR`], split at lines, keep every segment.
    fn default() -> Self {
        Self {
            gap_factor: GAP_FACTOR,
            split_lines: true,
            min_len: 1,
        }
    }
}

impl SegmentRule {
    /// The default rule without splitting at line changes.
    pub fn ignoring_lines() -> Self {
        Self {
            split_lines: false,
            ..Self::default()
        }
    }

    /// The default rule with segments of at least `min_len` rows.
    pub fn min_len(self, min_len: usize) -> Self {
        Self { min_len, ..self }
    }

    /// Split `time` (s) where `usable` holds, with the `line` labels when
    /// the rule splits at lines.
    pub fn split(&self, time: &[f64], line: Option<&[f64]>, usable: &[bool]) -> Segments {
        self.split_with(time, line, usable, || median_step(time))
    }

    /// [`SegmentRule::split`] with the median step of `time` (s) given by
    /// `median` (called only when the gap rule needs it), for a caller
    /// that has it already ([`crate::Flight::median_step_s`]).
    pub fn split_with(
        &self,
        time: &[f64],
        line: Option<&[f64]>,
        usable: &[bool],
        median: impl FnOnce() -> f64,
    ) -> Segments {
        let (kept, short) = split_segments_with(
            time,
            if self.split_lines { line } else { None },
            usable,
            self.gap_factor,
            self.min_len,
            median,
        );
        Segments { kept, short }
    }
}

/// The segments of a flight (row ranges, in order) and those set aside as
/// too short.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Segments {
    /// Segments of at least the rule's minimum length.
    pub kept: Vec<Range<usize>>,
    /// Shorter segments, not used.
    pub short: Vec<Range<usize>>,
}

impl Segments {
    /// Rows in the kept segments.
    pub fn rows(&self) -> usize {
        self.kept.iter().map(|r| r.len()).sum()
    }
}

/// Rows where `time` and every column of `cols` are finite.
pub(crate) fn finite_rows(time: &[f64], cols: &[&[f64]]) -> Vec<bool> {
    (0..time.len())
        .map(|k| time[k].is_finite() && cols.iter().all(|c| c[k].is_finite()))
        .collect()
}

/// The rows where `time` and every column of `cols` are finite, and their
/// segments under `rule` (split at `line` changes when the rule says so):
/// the usable-row rule of the rotor and pod models, whose inputs are all
/// plain columns.
pub fn finite_segments(
    time: &[f64],
    line: Option<&[f64]>,
    cols: &[&[f64]],
    rule: &SegmentRule,
) -> (Vec<bool>, Segments) {
    let usable = finite_rows(time, cols);
    let segs = rule.split(time, line, &usable);
    (usable, segs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_gap_rule_lines_and_unusable_rows_cut_segments() {
        // 10 Hz with one step of 0.14 s (< 1.5 × 0.1: not a gap) and one of
        // 0.2 s (a gap), a line change and an unusable row.
        let mut time: Vec<f64> = (0..40).map(|k| k as f64 * 0.1).collect();
        for t in &mut time[10..] {
            *t += 0.04;
        }
        for t in &mut time[20..] {
            *t += 0.1;
        }
        let line: Vec<f64> = (0..40).map(|k| if k < 30 { 1.0 } else { 2.0 }).collect();
        let mut usable = vec![true; 40];
        usable[25] = false;
        let s = SegmentRule::default().split(&time, Some(&line), &usable);
        assert_eq!(s.kept, vec![0..20, 20..25, 26..30, 30..40]);
        assert_eq!(s.rows(), 39);
        let s = SegmentRule::ignoring_lines()
            .min_len(6)
            .split(&time, Some(&line), &usable);
        assert_eq!(s.kept, vec![0..20, 26..40]);
        assert_eq!(s.short, vec![20..25]);
    }

    #[test]
    fn finite_segments_need_every_column() {
        let time: Vec<f64> = (0..10).map(|k| k as f64).collect();
        let mut a = vec![1.0; 10];
        a[4] = f64::NAN;
        let b = vec![2.0; 10];
        let (usable, s) = finite_segments(&time, None, &[&a, &b], &SegmentRule::default());
        assert_eq!(usable.iter().filter(|u| !**u).count(), 1);
        assert_eq!(s.kept, vec![0..4, 5..10]);
    }
}
