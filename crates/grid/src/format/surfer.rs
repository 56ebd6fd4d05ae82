//! Surfer grids (Golden Software), read: the `.grd` files Surfer, Oasis
//! montaj's export and many geophysical programs write, told from GMT's
//! netCDF `.grd` by their first four bytes.
//!
//! | magic | format | values |
//! | --- | --- | --- |
//! | `DSAA` | Surfer ASCII | text |
//! | `DSBB` | Surfer 6 binary | float32, little-endian |
//! | `DSRB` | Surfer 7 binary (tagged sections) | float64, little-endian |
//!
//! Surfer 6 (ASCII and binary): `nx ny`, `xlo xhi`, `ylo yhi`, `zlo zhi`
//! (the first and last nodes' coordinates: node registration, as
//! [`Grid`]'s), then the rows from the southern one, west to east; a value
//! of 1.70141·10³⁸ or more is blank. Surfer 7: a `DSRB` header section
//! (version 1 or 2), a `GRID` section (rows, columns, the south-western
//! node, the spacings, the z range, rotation and the blank value), a
//! `DATA` section of the rows from the south; other sections (faults) are
//! skipped. Version 1 blanks values of the blank value or more, version 2
//! exactly the blank value.
//!
//! Refused, naming the file: unequal x and y spacings (aeromag's cells are
//! square), a rotation, a header that declares more values than the file
//! holds, and values beyond float32's range ([`check_values`]). Surfer
//! grids record no coordinate system (it is in a separate `.prj` or not at
//! all): the CRS is unknown, and coordinates are taken as metres.

use std::fs;
use std::path::Path;

use super::{
    check_declared_size, check_values, checked_geometry, north_up, open_error, read_error,
    square_cell, stem,
};
use crate::error::Result;
use crate::grid::{Grid, GridGeometry};
use aeromag_core::error::shown_text;

/// Surfer 6's blank value: a value at or above it is blank.
const SURFER6_BLANK: f64 = 1.70141e38;

/// The Surfer format of a file's first bytes, if it is one.
pub(crate) fn kind(head: &[u8]) -> Option<&'static str> {
    match head.get(..4)? {
        b"DSAA" => Some("Surfer ASCII"),
        b"DSBB" => Some("Surfer 6 binary"),
        b"DSRB" => Some("Surfer 7 binary"),
        _ => None,
    }
}

/// Reads a Surfer grid (module docs). Its name is the file stem.
pub fn read(path: &Path) -> Result<Grid> {
    let bytes = fs::read(path).map_err(|e| open_error(path, e))?;
    let (geometry, values) = match bytes.get(..4) {
        Some(b"DSAA") => ascii(path, &bytes)?,
        Some(b"DSBB") => surfer6(path, &bytes)?,
        Some(b"DSRB") => surfer7(path, &bytes)?,
        _ => return Err(read_error(path, "not a Surfer grid (DSAA, DSBB or DSRB)")),
    };
    let mut grid = Grid::blank(geometry, &stem(path), "");
    grid.values = values;
    check_values(path, &grid)?;
    Ok(grid)
}

/// The geometry of Surfer 6's header: node counts and the first and last
/// nodes' coordinates.
fn geometry6(path: &Path, nx: i64, ny: i64, x: [f64; 2], y: [f64; 2]) -> Result<GridGeometry> {
    let count = |n: i64, what: &str| -> Result<usize> {
        usize::try_from(n)
            .ok()
            .filter(|&n| n >= 2)
            .ok_or_else(|| read_error(path, format!("{n} {what}: a Surfer grid has at least 2")))
    };
    let (nx, ny) = (count(nx, "columns")?, count(ny, "rows")?);
    let cell = square_cell(
        path,
        (x[1] - x[0]) / (nx - 1) as f64,
        (y[1] - y[0]) / (ny - 1) as f64,
    )?;
    checked_geometry(
        path,
        GridGeometry {
            x0: x[0],
            y0: y[0],
            cell,
            nx,
            ny,
        },
    )
}

/// Surfer ASCII: `DSAA`, then the header's numbers and the values as text.
fn ascii(path: &Path, bytes: &[u8]) -> Result<(GridGeometry, Vec<f64>)> {
    let text = String::from_utf8_lossy(&bytes[4..]);
    let mut tokens = text.split_ascii_whitespace();
    let mut next = |what: &str| -> Result<f64> {
        let t = tokens
            .next()
            .ok_or_else(|| read_error(path, format!("the file ends before {what}")))?;
        t.parse::<f64>()
            .map_err(|_| read_error(path, format!("{what}: {} is not a number", shown_text(t))))
    };
    let (nx, ny) = (next("the column count")?, next("the row count")?);
    let x = [next("xlo")?, next("xhi")?];
    let y = [next("ylo")?, next("yhi")?];
    let _z = [next("zlo")?, next("zhi")?];
    if nx.fract() != 0.0 || ny.fract() != 0.0 || !nx.is_finite() || !ny.is_finite() {
        return Err(read_error(
            path,
            format!("{nx} × {ny} is not a count of nodes"),
        ));
    }
    let geometry = geometry6(path, nx as i64, ny as i64, x, y)?;
    check_declared_size(path, geometry.nx, geometry.ny, 2.0, bytes.len() as u64 + 1)?;
    let mut values = Vec::with_capacity(geometry.len());
    for k in 0..geometry.len() {
        let v = next(&format!(
            "the value of row {} (from the south), column {}",
            k / geometry.nx + 1,
            k % geometry.nx + 1
        ))?;
        values.push(if v >= SURFER6_BLANK { f64::NAN } else { v });
    }
    if let Some(extra) = tokens.next() {
        return Err(read_error(
            path,
            format!("{} after the {} values", shown_text(extra), geometry.len()),
        ));
    }
    Ok((geometry, values))
}

/// Little-endian fields of a binary grid (Surfer's, Geosoft's), read
/// from `pos` on; reading past the end is an error naming the file.
pub(super) struct Fields<'a> {
    pub(super) path: &'a Path,
    pub(super) bytes: &'a [u8],
    pub(super) pos: usize,
}

impl Fields<'_> {
    fn take<const N: usize>(&mut self) -> Result<[u8; N]> {
        let end = self.pos + N;
        let b = self.bytes.get(self.pos..end).ok_or_else(|| {
            read_error(
                self.path,
                format!(
                    "the file ends at byte {} inside its header",
                    self.bytes.len()
                ),
            )
        })?;
        self.pos = end;
        Ok(b.try_into().expect("N bytes"))
    }
    fn i16(&mut self) -> Result<i16> {
        Ok(i16::from_le_bytes(self.take()?))
    }
    pub(super) fn i32(&mut self) -> Result<i32> {
        Ok(i32::from_le_bytes(self.take()?))
    }
    pub(super) fn i64(&mut self) -> Result<i64> {
        Ok(i64::from_le_bytes(self.take()?))
    }
    pub(super) fn f64(&mut self) -> Result<f64> {
        Ok(f64::from_le_bytes(self.take()?))
    }
    /// The values of `n` elements of `size` bytes from here, decoded.
    fn values(&self, n: usize, size: usize, decode: impl Fn(&[u8]) -> f64) -> Result<Vec<f64>> {
        let data = self
            .bytes
            .get(self.pos..)
            .filter(|d| d.len() / size >= n)
            .ok_or_else(|| {
                read_error(
                    self.path,
                    format!(
                        "the header declares {n} values of {size} bytes, but {} bytes follow it",
                        self.bytes.len().saturating_sub(self.pos)
                    ),
                )
            })?;
        Ok(data.chunks_exact(size).take(n).map(decode).collect())
    }
}

/// Surfer 6 binary: `DSBB`, two i16 counts, six f64, float32 values.
fn surfer6(path: &Path, bytes: &[u8]) -> Result<(GridGeometry, Vec<f64>)> {
    let mut f = Fields {
        path,
        bytes,
        pos: 4,
    };
    let (nx, ny) = (f.i16()?, f.i16()?);
    let x = [f.f64()?, f.f64()?];
    let y = [f.f64()?, f.f64()?];
    let _z = [f.f64()?, f.f64()?];
    let geometry = geometry6(path, nx.into(), ny.into(), x, y)?;
    let values = f.values(geometry.len(), 4, |b| {
        let v = f64::from(f32::from_le_bytes(b.try_into().expect("4 bytes")));
        if v >= SURFER6_BLANK { f64::NAN } else { v }
    })?;
    Ok((geometry, values))
}

/// Surfer 7 binary: tagged sections (module docs).
fn surfer7(path: &Path, bytes: &[u8]) -> Result<(GridGeometry, Vec<f64>)> {
    let mut f = Fields {
        path,
        bytes,
        pos: 0,
    };
    let (mut version, mut grid) = (None, None);
    while f.pos < bytes.len() {
        let tag: [u8; 4] = f.take()?;
        let size = usize::try_from(f.i32()?).map_err(|_| {
            read_error(
                path,
                format!("section {} has a negative size", tag_text(&tag)),
            )
        })?;
        let start = f.pos;
        match &tag {
            b"DSRB" => version = Some(f.i32()?),
            b"GRID" => {
                let (ny, nx) = (f.i32()?, f.i32()?);
                let (x0, y0, dx, dy) = (f.f64()?, f.f64()?, f.f64()?, f.f64()?);
                let (_zmin, _zmax, rotation, blank) = (f.f64()?, f.f64()?, f.f64()?, f.f64()?);
                grid = Some((nx, ny, x0, y0, dx, dy, rotation, blank));
            }
            b"DATA" => {
                let (nx, ny, x0, y0, dx, dy, rotation, blank) =
                    grid.ok_or_else(|| read_error(path, "a DATA section before the GRID section"))?;
                north_up(path, rotation)?;
                let cell = square_cell(path, dx, dy)?;
                let count = |n: i32, what: &str| -> Result<usize> {
                    usize::try_from(n)
                        .ok()
                        .filter(|&n| n >= 1)
                        .ok_or_else(|| read_error(path, format!("{n} {what}")))
                };
                let geometry = checked_geometry(
                    path,
                    GridGeometry {
                        x0,
                        y0,
                        cell,
                        nx: count(nx, "columns")?,
                        ny: count(ny, "rows")?,
                    },
                )?;
                // Version 1: blank from the blank value up; version 2: that value.
                let exact = version == Some(2);
                let values = f.values(geometry.len(), 8, |b| {
                    let v = f64::from_le_bytes(b.try_into().expect("8 bytes"));
                    if v == blank || (!exact && v >= blank) {
                        f64::NAN
                    } else {
                        v
                    }
                })?;
                return Ok((geometry, values));
            }
            _ => {}
        }
        // Skip to the section's end (sections may hold more than is read).
        f.pos = start
            .checked_add(size)
            .filter(|&e| e >= f.pos && e <= bytes.len())
            .ok_or_else(|| {
                read_error(
                    path,
                    format!("section {} runs past the end of the file", tag_text(&tag)),
                )
            })?;
    }
    Err(read_error(path, "no DATA section"))
}

fn tag_text(tag: &[u8; 4]) -> String {
    shown_text(&String::from_utf8_lossy(tag))
}

#[cfg(test)]
mod tests {
    use super::super::read_grid;
    use super::super::test_support::*;
    use super::*;

    /// GDAL writes the three Surfer formats (its GSAG, GSBG and GS7BG
    /// drivers) from an ESRI ASCII grid of the sample: read back here, the
    /// nodes and values (float32 in Surfer 6 binary, float64 in Surfer 7,
    /// GDAL's text in ASCII) and the blanks. Skipped (with a message) when
    /// GDAL is not on PATH.
    #[test]
    fn surfer_grids_written_by_gdal_are_read() {
        if !gdal_runs("gdal_translate") {
            return;
        }
        let dir = tempfile::tempdir().unwrap();
        let mut grid = sample_grid();
        grid.crs = None;
        let asc = dir.path().join("s.asc");
        super::super::write_grid(&asc, &grid).unwrap();
        for (driver, magic) in [("GSAG", "DSAA"), ("GSBG", "DSBB"), ("GS7BG", "DSRB")] {
            let grd = dir.path().join(format!("{driver}.grd"));
            gdal_translate(&["-of", driver], &asc, &grd);
            assert_eq!(&fs::read(&grd).unwrap()[..4], magic.as_bytes());
            let back = read_grid(&grd).unwrap();
            assert_eq!(back.geometry, grid.geometry, "{driver}");
            for (k, (a, b)) in grid.values.iter().zip(&back.values).enumerate() {
                if a.is_nan() {
                    assert!(b.is_nan(), "{driver} node {k}: {b}");
                } else {
                    assert!(
                        (a - b).abs() <= 1e-6 * a.abs(),
                        "{driver} node {k}: {a} vs {b}"
                    );
                }
            }
        }
    }

    #[test]
    fn surfer_ascii_is_read_and_what_cannot_be_is_refused_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.grd");
        fs::write(&path, SURFER_ASCII).unwrap();
        let g = read_grid(&path).unwrap();
        assert_eq!(
            (
                g.geometry.x0,
                g.geometry.y0,
                g.geometry.cell,
                g.geometry.nx,
                g.geometry.ny
            ),
            (100.0, 200.0, 10.0, 3, 2)
        );
        assert_eq!(g.values[..4], [1.0, 2.0, 3.0, 4.0]);
        assert!(g.values[4].is_nan());
        assert_eq!((g.name.as_str(), g.crs), ("s", None));
        for (text, needle) in [
            (
                "DSAA\n3 2\n100 120\n200 220\n1 6\n1 2 3\n4 5 6\n",
                "square cells",
            ),
            (
                "DSAA\n3 2\n100 120\n200 210\n1 6\n1 2 3\n4 5\n",
                "row 2 (from the south), column 3",
            ),
            (
                "DSAA\n3 2\n100 120\n200 210\n1 6\n1 2 3\n4 5 6 7\n",
                "\"7\" after the 6 values",
            ),
            ("DSAA\n1 2\n100 120\n200 210\n1 6\n1 2\n", "1 columns"),
            ("DSBB\x03\x00", "inside its header"),
        ] {
            fs::write(&path, text).unwrap();
            let e = read_grid(&path).unwrap_err();
            assert!(e.is_bad_input(), "{text}: {e}");
            assert!(
                e.to_string().contains("s.grd") && e.to_string().contains(needle),
                "{text}: {e}"
            );
        }
    }
}
