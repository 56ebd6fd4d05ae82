//! ESRI ASCII grid (`.asc`, "Arc/Info ASCII Grid") with a `.prj` sidecar.
//!
//! The header, one keyword and value a line:
//!
//! ```text
//! ncols        5
//! nrows        4
//! xllcenter    500000
//! yllcenter    6000050
//! cellsize     50
//! NODATA_value -99999
//! ```
//!
//! `xllcenter`/`yllcenter` are the south-western NODE (node registration:
//! the cells a GIS draws are centred on the nodes), then `nrows` lines of
//! `ncols` values, from the NORTHERN row to the southern, west to east.
//! Values are the shortest decimal that reads back to the same float32
//! (at most 9 significant digits, exponent form only below 10⁻⁵ or from
//! 10¹⁵ in magnitude): the same precision as the GeoTIFF and netCDF
//! files. Blank nodes are [`NODATA`].
//!
//! When the grid's CRS is known, `<stem>.prj` holds its OGC WKT 1 on one
//! line (GDAL and ArcGIS read both flavours); when it is not, an old
//! `<stem>.prj` (describing the file being replaced) is removed.
//!
//! The coordinates must be metres: a `.prj` declaring a geographic system
//! (`GEOGCS`, longitude and latitude in degrees) or a projected one in
//! another unit (`UNIT["US survey foot",0.3048006096]`) is refused, naming
//! the file; a `.prj` this crate cannot read is taken as metres, as one
//! that is absent.
//!
//! Reading accepts `xllcorner`/`yllcorner` too (the node then half a cell
//! in), any order of header lines, keywords in any case and an absent
//! `NODATA_value`. A value `nan` is a blank node too (as GDAL reads it).
//! Refused: a header whose cell size, coordinates or node count are out
//! of range ([`checked_geometry`]) or that declares more values than the
//! file can hold, and values that are infinite or beyond
//! [`MAX_VALUE`](crate::grid::MAX_VALUE) (the error names the row, from
//! the north, and the column).

use std::fs;
use std::io::{self, Write};
use std::path::Path;

use super::{
    CoordinateUnit, NODATA, check_declared_size, check_grid, check_values, checked_geometry,
    crs_from_wkt, crs_wkt, not_metres, open_error, read_error, stem, wkt_unit, write_atomic,
};
use crate::error::Result;
use crate::grid::{Grid, GridGeometry};
use aeromag_core::error::{shown, shown_text};

/// Writes `grid` as an ESRI ASCII grid to `path` and, when its CRS is
/// known, the WKT to `path` with extension `.prj` (both atomically). Errors
/// as [`write_grid`](super::write_grid).
pub fn write(path: &Path, grid: &Grid) -> Result<()> {
    check_grid(grid)?;
    write_atomic(path, |w| write_asc(w, grid))?;
    let prj = path.with_extension("prj");
    match &grid.crs {
        Some(crs) => {
            let wkt = crs_wkt(crs);
            write_atomic(&prj, |w| writeln!(w, "{wkt}"))?;
        }
        None => {
            if prj.is_file() {
                fs::remove_file(&prj).map_err(|source| crate::GridError::Write {
                    path: prj.display().to_string(),
                    source,
                })?;
            }
        }
    }
    Ok(())
}

fn write_asc(w: &mut impl Write, grid: &Grid) -> io::Result<()> {
    let g = &grid.geometry;
    writeln!(w, "ncols        {}", g.nx)?;
    writeln!(w, "nrows        {}", g.ny)?;
    // As Rust writes them, or in exponent form when that would be long.
    writeln!(w, "xllcenter    {}", shown(g.x0))?;
    writeln!(w, "yllcenter    {}", shown(g.y0))?;
    writeln!(w, "cellsize     {}", shown(g.cell))?;
    writeln!(w, "NODATA_value {NODATA}")?;
    let mut line = String::new();
    for j in (0..g.ny).rev() {
        line.clear();
        for i in 0..g.nx {
            if i > 0 {
                line.push(' ');
            }
            push_f32(&mut line, grid.values[g.index(i, j)]);
        }
        line.push('\n');
        w.write_all(line.as_bytes())?;
    }
    Ok(())
}

/// Appends the shortest decimal of `v` as float32 (NaN as [`NODATA`]).
pub(super) fn push_f32(s: &mut String, v: f64) {
    use std::fmt::Write as _;
    let v = if v.is_nan() { NODATA as f32 } else { v as f32 };
    let a = v.abs();
    // Display never uses an exponent: keep it for the tiny and the huge.
    let _ = if a == 0.0 || (1e-5..1e15).contains(&a) || a.is_infinite() {
        write!(s, "{v}")
    } else {
        write!(s, "{v:e}")
    };
}

/// Reads an ESRI ASCII grid and its `.prj` sidecar, if any. The name is the
/// file stem and the unit empty (the format carries neither).
pub fn read(path: &Path) -> Result<Grid> {
    let text = fs::read_to_string(path).map_err(|e| open_error(path, e))?;
    let (mut nx, mut ny, mut x, mut y, mut cell, mut nodata) = (None, None, None, None, None, None);
    let mut corner = (false, false);
    // The header: one `keyword value` per line, up to the first line that
    // starts with a number (read by lines: a keyword without its value took
    // the first grid value as its own, and the error blamed the data).
    let mut data_start = text.len();
    let mut offset = 0;
    for (k, line) in text.split_inclusive('\n').enumerate() {
        let line_no = k + 1;
        let mut words = line.split_ascii_whitespace();
        let Some(key) = words.next() else {
            offset += line.len();
            continue;
        };
        if key.parse::<f64>().is_ok() {
            data_start = offset;
            break;
        }
        offset += line.len();
        let (word, key) = (key, key.to_ascii_lowercase());
        let at = |what: String| read_error(path, format!("line {line_no}: {what}"));
        let value = words
            .next()
            .ok_or_else(|| at(format!("{} has no value", shown_text(word))))?;
        let number = || -> Result<f64> {
            value.parse::<f64>().map_err(|_| {
                at(format!(
                    "{} is not a number: {}",
                    shown_text(word),
                    shown_text(value)
                ))
            })
        };
        let count = || -> Result<usize> {
            match value.parse::<usize>() {
                Ok(0) => Err(at(format!(
                    "{} is 0: a grid has at least one",
                    shown_text(word)
                ))),
                Ok(n) => Ok(n),
                Err(_) => Err(at(format!(
                    "{} is not a count: {}",
                    shown_text(word),
                    shown_text(value)
                ))),
            }
        };
        match key.as_str() {
            "ncols" => nx = Some(count()?),
            "nrows" => ny = Some(count()?),
            "xllcenter" => x = Some(number()?),
            "yllcenter" => y = Some(number()?),
            "xllcorner" => {
                x = Some(number()?);
                corner.0 = true;
            }
            "yllcorner" => {
                y = Some(number()?);
                corner.1 = true;
            }
            "cellsize" => cell = Some(number()?),
            "nodata_value" => nodata = Some(number()?),
            _ => return Err(at(format!("unknown header keyword {}", shown_text(word)))),
        }
        if let Some(extra) = words.next() {
            return Err(at(format!(
                "{} has more than one value: {}",
                shown_text(word),
                shown_text(extra)
            )));
        }
    }
    let mut tokens = text[data_start..].split_ascii_whitespace();
    let missing = |k: &str| read_error(path, format!("no '{k}' in the header"));
    let cell = cell.ok_or_else(|| missing("cellsize"))?;
    let half = |c: bool| if c { cell / 2.0 } else { 0.0 };
    let geometry = checked_geometry(
        path,
        GridGeometry {
            x0: x.ok_or_else(|| missing("xllcenter"))? + half(corner.0),
            y0: y.ok_or_else(|| missing("yllcenter"))? + half(corner.1),
            cell,
            nx: nx.ok_or_else(|| missing("ncols"))?,
            ny: ny.ok_or_else(|| missing("nrows"))?,
        },
    )?;
    // The .prj first: a grid in degrees is refused whatever its values.
    let prj = path.with_extension("prj");
    let mut crs = None;
    if prj.is_file() {
        let wkt = fs::read_to_string(&prj).map_err(|e| open_error(&prj, e))?;
        if let Some(unit) = wkt_unit(&wkt).filter(|u| *u != CoordinateUnit::Metre) {
            let by = format!("its .prj ({})", prj.display());
            return Err(not_metres(path, &by, &unit));
        }
        crs = crs_from_wkt(wkt.trim());
    }
    // Each value takes at least one character and a separator (the last
    // none): check before allocating what the header declares.
    check_declared_size(path, geometry.nx, geometry.ny, 2.0, text.len() as u64 + 1)?;
    let mut grid = Grid::blank(geometry, &stem(path), "");
    for j in (0..geometry.ny).rev() {
        for i in 0..geometry.nx {
            let token = tokens.next().ok_or_else(|| {
                read_error(
                    path,
                    format!(
                        "{} values, expected {}",
                        (geometry.ny - 1 - j) * geometry.nx + i,
                        geometry.len()
                    ),
                )
            })?;
            let v: f64 = token.parse().map_err(|_| {
                read_error(
                    path,
                    format!(
                        "row {}, column {}: {} is not a number",
                        geometry.ny - j,
                        i + 1,
                        shown_text(token)
                    ),
                )
            })?;
            grid.values[geometry.index(i, j)] = if Some(v) == nodata { f64::NAN } else { v };
        }
    }
    check_values(path, &grid)?;
    if tokens.next().is_some() {
        return Err(read_error(
            path,
            format!("more than {} values", geometry.len()),
        ));
    }
    grid.crs = crs;
    Ok(grid)
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::super::{GridFormat, read_grid, write_grid};
    use super::*;

    #[test]
    fn esri_ascii_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("tmi.asc");
        let grid = sample_grid();
        assert_eq!(write_grid(&path, &grid).unwrap(), GridFormat::EsriAscii);
        let back = read_grid(&path).unwrap();
        assert_same_grid(&grid, &back);
        assert_eq!(back.name, "tmi");
        let text = fs::read_to_string(&path).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(
            lines[..6],
            [
                "ncols        5",
                "nrows        4",
                "xllcenter    500000",
                "yllcenter    6000050",
                "cellsize     50",
                "NODATA_value -99999"
            ]
        );
        // North row first; all float32 digits; blanks as NODATA.
        assert_eq!(lines[6], "3000.1235 3001.1235 3002.1235 3003.1235 -99999");
        assert_eq!(
            lines[7],
            "2000.1234 2001.1234 -51234.566 2003.1234 2004.1234"
        );
        assert_eq!(lines[9], "0.12345679 -99999 2.1234567 3.1234567 4.123457");
        assert_eq!(lines.len(), 10);
        let prj = fs::read_to_string(dir.path().join("tmi.prj")).unwrap();
        assert!(prj.starts_with("PROJCS[\"WGS 84 / UTM zone 37N\""));
        assert_eq!(entries(dir.path()), ["tmi.asc", "tmi.prj"]);

        // Without a CRS: no .prj (the old one goes with the old grid).
        let mut plain = grid.clone();
        plain.crs = None;
        write_grid(&path, &plain).unwrap();
        assert_eq!(entries(dir.path()), ["tmi.asc"]);
        assert_same_grid(&plain, &read_grid(&path).unwrap());
    }

    #[test]
    fn esri_ascii_reads_corner_headers_and_extreme_values() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.asc");
        fs::write(
            &path,
            "NCOLS 2\nNROWS 2\nXLLCORNER 100\nYLLCORNER 200\nCELLSIZE 10\n1e-30 -3.5e20\n0 7\n",
        )
        .unwrap();
        let g = read(&path).unwrap();
        assert_eq!(
            (g.geometry.x0, g.geometry.y0, g.geometry.cell),
            (105.0, 205.0, 10.0)
        );
        assert_eq!(g.values, [0.0, 7.0, 1e-30, -3.5e20]);
        assert_eq!(g.crs, None);
        let mut s = String::new();
        for v in [1e-30, -3.5e20, 0.0, 1e-5, 123456.78] {
            push_f32(&mut s, v);
            s.push(' ');
        }
        assert_eq!(s, "1e-30 -3.5e20 0 0.00001 123456.78 ");
        fs::write(
            &path,
            "ncols 2\nnrows 2\nxllcenter 0\nyllcenter 0\ncellsize 1\n1 2 3\n",
        )
        .unwrap();
        assert!(read(&path).is_err());
        fs::write(&path, "ncols 2\nnrows 1\nxllcenter 0\ncellsize 1\n1 2\n").unwrap();
        assert!(read(&path).unwrap_err().to_string().contains("yllcenter"));
        // Header errors name the keyword and its line: a keyword without
        // its value took the first grid value ("4 values, expected 5"),
        // and ncols 0 read as a size limit.
        for (header, says) in [
            ("NODATA_value\n", "line 6: \"NODATA_value\" has no value"),
            ("ncols 0\n", "line 6: \"ncols\" is 0"),
            (
                "cellsize 1 2\n",
                "line 6: \"cellsize\" has more than one value",
            ),
        ] {
            fs::write(
                &path,
                format!("ncols 2\nnrows 1\nxllcenter 0\nyllcenter 0\ncellsize 1\n{header}1 2\n"),
            )
            .unwrap();
            let e = read(&path).unwrap_err().to_string();
            assert!(e.contains(says), "{e}");
        }
    }

    /// The file `name` in `dir` with a 3 × 3 header of cell `cell` and the
    /// rows `body`, read.
    fn read_asc(dir: &Path, name: &str, cell: &str, body: &str) -> Result<Grid> {
        let path = dir.join(name);
        fs::write(
            &path,
            format!(
                "ncols 3\nnrows 3\nxllcenter 0\nyllcenter 0\ncellsize {cell}\n\
                 NODATA_value -99999\n{body}"
            ),
        )
        .unwrap();
        read(&path)
    }

    #[test]
    fn infinite_and_huge_values_are_refused_naming_row_and_column() {
        let dir = tempfile::tempdir().unwrap();
        for (value, shown) in [
            ("1e300", "1e300"),
            ("1e400", "inf"),
            ("-1e308", "-1e308"),
            ("inf", "inf"),
            ("-inf", "-inf"),
            ("1e308", "1e308"),
            ("1e39", "1e39"),
            ("-3.5e38", "-3.5e38"),
        ] {
            let e = read_asc(
                dir.path(),
                "v.asc",
                "100",
                &format!("1 2 3\n4 5 {value}\n7 8 9\n"),
            )
            .unwrap_err();
            assert!(e.is_bad_input());
            assert!(
                matches!(
                    e,
                    crate::GridError::BadValue {
                        row: 2,
                        column: 3,
                        ..
                    }
                ),
                "{value}: {e}"
            );
            let m = e.to_string();
            assert!(
                m.contains("v.asc") && m.contains(&format!("is {shown}:")),
                "{value}: {m}"
            );
        }
        // The largest value allowed, and NaN as a blank node.
        let g = read_asc(dir.path(), "v.asc", "100", "1 2 3\n4 nan -3.4e38\n7 8 9\n").unwrap();
        assert!(g.get(1, 1).is_nan());
        assert_eq!(g.get(2, 1), -3.4e38);
        assert_eq!(g.stats().count, 8);
    }

    #[test]
    fn cell_sizes_out_of_range_are_refused_in_short_messages() {
        let dir = tempfile::tempdir().unwrap();
        let body = "1 2 3\n4 5 6\n7 8 9\n";
        for cell in [
            "1e-308", "1e308", "-1e308", "0", "nan", "inf", "1e-7", "2e6",
        ] {
            let e = read_asc(dir.path(), "c.asc", cell, body).unwrap_err();
            let m = e.to_string();
            assert!(
                m.contains("c.asc") && m.contains("cell size") && m.len() < 120,
                "{cell}: {m}"
            );
        }
        for cell in ["1e-6", "1e6", "0.5"] {
            assert!(read_asc(dir.path(), "c.asc", cell, body).is_ok(), "{cell}");
        }
        // A corner of 1e300 m, or one past ±1e9 m by the grid's extent.
        let path = dir.path().join("far.asc");
        for (x, ncols) in [("1e300", 1), ("999999999", 3), ("-1e-300", 1)] {
            fs::write(
                &path,
                format!(
                    "ncols {ncols}\nnrows 1\nxllcenter {x}\nyllcenter 0\ncellsize 1\n{}\n",
                    "1 ".repeat(ncols)
                ),
            )
            .unwrap();
            let r = read(&path);
            if x == "-1e-300" {
                // A tiny coordinate is fine and written back short.
                let g = r.unwrap();
                write_grid(&path, &g).unwrap();
                let text = fs::read_to_string(&path).unwrap();
                assert!(text.contains("xllcenter    -1e-300\n"), "{text}");
            } else {
                let m = r.unwrap_err().to_string();
                assert!(
                    m.contains("coordinates must be within") && m.len() < 150,
                    "{m}"
                );
            }
        }
    }

    #[test]
    fn a_header_declaring_more_values_than_the_file_holds_is_refused_before_allocating() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("hd.asc");
        fs::write(
            &path,
            "ncols 15800\nnrows 15800\nxllcenter 0\nyllcenter 0\ncellsize 1\nNODATA_value -99999\n1 2 3\n",
        )
        .unwrap();
        let m = read(&path).unwrap_err().to_string();
        assert!(
            m.contains("hd.asc") && m.contains("declares 15800 × 15800") && m.contains("86"),
            "{m}"
        );
        // Exactly enough text: "1 2\n3 4" for 2 × 2.
        fs::write(
            &path,
            "ncols 2\nnrows 2\nxllcenter 0\nyllcenter 0\ncellsize 1\n1 2\n3 4",
        )
        .unwrap();
        assert_eq!(read(&path).unwrap().values, [3.0, 4.0, 1.0, 2.0]);
    }

    #[test]
    fn binary_garbage_is_not_echoed() {
        let dir = tempfile::tempdir().unwrap();
        let garbage = format!("x\u{1}{}", "\u{7f}\u{0}\u{1b}[2J".repeat(300));
        let e = read_asc(
            dir.path(),
            "b.asc",
            "100",
            &format!("1 2 3\n4 {garbage} 6\n7 8 9\n"),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("row 2, column 2") && e.contains("\\u{1}"), "{e}");
        assert!(!e.chars().any(|c| c.is_control()) && e.len() < 200, "{e}");
        let path = dir.path().join("k.asc");
        fs::write(&path, format!("ncols 1\n{garbage} 1\n")).unwrap();
        let e = read(&path).unwrap_err().to_string();
        assert!(!e.chars().any(|c| c.is_control()) && e.len() < 200, "{e}");
        fs::write(&path, format!("ncols {garbage}\n")).unwrap();
        let e = read(&path).unwrap_err().to_string();
        assert!(!e.chars().any(|c| c.is_control()) && e.len() < 200, "{e}");
    }

    /// A grid whose .prj declares a geographic system (a 0.001° cell) was
    /// differentiated as if the cell were 0.001 m, 10⁵ times too large
    /// (finding 08); one in feet 3.3 times. Both are now refused naming
    /// the grid and its .prj; an unreadable .prj is taken as metres.
    #[test]
    fn a_prj_not_in_metres_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("ll.asc");
        let mut grid = sample_grid();
        grid.crs = None;
        write_grid(&path, &grid).unwrap();
        let prj = dir.path().join("ll.prj");
        for (wkt, what) in [
            (
                "GEOGCS[\"WGS 84\",DATUM[\"WGS_1984\",SPHEROID[\"WGS 84\",6378137,\
                 298.257223563]],PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433]]\n",
                "a geographic coordinate system (longitude and latitude in degrees)",
            ),
            (
                "PROJCS[\"NAD83 / Texas Central (ftUS)\",GEOGCS[\"NAD83\",\
                 UNIT[\"degree\",0.0174532925199433]],PROJECTION[\"Lambert_Conformal_Conic_2SP\"],\
                 UNIT[\"US survey foot\",0.3048006096012192],AUTHORITY[\"EPSG\",\"2277\"]]",
                "coordinates in \"US survey foot\" (0.3048006096012192 m)",
            ),
        ] {
            fs::write(&prj, wkt).unwrap();
            let e = read_grid(&path).unwrap_err();
            assert!(e.is_bad_input());
            let e = e.to_string();
            assert!(
                e.starts_with(&format!("reading '{}': its .prj", path.display()))
                    && e.contains("ll.prj")
                    && e.contains(what)
                    && e.contains("must be in a projected coordinate system in metres"),
                "{e}"
            );
        }
        fs::write(&prj, "not a WKT").unwrap();
        assert_same_grid(&grid, &read_grid(&path).unwrap());
    }
}
