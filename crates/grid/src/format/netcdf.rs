//! netCDF classic, written by hand: the 64-bit-offset variant (CDF-2,
//! `CDF\x02`, big-endian) of Unidata's "NetCDF Classic Format
//! Specification", laid out as COARDS / CF-1.7 and GMT's netCDF grids
//! (`grdinfo`, `grdimage` read it as a gridline-registered grid; GDAL,
//! scipy, xarray and Geosoft as a plain CF grid).
//!
//! ```text
//! dimensions:  x = nx ; y = ny ;
//! variables:
//!   double x(x) ;  x:long_name = "Easting" ;  x:standard_name = "projection_x_coordinate" ;
//!                  x:units = "m" ;  x:actual_range = x0, x_max ;
//!   double y(y) ;  (the same: "Northing", "projection_y_coordinate", y0, y_max)
//!   int crs ;      crs:grid_mapping_name = "transverse_mercator" ; the UTM
//!                  parameters (CF names) ; crs:spatial_ref = crs:crs_wkt = WKT ;
//!                  crs:epsg_code = 32637 ;          (only when the CRS is known)
//!   float z(y, x) ; z:long_name = grid.name ; z:units = grid.unit ;
//!                  z:_FillValue = NaNf ; z:actual_range = min, max ;
//!                  z:grid_mapping = "crs" ;         (only when the CRS is known)
//! global attributes:
//!   :Conventions = "COARDS, CF-1.7" ; :title = grid.name ;
//!   :history = "aeromag-grid <version>" ; :node_offset = 0 ;
//! ```
//!
//! `x` and `y` are the node coordinates, both ascending: `z` is stored row
//! by row from the SOUTHERN row, as [`Grid::values`]. `node_offset = 0` is
//! GMT's gridline (node) registration; GDAL, which reads the coordinates as
//! cell centres, reports the origin `(x0 − cell/2, y_max + cell/2)`. Blank
//! nodes are NaN, the `_FillValue`. The data are float32 (0.004 nT at
//! 50 000 nT); `actual_range` of `z` is of the variable's type (float), NaN
//! for an all-blank grid. The 64-bit offsets leave the file size unlimited
//! (CDF-1 stops at 2 GiB); every netCDF library since 3.6 reads CDF-2.
//!
//! [`read`] reads classic files (CDF-1 and CDF-2), and netCDF-4 files (HDF5:
//! GMT 6's and xarray's default; [`super::netcdf4`]), holding a 2-D variable
//! (`z`, else the first 2-D one) with 1-D coordinate variables of regular
//! and equal spacing, `y` ascending or descending; it applies `_FillValue`
//! / `missing_value`, `scale_factor` and `add_offset`, and takes the CRS
//! from the grid-mapping variable (`epsg_code`, else the WKT of
//! `crs_wkt`/`spatial_ref`). The coordinates must be metres, or
//! kilometres (`units = "km"`, converted to metres: the grid read, and any
//! grid written from it, is in metres); coordinates in degrees
//! (`degrees_east`/`degrees_north`, a `latitude_longitude` grid mapping, a
//! geographic WKT) are refused. `units` this crate does not
//! know are taken as metres. Values in a magnetic-field unit other than nT
//! (`units = "T"`, as CF's SI units have it, `µT`, `pT`, `T/m`, …) are
//! taken to nT (`nT`, `nT/m`).

use std::fs;
use std::io::{self, Write};
use std::path::Path;

use super::{
    CoordinateUnit, check_grid, check_values, checked_geometry, crs_from_epsg, crs_from_wkt,
    crs_wkt, in_nanotesla, label_from_file, not_metres_reason, open_error, read_error, wkt_unit,
    write_atomic,
};
use crate::error::Result;
use crate::grid::{Grid, GridGeometry};
use crate::projection::Crs;
use aeromag_core::error::{shown, shown_text};

const NC_DIMENSION: u32 = 0x0A;
const NC_VARIABLE: u32 = 0x0B;
const NC_ATTRIBUTE: u32 = 0x0C;

/// netCDF external types.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum NcType {
    Byte = 1,
    Char = 2,
    Short = 3,
    Int = 4,
    Float = 5,
    Double = 6,
}

impl NcType {
    fn size(self) -> usize {
        match self {
            NcType::Byte | NcType::Char => 1,
            NcType::Short => 2,
            NcType::Int | NcType::Float => 4,
            NcType::Double => 8,
        }
    }

    fn from_code(code: u32) -> Option<Self> {
        Some(match code {
            1 => NcType::Byte,
            2 => NcType::Char,
            3 => NcType::Short,
            4 => NcType::Int,
            5 => NcType::Float,
            6 => NcType::Double,
            _ => return None,
        })
    }
}

/// An attribute value.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Value {
    Text(String),
    Int(Vec<i32>),
    Float(Vec<f32>),
    Double(Vec<f64>),
    /// Bytes and shorts (read only), as f64.
    Other(Vec<f64>),
}

impl Value {
    fn text(s: &str) -> Self {
        Value::Text(s.to_string())
    }

    /// The numbers of a numeric attribute.
    fn numbers(&self) -> Vec<f64> {
        match self {
            Value::Text(_) => vec![],
            Value::Int(v) => v.iter().map(|&x| x.into()).collect(),
            Value::Float(v) => v.iter().map(|&x| x.into()).collect(),
            Value::Double(v) | Value::Other(v) => v.clone(),
        }
    }
}

pub(super) type Attributes = Vec<(String, Value)>;

/// A variable of the header.
pub(super) struct Variable {
    pub(super) name: String,
    pub(super) dims: Vec<usize>,
    pub(super) attributes: Attributes,
    pub(super) nc_type: NcType,
    /// Offset of the data (read: from the file; write: computed; netCDF-4:
    /// none, 0).
    pub(super) begin: u64,
}

impl Variable {
    fn attribute(&self, name: &str) -> Option<&Value> {
        self.attributes
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v)
    }
}

/// The header's bytes: `dims` (name, length), global attributes and the
/// variables (their `begin` as given); CDF-2 (64-bit offsets) when `wide`,
/// else CDF-1.
fn header(wide: bool, dims: &[(&str, usize)], globals: &Attributes, vars: &[Variable]) -> Vec<u8> {
    let mut h = Vec::new();
    h.extend_from_slice(if wide { b"CDF\x02" } else { b"CDF\x01" });
    put_u32(&mut h, 0); // numrecs
    put_u32(&mut h, NC_DIMENSION);
    put_u32(&mut h, dims.len() as u32);
    for (name, len) in dims {
        put_name(&mut h, name);
        put_u32(&mut h, *len as u32);
    }
    put_attributes(&mut h, globals);
    put_u32(&mut h, NC_VARIABLE);
    put_u32(&mut h, vars.len() as u32);
    for v in vars {
        put_name(&mut h, &v.name);
        put_u32(&mut h, v.dims.len() as u32);
        for &d in &v.dims {
            put_u32(&mut h, d as u32);
        }
        put_attributes(&mut h, &v.attributes);
        put_u32(&mut h, v.nc_type as u32);
        // vsize, padded to 4; 2³²−1 when it does not fit (the last variable).
        let size = data_size(v, dims);
        put_u32(
            &mut h,
            u32::try_from(size.next_multiple_of(4)).unwrap_or(u32::MAX),
        );
        if wide {
            h.extend_from_slice(&v.begin.to_be_bytes());
        } else {
            put_u32(&mut h, v.begin as u32);
        }
    }
    h
}

/// Sets the `begin` of the variables, one after the other after the
/// header, and returns the header.
fn layout(
    wide: bool,
    dims: &[(&str, usize)],
    globals: &Attributes,
    vars: &mut [Variable],
) -> Vec<u8> {
    // The header's length does not depend on the offsets it holds.
    let mut begin = header(wide, dims, globals, vars).len() as u64;
    for v in vars.iter_mut() {
        v.begin = begin;
        begin += data_size(v, dims).next_multiple_of(4);
    }
    header(wide, dims, globals, vars)
}

fn data_size(v: &Variable, dims: &[(&str, usize)]) -> u64 {
    v.dims.iter().map(|&d| dims[d].1 as u64).product::<u64>() * v.nc_type.size() as u64
}

fn put_u32(h: &mut Vec<u8>, v: u32) {
    h.extend_from_slice(&v.to_be_bytes());
}

fn pad4(h: &mut Vec<u8>) {
    while !h.len().is_multiple_of(4) {
        h.push(0);
    }
}

fn put_name(h: &mut Vec<u8>, name: &str) {
    put_u32(h, name.len() as u32);
    h.extend_from_slice(name.as_bytes());
    pad4(h);
}

fn put_attributes(h: &mut Vec<u8>, attributes: &Attributes) {
    if attributes.is_empty() {
        // ABSENT: ZERO ZERO.
        put_u32(h, 0);
        put_u32(h, 0);
        return;
    }
    put_u32(h, NC_ATTRIBUTE);
    put_u32(h, attributes.len() as u32);
    for (name, value) in attributes {
        put_name(h, name);
        match value {
            Value::Text(s) => {
                put_u32(h, NcType::Char as u32);
                put_u32(h, s.len() as u32);
                h.extend_from_slice(s.as_bytes());
            }
            Value::Int(v) => {
                put_u32(h, NcType::Int as u32);
                put_u32(h, v.len() as u32);
                v.iter().for_each(|x| h.extend_from_slice(&x.to_be_bytes()));
            }
            Value::Float(v) => {
                put_u32(h, NcType::Float as u32);
                put_u32(h, v.len() as u32);
                v.iter().for_each(|x| h.extend_from_slice(&x.to_be_bytes()));
            }
            Value::Double(v) | Value::Other(v) => {
                put_u32(h, NcType::Double as u32);
                put_u32(h, v.len() as u32);
                v.iter().for_each(|x| h.extend_from_slice(&x.to_be_bytes()));
            }
        }
        pad4(h);
    }
}

/// The CF grid-mapping attributes of a CRS.
fn grid_mapping(crs: &Crs) -> Attributes {
    let Crs::Utm(zone) = crs;
    let false_northing = if zone.north { 0.0 } else { 10_000_000.0 };
    let wkt = crs_wkt(crs);
    let d = |x: f64| Value::Double(vec![x]);
    vec![
        (
            "grid_mapping_name".into(),
            Value::text("transverse_mercator"),
        ),
        (
            "longitude_of_central_meridian".into(),
            d(zone.central_meridian_deg()),
        ),
        ("latitude_of_projection_origin".into(), d(0.0)),
        ("scale_factor_at_central_meridian".into(), d(0.9996)),
        ("false_easting".into(), d(500_000.0)),
        ("false_northing".into(), d(false_northing)),
        ("semi_major_axis".into(), d(6_378_137.0)),
        ("inverse_flattening".into(), d(298.257_223_563)),
        ("longitude_of_prime_meridian".into(), d(0.0)),
        ("projected_crs_name".into(), Value::Text(crs.name())),
        ("spatial_ref".into(), Value::Text(wkt.clone())),
        ("crs_wkt".into(), Value::Text(wkt)),
        ("epsg_code".into(), Value::Int(vec![crs.epsg().into()])),
    ]
}

/// Writes `grid` as netCDF to `path`, atomically (module docs for the
/// layout). Errors as
/// [`write_grid`](super::write_grid).
pub fn write(path: &Path, grid: &Grid) -> Result<()> {
    check_grid(grid)?;
    let g = &grid.geometry;
    let stats = grid.stats();
    let coordinate = |long: &str, standard: &str, lo: f64, hi: f64, dim: usize| Variable {
        name: standard[11..12].to_string(), // "projection_x_coordinate" → "x"
        dims: vec![dim],
        attributes: vec![
            ("long_name".into(), Value::text(long)),
            ("standard_name".into(), Value::text(standard)),
            ("units".into(), Value::text("m")),
            ("actual_range".into(), Value::Double(vec![lo, hi])),
        ],
        nc_type: NcType::Double,
        begin: 0,
    };
    let mut vars = vec![
        coordinate("Easting", "projection_x_coordinate", g.x0, g.x_max(), 0),
        coordinate("Northing", "projection_y_coordinate", g.y0, g.y_max(), 1),
    ];
    let mut z_attributes: Attributes = vec![
        ("long_name".into(), Value::Text(grid.name.clone())),
        ("units".into(), Value::Text(grid.unit.clone())),
        ("_FillValue".into(), Value::Float(vec![f32::NAN])),
        (
            "actual_range".into(),
            Value::Float(vec![stats.min as f32, stats.max as f32]),
        ),
    ];
    if let Some(crs) = &grid.crs {
        vars.push(Variable {
            name: "crs".into(),
            dims: vec![],
            attributes: grid_mapping(crs),
            nc_type: NcType::Int,
            begin: 0,
        });
        z_attributes.push(("grid_mapping".into(), Value::text("crs")));
    }
    vars.push(Variable {
        name: "z".into(),
        dims: vec![1, 0],
        attributes: z_attributes,
        nc_type: NcType::Float,
        begin: 0,
    });
    let globals: Attributes = vec![
        ("Conventions".into(), Value::text("COARDS, CF-1.7")),
        ("title".into(), Value::Text(grid.name.clone())),
        (
            "history".into(),
            Value::Text(format!("aeromag-grid {}", env!("CARGO_PKG_VERSION"))),
        ),
        ("node_offset".into(), Value::Int(vec![0])),
    ];
    let dims = [("x", g.nx), ("y", g.ny)];
    let head = layout(true, &dims, &globals, &mut vars);
    write_atomic(path, |w| {
        w.write_all(&head)?;
        for v in &vars {
            match v.name.as_str() {
                "x" => (0..g.nx).try_for_each(|i| w.write_all(&g.x(i).to_be_bytes()))?,
                "y" => (0..g.ny).try_for_each(|j| w.write_all(&g.y(j).to_be_bytes()))?,
                "crs" => w.write_all(&0i32.to_be_bytes())?,
                _ => write_z(w, &grid.values)?,
            }
        }
        Ok(())
    })
}

fn write_z(w: &mut impl Write, values: &[f64]) -> io::Result<()> {
    let mut buf = Vec::with_capacity(1 << 16);
    for chunk in values.chunks(1 << 14) {
        buf.clear();
        for &v in chunk {
            buf.extend_from_slice(&(v as f32).to_be_bytes());
        }
        w.write_all(&buf)?;
    }
    Ok(())
}

/// A reader of the header's big-endian fields.
struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
}

/// A parse failure (the caller adds the file name).
pub(super) type Parse<T> = std::result::Result<T, String>;

impl Cursor<'_> {
    fn take(&mut self, n: usize) -> Parse<&[u8]> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.bytes.len());
        let end = end.ok_or_else(|| format!("truncated header at byte {}", self.pos))?;
        let s = &self.bytes[self.pos..end];
        self.pos = end;
        Ok(s)
    }

    fn u32(&mut self) -> Parse<u32> {
        Ok(u32::from_be_bytes(self.take(4)?.try_into().unwrap()))
    }

    fn u64(&mut self) -> Parse<u64> {
        Ok(u64::from_be_bytes(self.take(8)?.try_into().unwrap()))
    }

    fn count(&mut self) -> Parse<usize> {
        Ok(self.u32()? as usize)
    }

    fn padded(&mut self, n: usize) -> Parse<&[u8]> {
        let start = self.pos;
        self.take(n.next_multiple_of(4))?;
        Ok(&self.bytes[start..start + n])
    }

    fn name(&mut self) -> Parse<String> {
        let n = self.count()?;
        Ok(String::from_utf8_lossy(self.padded(n)?).into_owned())
    }

    /// A list's tag and count (`ABSENT` is 0, 0).
    fn list(&mut self, tag: u32) -> Parse<usize> {
        let (t, n) = (self.u32()?, self.count()?);
        if t == tag || (t == 0 && n == 0) {
            Ok(n)
        } else {
            Err(format!("expected list tag {tag}, found {t}"))
        }
    }

    fn attributes(&mut self) -> Parse<Attributes> {
        let n = self.list(NC_ATTRIBUTE)?;
        let mut out = Vec::with_capacity(n.min(1024));
        for _ in 0..n {
            let name = self.name()?;
            let code = self.u32()?;
            let t = NcType::from_code(code).ok_or_else(|| format!("attribute type {code}"))?;
            let count = self.count()?;
            let len = count.checked_mul(t.size()).ok_or("attribute too long")?;
            let bytes = self.padded(len)?;
            let value = match t {
                NcType::Char => Value::Text(
                    String::from_utf8_lossy(bytes)
                        .trim_end_matches('\0')
                        .to_string(),
                ),
                NcType::Int => Value::Int(
                    bytes
                        .chunks_exact(4)
                        .map(|b| i32::from_be_bytes(b.try_into().unwrap()))
                        .collect(),
                ),
                _ => Value::Other(decode(bytes, t)),
            };
            out.push((name, value));
        }
        Ok(out)
    }
}

/// Big-endian numbers of type `t` as f64.
fn decode(bytes: &[u8], t: NcType) -> Vec<f64> {
    match t {
        NcType::Byte | NcType::Char => bytes.iter().map(|&b| (b as i8).into()).collect(),
        NcType::Short => bytes
            .chunks_exact(2)
            .map(|b| i16::from_be_bytes(b.try_into().unwrap()).into())
            .collect(),
        NcType::Int => bytes
            .chunks_exact(4)
            .map(|b| i32::from_be_bytes(b.try_into().unwrap()).into())
            .collect(),
        NcType::Float => bytes
            .chunks_exact(4)
            .map(|b| f32::from_be_bytes(b.try_into().unwrap()).into())
            .collect(),
        NcType::Double => bytes
            .chunks_exact(8)
            .map(|b| f64::from_be_bytes(b.try_into().unwrap()))
            .collect(),
    }
}

/// The parsed header of a classic file (or the same from a netCDF-4 file,
/// [`super::netcdf4`]).
pub(super) struct Header {
    pub(super) dims: Vec<(String, usize)>,
    pub(super) vars: Vec<Variable>,
}

fn parse_header(bytes: &[u8]) -> Parse<Header> {
    let mut c = Cursor { bytes, pos: 0 };
    let magic = c.take(4).map_err(|_| "not a netCDF file".to_string())?;
    let wide = match magic {
        b"CDF\x01" => false,
        b"CDF\x02" => true,
        b"CDF\x05" => return Err("netCDF CDF-5 (64-bit data) is not read".into()),
        m if m.starts_with(b"\x89HDF") => {
            return Err("netCDF-4 (HDF5) is read from a file, not from bytes".into());
        }
        _ if super::geosoft::looks_geosoft(bytes) => {
            return Err("a Geosoft binary grid, not netCDF: read it with read_grid".into());
        }
        _ => return Err("not a netCDF classic file".into()),
    };
    c.u32()?; // numrecs
    let n = c.list(NC_DIMENSION)?;
    let mut dims = Vec::with_capacity(n.min(1024));
    for _ in 0..n {
        dims.push((c.name()?, c.count()?));
    }
    c.attributes()?; // globals
    let n = c.list(NC_VARIABLE)?;
    let mut vars = Vec::with_capacity(n.min(1024));
    for _ in 0..n {
        let name = c.name()?;
        let ndims = c.count()?;
        let mut ids = Vec::with_capacity(ndims.min(64));
        for _ in 0..ndims {
            let d = c.count()?;
            if d >= dims.len() {
                return Err(format!(
                    "variable {}: dimension {d} does not exist",
                    shown_text(&name)
                ));
            }
            ids.push(d);
        }
        let attributes = c.attributes()?;
        let code = c.u32()?;
        let nc_type = NcType::from_code(code).ok_or_else(|| format!("variable type {code}"))?;
        c.u32()?; // vsize
        let begin = if wide { c.u64()? } else { c.u32()?.into() };
        vars.push(Variable {
            name,
            dims: ids,
            attributes,
            nc_type,
            begin,
        });
    }
    Ok(Header { dims, vars })
}

impl Header {
    /// The values of a fixed-size variable, as f64.
    fn data(&self, bytes: &[u8], v: &Variable) -> Parse<Vec<f64>> {
        let mut n = 1usize;
        for &d in &v.dims {
            let len = self.dims[d].1;
            if len == 0 {
                return Err(format!(
                    "{} is a record variable: not read",
                    shown_text(&v.name)
                ));
            }
            n = n.checked_mul(len).ok_or("too large")?;
        }
        let len = n.checked_mul(v.nc_type.size()).ok_or("too large")?;
        let start = usize::try_from(v.begin).map_err(|_| "offset too large")?;
        let data = start
            .checked_add(len)
            .and_then(|end| bytes.get(start..end))
            .ok_or_else(|| {
                format!(
                    "the data of {} are past the end of the file",
                    shown_text(&v.name)
                )
            })?;
        Ok(decode(data, v.nc_type))
    }

    /// The 1-D coordinate variable of dimension `d`.
    fn coordinate(&self, d: usize) -> Parse<&Variable> {
        let name = &self.dims[d].0;
        self.vars
            .iter()
            .find(|v| &v.name == name && v.dims == [d])
            .ok_or_else(|| format!("no coordinate variable {}", shown_text(name)))
    }
}

/// Origin and spacing of regular coordinates (`None` spacing for a single
/// value).
fn regular(values: &[f64], name: &str) -> Parse<(f64, Option<f64>)> {
    let step = crate::grid::axis_spacing(values, name)
        .map_err(|_| format!("{} is not regularly spaced", shown_text(name)))?;
    Ok((values[0], step))
}

/// Metres in a kilometre, the one other unit of coordinates read.
const METRES_PER_KM: f64 = 1000.0;

/// The values of coordinate variable `v` in metres, by its `units` (and
/// `standard_name`): metres (`m`, `metre(s)`, `meter(s)`), no unit, or one
/// this crate does not know are taken as they are; kilometres (`km`,
/// `kilometre(s)`, `kilometer(s)`, as GMT grids in km have) are converted
/// to metres and rounded to the micrometre (the decimal error of a km
/// value in float64, ~10⁻¹⁰ m, must not make the cell 100.00000000000001
/// m); degrees (`degrees_east`, `degrees_north`, `degree`, `deg`; without
/// units, a `standard_name` of `longitude` or `latitude`) are refused: every
/// computation on a grid takes its cell in metres, and a 0.001° cell read
/// as 0.001 m gave a vertical derivative 10⁵ times too large.
fn in_metres(mut values: Vec<f64>, v: &Variable) -> Parse<Vec<f64>> {
    let attribute = |name: &str| match v.attribute(name) {
        Some(Value::Text(s)) => s.trim().to_string(),
        _ => String::new(),
    };
    let (raw, standard) = (attribute("units"), attribute("standard_name"));
    let units = raw.to_ascii_lowercase();
    let by = if units.starts_with("degree") || units == "deg" {
        format!(
            "the units attribute of {} ({})",
            shown_text(&v.name),
            shown_text(&raw)
        )
    } else if units.is_empty() && (standard == "longitude" || standard == "latitude") {
        format!(
            "the standard_name of {} ({})",
            shown_text(&v.name),
            shown_text(&standard)
        )
    } else {
        String::new()
    };
    if !by.is_empty() {
        return Err(not_metres_reason(&by, &CoordinateUnit::Degree));
    }
    if matches!(
        units.as_str(),
        "km" | "kilometre" | "kilometres" | "kilometer" | "kilometers"
    ) {
        for x in &mut values {
            *x = (*x * METRES_PER_KM * 1e6).round() / 1e6;
        }
    }
    Ok(values)
}

/// Reads a netCDF grid, classic or netCDF-4 ([`super::netcdf4`]; module
/// docs for what is accepted).
pub fn read(path: &Path) -> Result<Grid> {
    let (geometry, grid) = if aeromag_core::file_name::is_hdf5(path) {
        super::netcdf4::read(path)?
    } else {
        let bytes = fs::read(path).map_err(|e| open_error(path, e))?;
        read_bytes(&bytes).map_err(|e| read_error(path, e))?
    };
    checked_geometry(path, geometry)?;
    check_values(path, &grid)?;
    Ok(grid)
}

fn read_bytes(bytes: &[u8]) -> Parse<(GridGeometry, Grid)> {
    let h = parse_header(bytes)?;
    interpret(&h, |v| h.data(bytes, v))
}

/// The grid of a netCDF file's variables (module docs), the data of a
/// variable given by `data`.
pub(super) fn interpret(
    h: &Header,
    data: impl Fn(&Variable) -> Parse<Vec<f64>>,
) -> Parse<(GridGeometry, Grid)> {
    let z = h
        .vars
        .iter()
        .find(|v| v.name == "z" && v.dims.len() == 2)
        .or_else(|| h.vars.iter().find(|v| v.dims.len() == 2))
        .ok_or("no 2-D variable")?;
    if z.nc_type == NcType::Char {
        return Err(format!("{} is text", shown_text(&z.name)));
    }
    let (ydim, xdim) = (z.dims[0], z.dims[1]);
    let text = |v: &Variable, name: &str| match v.attribute(name) {
        Some(Value::Text(s)) => Some(s.clone()),
        _ => None,
    };
    let mapping = text(z, "grid_mapping").and_then(|m| h.vars.iter().find(|v| v.name == m));
    if let Some(m) = mapping {
        if text(m, "grid_mapping_name").as_deref() == Some("latitude_longitude") {
            let by = "its grid mapping (latitude_longitude)";
            return Err(not_metres_reason(by, &CoordinateUnit::Degree));
        }
        let wkt = text(m, "crs_wkt").or_else(|| text(m, "spatial_ref"));
        if let Some(unit) = wkt
            .and_then(|w| wkt_unit(&w))
            .filter(|u| *u != CoordinateUnit::Metre)
        {
            return Err(not_metres_reason("its grid mapping's WKT", &unit));
        }
    }
    let (x_var, y_var) = (h.coordinate(xdim)?, h.coordinate(ydim)?);
    let xs = in_metres(data(x_var)?, x_var)?;
    let ys = in_metres(data(y_var)?, y_var)?;
    let (x0, dx) = regular(&xs, &h.dims[xdim].0)?;
    let (y_first, dy) = regular(&ys, &h.dims[ydim].0)?;
    let cell = match (dx, dy) {
        (Some(dx), Some(dy)) if (dx - dy.abs()).abs() <= 1e-6 * dx => dx,
        (Some(dx), None) if dx > 0.0 => dx,
        (None, Some(dy)) => dy.abs(),
        (None, None) => return Err("a single node: the cell size is unknown".into()),
        _ => {
            let step = |d: Option<f64>| d.map_or("none".into(), shown);
            return Err(format!(
                "cells of {} × {}: x must ascend and cells be square",
                step(dx),
                step(dy)
            ));
        }
    };
    let south_first = dy.is_none_or(|dy| dy > 0.0);
    let (nx, ny) = (xs.len(), ys.len());
    let y0 = if south_first { y_first } else { ys[ny - 1] };
    let geometry = GridGeometry {
        x0,
        y0,
        cell,
        nx,
        ny,
    };
    let mut values = data(z)?;
    let number = |name: &str| z.attribute(name).and_then(|v| v.numbers().first().copied());
    let fill = number("_FillValue").or_else(|| number("missing_value"));
    let (scale, offset) = (
        number("scale_factor").unwrap_or(1.0),
        number("add_offset").unwrap_or(0.0),
    );
    for v in &mut values {
        *v = if Some(*v) == fill {
            f64::NAN
        } else {
            *v * scale + offset
        };
    }
    if !south_first {
        values = values.chunks_exact(nx).rev().flatten().copied().collect();
    }
    let crs = mapping.and_then(|m| {
        let epsg = m
            .attribute("epsg_code")
            .and_then(|v| v.numbers().first().copied());
        epsg.and_then(|c| crs_from_epsg(c as u32)).or_else(|| {
            text(m, "crs_wkt")
                .or_else(|| text(m, "spatial_ref"))
                .and_then(|w| crs_from_wkt(&w))
        })
    });
    // A field in tesla (CF's SI units) is taken to nT, as every command
    // works in nT.
    let mut unit = text(z, "units").unwrap_or_default();
    if let Some((factor, nt)) = in_nanotesla(&unit) {
        values.iter_mut().for_each(|v| *v *= factor);
        unit = nt;
    }
    let grid = Grid {
        geometry,
        values,
        crs,
        name: label_from_file(&text(z, "long_name").unwrap_or_else(|| z.name.clone())),
        unit: label_from_file(&unit),
    };
    Ok((geometry, grid))
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::super::{GridFormat, read_grid, write_grid};
    use super::*;

    #[test]
    fn netcdf_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("g.nc");
        let grid = sample_grid();
        assert_eq!(write_grid(&path, &grid).unwrap(), GridFormat::NetCdf);
        let back = read_grid(&path).unwrap();
        assert_same_grid(&grid, &back);
        assert_eq!(
            (back.name.as_str(), back.unit.as_str()),
            ("magnetic anomaly", "nT")
        );
        assert_eq!(entries(dir.path()), ["g.nc"]);

        let bytes = fs::read(&path).unwrap();
        assert_eq!(&bytes[..4], b"CDF\x02");
        let h = parse_header(&bytes).unwrap();
        assert_eq!(h.dims, [("x".to_string(), 5), ("y".to_string(), 4)]);
        let names: Vec<&str> = h.vars.iter().map(|v| v.name.as_str()).collect();
        assert_eq!(names, ["x", "y", "crs", "z"]);
        let var = |n: &str| h.vars.iter().find(|v| v.name == n).unwrap();
        assert_eq!(
            h.data(&bytes, var("y")).unwrap(),
            [6_000_050.0, 6_000_100.0, 6_000_150.0, 6_000_200.0]
        );
        assert_eq!(
            var("x").attribute("actual_range").unwrap().numbers(),
            [500_000.0, 500_200.0]
        );
        assert_eq!(var("x").attribute("units"), Some(&Value::text("m")));
        assert_eq!(
            var("y").attribute("long_name"),
            Some(&Value::text("Northing"))
        );
        let z = var("z");
        assert_eq!(z.dims, [1, 0]);
        assert_eq!(z.nc_type, NcType::Float);
        assert_eq!(z.attribute("grid_mapping"), Some(&Value::text("crs")));
        assert!(z.attribute("_FillValue").unwrap().numbers()[0].is_nan());
        assert_eq!(
            z.attribute("actual_range").unwrap().numbers(),
            [-51_234.566_406_25, 3_003.123_535_156_25]
        );
        let zs = h.data(&bytes, z).unwrap();
        assert_eq!(zs[0] as f32, 0.123_456_79); // south-west node first
        assert!(zs[1].is_nan());
        let crs = var("crs");
        assert_eq!(crs.attribute("epsg_code"), Some(&Value::Int(vec![32637])));
        assert_eq!(
            crs.attribute("grid_mapping_name"),
            Some(&Value::text("transverse_mercator"))
        );
        assert_eq!(
            crs.attribute("longitude_of_central_meridian")
                .unwrap()
                .numbers(),
            [39.0]
        );
        let Some(Value::Text(wkt)) = crs.attribute("crs_wkt") else {
            panic!()
        };
        assert!(wkt.ends_with("AUTHORITY[\"EPSG\",\"32637\"]]"));
        // The data end the file (no gap, no trailing bytes).
        assert_eq!(z.begin as usize + 4 * 20, bytes.len());
    }

    #[test]
    fn netcdf_without_crs_and_all_blank() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("b.grd");
        let mut grid = sample_grid();
        grid.crs = None;
        grid.values.fill(f64::NAN);
        grid.name = String::new();
        write_grid(&path, &grid).unwrap();
        let bytes = fs::read(&path).unwrap();
        let h = parse_header(&bytes).unwrap();
        assert!(h.vars.iter().all(|v| v.name != "crs"));
        let back = read(&path).unwrap();
        assert_same_grid(&grid, &back);
    }

    #[test]
    fn netcdf_reads_descending_y_cdf1_and_packed_values() {
        // A CDF-1 file as GDAL writes it: y descending (north first),
        // values packed in shorts with a fill value.
        let dims = [("lon", 3usize), ("lat", 2usize)];
        let mut vars = vec![
            Variable {
                name: "lon".into(),
                dims: vec![0],
                attributes: vec![],
                nc_type: NcType::Double,
                begin: 0,
            },
            Variable {
                name: "lat".into(),
                dims: vec![1],
                attributes: vec![],
                nc_type: NcType::Float,
                begin: 0,
            },
            Variable {
                name: "Band1".into(),
                dims: vec![1, 0],
                attributes: vec![
                    ("_FillValue".into(), Value::Other(vec![-1.0])),
                    ("scale_factor".into(), Value::Double(vec![0.5])),
                ],
                nc_type: NcType::Short,
                begin: 0,
            },
        ];
        let mut cdf1 = layout(false, &dims, &vec![], &mut vars);
        assert_eq!(&cdf1[..4], b"CDF\x01");
        for x in [100.0f64, 110.0, 120.0] {
            cdf1.extend_from_slice(&x.to_be_bytes());
        }
        for y in [210.0f32, 200.0] {
            cdf1.extend_from_slice(&y.to_be_bytes());
        }
        for z in [1i16, 2, 3, 4, -1, 6] {
            cdf1.extend_from_slice(&z.to_be_bytes());
        }
        let (geometry, grid) = read_bytes(&cdf1).unwrap();
        assert_eq!(
            geometry,
            GridGeometry {
                x0: 100.0,
                y0: 200.0,
                cell: 10.0,
                nx: 3,
                ny: 2
            }
        );
        // South row first; -1 is the fill, the rest is scaled by 0.5.
        assert_eq!(grid.values[0], 2.0);
        assert!(grid.values[1].is_nan());
        assert_eq!(grid.values[2..], [3.0, 0.5, 1.0, 1.5]);
        assert_eq!(grid.name, "Band1");
        assert_eq!(grid.crs, None);
    }

    #[test]
    fn netcdf_rejects_what_it_cannot_read() {
        assert!(read_bytes(b"CDF\x05").unwrap_err().contains("CDF-5"));
        assert!(read_bytes(b"\x89HDF\r\n").unwrap_err().contains("netCDF-4"));
        assert!(read_bytes(b"GIF89a").is_err());
        // A Geosoft grid's header: float32 (4, sign flag 2), 5 × 4, rows.
        let geosoft: Vec<u8> = [4i32, 2, 5, 4, 1]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .chain([0u8; 492])
            .collect();
        assert!(
            read_bytes(&geosoft)
                .unwrap_err()
                .contains("Geosoft binary grid")
        );
        assert!(
            read_bytes(b"CDF\x02\0\0")
                .unwrap_err()
                .contains("truncated")
        );
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("g.nc");
        write_grid(&path, &sample_grid()).unwrap();
        let bytes = fs::read(&path).unwrap();
        // Truncated data.
        assert!(
            read_bytes(&bytes[..bytes.len() - 1])
                .unwrap_err()
                .contains("past the end")
        );
        let e = read(&dir.path().join("missing.nc")).unwrap_err();
        assert!(e.to_string().contains("missing.nc"), "{e}");
    }

    #[test]
    fn a_corrupt_name_is_shown_escaped_and_short() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("g.nc");
        write_grid(&path, &sample_grid()).unwrap();
        let mut bytes = fs::read(&path).unwrap();
        // The variable 'y' (the second name "y" of the header; the first is
        // the dimension's): its length byte flipped from 1 to 129.
        let name = [0u8, 0, 0, 1, b'y', 0, 0, 0];
        let at = bytes
            .windows(8)
            .enumerate()
            .filter(|(_, w)| *w == name)
            .nth(1)
            .unwrap()
            .0;
        bytes[at + 3] = 129;
        fs::write(&path, &bytes).unwrap();
        let e = read(&path).unwrap_err().to_string();
        assert!(e.contains("g.nc"), "{e}");
        assert!(!e.chars().any(|c| c.is_control()) && e.len() < 200, "{e}");
    }

    /// A field in tesla (CF's SI units; finding 08's `unitsT.nc`) was
    /// carried in tesla, its vertical derivative printed as 0.0000 T/m:
    /// it is read in nT, and so is a gradient in T/m; nT and other units
    /// (metres of a DEM) are read as written.
    #[test]
    fn a_field_in_tesla_is_read_in_nanotesla() {
        let dir = tempfile::tempdir().unwrap();
        let nt = sample_grid();
        for (unit, factor, read_as) in [
            ("T", 1e-9, "nT"),
            ("µT", 1e-3, "nT"),
            ("pT", 1e3, "nT"),
            ("T/m", 1e-9, "nT/m"),
            ("gamma", 1.0, "nT"),
            ("nT", 1.0, "nT"),
            ("m", 1.0, "m"),
        ] {
            let mut g = nt.clone();
            g.unit = unit.into();
            g.values.iter_mut().for_each(|v| *v *= factor);
            let path = dir.path().join("t.nc");
            write_grid(&path, &g).unwrap();
            let back = read_grid(&path).unwrap();
            assert_eq!(back.unit, read_as, "{unit}");
            assert_eq!(back.geometry, nt.geometry);
            // float32 in the file: within two of its roundings.
            for (k, (x, y)) in nt.values.iter().zip(&back.values).enumerate() {
                assert!(
                    (x.is_nan() && y.is_nan()) || (x - y).abs() <= 2.4e-7 * x.abs(),
                    "{unit} node {k}: {x} read as {y}"
                );
            }
        }
    }

    /// A CDF-1 file of 3 × 2 nodes, x 437.1–437.3 and y 6206.4–6206.5,
    /// whose `x` and `y` have the `units` given (none when empty) and `y`
    /// the `standard_name` given (none when empty).
    fn grid_with_units(x_units: &str, y_units: &str, y_standard: &str) -> Vec<u8> {
        let text = |name: &str, u: &str| match u {
            "" => vec![],
            u => vec![(name.to_string(), Value::text(u))],
        };
        let dims = [("x", 3usize), ("y", 2usize)];
        let mut vars = vec![
            Variable {
                name: "x".into(),
                dims: vec![0],
                attributes: text("units", x_units),
                nc_type: NcType::Double,
                begin: 0,
            },
            Variable {
                name: "y".into(),
                dims: vec![1],
                attributes: [text("units", y_units), text("standard_name", y_standard)].concat(),
                nc_type: NcType::Double,
                begin: 0,
            },
            Variable {
                name: "z".into(),
                dims: vec![1, 0],
                attributes: vec![],
                nc_type: NcType::Float,
                begin: 0,
            },
        ];
        let mut b = layout(false, &dims, &vec![], &mut vars);
        for v in [437.1f64, 437.2, 437.3, 6206.4, 6206.5] {
            b.extend_from_slice(&v.to_be_bytes());
        }
        for z in [1f32, 2.0, 3.0, 4.0, 5.0, 6.0] {
            b.extend_from_slice(&z.to_be_bytes());
        }
        b
    }

    /// x/y in degrees (`degrees_east`, `degrees_north`) were read as
    /// metres: a 0.001° cell as 0.001 m, a vertical derivative 10⁵ times
    /// too large (finding 08). Now refused naming the variable and its
    /// unit; kilometres (read as metres, 1000 times off) are converted to
    /// metres exactly; metres and unknown units are read as before.
    #[test]
    fn coordinates_in_degrees_are_refused_and_kilometres_converted() {
        for (x, y, standard, named) in [
            (
                "degrees_east",
                "degrees_north",
                "",
                "the units attribute of \"x\" (\"degrees_east\")",
            ),
            (
                "m",
                "degree_N",
                "",
                "the units attribute of \"y\" (\"degree_N\")",
            ),
            (
                "Degrees",
                "",
                "",
                "the units attribute of \"x\" (\"Degrees\")",
            ),
            (
                "",
                "",
                "latitude",
                "the standard_name of \"y\" (\"latitude\")",
            ),
        ] {
            let e = read_bytes(&grid_with_units(x, y, standard)).unwrap_err();
            assert!(
                e.starts_with(&format!("{named} declares a geographic coordinate system"))
                    && e.contains("must be in a projected coordinate system in metres"),
                "{e}"
            );
        }
        for (x, y) in [("km", "km"), ("kilometres", " KM ")] {
            let (geometry, _) = read_bytes(&grid_with_units(x, y, "")).unwrap();
            assert_eq!(
                geometry,
                GridGeometry {
                    x0: 437_100.0,
                    y0: 6_206_400.0,
                    cell: 100.0,
                    nx: 3,
                    ny: 2
                },
                "{x}, {y}"
            );
        }
        for (x, y, standard) in [
            ("m", "m", ""),
            ("", "", ""),
            ("metre", "furlongs", ""),
            ("", "m", "latitude"),
        ] {
            let (geometry, _) = read_bytes(&grid_with_units(x, y, standard)).unwrap();
            assert_eq!((geometry.x0, geometry.y0), (437.1, 6206.4), "{x}, {y}");
        }
        // The file is named.
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("deg.nc");
        fs::write(&path, grid_with_units("degrees_east", "degrees_north", "")).unwrap();
        let e = read_grid(&path).unwrap_err();
        assert!(e.is_bad_input() && e.to_string().contains("deg.nc"), "{e}");
    }
}
