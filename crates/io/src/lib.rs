//! `aeromag-io`: flight-data tables in and out.
//!
//! Spec: `spec/data-formats.md` ("Flight data tables", "Real survey files").
//! The crate reads CSV, Geosoft XYZ and HDF5 files (MagNav/SGL layout,
//! [`read_hdf5`], pure Rust) into a column-major [`FlightTable`], maps file
//! column names onto aeromag's canonical names ([`ColumnMap`], MagNav
//! preset), checks time and units ([`check_time`], [`check_units`]), finds
//! positions off the track ([`position_glitches`]), summarizes a table for
//! `aeromag inspect` ([`summarize`]) and writes CSV ([`write_csv`]),
//! Geosoft XYZ ([`write_xyz`]), HDF5 ([`write_hdf5`]; [`write_table`]
//! chooses by the file name) and other outputs atomically ([`atomic`]).
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

pub mod atomic;
mod builder;
mod cell;
pub mod columns;
mod csv_clean;
mod csv_read;
mod csv_write;
pub mod derive;
mod error;
mod fields;
mod hdf5;
mod hdf5_write;
mod label_texts;
mod mat5;
mod mat5_write;
mod mat73;
mod matlab;
mod number_text;
mod ordered;
mod parts;
mod position_glitches;
mod read_ahead;
pub mod select;
mod sniff;
mod summary;
mod table;
mod table_file;
mod validate;
mod values;
mod wanted;
mod xyz;
mod xyz_write;

use std::path::Path;

pub use builder::{MAX_COLUMNS, MAX_LINE_BYTES};
pub use columns::{
    CANONICAL_COLUMNS, ColumnMap, MAGNAV_PRESET, MAGNETIC_COLUMNS, MapOrigin, MappedColumn,
    RESULT_COLUMNS, Sensors, closest_name, is_canonical, is_truth_column, magnav_name,
    sensor_names,
};
pub use csv_read::read_csv;
pub use csv_write::{write_csv, write_csv_to};
pub use derive::{Conversion, DerivedColumn, derive_columns};
pub use error::{IoError, Location, Result};
pub use fields::{KnownField, known_field};
pub use hdf5::{MAX_READ_BYTES, read_hdf5};
pub use hdf5_write::{check_hdf5, write_hdf5, write_hdf5_to};
pub use mat5::{MAX_DEPTH as MAT_MAX_DEPTH, read_mat5};
pub use mat5_write::{check_mat5, write_mat5, write_mat5_to};
pub use number_text::NumberText;
pub use parts::nan_count;
pub use position_glitches::{
    MAX_GROUND_SPEED_M_S, MIN_JUMP_M, position_glitches, projected_position_glitches,
};
pub use select::{RowSelection, label_number};
pub use summary::{ColumnKind, ColumnSummary, LineCount, Range, Summary, TimeSummary, summarize};
pub use table::{
    Column, ColumnData, ColumnSnapshot, ColumnSnapshotData, FlightTable, IN_MEMORY, Missing,
    NotRead, TableSnapshot,
};
pub use table_file::{TableFormat, write_table};
pub use validate::{
    EARTH_FIELD_NT, FINITE_COLUMNS, MAX_ALT_M, MAX_FIELD_NT, MAX_TIME_S, MEDIAN_SAMPLES,
    MIN_READING_NT, MIN_TIME_STEP_FRACTION, VECTOR_SCALAR_TOLERANCE, Warning, WarningKind,
    check_sensor_units, check_time, check_units, column_spread, convert_tesla_to_nt,
    median_in_place, reads_as_microtesla, sampled_median, step_distance_m,
};
pub use values::{SharedBuffer, Values};
pub use xyz::read_xyz;
pub use xyz_write::{check_xyz, write_xyz, write_xyz_to};

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
    /// HDF5 in the MagNav/SGL layout, see [`read_hdf5`].
    Hdf5,
    /// A MATLAB v5 MAT-file, see [`read_mat5`].
    Mat,
}

/// Which fields to read. Every format keeps the same fields of a file: an
/// HDF5 file reads only the datasets asked for; a CSV, whitespace or XYZ
/// file is still read to its end (every row delimited, counted and checked
/// for its number of fields), but only the fields asked for are parsed,
/// checked and stored. The others are listed by
/// [`FlightTable::unread_columns`] and named in the message for a missing
/// column. A command that names what it uses reads a wide text file in
/// less time and memory: `calibrate` of a 2.17·10⁶-row, 49-column CSV
/// (1.9 GB) took 3.84 s and 929 MB reading every field, 1.82–2.24 s and
/// 404 MB reading those it uses (`/usr/bin/time`; the same model file).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum Fields {
    /// Every field (the commands that write the input's columns back).
    #[default]
    All,
    /// The fields with these names: file names, canonical names (through
    /// the column map, the preset or a derivation), compared without
    /// regard to case; a name ending in `*` matches by prefix (`true_*`),
    /// one starting with `*` by suffix (`*_level`). The `line` and `time`
    /// fields a row selection needs are added.
    Only(Vec<String>),
}

impl Fields {
    /// Every canonical column, `line_type`, and `extra` names.
    pub fn canonical_and(extra: &[&str]) -> Fields {
        let mut names: Vec<String> = CANONICAL_COLUMNS.iter().map(|s| s.to_string()).collect();
        names.push("line_type".into());
        names.extend(extra.iter().map(|s| s.to_string()));
        Fields::Only(names)
    }
}

/// How to read a table.
#[derive(Clone, Debug, PartialEq)]
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
    /// The scalar and vector magnetometers to use (`--mag`, `--vector`);
    /// by default the map and the preset choose.
    pub sensors: Sensors,
    /// The rows to keep (`--lines`, `--time-range`); all by default.
    pub rows: RowSelection,
    /// The fields to read; all by default.
    pub fields: Fields,
}

impl Default for ReadOptions {
    fn default() -> Self {
        ReadOptions {
            columns: ColumnMap::new(),
            magnav_preset: true,
            delimiter: None,
            format: Format::Auto,
            sensors: Sensors::default(),
            rows: RowSelection::default(),
            fields: Fields::All,
        }
    }
}

/// Reads a flight-data table.
///
/// With [`Format::Auto`]: extension `.xyz` → Geosoft XYZ; `.csv`, `.tsv` →
/// CSV; `.h5`, `.hdf5`, `.he5` → HDF5; anything else (including `.txt` and
/// `.mat`) → by content: HDF5 if the file has the HDF5 signature (MATLAB
/// v7.3 files do, read as MATLAB workspaces), a MATLAB v5 MAT-file by its
/// header, XYZ if the first
/// non-blank line starts with `/`, else CSV.
///
/// Then the canonical columns in another unit are derived
/// ([`derive_columns`]: `lat` from `ins_lat` in radians, …) and the rows of
/// [`ReadOptions::rows`] kept ([`RowSelection::apply`]).
pub fn read_table(path: &Path, opts: &ReadOptions) -> Result<FlightTable> {
    let format = match opts.format {
        Format::Auto => detect_format(path)?,
        f => f,
    };
    let mut table = match format {
        Format::Xyz => read_xyz(path, opts),
        Format::Hdf5 => read_hdf5(path, opts),
        Format::Mat => read_mat5(path, opts),
        Format::Csv | Format::Auto => read_csv(path, opts),
    }?;
    opts.rows.apply(&mut table)?;
    derive_columns(&mut table)?;
    Ok(table)
}

/// A table from columns held in memory (Python's `Flight.from_dict`),
/// named as in files: the column map, the chosen sensors, the MagNav
/// preset, the row selection and the derived columns of `opts` apply as
/// they do to a file read by [`read_table`] (`opts.fields` and the format
/// options do not). Numeric columns count their NaN as missing.
///
/// Errors: no column or no row, a repeated name or columns of different
/// lengths ([`IoError::Columns`]), and the
/// mapping and selection errors of a file.
pub fn table_from_columns(
    columns: Vec<(String, ColumnData)>,
    opts: &ReadOptions,
) -> Result<FlightTable> {
    let len = |d: &ColumnData| match d {
        ColumnData::Numeric { values, .. } => values.len(),
        ColumnData::Text(t) => t.len(),
    };
    let Some(n_rows) = columns.first().map(|c| len(&c.1)) else {
        return Err(IoError::Empty {
            file: IN_MEMORY.into(),
        });
    };
    let mut header: Vec<String> = Vec::with_capacity(columns.len());
    for (name, data) in &columns {
        if header.iter().any(|h| h == name) {
            return Err(IoError::Columns {
                column: name.clone(),
                reason: "given twice".into(),
            });
        }
        if len(data) != n_rows {
            return Err(IoError::Columns {
                column: name.clone(),
                reason: format!(
                    "{} values, but '{}' has {n_rows}: columns must have one length",
                    len(data),
                    header[0]
                ),
            });
        }
        header.push(name.clone());
    }
    if n_rows == 0 {
        return Err(IoError::NoData {
            file: IN_MEMORY.into(),
            header_line: 0,
        });
    }
    let aliases = columns::resolve(
        IN_MEMORY,
        &header,
        &opts.columns,
        &opts.sensors,
        opts.magnav_preset,
    )?;
    let parts = columns
        .into_iter()
        .map(|(name, data)| (name, data, false))
        .collect();
    let mut table = FlightTable::from_parts(
        std::path::PathBuf::new(),
        n_rows,
        parts,
        aliases,
        Vec::new(),
    );
    table.forget_source();
    opts.rows.apply(&mut table)?;
    derive_columns(&mut table)?;
    Ok(table)
}

/// The kind of grid file whose first bytes are `head` (TIFF, netCDF
/// classic, Surfer) or whose extension is `ext` (`gxf`, and `grd` for
/// Geosoft's); `None` for anything else.
fn grid_kind(head: &[u8], ext: &str) -> Option<&'static str> {
    if ext == "gxf" {
        return Some("GXF");
    }
    [
        (&b"II*\0"[..], "TIFF"),
        (b"MM\0*", "TIFF"),
        (b"CDF", "netCDF"),
        (b"DSAA", "Surfer"),
        (b"DSBB", "Surfer"),
        (b"DSRB", "Surfer"),
    ]
    .into_iter()
    .find(|(magic, _)| head.starts_with(magic))
    .map(|(_, kind)| kind)
    // Geosoft's binary grid has no magic; a `.grd` is a grid format's.
    .or((ext == "grd").then_some("Geosoft"))
}

fn detect_format(path: &Path) -> Result<Format> {
    let ext = aeromag_core::file_name::extension(path);
    match ext.as_str() {
        "xyz" => return Ok(Format::Xyz),
        "csv" | "tsv" => return Ok(Format::Csv),
        "h5" | "hdf5" | "he5" => return Ok(Format::Hdf5),
        _ if hdf5::is_hdf5(path) => return Ok(Format::Hdf5),
        _ => {}
    }
    // One read of the first bytes tells the binary files that are not
    // flight tables.
    let head = aeromag_core::file_name::first_bytes(path, mat5::SIGNATURE.len());
    if let Some(kind) = grid_kind(&head, &ext) {
        return Err(IoError::Unsupported {
            file: path.display().to_string(),
            reason: format!(
                "a grid file ({kind}), not a flight table: `aeromag inspect` and `aeromag derive` \
                 read grids, and aeromag.read_grid in Python"
            ),
        });
    }
    if mat5::is_mat5(&head) {
        return Ok(Format::Mat);
    }
    let prefix = sniff::read_prefix(path)?;
    let first = sniff::first_content_line(&prefix.bytes, |_| false);
    Ok(match first {
        Some((_, line, _)) if line.trim_ascii_start().starts_with(b"/") => Format::Xyz,
        _ => Format::Csv,
    })
}
