//! A table as plain data and back, losslessly ([`TableSnapshot`],
//! [`FlightTable::snapshot`], [`FlightTable::from_snapshot`]): for a copy of
//! a table outside the process, such as a pickled Python `Flight`. The
//! snapshot holds everything but the numbers (source file, columns with
//! their missing-value causes and integer form, text columns, the
//! canonical mapping, derived columns, each row's file line and data row,
//! the file's unread columns); the numbers travel beside it as one array,
//! so that every value keeps its bits (NaN included, which JSON cannot
//! hold).

use super::{Column, ColumnData, FlightTable, Missing};
use crate::columns::MappedColumn;
use crate::derive::DerivedColumn;
use crate::error::{IoError, Result};
use crate::values::Values;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// A [`FlightTable`] without its numbers ([`FlightTable::snapshot`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TableSnapshot {
    /// The file read, if any.
    pub source: Option<PathBuf>,
    /// Number of rows.
    pub n_rows: usize,
    /// The columns in order.
    pub columns: Vec<ColumnSnapshot>,
    /// The canonical aliases in effect.
    pub aliases: Vec<MappedColumn>,
    /// Breakpoints `(row, file line)` of the rows' file lines.
    pub row_lines: Vec<(usize, u64)>,
    /// Breakpoints `(row, data row)` of the rows' data rows in the file.
    pub row_origin: Vec<(usize, usize)>,
    /// The columns computed from file columns.
    pub derived: Vec<DerivedColumn>,
    /// Every column of the file, read or not.
    pub file_columns: Vec<String>,
    /// What the file holds beside its fields ([`FlightTable::not_read`]).
    #[serde(default)]
    pub not_read: Vec<super::NotRead>,
}

/// One column of a [`TableSnapshot`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ColumnSnapshot {
    /// Its name.
    pub name: String,
    /// Every value was written as an integer in its file.
    pub integer_text: bool,
    /// Numbers (the next `n_rows` of the snapshot's numbers) or text.
    pub data: ColumnSnapshotData,
}

/// The values of a [`ColumnSnapshot`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ColumnSnapshotData {
    /// Numbers, with their missing samples by reason.
    Numeric {
        /// Missing samples by reason.
        missing: Missing,
    },
    /// Text, one string per row.
    Text(Vec<String>),
}

/// [`IoError::Snapshot`] for `reason`.
fn bad(reason: impl Into<String>) -> IoError {
    IoError::Snapshot {
        reason: reason.into(),
    }
}

/// Checks that breakpoints `(row, start)` have increasing rows within
/// `n_rows` and that `start + n_rows` stays a number (the row numbers
/// derived from them).
fn check_breakpoints<T: Copy + TryInto<u64>>(
    what: &str,
    points: &[(usize, T)],
    n_rows: usize,
) -> Result<()> {
    let increasing = points.windows(2).all(|w| w[0].0 < w[1].0);
    let fits = points.iter().all(|&(row, start)| {
        row < n_rows
            && start
                .try_into()
                .ok()
                .and_then(|s: u64| s.checked_add(n_rows as u64 + 1))
                .is_some_and(|end| usize::try_from(end).is_ok())
    });
    if increasing && fits {
        Ok(())
    } else {
        Err(bad(format!(
            "its {what} are not increasing rows of the table's {n_rows}"
        )))
    }
}

impl FlightTable {
    /// The table as a [`TableSnapshot`] and its numeric columns' values,
    /// one column after the other; [`FlightTable::from_snapshot`] gives
    /// the same table back.
    pub fn snapshot(&self) -> (TableSnapshot, Vec<f64>) {
        let mut numbers = Vec::new();
        let columns = self
            .columns
            .iter()
            .map(|c| ColumnSnapshot {
                name: c.name.clone(),
                integer_text: c.integer_text,
                data: match &c.data {
                    ColumnData::Numeric { values, missing } => {
                        numbers.extend_from_slice(values);
                        ColumnSnapshotData::Numeric { missing: *missing }
                    }
                    ColumnData::Text(t) => ColumnSnapshotData::Text(t.clone()),
                },
            })
            .collect();
        let snapshot = TableSnapshot {
            source: self.source.clone(),
            n_rows: self.n_rows,
            columns,
            aliases: self.aliases.clone(),
            row_lines: self.row_lines.clone(),
            row_origin: self.row_origin.clone(),
            derived: self.derived.clone(),
            file_columns: self.file_columns.clone(),
            not_read: self.not_read.clone(),
        };
        (snapshot, numbers)
    }

    /// The table of a [`FlightTable::snapshot`]. [`IoError::Snapshot`] when
    /// it is not one: numbers that do not fill the numeric columns, a
    /// column of another length or repeated, more missing values than
    /// rows, breakpoints out of order or beyond the rows.
    pub fn from_snapshot(s: TableSnapshot, numbers: Vec<f64>) -> Result<FlightTable> {
        let n = s.n_rows;
        let numeric = s
            .columns
            .iter()
            .filter(|c| matches!(c.data, ColumnSnapshotData::Numeric { .. }))
            .count();
        if numeric.checked_mul(n) != Some(numbers.len()) {
            return Err(bad(format!(
                "{} numbers for {numeric} numeric columns of {n} rows",
                numbers.len()
            )));
        }
        if s.columns.is_empty() && n != 0 {
            return Err(bad(format!("{n} rows without a column")));
        }
        check_breakpoints("file lines", &s.row_lines, n)?;
        check_breakpoints("data rows", &s.row_origin, n)?;
        let mut table = FlightTable {
            source: s.source,
            n_rows: n,
            columns: Vec::with_capacity(s.columns.len()),
            aliases: s.aliases,
            row_lines: s.row_lines,
            row_origin: s.row_origin,
            derived: s.derived,
            file_columns: s.file_columns,
            not_read: s.not_read,
        };
        let mut numbers = numbers.chunks_exact(n.max(1));
        for c in s.columns {
            let data = match c.data {
                ColumnSnapshotData::Numeric { missing } => {
                    if missing.total() > n {
                        return Err(bad(format!(
                            "column '{}' has {} missing values in {n} rows",
                            c.name,
                            missing.total()
                        )));
                    }
                    let values = if n == 0 {
                        Vec::new()
                    } else {
                        numbers.next().map(<[f64]>::to_vec).unwrap_or_default()
                    };
                    ColumnData::Numeric {
                        values: Values::Owned(values),
                        missing,
                    }
                }
                ColumnSnapshotData::Text(t) => ColumnData::Text(t),
            };
            let column = Column {
                name: c.name,
                data,
                integer_text: c.integer_text,
            };
            if table.columns.iter().any(|k| k.name == column.name) || column.len() != n {
                return Err(bad(format!(
                    "column '{}' is repeated or has {} values in {n} rows",
                    column.name,
                    column.len()
                )));
            }
            table.columns.push(column);
        }
        Ok(table)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::columns::MapOrigin;
    use crate::derive::Conversion;

    /// A table with every part a snapshot holds: an alias, file lines, a
    /// text column, an integer column, NaN and missing counts, a derived
    /// column and a row selection.
    fn table() -> FlightTable {
        let numeric = |values: Vec<f64>, missing| ColumnData::Numeric {
            values: values.into(),
            missing,
        };
        let cols = vec![
            (
                "tt".to_string(),
                numeric(vec![1.0, 2.0, 3.0, 4.0, 5.0], Missing::default()),
                true,
            ),
            (
                "mag".to_string(),
                numeric(
                    vec![9.0, f64::NAN, -0.0, 1e-300, 0.1 + 0.2],
                    Missing {
                        blank: 1,
                        ..Missing::default()
                    },
                ),
                false,
            ),
        ];
        let aliases = vec![MappedColumn {
            canonical: "time".into(),
            file_column: "tt".into(),
            origin: MapOrigin::User,
        }];
        let mut t = FlightTable::from_parts("f.csv".into(), 5, cols, aliases, vec![(0, 3), (2, 6)]);
        let labels = ["L1", "L1", "L2", "", "L2"].map(String::from).to_vec();
        t.add_text_column("line", labels).unwrap();
        let lat = DerivedColumn {
            canonical: "lat".into(),
            from: "ins_lat".into(),
            conversion: Conversion::RadiansToDegrees,
            minus: None,
        };
        t.add_derived(lat, vec![0.5; 5]).unwrap();
        t.retain_rows(&[true, true, false, true, true]);
        t
    }

    fn bits(t: &FlightTable) -> Vec<Vec<u64>> {
        t.columns()
            .iter()
            .filter_map(|c| c.values().map(|v| v.iter().map(|x| x.to_bits()).collect()))
            .collect()
    }

    #[test]
    fn a_snapshot_gives_the_same_table_bit_for_bit() {
        let t = table();
        let (s, numbers) = t.snapshot();
        assert_eq!(numbers.len(), 3 * 4);
        let json = serde_json::to_string(&s).unwrap();
        let back =
            FlightTable::from_snapshot(serde_json::from_str(&json).unwrap(), numbers).unwrap();
        assert_eq!(back.snapshot().0, s);
        assert_eq!(bits(&back), bits(&t));
        assert_eq!(back.source(), Some(std::path::Path::new("f.csv")));
        assert_eq!(back.resolve("time"), Some("tt"));
        assert!(back.columns()[0].integer_text() && !back.columns()[1].integer_text());
        assert_eq!(back.columns()[1].missing().blank, 1);
        assert!(back.is_derived("lat"));
        assert_eq!(back.text_column("line"), t.text_column("line"));
        for row in 0..5 {
            assert_eq!(back.line_of_row(row), t.line_of_row(row), "row {row}");
            assert_eq!(back.file_row(row), t.file_row(row), "row {row}");
        }
        // Row 2 of the table is the file's data row 3, line 7.
        assert_eq!((back.file_row(2), back.line_of_row(2)), (3, Some(7)));
    }

    #[test]
    fn a_snapshot_that_is_not_a_table_is_refused() {
        let (s, numbers) = table().snapshot();
        let refused = |s: TableSnapshot, numbers: Vec<f64>, expect: &str| {
            let e = FlightTable::from_snapshot(s, numbers).unwrap_err();
            assert!(matches!(e, IoError::Snapshot { .. }) && e.is_bad_input());
            assert!(e.to_string().contains(expect), "{e}");
        };
        refused(
            s.clone(),
            numbers[1..].to_vec(),
            "11 numbers for 3 numeric columns of 4 rows",
        );
        let mut twice = s.clone();
        twice.columns[1].name = "tt".into();
        refused(twice, numbers.clone(), "column 'tt' is repeated");
        let mut short = s.clone();
        short.columns[2].data = ColumnSnapshotData::Text(vec!["L1".into()]);
        refused(
            short,
            numbers.clone(),
            "column 'line' is repeated or has 1 values in 4 rows",
        );
        let mut missing = s.clone();
        missing.columns[1].data = ColumnSnapshotData::Numeric {
            missing: Missing {
                nan: 5,
                ..Missing::default()
            },
        };
        refused(missing, numbers.clone(), "5 missing values in 4 rows");
        let mut unordered = s.clone();
        unordered.row_lines.reverse();
        refused(
            unordered,
            numbers.clone(),
            "file lines are not increasing rows",
        );
        let mut beyond = s.clone();
        beyond.row_origin = vec![(0, usize::MAX - 2)];
        refused(beyond, numbers.clone(), "data rows are not increasing rows");
        let mut past_end = s.clone();
        past_end.row_lines = vec![(4, 1)];
        refused(past_end, numbers.clone(), "file lines");
        let mut empty = s;
        empty.columns.clear();
        refused(empty, Vec::new(), "4 rows without a column");
    }
}
