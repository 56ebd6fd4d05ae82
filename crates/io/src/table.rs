//! [`FlightTable`]: column-major flight data.
//!
//! A table is a list of equally long named columns. A column holds either
//! `f64` values (missing samples are `NaN`; the reason — blank cell, `NaN`
//! text, `*` dummy — is counted per column in [`Missing`]) or text (columns
//! that are not numbers, such as a flight id, which pass through unchanged).
//!
//! Canonical names (see [`columns`](crate::columns)) may be aliases of file
//! columns: [`FlightTable::column`] resolves the alias first, then the plain
//! column name. Rows are never dropped; readers keep every data row, and the
//! file line of each row is kept compactly so that messages can name it.

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::columns::MappedColumn;
use crate::derive::DerivedColumn;
use crate::error::{IoError, Result};
use crate::values::Values;

mod snapshot;
pub use snapshot::{ColumnSnapshot, ColumnSnapshotData, TableSnapshot};

/// Why samples of a numeric column are missing (`NaN`), counted per reason.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, serde::Deserialize)]
pub struct Missing {
    /// Empty (or whitespace-only) cells.
    pub blank: usize,
    /// Cells written as `NaN` (any case), and `NaN` values of in-memory columns.
    pub nan: usize,
    /// Dummy cells `*` (Geosoft XYZ convention, also accepted in CSV).
    pub dummy: usize,
}

impl Missing {
    /// Total number of missing samples.
    pub fn total(&self) -> usize {
        self.blank + self.nan + self.dummy
    }

    /// Counts one missing cell of kind `kind`.
    pub(crate) fn count(&mut self, kind: crate::cell::MissingKind) {
        use crate::cell::MissingKind;
        match kind {
            MissingKind::Blank => self.blank += 1,
            MissingKind::Nan => self.nan += 1,
            MissingKind::Dummy => self.dummy += 1,
        }
    }

    /// Adds the counts of `other` (rows appended).
    pub(crate) fn add(&mut self, other: &Missing) {
        self.blank += other.blank;
        self.nan += other.nan;
        self.dummy += other.dummy;
    }
}

/// The values of one column.
#[derive(Clone, Debug, PartialEq)]
pub enum ColumnData {
    /// Numbers; missing samples are `NaN`.
    Numeric {
        /// One value per row (owned, or shared memory: [`Values`]).
        values: Values,
        /// Missing samples by reason; `missing.total()` equals the number of `NaN`s.
        missing: Missing,
    },
    /// Text passed through unchanged (one string per row).
    Text(Vec<String>),
}

impl ColumnData {
    /// Numbers whose `NaN` values count as missing (`Missing::nan`), as a
    /// binary file or an array holds them.
    pub fn numeric(values: impl Into<Values>) -> Self {
        let values = values.into();
        let missing = Missing {
            nan: crate::parts::nan_count(&values),
            ..Missing::default()
        };
        ColumnData::Numeric { values, missing }
    }
}

/// A named column.
#[derive(Clone, Debug, PartialEq)]
pub struct Column {
    name: String,
    data: ColumnData,
    /// Every value was written as an integer in the file it was read from
    /// (`1003`, not `1003.0` or `1.003e3`): written back the same way.
    integer_text: bool,
}

impl Column {
    /// Column name as in the file (or as added).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// True when the column was read from a file where every value was
    /// written as an integer (`1003`); writers then keep that form. False
    /// for columns computed or changed in memory.
    pub fn integer_text(&self) -> bool {
        self.integer_text
    }

    /// The values.
    pub fn data(&self) -> &ColumnData {
        &self.data
    }

    /// Whether a binary file stores this column as integers: a column read
    /// as integers (`line` 1003, a flag) whose values are all whole and
    /// within ±2⁵³ (every whole `f64` up to it is an `i64` read back
    /// exactly).
    pub(crate) fn stores_integers(&self) -> bool {
        let whole =
            |v: &f64| v.is_finite() && v.fract() == 0.0 && v.abs() <= 9_007_199_254_740_992.0;
        self.integer_text && self.values().is_some_and(|v| v.iter().all(whole))
    }

    /// Numeric values, `None` for a text column.
    pub fn values(&self) -> Option<&[f64]> {
        match &self.data {
            ColumnData::Numeric { values, .. } => Some(values),
            ColumnData::Text(_) => None,
        }
    }

    /// Text values, `None` for a numeric column.
    pub fn text(&self) -> Option<&[String]> {
        match &self.data {
            ColumnData::Text(t) => Some(t),
            ColumnData::Numeric { .. } => None,
        }
    }

    /// Missing-sample counts (all zero for text columns).
    pub fn missing(&self) -> Missing {
        match &self.data {
            ColumnData::Numeric { missing, .. } => *missing,
            ColumnData::Text(_) => Missing::default(),
        }
    }

    fn len(&self) -> usize {
        match &self.data {
            ColumnData::Numeric { values, .. } => values.len(),
            ColumnData::Text(t) => t.len(),
        }
    }
}

/// Column-major table of flight data. See the module docs.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FlightTable {
    source: Option<PathBuf>,
    n_rows: usize,
    columns: Vec<Column>,
    aliases: Vec<MappedColumn>,
    /// Breakpoints `(row, line)`: from `row` on, row `r` is on file line
    /// `line + (r - row)`, until the next breakpoint. Empty for in-memory tables.
    row_lines: Vec<(usize, u64)>,
    /// Breakpoints `(row, data_row)` after a row selection: from `row` on,
    /// row `r` is the file's data row `data_row + (r - row)`. Empty when
    /// every row of the file is kept (row `r` is data row `r`).
    row_origin: Vec<(usize, usize)>,
    derived: Vec<DerivedColumn>,
    /// Every column of the file, in file order, read or not
    /// ([`crate::Fields::Only`]); empty for in-memory tables.
    file_columns: Vec<String>,
    /// What the file holds beside its fields (a MAT-file's scalars,
    /// matrices, text): [`FlightTable::not_read`].
    not_read: Vec<NotRead>,
}

/// Something a file holds that is not a field of the flight, so not read
/// into the table: a MATLAB MAT-file's scalar, matrix, text or vector of
/// another length ([`crate::read_mat5`]).
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct NotRead {
    /// Its name in the file (`TL_data.A_a` for a struct's field).
    pub name: String,
    /// What it is (`a 1000 × 18 matrix`, `a scalar`, `text (1 × 8)`).
    pub what: String,
}

/// Name used in messages for tables that were not read from a file.
pub const IN_MEMORY: &str = "<in-memory table>";

impl FlightTable {
    /// An empty in-memory table (no rows, no columns, no source file). The
    /// first added column sets the number of rows.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets the file the table is associated with (used in messages).
    pub fn set_source(&mut self, path: impl Into<PathBuf>) {
        self.source = Some(path.into());
    }

    /// The file the table was read from, if any.
    pub fn source(&self) -> Option<&Path> {
        self.source.as_deref()
    }

    /// The source file for messages, or `"<in-memory table>"`.
    pub fn file_label(&self) -> String {
        self.source
            .as_ref()
            .map_or_else(|| IN_MEMORY.to_string(), |p| p.display().to_string())
    }

    /// Number of rows.
    pub fn n_rows(&self) -> usize {
        self.n_rows
    }

    /// All columns in order.
    pub fn columns(&self) -> &[Column] {
        &self.columns
    }

    /// Column names in order (file names; aliases are not listed, see [`FlightTable::mapping`]).
    pub fn column_names(&self) -> Vec<&str> {
        self.columns.iter().map(|c| c.name.as_str()).collect()
    }

    /// The canonical aliases in effect (user map and MagNav preset).
    pub fn mapping(&self) -> &[MappedColumn] {
        &self.aliases
    }

    /// The column name in the table that `name` refers to: the file column of
    /// an alias, else `name` itself if such a column exists, else the one
    /// column that is `name` or its SGL counterpart without regard to case
    /// ([`crate::sensor_names`]: `mag_1_uc` finds `UNCOMPMAG1`, `cur_com_1`
    /// finds `CUR_COM1` and back), so that a model's or an option's column
    /// (`--extra`, `--reference-sensor`) finds the SGL field in either
    /// naming. Two columns that both match are no match (the caller's
    /// message lists the columns).
    pub fn resolve(&self, name: &str) -> Option<&str> {
        if let Some(m) = self.aliases.iter().find(|m| m.canonical == name) {
            return Some(m.file_column.as_str());
        }
        if let Some(c) = self.columns.iter().find(|c| c.name == name) {
            return Some(c.name.as_str());
        }
        if crate::columns::is_canonical(name) {
            return None;
        }
        crate::columns::sensor_names(name).iter().find_map(|n| {
            let mut hits = self
                .columns
                .iter()
                .filter(|c| c.name.eq_ignore_ascii_case(n));
            match (hits.next(), hits.next()) {
                (Some(c), None) => Some(c.name.as_str()),
                _ => None,
            }
        })
    }

    /// The column `name` (alias resolved), numeric or text.
    pub fn get(&self, name: &str) -> Option<&Column> {
        let target = self.resolve(name)?;
        self.columns.iter().find(|c| c.name == target)
    }

    /// Numeric values of column `name` (alias resolved); `None` if absent or text.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.get(name).and_then(Column::values)
    }

    /// The `line` column (alias resolved) as numbers, whatever its form: a
    /// numeric column as it is; a text column (`L1020`, `T901`, or number
    /// labels kept as text because two of them give one number, `1003.1`
    /// and `1003.10`: see the readers) numbered by label, each distinct
    /// label (trimmed, any case) 1, 2, … in order of first appearance, 0
    /// for no line (the number 0) and NaN for a missing label
    /// ([`crate::select::number_labels`]). What splits a flight at line changes and tells
    /// rows on a line; `None` without a `line` column.
    pub fn line_numbers(&self) -> Option<std::borrow::Cow<'_, [f64]>> {
        let column = self.get("line")?;
        if let Some(v) = column.values() {
            return Some(std::borrow::Cow::Borrowed(v));
        }
        let text = column.text()?;
        let (ids, _) = crate::select::number_labels(text.iter().map(String::as_str));
        Some(std::borrow::Cow::Owned(ids))
    }

    /// Text values of column `name` (alias resolved); `None` if absent or numeric.
    pub fn text_column(&self, name: &str) -> Option<&[String]> {
        self.get(name).and_then(Column::text)
    }

    /// Missing counts of column `name`; `None` if absent.
    pub fn missing(&self, name: &str) -> Option<Missing> {
        self.get(name).map(Column::missing)
    }

    /// Numeric values of a column a command cannot work without.
    ///
    /// Errors: [`IoError::MissingColumn`] naming the file, the column, the
    /// columns present and how to map it; [`IoError::NotNumeric`] for a text column.
    pub fn require(&self, name: &str) -> Result<&[f64]> {
        match self.get(name) {
            Some(c) => c.values().ok_or_else(|| IoError::NotNumeric {
                file: self.file_label(),
                column: name.to_string(),
                first: self.first_not_number(c),
            }),
            None => Err(IoError::MissingColumn {
                file: self.file_label(),
                column: name.to_string(),
                suggestion: crate::columns::closest_name(
                    name,
                    self.file_columns
                        .iter()
                        .map(String::as_str)
                        .chain(self.column_names()),
                )
                .map(|c| format!(" (did you mean '{c}'?)"))
                .unwrap_or_default(),
                present: self.present_columns(),
                // Only canonical and truth names can be mapped.
                hint: if crate::columns::is_canonical(name) || crate::columns::is_truth_column(name)
                {
                    format!(" (map a column onto it with --columns {name}=NAME)")
                } else {
                    String::new()
                },
            }),
        }
    }

    /// What a message about a missing column lists, comma-separated: the
    /// file's columns in file order, read or not
    /// ([`FlightTable::unread_columns`]), then the table's other columns
    /// (derived or added).
    pub fn present_columns(&self) -> String {
        let in_file = |c: &&str| self.file_columns.iter().any(|f| f == c);
        let added = self.column_names().into_iter().filter(|c| !in_file(c));
        self.file_columns
            .iter()
            .map(String::as_str)
            .chain(added)
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The file's columns that were not read, because the read asked for
    /// others only ([`crate::Fields::Only`]), in file order.
    pub fn unread_columns(&self) -> Vec<&str> {
        self.file_columns
            .iter()
            .map(String::as_str)
            .filter(|c| self.get(c).is_none())
            .collect()
    }

    /// What the file holds beside its fields, not read into the table
    /// ([`NotRead`]), in file order; empty for most formats, whose every
    /// field is a column.
    pub fn not_read(&self) -> &[NotRead] {
        &self.not_read
    }

    pub(crate) fn set_not_read(&mut self, not_read: Vec<NotRead>) {
        self.not_read = not_read;
    }

    /// Records every column of the file the table was read from, in file
    /// order (read or not).
    pub(crate) fn set_file_columns(&mut self, names: Vec<String>) {
        self.file_columns = names;
    }

    /// Adds a numeric column; `NaN` values count as missing (`Missing::nan`).
    /// Errors if the name exists or the length differs from [`FlightTable::n_rows`]
    /// (any length is accepted for the first column).
    pub fn add_column(&mut self, name: &str, values: Vec<f64>) -> Result<()> {
        self.push_column(Column {
            name: name.to_string(),
            data: ColumnData::numeric(values),
            integer_text: false,
        })
    }

    /// Adds a numeric column of whole numbers (flags, counts), written
    /// without `.0` (`0`, `1`; non-whole values keep their decimals);
    /// errors as [`FlightTable::add_column`].
    pub fn add_integer_column(&mut self, name: &str, values: Vec<f64>) -> Result<()> {
        self.add_column(name, values)?;
        if let Some(c) = self.columns.last_mut() {
            c.integer_text = true;
        }
        Ok(())
    }

    /// Adds a text column (errors as [`FlightTable::add_column`]).
    pub fn add_text_column(&mut self, name: &str, values: Vec<String>) -> Result<()> {
        self.push_column(Column {
            name: name.to_string(),
            data: ColumnData::Text(values),
            integer_text: false,
        })
    }

    /// Replaces the values of column `name` (no alias resolution) or adds it
    /// when absent. Errors only on a length mismatch.
    pub fn set_column(&mut self, name: &str, values: Vec<f64>) -> Result<()> {
        let values = Values::Owned(values);
        match self.columns.iter().position(|c| c.name == name) {
            Some(i) => {
                self.check_len(name, values.len())?;
                self.columns[i].data = ColumnData::numeric(values);
                self.columns[i].integer_text = false;
                Ok(())
            }
            None => self.add_column(name, values.into_vec()),
        }
    }

    /// 1-based file line of data row `row` (0-based); `None` for in-memory
    /// tables or out-of-range rows.
    pub fn line_of_row(&self, row: usize) -> Option<u64> {
        if row >= self.n_rows {
            return None;
        }
        let k = self.row_lines.partition_point(|(r, _)| *r <= row);
        let (r0, l0) = *self.row_lines.get(k.checked_sub(1)?)?;
        Some(l0 + (row - r0) as u64)
    }

    /// The file's data row (0-based) of table row `row`: the same number
    /// unless a row selection ([`FlightTable::retain_rows`], `--lines`,
    /// `--time-range`) dropped rows before it. Messages print it 1-based as
    /// "data row N", so that it agrees with the file line whatever rows
    /// were kept.
    pub fn file_row(&self, row: usize) -> usize {
        let k = self.row_origin.partition_point(|(r, _)| *r <= row);
        match k.checked_sub(1).and_then(|k| self.row_origin.get(k)) {
            Some(&(r0, d0)) => d0 + (row - r0),
            None => row,
        }
    }

    /// ` (data row R, line L: 'value')` for the first cell of a text column
    /// that is neither a number nor a missing marker (the reader's rule),
    /// data rows counted from 1; empty if there is none.
    fn first_not_number(&self, c: &Column) -> String {
        let Some(text) = c.text() else {
            return String::new();
        };
        match text
            .iter()
            .position(|v| crate::cell::parse_cell(v.as_bytes()).is_err())
        {
            Some(k) => {
                let line = self
                    .line_of_row(k)
                    .map_or(String::new(), |l| format!(", line {l}"));
                format!(" (data row {}{line}: '{}')", self.file_row(k) + 1, text[k])
            }
            None => String::new(),
        }
    }

    fn check_len(&self, name: &str, len: usize) -> Result<()> {
        if !self.columns.is_empty() && len != self.n_rows {
            return Err(IoError::LengthMismatch {
                column: name.to_string(),
                expected: self.n_rows,
                found: len,
            });
        }
        Ok(())
    }

    fn push_column(&mut self, column: Column) -> Result<()> {
        if self.columns.iter().any(|c| c.name == column.name) {
            return Err(IoError::ColumnExists {
                column: column.name,
            });
        }
        self.check_len(&column.name, column.len())?;
        self.n_rows = column.len();
        self.columns.push(column);
        Ok(())
    }

    /// A table of the fields read from a binary file (HDF5, MAT) whose
    /// fields are `header`: the aliases of fields not read are dropped.
    pub(crate) fn from_fields(
        source: &Path,
        n_rows: usize,
        columns: Vec<(String, ColumnData, bool)>,
        aliases: Vec<MappedColumn>,
        header: Vec<String>,
    ) -> Self {
        let aliases = aliases
            .into_iter()
            .filter(|m| columns.iter().any(|c| c.0 == m.file_column))
            .collect();
        let mut table =
            Self::from_parts(source.to_path_buf(), n_rows, columns, aliases, Vec::new());
        table.set_file_columns(header);
        table
    }

    /// Assembles a table read from a file (used by the readers).
    pub(crate) fn from_parts(
        source: PathBuf,
        n_rows: usize,
        columns: Vec<(String, ColumnData, bool)>,
        aliases: Vec<MappedColumn>,
        row_lines: Vec<(usize, u64)>,
    ) -> Self {
        FlightTable {
            source: Some(source),
            n_rows,
            columns: columns
                .into_iter()
                .map(|(name, data, integer_text)| Column {
                    name,
                    data,
                    integer_text,
                })
                .collect(),
            aliases,
            row_lines,
            row_origin: Vec::new(),
            derived: Vec::new(),
            file_columns: Vec::new(),
            not_read: Vec::new(),
        }
    }

    /// Makes a table assembled by [`FlightTable::from_parts`] an in-memory
    /// one (no source file).
    pub(crate) fn forget_source(&mut self) {
        self.source = None;
    }

    /// Keeps the rows `i` with `keep[i]` (in order), with their file lines
    /// and data-row numbers ([`FlightTable::file_row`]).
    /// Missing counts are recounted; their reasons are kept when a column
    /// had only one kind of missing value, else counted as `nan`.
    ///
    /// # Panics
    /// If `keep.len()` differs from [`FlightTable::n_rows`] (a programming error).
    pub fn retain_rows(&mut self, keep: &[bool]) {
        assert_eq!(keep.len(), self.n_rows, "retain_rows: mask length");
        fn filter<T>(v: &mut Vec<T>, keep: &[bool]) {
            let mut k = keep.iter();
            v.retain(|_| *k.next().unwrap_or(&false));
        }
        for c in &mut self.columns {
            match &mut c.data {
                ColumnData::Numeric { values, missing } => {
                    filter(values.to_mut(), keep);
                    let n = crate::parts::nan_count(values);
                    *missing = match (missing.blank, missing.nan, missing.dummy) {
                        (_, 0, 0) => Missing {
                            blank: n,
                            ..Missing::default()
                        },
                        (0, 0, _) => Missing {
                            dummy: n,
                            ..Missing::default()
                        },
                        _ => Missing {
                            nan: n,
                            ..Missing::default()
                        },
                    };
                }
                ColumnData::Text(t) => filter(t, keep),
            }
        }
        let mut row_lines: Vec<(usize, u64)> = Vec::new();
        if !self.row_lines.is_empty() {
            let mut prev: Option<u64> = None;
            let kept = keep.iter().enumerate().filter(|(_, k)| **k);
            for (j, (i, _)) in kept.enumerate() {
                let line = self.line_of_row(i);
                if let Some(l) = line
                    && prev.is_none_or(|p| p + 1 != l)
                {
                    row_lines.push((j, l));
                }
                prev = line;
            }
        }
        self.row_lines = row_lines;
        let mut row_origin: Vec<(usize, usize)> = Vec::new();
        let mut prev: Option<usize> = None;
        let kept = keep.iter().enumerate().filter(|(_, k)| **k);
        for (j, (i, _)) in kept.enumerate() {
            let d = self.file_row(i);
            if prev.is_none_or(|p| p + 1 != d) {
                row_origin.push((j, d));
            }
            prev = Some(d);
        }
        self.row_origin = row_origin;
        self.n_rows = keep.iter().filter(|k| **k).count();
    }

    /// Columns computed from file columns in another unit ([`crate::derive`]);
    /// writers leave them out.
    pub fn derived(&self) -> &[DerivedColumn] {
        &self.derived
    }

    /// Adds a derived column (see [`FlightTable::derived`]).
    pub(crate) fn add_derived(&mut self, d: DerivedColumn, values: Vec<f64>) -> Result<()> {
        self.add_column(&d.canonical, values)?;
        self.derived.push(d);
        Ok(())
    }

    /// Whether column `name` (no alias resolution) is derived.
    pub fn is_derived(&self, name: &str) -> bool {
        self.derived.iter().any(|d| d.canonical == name)
    }

    /// Multiplies the numeric column `name` (alias resolved) by `factor` in place.
    pub(crate) fn scale_column(&mut self, name: &str, factor: f64) -> bool {
        let Some(target) = self.resolve(name).map(str::to_string) else {
            return false;
        };
        match self.columns.iter_mut().find(|c| c.name == target) {
            Some(Column {
                data: ColumnData::Numeric { values, .. },
                integer_text,
                ..
            }) => {
                values.to_mut().iter_mut().for_each(|v| *v *= factor);
                *integer_text = false;
                true
            }
            _ => false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::columns::MapOrigin;

    #[test]
    fn text_line_labels_are_numbered_in_order_of_appearance() {
        let mut t = FlightTable::new();
        let labels = [
            "L2", "L2", "l2", "", "0", "T9", "NaN", "*", "1003.10", "1003.1", "T9",
        ];
        t.add_text_column("line", labels.iter().map(|s| s.to_string()).collect())
            .unwrap();
        let n = t.line_numbers().unwrap();
        let shown: Vec<String> = n.iter().map(|v| v.to_string()).collect();
        assert_eq!(
            shown,
            ["1", "1", "1", "NaN", "0", "2", "NaN", "NaN", "3", "4", "2"]
        );
        let mut numeric = FlightTable::new();
        numeric.add_column("line", vec![1003.1, 0.0]).unwrap();
        assert_eq!(&*numeric.line_numbers().unwrap(), &[1003.1, 0.0]);
        assert!(FlightTable::new().line_numbers().is_none());
    }

    #[test]
    fn add_and_access_columns() {
        let mut t = FlightTable::new();
        t.add_column("time", vec![0.0, 0.1, 0.2]).unwrap();
        t.add_column("mag", vec![1.0, f64::NAN, 3.0]).unwrap();
        t.add_text_column("id", vec!["a".into(), "b".into(), "c".into()])
            .unwrap();
        assert_eq!(t.n_rows(), 3);
        assert_eq!(t.column_names(), vec!["time", "mag", "id"]);
        assert_eq!(t.missing("mag").unwrap().total(), 1);
        assert!(t.column("id").is_none());
        assert_eq!(t.text_column("id").unwrap()[2], "c");
        assert!(matches!(
            t.add_column("x", vec![1.0]),
            Err(IoError::LengthMismatch {
                expected: 3,
                found: 1,
                ..
            })
        ));
        assert!(matches!(
            t.add_column("mag", vec![0.0; 3]),
            Err(IoError::ColumnExists { .. })
        ));
        t.set_column("mag", vec![f64::NAN; 3]).unwrap();
        assert_eq!(t.missing("mag").unwrap().nan, 3);
        assert!(matches!(t.require("id"), Err(IoError::NotNumeric { .. })));
        // The message points at the first value that is not a number;
        // missing markers do not count.
        t.add_text_column("az", vec!["".into(), "12.5".into(), "north".into()])
            .unwrap();
        let e = t.require("az").unwrap_err().to_string();
        assert!(
            e.contains("column 'az'") && e.contains("data row 3") && e.contains("'north'"),
            "{e}"
        );
        assert_eq!(t.line_of_row(0), None);
    }

    #[test]
    fn require_names_file_column_and_present_columns() {
        let mut t = FlightTable::new();
        t.set_source("/data/f.csv");
        t.add_column("time", vec![0.0]).unwrap();
        let e = t.require("mag").unwrap_err().to_string();
        assert!(
            e.contains("/data/f.csv") && e.contains("'mag'") && e.contains("columns present: time"),
            "{e}"
        );
        assert!(e.contains("--columns mag="), "{e}");
    }

    #[test]
    fn aliases_and_row_lines() {
        let cols = vec![
            (
                "tt".to_string(),
                ColumnData::Numeric {
                    values: vec![1.0, 2.0, 3.0, 4.0].into(),
                    missing: Missing::default(),
                },
                false,
            ),
            (
                "mag".to_string(),
                ColumnData::Numeric {
                    values: vec![9.0; 4].into(),
                    missing: Missing::default(),
                },
                false,
            ),
        ];
        let aliases = vec![MappedColumn {
            canonical: "time".into(),
            file_column: "tt".into(),
            origin: MapOrigin::User,
        }];
        // rows 0,1 on lines 3,4; a comment on line 5; rows 2,3 on lines 6,7.
        let t = FlightTable::from_parts("f.csv".into(), 4, cols, aliases, vec![(0, 3), (2, 6)]);
        assert_eq!(t.column("time").unwrap(), &[1.0, 2.0, 3.0, 4.0]);
        assert_eq!(t.resolve("time"), Some("tt"));
        assert_eq!(t.resolve("mag"), Some("mag"));
        let lines: Vec<_> = (0..5).map(|r| t.line_of_row(r)).collect();
        assert_eq!(lines, vec![Some(3), Some(4), Some(6), Some(7), None]);
    }
}
