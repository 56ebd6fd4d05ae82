//! Writing a flight table in the format its file name asks for: Geosoft
//! XYZ for `.xyz` ([`crate::write_xyz`]), CSV otherwise
//! ([`crate::write_csv`]; `.csv`, `.txt`, `.dat`, no extension), and a
//! clear error for the formats aeromag reads or writes elsewhere but not
//! as a flight table (`out.h5` was written as CSV under that name).

use std::path::Path;

use crate::error::{IoError, Result};
use crate::table::FlightTable;

/// The text formats a flight table is written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TableFormat {
    /// Comma-separated values with a header row ([`crate::write_csv`]).
    Csv,
    /// Geosoft XYZ ([`crate::write_xyz`]).
    Xyz,
}

/// Extensions of files that are not flight tables in text, or that
/// aeromag does not write as one: refused as outputs of a table.
const REFUSED: [(&str, &str); 9] = [
    ("h5", "HDF5"),
    ("hdf5", "HDF5"),
    ("he5", "HDF5"),
    ("nc", "a netCDF grid"),
    ("tif", "a GeoTIFF grid"),
    ("tiff", "a GeoTIFF grid"),
    ("asc", "an ESRI ASCII grid"),
    ("grd", "a grid"),
    ("json", "a model file"),
];

impl TableFormat {
    /// The format of an output named `path` (its extension, any case):
    /// bad input ([`IoError::Unsupported`]) for a grid, model or HDF5 name,
    /// so a long run never ends on one.
    pub fn of_path(path: &Path) -> Result<Self> {
        let ext = aeromag_core::file_name::extension(path);
        if ext == "xyz" {
            return Ok(TableFormat::Xyz);
        }
        match REFUSED.iter().find(|(e, _)| *e == ext) {
            Some((_, what)) => Err(IoError::Unsupported {
                file: path.display().to_string(),
                reason: format!(
                    "a '.{ext}' file is {what}: aeromag writes a flight table as CSV (.csv) or Geosoft XYZ (.xyz)"
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
    }
    Ok(format)
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
        for refused in ["out.h5", "o.HDF5", "g.tif", "g.nc", "m.json"] {
            let e = of(refused).unwrap_err();
            assert!(e.is_bad_input(), "{refused}");
            assert!(
                e.to_string().contains("CSV (.csv) or Geosoft XYZ (.xyz)"),
                "{e}"
            );
        }
    }
}
