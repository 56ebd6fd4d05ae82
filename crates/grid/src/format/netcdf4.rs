//! netCDF-4 grids: the HDF5 files GMT 6 (its default `nf` format), xarray
//! (`to_netcdf()` with the netCDF4 library) and GDAL write, read without a
//! C library by the HDF5 reader the flight files use (`hdf5-reader`).
//!
//! A netCDF-4 file holds its variables as the root group's datasets and
//! their attributes as HDF5 attributes; a dimension with a coordinate
//! variable is a 1-D dataset of the dimension's name. They are taken into
//! the classic reader's [`Header`] (the 1-D datasets as dimensions and
//! coordinate variables, the 2-D dataset's axes matched to them) and read
//! as a classic file is ([`super::netcdf::interpret`]: the same grid
//! variable, coordinates, fill values, packing, CRS and units).
//!
//! A 2-D variable's axes are matched to the coordinate variables by
//! length, the rows (first axis) to `y`-like names (`y`, `lat`,
//! `latitude`, `northing`) and the columns to `x`-like ones when two have
//! one length (a square grid): netCDF-4 records a variable's dimensions as
//! HDF5 object references (`DIMENSION_LIST`), and CF orders them `(y, x)`.
//! Groups, compound and string variables are not read; a file the HDF5
//! reader cannot read is an error naming it, never a panic (reads are
//! capped at [`MAX_READ_BYTES`]).

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;

use hdf5_reader::{Dataset, Datatype, Hdf5File, OpenOptions};

use super::netcdf::{Attributes, Header, NcType, Parse, Value, Variable, interpret};
use super::read_error;
use crate::error::Result;
use crate::grid::{Grid, GridGeometry};
use aeromag_core::error::shown_text;

/// The largest dataset read, bytes: 2 GiB, the 250 million float64 nodes
/// of [`MAX_NODES`](crate::grid::MAX_NODES) being 2 GB.
const MAX_READ_BYTES: usize = 2 << 30;

/// Names of the coordinate of a grid's rows (northing) and columns.
const Y_NAMES: [&str; 5] = [
    "y",
    "lat",
    "latitude",
    "northing",
    "projection_y_coordinate",
];
const X_NAMES: [&str; 5] = [
    "x",
    "lon",
    "longitude",
    "easting",
    "projection_x_coordinate",
];

/// Reads a netCDF-4 grid (module docs): its geometry (for the caller's
/// checks) and the grid.
pub(super) fn read(path: &Path) -> Result<(GridGeometry, Grid)> {
    match catch_unwind(AssertUnwindSafe(|| read_hdf5(path))) {
        Ok(r) => r.map_err(|e| read_error(path, format!("netCDF-4: {e}"))),
        Err(_) => Err(read_error(
            path,
            "netCDF-4: the HDF5 reader failed on this file (damaged or unsupported)",
        )),
    }
}

fn read_hdf5(path: &Path) -> Parse<(GridGeometry, Grid)> {
    let h5 = Hdf5File::open_with_options(
        path,
        OpenOptions::default()
            .with_chunk_cache_bytes(0)
            .with_max_read_bytes(MAX_READ_BYTES),
    )
    .map_err(|e| e.to_string())?;
    let root = h5.root_group().map_err(|e| e.to_string())?;
    let (_, names) = root.member_names().map_err(|e| e.to_string())?;
    let mut datasets = Vec::new();
    for name in names {
        let ds = root
            .dataset(&name)
            .map_err(|e| format!("{}: {e}", shown_text(&name)))?;
        datasets.push((name, ds));
    }
    let header = header(&datasets)?;
    interpret(&header, |v| {
        let (_, ds) = datasets
            .iter()
            .find(|(n, _)| *n == v.name)
            .ok_or_else(|| format!("no variable {}", shown_text(&v.name)))?;
        values(ds).map_err(|e| format!("{}: {e}", shown_text(&v.name)))
    })
}

/// The classic header of the root group's numeric datasets: the 1-D ones
/// as dimensions (their own coordinate variables), every scalar (a grid
/// mapping), 1-D and 2-D one as a variable.
fn header(datasets: &[(String, Dataset)]) -> Parse<Header> {
    let mut dims: Vec<(String, usize)> = Vec::new();
    for (name, ds) in datasets {
        if let [n] = ds.shape() {
            dims.push((name.clone(), usize::try_from(*n).map_err(|_| "too large")?));
        }
    }
    let mut vars = Vec::new();
    for (name, ds) in datasets {
        let Some(nc_type) = nc_type(ds.dtype()) else {
            continue; // text, compound: not a grid's variable
        };
        let var_dims = match ds.shape() {
            // A scalar: a grid mapping's attributes.
            [] => vec![],
            [_] => vec![
                dims.iter()
                    .position(|(d, _)| d == name)
                    .ok_or("a 1-D dataset")?,
            ],
            [rows, columns] => axes(name, *rows, *columns, &dims)?,
            _ => continue,
        };
        vars.push(Variable {
            name: name.clone(),
            dims: var_dims,
            attributes: attributes(ds),
            nc_type,
            begin: 0,
        });
    }
    Ok(Header { dims, vars })
}

/// The dimensions of a 2-D variable of `rows × columns`: the coordinate
/// variables of those lengths, by name when two have one length.
fn axes(name: &str, rows: u64, columns: u64, dims: &[(String, usize)]) -> Parse<Vec<usize>> {
    let pick = |len: u64, names: &[&str], other: Option<usize>| -> Parse<usize> {
        let of_len: Vec<usize> = (0..dims.len())
            .filter(|&d| dims[d].1 as u64 == len && Some(d) != other)
            .collect();
        match of_len[..] {
            [d] => Ok(d),
            [] => Err(format!(
                "no coordinate variable of {len} values for {}",
                shown_text(name)
            )),
            _ => of_len
                .iter()
                .copied()
                .find(|&d| names.contains(&dims[d].0.to_ascii_lowercase().as_str()))
                .ok_or_else(|| {
                    format!(
                        "cannot tell which coordinate variables are {}'s rows and columns",
                        shown_text(name)
                    )
                }),
        }
    };
    let y = pick(rows, &Y_NAMES, None)?;
    let x = pick(columns, &X_NAMES, Some(y))?;
    Ok(vec![y, x])
}

/// The classic type of an HDF5 numeric type; `None` for another.
fn nc_type(t: &Datatype) -> Option<NcType> {
    Some(match t {
        Datatype::FloatingPoint { size: 4, .. } => NcType::Float,
        Datatype::FloatingPoint { size: 8, .. } => NcType::Double,
        Datatype::FixedPoint { size: 1, .. } => NcType::Byte,
        Datatype::FixedPoint { size: 2, .. } => NcType::Short,
        Datatype::FixedPoint { size: 4, .. } => NcType::Int,
        _ => return None,
    })
}

/// The attributes of a dataset as classic values: text, numbers as
/// doubles; the HDF5 and netCDF-4 bookkeeping (`DIMENSION_LIST`, `CLASS`,
/// `_Netcdf4…`) and what cannot be read are left out.
fn attributes(ds: &Dataset) -> Attributes {
    ds.attributes()
        .into_iter()
        .filter_map(|a| {
            let value = match &a.datatype {
                Datatype::String { .. } | Datatype::VarLen { .. } => {
                    Value::Text(a.read_string().ok()?.trim_end_matches('\0').to_string())
                }
                Datatype::FloatingPoint { size: 4, .. } => Value::Other(
                    a.read_1d::<f32>()
                        .ok()?
                        .into_iter()
                        .map(f64::from)
                        .collect(),
                ),
                Datatype::FloatingPoint { size: 8, .. } => Value::Double(a.read_1d::<f64>().ok()?),
                Datatype::FixedPoint {
                    size: 4,
                    signed: true,
                    ..
                } => Value::Int(a.read_1d::<i32>().ok()?),
                Datatype::FixedPoint {
                    size: 2,
                    signed: true,
                    ..
                } => Value::Other(
                    a.read_1d::<i16>()
                        .ok()?
                        .into_iter()
                        .map(f64::from)
                        .collect(),
                ),
                Datatype::FixedPoint {
                    size: 1,
                    signed: true,
                    ..
                } => Value::Other(a.read_1d::<i8>().ok()?.into_iter().map(f64::from).collect()),
                _ => return None,
            };
            Some((a.name.clone(), value))
        })
        .collect()
}

/// A numeric dataset's values as f64 (exact for every netCDF type read).
fn values(ds: &Dataset) -> std::result::Result<Vec<f64>, hdf5_reader::error::Error> {
    fn widen<T: hdf5_reader::H5Type + Into<f64>>(
        ds: &Dataset,
    ) -> std::result::Result<Vec<f64>, hdf5_reader::error::Error> {
        let (v, _) = ds.read_array::<T>()?.into_raw_vec_and_offset();
        Ok(v.into_iter().map(Into::into).collect())
    }
    match ds.dtype() {
        Datatype::FloatingPoint { size: 8, .. } => {
            Ok(ds.read_array::<f64>()?.into_raw_vec_and_offset().0)
        }
        Datatype::FloatingPoint { size: 4, .. } => widen::<f32>(ds),
        Datatype::FixedPoint {
            size: 4,
            signed: true,
            ..
        } => widen::<i32>(ds),
        Datatype::FixedPoint {
            size: 4,
            signed: false,
            ..
        } => widen::<u32>(ds),
        Datatype::FixedPoint {
            size: 2,
            signed: true,
            ..
        } => widen::<i16>(ds),
        Datatype::FixedPoint {
            size: 2,
            signed: false,
            ..
        } => widen::<u16>(ds),
        Datatype::FixedPoint {
            size: 1,
            signed: true,
            ..
        } => widen::<i8>(ds),
        Datatype::FixedPoint {
            size: 1,
            signed: false,
            ..
        } => widen::<u8>(ds),
        other => Err(hdf5_reader::error::Error::InvalidData(format!(
            "not a numeric variable ({other:?})"
        ))),
    }
}

#[cfg(test)]
mod tests {
    use super::super::read_grid;
    use crate::projection::{Crs, UtmZone};
    use std::path::PathBuf;

    /// The files of `tools/reference/netcdf4_grids.py`, written by libnetcdf.
    fn data(name: &str) -> PathBuf {
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(name)
    }

    /// A square grid (axes told apart by name), y descending, int16 packed
    /// and deflated, a fill value and an EPSG code: the nodes as the script
    /// wrote them, rows from the south.
    #[test]
    fn a_packed_netcdf4_grid_is_read_as_written() {
        let g = read_grid(&data("nc4_packed.nc")).unwrap();
        let geometry = (
            g.geometry.x0,
            g.geometry.y0,
            g.geometry.cell,
            g.geometry.nx,
            g.geometry.ny,
        );
        assert_eq!(geometry, (500_000.0, 4_000_000.0, 10.0, 4, 4));
        assert_eq!(g.crs, Some(Crs::Utm(UtmZone::new(18, true).unwrap())));
        assert_eq!(
            (g.name.as_str(), g.unit.as_str()),
            ("total magnetic intensity", "nT")
        );
        // The file's first row is the northern one (y descending).
        let row =
            |j: usize| -> Vec<f64> { (0..4).map(|i| g.values[g.geometry.index(i, j)]).collect() };
        assert_eq!(row(0), [50_006.0, 50_006.5, 50_007.0, 50_007.5]);
        assert_eq!(row(2), [50_002.0, 50_002.5, 50_003.0, 50_003.5]);
        let north = row(3);
        assert!(north[0].is_nan());
        assert_eq!(north[1..], [50_000.5, 50_001.0, 50_001.5]);
    }

    #[test]
    fn a_netcdf4_grid_in_degrees_or_damaged_is_refused_naming_the_file() {
        let e = read_grid(&data("nc4_degrees.nc")).unwrap_err();
        assert!(e.is_bad_input(), "{e}");
        assert!(
            e.to_string().contains("nc4_degrees.nc") && e.to_string().contains("degrees"),
            "{e}"
        );
        let dir = tempfile::tempdir().unwrap();
        let bytes = std::fs::read(data("nc4_packed.nc")).unwrap();
        for cut in [100, 2000, bytes.len() / 2] {
            let p = dir.path().join("cut.nc");
            std::fs::write(&p, &bytes[..cut]).unwrap();
            let e = read_grid(&p).unwrap_err();
            assert!(
                e.is_bad_input() && e.to_string().contains("cut.nc"),
                "{cut}: {e}"
            );
        }
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(100))]
        /// A damaged netCDF-4 file (bytes changed, cut short) gives a grid
        /// or an error naming it, never a panic.
        #[test]
        fn damaged_netcdf4_files_are_errors_not_panics(
            edits in proptest::collection::vec((0.0f64..1.0, proptest::prelude::any::<u8>()), 1..6),
            keep in 0.5f64..=1.0,
        ) {
            let mut bytes = std::fs::read(data("nc4_packed.nc")).unwrap();
            for (at, byte) in edits {
                let k = ((bytes.len() as f64 * at) as usize).min(bytes.len() - 1);
                bytes[k] = byte;
            }
            bytes.truncate((bytes.len() as f64 * keep).ceil() as usize);
            let dir = tempfile::tempdir().unwrap();
            let path = dir.path().join("d.nc");
            std::fs::write(&path, &bytes).unwrap();
            if let Err(e) = read_grid(&path) {
                proptest::prop_assert!(e.to_string().contains("d.nc"), "{e}");
            }
        }
    }
}
