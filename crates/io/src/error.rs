//! The error type of `aeromag-io`.
//!
//! Every variant's `Display` text is the message a user sees on the command
//! line: it names the file, the 1-based line number in the file, the data row
//! and the column wherever they are known.
//!
//! Numbering conventions used in every message and field:
//!
//! - `line`: 1-based line number in the file, counting every physical line
//!   (comments, blank lines and the header included), as an editor shows it.
//! - `row`: 0-based index of the data row in the [`FlightTable`](crate::FlightTable).
//!   Messages print it 1-based as "data row N" (the first data row is
//!   "data row 1"), so `row` 14 is printed as "data row 15".

use aeromag_core::error::shown;
use aeromag_core::memory::size_text;

/// Everything that can go wrong while reading, mapping, checking or writing
/// flight-data tables.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum IoError {
    /// The file does not exist or cannot be opened.
    #[error("cannot open '{file}': {source}")]
    Open {
        /// File as given.
        file: String,
        /// The operating system's reason.
        #[source]
        source: std::io::Error,
    },
    /// An I/O error while reading an opened file.
    #[error("error reading '{file}' near line {line}: {source}")]
    Read {
        /// File as given.
        file: String,
        /// Line reached when the error happened.
        line: u64,
        /// The operating system's reason.
        #[source]
        source: std::io::Error,
    },
    /// The file has no header row (zero bytes, or only comments and blank lines).
    #[error("'{file}' is empty: expected a header row with column names")]
    Empty {
        /// File as given.
        file: String,
    },
    /// The file has a header row but not a single data row.
    #[error("'{file}' has a header (line {header_line}) but no data rows")]
    NoData {
        /// File as given.
        file: String,
        /// Line of the header.
        header_line: u64,
    },
    /// Invalid UTF-8 or NUL bytes: the file is binary or in another encoding.
    #[error(
        "'{file}' line {line}: {what}; this is not a UTF-8 text table (binary file, or another encoding?)"
    )]
    Binary {
        /// File as given.
        file: String,
        /// Line where the bad byte is.
        line: u64,
        /// What was found, e.g. "NUL byte in column 'mag'".
        what: String,
    },
    /// The header row splits into a single column although it contains
    /// another likely delimiter.
    #[error(
        "'{file}' line {line}: wrong delimiter? the header has one column '{header}' when split at {delimiter}"
    )]
    WrongDelimiter {
        /// File as given.
        file: String,
        /// Line of the header.
        line: u64,
        /// The header text.
        header: String,
        /// The delimiter used, in words ("comma", "tab", …).
        delimiter: String,
    },
    /// A line (or a quoted field spanning lines) or a header beyond the
    /// reader's limits ([`MAX_LINE_BYTES`](crate::MAX_LINE_BYTES),
    /// [`MAX_COLUMNS`](crate::MAX_COLUMNS)), which keep memory bounded on
    /// hostile files.
    #[error("'{file}' line {line}: {what}; this is not a flight-data table (or it must be split)")]
    TooLarge {
        /// File as given.
        file: String,
        /// Line where the limit was reached.
        line: u64,
        /// What is too large, with the limit.
        what: String,
    },
    /// A file whose table would not fit in the memory this process can
    /// take (estimated from the file's size and its first rows): refused
    /// with a message instead of ending in an allocation failure, which
    /// aborts the process (a Python kernel dies with it).
    #[error(
        "'{file}': about {rows} rows of {columns} columns to read, about {} in memory, more than the {} this process can take; split the file, or read fewer of its fields",
        size_text(*need_bytes), size_text(*available_bytes)
    )]
    OutOfMemory {
        /// File as given.
        file: String,
        /// Rows estimated.
        rows: u64,
        /// Columns read.
        columns: usize,
        /// Bytes the table would take.
        need_bytes: u64,
        /// Bytes this process can take.
        available_bytes: u64,
    },
    /// The lines end in `\r` alone (a classic Mac OS text file): the whole
    /// file read as one header line ("column name '0.0' appears twice").
    #[error(
        "'{file}' line {line}: the lines end in \\r alone (a classic Mac OS text file); convert the line ends to \\n or \\r\\n"
    )]
    CrLineEnds {
        /// File as given.
        file: String,
        /// The header's line.
        line: u64,
    },
    /// A quote opened in a field is not closed before the end of the file:
    /// every line after it was read as that field's text.
    #[error(
        "'{file}' line {line}: a quote (\") opened in this row is not closed before the end of the file, so every line after it was read as one field; close it or remove it"
    )]
    UnclosedQuote {
        /// File as given.
        file: String,
        /// The row's first line.
        line: u64,
    },
    /// A column name appears twice in the header.
    #[error(
        "'{file}' line {line}: column name '{column}' appears twice in the header (columns {first} and {second}, counted from 1)"
    )]
    DuplicateHeader {
        /// File as given.
        file: String,
        /// Line of the header.
        line: u64,
        /// The repeated name.
        column: String,
        /// 1-based position of its first occurrence.
        first: usize,
        /// 1-based position of its second occurrence.
        second: usize,
    },
    /// A data row has more or fewer fields than the header has columns.
    /// Rows are never dropped, so this is an error.
    #[error(
        "'{file}' line {line} (data row {}): {found} fields, but the header (line {header_line}) has {expected} columns (fields separated by {delimiter})",
        .row + 1
    )]
    FieldCount {
        /// File as given.
        file: String,
        /// Line of the bad row.
        line: u64,
        /// 0-based data row index.
        row: usize,
        /// Number of header columns.
        expected: usize,
        /// Number of fields found.
        found: usize,
        /// Line of the header.
        header_line: u64,
        /// The delimiter, in words.
        delimiter: String,
    },
    /// Text in a column that must be numeric.
    #[error(
        "cannot parse '{text}' as a number in column {column} at line {line} (data row {}) of '{file}'{hint}",
        .row + 1
    )]
    ParseNumber {
        /// File as given.
        file: String,
        /// Line of the cell.
        line: u64,
        /// 0-based data row index.
        row: usize,
        /// Column, quoted, with its canonical name when mapped, e.g. `'mag_1_uc' (mapped to 'mag')`.
        column: String,
        /// The cell text.
        text: String,
        /// Extra advice (starts with a space or is empty).
        hint: String,
    },
    /// A column that a command needs is not in the table.
    #[error(
        "'{file}': required column '{column}' is missing{suggestion}; columns present: {present}{hint}"
    )]
    MissingColumn {
        /// File (or `"<in-memory table>"`).
        file: String,
        /// The required (canonical) name.
        column: String,
        /// ` (did you mean 'NAME'?)` for a present column within a typo
        /// of it ([`crate::closest_name`]), else empty.
        suggestion: String,
        /// Comma-separated list of the columns present.
        present: String,
        /// Extra advice (starts with a space or is empty).
        hint: String,
    },
    /// A column is text where numbers are needed.
    #[error("'{file}': column '{column}' holds text, but numbers are needed{first}")]
    NotNumeric {
        /// File (or `"<in-memory table>"`).
        file: String,
        /// The column.
        column: String,
        /// Where the first value that is not a number stands, e.g.
        /// ` (data row 7, line 9: 'north')`; empty if unknown.
        first: String,
    },
    /// `--columns` maps a canonical name onto a column the file does not have.
    #[error(
        "'{file}': the column map sends '{canonical}' to column '{file_column}', which is not in the file; columns present: {present}"
    )]
    MappedColumnAbsent {
        /// File as given.
        file: String,
        /// Canonical name on the left of `=`.
        canonical: String,
        /// File column on the right of `=`.
        file_column: String,
        /// Comma-separated list of the columns present.
        present: String,
    },
    /// A column mapped (`--columns`, `--mag`, `--vector`) onto an input
    /// role it cannot play: a simulation truth column (estimators never
    /// read truth), or a column that keeps its own canonical role too
    /// (`--columns flux_x=flux_y` read one axis twice: "singular system").
    #[error("'{file}': column '{file_column}' cannot be read as `{canonical}`: {reason}")]
    MappedColumnRole {
        /// File as given.
        file: String,
        /// The role it was mapped onto.
        canonical: String,
        /// The file's column.
        file_column: String,
        /// Why not.
        reason: String,
    },
    /// An HDF5 file that cannot be read (not HDF5, damaged, a field of an
    /// unsupported type).
    #[error("'{file}'{}: {message}", dataset.as_ref().map(|d| format!(", dataset '{d}'")).unwrap_or_default())]
    Hdf5 {
        /// File as given.
        file: String,
        /// The dataset concerned, if one.
        dataset: Option<String>,
        /// What went wrong.
        message: String,
    },
    /// An HDF5 file that is not in the MagNav/SGL layout.
    #[error(
        "'{file}' is not a flight file in the MagNav/SGL HDF5 layout (one 1-D dataset per field, all of one length, at the root or in one group): {found}"
    )]
    Hdf5Layout {
        /// File as given.
        file: String,
        /// What the file holds instead.
        found: String,
    },
    /// A MATLAB MAT-file (v5, or v7.3 read as a MATLAB workspace) that
    /// cannot be read (damaged) or holds no flight.
    #[error("'{file}'{}: {message}", variable.as_ref().map(|v| format!(", variable '{v}'")).unwrap_or_default())]
    Mat {
        /// File as given.
        file: String,
        /// The variable concerned (`traj.lat` for a struct's field), if one.
        variable: Option<String>,
        /// What went wrong.
        message: String,
    },
    /// `--mag` / `--vector` names a sensor the file does not have.
    #[error(
        "'{file}': {option} {name}: no such column in the file; candidates present: {candidates}"
    )]
    SensorAbsent {
        /// File as given.
        file: String,
        /// `--mag` or `--vector`.
        option: &'static str,
        /// The sensor asked for.
        name: String,
        /// Comma-separated columns that look like sensors of that kind.
        candidates: String,
    },
    /// Several columns whose names differ only in case (`MAG` and `Mag`)
    /// would play the one name looked for (`mag`), none spelt exactly so.
    #[error(
        "'{file}': columns {matches} all read as '{name}' without regard to case; name the one meant: {choose}"
    )]
    AmbiguousColumn {
        /// File as given.
        file: String,
        /// The name looked for.
        name: String,
        /// The header's names that match it, quoted and comma-separated.
        matches: String,
        /// How to choose (`--columns mag=COLUMN`).
        choose: String,
    },
    /// A row selection (`--lines`, `--time-range`) that is malformed or
    /// selects nothing.
    #[error("{}{option}: {reason}", file_prefix(file))]
    Selection {
        /// File as given (empty while parsing the option).
        file: String,
        /// `--lines` or `--time-range`.
        option: &'static str,
        /// What is wrong, with what the file holds.
        reason: String,
    },
    /// Malformed `--columns` text.
    #[error("invalid column map '{text}': {reason}")]
    ColumnMap {
        /// The whole map text.
        text: String,
        /// What is wrong.
        reason: String,
    },
    /// A column added to a table has the wrong length.
    #[error("column '{column}' has {found} values, but the table has {expected} rows")]
    LengthMismatch {
        /// Column name.
        column: String,
        /// Rows of the table.
        expected: usize,
        /// Values given.
        found: usize,
    },
    /// A column added to a table already exists.
    #[error("column '{column}' already exists in the table")]
    ColumnExists {
        /// Column name.
        column: String,
    },
    /// Geosoft XYZ: no usable column-name header.
    #[error("'{file}' line {line}: {message}")]
    XyzHeader {
        /// File as given.
        file: String,
        /// Line of the first data line (or of the bad record).
        line: u64,
        /// What is wrong.
        message: String,
    },
    /// Time (or another column that must increase) steps back or repeats.
    #[error(
        "'{file}': column '{column}' must be strictly increasing, but data row {}{} has {} after data row {}{} has {}",
        .row_b + 1, fmt_line(*.line_b), shown(*.value_b), .row_a + 1, fmt_line(*.line_a), shown(*.value_a)
    )]
    NotIncreasing {
        /// File (or `"<in-memory table>"`).
        file: String,
        /// Column checked.
        column: String,
        /// 0-based index of the earlier row.
        row_a: usize,
        /// Its file line, when known.
        line_a: Option<u64>,
        /// Its value.
        value_a: f64,
        /// 0-based index of the later row.
        row_b: usize,
        /// Its file line, when known.
        line_b: Option<u64>,
        /// Its value.
        value_b: f64,
    },
    /// A missing value where one is not allowed (e.g. time).
    #[error("'{file}': column '{column}' has a missing value at data row {}{}", .row + 1, fmt_line(*.line))]
    MissingValue {
        /// File (or `"<in-memory table>"`).
        file: String,
        /// Column.
        column: String,
        /// 0-based row index.
        row: usize,
        /// File line, when known.
        line: Option<u64>,
    },
    /// Values in implausible units (e.g. tesla where nT is expected).
    #[error("'{file}': column '{column}': {message}")]
    Units {
        /// File (or `"<in-memory table>"`).
        file: String,
        /// Column.
        column: String,
        /// What looks wrong and how to fix it.
        message: String,
    },
    /// Writing an output file failed.
    #[error("cannot write '{file}': {source}")]
    Write {
        /// File as given.
        file: String,
        /// The operating system's reason.
        #[source]
        source: std::io::Error,
    },
    /// Columns given in memory (Python's `Flight.from_dict`) that do not
    /// form a table: a repeated name, lengths that differ.
    #[error("'<in-memory table>': column '{column}': {reason}")]
    Columns {
        /// The column concerned.
        column: String,
        /// What is wrong.
        reason: String,
    },
    /// A table's snapshot (a pickled Python `Flight`) that is not a
    /// table's ([`crate::FlightTable::from_snapshot`]).
    #[error("not a flight table's snapshot: {reason}")]
    Snapshot {
        /// What is wrong.
        reason: String,
    },
    /// A table the output's format cannot hold (a text cell with a space
    /// in Geosoft XYZ): bad input, found before anything is written.
    #[error("'{file}': column '{column}'{}: {reason}", row.map(|r| format!(", data row {}", r + 1)).unwrap_or_default())]
    CannotWrite {
        /// The output file as given.
        file: String,
        /// The column.
        column: String,
        /// 0-based data row of the table, when a cell is the cause.
        row: Option<usize>,
        /// Why, and what to do.
        reason: String,
    },
    /// A file format this build cannot read (or write as a flight table).
    #[error("'{file}': {reason}")]
    Unsupported {
        /// File as given.
        file: String,
        /// Why, and what to do.
        reason: String,
    },
}

impl IoError {
    /// Where in which file the error is, as far as it says: for the
    /// errors of a cell, a row or a column. Rows are the file's data rows
    /// (0-based), lines 1-based.
    pub fn location(&self) -> Location {
        use IoError::*;
        let mut at = Location::default();
        match self {
            Open { file, .. }
            | Empty { file }
            | NoData { file, .. }
            | Hdf5 { file, .. }
            | Hdf5Layout { file, .. }
            | Mat { file, .. }
            | SensorAbsent { file, .. }
            | AmbiguousColumn { file, .. }
            | Selection { file, .. }
            | Write { file, .. }
            | OutOfMemory { file, .. }
            | Unsupported { file, .. } => at.file = Some(file.clone()),
            Read { file, line, .. }
            | Binary { file, line, .. }
            | CrLineEnds { file, line }
            | UnclosedQuote { file, line }
            | WrongDelimiter { file, line, .. }
            | TooLarge { file, line, .. }
            | XyzHeader { file, line, .. } => {
                at.file = Some(file.clone());
                at.line = Some(*line);
            }
            DuplicateHeader {
                file, line, column, ..
            } => {
                at.file = Some(file.clone());
                at.line = Some(*line);
                at.column = Some(column.clone());
            }
            FieldCount {
                file, line, row, ..
            } => {
                at.file = Some(file.clone());
                at.line = Some(*line);
                at.row = Some(*row);
            }
            ParseNumber {
                file,
                line,
                row,
                column,
                ..
            } => {
                at.file = Some(file.clone());
                at.line = Some(*line);
                at.row = Some(*row);
                // The label of a message: `'name'` or `'name' (mapped to 'role')`.
                let name = column.strip_prefix('\'').and_then(|c| c.split('\'').next());
                at.column = Some(name.unwrap_or(column).to_string());
            }
            CannotWrite {
                file, column, row, ..
            } => {
                at.file = Some(file.clone());
                at.column = Some(column.clone());
                at.row = *row;
            }
            MissingColumn { file, column, .. }
            | NotNumeric { file, column, .. }
            | Units { file, column, .. } => {
                at.file = Some(file.clone());
                at.column = Some(column.clone());
            }
            MappedColumnAbsent {
                file, file_column, ..
            }
            | MappedColumnRole {
                file, file_column, ..
            } => {
                at.file = Some(file.clone());
                at.column = Some(file_column.clone());
            }
            NotIncreasing {
                file,
                column,
                row_b,
                line_b,
                ..
            } => {
                at.file = Some(file.clone());
                at.column = Some(column.clone());
                at.row = Some(*row_b);
                at.line = *line_b;
            }
            MissingValue {
                file,
                column,
                row,
                line,
            } => {
                at.file = Some(file.clone());
                at.column = Some(column.clone());
                at.row = Some(*row);
                at.line = *line;
            }
            Columns { column, .. } => {
                at.file = Some(crate::IN_MEMORY.to_string());
                at.column = Some(column.clone());
            }
            LengthMismatch { column, .. } | ColumnExists { column } => {
                at.column = Some(column.clone())
            }
            ColumnMap { .. } | Snapshot { .. } => {}
        }
        at
    }

    /// True when the error is caused by the user's input (a file, a column,
    /// a column map, a value): the command line exits with code 2 for these.
    /// False for failures of the machine (I/O errors while reading an opened
    /// file, write failures) and for programming errors of a caller
    /// (`LengthMismatch`, `ColumnExists`).
    pub fn is_bad_input(&self) -> bool {
        !matches!(
            self,
            IoError::Read { .. }
                | IoError::Write { .. }
                | IoError::LengthMismatch { .. }
                | IoError::ColumnExists { .. }
        )
    }
}

/// "'FILE': " or "" when there is no file yet.
fn file_prefix(file: &str) -> String {
    if file.is_empty() {
        String::new()
    } else {
        format!("'{file}': ")
    }
}

/// " (line N)" or "" when the line is unknown (in-memory tables).
fn fmt_line(line: Option<u64>) -> String {
    match line {
        Some(l) => format!(" (line {l})"),
        None => String::new(),
    }
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, IoError>;

/// Where an error is: file, 1-based line, 0-based data row of the file,
/// column; each when known ([`IoError::location`]).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Location {
    /// The file (as named in messages).
    pub file: Option<String>,
    /// 1-based line of a text file.
    pub line: Option<u64>,
    /// 0-based data row of the file (messages print it 1-based).
    pub row: Option<usize>,
    /// The column (or field) concerned.
    pub column: Option<String>,
}

impl Location {
    /// A location that names the file alone.
    pub fn in_file(file: impl Into<String>) -> Self {
        Location {
            file: Some(file.into()),
            ..Location::default()
        }
    }
}
