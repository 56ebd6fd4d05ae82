//! The CSV reader's fast path: runs of *clean* rows parsed on all cores.
//!
//! A clean row is a line without a quote character whose fields (split on
//! the delimiter, as many as the header has names) are all numbers or
//! missing markers ([`parse_cell`]); comment lines (`#` first) and blank
//! lines between them are skipped as the general reader skips them. After
//! the header, the file is cut into pieces of about [`PIECE_BYTES`], each
//! ending at a line end, which workers on all cores read and parse into
//! column vectors and the calling thread appends to the [`TableBuilder`]
//! in file order ([`push_clean_rows`]), so the table (values, missing
//! counts, integer flags, line numbers) is the same whatever the number of
//! threads.
//!
//! The fast path never reports an error. At the first line that is not
//! clean (a quote, a text cell, a bad cell, a short or long row, a line
//! longer than a piece) it stops and returns that line's byte
//! offset and line number; the general reader ([`super::csv_read`]) goes on
//! from there with the same builder, so every warning, text column and
//! error (with its file, line, row and column) is the general reader's own.
//!
//! On two cores this reads a 10⁷-row flight about 1.5× faster than the
//! general reader, whose tokenizer and cell parser run one thread each
//! (README, reading benchmark).
//!
//! Whitespace tables and Geosoft XYZ files ([`crate::xyz`]) take the same
//! path with a whitespace [`Shape`]: fields parted by runs of spaces and
//! tabs, their comment lines, and for XYZ the `Line`/`Tie` records, kept
//! per piece ([`CleanRows::records`]) for the reader's line columns.

use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::ops::Range;
use std::path::Path;
use std::sync::Mutex;

use crate::builder::{TableBuilder, is_integer_text};
use crate::cell::{Cell, EXACT_POWERS_OF_TEN, MissingKind, parse_cell, plain_decimal_prefix};
use crate::error::{IoError, Result};
use crate::label_texts::LabelTexts;
use crate::ordered::{in_order, lock};
use crate::table::Missing;
use crate::xyz::{Dialect, Kind, line_kind, record_text};

/// Bytes per piece (about; a piece ends at a line end).
pub(crate) const PIECE_BYTES: usize = 512 << 10;

/// A place in the file: byte offset of a line's start and its 1-based number.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Resume {
    pub offset: u64,
    pub line: u64,
}

/// How the rows of the file are laid out (from the header).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Shape<'a> {
    pub delimiter: u8,
    pub n_fields: usize,
    /// The header ended with `\r\n`: the last field of each row loses a final `\r`.
    pub crlf: bool,
    /// A whitespace table or XYZ file ([`crate::xyz`]) of this dialect:
    /// fields separated by runs of spaces and tabs, with any before the
    /// first and after the last, lines classified by
    /// [`crate::xyz::line_kind`]; `delimiter` and `crlf` are not used.
    pub whitespace: Option<Dialect>,
    /// The fields read, when not all are ([`crate::Fields::Only`]): the
    /// others are only delimited, as the general reader leaves them
    /// unparsed. A line whose unread fields hold a quote or, in a
    /// whitespace table, an ASCII space other than a blank is not clean:
    /// the general reader splits it its own way.
    pub wanted: Option<&'a [bool]>,
    /// The `line` column, whose cells' texts are kept
    /// ([`CleanRows::labels`], [`crate::label_texts`]).
    pub label: Option<usize>,
}

/// Whether field `i` of `shape` is read.
#[inline(always)]
fn read(shape: &Shape, i: usize) -> bool {
    shape.wanted.is_none_or(|w| w[i])
}

/// The end of the unread field at `piece[p..]` of a delimited row, for
/// [`plain_row`]: the position of the first delimiter, `\n`, `\r` or quote
/// (the file's end without one). [`plain_row`] takes a delimiter, a line
/// end or a CRLF there as [`plain_decimal_field`]'s end, and leaves the line
/// to [`clean_row`] at anything else (a quote: to the general reader).
#[inline]
fn unread_field_end(piece: &[u8], p: usize, delimiter: u8) -> usize {
    let rest = piece.get(p..).unwrap_or_default();
    let stop = |&b: &u8| b == delimiter || matches!(b, b'\n' | b'\r' | b'"');
    p + rest.iter().position(stop).unwrap_or(rest.len())
}

/// The clean rows at the start of one piece, column by column.
#[derive(Debug, Default)]
pub(crate) struct CleanRows {
    /// Values of each column (NaN where missing).
    pub values: Vec<Vec<f64>>,
    /// Missing cells of each column by reason.
    pub missing: Vec<Missing>,
    /// Whether every value of each column was written as an integer.
    pub integers: Vec<bool>,
    /// Rows parsed.
    pub rows: usize,
    /// `(row, line)` of each row whose line (counted from the piece's first
    /// line, 0) does not follow the previous row's line; the first row's always.
    pub breaks: Vec<(usize, u64)>,
    /// Line of the last row, counted from the piece's first line.
    pub last_row_line: u64,
    /// Lines consumed (rows, comments, blank lines).
    pub lines: u64,
    /// Bytes consumed.
    pub bytes: usize,
    /// Whether the piece stopped at a line that is not clean.
    pub stopped: bool,
    /// The Geosoft `Line`/`Tie` records read: `(rows before it in the
    /// piece, its number, whether a tie, its number as written)`.
    pub records: Vec<(usize, f64, bool, Vec<u8>)>,
    /// The texts of the `line` column's cells ([`Shape::label`]).
    pub labels: LabelTexts,
}

impl CleanRows {
    /// No rows yet, for `n` columns; the vectors keep their capacity, so a
    /// piece buffer reused piece after piece is allocated once.
    fn clear(&mut self, n: usize) {
        self.values.resize_with(n, Vec::new);
        for v in &mut self.values {
            v.clear();
        }
        self.missing.clear();
        self.missing.resize(n, Missing::default());
        self.integers.clear();
        self.integers.resize(n, true);
        self.rows = 0;
        self.breaks.clear();
        self.last_row_line = 0;
        self.lines = 0;
        self.bytes = 0;
        self.stopped = false;
        self.records.clear();
        self.labels.clear();
    }

    /// Counts a row (its values already pushed) on `line` of the piece.
    fn row_on(&mut self, line: u64) {
        if self.rows == 0 || line != self.last_row_line + 1 {
            self.breaks.push((self.rows, line));
        }
        self.last_row_line = line;
        self.rows += 1;
    }
}

/// Parses the clean rows at the start of `piece` (whole lines; only the
/// file's last line may lack its line end).
pub(crate) fn parse_piece(piece: &[u8], shape: Shape<'_>, out: &mut CleanRows) {
    let n = shape.n_fields;
    out.clear(n);
    let quotes = memchr::memchr(b'"', piece).is_some();
    // One row's missing cells before they are counted.
    let mut missing: Vec<(usize, MissingKind)> = Vec::new();
    let mut pos = 0;
    let mut line = 0u64;
    while pos < piece.len() {
        // Most lines: plain decimals and the line end, in one pass.
        let row = if shape.whitespace.is_some() {
            whitespace_row(
                piece,
                pos,
                shape,
                &mut out.values,
                &mut out.integers,
                &mut out.labels,
            )
        } else {
            plain_row(
                piece,
                pos,
                shape,
                &mut out.values,
                &mut out.integers,
                &mut out.labels,
            )
        };
        if let Some(end) = row {
            out.row_on(line);
            line += 1;
            pos = (end + 1).min(piece.len());
            continue;
        }
        for v in &mut out.values {
            v.truncate(out.rows);
        }
        let end = memchr::memchr(b'\n', &piece[pos..]).map_or(piece.len(), |i| pos + i);
        let body = &piece[pos..end];
        let next = (end + 1).min(piece.len());
        let skip = if let Some(dialect) = shape.whitespace {
            // As the whitespace reader classifies the line (it drops
            // line-end `\r`s first).
            let mut t = body;
            while let [rest @ .., b'\r'] = t {
                t = rest;
            }
            match line_kind(dialect, t) {
                Some(Kind::Data) => false,
                Some(Kind::Record { number, tie }) => {
                    let text = record_text(t).to_vec();
                    out.records.push((out.rows, number, tie, text));
                    true
                }
                Some(Kind::Blank | Kind::Comment) => true,
                // A record without a number: the general reader's error.
                None => {
                    out.stopped = true;
                    break;
                }
            }
        } else {
            body.first() == Some(&b'#')
                || (body.trim_ascii().is_empty() && !body.contains(&shape.delimiter))
        };
        if !skip {
            let clean = if shape.whitespace.is_some() {
                whitespace_clean_row(
                    body,
                    shape,
                    &mut out.values,
                    &mut out.integers,
                    &mut out.labels,
                    &mut missing,
                )
            } else {
                !(quotes && body.contains(&b'"'))
                    && clean_row(
                        piece,
                        pos..end,
                        shape,
                        &mut out.values,
                        &mut out.integers,
                        &mut out.labels,
                        &mut missing,
                    )
            };
            if !clean {
                for v in &mut out.values {
                    v.truncate(out.rows);
                }
                out.stopped = true;
                break;
            }
            for &(i, kind) in &missing {
                out.missing[i].count(kind);
            }
            out.row_on(line);
        }
        line += 1;
        pos = next;
    }
    out.lines = line;
    out.bytes = pos;
}

/// The line starting at `piece[start]` when every field is a plain decimal
/// ([`plain_decimal_field`]): pushes its values and clears the integer
/// flags as [`clean_row`] does, and returns the position of its line end
/// (`piece.len()` for an unterminated last line). `None` (some columns may
/// then hold one value more than the others) leaves the line to
/// [`clean_row`], which reads the same fields the same way: this is the
/// same parse without first searching the line end.
#[inline]
fn plain_row(
    piece: &[u8],
    start: usize,
    shape: Shape<'_>,
    values: &mut [Vec<f64>],
    integers: &mut [bool],
    labels: &mut LabelTexts,
) -> Option<usize> {
    // The label column's index (none: past every field).
    let label = shape.label.unwrap_or(usize::MAX);
    let last = shape.n_fields.saturating_sub(1);
    let mut p = start;
    for (i, (column, integer)) in values.iter_mut().zip(integers.iter_mut()).enumerate() {
        let end = if read(&shape, i) {
            let (v, is_integer, len) = plain_decimal_field(piece, p, piece.len())?;
            column.push(v);
            *integer &= is_integer;
            if i == label {
                labels.note_at(piece, p, len, v);
            }
            p + len
        } else {
            unread_field_end(piece, p, shape.delimiter)
        };
        if i < last {
            if piece.get(end) != Some(&shape.delimiter) {
                return None;
            }
            p = end + 1;
        } else {
            return match piece.get(end) {
                None | Some(b'\n') => Some(end),
                Some(b'\r') if shape.crlf && matches!(piece.get(end + 1), None | Some(b'\n')) => {
                    Some(end + 1)
                }
                _ => None,
            };
        }
    }
    None
}

/// [`plain_row`] for a whitespace table: the line starting at
/// `piece[start]` when it is `n_fields` plain decimals separated by runs of
/// spaces and tabs, with any before the first and after the last and an
/// optional `\r` before the line end (the whitespace reader drops line-end
/// `\r`s); the position of its line end. Any other line (a dummy `*`, an
/// exponent, a field count that is not the header's) is `None`, for
/// [`whitespace_clean_row`].
#[inline]
fn whitespace_row(
    piece: &[u8],
    start: usize,
    shape: Shape<'_>,
    values: &mut [Vec<f64>],
    integers: &mut [bool],
    labels: &mut LabelTexts,
) -> Option<usize> {
    // The label column's index (none: past every field).
    let label = shape.label.unwrap_or(usize::MAX);
    let blank = |p: usize| matches!(piece.get(p), Some(b' ' | b'\t'));
    let mut p = start;
    while blank(p) {
        p += 1;
    }
    let fields = values.iter_mut().zip(integers.iter_mut());
    for (i, (column, integer)) in fields.take(shape.n_fields).enumerate() {
        if read(&shape, i) {
            let (v, is_integer, len) = plain_decimal_field(piece, p, piece.len())?;
            column.push(v);
            *integer &= is_integer;
            if i == label {
                labels.note_at(piece, p, len, v);
            }
            p += len;
        } else {
            // An unread field: its bytes up to any ASCII space (one other
            // than a blank or a line end is then not clean).
            let rest = piece.get(p..).unwrap_or_default();
            let len = rest
                .iter()
                .position(u8::is_ascii_whitespace)
                .unwrap_or(rest.len());
            if len == 0 {
                return None;
            }
            p += len;
        }
        // A field ends at a blank or the line's end.
        if !blank(p) && !matches!(piece.get(p), None | Some(b'\n' | b'\r')) {
            return None;
        }
        while blank(p) {
            p += 1;
        }
    }
    while piece.get(p) == Some(&b'\r') {
        p += 1;
    }
    match piece.get(p) {
        None | Some(b'\n') => Some(p),
        _ => None,
    }
}

/// [`clean_row`] for a whitespace table: the fields of `line` (without its
/// line end), split on runs of spaces and tabs after dropping line-end
/// `\r`s, each read by [`parse_cell`] (a dummy `*`, `NaN`, an exponent);
/// `false` for a line that is not clean (a field count that is not the
/// header's, a cell that is not a number or a missing marker, or another
/// ASCII blank, which the whitespace reader would also split on).
#[inline]
fn whitespace_clean_row(
    line: &[u8],
    shape: Shape<'_>,
    values: &mut [Vec<f64>],
    integers: &mut [bool],
    labels: &mut LabelTexts,
    missing: &mut Vec<(usize, MissingKind)>,
) -> bool {
    // The label column's index (none: past every field).
    let label = shape.label.unwrap_or(usize::MAX);
    missing.clear();
    let mut line = line;
    while let [rest @ .., b'\r'] = line {
        line = rest;
    }
    let mut fields = line
        .split(|b| matches!(b, b' ' | b'\t'))
        .filter(|f| !f.is_empty());
    for (i, column) in values.iter_mut().enumerate().take(shape.n_fields) {
        let Some(f) = fields.next() else {
            return false; // short row
        };
        if f.iter().any(u8::is_ascii_whitespace) {
            return false;
        }
        if read(&shape, i) && !push_cell(f, i, column, integers, missing) {
            return false;
        }
        if i == label {
            labels.note(f, column.last().copied().unwrap_or(f64::NAN));
        }
    }
    fields.next().is_none() // else a long row
}

/// Splits and parses the line `piece[line]`, pushing one value onto each
/// column of `values`, clearing the flag in `integers` of a column whose
/// value is not written as an integer and listing the missing cells in
/// `missing`; `false` when the line is not clean (some columns may then
/// hold one value more than the others).
///
/// The integer flags are cleared at once, even for a line that turns out
/// not clean: the general reader then reads the same line and clears the
/// same flags for the cells it stores as numbers (fields split the same
/// way: no quote), or stops the read, or turns the column to text, whose
/// flag does not count.
#[inline]
fn clean_row(
    piece: &[u8],
    line: Range<usize>,
    shape: Shape<'_>,
    values: &mut [Vec<f64>],
    integers: &mut [bool],
    labels: &mut LabelTexts,
    missing: &mut Vec<(usize, MissingKind)>,
) -> bool {
    // The label column's index (none: past every field).
    let label = shape.label.unwrap_or(usize::MAX);
    missing.clear();
    let last = shape.n_fields.saturating_sub(1);
    let mut start = line.start;
    for (i, column) in values.iter_mut().enumerate() {
        if start > line.end {
            return false; // short row
        }
        // Most cells: a plain decimal ended by the delimiter or the line.
        let wanted = read(&shape, i);
        if wanted && let Some((v, integer, len)) = plain_decimal_field(piece, start, line.end) {
            let end = start + len;
            let end_ok = if i == last {
                end == line.end || (shape.crlf && end + 1 == line.end && piece[end] == b'\r')
            } else {
                end < line.end && piece[end] == shape.delimiter
            };
            if end_ok {
                column.push(v);
                integers[i] &= integer;
                if i == label {
                    labels.note_at(piece, start, end - start, v);
                }
                start = end + 1;
                continue;
            }
        }
        let rest = &piece[start..line.end];
        let len = if i == last {
            rest.len()
        } else {
            match memchr::memchr(shape.delimiter, rest) {
                Some(len) => len,
                None => return false, // short row
            }
        };
        let f = &rest[..len];
        if i == last && f.contains(&shape.delimiter) {
            return false; // long row
        }
        let f = if shape.crlf && i == last {
            f.strip_suffix(b"\r").unwrap_or(f)
        } else {
            f
        };
        if wanted && !push_cell(f, i, column, integers, missing) {
            return false;
        }
        if wanted && i == label {
            labels.note(f, column.last().copied().unwrap_or(f64::NAN));
        }
        start += len + 1;
    }
    true
}

/// The cell `f` of column `i` read by [`parse_cell`] onto `column`: a
/// number (clearing the column's integer flag unless written as an
/// integer) or NaN with its reason in `missing`; `false` for a cell that
/// is neither (text, a NUL, invalid UTF-8).
#[inline]
fn push_cell(
    f: &[u8],
    i: usize,
    column: &mut Vec<f64>,
    integers: &mut [bool],
    missing: &mut Vec<(usize, MissingKind)>,
) -> bool {
    match parse_cell(f) {
        Ok(Cell::Value(v)) => {
            column.push(v);
            integers[i] &= is_integer_text(f);
        }
        Ok(Cell::Missing(kind)) => {
            column.push(f64::NAN);
            missing.push((i, kind));
        }
        Err(_) => return false,
    }
    true
}

/// A plain decimal at `text[p..]` within `text[..end]` (optional sign,
/// digits, optional point and digits), as [`parse_cell`] reads such a
/// cell: its value, whether it is an integer as [`is_integer_text`] has
/// it, and its length; the caller checks what follows it. `None` sends the
/// cell to [`parse_cell`]. The value is `±m / 10^k` with `m < 2⁵³`, at
/// most 19 digits and `k ≤ 22`, the same division as [`crate::cell`]'s fast
/// path, so the same bits.
///
/// Runs of at most 7 digits are read 8 bytes at a time ([`digit_run`]),
/// which may look past `end` into the next lines of `text`: a digit run
/// stops at the line end, so only the bytes of the cell count.
#[inline(always)]
fn plain_decimal_field(text: &[u8], p: usize, end: usize) -> Option<(f64, bool, usize)> {
    let first = *text[..end].get(p)?;
    // No branch on the sign: signs mix in a column of field components.
    let negative = first == b'-';
    let i = p + usize::from(negative | (first == b'+'));
    let Some((int, int_len)) = digit_run(text, i) else {
        return plain_decimal_prefix(&text[p..end]);
    };
    let mut q = i + int_len;
    let (mut m, mut k, mut point) = (int, 0, false);
    if q < end && text[q] == b'.' {
        let Some((frac, frac_len)) = digit_run(text, q + 1) else {
            return plain_decimal_prefix(&text[p..end]);
        };
        m = int * POWERS_OF_TEN_U64[frac_len] + frac;
        k = frac_len;
        q += 1 + frac_len;
        point = true;
    }
    if int_len + k == 0 || q > end {
        return None;
    }
    // At most 14 digits: m < 10¹⁴ < 2⁵³, exact as i64 and as f64 (the
    // signed conversion is one instruction, the unsigned one several).
    let v = m as i64 as f64 / EXACT_POWERS_OF_TEN[k];
    Some((
        f64::from_bits(v.to_bits() | u64::from(negative) << 63),
        !point,
        q - p,
    ))
}

/// 10⁰ … 10⁷.
const POWERS_OF_TEN_U64: [u64; 8] = [1, 10, 100, 1_000, 10_000, 100_000, 1_000_000, 10_000_000];

/// The value and length of the run of decimal digits at `text[p..]` when it
/// is at most 7 digits long and 8 bytes are there to load; `None` sends the
/// caller to the byte-by-byte parser. SWAR: the 8 bytes as one little-endian
/// `u64`, a bit per byte that is not a digit, and the digits combined in
/// three multiplications (pairs, quads, the eight: Lemire, "Faster integer
/// parsing", 2018), with no branch on the number of digits.
#[inline(always)]
fn digit_run(text: &[u8], p: usize) -> Option<(u64, usize)> {
    let bytes: [u8; 8] = text.get(p..p + 8)?.try_into().ok()?;
    // Digits become 0–9; every other byte something else.
    let t = u64::from_le_bytes(bytes) ^ 0x3030_3030_3030_3030;
    // Bit 7 of each byte: set when the byte is ≥ 10 (no carry between bytes).
    let not_digit =
        (((t & 0x7f7f_7f7f_7f7f_7f7f) + 0x7676_7676_7676_7676) | t) & 0x8080_8080_8080_8080;
    if not_digit == 0 {
        return None;
    }
    let len = (not_digit.trailing_zeros() / 8) as usize;
    if len == 0 {
        return Some((0, 0));
    }
    // The run's digits in the high bytes, zeros (leading zeros) below.
    let v = t << (8 * (8 - len));
    let v = (v.wrapping_mul(10) + (v >> 8)) & 0x00ff_00ff_00ff_00ff;
    let v = (v.wrapping_mul(100) + (v >> 16)) & 0x0000_ffff_0000_ffff;
    let v = (v.wrapping_mul(10_000) + (v >> 32)) & 0xffff_ffff;
    Some((v, len))
}

/// The fast path's setting for the readers: all cores
/// (`aeromag_core::parallel::threads`: `AEROMAG_THREADS` or the available
/// cores, at most 8; the table read is the same whatever the number),
/// pieces of [`PIECE_BYTES`].
pub(crate) fn on_all_cores() -> Option<(usize, usize)> {
    Some((aeromag_core::parallel::threads(), PIECE_BYTES))
}

/// Appends the clean rows of `path` from `from` (a line start after the
/// header) to `builder`, in pieces of about `piece_bytes` (whole lines)
/// read and parsed by `threads` workers, and shows each piece appended to
/// `on_piece` (in file order); returns where the general reader must go on
/// (`None`: the file ended clean). See the module docs.
///
/// An ordered pipeline ([`in_order`]): each worker reads the file's next
/// piece (in turn, under a lock, numbered) and parses it; the calling
/// thread appends the parsed pieces in file order. [`PIECES`] buffers per
/// worker go round, so memory stays bounded. Against the reader before
/// (rounds of one 4 MiB piece per thread, the next round read and the last
/// appended during each, all joined after it), reading alone, whole
/// process (`examples/read_time` `FILE 1`, hyperfine, 30 runs each, on two
/// cores): the 10⁶-row peer flight (53 MB) 98.8 ± 4.1 → 72.4 ± 2.3 ms; its
/// 10⁵-row one 11.8 ± 0.9 → 9.8 ± 0.7 ms; a 10⁶-row XYZ file 102.1 ± 6.5 →
/// 79.2 ± 2.2 ms. Pieces of 512 KiB read 10⁵ rows faster than 2 MiB (9.8
/// against 11.2 ms) and 10⁶ rows as fast.
pub(crate) fn push_clean_rows(
    builder: &mut TableBuilder,
    path: &Path,
    from: Resume,
    shape: Shape,
    threads: usize,
    piece_bytes: usize,
    on_piece: &mut dyn FnMut(&CleanRows),
) -> Result<Option<Resume>> {
    let file = path.display().to_string();
    let read_err = |line, source| IoError::Read {
        file: file.clone(),
        line,
        source,
    };
    let mut f = File::open(path).map_err(|source| IoError::Open {
        file: file.clone(),
        source,
    })?;
    f.seek(SeekFrom::Start(from.offset))
        .map_err(|e| read_err(from.line, e))?;
    let source = Mutex::new(Pieces {
        file: f,
        piece_bytes: piece_bytes.max(1),
        carry: Vec::new(),
        next: 0,
        ended: false,
    });
    let mut at = from;
    let mut stop = None;
    // Appends a piece in order; `Ok(false)` (`stop` set) where the general
    // reader must go on.
    let mut append = |piece: &mut Piece| -> Result<bool> {
        // Where the general reader goes on if this piece is not all appended.
        stop = Some(at);
        match std::mem::take(&mut piece.cut) {
            Cut::Lines => {}
            // A line longer than a piece: the general reader has the limit.
            Cut::LongLine => return Ok(false),
            Cut::Failed(e) => return Err(read_err(at.line, e)),
        }
        let part = &piece.rows;
        let bytes_read = at.offset + part.bytes as u64;
        if !builder.append_clean(part, at.line, bytes_read)? {
            return Ok(false);
        }
        on_piece(part);
        at = Resume {
            offset: bytes_read,
            line: at.line + part.lines,
        };
        stop = part.stopped.then_some(at);
        Ok(!part.stopped)
    };
    in_order(
        threads,
        PIECES,
        |piece: &mut Piece| {
            let number = {
                let mut src = lock(&source);
                if src.ended {
                    return None;
                }
                piece.cut = match src.read_into(&mut piece.text) {
                    Ok((false, _)) => return None,
                    Ok((true, cut)) => cut,
                    Err(e) => {
                        src.ended = true;
                        Cut::Failed(e)
                    }
                };
                src.next += 1;
                src.next - 1
            };
            if matches!(piece.cut, Cut::Lines) {
                parse_piece(&piece.text, shape, &mut piece.rows);
            }
            Some(number)
        },
        |piece| {
            let go_on = append(piece);
            if !matches!(go_on, Ok(true)) {
                // No piece read after this.
                lock(&source).ended = true;
            }
            go_on
        },
    )?;
    Ok(stop)
}

/// Pieces each worker of [`push_clean_rows`] may have read ahead of the
/// appending.
const PIECES: usize = 2;

/// The file being cut into pieces ([`push_clean_rows`]).
struct Pieces {
    file: File,
    piece_bytes: usize,
    /// The text after the last piece's last line end.
    carry: Vec<u8>,
    /// Number of the next piece.
    next: usize,
    /// No piece after this: the file's end, a read error, a line longer
    /// than a piece, or the appending has stopped.
    ended: bool,
}

/// One piece's buffers: its text (whole lines) and its parsed rows.
#[derive(Default)]
struct Piece {
    text: Vec<u8>,
    rows: CleanRows,
    cut: Cut,
}

/// How a piece was cut from the file.
#[derive(Default)]
enum Cut {
    /// Whole lines (the last may lack its line end at the file's end).
    #[default]
    Lines,
    /// No line end in a whole piece.
    LongLine,
    Failed(std::io::Error),
}

impl Pieces {
    /// The next piece into `text`: the carried text, then the file's next
    /// bytes up to `piece_bytes`, cut after the last line end (the rest
    /// carried); `false` at the end of the file with nothing left.
    fn read_into(&mut self, text: &mut Vec<u8>) -> std::io::Result<(bool, Cut)> {
        text.clear();
        text.append(&mut self.carry);
        let want = self.piece_bytes.saturating_sub(text.len()) as u64;
        let got = (&mut self.file).take(want).read_to_end(text)? as u64;
        if got < want {
            self.ended = true;
            return Ok((!text.is_empty(), Cut::Lines));
        }
        match memchr::memrchr(b'\n', text) {
            Some(i) => {
                self.carry.extend_from_slice(&text[i + 1..]);
                text.truncate(i + 1);
                Ok((true, Cut::Lines))
            }
            None => {
                self.ended = true;
                Ok((true, Cut::LongLine))
            }
        }
    }
}

/// What the tests of the fast path's readers ([`crate::csv_read`],
/// [`crate::xyz`]) share: a file of lines among runs of clean rows, and the
/// check that the fast path reads it as the general reader alone does.
#[cfg(test)]
pub(crate) mod check {
    use crate::error::Result;
    use crate::table::FlightTable;
    use proptest::test_runner::TestCaseError;
    use std::path::Path;

    /// `head`, then each of `lines` (`None`: a run of 40 clean rows,
    /// `clean(k, i)` the `i`-th of the `k`-th run, so that pieces hold
    /// many), each ended by `end`; the last line end cut without
    /// `last_newline`.
    pub(crate) fn text(
        head: &str,
        lines: &[Option<String>],
        clean: impl Fn(usize, usize) -> String,
        end: &str,
        last_newline: bool,
    ) -> Vec<u8> {
        let mut text = head.to_string();
        for (k, l) in lines.iter().enumerate() {
            match l {
                Some(l) => text.push_str(l),
                None => text.push_str(&(0..40).map(|i| clean(k, i)).collect::<Vec<_>>().join(end)),
            }
            text.push_str(end);
        }
        if !last_newline && text.ends_with(end) {
            text.truncate(text.len() - end.len());
        }
        text.into_bytes()
    }

    /// `text` read with `fields` has the columns of the whole read that
    /// `fields` asks for (the first when it asks for none the file has),
    /// each the same, with the same rows and lines, when the whole read
    /// succeeds.
    pub(crate) fn some_fields_are_those_of_the_whole(
        text: &[u8],
        fields: crate::Fields,
        read: impl Fn(&Path, &crate::ReadOptions) -> Result<FlightTable>,
    ) -> std::result::Result<(), TestCaseError> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f.txt");
        std::fs::write(&path, text).unwrap();
        let Ok(whole) = read(&path, &crate::ReadOptions::default()) else {
            return Ok(());
        };
        let asked = crate::ReadOptions {
            fields: fields.clone(),
            ..crate::ReadOptions::default()
        };
        let some = read(&path, &asked);
        let some = some.map_err(|e| TestCaseError::fail(format!("{fields:?}: {e}")))?;
        let wanted: Vec<&str> = match &fields {
            crate::Fields::All => whole.column_names(),
            crate::Fields::Only(names) => {
                let named: Vec<&str> = whole
                    .column_names()
                    .into_iter()
                    .filter(|c| names.iter().any(|n| n.eq_ignore_ascii_case(c)))
                    .collect();
                if named.is_empty() {
                    whole.column_names()[..1].to_vec()
                } else {
                    named
                }
            }
        };
        proptest::prop_assert_eq!(some.column_names(), wanted.clone());
        proptest::prop_assert_eq!(some.n_rows(), whole.n_rows());
        for name in wanted {
            // Compared as text: a missing value is a NaN, unequal to itself.
            let (a, b) = (some.get(name), whole.get(name));
            proptest::prop_assert_eq!(format!("{a:?}"), format!("{b:?}"));
        }
        for r in 0..whole.n_rows() {
            proptest::prop_assert_eq!(some.line_of_row(r), whole.line_of_row(r));
        }
        Ok(())
    }

    /// The field selections the property tests read their files with
    /// (files of the columns `time`, `mag` and `note`): all, one or two of
    /// them, or none that the file has (its first field is then read).
    pub(crate) fn fields() -> impl proptest::strategy::Strategy<Value = crate::Fields> {
        use crate::Fields;
        let only = |names: &[&str]| Fields::Only(names.iter().map(|n| n.to_string()).collect());
        proptest::sample::select(vec![
            Fields::All,
            Fields::All,
            only(&["time"]),
            only(&["mag"]),
            only(&["note"]),
            only(&["time", "note"]),
            only(&["MAG", "note"]),
            only(&["absent"]),
        ])
    }

    /// `text` written to a file and read by `read` with the fast path on
    /// `threads` threads in pieces of `piece` bytes (and of the default
    /// size) gives the same table (values, missing counts, integer flags,
    /// text columns, line numbers) or the same error as `read` without it.
    pub(crate) fn reads_as_the_general_reader(
        text: &[u8],
        read: impl Fn(&Path, Option<(usize, usize)>) -> Result<FlightTable>,
        threads: usize,
        piece: usize,
    ) -> std::result::Result<(), TestCaseError> {
        let outcome =
            |r: Result<FlightTable>| r.map(|t| format!("{t:?}")).map_err(|e| e.to_string());
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f.txt");
        std::fs::write(&path, text).unwrap();
        let general = outcome(read(&path, None));
        let clean = outcome(read(&path, Some((threads, piece))));
        proptest::prop_assert_eq!(&clean, &general, "{}", String::from_utf8_lossy(text));
        let big = outcome(read(&path, Some((threads, super::PIECE_BYTES))));
        proptest::prop_assert_eq!(&big, &general);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SHAPE: Shape = Shape {
        delimiter: b',',
        n_fields: 2,
        crlf: false,
        whitespace: None,
        wanted: None,
        label: None,
    };

    fn parsed(piece: &[u8], shape: Shape) -> CleanRows {
        let mut out = CleanRows::default();
        parse_piece(piece, shape, &mut out);
        out
    }

    #[test]
    fn clean_rows_comments_and_blank_lines() {
        let p = parsed(b"1,2\n# c\n\n3,*\n  \n5,nan\n", SHAPE);
        assert_eq!(p.rows, 3);
        assert_eq!(p.values[0], vec![1.0, 3.0, 5.0]);
        assert_eq!(
            p.missing[1],
            Missing {
                blank: 0,
                nan: 1,
                dummy: 1
            }
        );
        assert_eq!(p.integers, vec![true, true]);
        assert_eq!(p.breaks, vec![(0, 0), (1, 3), (2, 5)]);
        assert_eq!(
            (p.last_row_line, p.lines, p.bytes, p.stopped),
            (5, 6, 22, false)
        );
    }

    #[test]
    fn stops_at_the_first_line_that_is_not_clean() {
        for (bad, why) in [
            ("\"3\",4", "quote"),
            ("3", "short"),
            ("3,4,5", "long"),
            ("3,abc", "text"),
            ("3,1\u{0}", "binary"),
            (",", "two blank cells are a row, a blank line is not"),
        ] {
            let text = format!("1.5,2\n{bad}\n7,8\n");
            let p = parsed(text.as_bytes(), SHAPE);
            if why.starts_with("two") {
                assert_eq!((p.rows, p.stopped), (3, false), "{why}");
                assert_eq!(p.missing[0].blank, 1);
                continue;
            }
            assert_eq!(
                (p.rows, p.lines, p.bytes, p.stopped),
                (1, 1, 6, true),
                "{why}"
            );
            assert_eq!(p.integers, vec![false, true]);
        }
    }

    #[test]
    fn crlf_and_an_unterminated_last_line() {
        let crlf = Shape {
            crlf: true,
            ..SHAPE
        };
        let p = parsed(b"1,2\r\n3,4", crlf);
        assert_eq!((p.rows, p.lines, p.bytes), (2, 2, 8));
        assert_eq!(p.values[1], vec![2.0, 4.0]);
        assert_eq!(p.integers, vec![true, true]);
    }

    proptest::proptest! {
        /// The 8-byte digit run equals the byte-by-byte one: its length and
        /// value when shorter than 8 digits, `None` at 8.
        #[test]
        fn digit_runs_read_8_bytes_at_a_time_as_byte_by_byte(
            bytes in proptest::collection::vec(
                proptest::prop_oneof![4 => b'0'..=b'9', 1 => proptest::num::u8::ANY],
                8..12,
            ),
            p in 0usize..4,
        ) {
            let run = bytes[p..].iter().take_while(|b| b.is_ascii_digit()).count();
            let expected = (p + 8 <= bytes.len() && run < 8).then(|| {
                let v = bytes[p..p + run]
                    .iter()
                    .fold(0u64, |m, b| m * 10 + u64::from(b - b'0'));
                (v, run)
            });
            proptest::prop_assert_eq!(digit_run(&bytes, p), expected);
        }
    }

    /// The pieces end at line ends and put together are the file from
    /// the start offset; the last line may lack its line end; a line longer
    /// than a piece ends the pieces.
    #[test]
    fn pieces_are_whole_lines_of_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.txt");
        let text = b"head\naa\nbbbb\nc\ndddddd\ne\nff";
        std::fs::write(&path, text).unwrap();
        for piece_bytes in 1..12 {
            let mut file = File::open(&path).unwrap();
            file.seek(SeekFrom::Start(5)).unwrap();
            let mut pieces = Pieces {
                file,
                piece_bytes,
                carry: Vec::new(),
                next: 0,
                ended: false,
            };
            let (mut all, mut buf) = (Vec::new(), Vec::new());
            let mut long = false;
            while !pieces.ended {
                match pieces.read_into(&mut buf).unwrap() {
                    (false, _) => break,
                    (true, Cut::Lines) => {
                        assert!(
                            buf.ends_with(b"\n") || pieces.ended,
                            "{piece_bytes}: {buf:?}"
                        );
                        assert!(buf.len() <= piece_bytes.max(7), "{piece_bytes}: {buf:?}");
                        all.extend_from_slice(&buf);
                    }
                    (true, Cut::LongLine) => long = true,
                    (true, Cut::Failed(e)) => panic!("{e}"),
                }
            }
            // The longest line with its line end is 7 bytes.
            assert_eq!(long, piece_bytes < 7, "{piece_bytes}");
            if !long {
                assert_eq!(all, &text[5..], "{piece_bytes}");
            }
        }
    }
}
