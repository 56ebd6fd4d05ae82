//! Grid files a GIS, GMT and Geosoft open: GeoTIFF, ESRI ASCII grid and
//! netCDF (COARDS/CF, as GMT writes it), written and read back without any
//! C library.
//!
//! The extension picks the format ([`GridFormat::from_path`], case
//! insensitive):
//!
//! | extension | format | module |
//! | --- | --- | --- |
//! | `.tif`, `.tiff` | GeoTIFF, one float32 band, rows north to south | [`geotiff`] |
//! | `.asc` | ESRI ASCII grid (+ `.prj` sidecar with the WKT) | [`esri_ascii`] |
//! | `.nc`, `.grd` | netCDF classic (CDF-2), COARDS/CF-1.7, GMT's gridline registration; netCDF-4 read | [`netcdf`] |
//! | `.gxf` | GXF-3, Geosoft's Grid eXchange File (text; compressed form read) | [`gxf`] |
//! | `.grd` read | a Surfer grid (ASCII, 6 or 7 binary) when its first bytes say so | [`surfer`] |
//! | `.grd` read | a Geosoft grid (Oasis montaj's binary, any element type, compressed or not) when its first bytes say so | [`geosoft`] |
//! | `.grd(GRD)` | a Geosoft grid, float32, written as Oasis montaj writes it (the file `.grd`; Oasis montaj's decoration) | [`geosoft`] |
//!
//! (A plain `.grd` is written as GMT's netCDF grid.)
//!
//! Every format keeps the node registration of [`Grid`]: the values are
//! those of the nodes, and a reader that thinks in cells (GDAL, a GIS) sees
//! cells of side `cell` centred on the nodes, so its extent is half a cell
//! wider than the nodes' on each side and its origin (upper-left corner) is
//! `(x0 − cell/2, y_max + cell/2)`.
//!
//! Values are stored as float32 in every format (the ESRI ASCII and GXF
//! text holds the shortest decimal of the float32): relative precision
//! 6·10⁻⁸, i.e. 0.004 nT at 50 000 nT. Blank (NaN) nodes are [`NODATA`] in
//! the GeoTIFF and ESRI ASCII files, NaN (`_FillValue`) in netCDF and
//! Geosoft's dummy `-1e32` in GXF.
//!
//! [`write_grid`] writes atomically: a temporary file in the destination
//! folder, flushed to disk, then renamed over the destination, so a reader
//! never sees half a file and a failed write leaves the old file as it was.

pub mod esri_ascii;
pub mod geosoft;
pub mod geotiff;
pub mod gxf;
pub mod netcdf;
mod netcdf4;
pub mod surfer;

use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::{GridError, Result};
use crate::grid::{Grid, GridGeometry, MAX_VALUE};
use crate::projection::{Crs, UtmZone};
use aeromag_core::error::{shown, shown_text};
use aeromag_core::memory::size_text;
use aeromag_core::output_target::{OutputTarget, output_target};

/// The value blank nodes take in the GeoTIFF (`GDAL_NODATA` tag) and ESRI
/// ASCII (`NODATA_value`) files: −99999, exact in float32 and far outside
/// any magnetic field or gradient value. (A node whose value is exactly
/// −99999 would read back as blank.)
pub const NODATA: f64 = -99999.0;

/// A grid file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum GridFormat {
    /// GeoTIFF, float32, one band ([`geotiff`]).
    GeoTiff,
    /// ESRI ASCII grid with a `.prj` sidecar ([`esri_ascii`]).
    EsriAscii,
    /// netCDF classic, COARDS/CF as GMT reads it ([`netcdf`]).
    NetCdf,
    /// GXF-3, Geosoft's Grid eXchange File ([`gxf`]).
    Gxf,
    /// Geosoft's binary grid, Oasis montaj's own ([`geosoft`]): a file
    /// named with Oasis montaj's decoration, `mag.grd(GRD)`.
    Geosoft,
}

/// Oasis montaj's decoration of a grid file's name that names the Geosoft
/// format: `mag.grd(GRD)` is the file `mag.grd` (any case).
const GEOSOFT_DECORATION: &str = "(GRD)";

/// `path` without Oasis montaj's `(GRD)` decoration, if it has one.
fn undecorated(path: &Path) -> Option<PathBuf> {
    let text = path.to_str()?;
    let cut = text.len().checked_sub(GEOSOFT_DECORATION.len())?;
    let decoration = text.get(cut..)?;
    decoration
        .eq_ignore_ascii_case(GEOSOFT_DECORATION)
        .then(|| PathBuf::from(&text[..cut]))
}

impl GridFormat {
    /// The format of a file by its extension: `.tif`/`.tiff` GeoTIFF,
    /// `.asc` ESRI ASCII, `.nc`/`.grd` netCDF, `.gxf` GXF (case
    /// insensitive); a name ending in Oasis montaj's decoration `(GRD)`
    /// (`mag.grd(GRD)`) Geosoft's grid; anything else is
    /// [`GridError::UnknownFormat`].
    pub fn from_path(path: &Path) -> Result<Self> {
        if undecorated(path).is_some() {
            return Ok(GridFormat::Geosoft);
        }
        match aeromag_core::file_name::extension(path).as_str() {
            "tif" | "tiff" => Ok(GridFormat::GeoTiff),
            "asc" => Ok(GridFormat::EsriAscii),
            "nc" | "grd" => Ok(GridFormat::NetCdf),
            "gxf" => Ok(GridFormat::Gxf),
            _ => Err(GridError::UnknownFormat(path.display().to_string())),
        }
    }

    /// The usual extension, without the dot (`tif`, `asc`, `nc`).
    pub fn extension(&self) -> &'static str {
        match self {
            GridFormat::GeoTiff => "tif",
            GridFormat::EsriAscii => "asc",
            GridFormat::NetCdf => "nc",
            GridFormat::Gxf => "gxf",
            GridFormat::Geosoft => "grd",
        }
    }

    /// Whether a file of this format records the grid's coordinate system
    /// (all but Geosoft's grid, whose system Oasis montaj keeps in an
    /// unpublished `.gi` sidecar).
    pub fn keeps_crs(&self) -> bool {
        !matches!(self, GridFormat::Geosoft)
    }

    /// Writes `grid` to `path` in this format, atomically (module docs),
    /// whatever the extension of `path` (the file named without a `(GRD)`
    /// decoration).
    pub fn write(&self, path: &Path, grid: &Grid) -> Result<()> {
        let undecorated = undecorated(path);
        let path = undecorated.as_deref().unwrap_or(path);
        match self {
            GridFormat::GeoTiff => geotiff::write(path, grid),
            GridFormat::EsriAscii => esri_ascii::write(path, grid),
            GridFormat::NetCdf => netcdf::write(path, grid),
            GridFormat::Gxf => gxf::write(path, grid),
            GridFormat::Geosoft => geosoft::write(path, grid),
        }
    }

    /// Reads a grid of this format from `path` (the file named without a
    /// `(GRD)` decoration).
    pub fn read(&self, path: &Path) -> Result<Grid> {
        let undecorated = undecorated(path);
        let path = undecorated.as_deref().unwrap_or(path);
        match self {
            GridFormat::GeoTiff => geotiff::read(path),
            GridFormat::EsriAscii => esri_ascii::read(path),
            GridFormat::NetCdf => {
                let head = aeromag_core::file_name::first_bytes(path, 20);
                if surfer::kind(&head).is_some() {
                    surfer::read(path)
                } else if geosoft::looks_geosoft(&head) {
                    geosoft::read(path)
                } else {
                    netcdf::read(path)
                }
            }
            GridFormat::Gxf => gxf::read(path),
            GridFormat::Geosoft => geosoft::read(path),
        }
    }
}

/// Writes `grid` to `path` in the format its extension names
/// ([`GridFormat::from_path`]), atomically (module docs). Returns the
/// format written.
///
/// Errors: [`GridError::UnknownFormat`] for another extension,
/// [`GridError::LengthMismatch`] / [`GridError::Unusable`] for a grid whose
/// values do not match its geometry, that has no node or a value beyond
/// float32's range,
/// [`GridError::Write`] when the file cannot be written (a missing folder,
/// no permission, a full disk).
pub fn write_grid(path: &Path, grid: &Grid) -> Result<GridFormat> {
    let format = GridFormat::from_path(path)?;
    format.write(path, grid)?;
    Ok(format)
}

/// Reads a grid file written by [`write_grid`] (or a compatible one: any
/// ESRI ASCII grid, a netCDF classic grid with 1-D `x`/`y` coordinates and
/// square cells, a single-band north-up GeoTIFF with square pixels), the
/// format chosen by the extension.
///
/// Errors: [`GridError::UnknownFormat`] for another extension,
/// [`GridError::Read`] for a file that cannot be read or parsed,
/// [`GridError::BadValue`] for a node that is not a grid value (both name
/// the file). The grid's name and unit are the file's, made printable
/// ([`label_from_file`]).
pub fn read_grid(path: &Path) -> Result<Grid> {
    GridFormat::from_path(path)?.read(path)
}

/// Checks that a grid can be written: values match the geometry, at least
/// one node, finite origin and positive cell.
pub(crate) fn check_grid(grid: &Grid) -> Result<()> {
    let g = &grid.geometry;
    if grid.values.len() != g.len() {
        return Err(GridError::LengthMismatch {
            what: "grid values",
            got: grid.values.len(),
            expected: g.len(),
        });
    }
    crate::error::positive("cell size", g.cell)?;
    if g.is_empty() || !(g.x0.is_finite() && g.y0.is_finite()) {
        return Err(GridError::Unusable(format!(
            "cannot write a grid of {} × {} nodes with origin ({}, {})",
            g.nx,
            g.ny,
            shown(g.x0),
            shown(g.y0)
        )));
    }
    if g.nx > i32::MAX as usize || g.ny > i32::MAX as usize {
        return Err(GridError::Unusable(format!(
            "{} × {} nodes is too many for a grid file",
            g.nx, g.ny
        )));
    }
    // Every format stores float32: a value beyond its range (or ±∞, e.g. a
    // product that overflowed) would be written as ±∞.
    if let Some((row, column, value)) = beyond_float32(grid) {
        return Err(GridError::Unusable(format!(
            "node at row {row}, column {column} (from the north-west corner, 1-based) is {}: \
             not a float32 value, so not written",
            shown(value)
        )));
    }
    Ok(())
}

/// A magnetic-field unit other than nT (`T`, `mT`, `µT`, `pT`, their
/// names, `gamma`), alone or per length (`T/m`), as a grid file may
/// declare it (a netCDF variable's `units`): the factor that takes its
/// values to nT and the unit then (`nT`, `nT/m`). `None` for nT and for
/// any other unit. A CF file in SI units holds a field of 5·10⁻⁵ T, which
/// was carried as such and printed as 0.0000.
pub(crate) fn in_nanotesla(unit: &str) -> Option<(f64, String)> {
    let (base, per) = match unit.trim().split_once('/') {
        Some((b, p)) => (b.trim(), format!("/{}", p.trim())),
        None => (unit.trim(), String::new()),
    };
    let factor = match base {
        "T" | "tesla" | "Tesla" => 1e9,
        "mT" | "millitesla" => 1e6,
        "uT" | "µT" | "μT" | "microtesla" => 1e3,
        "pT" | "picotesla" => 1e-3,
        "gamma" | "gammas" => 1.0,
        _ => return None,
    };
    Some((factor, format!("nT{per}")))
}

/// Most characters of a grid's name or unit read from a file: the longest
/// this crate writes (a column name and two products, "mag_comp_level
/// continued up 200 m vertical derivative") is about 60.
pub const MAX_LABEL_CHARS: usize = 200;

/// A name or unit from a grid file as the grid keeps it: control
/// characters escaped (`\u{1b}`, `\n`), so that a corrupt attribute is
/// never printed raw to a terminal nor written into the next file, and cut
/// after its first [`MAX_LABEL_CHARS`] characters with `…`.
pub fn label_from_file(text: &str) -> String {
    let mut label = String::new();
    for (n, c) in text.chars().enumerate() {
        if n == MAX_LABEL_CHARS {
            label.push('…');
            break;
        }
        if c.is_control() {
            label.extend(c.escape_debug());
        } else {
            label.push(c);
        }
    }
    label
}

/// The first node (row from the north, column from the west, 1-based, and
/// its value) that is neither blank (NaN) nor within [`MAX_VALUE`], the
/// range of the float32 every format stores.
pub(crate) fn beyond_float32(grid: &Grid) -> Option<(usize, usize, f64)> {
    let k = grid
        .values
        .iter()
        .position(|v| !v.is_nan() && v.abs() > MAX_VALUE)?;
    let (row, column) = grid.geometry.row_column(k);
    Some((row, column, grid.values[k]))
}

/// Writes a file atomically: `fill` writes into a temporary file created in
/// the folder of `path` (`.<name>.<pid>.<n>.tmp`), which is then flushed,
/// synced and renamed to `path`. On any error the temporary file is
/// removed and the error is [`GridError::Write`] naming `path`. A symbolic
/// link is followed; a device, FIFO or socket is written directly
/// ([`output_target`]).
pub(crate) fn write_atomic(
    path: &Path,
    fill: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
) -> Result<()> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let write_error = |source| GridError::Write {
        path: path.display().to_string(),
        source,
    };
    let target = output_target(path).map_err(write_error)?;
    let path = match &target {
        // A device, FIFO or socket is written as it is: a rename would
        // replace it by a regular file.
        OutputTarget::Stream(p) => {
            let file = OpenOptions::new()
                .write(true)
                .open(p)
                .map_err(write_error)?;
            let mut w = BufWriter::with_capacity(1 << 16, file);
            return fill(&mut w).and_then(|()| w.flush()).map_err(write_error);
        }
        OutputTarget::File(p) => p.as_path(),
    };
    let name = path.file_name().ok_or_else(|| {
        write_error(io::Error::new(
            io::ErrorKind::InvalidInput,
            "not a file name",
        ))
    })?;
    let tmp: PathBuf = path.with_file_name(format!(
        ".{}.{}.{}.tmp",
        name.to_string_lossy(),
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    let file = OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&tmp)
        .map_err(write_error)?;
    let result = (|| {
        let mut w = BufWriter::with_capacity(1 << 16, file);
        fill(&mut w)?;
        w.flush()?;
        let file = w.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
        drop(file);
        fs::rename(&tmp, path)
    })();
    if let Err(e) = result {
        let _ = fs::remove_file(&tmp);
        return Err(write_error(e));
    }
    Ok(())
}

/// The error of a file that cannot be read or parsed.
pub(crate) fn read_error(path: &Path, what: impl std::fmt::Display) -> GridError {
    GridError::Read {
        path: path.display().to_string(),
        reason: what.to_string(),
    }
}

/// The error of a file that cannot be opened or read.
pub(crate) fn open_error(path: &Path, source: std::io::Error) -> GridError {
    GridError::Open {
        path: path.display().to_string(),
        source,
    }
}

/// Checks the geometry of a grid read from a file
/// ([`GridGeometry::problem`]): the reason is a read error naming the file.
pub(crate) fn checked_geometry(path: &Path, geometry: GridGeometry) -> Result<GridGeometry> {
    match geometry.problem() {
        Some(reason) => Err(read_error(path, reason)),
        None => Ok(geometry),
    }
}

/// The cell of a grid file whose nodes are `dx` apart in x and `dy` in y:
/// bad input unless both are positive (x and y ascending) and equal to
/// 10⁻⁹ relative, aeromag's cells being square.
pub(crate) fn square_cell(path: &Path, dx: f64, dy: f64) -> Result<f64> {
    if dx > 0.0 && dy > 0.0 && (dx - dy).abs() <= 1e-9 * dx {
        return Ok(dx);
    }
    Err(read_error(
        path,
        format!(
            "nodes {} apart in x and {} in y: aeromag's grids have square cells, x and y ascending",
            shown(dx),
            shown(dy)
        ),
    ))
}

/// Bad input for a grid file rotated by `degrees` (aeromag's grids are
/// north-up).
pub(crate) fn north_up(path: &Path, degrees: f64) -> Result<()> {
    if degrees == 0.0 {
        return Ok(());
    }
    Err(read_error(
        path,
        format!(
            "the grid is rotated by {}°: aeromag's grids are north-up",
            shown(degrees)
        ),
    ))
}

/// Checks, before they are allocated, that `nx × ny` nodes of at least
/// `bytes_per_node` bytes each fit in a file of `file_len` bytes (a
/// corrupt header must not claim gigabytes for a tiny file).
pub(crate) fn check_declared_size(
    path: &Path,
    nx: usize,
    ny: usize,
    bytes_per_node: f64,
    file_len: u64,
) -> Result<()> {
    let needed = (nx as f64 * ny as f64 * bytes_per_node).ceil();
    if needed > file_len as f64 {
        return Err(read_error(
            path,
            format!(
                "the header declares {nx} × {ny} nodes, at least {needed} bytes, \
                 but the file has {file_len}"
            ),
        ));
    }
    Ok(())
}

/// A compressed file's few bytes may declare a large grid (GXF's repeats,
/// Geosoft's zlib blocks): its nodes (8 bytes each) must fit in the memory
/// `left` (none: not known).
pub(crate) fn fits_in_memory(path: &Path, nx: usize, ny: usize, left: Option<u64>) -> Result<()> {
    let need = (nx * ny) as u64 * 8;
    match left {
        Some(left) if need > left => Err(read_error(
            path,
            format!(
                "the header declares {nx} × {ny} nodes, {}, more than the {} this process can take",
                size_text(need),
                size_text(left)
            ),
        )),
        _ => Ok(()),
    }
}

/// Checks the node values of a grid read from a file: each is blank (NaN:
/// GeoTIFF and netCDF float grids mark blanks so, and an ESRI ASCII `nan`
/// is read the same way) or finite and at most [`MAX_VALUE`] in
/// magnitude, else [`GridError::BadValue`] naming its row and column.
pub(crate) fn check_values(path: &Path, grid: &Grid) -> Result<()> {
    match beyond_float32(grid) {
        Some((row, column, value)) => Err(GridError::BadValue {
            path: path.display().to_string(),
            row,
            column,
            value,
        }),
        None => Ok(()),
    }
}

/// OGC WKT 1 of a coordinate system, with its EPSG authority (the `.prj`
/// sidecar, the netCDF `spatial_ref`/`crs_wkt`): [`UtmZone::wkt`].
pub(crate) fn crs_wkt(crs: &Crs) -> String {
    match crs {
        Crs::Utm(zone) => zone.wkt(),
    }
}

/// The coordinate system of an EPSG code this crate knows (WGS 84 / UTM:
/// 32601–32660, 32701–32760).
pub(crate) fn crs_from_epsg(code: u32) -> Option<Crs> {
    let (north, number) = match code {
        32601..=32660 => (true, code - 32600),
        32701..=32760 => (false, code - 32700),
        _ => return None,
    };
    UtmZone::new(number as u8, north).ok().map(Crs::Utm)
}

/// The coordinate system a WKT (1 or 2, OGC or ESRI flavour) names: its
/// outermost EPSG authority, else a `UTM zone 37N`-like name on a WGS 84
/// datum. `None` for anything else.
pub(crate) fn crs_from_wkt(wkt: &str) -> Option<Crs> {
    // The last authority of a WKT 1 is the outermost (the PROJCS's).
    for (key, quote) in [("AUTHORITY[\"EPSG\",\"", true), ("ID[\"EPSG\",", false)] {
        if let Some(pos) = wkt.rfind(key) {
            let rest = &wkt[pos + key.len()..];
            let end = rest
                .find(|c: char| !c.is_ascii_digit())
                .unwrap_or(rest.len());
            let closes = if quote { "\"]]" } else { "]]" };
            // Only the outermost: the authority closes the whole WKT.
            if rest[end..].trim_end() == closes
                && let Some(crs) = rest[..end].parse().ok().and_then(crs_from_epsg)
            {
                return Some(crs);
            }
        }
    }
    let upper = wkt.to_ascii_uppercase();
    if !(upper.contains("WGS 84") || upper.contains("WGS_1984") || upper.contains("WGS84")) {
        return None;
    }
    for key in ["UTM ZONE ", "UTM_ZONE_"] {
        if let Some(pos) = upper.find(key) {
            let rest = &upper[pos + key.len()..];
            let end = rest
                .find(|c: char| !c.is_ascii_digit())
                .unwrap_or(rest.len());
            let number: u8 = rest[..end].parse().ok()?;
            let north = match rest[end..].chars().next()? {
                'N' => true,
                'S' => false,
                _ => return None,
            };
            if let Ok(zone) = UtmZone::new(number, north) {
                return Some(Crs::Utm(zone));
            }
        }
    }
    None
}

/// What a grid file says of the unit of its `x`, `y` coordinates. Every
/// computation on a grid (the spectral products' wavenumbers, distances,
/// continuation heights) takes the cell in metres: a geographic grid's
/// 0.001° cell read as 0.001 m gave a vertical derivative 10⁵ times too
/// large.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum CoordinateUnit {
    /// Metres (or the file does not say: as before, taken as metres).
    Metre,
    /// Longitude and latitude: a geographic coordinate system.
    Degree,
    /// Another linear unit: its name and its length in metres.
    Other(String, f64),
}

/// One element of a WKT: its keyword and what its brackets hold, quoted
/// strings and numbers as text, nested elements as such.
#[derive(Debug)]
struct WktNode {
    keyword: String,
    texts: Vec<String>,
    children: Vec<WktNode>,
}

/// Most nested brackets of a WKT read ([`parse_wkt`]): a real one has
/// about 5; a corrupt `.prj` of a million `[` must not overflow the stack.
const MAX_WKT_DEPTH: usize = 64;

/// The WKT element starting at `s[*pos..]` (WKT 1 or 2, OGC or ESRI);
/// `None` when it is not well formed.
fn parse_wkt(s: &[u8], pos: &mut usize, depth: usize) -> Option<WktNode> {
    if depth > MAX_WKT_DEPTH {
        return None;
    }
    let skip = |pos: &mut usize| {
        while s.get(*pos).is_some_and(u8::is_ascii_whitespace) {
            *pos += 1;
        }
    };
    skip(pos);
    let start = *pos;
    while s
        .get(*pos)
        .is_some_and(|c| c.is_ascii_alphanumeric() || *c == b'_')
    {
        *pos += 1;
    }
    let keyword = String::from_utf8_lossy(&s[start..*pos]).to_ascii_uppercase();
    skip(pos);
    let mut node = WktNode {
        keyword,
        texts: vec![],
        children: vec![],
    };
    if !matches!(s.get(*pos), Some(b'[' | b'(')) {
        return None;
    }
    *pos += 1;
    loop {
        skip(pos);
        match s.get(*pos)? {
            b']' | b')' => {
                *pos += 1;
                return Some(node);
            }
            b',' => *pos += 1,
            b'"' => {
                let end = *pos + 1 + s[*pos + 1..].iter().position(|&c| c == b'"')?;
                node.texts
                    .push(String::from_utf8_lossy(&s[*pos + 1..end]).into_owned());
                *pos = end + 1;
            }
            _ => {
                let start = *pos;
                while s
                    .get(*pos)
                    .is_some_and(|&c| !matches!(c, b',' | b'[' | b'(' | b']' | b')'))
                {
                    *pos += 1;
                }
                if matches!(s.get(*pos), Some(b'[' | b'(')) {
                    *pos = start;
                    node.children.push(parse_wkt(s, pos, depth + 1)?);
                } else {
                    node.texts
                        .push(String::from_utf8_lossy(&s[start..*pos]).trim().to_string());
                }
            }
        }
    }
}

/// The unit of the coordinates a WKT (a `.prj`, a netCDF `crs_wkt`)
/// declares: [`CoordinateUnit::Degree`] for a geographic system
/// (`GEOGCS`, `GEOGCRS`, an ellipsoidal `GEODCRS`), the linear unit of a
/// projected one (`PROJCS`'s own `UNIT`, `PROJCRS`'s `LENGTHUNIT` of its
/// axes), metre when its length is 1 m. `None` for a WKT this crate cannot
/// read (left as before: metres).
pub(crate) fn wkt_unit(wkt: &str) -> Option<CoordinateUnit> {
    let root = parse_wkt(wkt.trim().as_bytes(), &mut 0, 0)?;
    fn child<'a>(n: &'a WktNode, keys: &[&str]) -> Option<&'a WktNode> {
        n.children
            .iter()
            .find(|c| keys.contains(&c.keyword.as_str()))
    }
    match root.keyword.as_str() {
        "GEOGCS" | "GEOGCRS" | "GEOGRAPHICCRS" => Some(CoordinateUnit::Degree),
        "GEODCRS" | "GEODETICCRS"
            if child(&root, &["CS"]).is_some_and(|cs| {
                cs.texts
                    .first()
                    .is_some_and(|t| t.eq_ignore_ascii_case("ellipsoidal"))
            }) =>
        {
            Some(CoordinateUnit::Degree)
        }
        "PROJCS" | "PROJCRS" | "PROJECTEDCRS" => {
            let keys = ["UNIT", "LENGTHUNIT"];
            let unit = child(&root, &keys).or_else(|| {
                root.children
                    .iter()
                    .filter(|c| c.keyword == "AXIS")
                    .find_map(|a| child(a, &keys))
            })?;
            let name = unit.texts.first()?.clone();
            let metres: f64 = unit.texts.get(1)?.parse().ok()?;
            if !(metres.is_finite() && metres > 0.0) {
                return None;
            }
            Some(if (metres - 1.0).abs() <= 1e-9 {
                CoordinateUnit::Metre
            } else {
                CoordinateUnit::Other(name, metres)
            })
        }
        _ => None,
    }
}

/// The error of a grid whose coordinates are declared in another unit
/// than metres, `by` saying where (e.g. "its .prj"), `unit` what it says.
pub(crate) fn not_metres(path: &Path, by: &str, unit: &CoordinateUnit) -> GridError {
    read_error(path, not_metres_reason(by, unit))
}

/// The reason of [`not_metres`], without the file.
pub(crate) fn not_metres_reason(by: &str, unit: &CoordinateUnit) -> String {
    let what = match unit {
        CoordinateUnit::Degree => {
            "a geographic coordinate system (longitude and latitude in degrees)".to_string()
        }
        CoordinateUnit::Other(name, metres) => {
            format!("coordinates in {} ({} m)", shown_text(name), shown(*metres))
        }
        CoordinateUnit::Metre => "coordinates in metres".to_string(),
    };
    format!(
        "{by} declares {what}: grids must be in a projected coordinate system in metres \
         (e.g. UTM), as cell sizes, derivatives and heights are computed in metres; \
         project the grid first (e.g. gdalwarp -t_srs EPSG:32637)"
    )
}

/// The file stem, for the name of a grid whose file does not carry one
/// ([`label_from_file`]).
pub(crate) fn stem(path: &Path) -> String {
    path.file_stem()
        .map(|s| label_from_file(&s.to_string_lossy()))
        .unwrap_or_default()
}

#[cfg(test)]
pub(crate) mod test_support {
    use super::*;

    /// WGS 84 / UTM zone 37N (EPSG 32637).
    pub const ZONE_37N: Crs = Crs::Utm(UtmZone {
        number: 37,
        north: true,
    });

    /// A 5 × 4 grid at 50 m whose value tells its node, `1000 j + i + 0.1`
    /// (j from the south) plus a fraction that needs all float32 digits,
    /// with two blank nodes, in UTM 37N.
    pub fn sample_grid() -> Grid {
        let geometry = GridGeometry {
            x0: 500_000.0,
            y0: 6_000_050.0,
            cell: 50.0,
            nx: 5,
            ny: 4,
        };
        let mut grid = Grid::blank(geometry, "magnetic anomaly", "nT");
        for j in 0..geometry.ny {
            for i in 0..geometry.nx {
                grid.values[geometry.index(i, j)] = 1000.0 * j as f64 + i as f64 + 0.123_456_789;
            }
        }
        grid.values[geometry.index(1, 0)] = f64::NAN;
        grid.values[geometry.index(4, 3)] = f64::NAN;
        grid.values[geometry.index(2, 2)] = -51_234.567_89;
        grid.crs = Some(ZONE_37N);
        grid
    }

    /// Asserts two grids have the same geometry, CRS and values to float32
    /// precision, with the same blanks.
    pub fn assert_same_grid(a: &Grid, b: &Grid) {
        assert_eq!(a.geometry, b.geometry);
        assert_eq!(a.crs, b.crs);
        assert_eq!(a.values.len(), b.values.len());
        for (k, (x, y)) in a.values.iter().zip(&b.values).enumerate() {
            if x.is_nan() || y.is_nan() {
                assert!(x.is_nan() && y.is_nan(), "node {k}: {x} vs {y}");
            } else {
                assert_eq!(*x as f32, *y as f32, "node {k}");
            }
        }
    }

    /// A compressed GXF (`#GTYPE 2`, base 90 from `%`): sense -2 (the first
    /// row the northern), `#TRANSFORM 0.5,1000`; "%&" = 1, "&%" = 90, "!!"
    /// a dummy, "%(" = 3; then a repeat of 3 × "%*" (5) and "%," (7).
    pub const COMPRESSED_GXF: &str = "#POINTS\n4\n#ROWS\n2\n#PTSEPARATION\n10\n#RWSEPARATION\n10\n\
        #XORIGIN\n100\n#YORIGIN\n230\n#SENSE\n-2\n#DUMMY\n-1e32\n#TRANSFORM\n0.5,1000\n#GTYPE\n2\n\
        #GRID\n%&&%!!%(\n\"\"%(%*\n%,\n";

    /// A Surfer ASCII grid of 3 × 2 nodes 10 m apart, one blank.
    pub const SURFER_ASCII: &str = "DSAA\n3 2\n100 120\n200 210\n1 6\n1 2 3\n4 1.70141e38 6\n";

    /// Whether GDAL's `tool` (`gdalinfo`, `gdal_translate`) runs; when it
    /// does not, the test that asks says it is skipped.
    pub fn gdal_runs(tool: &str) -> bool {
        let runs = std::process::Command::new(tool)
            .arg("--version")
            .output()
            .is_ok_and(|o| o.status.success());
        if !runs {
            println!("SKIPPED: {tool} is not on PATH");
        }
        runs
    }

    /// `gdal_translate -q <options> input output` (`-of DRIVER`, `-co
    /// COMPRESS=LZW`, …), which must succeed.
    pub fn gdal_translate(options: &[&str], input: &Path, output: &Path) {
        let out = std::process::Command::new("gdal_translate")
            .arg("-q")
            .args(options)
            .arg(input)
            .arg(output)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{options:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }

    /// Every entry of a folder, for checking that no temporary is left.
    pub fn entries(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }
}

#[cfg(test)]
mod tests {
    use super::test_support::*;
    use super::*;

    #[test]
    fn format_from_extension() {
        let f = |p: &str| GridFormat::from_path(Path::new(p));
        assert_eq!(f("a/b.tif").unwrap(), GridFormat::GeoTiff);
        assert_eq!(f("b.TIFF").unwrap(), GridFormat::GeoTiff);
        assert_eq!(f("b.asc").unwrap(), GridFormat::EsriAscii);
        assert_eq!(f("b.nc").unwrap(), GridFormat::NetCdf);
        assert_eq!(f("b.grd").unwrap(), GridFormat::NetCdf);
        assert_eq!(f("b.GXF").unwrap(), GridFormat::Gxf);
        for bad in ["b.xyz", "b", "b.tif.bak", ".nc"] {
            let e = f(bad).unwrap_err();
            assert!(matches!(e, GridError::UnknownFormat(_)), "{bad}: {e}");
            assert!(e.is_bad_input());
        }
        let dir = tempfile::tempdir().unwrap();
        let e = write_grid(&dir.path().join("g.png"), &sample_grid()).unwrap_err();
        assert!(matches!(e, GridError::UnknownFormat(_)));
        assert!(entries(dir.path()).is_empty());
        assert!(matches!(
            read_grid(&dir.path().join("g.png")),
            Err(GridError::UnknownFormat(_))
        ));
    }

    #[test]
    fn atomic_write_leaves_only_the_files() {
        let dir = tempfile::tempdir().unwrap();
        let grid = sample_grid();
        for (name, format) in [
            ("g.tif", GridFormat::GeoTiff),
            ("g.asc", GridFormat::EsriAscii),
            ("g.nc", GridFormat::NetCdf),
        ] {
            assert_eq!(write_grid(&dir.path().join(name), &grid).unwrap(), format);
            // Overwriting replaces the file.
            write_grid(&dir.path().join(name), &grid).unwrap();
        }
        assert_eq!(entries(dir.path()), ["g.asc", "g.nc", "g.prj", "g.tif"]);
    }

    #[test]
    fn write_into_a_missing_folder_is_a_write_error() {
        let dir = tempfile::tempdir().unwrap();
        for name in ["g.tif", "g.asc", "g.nc"] {
            let path = dir.path().join("missing").join(name);
            let e = write_grid(&path, &sample_grid()).unwrap_err();
            match &e {
                GridError::Write { path: p, source } => {
                    assert!(p.ends_with(name), "{p}");
                    assert_eq!(source.kind(), io::ErrorKind::NotFound);
                }
                other => panic!("{name}: {other}"),
            }
            assert!(!e.is_bad_input());
        }
        assert!(entries(dir.path()).is_empty());
    }

    #[test]
    fn a_grid_not_matching_its_geometry_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let mut grid = sample_grid();
        grid.values.pop();
        let e = write_grid(&dir.path().join("g.nc"), &grid).unwrap_err();
        assert!(matches!(e, GridError::LengthMismatch { .. }), "{e}");
        let mut grid = sample_grid();
        grid.geometry.nx = 0;
        grid.values.clear();
        assert!(matches!(
            write_grid(&dir.path().join("g.tif"), &grid),
            Err(GridError::Unusable(_))
        ));
        assert!(entries(dir.path()).is_empty());
    }

    /// A name or unit with control characters (an escape sequence, a
    /// NUL, a new line) or of a megabyte was read as it stood, printed by
    /// `derive` and written into its output.
    #[test]
    fn names_and_units_from_files_are_printable_and_short() {
        assert_eq!(label_from_file("B<&>é nT/m"), "B<&>é nT/m");
        assert_eq!(label_from_file("a\u{1b}[31m\0b\n"), "a\\u{1b}[31m\\0b\\n");
        let long = "x".repeat(10 * MAX_LABEL_CHARS);
        assert_eq!(
            label_from_file(&long),
            format!("{}…", &long[..MAX_LABEL_CHARS])
        );
        let dir = tempfile::tempdir().unwrap();
        let mut grid = sample_grid();
        grid.name = format!("\u{1b}]0;pwned\u{7}{}", "n".repeat(100_000));
        grid.unit = "n\0\rT".into();
        for name in ["g.tif", "g.nc"] {
            let path = dir.path().join(name);
            write_grid(&path, &grid).unwrap();
            let back = read_grid(&path).unwrap();
            assert!(
                back.name.starts_with("\\u{1b}]0;pwned\\u{7}nnn")
                    && back.name.ends_with('…')
                    // The first MAX_LABEL_CHARS characters, two escaped
                    // (`\u{1b}` and `\u{7}`: 5 and 4 more).
                    && back.name.chars().count() == MAX_LABEL_CHARS + 1 + 5 + 4,
                "{name}: {} chars, ends {:?}",
                back.name.chars().count(),
                back.name.chars().rev().take(5).collect::<String>()
            );
            assert_eq!(back.unit, "n\\0\\rT", "{name}");
            assert!(
                !back
                    .name
                    .chars()
                    .chain(back.unit.chars())
                    .any(char::is_control)
            );
        }
        let path = dir.path().join("a\u{1}b.asc");
        write_grid(&path, &sample_grid()).unwrap();
        assert_eq!(read_grid(&path).unwrap().name, "a\\u{1}b");
    }

    #[test]
    fn infinite_values_are_neither_read_nor_written() {
        let dir = tempfile::tempdir().unwrap();
        let mut grid = sample_grid();
        // Node (2, 1): the third row from the north of four, third column.
        let k = grid.geometry.index(2, 1);
        grid.values[k] = 12345.0;
        for (name, marker, inf) in [
            (
                "g.tif",
                12345f32.to_le_bytes().to_vec(),
                f32::INFINITY.to_le_bytes().to_vec(),
            ),
            (
                "g.nc",
                12345f32.to_be_bytes().to_vec(),
                f32::NEG_INFINITY.to_be_bytes().to_vec(),
            ),
            ("g.asc", b"12345 ".to_vec(), b"-inf  ".to_vec()),
        ] {
            let path = dir.path().join(name);
            write_grid(&path, &grid).unwrap();
            let mut bytes = fs::read(&path).unwrap();
            // The last: netCDF has the value in `actual_range` too.
            let at = bytes
                .windows(marker.len())
                .rposition(|w| w == marker)
                .unwrap();
            bytes[at..at + marker.len()].copy_from_slice(&inf);
            fs::write(&path, &bytes).unwrap();
            let e = read_grid(&path).unwrap_err();
            assert!(
                matches!(
                    e,
                    GridError::BadValue {
                        row: 3,
                        column: 3,
                        ..
                    }
                ),
                "{name}: {e}"
            );
            assert!(e.is_bad_input() && e.to_string().contains(name), "{e}");
        }
        // Nor written: a value beyond float32 (an overflowed product).
        for value in [f64::INFINITY, -1e300, 3.5e38] {
            grid.values[k] = value;
            for name in ["w.tif", "w.asc", "w.nc"] {
                let e = write_grid(&dir.path().join(name), &grid).unwrap_err();
                let m = e.to_string();
                assert!(
                    matches!(e, GridError::Unusable(_)) && m.contains("row 3, column 3"),
                    "{name}: {m}"
                );
                assert!(m.len() < 150, "{m}");
            }
        }
        grid.values[k] = f32::MAX as f64;
        write_grid(&dir.path().join("w.nc"), &grid).unwrap();
        assert_eq!(
            read_grid(&dir.path().join("w.nc")).unwrap().values[k],
            f32::MAX as f64
        );
    }

    #[test]
    fn wkt_names_the_crs_and_reads_back() {
        let wkt = crs_wkt(&ZONE_37N);
        assert!(wkt.starts_with("PROJCS[\"WGS 84 / UTM zone 37N\""));
        assert!(wkt.contains("PARAMETER[\"central_meridian\",39]"));
        assert!(wkt.ends_with("AUTHORITY[\"EPSG\",\"32637\"]]"));
        assert_eq!(crs_from_wkt(&wkt), Some(ZONE_37N));
        let south = Crs::Utm(UtmZone {
            number: 1,
            north: false,
        });
        let wkt = crs_wkt(&south);
        assert!(wkt.contains("PARAMETER[\"central_meridian\",-177]"));
        assert!(wkt.contains("PARAMETER[\"false_northing\",10000000]"));
        assert_eq!(crs_from_wkt(&wkt), Some(south));
        // ESRI flavour (no authority), and WKT 2.
        let esri = "PROJCS[\"WGS_1984_UTM_Zone_37N\",GEOGCS[\"GCS_WGS_1984\"]]";
        assert_eq!(crs_from_wkt(esri), Some(ZONE_37N));
        assert_eq!(
            crs_from_wkt("PROJCRS[\"x\",BASEGEOGCRS[\"y\",ID[\"EPSG\",4326]],ID[\"EPSG\",32737]]"),
            Some(Crs::Utm(UtmZone {
                number: 37,
                north: false
            }))
        );
        assert_eq!(
            crs_from_wkt("GEOGCS[\"WGS 84\",AUTHORITY[\"EPSG\",\"4326\"]]"),
            None
        );
        assert_eq!(
            crs_from_epsg(32660),
            Some(Crs::Utm(UtmZone {
                number: 60,
                north: true
            }))
        );
        assert_eq!(crs_from_epsg(32661), None);
    }

    /// The coordinate unit a WKT declares: degrees for a geographic
    /// system (WKT 1 and 2), the projected system's own linear unit (not
    /// its geographic base's degrees), `None` for what cannot be read.
    #[test]
    fn wkt_units_are_read_from_the_right_element() {
        assert_eq!(wkt_unit(&crs_wkt(&ZONE_37N)), Some(CoordinateUnit::Metre));
        assert_eq!(
            wkt_unit(
                "PROJCS[\"WGS_1984_UTM_Zone_37N\",GEOGCS[\"GCS_WGS_1984\",UNIT[\"Degree\",0.017]],UNIT[\"Meter\",1.0]]"
            ),
            Some(CoordinateUnit::Metre)
        );
        for geographic in [
            "GEOGCS[\"WGS 84\",UNIT[\"degree\",0.0174532925199433]]",
            " geogcs [\"GCS_WGS_1984\"]",
            "GEOGCRS[\"WGS 84\",CS[ellipsoidal,2],ID[\"EPSG\",4326]]",
            "GEODCRS[\"WGS 84\",CS[ellipsoidal,2]]",
        ] {
            assert_eq!(
                wkt_unit(geographic),
                Some(CoordinateUnit::Degree),
                "{geographic}"
            );
        }
        assert_eq!(
            wkt_unit(
                "PROJCRS[\"x\",BASEGEOGCRS[\"y\",ANGLEUNIT[\"degree\",0.017]],\
                 CONVERSION[\"z\",PARAMETER[\"False easting\",0,LENGTHUNIT[\"metre\",1]]],\
                 CS[Cartesian,2],AXIS[\"easting\",east,LENGTHUNIT[\"foot\",0.3048]]]"
            ),
            Some(CoordinateUnit::Other("foot".into(), 0.3048))
        );
        for unreadable in [
            "",
            "junk",
            "GEODCRS[\"x\",CS[Cartesian,3]]",
            "PROJCS[\"x\",UNIT[\"m\",zero]]",
            "PROJCS[\"unclosed\",UNIT[\"metre\",1]",
            &"PROJCS[".repeat(100_000),
        ] {
            assert_eq!(wkt_unit(unreadable), None, "{unreadable:.40}");
        }
    }

    /// `gdalinfo -json` on the three formats: origin and pixel size of
    /// node registration, the EPSG code, the nodata value. Skipped (with a
    /// message) when `gdalinfo` is not on PATH.
    #[test]
    fn gdalinfo_reads_the_three_formats() {
        if !gdal_runs("gdalinfo") {
            return;
        }
        let dir = tempfile::tempdir().unwrap();
        let grid = sample_grid();
        let g = grid.geometry;
        let expected = [g.x0 - 25.0, 50.0, 0.0, g.y_max() + 25.0, 0.0, -50.0];
        for (name, nodata) in [
            ("g.tif", Some(NODATA)),
            ("g.asc", Some(NODATA)),
            ("g.nc", None),
        ] {
            let path = dir.path().join(name);
            write_grid(&path, &grid).unwrap();
            let out = std::process::Command::new("gdalinfo")
                .arg("-json")
                .arg(&path)
                .output()
                .unwrap();
            let json = String::from_utf8_lossy(&out.stdout);
            assert!(
                out.status.success(),
                "{name}: {}",
                String::from_utf8_lossy(&out.stderr)
            );
            let gt = json_numbers_after(&json, "\"geoTransform\"");
            assert_eq!(gt.len(), 6, "{name}: {json}");
            for (a, b) in gt.iter().zip(expected) {
                assert!(
                    (a - b).abs() < 1e-6,
                    "{name}: geoTransform {gt:?}, expected {expected:?}"
                );
            }
            assert!(
                json.contains("ID[\\\"EPSG\\\",32637]]"),
                "{name}: no EPSG 32637 in {json}"
            );
            let size = json_numbers_after(&json, "\"size\"");
            assert_eq!(size, [5.0, 4.0], "{name}");
            match nodata {
                Some(v) => assert_eq!(json_numbers_after(&json, "\"noDataValue\"")[0], v, "{name}"),
                None => assert!(json.contains("\"noDataValue\":\"NaN\""), "{name}: {json}"),
            }
        }
    }

    /// Valid files of the text and binary formats read here, each with its
    /// extension: GXF (plain and compressed), Surfer ASCII, 6 and 7 binary.
    fn valid_files() -> Vec<(&'static str, Vec<u8>)> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.gxf");
        write_grid(&path, &sample_grid()).unwrap();
        let gxf = fs::read(&path).unwrap();
        let compressed = COMPRESSED_GXF.as_bytes().to_vec();
        let ascii = SURFER_ASCII.as_bytes().to_vec();
        let mut six = b"DSBB".to_vec();
        six.extend(3i16.to_le_bytes());
        six.extend(2i16.to_le_bytes());
        for v in [100.0f64, 120.0, 200.0, 210.0, 1.0, 6.0] {
            six.extend(v.to_le_bytes());
        }
        for v in [1.0f32, 2.0, 3.0, 4.0, 1.70141e38, 6.0] {
            six.extend(v.to_le_bytes());
        }
        let mut seven = b"DSRB".to_vec();
        seven.extend(4i32.to_le_bytes());
        seven.extend(2i32.to_le_bytes());
        seven.extend(b"GRID");
        seven.extend(72i32.to_le_bytes());
        seven.extend(2i32.to_le_bytes());
        seven.extend(3i32.to_le_bytes());
        for v in [100.0f64, 200.0, 10.0, 10.0, 1.0, 6.0, 0.0, 1.70141e38] {
            seven.extend(v.to_le_bytes());
        }
        seven.extend(b"DATA");
        seven.extend(48i32.to_le_bytes());
        for v in [1.0f64, 2.0, 3.0, 4.0, 1.70141e38, 6.0] {
            seven.extend(v.to_le_bytes());
        }
        vec![
            ("gxf", gxf),
            ("gxf", compressed),
            ("grd", ascii),
            ("grd", six),
            ("grd", seven),
        ]
    }

    #[test]
    fn the_valid_files_of_the_hostile_file_test_read() {
        let dir = tempfile::tempdir().unwrap();
        for (k, (ext, bytes)) in valid_files().into_iter().enumerate() {
            let path = dir.path().join(format!("f{k}.{ext}"));
            fs::write(&path, &bytes).unwrap();
            read_grid(&path).unwrap_or_else(|e| panic!("file {k}: {e}"));
        }
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(200))]
        /// Damaged files (bytes changed, the file cut short) of the GXF and
        /// Surfer readers give a grid or an error, never a panic.
        #[test]
        fn damaged_gxf_and_surfer_files_are_errors_not_panics(
            which in 0usize..5,
            edits in proptest::collection::vec((0.0f64..1.0, proptest::prelude::any::<u8>()), 0..6),
            keep in 0.0f64..=1.0,
        ) {
            let (ext, mut bytes) = valid_files().swap_remove(which);
            for (at, byte) in edits {
                let k = ((bytes.len() as f64 * at) as usize).min(bytes.len() - 1);
                bytes[k] = byte;
            }
            bytes.truncate(((bytes.len() as f64 * keep).ceil() as usize).max(4));
            let dir = tempfile::tempdir().unwrap();
            let path = dir.path().join(format!("d.{ext}"));
            fs::write(&path, &bytes).unwrap();
            if let Err(e) = read_grid(&path) {
                proptest::prop_assert!(e.to_string().contains("d."), "{e}");
            }
        }
    }

    /// The numbers of the JSON value after `key` (a number or an array of
    /// numbers), by hand: the crate has no JSON parser.
    fn json_numbers_after(json: &str, key: &str) -> Vec<f64> {
        let Some(pos) = json.find(key) else {
            return vec![];
        };
        let rest = json[pos + key.len()..]
            .trim_start()
            .trim_start_matches(':')
            .trim_start();
        let end = if rest.starts_with('[') {
            rest.find(']').map(|e| e + 1).unwrap_or(rest.len())
        } else {
            rest.find([',', '}', '\n']).unwrap_or(rest.len())
        };
        rest[..end]
            .trim_matches(|c| c == '[' || c == ']')
            .split(',')
            .filter_map(|s| s.trim().parse().ok())
            .collect()
    }
}
