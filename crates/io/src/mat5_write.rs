//! MATLAB v5 MAT-file writer: a flight table as MATLAB's `save` writes a
//! workspace of column vectors, in the format MATLAB's `load` reads (the
//! MathWorks "MAT-File Format", Level 5), checked with `scipy.io.loadmat`
//! (Python tests) and [`crate::read_mat5`].
//!
//! - One variable per column, named as the column, in the table's order:
//!   an n × 1 column vector (as a MATLAB table's columns are).
//! - Numbers are `double` (every value, NaN for a missing one, reads back
//!   bit for bit). A column read as integers whose values are all whole
//!   (`line` 1003, a flag column) is `int64`, as HDF5 output holds it, and
//!   reads back as integers.
//! - A text column (line labels such as `L1020`) is an n × k `char`
//!   matrix, each row padded with spaces to the longest (MATLAB's
//!   convention; `cellstr` turns it into a cell array of strings, and
//!   [`crate::read_mat5`] reads it back with the padding removed).
//! - Uncompressed (MATLAB's `-v6`): the file is written at the disk's
//!   speed and read back without inflating; `save(file, '-v7')` in MATLAB
//!   compresses it if wanted.
//!
//! What the format cannot hold is refused before anything is written
//! ([`IoError::CannotWrite`], bad input, naming the column): a name that is
//! not a MATLAB variable name (a letter, then letters, digits and `_`, at
//! most 63 characters, not a keyword such as `end`), and a column of more
//! than 2³² bytes (about 5·10⁸ rows; write HDF5, which MATLAB's `-v7.3`
//! files are, instead).

use std::io::Write;
use std::path::Path;

use crate::csv_write::written_columns;
use crate::error::Result;
use crate::table::{Column, FlightTable};

/// MATLAB's `namelengthmax`.
const MAX_NAME_CHARS: usize = 63;

/// MATLAB's keywords (`iskeyword`): no variable can be named one.
const KEYWORDS: [&str; 20] = [
    "break",
    "case",
    "catch",
    "classdef",
    "continue",
    "else",
    "elseif",
    "end",
    "for",
    "function",
    "global",
    "if",
    "otherwise",
    "parfor",
    "persistent",
    "return",
    "spmd",
    "switch",
    "try",
    "while",
];

// Data types and classes of the format (its Tables 1-1 and 1-3).
const MI_INT8: u32 = 1;
const MI_INT32: u32 = 5;
const MI_UINT32: u32 = 6;
const MI_DOUBLE: u32 = 9;
const MI_INT64: u32 = 12;
const MI_MATRIX: u32 = 14;
const MI_UTF8: u32 = 16;
const MI_UTF16: u32 = 17;
const MX_CHAR: u32 = 4;
const MX_DOUBLE: u32 = 6;
const MX_INT64: u32 = 14;

/// Writes `table` as a MATLAB v5 MAT-file to `path` (created or replaced,
/// atomically as [`crate::write_csv`]). Errors: [`IoError::CannotWrite`]
/// (bad input) for a table the format cannot hold, before anything is
/// written; [`IoError::Write`] when the file cannot be written.
pub fn write_mat5(table: &FlightTable, path: &Path) -> Result<()> {
    crate::table_file::write_checked(table, path, check_mat5, |t, w| write_mat5_to(t, w))
}

/// Whether a MAT-file can hold `table` (module docs); `file` names the
/// output in the error.
pub fn check_mat5(table: &FlightTable, file: &str) -> Result<()> {
    let n_rows = table.n_rows();
    crate::table_file::refuse_column(table, file, "CSV (.csv) or HDF5 (.h5)", |c| {
        let name = c.name();
        let mut chars = name.chars();
        Some(
            if !chars.next().is_some_and(|f| f.is_ascii_alphabetic())
                || !chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
            {
                "a MATLAB variable name is a letter, then letters, digits and '_'".to_string()
            } else if name.len() > MAX_NAME_CHARS {
                format!("a MATLAB variable name has at most {MAX_NAME_CHARS} characters")
            } else if KEYWORDS.contains(&name) {
                format!("'{name}' is a MATLAB keyword, which no variable can be named")
            } else if data_bytes(c, n_rows) > u64::from(u32::MAX) - 64 {
                "a MAT-file variable holds at most 4 GB (HDF5, which MATLAB reads, has no such \
                 limit)"
                    .to_string()
            } else {
                return None;
            },
        )
    })
}

/// How a column is stored: its class, its data type and, for text, the
/// rows' UTF-16 code units and their padded length.
enum Stored {
    Double,
    Int64,
    Char { rows: Vec<Vec<u16>>, width: usize },
}

impl Stored {
    fn of(c: &Column) -> Self {
        match c.text() {
            Some(text) => {
                let rows: Vec<Vec<u16>> = text.iter().map(|t| t.encode_utf16().collect()).collect();
                let width = rows.iter().map(Vec::len).max().unwrap_or(0);
                Stored::Char { rows, width }
            }
            None if c.stores_integers() => Stored::Int64,
            None => Stored::Double,
        }
    }
}

/// The bytes of column `c`'s data, for the size check (a text column's
/// widest row counted in bytes, at least its UTF-16 units).
fn data_bytes(c: &Column, n_rows: usize) -> u64 {
    let width = match c.text() {
        Some(text) => text.iter().map(String::len).max().unwrap_or(0),
        None => 4,
    };
    (n_rows as u64).saturating_mul(2 * width as u64)
}

/// Writes `table` as a MAT-file to any writer, without the checks of
/// [`write_mat5`] (call [`check_mat5`] first).
pub fn write_mat5_to<W: Write>(table: &FlightTable, mut out: W) -> std::io::Result<()> {
    let mut header = format!(
        "MATLAB 5.0 MAT-file, written by aeromag {}",
        env!("CARGO_PKG_VERSION")
    )
    .into_bytes();
    header.resize(116, b' ');
    header.extend([0u8; 8]); // no subsystem data
    header.extend(0x0100u16.to_le_bytes());
    header.extend(b"IM");
    out.write_all(&header)?;
    let n = table.n_rows();
    for c in written_columns(table) {
        let stored = Stored::of(c);
        let (class, cols, data_type, data_len) = match &stored {
            Stored::Double => (MX_DOUBLE, 1, MI_DOUBLE, 8 * n),
            Stored::Int64 => (MX_INT64, 1, MI_INT64, 8 * n),
            // ASCII as MATLAB writes it (UTF-8, a byte a character), other
            // text as UTF-16 code units, which a `char` counts.
            Stored::Char { rows, width } if rows.iter().flatten().all(|&u| u < 0x80) => {
                (MX_CHAR, *width, MI_UTF8, n * width)
            }
            Stored::Char { width, .. } => (MX_CHAR, *width, MI_UTF16, 2 * n * width),
        };
        let mut head = Vec::with_capacity(64 + c.name().len());
        tag(&mut head, MI_UINT32, 8);
        head.extend(class.to_le_bytes());
        head.extend(0u32.to_le_bytes());
        tag(&mut head, MI_INT32, 8);
        head.extend((n as u32).to_le_bytes());
        head.extend((cols as u32).to_le_bytes());
        tag(&mut head, MI_INT8, c.name().len());
        head.extend(c.name().as_bytes());
        pad(&mut head);
        tag(&mut head, data_type, data_len);
        let body_len = head.len() + data_len.next_multiple_of(8);
        let mut matrix = Vec::with_capacity(8);
        tag(&mut matrix, MI_MATRIX, body_len);
        out.write_all(&matrix)?;
        out.write_all(&head)?;
        match stored {
            Stored::Double => write_chunked(&mut out, c.values().unwrap_or_default(), |v| {
                v.to_le_bytes()
            })?,
            Stored::Int64 => write_chunked(&mut out, c.values().unwrap_or_default(), |v| {
                (*v as i64).to_le_bytes()
            })?,
            Stored::Char { rows, width } => {
                // Column-major: the first character of every row, then the
                // second, …, spaces past a row's end.
                let mut bytes = Vec::with_capacity(data_len);
                for j in 0..width {
                    for r in &rows {
                        let unit = r.get(j).copied().unwrap_or(0x20);
                        if data_type == MI_UTF8 {
                            bytes.push(unit as u8);
                        } else {
                            bytes.extend(unit.to_le_bytes());
                        }
                    }
                }
                out.write_all(&bytes)?;
            }
        }
        out.write_all(&[0u8; 8][..data_len.next_multiple_of(8) - data_len])?;
    }
    Ok(())
}

/// A tag of type `kind` for `len` bytes, little-endian.
fn tag(out: &mut Vec<u8>, kind: u32, len: usize) {
    out.extend(kind.to_le_bytes());
    out.extend((len as u32).to_le_bytes());
}

/// Zeros up to the next multiple of 8 bytes.
fn pad(out: &mut Vec<u8>) {
    out.resize(out.len().next_multiple_of(8), 0);
}

/// `values` as 8-byte little-endian items, in buffers of 64 KiB.
fn write_chunked<W: Write>(
    out: &mut W,
    values: &[f64],
    bytes: impl Fn(&f64) -> [u8; 8],
) -> std::io::Result<()> {
    let mut buf = Vec::with_capacity(1 << 16);
    for chunk in values.chunks(1 << 13) {
        buf.clear();
        for v in chunk {
            buf.extend(bytes(v));
        }
        out.write_all(&buf)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ReadOptions;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(100))]

        /// Any numbers (every bit pattern but NaN payloads) and text
        /// without trailing spaces (the `char` matrix's padding) read back
        /// as written, from one row up.
        #[test]
        fn write_then_read_is_lossless(
            rows in 1usize..30,
            seed in proptest::collection::vec(any::<u64>(), 1..4),
            text in proptest::collection::vec("[a-zA-Z0-9 ,.é€-]{0,6}[a-z]?", 30),
        ) {
            let mut t = FlightTable::new();
            for (k, s) in seed.iter().enumerate() {
                let values: Vec<f64> = (0..rows as u64)
                    .map(|r| f64::from_bits(s.wrapping_mul(r + 1).rotate_left(k as u32 * 7)))
                    .map(|v| if v.is_nan() { f64::NAN } else { v })
                    .collect();
                t.add_column(&format!("c{k}"), values).unwrap();
            }
            let cells: Vec<String> =
                text[..rows].iter().map(|c| c.trim_end_matches(' ').to_string()).collect();
            t.add_text_column("label", cells.clone()).unwrap();
            let dir = tempfile::tempdir().unwrap();
            let path = dir.path().join("p.mat");
            write_mat5(&t, &path).unwrap();
            let back = crate::read_mat5(&path, &ReadOptions::default()).unwrap();
            prop_assert_eq!(back.column_names(), t.column_names());
            for k in 0..seed.len() {
                let name = format!("c{k}");
                let bits = |t: &FlightTable| -> Vec<u64> {
                    t.column(&name).unwrap().iter().map(|v| v.to_bits()).collect()
                };
                prop_assert_eq!(bits(&back), bits(&t));
            }
            prop_assert_eq!(back.text_column("label").unwrap(), &cells[..]);
        }
    }

    fn table() -> FlightTable {
        let mut t = FlightTable::new();
        t.add_column("time", vec![0.0, 0.1, 0.2]).unwrap();
        t.add_column("mag", vec![53064.063, f64::NAN, -0.0])
            .unwrap();
        t.add_integer_column("comp_flag", vec![0.0, 1.0, 0.0])
            .unwrap();
        t.add_integer_column("half", vec![0.0, 0.5, 1.0]).unwrap();
        // ASCII (UTF-8 in the file) and not (UTF-16).
        t.add_text_column("line", vec!["L1020".into(), "".into(), "T901".into()])
            .unwrap();
        t.add_text_column("note", vec!["µ-metal".into(), "a b".into(), "".into()])
            .unwrap();
        t
    }

    #[test]
    fn a_table_reads_back_bit_for_bit_with_its_integers_and_text() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.mat");
        let t = table();
        write_mat5(&t, &path).unwrap();
        let back = crate::read_mat5(&path, &ReadOptions::default()).unwrap();
        assert_eq!(back.column_names(), t.column_names());
        assert!(back.not_read().is_empty(), "{:?}", back.not_read());
        for name in ["time", "mag", "comp_flag", "half"] {
            let bits = |t: &FlightTable| -> Vec<u64> {
                t.column(name)
                    .unwrap()
                    .iter()
                    .map(|v| v.to_bits())
                    .collect()
            };
            assert_eq!(bits(&back), bits(&t), "{name}");
        }
        assert!(back.get("comp_flag").unwrap().integer_text());
        assert!(!back.get("half").unwrap().integer_text());
        assert_eq!(back.text_column("line").unwrap(), ["L1020", "", "T901"]);
        assert_eq!(back.text_column("note").unwrap(), ["µ-metal", "a b", ""]);
    }

    #[test]
    fn names_matlab_cannot_hold_are_refused_naming_the_column() {
        for (name, why) in [
            ("1st", "a letter, then"),
            ("_x", "a letter, then"),
            ("mag.uc", "a letter, then"),
            ("end", "MATLAB keyword"),
            (&"a".repeat(64), "at most 63"),
        ] {
            let mut t = FlightTable::new();
            t.add_column(name, vec![1.0, 2.0]).unwrap();
            let e = check_mat5(&t, "out.mat").unwrap_err();
            assert!(e.is_bad_input());
            let text = e.to_string();
            assert!(
                text.contains(&format!("column '{name}'")) && text.contains(why),
                "{text}"
            );
        }
        let mut t = FlightTable::new();
        t.add_column(&"a".repeat(63), vec![1.0, 2.0]).unwrap();
        check_mat5(&t, "out.mat").unwrap();
    }
}
