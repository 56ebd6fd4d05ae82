//! Geosoft XYZ reader (and whitespace-separated tables).
//!
//! Geosoft XYZ is the column text format of airborne geophysics:
//!
//! ```text
//! / XYZ EXPORT [06/20/2020]
//! / DATABASE   [survey.gdb]
//! /
//! /   time        lat         lon        alt      mag
//! Line 1010
//!   0.0    45.001    -75.002    300.0   53210.4
//!   0.1    45.002    -75.002    300.1        *
//! Tie 2010
//!   ...
//! ```
//!
//! Rules of this reader:
//!
//! - Lines starting with `/` are comments (anywhere). Blank lines are skipped.
//!   A UTF-8 byte-order mark and `\r\n` line ends are accepted.
//! - Data lines are whitespace separated; `*` is the dummy (missing) value, as
//!   are empty-looking `NaN` tokens (see `cell.rs`). Every data line must have
//!   as many values as the header has names (else [`IoError::FieldCount`]).
//! - **Header rule.** The column names are taken from the *last* comment line
//!   before the first data line whose number of names equals the number of
//!   values on that first data line and whose names all start with a letter
//!   or `_`. The names are what follows the leading slashes, separated by
//!   whitespace and/or commas, so `/ time lat lon` and `/time,lat,lon` are
//!   both accepted. Lines starting with `//` (Geosoft's metadata lines) are
//!   used only when no single-`/` line qualifies. A units line written after
//!   the names line must therefore start with `//` (or contain a token that
//!   does not start with a letter). No qualifying line is an
//!   [`IoError::XyzHeader`] error.
//! - **Line records.** A line whose first word is `Line` or `Tie` (any case)
//!   starts a survey line or tie line; its number is the next word, with
//!   leading letters dropped (`Line 1010`, `LINE L1010`, `Tie 2010.1`). If the
//!   file has at least one record, two columns are added after the file's
//!   columns: `line` (the number as written; ties keep their own number;
//!   missing before the first record) and `line_type` (0 for `Line`, 1 for
//!   `Tie`). If the header already has a column of that name, the added
//!   column is called `xyz_line` (resp. `xyz_line_type`) instead.
//!
//! The same tokenizer reads whitespace-separated tables with a plain header
//! (`time lat lon` as the first line that is not a `#` comment), which
//! [`read_csv`](crate::read_csv) hands over when it detects them.
//!
//! In both, the data lines after the header are read on all cores by the
//! CSV reader's fast path ([`crate::csv_clean`], whitespace shape: the same
//! fields, comments and records as these rules), and this reader goes on
//! from the first line that path leaves (a text cell, a wrong field count,
//! a record without a number), so every warning and error is its own.

use std::fs::File;
use std::io::{BufRead, BufReader, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use crate::ReadOptions;
use crate::builder::{
    Layout, MAX_COLUMNS, MAX_LINE_BYTES, RowFields, RowSource, TableBuilder, line_too_long,
    too_many_columns,
};
use crate::csv_clean::{self, Resume, Shape, push_clean_rows};
use crate::error::{IoError, Result};
use crate::label_texts::LabelClash;
use crate::read_ahead::push_rows;
use crate::sniff::{BOM, read_prefix};
use crate::table::FlightTable;

/// Reads a Geosoft XYZ file. See the module docs for the header rule and the
/// `line`/`line_type` columns.
pub fn read_xyz(path: &Path, opts: &ReadOptions) -> Result<FlightTable> {
    read_tokens(path, opts, Dialect::Geosoft, csv_clean::on_all_cores())
}

/// Reads a whitespace-separated table with a plain header line and `#`
/// comments (data lines on all cores: module docs).
pub(crate) fn read_whitespace(path: &Path, opts: &ReadOptions) -> Result<FlightTable> {
    read_tokens(path, opts, Dialect::Whitespace, csv_clean::on_all_cores())
}

/// A file of `dialect`, with the clean rows read on `threads` threads in
/// pieces of `piece_bytes` when `clean` is given, by the general reader
/// alone otherwise (tests compare the two).
fn read_tokens(
    path: &Path,
    opts: &ReadOptions,
    dialect: Dialect,
    clean: Option<(usize, usize)>,
) -> Result<FlightTable> {
    let prefix = read_prefix(path)?;
    let (mut src, names) = TokenSource::open(path, dialect)?;
    let layout = Layout {
        path: path.to_path_buf(),
        names,
        header_line: src.header_line,
        file_size: prefix.file_size,
        header_bytes: src.bytes,
        decimal_comma_hint: false,
    };
    let mut builder = TableBuilder::new(layout, opts)?;
    let header = builder.names().to_vec();
    let wanted = builder.wanted();
    let mut src = match clean {
        Some((threads, piece_bytes)) => {
            // The first data line: after a plain table's header line; the
            // line the Geosoft header rule stopped at (read, to replay).
            let (offset, line) = if src.replay {
                (src.line_start, src.line)
            } else {
                (src.bytes, src.line + 1)
            };
            let shape = Shape {
                delimiter: b' ',
                n_fields: src.n_fields,
                crlf: false,
                whitespace: Some(dialect),
                wanted: wanted.as_deref(),
                label: builder.label_column(),
            };
            let stop = push_clean_rows(
                &mut builder,
                path,
                Resume { offset, line },
                shape,
                threads,
                piece_bytes,
                &mut |piece| src.take_clean_piece(piece),
            )?;
            match stop {
                Some(at) => {
                    let rows = builder.rows();
                    push_rows(&mut builder, src.resumed_at(at, rows)?)?
                }
                None => src,
            }
        }
        None => push_rows(&mut builder, src)?,
    };
    let mut table = builder.finish(|| TokenSource::open(path, dialect).map(|(s, _)| s))?;
    if src.any_record {
        let free = |name: &str| {
            if header.iter().any(|h| h == name) {
                format!("xyz_{name}")
            } else {
                name.to_string()
            }
        };
        match src.take_line_column() {
            Ok(numbers) => table.add_column(&free("line"), numbers)?,
            Err(text) => table.add_text_column(&free("line"), text)?,
        }
        table.add_column(&free("line_type"), std::mem::take(&mut src.line_types))?;
    }
    Ok(table)
}

/// Which text layout is read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Dialect {
    /// Geosoft XYZ: `/` comments, header in a comment, `Line`/`Tie` records.
    Geosoft,
    /// Plain whitespace table: `#` comments, first content line is the header.
    Whitespace,
}

/// What a physical line is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Kind {
    Blank,
    Comment,
    Record { number: f64, tie: bool },
    Data,
}

/// Whitespace-separated rows (see [`RowSource`]).
struct TokenSource {
    reader: BufReader<File>,
    path: PathBuf,
    buf: Vec<u8>,
    spans: Vec<(usize, usize)>,
    file: String,
    dialect: Dialect,
    line: u64,
    bytes: u64,
    /// File offset of the start of line `line`.
    line_start: u64,
    n_fields: usize,
    header_line: u64,
    row: usize,
    replay: bool,
    current_line: f64,
    current_type: f64,
    any_record: bool,
    line_values: Vec<f64>,
    line_types: Vec<f64>,
    /// `(rows before it, its number as written)` of each record, for the
    /// `line` column as text when two records' numbers clash
    /// ([`crate::label_texts`]: `Line 1003.1` and `Line 1003.10`).
    record_texts: Vec<(usize, Vec<u8>)>,
    record_clash: LabelClash,
    /// More records than [`crate::label_texts::MAX_LABELS`] came without a
    /// clash: texts no longer kept, the numbers stay.
    records_untracked: bool,
}

impl TokenSource {
    /// Opens the file and reads up to the first data line; returns the source
    /// (positioned so that the first `next_row` yields that line) and the header names.
    fn open(path: &Path, dialect: Dialect) -> Result<(Self, Vec<String>)> {
        let mut src = Self::new(path, dialect)?;
        let names = match dialect {
            Dialect::Geosoft => src.geosoft_header()?,
            Dialect::Whitespace => src.plain_header()?,
        };
        src.n_fields = names.len();
        Ok((src, names))
    }

    /// A source at the start of the file.
    fn new(path: &Path, dialect: Dialect) -> Result<Self> {
        let file = path.display().to_string();
        let f = File::open(path).map_err(|source| IoError::Open {
            file: file.clone(),
            source,
        })?;
        Ok(TokenSource {
            reader: BufReader::with_capacity(256 * 1024, f),
            path: path.to_path_buf(),
            buf: Vec::with_capacity(1024),
            spans: Vec::new(),
            file,
            dialect,
            line: 0,
            bytes: 0,
            line_start: 0,
            n_fields: 0,
            header_line: 0,
            row: 0,
            replay: false,
            current_line: f64::NAN,
            current_type: f64::NAN,
            any_record: false,
            line_values: Vec::new(),
            line_types: Vec::new(),
            record_texts: Vec::new(),
            record_clash: LabelClash::default(),
            records_untracked: false,
        })
    }

    /// The line labels of a piece of rows read by the fast path
    /// ([`csv_clean`]), with its records (Geosoft: the current record's
    /// number and type for each row, as [`Self::accept_row`] keeps them).
    fn take_clean_piece(&mut self, piece: &csv_clean::CleanRows) {
        if self.dialect != Dialect::Geosoft {
            return;
        }
        let mut records = piece.records.iter().peekable();
        for row in 0..piece.rows {
            while let Some((_, number, tie, text)) = records.next_if(|r| r.0 <= row) {
                self.set_record(*number, *tie, text);
            }
            self.line_values.push(self.current_line);
            self.line_types.push(self.current_type);
        }
        for (_, number, tie, text) in records {
            self.set_record(*number, *tie, text);
        }
    }

    /// This source (its header read) moved to the line start `at`, with
    /// `rows` data rows already read before it.
    fn resumed_at(mut self, at: Resume, rows: usize) -> Result<Self> {
        self.reader
            .seek(SeekFrom::Start(at.offset))
            .map_err(|source| IoError::Read {
                file: self.file.clone(),
                line: at.line,
                source,
            })?;
        self.bytes = at.offset;
        self.line = at.line - 1;
        self.row = rows;
        self.replay = false;
        Ok(self)
    }

    /// Scans comments and records up to the first data line and applies the header rule.
    fn geosoft_header(&mut self) -> Result<Vec<String>> {
        let mut last_comment = None;
        loop {
            if !self.read_line()? {
                return Err(match last_comment {
                    Some(line) => IoError::NoData {
                        file: self.file.clone(),
                        header_line: line,
                    },
                    None => IoError::Empty {
                        file: self.file.clone(),
                    },
                });
            }
            match self.classify()? {
                Kind::Blank => {}
                Kind::Comment => {
                    if std::str::from_utf8(&self.buf).is_ok() {
                        last_comment = Some(self.line);
                    }
                }
                Kind::Record { number, tie } => {
                    let text = record_text(&self.buf).to_vec();
                    self.set_record(number, tie, &text)
                }
                Kind::Data => break,
            }
        }
        self.tokenize();
        let n = self.spans.len();
        if n > MAX_COLUMNS {
            return Err(too_many_columns(&self.file, self.line, n));
        }
        // The comment lines are read again rather than kept: memory stays
        // bounded by one line however many comments precede the data.
        let (single, double) = self.header_candidates(n)?;
        let Some((line, names)) = single.or(double) else {
            return Err(IoError::XyzHeader {
                file: self.file.clone(),
                line: self.line,
                message: format!(
                    "no column-name header: the first data line has {n} values, but no '/' comment line before it has {n} names; add a line '/ name1 name2 …' before the data"
                ),
            });
        };
        self.header_line = line;
        self.replay = true;
        Ok(names)
    }

    /// The last `/` and the last `//` comment line before the first data line
    /// (line `self.line`) with `n` names that all start with a letter or `_`.
    #[allow(clippy::type_complexity)]
    fn header_candidates(
        &self,
        n: usize,
    ) -> Result<(Option<(u64, Vec<String>)>, Option<(u64, Vec<String>)>)> {
        let mut again = TokenSource::new(&self.path, self.dialect)?;
        let (mut single, mut double) = (None, None);
        while again.line + 1 < self.line && again.read_line()? {
            let Ok(text) = std::str::from_utf8(&again.buf) else {
                continue;
            };
            // A comment as `classify` says; its names as the header rule says.
            if !text.trim_ascii_start().starts_with('/') {
                continue;
            }
            let names = || {
                text.trim_start_matches('/')
                    .split(|c: char| c.is_whitespace() || c == ',')
                    .filter(|t| !t.is_empty())
            };
            let name_like = |t: &str| t.starts_with(|c: char| c.is_alphabetic() || c == '_');
            if names().count() == n && names().all(name_like) {
                let found = Some((again.line, names().map(str::to_string).collect()));
                if text.starts_with("//") {
                    double = found;
                } else {
                    single = found;
                }
            }
        }
        Ok((single, double))
    }

    /// The first content line (not blank, not `#`) is the header.
    fn plain_header(&mut self) -> Result<Vec<String>> {
        loop {
            if !self.read_line()? {
                return Err(IoError::Empty {
                    file: self.file.clone(),
                });
            }
            if matches!(self.classify()?, Kind::Data) {
                break;
            }
        }
        self.header_line = self.line;
        let text = std::str::from_utf8(&self.buf).map_err(|_| IoError::Binary {
            file: self.file.clone(),
            line: self.line,
            what: "invalid bytes in the header row".to_string(),
        })?;
        let n = text.split_whitespace().count();
        if n > MAX_COLUMNS {
            return Err(too_many_columns(&self.file, self.line, n));
        }
        Ok(text.split_whitespace().map(str::to_string).collect())
    }

    /// Reads the next physical line into `buf` without its line end; `false` at the end.
    fn read_line(&mut self) -> Result<bool> {
        self.buf.clear();
        // At most the limit plus "\r\n": a longer line is an error, not a
        // buffer of the whole file.
        let n = (&mut self.reader)
            .take(MAX_LINE_BYTES + 2)
            .read_until(b'\n', &mut self.buf)
            .map_err(|source| IoError::Read {
                file: self.file.clone(),
                line: self.line + 1,
                source,
            })?;
        if n == 0 {
            return Ok(false);
        }
        if n as u64 == MAX_LINE_BYTES + 2 && self.buf.last() != Some(&b'\n') {
            return Err(line_too_long(&self.file, self.line + 1));
        }
        self.line_start = self.bytes;
        self.bytes += n as u64;
        self.line += 1;
        if self.line == 1 && self.buf.starts_with(BOM) {
            self.buf.drain(..BOM.len());
        }
        while matches!(self.buf.last(), Some(b'\n' | b'\r')) {
            self.buf.pop();
        }
        if self.buf.len() as u64 > MAX_LINE_BYTES {
            return Err(line_too_long(&self.file, self.line));
        }
        // The first line holding a `\r`: the lines end in `\r` alone and
        // the whole file is one line ("a header but no data rows").
        if self.line == 1 && memchr::memchr(b'\r', &self.buf).is_some() {
            return Err(IoError::CrLineEnds {
                file: self.file.clone(),
                line: 1,
            });
        }
        Ok(true)
    }

    fn classify(&self) -> Result<Kind> {
        line_kind(self.dialect, &self.buf).ok_or_else(|| IoError::XyzHeader {
            file: self.file.clone(),
            line: self.line,
            message: format!(
                "line record '{}' has no line number (expected e.g. 'Line 1010' or 'Tie 2010')",
                String::from_utf8_lossy(self.buf.trim_ascii_start())
            ),
        })
    }

    /// A `Line`/`Tie` record of number `number`, written `text`.
    fn set_record(&mut self, number: f64, tie: bool, text: &[u8]) {
        self.current_line = number;
        self.current_type = if tie { 1.0 } else { 0.0 };
        self.any_record = true;
        // A record on every row of a hostile file: beyond MAX_LABELS
        // records without a clash, their texts are no longer kept.
        if self.record_texts.len() >= crate::label_texts::MAX_LABELS && !self.record_clash.clash {
            self.records_untracked = true;
            self.record_texts = Vec::new();
        }
        if self.records_untracked {
            return;
        }
        if number != 0.0 {
            self.record_clash.add(text, number);
        }
        self.record_texts
            .push((self.line_values.len(), text.to_vec()));
    }

    /// The `line` column of the records: their numbers, or their texts
    /// when two texts give one number (NaN, resp. empty, before the first).
    fn take_line_column(&mut self) -> std::result::Result<Vec<f64>, Vec<String>> {
        let values = std::mem::take(&mut self.line_values);
        if !self.record_clash.clash || self.records_untracked {
            return Ok(values);
        }
        let mut text = Vec::with_capacity(values.len());
        let mut runs = self.record_texts.iter().peekable();
        let mut current = String::new();
        for row in 0..values.len() {
            while let Some((_, t)) = runs.next_if(|r| r.0 <= row) {
                current = String::from_utf8_lossy(t).into_owned();
            }
            text.push(current.clone());
        }
        Err(text)
    }

    fn tokenize(&mut self) {
        self.spans.clear();
        let b = &self.buf;
        let mut i = 0;
        while i < b.len() {
            while i < b.len() && b[i].is_ascii_whitespace() {
                i += 1;
            }
            let start = i;
            while i < b.len() && !b[i].is_ascii_whitespace() {
                i += 1;
            }
            if i > start {
                self.spans.push((start, i));
            }
        }
    }

    /// Checks the field count of the current data line and counts the row.
    fn accept_row(&mut self) -> Result<()> {
        if self.spans.len() != self.n_fields {
            return Err(IoError::FieldCount {
                file: self.file.clone(),
                line: self.line,
                row: self.row,
                expected: self.n_fields,
                found: self.spans.len(),
                header_line: self.header_line,
                delimiter: "whitespace".to_string(),
            });
        }
        self.row += 1;
        if self.dialect == Dialect::Geosoft {
            self.line_values.push(self.current_line);
            self.line_types.push(self.current_type);
        }
        Ok(())
    }
}

impl RowSource for TokenSource {
    fn next_row(&mut self) -> Result<bool> {
        if self.replay {
            self.replay = false;
            self.tokenize();
            self.accept_row()?;
            return Ok(true);
        }
        loop {
            if !self.read_line()? {
                return Ok(false);
            }
            match self.classify()? {
                Kind::Blank | Kind::Comment => {}
                Kind::Record { number, tie } => {
                    let text = record_text(&self.buf).to_vec();
                    self.set_record(number, tie, &text)
                }
                Kind::Data => {
                    self.tokenize();
                    self.accept_row()?;
                    return Ok(true);
                }
            }
        }
    }
}

impl RowFields for TokenSource {
    fn line(&self) -> u64 {
        self.line
    }

    #[inline]
    fn field(&self, i: usize) -> &[u8] {
        let (a, b) = self.spans[i];
        &self.buf[a..b]
    }

    fn bytes_read(&self) -> u64 {
        self.bytes
    }
}

/// What a line of a file of `dialect` is (`line`: without its line end
/// and line-end `\r`s), for this reader and the fast path
/// ([`csv_clean`]): blank, a comment (`#` in a plain table, `/` in an XYZ
/// file), a `Line`/`Tie` record (XYZ) or data; `None` for a record word
/// without a number.
pub(crate) fn line_kind(dialect: Dialect, line: &[u8]) -> Option<Kind> {
    let t = line.trim_ascii_start();
    if t.trim_ascii_end().is_empty() {
        return Some(Kind::Blank);
    }
    match dialect {
        Dialect::Whitespace if t.starts_with(b"#") => Some(Kind::Comment),
        Dialect::Whitespace => Some(Kind::Data),
        Dialect::Geosoft => geosoft_kind(t),
    }
}

/// [`line_kind`] of an XYZ line (`t`: not blank, without leading blanks).
fn geosoft_kind(t: &[u8]) -> Option<Kind> {
    if t.starts_with(b"/") {
        return Some(Kind::Comment);
    }
    let mut words = t
        .split(|b| b.is_ascii_whitespace())
        .filter(|w| !w.is_empty());
    let first = words.next().unwrap_or_default();
    let tie = first.eq_ignore_ascii_case(b"tie");
    if !tie && !first.eq_ignore_ascii_case(b"line") {
        return Some(Kind::Data);
    }
    let number = record_number(words.next().unwrap_or_default())?;
    Some(Kind::Record { number, tie })
}

/// The number of a `Line`/`Tie` record as written (`Line L1003.10` →
/// `1003.10`; see [`record_number`]), of a line [`line_kind`] found a
/// record (empty otherwise).
pub(crate) fn record_text(line: &[u8]) -> &[u8] {
    let word = line
        .split(|b| b.is_ascii_whitespace())
        .filter(|w| !w.is_empty())
        .nth(1)
        .unwrap_or_default();
    record_digits(word).unwrap_or_default()
}

/// The digits and dots of a record word after its leading letters.
fn record_digits(word: &[u8]) -> Option<&[u8]> {
    let digits = word.trim_ascii_start();
    let start = digits.iter().position(|b| !b.is_ascii_alphabetic())?;
    let rest = &digits[start..];
    let end = rest
        .iter()
        .position(|b| !(b.is_ascii_digit() || *b == b'.'))
        .unwrap_or(rest.len());
    Some(&rest[..end])
}

/// The number of a `Line`/`Tie` record word: leading letters dropped, then
/// the leading digits and dots (`L1010` → 1010, `1010.1` → 1010.1, `10:2` → 10).
fn record_number(word: &[u8]) -> Option<f64> {
    std::str::from_utf8(record_digits(word)?).ok()?.parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn record_numbers() {
        assert_eq!(record_number(b"1010"), Some(1010.0));
        assert_eq!(record_number(b"L1010"), Some(1010.0));
        assert_eq!(record_number(b"1010.1"), Some(1010.1));
        assert_eq!(record_number(b"10:2"), Some(10.0));
        assert_eq!(record_number(b"abc"), None);
        assert_eq!(record_number(b""), None);
    }

    mod fast_path {
        use super::*;
        use proptest::prelude::*;

        /// One line of a whitespace table of three columns: mostly plain
        /// decimals with runs of spaces and tabs around them, and what the
        /// fast path leaves to the general reader.
        fn whitespace_line() -> impl Strategy<Value = String> {
            let blank = prop::sample::select(vec![" ", "  ", "\t", " \t ", "   "]);
            let num = prop_oneof![
                6 => (-99999i32..99999, 0u32..4).prop_map(|(m, k)| {
                    let v = m as f64 / 10f64.powi(k as i32);
                    if k == 0 { format!("{m}") } else { format!("{v:.*}", k as usize) }
                }),
                1 => prop::sample::select(vec!["*", "NaN", "1e3", "+2.5", "-0", ".5", "7.", "abc", "1\u{0c}"])
                    .prop_map(str::to_string),
            ];
            prop_oneof![
                12 => (blank.clone(), num.clone(), blank.clone(), num.clone(), blank.clone(), num, prop::sample::select(vec!["", " ", "\t", "\r"]))
                    .prop_map(|(a, x, b, y, c, z, end)| {
                        let lead = if a.len() > 1 { a } else { "" };
                        format!("{lead}{x}{b}{y}{c}{z}{end}")
                    }),
                1 => Just("# a comment".to_string()),
                1 => Just("   # indented comment".to_string()),
                1 => Just("".to_string()),
                1 => Just(" \t ".to_string()),
                1 => Just("1 2".to_string()),
                1 => Just("1 2 3 4".to_string()),
                // Fields not parted by a blank.
                1 => Just("1-2-3".to_string()),
                1 => Just("4.5.6 1".to_string()),
            ]
        }

        /// One line of a Geosoft XYZ file of three columns: a whitespace
        /// table's line, a `/` comment, a `Line`/`Tie` record (with and
        /// without a number), a `#` line (data here).
        fn geosoft_line() -> impl Strategy<Value = String> {
            prop_oneof![
                10 => whitespace_line(),
                1 => Just("/ a comment".to_string()),
                1 => Just("  // units".to_string()),
                2 => (1u32..3000).prop_map(|n| format!("Line {n}")),
                1 => (1u32..3000).prop_map(|n| format!("  tie L{n}.5\r")),
                1 => Just("LINE".to_string()),
                1 => Just("# not a comment here".to_string()),
            ]
        }

        /// A file of `dialect`: its header (an XYZ file: comments, the
        /// names, maybe a record), then lines among runs of 40 clean rows
        /// (so that pieces hold many; in an XYZ file every other run after
        /// a record of its own), LF or CRLF, a final line end or none.
        fn file(dialect: Dialect) -> impl Strategy<Value = Vec<u8>> {
            let line = match dialect {
                Dialect::Whitespace => whitespace_line().boxed(),
                Dialect::Geosoft => geosoft_line().boxed(),
            };
            (
                proptest::collection::vec(
                    prop_oneof![8 => line.prop_map(Some), 1 => Just(None)],
                    0..60,
                ),
                any::<bool>(),
                any::<bool>(),
                any::<bool>(),
            )
                .prop_map(move |(lines, crlf, last_newline, first_record)| {
                    let end = if crlf { "\r\n" } else { "\n" };
                    let geosoft = dialect == Dialect::Geosoft;
                    let head = match (geosoft, first_record) {
                        (false, _) => format!("# head{end}time  mag\tnote{end}"),
                        (true, false) => format!("/ XYZ EXPORT{end}/ time  mag note{end}"),
                        (true, true) => {
                            format!("/ XYZ EXPORT{end}/ time  mag note{end}Line 1000{end}")
                        }
                    };
                    csv_clean::check::text(
                        &head,
                        &lines,
                        |k, i| {
                            let record = if geosoft && i == 0 && k % 2 == 0 {
                                format!("Line {k}{end}")
                            } else {
                                String::new()
                            };
                            format!("{record} {k}.{i}   -5300{i}.25\t{i}")
                        },
                        end,
                        last_newline,
                    )
                })
        }

        proptest! {
            #![proptest_config(ProptestConfig::with_cases(300))]

            /// The fast path changes nothing: the same table (values,
            /// missing counts, integer flags, line numbers; an XYZ file's
            /// `line` and `line_type` columns) or the same error as the
            /// general reader alone, for any thread count and piece size.
            #[test]
            fn clean_rows_read_as_the_general_reader_reads_them(
                table in file(Dialect::Whitespace),
                xyz in file(Dialect::Geosoft),
                threads in 1usize..4,
                piece in 8usize..300,
                fields in csv_clean::check::fields(),
            ) {
                let opts = ReadOptions { fields, ..ReadOptions::default() };
                for (text, dialect) in [(&table, Dialect::Whitespace), (&xyz, Dialect::Geosoft)] {
                    csv_clean::check::reads_as_the_general_reader(
                        text,
                        |path, clean| read_tokens(path, &opts, dialect, clean),
                        threads,
                        piece,
                    )?;
                }
            }
        }

        proptest! {
            #![proptest_config(ProptestConfig::with_cases(200))]

            /// Reading some fields of a whitespace table gives those
            /// columns of the whole read (an XYZ file's records add its
            /// `line` and `line_type` columns whatever the selection; the
            /// property above covers its fields).
            #[test]
            fn some_fields_are_those_columns_of_the_whole_read(
                table in file(Dialect::Whitespace),
                fields in csv_clean::check::fields(),
            ) {
                csv_clean::check::some_fields_are_those_of_the_whole(&table, fields, |path, opts| {
                    read_tokens(path, opts, Dialect::Whitespace, csv_clean::on_all_cores())
                })?;
            }
        }

        /// A table of plain decimals is read whole by the fast path; the
        /// same table with a dummy half way is read by both, the same.
        #[test]
        fn a_plain_table_and_one_with_a_dummy() {
            let dir = tempfile::tempdir().unwrap();
            let path = dir.path().join("t.txt");
            let mut text = String::from("time mag\n");
            for i in 0..5000 {
                text.push_str(&format!("  {}.{}\t{}.5 \n", i / 10, i % 10, 53000 + i));
            }
            // The file read by the fast path, checked against the general
            // reader alone.
            let read_both = |text: &str| {
                std::fs::write(&path, text).unwrap();
                let opts = ReadOptions::default();
                let fast = read_tokens(&path, &opts, Dialect::Whitespace, Some((2, 4096))).unwrap();
                let general = read_tokens(&path, &opts, Dialect::Whitespace, None).unwrap();
                assert_eq!(format!("{fast:?}"), format!("{general:?}"));
                fast
            };
            let fast = read_both(&text);
            assert_eq!(fast.n_rows(), 5000);
            assert_eq!(fast.column("mag").unwrap()[4999], 57999.5);
            let fast = read_both(&text.replacen("53100.5", "*", 1));
            assert!(fast.column("mag").unwrap()[100].is_nan());
        }

        /// Records between rows label the rows after them, read by the
        /// fast path (with pieces that end between a record and its rows).
        /// Two records whose numbers differ as text only (`Line 1003.1`,
        /// `Line L1003.10`: Geosoft line 1003, versions 1 and 10) label two
        /// lines: the `line` column then holds each record's number as
        /// written, in either reader.
        #[test]
        fn records_of_one_number_in_two_texts_stay_two_lines() {
            let dir = tempfile::tempdir().unwrap();
            let path = dir.path().join("v.xyz");
            let mut text = String::from("/ time mag\n  0.0  53000.5\n");
            for (k, record) in ["Line 1003.1", "Tie T901", "Line L1003.10", "Line 1003.1"]
                .iter()
                .enumerate()
            {
                text.push_str(record);
                text.push('\n');
                for i in 0..700 {
                    text.push_str(&format!("  {k}{i:04}.5  53{i:03}.5\n"));
                }
            }
            std::fs::write(&path, &text).unwrap();
            let opts = ReadOptions::default();
            let fast = read_tokens(&path, &opts, Dialect::Geosoft, Some((2, 1000))).unwrap();
            let line = fast.text_column("line").unwrap();
            assert_eq!(
                (
                    &*line[0],
                    &*line[1],
                    &*line[701],
                    &*line[1401],
                    &*line[2101],
                    &*line[2800]
                ),
                ("", "1003.1", "901", "1003.10", "1003.1", "1003.1")
            );
            assert_eq!(
                format!("{fast:?}"),
                format!(
                    "{:?}",
                    read_tokens(&path, &opts, Dialect::Geosoft, None).unwrap()
                )
            );
            // Without the clash the numbers stay numbers.
            std::fs::write(&path, text.replace("L1003.10", "1004")).unwrap();
            let numbers = read_tokens(&path, &opts, Dialect::Geosoft, Some((2, 1000))).unwrap();
            assert_eq!(numbers.column("line").unwrap()[1401], 1004.0);
        }

        #[test]
        fn records_label_the_rows_after_them() {
            let dir = tempfile::tempdir().unwrap();
            let path = dir.path().join("s.xyz");
            let mut text = String::from("/ time mag\n");
            for i in 0..3000 {
                if i % 1000 == 0 {
                    text.push_str(&format!(
                        "{} {}\n",
                        if i == 2000 { "Tie" } else { "Line" },
                        1001 + i / 1000
                    ));
                }
                text.push_str(&format!("  {}.{}  {}.5\n", i / 10, i % 10, 53000 + i));
            }
            std::fs::write(&path, &text).unwrap();
            let opts = ReadOptions::default();
            let fast = read_tokens(&path, &opts, Dialect::Geosoft, Some((2, 1000))).unwrap();
            let line = fast.column("line").unwrap();
            let kind = fast.column("line_type").unwrap();
            assert_eq!(
                (line[0], line[999], line[1000], line[2999]),
                (1001.0, 1001.0, 1002.0, 1003.0)
            );
            assert_eq!((kind[1999], kind[2000]), (0.0, 1.0));
            assert_eq!(
                format!("{fast:?}"),
                format!(
                    "{:?}",
                    read_tokens(&path, &opts, Dialect::Geosoft, None).unwrap()
                )
            );
        }
    }
}
