//! HDF5 flight files in the MagNav/SGL layout, read without a C library.
//!
//! **Layout** (spec `data-formats.md`, "Real survey files"; MagNav.jl's
//! `get_XYZ20`): one 1-D dataset per field, all of the same length, at the
//! file's root or inside one group (`/data`, `/flight`, …; used when the
//! root holds no dataset and exactly one group). Datasets may be float64,
//! float32 or integers (read exactly as `f64`; integer fields are written
//! back as integers), or strings, fixed or variable length (a text column,
//! such as line labels `L1020`), contiguous or chunked with gzip/shuffle as h5py writes
//! them. Scalar and empty datasets (0-D, or of length 0 or 1 beside longer
//! ones, e.g. a sample count) hold no rows and are skipped; any other shape
//! is not this layout.
//!
//! **MATLAB v7.3 MAT-files** (HDF5 after a 512-byte user block beginning
//! `MATLAB 7.3 MAT-file`) are read as MATLAB workspaces instead
//! ([`crate::mat73`]): their vectors at the root, or the fields of a
//! struct, as a v5 MAT-file's ([`crate::read_mat5`]).
//!
//! **Only the fields a command needs are read** ([`Fields::Only`](crate::Fields::Only)): the
//! datasets' headers are parsed when the file is opened, the data of a
//! dataset only when it is read, so 4 fields of a 100-field flight cost 4
//! fields.
//!
//! **Reader.** [`hdf5-reader`](https://crates.io/crates/hdf5-reader) 0.12
//! (pure Rust, read-only), chosen after reading 101 datasets written by
//! h5py (`tools/reference/sgl_h5.py`: root and group layouts, f8/f4/i8/i4/
//! i2/u1, contiguous, chunked, gzip+shuffle, `libver="latest"`, empty) with
//! five pure-Rust readers: it was the only one to read all of them
//! bit-exactly (`hdf5-pure` failed the `libver="latest"` file, `rustyhdf5`
//! returned the first chunked dataset's data for the others without an
//! error), and on 30 hostile files and 400 mutants it returned errors
//! without a panic or a huge allocation. Its chunk cache is turned off
//! (whole-dataset reads do not need it; with it, reading every field of a
//! gzip file took twice the memory). Reads are still wrapped in
//! `catch_unwind`, and one read is capped at [`MAX_READ_BYTES`].
//!
//! A dataset's `units` attribute, where present, must agree with the unit
//! the layout gives that field (`ins_lat` rad, `mag_1_uc` nT, …): a
//! contradiction is an error, never a silent mis-conversion.
//!
//! Rows have no file line: messages name the data row (the dataset index + 1).

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;

use hdf5_reader::{Dataset, Datatype, H5Type, Hdf5File, OpenOptions, VarLenKind, group::Group};

use crate::ReadOptions;
use crate::error::{IoError, Result};
use crate::table::{ColumnData, FlightTable};
use crate::wanted::mapped_fields;

/// Largest single read, bytes (4 GiB, 5·10⁸ float64 values): far above any flight's field, far
/// below what a forged header could claim; also the most the fields a command asks for may take
/// together.
pub const MAX_READ_BYTES: usize = 4 << 30;

pub use aeromag_core::file_name::{HDF5_SIGNATURE as SIGNATURE, is_hdf5};

/// Reads an HDF5 flight file in the MagNav/SGL layout (module docs): the
/// fields [`ReadOptions::fields`] asks for, mapped like a CSV header.
///
/// Errors: [`IoError::Hdf5`] for a file that is not HDF5 or is damaged,
/// [`IoError::Hdf5Layout`] for one that is not in this layout.
pub fn read_hdf5(path: &Path, opts: &ReadOptions) -> Result<FlightTable> {
    let file = path.display().to_string();
    match catch_unwind(AssertUnwindSafe(|| read(path, &file, opts))) {
        Ok(r) => r,
        Err(_) => Err(IoError::Hdf5 {
            file,
            dataset: None,
            message: "the HDF5 reader failed on this file (damaged or unsupported)".into(),
        }),
    }
}

fn read(path: &Path, file: &str, opts: &ReadOptions) -> Result<FlightTable> {
    let h5err = |dataset: Option<&str>, e: hdf5_reader::error::Error| IoError::Hdf5 {
        file: file.to_string(),
        dataset: dataset.map(str::to_string),
        message: e.to_string(),
    };
    if let Err(e) = std::fs::metadata(path) {
        return Err(IoError::Open {
            file: file.to_string(),
            source: e,
        });
    }
    let h5 = Hdf5File::open_with_options(
        path,
        OpenOptions::default()
            .with_chunk_cache_bytes(0)
            .with_max_read_bytes(MAX_READ_BYTES),
    )
    .map_err(|e| h5err(None, e))?;
    let root = h5.root_group().map_err(|e| h5err(None, e))?;
    if aeromag_core::file_name::first_bytes(path, crate::mat73::SIGNATURE.len())
        .starts_with(crate::mat73::SIGNATURE)
    {
        return read_mat73(path, file, &root, opts);
    }
    let (groups, datasets) = root.member_names().map_err(|e| h5err(None, e))?;
    let (group, prefix): (Group, String) = if !datasets.is_empty() {
        (root, "/".into())
    } else if groups.len() == 1 {
        let g = root.group(&groups[0]).map_err(|e| h5err(None, e))?;
        (g, format!("/{}/", groups[0]))
    } else {
        return Err(IoError::Hdf5Layout {
            file: file.to_string(),
            found: if groups.is_empty() {
                "no dataset and no group".into()
            } else {
                format!(
                    "no dataset at the root and {} groups ({})",
                    groups.len(),
                    groups.join(", ")
                )
            },
        });
    };
    let (_, names) = group.member_names().map_err(|e| h5err(None, e))?;
    if ["map", "xx", "yy"]
        .iter()
        .all(|n| names.iter().any(|m| m == n))
    {
        return Err(IoError::Hdf5 {
            file: file.to_string(),
            dataset: None,
            message: format!("is {}", crate::matlab::MAGNAV_MAP),
        });
    }
    // Shapes first (headers only): every field 1-D and of one length.
    let mut fields: Vec<(String, Dataset, u64)> = Vec::new();
    for name in names {
        let ds = group.dataset(&name).map_err(|e| h5err(Some(&name), e))?;
        let shape = ds.shape().to_vec();
        match shape[..] {
            [] => {} // a scalar: not a field of the flight
            [n] => fields.push((name, ds, n)),
            _ => {
                return Err(IoError::Hdf5Layout {
                    file: file.to_string(),
                    found: format!("dataset '{prefix}{name}' has shape {shape:?}"),
                });
            }
        }
    }
    let n_rows = fields.iter().map(|f| f.2).max().unwrap_or(0);
    if n_rows > 1 {
        // Length 0 or 1 beside longer fields: an empty or a scalar field,
        // no rows of the flight.
        fields.retain(|(_, _, n)| *n > 1);
    }
    if let Some((name, _, n)) = fields.iter().find(|f| f.2 != n_rows) {
        let (longest, _, _) = fields.iter().find(|f| f.2 == n_rows).expect("the maximum");
        return Err(IoError::Hdf5Layout {
            file: file.to_string(),
            found: format!(
                "dataset '{prefix}{name}' has {n} values, '{prefix}{longest}' {n_rows} (fields must have one length)"
            ),
        });
    }
    if fields.is_empty() {
        return Err(IoError::Hdf5Layout {
            file: file.to_string(),
            found: format!("no 1-D dataset in '{prefix}'"),
        });
    }
    let header: Vec<String> = fields.iter().map(|f| f.0.clone()).collect();
    // The row count comes from data actually read, never from headers alone
    // (a forged header could claim 10^12 rows that nothing then checks): with
    // none of the fields asked for present, the first field is read.
    let (aliases, wanted) = mapped_fields(file, &header, opts)?;
    check_reads(file, n_rows, &wanted)?;
    let mut columns = Vec::new();
    for ((name, ds, _), want) in fields.into_iter().zip(wanted) {
        if !want {
            continue;
        }
        let path = format!("{prefix}{name}");
        check_units_attribute(file, &path, &name, &ds)?;
        if let Datatype::String { .. }
        | Datatype::VarLen {
            kind: VarLenKind::String,
            ..
        } = ds.dtype()
        {
            let text = ds.read_strings().map_err(|e| h5err(Some(&path), e))?;
            columns.push((name, ColumnData::Text(text), false));
            continue;
        }
        let (values, integer) = read_f64(&ds).map_err(|e| h5err(Some(&path), e))?;
        columns.push((name, ColumnData::numeric(values), integer));
    }
    // The rows are the values read (at least one field was), which must
    // match the headers' length.
    let len = |c: &ColumnData| match c {
        ColumnData::Numeric { values, .. } => values.len(),
        ColumnData::Text(t) => t.len(),
    };
    if let Some((name, data, _)) = columns.iter().find(|c| len(&c.1) as u64 != n_rows) {
        return Err(IoError::Hdf5Layout {
            file: file.to_string(),
            found: format!(
                "dataset '{prefix}{name}' holds {} values where its header says {n_rows}",
                len(data)
            ),
        });
    }
    let n_rows = columns.first().map_or(0, |c| len(&c.1));
    Ok(FlightTable::from_fields(
        path, n_rows, columns, aliases, header,
    ))
}

/// One read is capped by the reader; the reads of the `wanted` fields of
/// `n_rows` together here, before any: 7 fields of 4·10⁸ rows (3.2 GB
/// each, each under the cap) in a 10 kB file of unwritten chunks aborted
/// the process out of memory.
fn check_reads(file: &str, n_rows: u64, wanted: &[bool]) -> Result<()> {
    let n_wanted = wanted.iter().filter(|&&w| w).count().max(1) as u64;
    let total = n_rows.saturating_mul(n_wanted).saturating_mul(8);
    if total > MAX_READ_BYTES as u64 {
        return Err(IoError::Hdf5 {
            file: file.to_string(),
            dataset: None,
            message: format!(
                "{n_wanted} fields of {n_rows} values would take {} GB, more than {} GB read from one file: damaged, or far beyond any flight",
                total >> 30,
                MAX_READ_BYTES >> 30
            ),
        });
    }
    Ok(())
}

/// A MATLAB v7.3 MAT-file's flight ([`crate::mat73`], chosen by
/// [`crate::matlab`]'s rules): the wanted fields' datasets read, each
/// checked to hold the rows its dimensions say.
fn read_mat73(path: &Path, file: &str, root: &Group, opts: &ReadOptions) -> Result<FlightTable> {
    let mat = |(variable, message): crate::matlab::WorkspaceError| IoError::Mat {
        file: file.to_string(),
        variable,
        message,
    };
    let variables = crate::mat73::variables(root, "", 0).map_err(mat)?;
    crate::matlab::flight_of(variables)
        .map_err(mat)?
        .into_table(
            path,
            opts,
            |n_rows, wanted| check_reads(file, n_rows as u64, wanted),
            |ds| read_f64(&ds).map(|(v, _)| v).map_err(|e| e.to_string()),
        )
}

/// A `units` attribute that contradicts the unit the layout gives the field
/// ([`known_field`](crate::known_field): `ins_lat` in rad, `mag_1_uc` in
/// nT, …) is an error: the file is then not in the SGL layout, and reading
/// it as if it were would silently convert (or not convert) wrongly. An
/// attribute that cannot be read, or a field the layout does not know, is
/// not checked.
fn check_units_attribute(file: &str, path: &str, name: &str, ds: &Dataset) -> Result<()> {
    let Some(declared) = ds
        .attribute("units")
        .ok()
        .and_then(|a| a.read_string().ok())
    else {
        return Ok(());
    };
    let Some(known) = crate::known_field(name) else {
        return Ok(());
    };
    match (normalise_unit(&declared), normalise_unit(known.unit)) {
        (Some(d), Some(k)) if d != k => Err(IoError::Hdf5 {
            file: file.to_string(),
            dataset: Some(path.to_string()),
            message: format!(
                "declares units '{declared}', but in the SGL layout '{name}' is in {} ({}); convert the file, or map the field with --columns onto a canonical column in that unit",
                known.unit, known.meaning
            ),
        }),
        _ => Ok(()),
    }
}

/// A unit name in one spelling (`None` for units this check does not know).
fn normalise_unit(u: &str) -> Option<&'static str> {
    Some(match u.trim().to_ascii_lowercase().as_str() {
        "deg" | "degree" | "degrees" | "°" | "decimal degrees" => "deg",
        "rad" | "radian" | "radians" => "rad",
        "nt" | "nanotesla" | "nanoteslas" => "nT",
        "t" | "tesla" => "T",
        "ut" | "µt" | "microtesla" => "uT",
        "m/s" | "m s-1" | "m s^-1" | "meters per second" | "metres per second" => "m/s",
        "m" | "meter" | "meters" | "metre" | "metres" => "m",
        "ft" | "feet" => "ft",
        "s" | "sec" | "second" | "seconds" => "s",
        "a" | "amp" | "amps" | "ampere" | "amperes" => "A",
        "v" | "volt" | "volts" => "V",
        _ => return None,
    })
}

/// A 1-D numeric dataset as `f64` (exact for f32 and integers up to 2⁵³),
/// and whether it holds integers.
pub(crate) fn read_f64(
    ds: &Dataset,
) -> std::result::Result<(Vec<f64>, bool), hdf5_reader::error::Error> {
    fn vec<T: H5Type>(ds: &Dataset) -> std::result::Result<Vec<T>, hdf5_reader::error::Error> {
        Ok(ds.read_array::<T>()?.into_raw_vec_and_offset().0)
    }
    fn widen<T: H5Type + Into<f64>>(
        ds: &Dataset,
    ) -> std::result::Result<Vec<f64>, hdf5_reader::error::Error> {
        Ok(vec::<T>(ds)?.into_iter().map(Into::into).collect())
    }
    Ok(match ds.dtype() {
        Datatype::FloatingPoint { size: 8, .. } => (vec::<f64>(ds)?, false),
        Datatype::FloatingPoint { size: 4, .. } => (widen::<f32>(ds)?, false),
        Datatype::FixedPoint {
            size: 1,
            signed: true,
            ..
        } => (widen::<i8>(ds)?, true),
        Datatype::FixedPoint {
            size: 1,
            signed: false,
            ..
        } => (widen::<u8>(ds)?, true),
        Datatype::FixedPoint {
            size: 2,
            signed: true,
            ..
        } => (widen::<i16>(ds)?, true),
        Datatype::FixedPoint {
            size: 2,
            signed: false,
            ..
        } => (widen::<u16>(ds)?, true),
        Datatype::FixedPoint {
            size: 4,
            signed: true,
            ..
        } => (widen::<i32>(ds)?, true),
        Datatype::FixedPoint {
            size: 4,
            signed: false,
            ..
        } => (widen::<u32>(ds)?, true),
        Datatype::FixedPoint {
            size: 8,
            signed: true,
            ..
        } => (
            vec::<i64>(ds)?.into_iter().map(|x| x as f64).collect(),
            true,
        ),
        Datatype::FixedPoint {
            size: 8,
            signed: false,
            ..
        } => (
            vec::<u64>(ds)?.into_iter().map(|x| x as f64).collect(),
            true,
        ),
        other => {
            return Err(hdf5_reader::error::Error::InvalidData(format!(
                "not a numeric field ({other:?})"
            )));
        }
    })
}
