//! Streaming assembly of a [`FlightTable`] from rows of byte fields.
//!
//! Both readers (CSV and whitespace/XYZ) hand their rows to one
//! [`TableBuilder`] through the [`RowSource`] trait, so the column typing,
//! missing-value handling and error messages are the same for every format.
//!
//! # Column typing
//!
//! A column whose role (canonical name, directly or through the column map)
//! is canonical (except `line`) or `true_*` must be numeric: text in it is an
//! error. Any other column starts numeric and turns into a text column at its
//! first cell that is not a number (or missing marker). The rows before that
//! cell were stored as numbers, so their original text is recovered by a
//! second pass over those rows only (usually none: a text column such as a
//! flight id already fails on the first row).
//!
//! The `line` column is read as numbers while its labels are numbers, but
//! when two of its labels differ as text and not as numbers (`1003.1` and
//! `1003.10`: [`crate::label_texts`]) it is read again as text, whole, by
//! the same second pass.
//!
//! A column that [`Fields::Only`](crate::Fields::Only) does not ask for
//! is skipped: its cells are not parsed or checked, it holds no memory,
//! and the table leaves it out ([`FlightTable::unread_columns`] names it).
//!
//! # Memory
//!
//! Cells are parsed straight into one `Vec<f64>` per column; the file's text
//! is never held (one record buffer is reused). After
//! [`RESERVE_AFTER_ROWS`] rows the number of rows is estimated from the file
//! size and the bytes per row so far, and every column reserves
//! `1.02 × estimate` values at once (a table larger than the memory the
//! process can take is refused there instead, [`IoError::OutOfMemory`]),
//! so the vectors are allocated about once
//! at their final size instead of growing by doubling. If the estimate is
//! short (later rows longer than the first ones) the vectors grow by
//! doubling from there (large reallocations are page remaps, not copies, on
//! Linux/glibc). At the end, vectors with more than 1/8 spare capacity are
//! shrunk. Peak memory is therefore about 1.02–1.1 × the f64 data when the
//! estimate holds, and at most about 2× when it does not. Text columns cost a
//! `String` per row (24 bytes plus the text).

use std::path::PathBuf;

use crate::ReadOptions;
use crate::cell::{Cell, CellError, check_text, parse_cell};
use crate::columns::{MappedColumn, must_be_numeric, resolve};
use crate::error::{IoError, Result};
use crate::label_texts::{LabelClash, LabelTexts};
use crate::table::{ColumnData, FlightTable, Missing};
use crate::wanted::wanted_fields;

/// Rows read before the capacity of the columns is estimated.
pub(crate) const RESERVE_AFTER_ROWS: usize = 1024;

/// Longest line the readers accept, in bytes (16 MiB; for CSV, a quoted
/// field spanning lines counts as one line). A longer one is an
/// [`IoError::TooLarge`] error, so that a file without line ends (or a
/// hostile 1 GB line) is not read into memory whole.
pub const MAX_LINE_BYTES: u64 = 16 << 20;

/// Most columns a header may have (100 000); more is an
/// [`IoError::TooLarge`] error (every column costs a few hundred bytes
/// before the first data row is read).
pub const MAX_COLUMNS: usize = 100_000;

/// The error for a header of more than [`MAX_COLUMNS`] columns.
pub(crate) fn too_many_columns(file: &str, line: u64, n: usize) -> IoError {
    IoError::TooLarge {
        file: file.to_string(),
        line,
        what: format!("the header has {n} columns, more than the limit of {MAX_COLUMNS}"),
    }
}

/// The error for a line longer than [`MAX_LINE_BYTES`].
pub(crate) fn line_too_long(file: &str, line: u64) -> IoError {
    IoError::TooLarge {
        file: file.to_string(),
        line,
        what: format!(
            "line longer than {} MiB (the limit of the reader)",
            MAX_LINE_BYTES >> 20
        ),
    }
}

/// A stream of data rows whose field count already matches the header.
pub(crate) trait RowSource: RowFields {
    /// Advances to the next data row; `false` at the end of the input.
    fn next_row(&mut self) -> Result<bool>;
}

/// The current row of a [`RowSource`] (or of rows read ahead).
pub(crate) trait RowFields {
    /// 1-based file line of the current row.
    fn line(&self) -> u64;
    /// Field `i` of the current row (`i` < number of header columns).
    fn field(&self, i: usize) -> &[u8];
    /// Bytes of the file consumed so far (for the capacity estimate).
    fn bytes_read(&self) -> u64;
}

/// What a reader knows once the header is parsed.
pub(crate) struct Layout {
    /// The file.
    pub path: PathBuf,
    /// Column names as in the header (trimmed; not yet de-duplicated).
    pub names: Vec<String>,
    /// 1-based line of the header.
    pub header_line: u64,
    /// File size in bytes.
    pub file_size: u64,
    /// Bytes consumed up to the end of the header.
    pub header_bytes: u64,
    /// Cells may use a decimal comma (delimiter is not a comma): adds a hint to parse errors.
    pub decimal_comma_hint: bool,
}

enum ColState {
    Numeric {
        values: Vec<f64>,
        missing: Missing,
        /// Every value so far was written as an integer (`1003`).
        integers: bool,
    },
    /// Text from row `from_row` on; rows before it need the second pass.
    Text {
        values: Vec<String>,
        from_row: usize,
    },
    /// Not read ([`crate::Fields::Only`] does not ask for it): its cells
    /// are neither parsed nor checked, and the table does not have it.
    Skipped,
}

/// Builds a [`FlightTable`] row by row (see the module docs).
pub(crate) struct TableBuilder {
    file: String,
    path: PathBuf,
    names: Vec<String>,
    labels: Vec<String>,
    numeric_only: Vec<bool>,
    cols: Vec<ColState>,
    aliases: Vec<MappedColumn>,
    header_line: u64,
    file_size: u64,
    header_bytes: u64,
    decimal_comma_hint: bool,
    n_rows: usize,
    row_lines: Vec<(usize, u64)>,
    last_line: u64,
    /// The read column whose role is `line`, if any: its labels' texts
    /// are kept while it is numeric ([`crate::label_texts`]).
    label_column: Option<usize>,
    /// The texts of that column's cells read by [`Self::push_row`].
    label_texts: LabelTexts,
    /// Whether two of its texts (from either reader) give one number.
    label_clash: LabelClash,
}

/// Bytes a text cell takes at least (a `String`).
const TEXT_CELL_BYTES: u64 = 24;

/// The error of a table of `rows` rows whose columns take `column_bytes`
/// bytes a row each, when it would take more than the `available` bytes
/// ([`aeromag_core::memory::available_bytes`], as gridding checks its
/// nodes; `None`, unknown: no error).
fn memory_error(
    file: &str,
    rows: u64,
    column_bytes: &[u64],
    available: Option<u64>,
) -> Option<IoError> {
    let available = available?;
    let need = rows.saturating_mul(column_bytes.iter().sum());
    (need > available).then(|| IoError::OutOfMemory {
        file: file.to_string(),
        rows,
        columns: column_bytes.len(),
        need_bytes: need,
        available_bytes: available,
    })
}

impl TableBuilder {
    /// Checks the header (empty names become `unnamed_<position>`, repeated
    /// names are an error) and resolves the column map.
    pub(crate) fn new(layout: Layout, opts: &ReadOptions) -> Result<Self> {
        let file = layout.path.display().to_string();
        let names: Vec<String> = layout
            .names
            .into_iter()
            .enumerate()
            .map(|(i, n)| {
                if n.is_empty() {
                    format!("unnamed_{}", i + 1)
                } else {
                    n
                }
            })
            .collect();
        if names.len() > MAX_COLUMNS {
            return Err(too_many_columns(&file, layout.header_line, names.len()));
        }
        // A map, not a scan of the names before each one: a wide header
        // (10^5 columns) is checked in linear time.
        let mut seen = std::collections::HashMap::with_capacity(names.len());
        for (j, name) in names.iter().enumerate() {
            if let Some(i) = seen.insert(name.as_str(), j) {
                return Err(IoError::DuplicateHeader {
                    file,
                    line: layout.header_line,
                    column: name.clone(),
                    first: i + 1,
                    second: j + 1,
                });
            }
        }
        let aliases = resolve(
            &file,
            &names,
            &opts.columns,
            &opts.sensors,
            opts.magnav_preset,
        )?;
        let role_of = |name: &str| {
            aliases
                .iter()
                .find(|m| m.file_column == name)
                .map_or(name.to_string(), |m| m.canonical.clone())
        };
        let labels = names
            .iter()
            .map(|n| {
                let role = role_of(n);
                if role == *n {
                    format!("'{n}'")
                } else {
                    format!("'{n}' (mapped to '{role}')")
                }
            })
            .collect();
        let numeric_only = names.iter().map(|n| must_be_numeric(&role_of(n))).collect();
        let wanted = wanted_fields(&names, &aliases, opts);
        let label_column = names
            .iter()
            .zip(&wanted)
            .position(|(n, &read)| read && role_of(n) == "line");
        let cols = wanted
            .into_iter()
            .map(|wanted| match wanted {
                true => ColState::Numeric {
                    values: Vec::new(),
                    missing: Missing::default(),
                    integers: true,
                },
                false => ColState::Skipped,
            })
            .collect();
        Ok(TableBuilder {
            file,
            path: layout.path,
            names,
            labels,
            numeric_only,
            cols,
            aliases,
            header_line: layout.header_line,
            file_size: layout.file_size,
            header_bytes: layout.header_bytes,
            decimal_comma_hint: layout.decimal_comma_hint,
            n_rows: 0,
            row_lines: Vec::new(),
            last_line: 0,
            label_column,
            label_texts: LabelTexts::default(),
            label_clash: LabelClash::default(),
        })
    }

    /// The read column whose role is `line` (its labels' texts are kept
    /// while it is read as numbers: [`crate::label_texts`]).
    pub(crate) fn label_column(&self) -> Option<usize> {
        self.label_column
    }

    /// Column names after de-duplication checks (header order).
    pub(crate) fn names(&self) -> &[String] {
        &self.names
    }

    /// Which columns are read (header order); `None` when every one is.
    pub(crate) fn wanted(&self) -> Option<Vec<bool>> {
        let wanted: Vec<bool> = self
            .cols
            .iter()
            .map(|c| !matches!(c, ColState::Skipped))
            .collect();
        wanted.contains(&false).then_some(wanted)
    }

    /// Data rows so far.
    pub(crate) fn rows(&self) -> usize {
        self.n_rows
    }

    /// Appends the current row of `src`.
    pub(crate) fn push_row<S: RowFields>(&mut self, src: &S) -> Result<()> {
        let row = self.n_rows;
        let line = src.line();
        if row == RESERVE_AFTER_ROWS {
            self.reserve(src.bytes_read())?;
        }
        for (i, col) in self.cols.iter_mut().enumerate() {
            if matches!(col, ColState::Skipped) {
                continue;
            }
            let bytes = src.field(i);
            match col {
                ColState::Numeric {
                    values,
                    missing,
                    integers,
                } => match parse_cell(bytes) {
                    Ok(Cell::Value(v)) => {
                        *integers = *integers && is_integer_text(bytes);
                        values.push(v);
                        if self.label_column == Some(i) {
                            self.label_texts.note(bytes, v);
                        }
                    }
                    Ok(Cell::Missing(kind)) => {
                        values.push(f64::NAN);
                        missing.count(kind);
                        if self.label_column == Some(i) {
                            self.label_texts.note(bytes, f64::NAN);
                        }
                    }
                    Err(CellError::NotNumber) if !self.numeric_only[i] => {
                        // First text cell of a free column: it becomes a text column.
                        let mut text = Vec::with_capacity(values.capacity());
                        text.push(String::from_utf8_lossy(bytes).into_owned());
                        *col = ColState::Text {
                            values: text,
                            from_row: row,
                        };
                    }
                    Err(e) => {
                        return Err(cell_error(
                            e,
                            &self.file,
                            line,
                            row,
                            &self.labels[i],
                            bytes,
                            self.decimal_comma_hint,
                        ));
                    }
                },
                ColState::Skipped => {}
                ColState::Text { values, .. } => match check_text(bytes) {
                    Ok(s) => values.push(s.to_string()),
                    Err(e) => {
                        return Err(cell_error(
                            e,
                            &self.file,
                            line,
                            row,
                            &self.labels[i],
                            bytes,
                            false,
                        ));
                    }
                },
            }
        }
        if line != self.last_line + 1 || row == 0 {
            self.row_lines.push((row, line));
        }
        self.last_line = line;
        self.n_rows += 1;
        Ok(())
    }

    /// Appends the clean rows of a piece of the file whose first line is
    /// `first_line` ([`crate::csv_clean`]); `bytes_read` is the file offset
    /// after the piece. The same columns, counts and line breakpoints as
    /// [`Self::push_row`] on each of its rows. `false` (nothing appended)
    /// when a column has turned to text: such rows are the general reader's.
    pub(crate) fn append_clean(
        &mut self,
        part: &crate::csv_clean::CleanRows,
        first_line: u64,
        bytes_read: u64,
    ) -> Result<bool> {
        if self.cols.iter().any(|c| matches!(c, ColState::Text { .. })) {
            return Ok(false);
        }
        if part.rows == 0 {
            return Ok(true);
        }
        self.label_clash.add_all(&part.labels);
        for (i, col) in self.cols.iter_mut().enumerate() {
            if let ColState::Numeric {
                values,
                missing,
                integers,
            } = col
            {
                values.extend_from_slice(&part.values[i]);
                missing.add(&part.missing[i]);
                *integers &= part.integers[i];
            }
        }
        for &(r, l) in &part.breaks {
            let (row, line) = (self.n_rows + r, first_line + l);
            if r > 0 || row == 0 || line != self.last_line + 1 {
                self.row_lines.push((row, line));
            }
        }
        let before = self.n_rows;
        self.n_rows += part.rows;
        self.last_line = first_line + part.last_row_line;
        if before <= RESERVE_AFTER_ROWS && self.n_rows > RESERVE_AFTER_ROWS {
            self.reserve(bytes_read)?;
        }
        Ok(true)
    }

    /// Reserves every column for the estimated total number of rows, once
    /// the table is known to fit in memory ([`memory_error`]).
    fn reserve(&mut self, bytes_read: u64) -> Result<()> {
        let used = bytes_read.saturating_sub(self.header_bytes).max(1);
        let rest = self.file_size.saturating_sub(self.header_bytes);
        let estimate = (rest as f64 / used as f64 * self.n_rows as f64 * 1.02) as usize + 16;
        // Guard against absurd estimates (e.g. a file growing while read).
        let estimate = estimate.min(self.file_size as usize / 2 + 16);
        let columns: Vec<u64> = self
            .cols
            .iter()
            .filter_map(|c| match c {
                ColState::Numeric { .. } => Some(8),
                ColState::Text { .. } => Some(TEXT_CELL_BYTES),
                ColState::Skipped => None,
            })
            .collect();
        let available = aeromag_core::memory::available_bytes();
        if let Some(e) = memory_error(&self.file, estimate as u64, &columns, available) {
            return Err(e);
        }
        for col in &mut self.cols {
            match col {
                ColState::Numeric { values, .. } => {
                    values.reserve_exact(estimate.saturating_sub(values.len()))
                }
                ColState::Text { values, .. } => {
                    values.reserve_exact(estimate.saturating_sub(values.len()))
                }
                ColState::Skipped => {}
            }
        }
        Ok(())
    }

    /// Finishes the table. Text columns that started as numbers get their
    /// first rows' text from a second pass over a fresh source from `reopen`.
    pub(crate) fn finish<S: RowSource>(
        self,
        reopen: impl FnOnce() -> Result<S>,
    ) -> Result<FlightTable> {
        if self.n_rows == 0 {
            return Err(IoError::NoData {
                file: self.file,
                header_line: self.header_line,
            });
        }
        let TableBuilder {
            file,
            path,
            names,
            mut cols,
            aliases,
            n_rows,
            row_lines,
            label_column,
            label_texts,
            mut label_clash,
            ..
        } = self;
        // Two texts of one number in the `line` column (`1003.1` and
        // `1003.10`): the column is read again as text, whole.
        label_clash.add_all(&label_texts);
        if let Some(c) = label_column
            && label_clash.clash
            && matches!(cols[c], ColState::Numeric { .. })
        {
            cols[c] = ColState::Text {
                values: Vec::new(),
                from_row: n_rows,
            };
        }
        let pending: Vec<(usize, usize)> = cols
            .iter()
            .enumerate()
            .filter_map(|(i, c)| match c {
                ColState::Text { from_row, .. } if *from_row > 0 => Some((i, *from_row)),
                _ => None,
            })
            .collect();
        if let Some(max_row) = pending.iter().map(|(_, r)| *r).max() {
            let mut src = reopen()?;
            let mut prefixes: Vec<Vec<String>> = pending
                .iter()
                .map(|(_, r)| Vec::with_capacity(*r))
                .collect();
            let mut row = 0;
            while row < max_row && src.next_row()? {
                for ((c, from_row), prefix) in pending.iter().zip(&mut prefixes) {
                    if row < *from_row {
                        prefix.push(String::from_utf8_lossy(src.field(*c)).into_owned());
                    }
                }
                row += 1;
            }
            if row < max_row {
                return Err(IoError::Read {
                    file,
                    line: src.line(),
                    source: std::io::Error::other("the file changed while it was being read"),
                });
            }
            for ((c, _), mut prefix) in pending.into_iter().zip(prefixes) {
                if let ColState::Text { values, .. } = &mut cols[c] {
                    prefix.append(values);
                    *values = prefix;
                }
            }
        }
        let read = |name: &str| {
            names
                .iter()
                .zip(&cols)
                .any(|(n, c)| n == name && !matches!(c, ColState::Skipped))
        };
        let file_columns = names.clone();
        let aliases = aliases
            .into_iter()
            .filter(|m| read(&m.file_column))
            .collect();
        let columns = names
            .into_iter()
            .zip(cols)
            .filter(|(_, col)| !matches!(col, ColState::Skipped))
            .map(|(name, col)| {
                let data = match col {
                    ColState::Numeric {
                        mut values,
                        missing,
                        integers,
                    } => {
                        shrink(&mut values);
                        // A column with no value at all has no form to keep.
                        let integers = integers && missing.total() < values.len();
                        (
                            ColumnData::Numeric {
                                values: values.into(),
                                missing,
                            },
                            integers,
                        )
                    }
                    ColState::Text { mut values, .. } => {
                        shrink(&mut values);
                        (ColumnData::Text(values), false)
                    }
                    ColState::Skipped => unreachable!("skipped columns are left out above"),
                };
                (name, data.0, data.1)
            })
            .collect();
        let mut table = FlightTable::from_parts(path, n_rows, columns, aliases, row_lines);
        table.set_file_columns(file_columns);
        Ok(table)
    }
}

/// Shrinks a vector with more than 1/8 spare capacity.
fn shrink<T>(v: &mut Vec<T>) {
    if v.capacity() > v.len() + v.len() / 8 {
        v.shrink_to_fit();
    }
}

/// The user-facing error for a cell that cannot be stored.
pub(crate) fn cell_error(
    e: CellError,
    file: &str,
    line: u64,
    row: usize,
    label: &str,
    bytes: &[u8],
    decimal_comma_hint: bool,
) -> IoError {
    match e {
        CellError::Nul => IoError::Binary {
            file: file.to_string(),
            line,
            what: format!("NUL byte in column {label} (data row {})", row + 1),
        },
        CellError::NotUtf8 => IoError::Binary {
            file: file.to_string(),
            line,
            what: format!("invalid UTF-8 in column {label} (data row {})", row + 1),
        },
        CellError::NotNumber => {
            let text = String::from_utf8_lossy(bytes).into_owned();
            let hint = if decimal_comma_hint
                && text.contains(',')
                && text.replace(',', ".").trim().parse::<f64>().is_ok()
            {
                " (decimal comma? numbers must use '.')".to_string()
            } else {
                String::new()
            };
            IoError::ParseNumber {
                file: file.to_string(),
                line,
                row,
                column: label.to_string(),
                text,
                hint,
            }
        }
    }
}

/// True for a cell written as an integer: optional sign and decimal digits
/// (surrounding spaces allowed), e.g. `1003`, `-7`; not `1003.0`, `1e3`.
pub(crate) fn is_integer_text(bytes: &[u8]) -> bool {
    let b = bytes.trim_ascii();
    let digits = b
        .strip_prefix(b"-")
        .or_else(|| b.strip_prefix(b"+"))
        .unwrap_or(b);
    !digits.is_empty() && digits.len() <= 15 && digits.iter().all(u8::is_ascii_digit)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_table_larger_than_the_memory_left_is_refused() {
        // 10⁸ rows of 20 numeric columns and a text one: 18.4 GB.
        let cols: Vec<u64> = std::iter::repeat_n(8, 20)
            .chain([TEXT_CELL_BYTES])
            .collect();
        let e = memory_error("big.csv", 100_000_000, &cols, Some(16_000_000_000)).unwrap();
        let small = memory_error("f.csv", 1_000_000, &[8; 6], Some(20_000_000)).unwrap();
        assert!(
            small
                .to_string()
                .contains("about 48 MB in memory, more than the 20 MB"),
            "{small}"
        );
        assert!(e.is_bad_input());
        assert_eq!(e.location().file.as_deref(), Some("big.csv"));
        let text = e.to_string();
        assert!(
            text.contains("about 100000000 rows of 21 columns"),
            "{text}"
        );
        assert!(
            text.contains("18.4 GB") && text.contains("16.0 GB"),
            "{text}"
        );
        // Within what is left, or nothing known: no error.
        assert!(memory_error("big.csv", 100_000_000, &cols, Some(18_400_000_000)).is_none());
        assert!(memory_error("big.csv", 100_000_000, &cols, None).is_none());
    }
}
