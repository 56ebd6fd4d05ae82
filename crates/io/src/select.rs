//! Picking segments out of a whole flight: rows by line label (`--lines`)
//! and by time (`--time-range`).
//!
//! A whole survey flight holds take-off, transits, calibration boxes and
//! survey lines; the line label tells them apart (SGL: `1002.02` =
//! "Shawville calibration 1", spec `data-formats.md`, "Real survey files").
//! MagNav's workflow calibrates on one segment and compensates the others,
//! so every command that reads flight data can keep only some rows.
//!
//! **Labels are labels**, compared as text where the column is text
//! (`L1020`, `T901`, any case) and as numbers where it is numeric: `1003.01`
//! selects the rows whose value is the number 1003.01, and a label with
//! leading letters (`L1020`) selects 1020 in a numeric column (the Geosoft
//! XYZ reader keeps the number of a `Line L1020` record). A `line` column
//! whose labels differ as text but not as numbers (`1003.1` and `1003.10`)
//! is read as text, so `--lines 1003.1` selects that line only.
//!
//! The rows kept keep their file line numbers, so messages still name the
//! file's lines; data rows are counted within the selection.
//!
//! ```
//! use aeromag_io::{FlightTable, RowSelection};
//! let mut t = FlightTable::new();
//! t.add_column("time", vec![0.0, 1.0, 2.0, 3.0])?;
//! t.add_column("line", vec![1002.01, 1002.02, 1002.02, 1003.01])?;
//! let sel = RowSelection::parse(Some("1002.02"), Some("0,1.5"))?;
//! sel.apply(&mut t)?;
//! assert_eq!(t.column("time").unwrap(), &[1.0]);
//! # Ok::<(), aeromag_io::IoError>(())
//! ```

use crate::error::{IoError, Result};
use crate::table::FlightTable;
use aeromag_core::error::shown;

/// Rows to keep: those on any of `lines` (all when empty) and, with a
/// `time_range`, those whose `time` lies in `[t0, t1]` (s, inclusive).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RowSelection {
    /// Line labels as typed (`1003.01`, `L1020`).
    pub lines: Vec<String>,
    /// `(t0, t1)` in the file's time unit (s), `t0 ≤ t1`.
    pub time_range: Option<(f64, f64)>,
}

impl RowSelection {
    /// Parses the texts of `--lines LABEL,LABEL` and `--time-range T0,T1`.
    /// Errors ([`IoError::Selection`]): an empty label, a time range that is
    /// not two finite numbers with `T0 ≤ T1`.
    pub fn parse(lines: Option<&str>, time_range: Option<&str>) -> Result<Self> {
        let err = |option, reason: String| IoError::Selection {
            file: String::new(),
            option,
            reason,
        };
        let mut sel = RowSelection::default();
        if let Some(text) = lines {
            for label in text.split(',').map(str::trim) {
                if label.is_empty() {
                    return Err(err(
                        "--lines",
                        format!("'{text}' has an empty label (expected e.g. 1002.02,L1020)"),
                    ));
                }
                sel.lines.push(label.to_string());
            }
        }
        if let Some(text) = time_range {
            let parts: Vec<&str> = text.split(',').map(str::trim).collect();
            let nums: Vec<Option<f64>> = parts
                .iter()
                .map(|p| p.parse::<f64>().ok().filter(|v| v.is_finite()))
                .collect();
            match nums[..] {
                [Some(t0), Some(t1)] if t0 <= t1 => sel.time_range = Some((t0, t1)),
                [Some(t0), Some(t1)] => {
                    return Err(err(
                        "--time-range",
                        format!("start {} is after end {}", shown(t0), shown(t1)),
                    ));
                }
                _ => {
                    return Err(err(
                        "--time-range",
                        format!("'{text}' must be two finite numbers T0,T1 (s)"),
                    ));
                }
            }
        }
        Ok(sel)
    }

    /// True when every row is kept.
    pub fn is_all(&self) -> bool {
        self.lines.is_empty() && self.time_range.is_none()
    }

    /// Which rows of `table` are kept. Errors: no `line` (or `time`) column,
    /// a label that matches no row (naming the labels present), or a
    /// selection that keeps nothing.
    pub fn mask(&self, table: &FlightTable) -> Result<Vec<bool>> {
        let file = table.file_label();
        let err = |option, reason: String| IoError::Selection {
            file: file.clone(),
            option,
            reason,
        };
        let mut keep = vec![true; table.n_rows()];
        if !self.lines.is_empty() {
            let labels = LineLabels::of(table).ok_or_else(|| {
                err(
                    "--lines",
                    "the file has no line-label column ('line', or one mapped onto it with --columns line=NAME)"
                        .into(),
                )
            })?;
            let mut on_line = vec![false; keep.len()];
            for label in &self.lines {
                let mut any = false;
                for (i, k) in on_line.iter_mut().enumerate() {
                    if labels.matches(i, label) {
                        *k = true;
                        any = true;
                    }
                }
                if !any {
                    return Err(err(
                        "--lines",
                        format!(
                            "no row has the line label '{label}'; labels present: {}",
                            labels.distinct(20)
                        ),
                    ));
                }
            }
            keep = on_line;
        }
        if let Some((t0, t1)) = self.time_range {
            let time = table.column("time").ok_or_else(|| {
                err(
                    "--time-range",
                    "the file has no numeric 'time' column".into(),
                )
            })?;
            for (k, &t) in keep.iter_mut().zip(time) {
                *k = *k && t >= t0 && t <= t1;
            }
            if !keep.contains(&true) {
                let finite = time.iter().copied().filter(|t| t.is_finite());
                let (lo, hi) = finite.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), t| {
                    (a.min(t), b.max(t))
                });
                return Err(err(
                    "--time-range",
                    format!(
                        "no selected row has a time in [{}, {}] s; the file's time runs from {} to {} s",
                        shown(t0),
                        shown(t1),
                        shown(lo),
                        shown(hi)
                    ),
                ));
            }
        }
        Ok(keep)
    }

    /// Keeps the selected rows of `table` (see [`RowSelection::mask`]).
    pub fn apply(&self, table: &mut FlightTable) -> Result<()> {
        if self.is_all() {
            return Ok(());
        }
        let keep = self.mask(table)?;
        table.retain_rows(&keep);
        Ok(())
    }
}

/// The line labels of a table, numeric or text.
pub(crate) enum LineLabels<'a> {
    /// A numeric `line` column.
    Numeric(&'a [f64]),
    /// A text `line` column.
    Text(&'a [String]),
}

impl<'a> LineLabels<'a> {
    /// The `line` column (alias resolved), if any.
    pub(crate) fn of(table: &'a FlightTable) -> Option<Self> {
        let c = table.get("line")?;
        Some(match (c.values(), c.text()) {
            (Some(v), _) => LineLabels::Numeric(v),
            (None, Some(t)) => LineLabels::Text(t),
            (None, None) => return None,
        })
    }

    /// Whether row `i` carries `label` (see the module docs).
    pub(crate) fn matches(&self, i: usize, label: &str) -> bool {
        match self {
            LineLabels::Text(t) => t[i].trim().eq_ignore_ascii_case(label),
            LineLabels::Numeric(v) => label_number(label).is_some_and(|x| v[i] == x),
        }
    }

    /// Up to `max` distinct labels in order of appearance, comma-separated.
    pub(crate) fn distinct(&self, max: usize) -> String {
        let mut seen: Vec<String> = Vec::new();
        let n = match self {
            LineLabels::Numeric(v) => v.len(),
            LineLabels::Text(t) => t.len(),
        };
        let mut more = false;
        for i in 0..n {
            let s = match self {
                LineLabels::Numeric(v) if v[i].is_nan() => continue,
                LineLabels::Numeric(v) => v[i].to_string(),
                LineLabels::Text(t) => t[i].trim().to_string(),
            };
            if no_line_label(&s) || seen.contains(&s) {
                continue;
            }
            if seen.len() == max {
                more = true;
                break;
            }
            seen.push(s);
        }
        if seen.is_empty() {
            return "none".into();
        }
        let mut out = seen.join(", ");
        if more {
            out.push_str(", …");
        }
        out
    }
}

/// The number a label stands for in a numeric column: the label itself
/// (`1003.01`), or what follows its leading letters (`L1020` → 1020).
pub fn label_number(label: &str) -> Option<f64> {
    let digits = label.trim_start_matches(|c: char| c.is_ascii_alphabetic());
    digits.parse::<f64>().ok().filter(|v| v.is_finite())
}

/// Whether a text label says no line at all: a missing marker as the
/// readers know them (empty, `NaN`, Geosoft's `*`) or the number 0 (turns
/// and transits, spec `data-formats.md`).
pub fn no_line_label(label: &str) -> bool {
    match crate::cell::parse_cell(label.as_bytes()) {
        Ok(crate::cell::Cell::Missing(_)) => true,
        Ok(crate::cell::Cell::Value(v)) => v == 0.0,
        Err(_) => false,
    }
}

/// Text line labels numbered: per label (trimmed), NaN when missing
/// ([`missing_label`]), 0 for no line (the number 0, [`no_line_label`]),
/// else `k` for the `k`-th distinct label (any case, 1-based, in order of
/// first appearance); and the distinct labels as first written. One map
/// lookup per run of equal labels, however many lines the file has.
pub fn number_labels<'a>(labels: impl IntoIterator<Item = &'a str>) -> (Vec<f64>, Vec<String>) {
    let mut distinct: Vec<String> = Vec::new();
    let mut index: std::collections::HashMap<String, f64> = std::collections::HashMap::new();
    let mut previous: Option<(&str, f64)> = None;
    let ids = labels
        .into_iter()
        .map(|t| {
            let t = t.trim();
            match previous {
                Some((p, id)) if p == t => id,
                _ => {
                    let id = if missing_label(t) {
                        f64::NAN
                    } else if no_line_label(t) {
                        0.0
                    } else {
                        let next = distinct.len() as f64 + 1.0;
                        let id = *index.entry(t.to_ascii_lowercase()).or_insert(next);
                        if id == next {
                            distinct.push(t.to_string());
                        }
                        id
                    };
                    previous = Some((t, id));
                    id
                }
            }
        })
        .collect();
    (ids, distinct)
}

/// Whether a text label is missing (empty, `NaN`, `*`): no line, as a
/// turn's 0 is, but seldom what a file means ([`no_line_label`]).
pub fn missing_label(label: &str) -> bool {
    matches!(
        crate::cell::parse_cell(label.as_bytes()),
        Ok(crate::cell::Cell::Missing(_))
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table() -> FlightTable {
        let mut t = FlightTable::new();
        t.set_source("f.csv");
        t.add_column("time", vec![0.0, 1.0, 2.0, 3.0, 4.0]).unwrap();
        t.add_column("line", vec![1002.01, 1002.02, 1002.02, f64::NAN, 1003.01])
            .unwrap();
        t
    }

    #[test]
    fn missing_and_zero_labels_are_no_line() {
        for t in ["", " ", "NaN", "nan", "*", "0", "0.0", "-0"] {
            assert!(no_line_label(t), "{t:?}");
        }
        for t in ["1003", "L0", "T901", "1003.10", "x"] {
            assert!(!no_line_label(t), "{t:?}");
        }
        for (t, missing) in [
            ("", true),
            ("NaN", true),
            ("*", true),
            ("0", false),
            ("7", false),
        ] {
            assert_eq!(missing_label(t), missing, "{t:?}");
        }
    }

    #[test]
    fn labels_select_numeric_rows_and_unknown_labels_are_errors() {
        let sel = RowSelection::parse(Some("1002.02, 1003.01"), None).unwrap();
        assert_eq!(
            sel.mask(&table()).unwrap(),
            [false, true, true, false, true]
        );
        let e = RowSelection::parse(Some("1002.2"), None)
            .unwrap()
            .mask(&table())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("'1002.2'")
                && e.contains("1002.01, 1002.02, 1003.01")
                && e.contains("f.csv"),
            "{e}"
        );
    }

    #[test]
    fn text_labels_and_letter_prefixes() {
        let mut t = FlightTable::new();
        t.add_text_column(
            "line",
            ["L1020", "T901", "l1020", ""].map(String::from).to_vec(),
        )
        .unwrap();
        let sel = RowSelection::parse(Some("L1020"), None).unwrap();
        assert_eq!(sel.mask(&t).unwrap(), [true, false, true, false]);
        let mut n = FlightTable::new();
        n.add_column("line", vec![1020.0, 901.0]).unwrap();
        let sel = RowSelection::parse(Some("T901"), None).unwrap();
        assert_eq!(sel.mask(&n).unwrap(), [false, true]);
    }

    #[test]
    fn time_range_is_inclusive_and_checked() {
        let sel = RowSelection::parse(None, Some("1, 3")).unwrap();
        assert_eq!(
            sel.mask(&table()).unwrap(),
            [false, true, true, true, false]
        );
        for bad in ["3,1", "1", "a,b", "1,2,3", "nan,1"] {
            assert!(RowSelection::parse(None, Some(bad)).is_err(), "{bad}");
        }
        let e = RowSelection::parse(None, Some("10,20"))
            .unwrap()
            .mask(&table())
            .unwrap_err()
            .to_string();
        assert!(e.contains("from 0 to 4 s"), "{e}");
        // Far values in exponent form, not 300 digits.
        let e = RowSelection::parse(None, Some("-1e300,-1e299"))
            .unwrap()
            .mask(&table())
            .unwrap_err()
            .to_string();
        assert!(e.contains("[-1e300, -1e299]") && e.len() < 200, "{e}");
        assert!(RowSelection::parse(Some("1,,2"), None).is_err());
    }

    #[test]
    fn apply_keeps_file_lines() {
        let (_dir, path) = write("time,line\n0,1\n1,2\n2,2\n3,1\n");
        let mut t = crate::read_csv(&path, &crate::ReadOptions::default()).unwrap();
        RowSelection::parse(Some("1"), None)
            .unwrap()
            .apply(&mut t)
            .unwrap();
        assert_eq!(t.column("time").unwrap(), &[0.0, 3.0]);
        assert_eq!(t.line_of_row(0), Some(2));
        assert_eq!(t.line_of_row(1), Some(5));
        assert_eq!((t.file_row(0), t.file_row(1)), (0, 3));
    }

    /// Messages name the file's data row and line, not the row's place in
    /// the selection, also after two selections.
    #[test]
    fn messages_count_data_rows_of_the_file() {
        let (_dir, path) = write(
            "time,line,lat
0,1,45
1,2,45
2,2,45
3,1,45
4,1,45
5,1,145
",
        );
        let mut t = crate::read_csv(&path, &crate::ReadOptions::default()).unwrap();
        RowSelection::parse(Some("1"), None)
            .unwrap()
            .apply(&mut t)
            .unwrap();
        RowSelection::parse(None, Some("3,5"))
            .unwrap()
            .apply(&mut t)
            .unwrap();
        assert_eq!(t.column("time").unwrap(), &[3.0, 4.0, 5.0]);
        assert_eq!((0..3).map(|r| t.file_row(r)).collect::<Vec<_>>(), [3, 4, 5]);
        let e = crate::check_units(&t).unwrap_err().to_string();
        assert!(e.contains("at data row 6 (line 7)"), "{e}");
        let mut bad = t.clone();
        bad.set_column("time", vec![3.0, 4.0, 4.0]).unwrap();
        let e = crate::check_time(&bad).unwrap_err().to_string();
        assert!(
            e.contains("data row 6 (line 7) has 4 after data row 5 (line 6)"),
            "{e}"
        );
    }

    /// `text` in a file of a folder removed when the returned guard drops
    /// (the folders of a counter under the system's temporary folder were
    /// left behind by every run).
    fn write(text: &str) -> (tempfile::TempDir, std::path::PathBuf) {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.csv");
        std::fs::write(&p, text).unwrap();
        (dir, p)
    }
}
