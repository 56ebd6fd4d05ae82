//! CSV writer.
//!
//! Output layout: one header row with the table's column names (file names;
//! aliases are not written), one row per table row, comma separated, `\n`
//! line ends, a final line end.
//!
//! - Numbers are written with the shortest text that reads back to the same
//!   `f64` ([`NumberText`], in Ryū's layout: `0.1`, `53210.4`, `1e-7`,
//!   `-0.0`, `inf`), so a write → read round trip preserves every finite
//!   value and infinity bit for bit.
//! - Missing values (`NaN`) are written as **empty cells** (the reader reads
//!   them back as missing, `Missing::blank`); the NaN payload and sign are not
//!   kept. Exception: in a one-column table they are written as `NaN`, because
//!   an empty line would be skipped as a blank line and the row lost.
//! - Text cells and names are written as they are, quoted (`"…"`, inner `"`
//!   doubled) when they contain a comma, a quote, a line end, or start with
//!   `#` (which would otherwise read as a comment).
//!
//! A text column whose cells all look like numbers reads back as a numeric
//! column (column types are not stored in CSV).
//!
//! Rows are formatted in chunks of 16 384 rows on the available cores and
//! written in order by the calling thread while the workers format the
//! next ones ([`crate::ordered`]; the same bytes whatever the thread
//! count). A chunk of
//! numbers only is formatted into a buffer grown as its rows need (by the
//! longest text of [`GROW_ROWS`] rows at a time), each cell moved with
//! fixed-size copies (1.32× faster `compensate` of 10⁶ rows than a copy
//! call per cell: 300 against 396 ms, hyperfine), the cells of a row
//! formatted before they are copied ([`STAGED`]).

use std::io::Write;
use std::path::Path;

use crate::error::{IoError, Result};
use crate::number_text::NumberText;
use crate::table::{Column, ColumnData, FlightTable};

/// Writes `table` as CSV to the file `path` (created or replaced).
///
/// The table is written to a temporary file in the same folder and renamed
/// to `path` when complete ([`crate::atomic`]), so an interrupted or failed
/// write never leaves a complete-looking partial file.
pub fn write_csv(table: &FlightTable, path: &Path) -> Result<()> {
    crate::atomic::write_atomically(path, |w| write_csv_to(table, w)).map_err(|source| {
        IoError::Write {
            file: path.display().to_string(),
            source,
        }
    })
}

/// Writes `table` as CSV to any writer (wrap unbuffered writers in a `BufWriter`).
pub fn write_csv_to<W: Write>(table: &FlightTable, mut out: W) -> std::io::Result<()> {
    let mut line: Vec<u8> = Vec::with_capacity(4096);
    let columns = written_columns(table);
    for (i, c) in columns.iter().enumerate() {
        if i > 0 {
            line.push(b',');
        }
        push_text(&mut line, c.name());
    }
    line.push(b'\n');
    out.write_all(&line)?;
    let missing: &[u8] = if columns.len() == 1 { b"NaN" } else { b"" };
    write_rows::<b',', W>(&columns, table.n_rows(), missing, out)
}

/// The columns a table's file holds: derived columns (`lat` from
/// `ins_lat` in radians) are not the input's and are left out, so the
/// output is the input plus the results.
pub(crate) fn written_columns(table: &FlightTable) -> Vec<&Column> {
    table
        .columns()
        .iter()
        .filter(|c| !table.is_derived(c.name()))
        .collect()
}

/// Writes the `n` rows of `columns`, cells separated by `SEP` (`,` for
/// CSV, a space for Geosoft XYZ, whose text cells [`crate::xyz_write`] has
/// checked to need no quotes: an empty one is written `missing`), missing
/// values as `missing`.
pub(crate) fn write_rows<const SEP: u8, W: Write>(
    columns: &[&Column],
    n: usize,
    missing: &[u8],
    mut out: W,
) -> std::io::Result<()> {
    let threads = aeromag_core::parallel::threads();
    // Chunks of rows are formatted by `threads` workers, each taking the
    // next chunk in turn, and written in order by the calling thread
    // ([`crate::ordered`]): the same bytes for any thread count.
    let chunk_rows = WRITE_CHUNK_ROWS.min((WRITE_CHUNK_CELLS / columns.len().max(1)).max(1));
    let n_chunks = n.div_ceil(chunk_rows);
    let next = std::sync::atomic::AtomicUsize::new(0);
    crate::ordered::in_order(
        threads.min(n_chunks),
        CHUNKS,
        |(buf, len): &mut (Vec<u8>, usize)| {
            let k = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            let a = k.checked_mul(chunk_rows).filter(|&a| a < n)?;
            *len = format_rows::<SEP>(columns, a..(a + chunk_rows).min(n), missing, buf);
            Some(k)
        },
        |(buf, len)| out.write_all(&buf[..*len]).map(|()| true),
    )
}

/// Buffers per worker of [`write_csv_to`] (chunks formatted ahead of the
/// writing).
const CHUNKS: usize = 2;

/// Rows per chunk formatted by one thread of [`write_csv_to`].
const WRITE_CHUNK_ROWS: usize = 16 * 1024;

/// Cells per chunk of [`write_csv_to`] at most: a wide table's chunks hold
/// fewer rows (tables of up to 16 columns keep [`WRITE_CHUNK_ROWS`]), so
/// that an 11 s flight of 99 019 columns is formatted on every core
/// instead of as one chunk on one.
const WRITE_CHUNK_CELLS: usize = 16 * WRITE_CHUNK_ROWS;

/// One column as [`format_rows`] writes it.
enum Cells<'a> {
    /// Shortest round-trip text ([`NumberText`]).
    Float(&'a [f64]),
    /// Read as integers (`1003`): whole values written without `.0`.
    Integer(&'a [f64]),
    /// Text, quoted when needed.
    Text(&'a [String]),
}

impl<'a> Cells<'a> {
    fn of(c: &'a Column) -> Self {
        match c.data() {
            ColumnData::Numeric { values, .. } if c.integer_text() => Cells::Integer(values),
            ColumnData::Numeric { values, .. } => Cells::Float(values),
            ColumnData::Text(t) => Cells::Text(t),
        }
    }
}

/// The text of `rows` of `columns` (each row ending in `\n`) into
/// `out[..len]`, returning `len`; missing values as `missing`. What `out`
/// holds after `len` is left over (a buffer reused chunk after chunk is
/// neither zeroed nor cut each time).
fn format_rows<const SEP: u8>(
    columns: &[&Column],
    rows: std::ops::Range<usize>,
    missing: &[u8],
    out: &mut Vec<u8>,
) -> usize {
    let cells: Vec<Cells> = columns.iter().map(|c| Cells::of(c)).collect();
    let mut int = itoa::Buffer::new();
    let mut float = NumberText::new();
    if cells.iter().any(|c| matches!(c, Cells::Text(_))) {
        out.clear();
        for row in rows {
            for (i, c) in cells.iter().enumerate() {
                if i > 0 {
                    out.push(SEP);
                }
                match c {
                    Cells::Text(t) if SEP == b',' => push_text(out, &t[row]),
                    Cells::Text(t) if t[row].is_empty() => out.extend_from_slice(missing),
                    Cells::Text(t) => out.extend_from_slice(t[row].as_bytes()),
                    _ => out.extend_from_slice(number(c, row, missing, &mut int, &mut float)),
                }
            }
            out.push(b'\n');
        }
        return out.len();
    }
    // Numbers only: every cell fits in NUMBER_MAX bytes, so a row's
    // longest text is known. `out` is grown (never cut) to hold the next
    // rows' longest text, so it is only zeroed as far as the rows reach,
    // and each cell is copied with fixed-size moves (`put`) instead of a
    // copy call per cell. A row's cells (up to STAGED at a time) are
    // formatted first, each by a formatter of its own, and copied after
    // (see STAGED).
    let row_max = cells.len() * (NUMBER_MAX.max(missing.len()) + 1) + 1;
    let mut floats: [NumberText; STAGED] = std::array::from_fn(|_| NumberText::new());
    let mut ints: [itoa::Buffer; STAGED] = std::array::from_fn(|_| itoa::Buffer::new());
    let mut pos = 0;
    for row in rows.clone() {
        if out.len() < pos + row_max {
            let ahead = (rows.end - row)
                .min(GROW_ROWS)
                .min((GROW_BYTES / row_max).max(1));
            out.resize(pos + ahead * row_max, 0);
        }
        for group in cells.chunks(STAGED) {
            let mut texts: [&[u8]; STAGED] = [&[]; STAGED];
            for (((text, c), float), int) in
                texts.iter_mut().zip(group).zip(&mut floats).zip(&mut ints)
            {
                *text = number(c, row, missing, int, float);
            }
            for text in &texts[..group.len()] {
                pos = put(out, pos, text);
                out[pos] = SEP;
                pos += 1;
            }
        }
        // The row's last separator is its line end.
        if cells.is_empty() {
            pos += 1;
        }
        out[pos - 1] = b'\n';
    }
    pos
}

/// Cells of a row that [`format_rows`] formats before copying them. A
/// text copied right after its formatting is read back from bytes the
/// formatter has just stored in pieces (the copies were the profile's
/// hottest instructions); formatted a row at a time and then copied, and
/// with the buffer grown as the rows need instead of zeroed for the
/// longest possible text (4.9 MB per chunk of 16 384 rows of nine
/// columns), `compensate` of the 10⁶-row peer flight takes 210.8 ± 5.9
/// and 210.2 ± 4.3 ms against 220.4 ± 7.0 and 220.6 ± 4.5 ms before
/// (hyperfine, two runs of 30 each; the same bytes).
const STAGED: usize = 16;

/// Rows' worth of their longest text by which [`format_rows`] grows its
/// buffer.
const GROW_ROWS: usize = 1024;

/// The most bytes of longest text by which [`format_rows`] grows its
/// buffer at once (at least one row's): [`GROW_ROWS`] rows of a table of
/// 99 019 columns asked for 3.3 GB, which `rotor apply` of an 11 s flight
/// of that width zeroed and held for 30 s and 4.7 GB (`inspect` of it:
/// 4.8 s, 1.5 GB). The peers' 9-column output grows by 300 kB as before.
const GROW_BYTES: usize = 4 << 20;

/// The text of a number cell (`c` is not a text column): `missing` for a
/// missing value, an integer column's whole values without `.0` (read as
/// `1003`, written back as `1003`: at most 15 digits, so exact), the
/// shortest round-trip text otherwise.
#[inline(always)]
fn number<'b>(
    c: &Cells,
    row: usize,
    missing: &'b [u8],
    int: &'b mut itoa::Buffer,
    float: &'b mut NumberText,
) -> &'b [u8] {
    match c {
        Cells::Float(values) | Cells::Integer(values) if values[row].is_nan() => missing,
        Cells::Integer(values) if values[row].fract() == 0.0 => {
            int.format(values[row] as i64).as_bytes()
        }
        Cells::Float(values) | Cells::Integer(values) => float.format(values[row]).as_bytes(),
        Cells::Text(_) => unreachable!("text cells are written by push_text"),
    }
}

/// Longest text of a number cell (a sign, 17 digits, a point and an
/// exponent, `-2.2250738585072014e-308`, is 24 bytes; an integer at most
/// 20), with room to spare.
const NUMBER_MAX: usize = 32;

/// Copies `text` into `out` at `pos` and returns the position after it,
/// with two overlapping fixed-size moves for the lengths of numbers
/// (compiled to a few register moves, not a call).
#[inline(always)]
fn put(out: &mut [u8], pos: usize, text: &[u8]) -> usize {
    let n = text.len();
    let dst = &mut out[pos..pos + n];
    match n {
        16..=32 => {
            dst[..16].copy_from_slice(&text[..16]);
            dst[n - 16..].copy_from_slice(&text[n - 16..]);
        }
        8..=15 => {
            dst[..8].copy_from_slice(&text[..8]);
            dst[n - 8..].copy_from_slice(&text[n - 8..]);
        }
        4..=7 => {
            dst[..4].copy_from_slice(&text[..4]);
            dst[n - 4..].copy_from_slice(&text[n - 4..]);
        }
        // `1`, `0.0`: three byte moves cover 1 to 3 bytes.
        1..=3 => {
            dst[0] = text[0];
            dst[n / 2] = text[n / 2];
            dst[n - 1] = text[n - 1];
        }
        _ => dst.copy_from_slice(text),
    }
    pos + n
}

/// Appends a text cell, quoted when needed (see the module docs).
fn push_text(line: &mut Vec<u8>, s: &str) {
    let needs_quotes =
        s.starts_with('#') || s.bytes().any(|b| matches!(b, b',' | b'"' | b'\n' | b'\r'));
    if !needs_quotes {
        line.extend_from_slice(s.as_bytes());
        return;
    }
    line.push(b'"');
    for b in s.bytes() {
        if b == b'"' {
            line.push(b'"');
        }
        line.push(b);
    }
    line.push(b'"');
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_numbers_missing_and_quoted_text() {
        let mut t = FlightTable::new();
        t.add_column("time", vec![0.1, 1e-7]).unwrap();
        t.add_column("mag", vec![f64::NAN, -0.0]).unwrap();
        t.add_text_column("note", vec!["a,b".into(), "say \"hi\"".into()])
            .unwrap();
        t.add_text_column("id", vec!["#1".into(), "plain".into()])
            .unwrap();
        let mut out = Vec::new();
        write_csv_to(&t, &mut out).unwrap();
        let s = String::from_utf8(out).unwrap();
        assert_eq!(
            s,
            "time,mag,note,id\n0.1,,\"a,b\",\"#1\"\n1e-7,-0.0,\"say \"\"hi\"\"\",plain\n"
        );
    }

    /// A wide table is written in chunks of fewer rows
    /// ([`WRITE_CHUNK_CELLS`]), its buffer growing by at most
    /// [`GROW_BYTES`] at once (here 25 of its 165 kB rows): the bytes of
    /// one pass over every row.
    #[test]
    fn a_wide_table_is_written_in_small_chunks_with_the_same_bytes() {
        let (n, width) = (2 * WRITE_CHUNK_CELLS / 5000 + 3, 5000);
        let mut t = FlightTable::new();
        for c in 0..width {
            let v: Vec<f64> = (0..n)
                .map(|i| (i * width + c) as f64 * 0.25 - 7.0)
                .collect();
            t.add_column(&format!("c{c}"), v).unwrap();
        }
        let mut out = Vec::new();
        write_csv_to(&t, &mut out).unwrap();
        let columns: Vec<&Column> = t.columns().iter().collect();
        let mut rows = Vec::new();
        let len = format_rows::<b','>(&columns, 0..n, b"", &mut rows);
        let header_end = out.iter().position(|&b| b == b'\n').unwrap() + 1;
        assert_eq!(&out[header_end..], &rows[..len]);
        assert_eq!(String::from_utf8_lossy(&out).lines().count(), n + 1);
    }

    /// Rows formatted in chunks on several threads are the bytes of one
    /// pass over every row, in order.
    #[test]
    fn chunked_rows_are_written_in_order() {
        let n = 3 * WRITE_CHUNK_ROWS + 123;
        let mut t = FlightTable::new();
        let x: Vec<f64> = (0..n)
            .map(|i| {
                if i % 1001 == 7 {
                    f64::NAN
                } else {
                    i as f64 * 0.37 - 1e3
                }
            })
            .collect();
        t.add_column("x", x).unwrap();
        t.add_text_column("tag", (0..n).map(|i| format!("r{i}")).collect())
            .unwrap();
        let mut out = Vec::new();
        write_csv_to(&t, &mut out).unwrap();
        let columns: Vec<&Column> = t.columns().iter().collect();
        let mut one = b"x,tag\n".to_vec();
        let mut rows = Vec::new();
        let len = format_rows::<b','>(&columns, 0..n, b"", &mut rows);
        rows.truncate(len);
        one.extend(rows);
        assert_eq!(out, one);
        let text = String::from_utf8(out).unwrap();
        assert_eq!(text.lines().count(), n + 1);
        assert_eq!(text.lines().nth(8).unwrap(), ",r7");
        // No rows: the header alone.
        let mut empty = FlightTable::new();
        empty.add_column("x", Vec::new()).unwrap();
        empty.add_column("y", Vec::new()).unwrap();
        let mut out = Vec::new();
        write_csv_to(&empty, &mut out).unwrap();
        assert_eq!(out, b"x,y\n");
    }

    /// The numbers-only path (fixed-size moves into a chunk sized for its
    /// longest text) writes every cell as [`NumberText`] writes it, for
    /// texts of every length (1 to 24 bytes), missing cells and integers.
    #[test]
    fn number_rows_are_each_cells_text() {
        let mut values = vec![
            0.0,
            -0.0,
            5e-324,
            -2.2250738585072014e-308,
            f64::MAX,
            -f64::MAX,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            1e16,
            9999999999999998.0,
            -0.000012345678901234567,
            0.1,
            -1e-7,
            53210.4,
        ];
        let mut state = 20261128u64;
        for k in 0..6000 {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let v = f64::from_bits(state);
            let scale = 10f64.powi(k % 18);
            values.push(if k % 2 == 0 {
                v
            } else {
                ((state >> 11) as f64 / (1u64 << 53) as f64 * 2e5 - 1e5) * scale.round() / scale
            });
        }
        let n = values.len();
        let shifted: Vec<f64> = (0..n).map(|i| values[(i + 7) % n]).collect();
        let mut t = FlightTable::new();
        t.add_column("a", values.clone()).unwrap();
        t.add_column("b", shifted.clone()).unwrap();
        let columns: Vec<&Column> = t.columns().iter().collect();
        let mut got = Vec::new();
        let len = format_rows::<b','>(&columns, 0..n, b"", &mut got);
        got.truncate(len);
        let mut text = NumberText::new();
        let mut cell = |v: f64| {
            if v.is_nan() {
                String::new()
            } else {
                text.format(v).to_string()
            }
        };
        let want: String = (0..n)
            .map(|i| format!("{},{}\n", cell(values[i]), cell(shifted[i])))
            .collect();
        assert!(
            values
                .iter()
                .any(|v| NumberText::new().format(*v).len() == 24)
        );
        assert_eq!(String::from_utf8(got).unwrap(), want);
        // One column: missing as `NaN`.
        let mut one = FlightTable::new();
        one.add_column("a", vec![1.5, f64::NAN]).unwrap();
        let mut out = Vec::new();
        write_csv_to(&one, &mut out).unwrap();
        assert_eq!(out, b"a\n1.5\nNaN\n");
        // Integer columns as read (`1003`, not `1003.0`).
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("in.csv");
        std::fs::write(&p, "n,x\n1003,1.5\n-42,\n9,2\n10,3\n").unwrap();
        let read = crate::read_csv(&p, &crate::ReadOptions::default()).unwrap();
        let mut out = Vec::new();
        write_csv_to(&read, &mut out).unwrap();
        assert_eq!(
            String::from_utf8(out).unwrap(),
            "n,x\n1003,1.5\n-42,\n9,2.0\n10,3.0\n"
        );
    }

    /// Rows of more cells than one stage of [`format_rows`] (the cells of
    /// a row are formatted [`STAGED`] at a time and copied after) and rows
    /// filling a stage exactly are each cell's text in column order, with
    /// whole values, missing cells and texts of many lengths, over more
    /// rows than one growth of the buffer ([`GROW_ROWS`]). (Columns read as
    /// integers are in `number_rows_are_each_cells_text`.)
    #[test]
    fn rows_wider_than_a_stage_are_each_cells_text() {
        let rows = 2 * GROW_ROWS + 3;
        for width in [1, STAGED - 1, STAGED, STAGED + 1, 2 * STAGED + 5] {
            let mut t = FlightTable::new();
            let mut want = vec![String::new(); rows];
            let mut text = NumberText::new();
            for c in 0..width {
                let values: Vec<f64> = (0..rows)
                    .map(|r| match (r + c) % 11 {
                        0 => f64::NAN,
                        1 => -((r * 31 + c) as f64),
                        k => (r as f64 + 0.5) * 10f64.powi(k as i32 - 6) / (c as f64 + 3.0),
                    })
                    .collect();
                for (r, v) in values.iter().enumerate() {
                    if c > 0 {
                        want[r].push(',');
                    }
                    if !v.is_nan() {
                        want[r].push_str(text.format(*v));
                    }
                }
                t.add_column(&format!("c{c}"), values).unwrap();
            }
            let columns: Vec<&Column> = t.columns().iter().collect();
            let mut got = Vec::new();
            let len = format_rows::<b','>(&columns, 0..rows, b"", &mut got);
            got.truncate(len);
            let want: String = want.iter().map(|r| format!("{r}\n")).collect();
            assert_eq!(String::from_utf8(got).unwrap(), want, "{width} columns");
        }
    }

    /// A chunk buffer reused for a chunk of shorter rows than the last
    /// (it is neither cut nor zeroed in between) gives that chunk's text
    /// alone, and a whole table of such chunks is written in order.
    #[test]
    fn a_reused_chunk_buffer_holds_only_its_chunk() {
        let n = 2 * WRITE_CHUNK_ROWS + 5;
        let long: Vec<f64> = (0..n)
            .map(|i| {
                if i < WRITE_CHUNK_ROWS {
                    1.0 / (i as f64 + 3.0)
                } else {
                    (i % 7) as f64
                }
            })
            .collect();
        let mut t = FlightTable::new();
        t.add_column("a", long.clone()).unwrap();
        t.add_column("b", long.iter().map(|v| -v).collect())
            .unwrap();
        let columns: Vec<&Column> = t.columns().iter().collect();
        let mut buf = Vec::new();
        let first = format_rows::<b','>(&columns, 0..WRITE_CHUNK_ROWS, b"", &mut buf);
        let second = format_rows::<b','>(&columns, WRITE_CHUNK_ROWS..n, b"", &mut buf);
        assert!(second < first && buf.len() > second);
        let mut text = NumberText::new();
        let want: String = (WRITE_CHUNK_ROWS..n)
            .map(|i| {
                let a = text.format(long[i]).to_string();
                format!("{a},{}\n", text.format(-long[i]))
            })
            .collect();
        assert_eq!(std::str::from_utf8(&buf[..second]).unwrap(), want);
        let mut out = Vec::new();
        write_csv_to(&t, &mut out).unwrap();
        let all: String = (0..n)
            .map(|i| {
                let a = text.format(long[i]).to_string();
                format!("{a},{}\n", text.format(-long[i]))
            })
            .collect();
        assert_eq!(String::from_utf8(out).unwrap(), format!("a,b\n{all}"));
    }

    #[test]
    fn a_file_is_replaced_whole_and_no_temporary_is_left() {
        let _serial = crate::atomic::serial();
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("out.csv");
        let mut t = FlightTable::new();
        t.add_column("time", vec![0.0, 1.0]).unwrap();
        write_csv(&t, &p).unwrap();
        t.add_column("mag", vec![1.0, 2.0]).unwrap();
        write_csv(&t, &p).unwrap();
        assert_eq!(
            std::fs::read_to_string(&p).unwrap(),
            "time,mag\n0.0,1.0\n1.0,2.0\n"
        );
        assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 1);
        // A folder that does not exist: an error naming the file, nothing left.
        let e = write_csv(&t, &d.path().join("no/out.csv")).unwrap_err();
        assert!(
            !e.is_bad_input() && e.to_string().contains("out.csv"),
            "{e}"
        );
    }
}
