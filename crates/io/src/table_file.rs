//! Writing a flight table in the format its file name asks for: Geosoft
//! XYZ for `.xyz` ([`crate::write_xyz`]), HDF5 in the MagNav/SGL layout
//! for `.h5` and `.hdf5` ([`crate::write_hdf5`]), a MATLAB v5 MAT-file for
//! `.mat` ([`crate::write_mat5`]), CSV otherwise
//! ([`crate::write_csv`]; `.csv`, `.txt`, `.dat`, no extension), and a
//! clear error for the formats aeromag reads or writes elsewhere but not
//! as a flight table (`out.tif` would be CSV under a grid's name).

use std::io::BufWriter;
use std::path::Path;

use crate::atomic::Output;
use crate::csv_write::written_columns;
use crate::error::{IoError, Result};
use crate::table::{Column, FlightTable};

/// The formats a flight table is written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TableFormat {
    /// Comma-separated values with a header row ([`crate::write_csv`]).
    Csv,
    /// Geosoft XYZ ([`crate::write_xyz`]).
    Xyz,
    /// HDF5, one dataset per column ([`crate::write_hdf5`]).
    Hdf5,
    /// MATLAB v5 MAT-file, one column vector per column ([`crate::write_mat5`]).
    Mat,
}

/// Extensions of files that are not flight tables, or that aeromag does
/// not write as one: refused as outputs of a table.
const REFUSED: [(&str, &str); 7] = [
    ("he5", "HDF-EOS5"),
    ("nc", "a netCDF grid"),
    ("tif", "a GeoTIFF grid"),
    ("tiff", "a GeoTIFF grid"),
    ("asc", "an ESRI ASCII grid"),
    ("grd", "a grid"),
    ("json", "a model file"),
];

impl TableFormat {
    /// The format of an output named `path` (its extension, any case):
    /// bad input ([`IoError::Unsupported`]) for a grid, model or HDF-EOS5
    /// name, so a long run never ends on one.
    pub fn of_path(path: &Path) -> Result<Self> {
        let ext = aeromag_core::file_name::extension(path);
        match ext.as_str() {
            "xyz" => return Ok(TableFormat::Xyz),
            "h5" | "hdf5" => return Ok(TableFormat::Hdf5),
            "mat" => return Ok(TableFormat::Mat),
            _ => {}
        }
        match REFUSED.iter().find(|(e, _)| *e == ext) {
            Some((_, what)) => Err(IoError::Unsupported {
                file: path.display().to_string(),
                reason: format!(
                    "a '.{ext}' file is {what}: aeromag writes a flight table as CSV (.csv), Geosoft XYZ (.xyz), HDF5 (.h5) or a MATLAB MAT-file (.mat)"
                ),
            }),
            None => Ok(TableFormat::Csv),
        }
    }
}

/// Writes `table` to `path` in the format of its name
/// ([`TableFormat::of_path`]), atomically; returns the format written.
pub fn write_table(table: &FlightTable, path: &Path) -> Result<TableFormat> {
    let format = TableFormat::of_path(path)?;
    match format {
        TableFormat::Csv => crate::write_csv(table, path)?,
        TableFormat::Xyz => crate::write_xyz(table, path)?,
        TableFormat::Hdf5 => crate::write_hdf5(table, path)?,
        TableFormat::Mat => crate::write_mat5(table, path)?,
    }
    Ok(format)
}

/// Writes `table` to `path` in a format that `check`s it first (bad input
/// found before anything is written), atomically as [`crate::write_csv`].
pub(crate) fn write_checked(
    table: &FlightTable,
    path: &Path,
    check: impl FnOnce(&FlightTable, &str) -> Result<()>,
    write: impl FnOnce(&FlightTable, &mut BufWriter<Output>) -> std::io::Result<()>,
) -> Result<()> {
    let file = path.display().to_string();
    check(table, &file)?;
    crate::atomic::write_atomically(path, |w| write(table, w))
        .map_err(|source| IoError::Write { file, source })
}

/// The first written column of `table` that a format cannot hold, by
/// `reason` (why, `None` for a column it holds), as
/// [`IoError::CannotWrite`] naming the output `file`, with what to do:
/// rename the column, or write one of `instead`.
pub(crate) fn refuse_column(
    table: &FlightTable,
    file: &str,
    instead: &str,
    reason: impl Fn(&Column) -> Option<String>,
) -> Result<()> {
    for c in written_columns(table) {
        if let Some(reason) = reason(c) {
            return Err(IoError::CannotWrite {
                file: file.to_string(),
                column: c.name().to_string(),
                row: None,
                reason: format!("{reason}; rename the column, or write {instead}"),
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_extension_chooses_the_format() {
        let of = |p: &str| TableFormat::of_path(Path::new(p));
        assert_eq!(of("out.csv").unwrap(), TableFormat::Csv);
        assert_eq!(of("out").unwrap(), TableFormat::Csv);
        assert_eq!(of("out.dat").unwrap(), TableFormat::Csv);
        assert_eq!(of("OUT.XYZ").unwrap(), TableFormat::Xyz);
        assert_eq!(of("out.h5").unwrap(), TableFormat::Hdf5);
        assert_eq!(of("o.HDF5").unwrap(), TableFormat::Hdf5);
        assert_eq!(of("o.mat").unwrap(), TableFormat::Mat);
        for refused in ["out.he5", "g.tif", "g.nc", "m.json"] {
            let e = of(refused).unwrap_err();
            assert!(e.is_bad_input(), "{refused}");
            assert!(
                e.to_string().contains(
                    "CSV (.csv), Geosoft XYZ (.xyz), HDF5 (.h5) or a MATLAB MAT-file (.mat)"
                ),
                "{e}"
            );
        }
    }
}
