//! `aeromag-io`: flight-data tables in and out.
//!
//! Spec: `spec/data-formats.md` ("Flight data tables"). The crate reads CSV
//! and Geosoft XYZ files into a column-major [`FlightTable`], maps file
//! column names onto aeromag's canonical names ([`ColumnMap`], MagNav
//! preset), checks time and units ([`check_time`], [`check_units`]),
//! summarizes a table for `aeromag inspect` ([`summarize`]) and writes CSV
//! ([`write_csv`]).
//!
//! ```no_run
//! use aeromag_io::{ColumnMap, ReadOptions, read_table, check_time, check_units};
//! # fn main() -> Result<(), aeromag_io::IoError> {
//! let opts = ReadOptions { columns: ColumnMap::parse("mag=mag_1_uc")?, ..ReadOptions::default() };
//! let table = read_table("flight.csv".as_ref(), &opts)?;
//! check_time(&table)?;
//! for w in check_units(&table)? {
//!     eprintln!("warning: {w}");
//! }
//! let mag: &[f64] = table.require("mag")?; // nT; NaN = missing
//! # let _ = mag; Ok(()) }
//! ```
//!
//! Principles: rows are never dropped (missing values are `NaN`, counted per
//! column by reason); every error names the file, the line and the column
//! ([`IoError`]'s messages are the user-facing text); files are streamed
//! into per-column vectors without holding their text (see `builder.rs` for
//! the memory bound: about 1.02–1.1× the f64 data, at most ~2×).
//!
//! Units: files hold nT, m, s, degrees (spec README "Conventions"); this
//! crate does not convert anything except on request
//! ([`convert_tesla_to_nt`]).

mod builder;
mod cell;
pub mod columns;
mod csv_read;
mod csv_write;
mod error;
mod fields;
mod sniff;
mod summary;
mod table;
mod validate;
mod xyz;

use std::path::Path;

pub use builder::{MAX_COLUMNS, MAX_LINE_BYTES};
pub use columns::{
    CANONICAL_COLUMNS, ColumnMap, MAGNAV_PRESET, MAGNETIC_COLUMNS, MapOrigin, MappedColumn,
    is_canonical, is_truth_column,
};
pub use csv_read::read_csv;
pub use csv_write::{write_csv, write_csv_to};
pub use error::{IoError, Result};
pub use fields::{KnownField, known_field};
pub use summary::{ColumnKind, ColumnSummary, LineCount, Range, Summary, TimeSummary, summarize};
pub use table::{Column, ColumnData, FlightTable, IN_MEMORY, Missing};
pub use validate::{MEDIAN_SAMPLES, Warning, check_time, check_units, convert_tesla_to_nt};
pub use xyz::read_xyz;

/// File formats [`read_table`] can read.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Format {
    /// Decide from the extension and the content (see [`read_table`]).
    #[default]
    Auto,
    /// CSV (or whitespace-separated text), see [`read_csv`].
    Csv,
    /// Geosoft XYZ, see [`read_xyz`].
    Xyz,
}

/// How to read a table.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ReadOptions {
    /// User column map (`--columns`); empty by default.
    pub columns: ColumnMap,
    /// Apply the MagNav/SGL preset to canonical names that are neither in the
    /// file nor mapped (default `true`; see [`columns`]).
    pub magnav_preset: bool,
    /// CSV delimiter; `None` detects it from the header (see [`read_csv`]).
    pub delimiter: Option<u8>,
    /// File format; [`Format::Auto`] by default.
    pub format: Format,
}

impl Default for ReadOptions {
    fn default() -> Self {
        ReadOptions {
            columns: ColumnMap::new(),
            magnav_preset: true,
            delimiter: None,
            format: Format::Auto,
        }
    }
}

/// Reads a flight-data table.
///
/// With [`Format::Auto`]: extension `.xyz` → Geosoft XYZ; `.csv`, `.tsv` →
/// CSV; `.h5`/`.hdf5`/`.mat` → [`IoError::Unsupported`] (export to CSV
/// first); anything else (including `.txt`) → by content: XYZ if the first
/// non-blank line starts with `/`, else CSV.
pub fn read_table(path: &Path, opts: &ReadOptions) -> Result<FlightTable> {
    let format = match opts.format {
        Format::Auto => detect_format(path)?,
        f => f,
    };
    match format {
        Format::Xyz => read_xyz(path, opts),
        _ => read_csv(path, opts),
    }
}

fn detect_format(path: &Path) -> Result<Format> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    match ext.as_str() {
        "xyz" => Ok(Format::Xyz),
        "csv" | "tsv" => Ok(Format::Csv),
        "h5" | "hdf5" | "mat" => Err(IoError::Unsupported {
            file: path.display().to_string(),
            reason: format!(
                ".{ext} files are not supported by this build; export the fields to CSV (one column per field, names as in MagNav: tt, lat, lon, mag_1_uc, flux_a_x, …)"
            ),
        }),
        _ => {
            let prefix = sniff::read_prefix(path)?;
            let first = sniff::first_content_line(&prefix.bytes, |_| false);
            Ok(match first {
                Some((_, line, _)) if line.trim_ascii_start().starts_with(b"/") => Format::Xyz,
                _ => Format::Csv,
            })
        }
    }
}
