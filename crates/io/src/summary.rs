//! File summary for `aeromag inspect`: rows, sampling, gaps, lines, missing
//! values and value ranges, as a serializable [`Summary`].
//!
//! Sampling statistics use the time differences `dt_i = t_{i+1} − t_i` of
//! consecutive rows where both times are finite:
//!
//! - sample interval `Δ` = median of `dt` (s); rate = `1/Δ` (Hz);
//! - gaps: `dt > 1.5 Δ`; reported as count, largest `dt` and the data row
//!   after the largest gap;
//! - jitter: standard deviation and maximum of `|dt − Δ|` over the `dt` that
//!   are not gaps (so a single long gap does not hide the clock jitter);
//! - duration = last − first finite time.
//!
//! `summarize` does not validate: a table whose time steps back still gets a
//! summary (negative `dt` count in the jitter); run
//! [`check_time`](crate::check_time) for the verdict.

use std::collections::HashMap;

use serde::Serialize;

use crate::columns::MappedColumn;
use crate::derive::Conversion;
use crate::derive::DerivedColumn;
use crate::fields::known_field;
use crate::table::{ColumnData, FlightTable, Missing};
use crate::validate::median_in_place;
use aeromag_core::error::shown;

/// Everything `aeromag inspect` prints about a table.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Summary {
    /// File (or `"<in-memory table>"`).
    pub file: String,
    /// Number of data rows.
    pub rows: usize,
    /// Per column statistics, in table order.
    pub columns: Vec<ColumnSummary>,
    /// Canonical aliases in effect.
    pub mapping: Vec<MappedColumn>,
    /// Canonical columns computed from fields in another unit
    /// ([`derive`](crate::derive)), listed among the columns too.
    pub derived: Vec<DerivedColumn>,
    /// Sampling of `time`; `None` without a numeric `time` column or with fewer than two finite times.
    pub time: Option<TimeSummary>,
    /// Distinct values of `line` in order of first appearance; `None` without a `line` column.
    pub lines: Option<Vec<LineCount>>,
    /// Range of the scalar field `mag` (nT).
    pub mag_range_nt: Option<Range>,
    /// Range of the vector magnitude `sqrt(flux_x² + flux_y² + flux_z²)` (nT).
    pub flux_magnitude_range_nt: Option<Range>,
    /// 0-based data rows whose position jumps off the track and back
    /// faster than anything flies ([`crate::position_glitches`]); `None`
    /// without numeric `time`, `lat` and `lon` columns.
    pub position_glitch_rows: Option<Vec<usize>>,
    /// What the file holds beside its fields, not read
    /// ([`FlightTable::not_read`]: a MAT-file's scalars, matrices, text);
    /// left out of the JSON when empty.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub not_read: Vec<crate::NotRead>,
}

/// Minimum and maximum.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Range {
    /// Smallest finite value.
    pub min: f64,
    /// Largest finite value.
    pub max: f64,
}

/// Whether a column holds numbers or text.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ColumnKind {
    /// `f64` values.
    Numeric,
    /// Text passed through.
    Text,
}

/// Statistics of one column.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ColumnSummary {
    /// Name in the table.
    pub name: String,
    /// Canonical name this column is mapped to, if any.
    pub canonical: Option<String>,
    /// Unit: the canonical column's, else that of a recognised field
    /// ([`known_field`](crate::known_field)); `None` for unknown names.
    pub unit: Option<&'static str>,
    /// Numeric or text.
    pub kind: ColumnKind,
    /// Missing samples by reason.
    pub missing: Missing,
    /// Total missing samples.
    pub missing_total: usize,
    /// Smallest finite value (numeric columns).
    pub min: Option<f64>,
    /// Largest finite value.
    pub max: Option<f64>,
    /// Mean of the finite values.
    pub mean: Option<f64>,
}

/// Sampling of the `time` column (see the module docs for definitions).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TimeSummary {
    /// First finite time (s).
    pub start_s: f64,
    /// Last finite time (s).
    pub end_s: f64,
    /// `end_s − start_s` (s).
    pub duration_s: f64,
    /// Median time step (s).
    pub sample_interval_s: f64,
    /// `1 / sample_interval_s` (Hz); `None` if the median step is not positive.
    pub rate_hz: Option<f64>,
    /// Standard deviation of `dt − Δ` over non-gap steps (s).
    pub jitter_std_s: f64,
    /// Largest `|dt − Δ|` over non-gap steps (s).
    pub jitter_max_s: f64,
    /// Gap threshold `1.5 Δ` (s).
    pub gap_threshold_s: f64,
    /// Number of steps longer than the threshold.
    pub gaps: usize,
    /// Longest gap (s), if any.
    pub largest_gap_s: Option<f64>,
    /// 0-based data row right after the longest gap.
    pub largest_gap_row: Option<usize>,
}

/// Samples of one line label.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct LineCount {
    /// The label (numbers written without a fractional part when integral).
    pub line: String,
    /// Number of rows with this label.
    pub samples: usize,
    /// 0-based first row with this label.
    pub first_row: usize,
}

/// Computes the [`Summary`] of a table.
pub fn summarize(table: &FlightTable) -> Summary {
    let ins_unit = crate::derive::ins_position_unit(table).map(|(c, _)| c);
    let columns = table
        .columns()
        .iter()
        .map(|c| {
            let canonical = table
                .mapping()
                .iter()
                .find(|m| m.file_column == c.name())
                .map(|m| m.canonical.clone());
            let mut unit = known_field(canonical.as_deref().unwrap_or(c.name())).map(|k| k.unit);
            // `ins_lat`/`ins_lon` in degrees (MagNav's XYZ0 layout), told by
            // their values (`derive` module docs).
            if unit == Some("rad")
                && ["ins_lat", "ins_lon"]
                    .iter()
                    .any(|f| c.name().eq_ignore_ascii_case(f))
                && ins_unit == Some(Conversion::DegreesAsRecorded)
            {
                unit = Some("deg");
            }
            match c.data() {
                ColumnData::Numeric { values, missing } => {
                    let (min, max, mean) = min_max_mean(values);
                    ColumnSummary {
                        name: c.name().to_string(),
                        canonical,
                        unit,
                        kind: ColumnKind::Numeric,
                        missing: *missing,
                        missing_total: missing.total(),
                        min,
                        max,
                        mean,
                    }
                }
                ColumnData::Text(_) => ColumnSummary {
                    name: c.name().to_string(),
                    canonical,
                    unit,
                    kind: ColumnKind::Text,
                    missing: Missing::default(),
                    missing_total: 0,
                    min: None,
                    max: None,
                    mean: None,
                },
            }
        })
        .collect();
    let flux = match (
        table.column("flux_x"),
        table.column("flux_y"),
        table.column("flux_z"),
    ) {
        (Some(x), Some(y), Some(z)) => {
            range((0..table.n_rows()).map(|i| (x[i] * x[i] + y[i] * y[i] + z[i] * z[i]).sqrt()))
        }
        _ => None,
    };
    Summary {
        file: table.file_label(),
        rows: table.n_rows(),
        columns,
        mapping: table.mapping().to_vec(),
        derived: table.derived().to_vec(),
        time: table.column("time").and_then(time_summary),
        lines: line_counts(table),
        mag_range_nt: table.column("mag").and_then(|v| range(v.iter().copied())),
        flux_magnitude_range_nt: flux,
        position_glitch_rows: match (
            table.column("time"),
            table.column("lat"),
            table.column("lon"),
        ) {
            (Some(t), Some(lat), Some(lon)) => Some(crate::position_glitches(t, lat, lon)),
            _ => None,
        },
        not_read: table.not_read().to_vec(),
    }
}

fn min_max_mean(v: &[f64]) -> (Option<f64>, Option<f64>, Option<f64>) {
    let mut n = 0usize;
    let mut sum = 0.0;
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for &x in v.iter().filter(|x| x.is_finite()) {
        n += 1;
        sum += x;
        lo = lo.min(x);
        hi = hi.max(x);
    }
    if n == 0 {
        return (None, None, None);
    }
    let mut mean = sum / n as f64;
    if !mean.is_finite() {
        // The sum overflowed (values near ±1.8e308): the mean of the
        // values divided by n does not.
        mean = v
            .iter()
            .filter(|x| x.is_finite())
            .map(|&x| x / n as f64)
            .sum();
    }
    (Some(lo), Some(hi), Some(mean))
}

fn range(values: impl Iterator<Item = f64>) -> Option<Range> {
    let (lo, hi) = values
        .filter(|x| x.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
            (lo.min(x), hi.max(x))
        });
    (lo <= hi).then_some(Range { min: lo, max: hi })
}

/// Sampling statistics of a time column (see the module docs).
pub(crate) fn time_summary(t: &[f64]) -> Option<TimeSummary> {
    let finite: Vec<(usize, f64)> = t
        .iter()
        .copied()
        .enumerate()
        .filter(|(_, x)| x.is_finite())
        .collect();
    let (&(_, start), &(_, end)) = (finite.first()?, finite.last()?);
    // (dt, row after the step) over consecutive rows with finite times.
    let steps: Vec<(f64, usize)> = t
        .windows(2)
        .enumerate()
        .filter(|(_, w)| w[0].is_finite() && w[1].is_finite())
        .map(|(i, w)| (w[1] - w[0], i + 1))
        .collect();
    let mut dts: Vec<f64> = steps.iter().map(|s| s.0).collect();
    let interval = median_in_place(&mut dts)?;
    let threshold = 1.5 * interval;
    let is_gap = |dt: f64| interval > 0.0 && dt > threshold;
    let mut gaps = 0;
    let mut largest: Option<(f64, usize)> = None;
    let (mut n, mut sum2, mut jmax) = (0usize, 0.0, 0.0f64);
    for &(dt, row) in &steps {
        if is_gap(dt) {
            gaps += 1;
            if largest.is_none_or(|(g, _)| dt > g) {
                largest = Some((dt, row));
            }
        } else {
            let d = dt - interval;
            n += 1;
            sum2 += d * d;
            jmax = jmax.max(d.abs());
        }
    }
    Some(TimeSummary {
        start_s: start,
        end_s: end,
        duration_s: end - start,
        sample_interval_s: interval,
        rate_hz: (interval > 0.0).then(|| 1.0 / interval),
        jitter_std_s: if n > 0 {
            let deviations = steps
                .iter()
                .filter(|s| !is_gap(s.0))
                .map(|s| s.0 - interval);
            jitter_std(deviations, n, sum2, jmax)
        } else {
            0.0
        },
        jitter_max_s: jmax,
        gap_threshold_s: threshold,
        gaps,
        largest_gap_s: largest.map(|g| g.0),
        largest_gap_row: largest.map(|g| g.1),
    })
}

/// Distinct `line` labels with counts, in order of first appearance (missing labels skipped).
fn line_counts(table: &FlightTable) -> Option<Vec<LineCount>> {
    let col = table.get("line")?;
    let mut out: Vec<LineCount> = Vec::new();
    let mut index: HashMap<String, usize> = HashMap::new();
    let mut add = |label: String, row: usize| match index.get(&label) {
        Some(&k) => out[k].samples += 1,
        None => {
            index.insert(label.clone(), out.len());
            out.push(LineCount {
                line: label,
                samples: 1,
                first_row: row,
            });
        }
    };
    match col.data() {
        ColumnData::Numeric { values, .. } => {
            // Runs of equal values share one label lookup.
            let mut prev: Option<(u64, String)> = None;
            for (row, &v) in values.iter().enumerate() {
                if v.is_nan() {
                    continue;
                }
                let label = match &prev {
                    Some((bits, l)) if *bits == v.to_bits() => l.clone(),
                    _ => {
                        let l = format_label(v);
                        prev = Some((v.to_bits(), l.clone()));
                        l
                    }
                };
                add(label, row);
            }
        }
        ColumnData::Text(t) => {
            for (row, s) in t.iter().enumerate() {
                add(s.clone(), row);
            }
        }
    }
    Some(out)
}

/// The standard deviation of the `n` `deviations` of the steps within the
/// gap threshold from the interval, from their squares' sum `sum2`; when
/// that sum overflowed (steps near 1e300 s), again with each deviation
/// divided by the largest, `jmax`, which does not (the deviations are only
/// gone through then).
fn jitter_std(deviations: impl Iterator<Item = f64>, n: usize, sum2: f64, jmax: f64) -> f64 {
    let std = (sum2 / n as f64).sqrt();
    if std.is_finite() || !(jmax.is_finite() && jmax > 0.0) {
        return std;
    }
    let scaled: f64 = deviations.map(|d| (d / jmax).powi(2)).sum();
    jmax * (scaled / n as f64).sqrt()
}

/// A line number as text: integral values without a fractional part.
fn format_label(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e15 {
        format!("{}", v as i64)
    } else {
        shown(v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_statistics_with_gap_and_jitter() {
        // 10 Hz with one 0.5 s gap after row 3 and a 0.11 s step.
        let t = [0.0, 0.1, 0.2, 0.3, 0.8, 0.9, 1.01, 1.11];
        let s = time_summary(&t).unwrap();
        assert!((s.sample_interval_s - 0.1).abs() < 1e-12);
        assert!((s.rate_hz.unwrap() - 10.0).abs() < 1e-9);
        assert_eq!(s.gaps, 1);
        assert!((s.largest_gap_s.unwrap() - 0.5).abs() < 1e-12);
        assert_eq!(s.largest_gap_row, Some(4));
        assert!((s.jitter_max_s - 0.01).abs() < 1e-9, "{}", s.jitter_max_s);
        assert!((s.duration_s - 1.11).abs() < 1e-12);
        assert!(time_summary(&[1.0]).is_none());
    }

    #[test]
    fn positions_off_the_track_need_time_lat_and_lon() {
        let mut t = FlightTable::new();
        t.add_column("time", (0..50).map(|k| k as f64).collect())
            .unwrap();
        let mut lat = vec![45.0; 50];
        lat[20] = 0.0;
        t.add_column("lat", lat).unwrap();
        assert_eq!(summarize(&t).position_glitch_rows, None);
        t.add_column("lon", vec![-75.0; 50]).unwrap();
        assert_eq!(summarize(&t).position_glitch_rows, Some(vec![20]));
    }

    #[test]
    fn line_labels_in_order_of_appearance() {
        let mut t = FlightTable::new();
        t.add_column(
            "line",
            vec![1010.0, 1010.0, f64::NAN, 2010.0, 1010.0, 1010.5],
        )
        .unwrap();
        let lines = line_counts(&t).unwrap();
        let got: Vec<_> = lines
            .iter()
            .map(|l| (l.line.as_str(), l.samples, l.first_row))
            .collect();
        assert_eq!(got, vec![("1010", 3, 0), ("2010", 1, 3), ("1010.5", 1, 5)]);
    }

    /// A label or a column of values near f64's limit is summarised
    /// shortly and finitely: the label 1e308 was printed with 309 digits
    /// and the mean of two 1e308 values was `inf`.
    #[test]
    fn huge_labels_and_values_stay_short_and_finite() {
        let mut t = FlightTable::new();
        t.add_column("line", vec![1e308, 1e308, 1003.0]).unwrap();
        t.add_column("alt", vec![1e308, 1e308, f64::NAN]).unwrap();
        let lines = line_counts(&t).unwrap();
        assert_eq!(lines[0].line, "1e308");
        let (lo, hi, mean) = min_max_mean(t.column("alt").unwrap());
        assert_eq!((lo, hi, mean), (Some(1e308), Some(1e308), Some(1e308)));
        assert_eq!(min_max_mean(&[1.0, 2.0, f64::NAN]).2, Some(1.5));
        // Steps near 1e290 s: the jitter's sum of squares overflowed to inf.
        let t: Vec<f64> = (0..5)
            .map(|k| 1e300 + [0.0, 1.0, 2.1, 3.0, 4.0][k] * 1e290)
            .collect();
        let s = time_summary(&t).unwrap();
        assert!(s.jitter_std_s.is_finite() && s.jitter_std_s > 0.0, "{s:?}");
        assert!(s.jitter_std_s <= s.jitter_max_s, "{s:?}");
    }
}
