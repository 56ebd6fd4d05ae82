//! Geosoft XYZ writer: the table as the column text format survey
//! processors import (Oasis montaj's XYZ import, MagNav.jl's `get_XYZ`),
//! read back by [`crate::read_xyz`] to the same table.
//!
//! ```text
//! / XYZ export of aeromag 0.1.0
//! / time lat lon alt mag line
//! 0.0 45.001 -75.002 300.0 53210.4 1003.01
//! 0.1 45.002 -75.002 300.1 * 1003.01
//! ```
//!
//! - A `/` comment naming the writer, then the column names on one `/`
//!   line (the header [`crate::read_xyz`] takes: the last comment line with
//!   as many names as the data lines have values).
//! - One data line per row, values separated by one space, numbers in the
//!   CSV writer's shortest round-trip text ([`crate::NumberText`]), missing
//!   values (and empty text cells) as Geosoft's dummy `*`.
//! - The line labels stay a column (`line`, as SGL's exports and the
//!   Flt1003 sample of MagNav.jl hold them): no `Line`/`Tie` records, which
//!   cannot hold the rows between lines (turns, rows without a label) and
//!   would be read back as a second line column.
//!
//! What the format cannot hold is refused before anything is written
//! ([`IoError::CannotWrite`]: bad input, naming the column and row): a
//! column name that does not start with a letter or `_` or holds a space
//! or comma (the header rule would not find it), a text cell with a space
//! (it would split into two values), a text cell starting with `/` in the
//! first column (a comment) or equal to `Line`/`Tie` there (a record). Such
//! a table is written as CSV instead.

use std::io::Write;
use std::path::Path;

use crate::csv_write::{write_rows, written_columns};
use crate::error::{IoError, Result};
use crate::table::{Column, FlightTable};

/// Writes `table` as Geosoft XYZ to the file `path` (created or replaced,
/// atomically as [`crate::write_csv`]). Errors: [`IoError::CannotWrite`]
/// (bad input) for a table the format cannot hold (module docs), before
/// anything is written; [`IoError::Write`] when the file cannot be written.
pub fn write_xyz(table: &FlightTable, path: &Path) -> Result<()> {
    crate::table_file::write_checked(table, path, check_xyz, |t, w| write_xyz_to(t, w))
}

/// Writes `table` as Geosoft XYZ to any writer, without the checks of
/// [`write_xyz`] (call [`check_xyz`] first).
pub fn write_xyz_to<W: Write>(table: &FlightTable, mut out: W) -> std::io::Result<()> {
    let columns = written_columns(table);
    let mut head = format!("/ XYZ export of aeromag {}\n/", env!("CARGO_PKG_VERSION"));
    for c in &columns {
        head.push(' ');
        head.push_str(c.name());
    }
    head.push('\n');
    out.write_all(head.as_bytes())?;
    write_rows::<b' ', W>(&columns, table.n_rows(), b"*", out)
}

/// Whether Geosoft XYZ can hold `table` (module docs); `file` names the
/// output in the error.
pub fn check_xyz(table: &FlightTable, file: &str) -> Result<()> {
    let refuse = |column: &str, row: Option<usize>, reason: &str| IoError::CannotWrite {
        file: file.to_string(),
        column: column.to_string(),
        row,
        reason: format!("{reason}; write the table as CSV (.csv) instead"),
    };
    let columns = written_columns(table);
    for (k, c) in columns.iter().enumerate() {
        let name = c.name();
        let starts_well = name
            .chars()
            .next()
            .is_some_and(|ch| ch.is_alphabetic() || ch == '_');
        if !starts_well || name.contains(|ch: char| ch.is_whitespace() || ch == ',') {
            return Err(refuse(
                name,
                None,
                "a Geosoft XYZ column name must start with a letter or '_' and hold no space or comma (its header could not be read back)",
            ));
        }
        if let Some((row, reason)) = unwritable_text(c, k == 0) {
            return Err(refuse(name, Some(row), reason));
        }
    }
    Ok(())
}

/// The first text cell of `c` a Geosoft XYZ data line cannot hold, and
/// why (`first`: the line's first column).
fn unwritable_text(c: &Column, first: bool) -> Option<(usize, &'static str)> {
    c.text()?.iter().enumerate().find_map(|(row, t)| {
        if t.contains(char::is_whitespace) {
            Some((
                row,
                "the text holds a space or line end, which would split it into two values",
            ))
        } else if first && t.starts_with('/') {
            Some((row, "a line starting with '/' is a comment in Geosoft XYZ"))
        } else if first && (t.eq_ignore_ascii_case("line") || t.eq_ignore_ascii_case("tie")) {
            Some((
                row,
                "a line starting with 'Line' or 'Tie' is a line record in Geosoft XYZ",
            ))
        } else {
            None
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ReadOptions;

    fn table() -> FlightTable {
        let mut t = FlightTable::new();
        t.add_column("time", vec![0.0, 0.1, 0.2]).unwrap();
        t.add_column("mag", vec![53210.4, f64::NAN, -1e-7]).unwrap();
        t.add_text_column("id", vec!["a1".into(), String::new(), "b-2".into()])
            .unwrap();
        t
    }

    #[test]
    fn writes_the_header_and_rows_with_dummies() {
        let mut out = Vec::new();
        write_xyz_to(&table(), &mut out).unwrap();
        let text = String::from_utf8(out).unwrap();
        let mut lines = text.lines();
        assert!(
            lines
                .next()
                .unwrap()
                .starts_with("/ XYZ export of aeromag ")
        );
        assert_eq!(
            lines.collect::<Vec<_>>(),
            [
                "/ time mag id",
                "0.0 53210.4 a1",
                "0.1 * *",
                "0.2 -1e-7 b-2"
            ]
        );
    }

    #[test]
    fn reads_back_to_the_same_numbers() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.xyz");
        let mut t = FlightTable::new();
        t.add_column("time", vec![0.0, 0.1, 0.2]).unwrap();
        t.add_column("mag", vec![53210.4, f64::NAN, 1.0 / 3.0])
            .unwrap();
        t.add_column("line", vec![1003.01, 1003.01, 1003.02])
            .unwrap();
        write_xyz(&t, &path).unwrap();
        let back = crate::read_xyz(&path, &ReadOptions::default()).unwrap();
        assert_eq!(back.column_names(), ["time", "mag", "line"]);
        for name in ["time", "mag", "line"] {
            let (a, b) = (t.column(name).unwrap(), back.column(name).unwrap());
            assert!(
                a.iter()
                    .zip(b)
                    .all(|(x, y)| x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan())),
                "{name}: {a:?} {b:?}"
            );
        }
    }

    #[test]
    fn what_the_format_cannot_hold_is_refused_naming_column_and_row() {
        let mut spaced = table();
        spaced
            .add_text_column("note", vec!["ok".into(), "two words".into(), "x".into()])
            .unwrap();
        let e = check_xyz(&spaced, "o.xyz").unwrap_err();
        assert!(e.is_bad_input());
        let at = e.location();
        assert_eq!(
            (at.column.as_deref(), at.row),
            (Some("note"), Some(1)),
            "{e}"
        );
        assert!(e.to_string().contains("write the table as CSV"), "{e}");

        let mut numbered = FlightTable::new();
        numbered.add_column("2nd", vec![1.0]).unwrap();
        let e = check_xyz(&numbered, "o.xyz").unwrap_err();
        assert_eq!(e.location().column.as_deref(), Some("2nd"), "{e}");

        for first in ["/x", "Line", "TIE"] {
            let mut t = FlightTable::new();
            t.add_text_column("label", vec![first.into()]).unwrap();
            t.add_column("mag", vec![1.0]).unwrap();
            assert!(check_xyz(&t, "o.xyz").is_err(), "{first}");
        }
        // Not first, the same texts are plain values.
        let mut t = FlightTable::new();
        t.add_column("mag", vec![1.0]).unwrap();
        t.add_text_column("label", vec!["Line".into()]).unwrap();
        check_xyz(&t, "o.xyz").unwrap();
    }
}
