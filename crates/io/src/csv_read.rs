//! CSV reader.
//!
//! Accepted layout (spec `data-formats.md`, "Flight data tables"):
//!
//! - optional UTF-8 byte-order mark; `\n` or `\r\n` line ends; the last line
//!   may lack its line end;
//! - lines starting with `#` are comments, before the header and anywhere
//!   after it; blank lines are skipped (in a one-column file a blank line is
//!   therefore not a blank cell);
//! - one header row with the column names (trimmed; an empty name becomes
//!   `unnamed_<position>`; a repeated name is an error);
//! - one data row per sample with exactly as many fields as the header has
//!   names: a shorter or longer row is an error (rows are never dropped or
//!   padded); fields may be quoted (`"…"`, `""` for a quote);
//! - missing values: empty cell, `NaN` (any case), `*`; numbers in Rust's
//!   `f64` syntax, surrounding whitespace ignored (see `cell.rs`).
//!
//! # Delimiter
//!
//! [`ReadOptions::delimiter`](crate::ReadOptions) forces one. Otherwise it is
//! detected from the header line: the most frequent of comma, tab and
//! semicolon (comma on a tie). A header with none of them but with several
//! whitespace-separated names (`time lat lon`) makes the file a
//! whitespace-separated table, read by the same tokenizer as Geosoft XYZ
//! with `#` comments and the first content line as header. A header without
//! any separator is a one-column table. When a forced delimiter does not
//! occur in the header but another candidate does, the error
//! [`IoError::WrongDelimiter`] says so ("wrong delimiter? the header has one
//! column 'a;b;c'"). With a semicolon or tab delimiter, a number with a
//! decimal comma gets a hint in its parse error.
//!
//! # Two readers, one table
//!
//! After the header, the rows go into the per-column vectors of one
//! [`TableBuilder`](crate::builder) (see there for the memory bound):
//!
//! - first through the fast path ([`crate::csv_clean`]): clean rows (no
//!   quote, numbers and missing markers only, as many fields as names)
//!   parsed on all cores, piece by piece, in file order;
//! - from the first line that is not clean, through the general reader:
//!   `csv::ByteRecord` (one reused buffer) with quotes, text columns and
//!   every error message, its tokenizer one thread ahead of the cell parser
//!   ([`crate::read_ahead`]).
//!
//! The table, the warnings and the errors are the general reader's own
//! either way (a property test reads generated files both ways).
//!
//! With [`Fields::Only`](crate::Fields::Only) both readers only delimit the
//! fields not asked for: their cells are neither parsed nor checked, and
//! the table does not have them (a property test: the same columns as the
//! whole read's).

use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use crate::ReadOptions;
use crate::builder::{
    Layout, MAX_COLUMNS, MAX_LINE_BYTES, RowFields, RowSource, TableBuilder, line_too_long,
    too_many_columns,
};
use crate::cell::check_text;
use crate::csv_clean::{self, Resume, Shape, push_clean_rows};
use crate::error::{IoError, Result};
use crate::read_ahead::push_rows;
use crate::sniff::{BOM, first_content_line, read_prefix};
use crate::table::FlightTable;
use crate::xyz;

/// Reads a CSV (or whitespace-separated) flight-data file. See the module docs.
pub fn read_csv(path: &Path, opts: &ReadOptions) -> Result<FlightTable> {
    read_csv_with(path, opts, csv_clean::on_all_cores())
}

/// [`read_csv`], with the clean rows read by [`csv_clean`] on `threads`
/// threads in pieces of `piece_bytes` when `clean` is given, by the general
/// reader alone otherwise (tests compare the two).
fn read_csv_with(
    path: &Path,
    opts: &ReadOptions,
    clean: Option<(usize, usize)>,
) -> Result<FlightTable> {
    let file = path.display().to_string();
    let prefix = read_prefix(path)?;
    let Some((header_line, header, _)) = first_content_line(&prefix.bytes, |l| l.starts_with(b"#"))
    else {
        return Err(IoError::Empty { file });
    };
    let header_text = check_text(header).map_err(|_| IoError::Binary {
        file: file.clone(),
        line: header_line,
        what: "invalid bytes in the header row".to_string(),
    })?;
    let delimiter = match opts.delimiter {
        Some(d) => {
            check_forced_delimiter(&file, header_line, header_text, d)?;
            d
        }
        None => match detect_delimiter(header_text) {
            Some(d) => d,
            None => return xyz::read_whitespace(path, opts),
        },
    };
    let open = || CsvSource::open(path, delimiter, prefix.file_size);
    let mut src = open()?;
    let names = src.header()?;
    let layout = Layout {
        path: path.to_path_buf(),
        names,
        header_line: src.header_line,
        file_size: prefix.file_size,
        header_bytes: src.bytes_read(),
        decimal_comma_hint: delimiter != b',',
    };
    let mut builder = TableBuilder::new(layout, opts)?;
    src.n_fields = builder.names().len();
    let wanted = builder.wanted();
    let shape = Shape {
        delimiter,
        n_fields: src.n_fields,
        crlf: src.crlf,
        whitespace: None,
        wanted: wanted.as_deref(),
        label: builder.label_column(),
    };
    // Clean rows on all cores first; the general reader from the first
    // line that is not clean (module docs of csv_clean).
    if let Some((threads, piece_bytes)) = clean {
        let (after_header, header_line) = (src.resume(), src.header_line);
        drop(src);
        if let Some(at) = push_clean_rows(
            &mut builder,
            path,
            after_header,
            shape,
            threads,
            piece_bytes,
            &mut |_| {},
        )? {
            let src = CsvSource::open_at(path, delimiter, prefix.file_size, at)?.after_header(
                header_line,
                shape,
                builder.rows(),
            );
            push_rows(&mut builder, src)?;
        }
    } else {
        push_rows(&mut builder, src)?;
    }
    builder.finish(|| {
        let mut s = open()?;
        s.n_fields = s.header()?.len();
        Ok(s)
    })
}

/// The delimiter of a header line: most frequent of `,` `\t` `;` (comma on a
/// tie); `None` for a whitespace-separated header; comma for a single name.
fn detect_delimiter(header: &str) -> Option<u8> {
    let count = |c: char| header.matches(c).count();
    let candidates = [(b',', count(',')), (b'\t', count('\t')), (b';', count(';'))];
    let best = candidates.iter().fold(
        (b',', 0),
        |acc, &(d, n)| if n > acc.1 { (d, n) } else { acc },
    );
    if best.1 > 0 {
        return Some(best.0);
    }
    if header.split_ascii_whitespace().count() > 1 {
        None
    } else {
        Some(b',')
    }
}

/// Errors when a forced delimiter leaves the header as one column although
/// another delimiter (or whitespace) separates it.
fn check_forced_delimiter(file: &str, line: u64, header: &str, d: u8) -> Result<()> {
    if header.as_bytes().contains(&d) {
        return Ok(());
    }
    let other = [b',', b'\t', b';']
        .iter()
        .any(|c| *c != d && header.as_bytes().contains(c))
        || header.split_ascii_whitespace().count() > 1;
    if other {
        return Err(IoError::WrongDelimiter {
            file: file.to_string(),
            line,
            header: header.to_string(),
            delimiter: delimiter_name(d),
        });
    }
    Ok(())
}

/// A delimiter in words, for messages.
pub(crate) fn delimiter_name(d: u8) -> String {
    match d {
        b',' => "comma".into(),
        b';' => "semicolon".into(),
        b'\t' => "tab".into(),
        b' ' => "whitespace".into(),
        other => format!("'{}'", other as char),
    }
}

/// The last byte of a file (`None` when empty).
fn last_byte(file: &str, path: &Path, size: u64) -> Result<Option<u8>> {
    use std::io::{Read, Seek, SeekFrom};
    if size == 0 {
        return Ok(None);
    }
    let err = |source| IoError::Read {
        file: file.to_string(),
        line: 1,
        source,
    };
    let mut f = File::open(path).map_err(|source| IoError::Open {
        file: file.to_string(),
        source,
    })?;
    f.seek(SeekFrom::End(-1)).map_err(err)?;
    let mut b = [0u8];
    f.read_exact(&mut b).map_err(err)?;
    Ok(Some(b[0]))
}

/// Bytes the csv reader may read ahead of the record it returns (its buffer).
const READ_AHEAD: u64 = 256 * 1024;

/// The message of the I/O error [`Budget`] returns, recognised by [`CsvSource::read_record`].
const OVER_BUDGET: &str = "record longer than the line limit";

/// A reader that fails once more than a budget of bytes has been read since
/// the budget was last set: [`CsvSource`] sets it to [`MAX_LINE_BYTES`] plus
/// the read-ahead after every record, so a record (a line, or a quoted field
/// spanning lines) never grows beyond the limit in memory.
struct Budget<R> {
    inner: R,
    left: Arc<AtomicU64>,
}

impl<R: Read> Read for Budget<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let left = self.left.load(Ordering::Relaxed);
        if left == 0 {
            return Err(std::io::Error::other(OVER_BUDGET));
        }
        let n = buf.len().min(usize::try_from(left).unwrap_or(usize::MAX));
        let got = self.inner.read(&mut buf[..n])?;
        self.left.store(left - got as u64, Ordering::Relaxed);
        Ok(got)
    }
}

/// Rows of a CSV file through `csv::Reader` (see [`RowSource`]). The
/// terminator is `\n` alone so that every record consumes its own line end
/// and csv-core's line counter gives exact line numbers (comments and blank
/// lines included). In a file whose header line ends with `\r\n`, the `\r`
/// left on the last field of each row is trimmed (so a quoted text cell
/// ending in `\r` in the last column of a CRLF file loses that `\r`).
struct CsvSource {
    rdr: csv::Reader<Budget<BufReader<File>>>,
    budget: Arc<AtomicU64>,
    rec: csv::ByteRecord,
    file: String,
    path: std::path::PathBuf,
    delimiter: u8,
    header_line: u64,
    /// Line on which the previous record ended (0 before the first).
    last_line_end: u64,
    n_fields: usize,
    row: usize,
    line: u64,
    /// File offset of the reader's first byte (after a byte-order mark, or
    /// where the reader was opened) and the number of lines before it.
    base: u64,
    line_base: u64,
    file_size: u64,
    ends_with_newline: bool,
    last: usize,
    crlf: bool,
}

impl CsvSource {
    fn open(path: &Path, delimiter: u8, file_size: u64) -> Result<Self> {
        Self::open_at(path, delimiter, file_size, Resume { offset: 0, line: 1 })
    }

    /// A reader from the start of a line `at` (the file's start: after its
    /// byte-order mark, if any).
    fn open_at(path: &Path, delimiter: u8, file_size: u64, at: Resume) -> Result<Self> {
        use std::io::{Seek, SeekFrom};
        let file = path.display().to_string();
        let read_err = |source| IoError::Read {
            file: file.clone(),
            line: at.line,
            source,
        };
        let mut f = File::open(path).map_err(|source| IoError::Open {
            file: file.clone(),
            source,
        })?;
        if at.offset > 0 {
            f.seek(SeekFrom::Start(at.offset)).map_err(read_err)?;
        }
        let mut reader = BufReader::with_capacity(256 * 1024, f);
        let head = reader.fill_buf().map_err(read_err)?;
        let bom = if at.offset == 0 && head.starts_with(BOM) {
            BOM.len()
        } else {
            0
        };
        reader.consume(bom);
        let ends_with_newline = last_byte(&file, path, file_size)? == Some(b'\n');
        let budget = Arc::new(AtomicU64::new(MAX_LINE_BYTES + READ_AHEAD));
        let reader = Budget {
            inner: reader,
            left: Arc::clone(&budget),
        };
        let rdr = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .comment(Some(b'#'))
            .delimiter(delimiter)
            .terminator(csv::Terminator::Any(b'\n'))
            .buffer_capacity(if file_size > (1 << 20) {
                READ_AHEAD as usize
            } else {
                16 * 1024
            })
            .from_reader(reader);
        Ok(CsvSource {
            rdr,
            budget,
            rec: csv::ByteRecord::new(),
            file,
            path: path.to_path_buf(),
            delimiter,
            header_line: 0,
            last_line_end: at.line - 1,
            n_fields: 0,
            row: 0,
            line: at.line - 1,
            base: at.offset + bom as u64,
            line_base: at.line - 1,
            file_size,
            ends_with_newline,
            last: 0,
            crlf: false,
        })
    }

    /// Reads one record; skips whitespace-only lines. `false` at the end.
    fn read_record(&mut self) -> Result<bool> {
        loop {
            match self.rdr.read_byte_record(&mut self.rec) {
                Ok(false) => return Ok(false),
                Ok(true) => {}
                Err(e) => {
                    let line = e
                        .position()
                        .map_or(self.line + 1, |p| p.line() + self.line_base);
                    let source = match e.into_kind() {
                        csv::ErrorKind::Io(io) if io.to_string() == OVER_BUDGET => {
                            // csv-core has not counted the record's lines yet.
                            return Err(line_too_long(&self.file, self.line + 1));
                        }
                        csv::ErrorKind::Io(io) => io,
                        other => std::io::Error::other(format!("{other:?}")),
                    };
                    return Err(IoError::Read {
                        file: self.file.clone(),
                        line,
                        source,
                    });
                }
            }
            self.budget
                .store(MAX_LINE_BYTES + READ_AHEAD, Ordering::Relaxed);
            // The budget allows up to READ_AHEAD more; the limit itself is
            // on the record's text (fields and delimiters, quotes excluded).
            let cr = self.rec.as_slice().ends_with(b"\r");
            let record_bytes =
                self.rec.as_slice().len() + self.rec.len().saturating_sub(1) - usize::from(cr);
            // The line counter of csv-core counts every '\n' consumed. The
            // record's own '\n' has been consumed unless it is the unterminated
            // last line; quoted fields may contain more line ends.
            let pos = self.rdr.position();
            let at_end = pos.byte() + self.base >= self.file_size;
            let last_line =
                pos.line() + self.line_base - u64::from(!at_end || self.ends_with_newline);
            // A record ending on the line after the previous one holds no
            // line end of its own (the common case: no scan of its bytes).
            let embedded = if last_line == self.last_line_end + 1 {
                0
            } else {
                self.rec.as_slice().iter().filter(|&&b| b == b'\n').count() as u64
            };
            self.last_line_end = last_line;
            self.line = last_line.saturating_sub(embedded).max(1);
            if record_bytes as u64 > MAX_LINE_BYTES {
                return Err(line_too_long(&self.file, self.line));
            }
            if at_end && self.quote_left_open()? {
                // The file's last line end is inside the record's field,
                // not the record's own.
                let ends = self.rec.as_slice().iter().filter(|&&b| b == b'\n').count();
                let line = (last_line + 1).saturating_sub(ends as u64).max(1);
                return Err(IoError::UnclosedQuote {
                    file: self.file.clone(),
                    line,
                });
            }
            if self.rec.len() == 1 && self.rec[0].trim_ascii().is_empty() {
                continue;
            }
            return Ok(true);
        }
    }

    /// Whether the last record, which reached the end of the file, is a
    /// quote left open (csv-core reads one to the end of the file without an
    /// error): in a file ending with a line end, that line end is then in
    /// the record's last field (a record's own line end never is), and no
    /// closing quote comes before it (`"\n`, as a quoted field closed on
    /// the last line has it). Not told in a file without a last line end.
    fn quote_left_open(&self) -> Result<bool> {
        use std::io::{Read, Seek, SeekFrom};
        if !(self.ends_with_newline && self.rec.as_slice().ends_with(b"\n")) {
            return Ok(false);
        }
        let mut tail = [0u8; 3];
        let n = self.file_size.min(3) as usize;
        let read = |tail: &mut [u8]| -> std::io::Result<()> {
            let mut f = File::open(&self.path)?;
            f.seek(SeekFrom::Start(self.file_size - n as u64))?;
            f.read_exact(tail)
        };
        read(&mut tail[3 - n..]).map_err(|source| IoError::Read {
            file: self.file.clone(),
            line: self.last_line_end,
            source,
        })?;
        let body = match tail {
            [_, b'\r', b'\n'] => &tail[..1],
            [_, _, b'\n'] => &tail[..2],
            _ => &tail[..],
        };
        Ok(body.last() != Some(&b'"'))
    }

    /// Where the next record starts (after the last one read).
    fn resume(&self) -> Resume {
        Resume {
            offset: self.bytes_read(),
            line: self.last_line_end + 1,
        }
    }

    /// A reader opened after the header ([`Self::open_at`]) for rows of
    /// `shape`, `rows` data rows already read.
    fn after_header(mut self, header_line: u64, shape: Shape, rows: usize) -> Self {
        self.header_line = header_line;
        self.n_fields = shape.n_fields;
        self.last = shape.n_fields.saturating_sub(1);
        self.crlf = shape.crlf;
        self.row = rows;
        self
    }

    /// Reads the header record and returns its names (trimmed).
    fn header(&mut self) -> Result<Vec<String>> {
        if !self.read_record()? {
            return Err(IoError::Empty {
                file: self.file.clone(),
            });
        }
        self.header_line = self.line;
        self.last = self.rec.len().saturating_sub(1);
        self.crlf = self.rec.get(self.last).is_some_and(|f| f.ends_with(b"\r"));
        // A `\r` inside the header record other than a CRLF end: the file
        // ends its lines in `\r` alone and was read as one line.
        let inner_cr = self.rec.iter().enumerate().any(|(k, f)| {
            let f = if self.crlf && k == self.last {
                f.strip_suffix(b"\r").unwrap_or(f)
            } else {
                f
            };
            f.contains(&b'\r')
        });
        if inner_cr {
            return Err(IoError::CrLineEnds {
                file: self.file.clone(),
                line: self.line,
            });
        }
        // After the `\r` check: a file of `\r` line ends is one header of
        // every line's cells (360 019 columns), which this limit named.
        if self.rec.len() > MAX_COLUMNS {
            return Err(too_many_columns(&self.file, self.line, self.rec.len()));
        }
        self.rec
            .iter()
            .map(|f| {
                check_text(f)
                    .map(|s| s.trim().to_string())
                    .map_err(|_| IoError::Binary {
                        file: self.file.clone(),
                        line: self.line,
                        what: "invalid bytes in the header row".to_string(),
                    })
            })
            .collect()
    }
}

impl RowSource for CsvSource {
    fn next_row(&mut self) -> Result<bool> {
        if !self.read_record()? {
            return Ok(false);
        }
        if self.rec.len() != self.n_fields {
            return Err(IoError::FieldCount {
                file: self.file.clone(),
                line: self.line,
                row: self.row,
                expected: self.n_fields,
                found: self.rec.len(),
                header_line: self.header_line,
                delimiter: delimiter_name(self.delimiter),
            });
        }
        self.row += 1;
        Ok(true)
    }
}

impl RowFields for CsvSource {
    fn line(&self) -> u64 {
        self.line
    }

    #[inline]
    fn field(&self, i: usize) -> &[u8] {
        let f = &self.rec[i];
        // With '\n' as the terminator, a CRLF file leaves '\r' on the last field.
        if self.crlf && i == self.last {
            f.strip_suffix(b"\r").unwrap_or(f)
        } else {
            f
        }
    }

    fn bytes_read(&self) -> u64 {
        self.rdr.position().byte() + self.base
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// One line of a generated file (`{d}` stands for the delimiter):
    /// mostly clean rows, some lines the fast path leaves to the general
    /// reader (comments, blank lines, quotes, text in the free column `note`),
    /// rarely one that makes the read fail.
    fn line() -> impl Strategy<Value = String> {
        let cell = prop_oneof![
            8 => (-99_999_999i64..99_999_999, 0u32..9).prop_map(|(m, k)| {
                let s = format!("{}", m.abs());
                let s = if k == 0 || (k as usize) >= s.len() {
                    s
                } else {
                    format!("{}.{}", &s[..s.len() - k as usize], &s[s.len() - k as usize..])
                };
                if m < 0 { format!("-{s}") } else { s }
            }),
            1 => prop::sample::select(vec![
                "", " ", "*", "NaN", "-nan", "inf", "1e-3", " 12 ", "+5", "5.", ".5", "-0",
                "12345678901234567890", "0.12345678901234567", "1234567.1234567", "007",
                "9007199254740993", "123456789", "-12345678.9", "1\r",
            ])
            .prop_map(str::to_string),
        ];
        prop_oneof![
            // `note` mostly integers (its integer flag is then at stake).
            60 => (proptest::collection::vec(cell.clone(), 2), prop_oneof![
                9 => (-9999i64..9999).prop_map(|i| i.to_string()),
                1 => cell,
            ])
                .prop_map(|(c, n)| format!("{}{{d}}{}{{d}}{n}", c[0], c[1])),
            2 => Just("# a comment, with \"quotes\"".to_string()),
            2 => prop::sample::select(vec!["", "   ", "\r"]).prop_map(str::to_string),
            1 => Just("\"1.5\"{d}2{d}\"3\"".to_string()),
            1 => Just("1{d}2{d}\"multi\nline\"".to_string()),
            1 => Just("1{d}2{d}text".to_string()),
            // Fatal: text in a numeric column, short and long rows, a NUL.
            1 => prop::sample::select(vec![
                "1{d}text{d}3", "1{d}2", "1{d}2{d}3{d}4", "1{d}2{d}\u{0}", "1.2.3{d}2{d}3",
            ])
            .prop_map(str::to_string),
        ]
    }

    /// A whole file: header `time,mag,note` (`mag` must be numeric, `note`
    /// may turn to text), lines mostly clean, a delimiter, CRLF or LF, a
    /// byte-order mark or none, a final line end or none.
    fn file() -> impl Strategy<Value = Vec<u8>> {
        (
            proptest::collection::vec(
                prop_oneof![8 => line().prop_map(Some), 1 => Just(None)],
                0..60,
            ),
            prop::sample::select(vec![",", ";", "\t"]),
            any::<bool>(),
            any::<bool>(),
            any::<bool>(),
        )
            .prop_map(|(lines, d, crlf, bom, last_newline)| {
                let end = if crlf { "\r\n" } else { "\n" };
                let bom = if bom { "\u{feff}" } else { "" };
                let lines: Vec<Option<String>> = lines
                    .iter()
                    .map(|l| l.as_ref().map(|l| l.replace("{d}", d)))
                    .collect();
                csv_clean::check::text(
                    &format!("{bom}# head{end}time{d}mag{d}note{end}"),
                    &lines,
                    |k, i| format!("{k}.{i}{d}-5300{i}.25{d}{i}"),
                    end,
                    last_newline,
                )
            })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]

        /// The fast path changes nothing: the same table (values, missing
        /// counts, integer flags, text columns, line numbers) or the same
        /// error as the general reader alone, for any thread count and
        /// piece size (small pieces: pieces end inside long lines).
        #[test]
        fn clean_rows_read_as_the_general_reader_reads_them(
            text in file(),
            threads in 1usize..4,
            piece in 8usize..300,
            fields in csv_clean::check::fields(),
        ) {
            let opts = ReadOptions { fields, ..ReadOptions::default() };
            csv_clean::check::reads_as_the_general_reader(
                &text,
                |path, clean| read_csv_with(path, &opts, clean),
                threads,
                piece,
            )?;
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]

        /// Line labels are names (`crate::label_texts`): a `line` column
        /// stays numeric unless two of its labels differ as text and not as
        /// numbers, and then holds every label as written; the fast path
        /// reads it as the general reader does, in any piece size.
        #[test]
        fn line_labels_of_one_number_in_two_texts_stay_two_lines(
            labels in proptest::collection::vec(
                prop::sample::select(vec![
                    "1003", "1003.0", "01003", "1003.1", "1003.10", " 1003.1", "7", "0", "0.0",
                    "", "NaN", "*", "1e3", "1000", "100300000.25", "100300000.250",
                    "12345678", "012345678",
                ]),
                1..12,
            ),
            run in 1usize..30,
            threads in 1usize..4,
            piece in 8usize..300,
        ) {
            let mut text = String::from("time,line,mag\n");
            let mut row = 0;
            for l in &labels {
                for _ in 0..run {
                    text.push_str(&format!("{row}.5,{l},5{row}.25\n"));
                    row += 1;
                }
            }
            let opts = ReadOptions::default();
            csv_clean::check::reads_as_the_general_reader(
                text.as_bytes(),
                |path, clean| read_csv_with(path, &opts, clean),
                threads,
                piece,
            )?;
            let dir = tempfile::tempdir().unwrap();
            let path = dir.path().join("l.csv");
            std::fs::write(&path, &text).unwrap();
            let t = read_csv(&path, &opts).unwrap();
            let value = |l: &str| l.trim().parse::<f64>().ok().filter(|v| *v != 0.0 && !v.is_nan());
            let mut by_value: Vec<(f64, &str)> = Vec::new();
            let mut clash = false;
            for l in &labels {
                if let Some(v) = value(l) {
                    match by_value.iter().find(|(x, _)| *x == v) {
                        Some((_, first)) => clash |= first.trim() != l.trim(),
                        None => by_value.push((v, l)),
                    }
                }
            }
            match t.text_column("line") {
                Some(cells) => {
                    prop_assert!(clash, "read as text without a clash: {labels:?}");
                    let written: Vec<&str> = labels
                        .iter()
                        .flat_map(|l| std::iter::repeat_n(*l, run))
                        .collect();
                    prop_assert_eq!(cells, &written);
                }
                None => prop_assert!(!clash, "clash read as numbers: {:?}", labels),
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]

        /// Reading some fields gives those columns of the whole read, the
        /// same values, missing counts, integer flags and lines (when the
        /// whole read succeeds: the fields not read are not checked).
        #[test]
        fn some_fields_are_those_columns_of_the_whole_read(
            text in file(),
            fields in csv_clean::check::fields(),
        ) {
            csv_clean::check::some_fields_are_those_of_the_whole(&text, fields, |path, opts| {
                read_csv(path, opts)
            })?;
        }
    }

    /// A read of some fields: those columns, typed and checked; the others
    /// not parsed (text in a numeric-only column passes), listed, and named
    /// in the message for a missing column.
    #[test]
    fn a_selection_reads_its_fields_and_names_the_others() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("wide.csv");
        let mut text = String::from("time,lat,magnetic,true_mag,flux_x,note\n");
        for i in 0..3000 {
            let truth = if i == 2000 {
                "oops".to_string()
            } else {
                format!("{i}.5")
            };
            text.push_str(&format!(
                "{}.{},56.{i},5300{},{truth},1{i}.25,\"a, b\"\n",
                i / 10,
                i % 10,
                i % 10
            ));
        }
        std::fs::write(&path, &text).unwrap();
        // The whole read fails at the text in `true_mag` (numeric only).
        let e = read_csv(&path, &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains("true_mag"), "{e}");
        let opts = ReadOptions {
            fields: crate::Fields::Only(vec!["time".into(), "FLUX_X".into()]),
            ..ReadOptions::default()
        };
        let t = read_csv(&path, &opts).unwrap();
        assert_eq!(t.column_names(), ["time", "flux_x"]);
        assert_eq!(t.n_rows(), 3000);
        assert_eq!(t.column("flux_x").unwrap()[2999], 12999.25);
        assert_eq!(t.line_of_row(2999), Some(3001));
        assert_eq!(t.unread_columns(), ["lat", "magnetic", "true_mag", "note"]);
        let e = t.require("mag").unwrap_err().to_string();
        assert!(
            e.contains("columns present: time, lat, magnetic, true_mag, flux_x, note ("),
            "{e}"
        );
    }

    #[test]
    fn delimiter_detection() {
        assert_eq!(detect_delimiter("time,lat,lon"), Some(b','));
        assert_eq!(detect_delimiter("time;lat;lon"), Some(b';'));
        assert_eq!(detect_delimiter("time\tlat\tlon"), Some(b'\t'));
        assert_eq!(detect_delimiter("a;b;c,d"), Some(b';'));
        assert_eq!(detect_delimiter("time lat  lon"), None);
        assert_eq!(detect_delimiter("mag"), Some(b','));
    }

    #[test]
    fn forced_delimiter_mismatch() {
        let e = check_forced_delimiter("f.csv", 3, "a;b;c", b',').unwrap_err();
        let s = e.to_string();
        assert!(
            s.contains("wrong delimiter?") && s.contains("'a;b;c'") && s.contains("line 3"),
            "{s}"
        );
        assert!(check_forced_delimiter("f.csv", 3, "a,b", b',').is_ok());
        assert!(check_forced_delimiter("f.csv", 3, "mag", b',').is_ok());
    }
}
