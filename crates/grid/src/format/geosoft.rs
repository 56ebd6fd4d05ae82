//! Geosoft binary grids (`.grd`, Oasis montaj's own format, version 2 of
//! the Geosoft Grid File Format), read, told from GMT's netCDF and
//! Surfer's `.grd` by their first 20 bytes ([`looks_geosoft`]); written
//! ([`write`]) when the file is named with Oasis montaj's decoration,
//! `mag.grd(GRD)`.
//!
//! The file is a 512-byte header of little-endian fields, then the values:
//!
//! | offset | field | read as |
//! | --- | --- | --- |
//! | 0 | `ES` element size 1, 2, 4 or 8 bytes, plus 1024 when compressed | [`Element`] |
//! | 4 | `SF` sign flag: 0 unsigned, 1 signed, 2 float, 3 colour | refused if colour |
//! | 8, 12 | `NE` elements per vector, `NV` vectors | nodes |
//! | 16 | `KX` storage: 1 vectors are rows from the south, −1 columns from the west | other corners refused |
//! | 20, 28 | `DE`, `DV` element and vector spacings | the (square) cell |
//! | 36, 44 | `X0`, `Y0` the first element's position | the south-western node |
//! | 52 | `ROT` rotation, degrees counter-clockwise | refused unless 0 |
//! | 60, 68 | `ZBASE`, `ZMULT` | value = stored / `ZMULT` + `ZBASE` |
//!
//! The rest of the header (label, statistics, application area) is not
//! needed. A blank node is the type's dummy: 255 (unsigned byte), −127
//! (signed byte), 65535, −32767 (16-bit), 4294967295, −2147483647
//! (32-bit), any float at or below −10³² (Geosoft's float dummy), and NaN
//! as in the other float formats.
//!
//! A compressed grid (`ES` > 1024) holds, after the header, a signature,
//! the compression type, the number of blocks and of vectors per block,
//! each block's offset (64-bit) and size (32-bit); each block is a 16-byte
//! block header then a zlib stream of whole vectors. Oasis montaj writes
//! zlib whatever the type field says (harmonica's and Loop3D's readers
//! found the same); a block that is not zlib is refused, naming it.
//!
//! Geosoft keeps a grid's coordinate system in the `.gi` sidecar (an
//! undocumented binary) and in the `.grd.xml` metadata: the `<projection>`
//! of the XML's `<georeference>` gives it here, by its `wellknown_epsg` or
//! a `WGS 84 / UTM zone 33N`-like name; geographic coordinates or a unit
//! other than metres are refused ([`super::not_metres`]). Without the XML
//! the system is unknown and coordinates are taken as metres.
//!
//! Checked against the grids Oasis montaj 9.6 wrote for harmonica's tests
//! (every element type, column storage, compression, rotation) and the
//! values harmonica's `load_oasis_montaj_grid` reads from them
//! (`tests/geosoft.rs`).

use std::borrow::Cow;
use std::fs;
use std::io::{Read, Write};
use std::path::Path;

use super::surfer::Fields;
use super::{
    CoordinateUnit, checked_geometry, crs_from_epsg, crs_from_wkt, fits_in_memory, north_up,
    not_metres, open_error, read_error, square_cell, stem, write_atomic,
};
use crate::error::Result;
use crate::grid::{Grid, GridGeometry};
use crate::projection::Crs;
use aeromag_core::error::{shown, shown_text};

/// The header's length in bytes.
const HEADER_BYTES: usize = 512;

/// Geosoft's float dummy: a float value at or below it is blank.
const FLOAT_DUMMY: f64 = -1e32;

/// Whether `head` (at least the first 20 bytes of a file) starts as a
/// Geosoft grid: element size 1, 2, 4 or 8 bytes (1024 more when
/// compressed), sign flag 0–3, positive counts of elements and vectors,
/// storage ±1 to ±4 (little-endian 32-bit integers).
pub(crate) fn looks_geosoft(head: &[u8]) -> bool {
    let int = |k: usize| {
        head.get(4 * k..4 * k + 4)
            .map(|b| i32::from_le_bytes(b.try_into().expect("4 bytes")))
    };
    matches!(
        (int(0), int(1), int(2), int(3), int(4)),
        (Some(es), Some(sf), Some(ne), Some(nv), Some(kx))
            if [1, 2, 4, 8].contains(&(es % 1024)) && es < 2048
                && (0..=3).contains(&sf) && ne > 0 && nv > 0 && (1..=4).contains(&kx.abs())
    )
}

/// The type of a grid's stored values (`ES` and `SF`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Element {
    U8,
    I8,
    U16,
    I16,
    U32,
    I32,
    F32,
    F64,
}

impl Element {
    /// The type of element size `size` (bytes, without the compression
    /// flag) and sign flag `sign`; the reason it is not read otherwise.
    fn of(size: i32, sign: i32) -> std::result::Result<Self, String> {
        Ok(match (size, sign) {
            (_, 3) => {
                return Err(
                    "a colour (RGB) grid: it holds colours, not values; export the values' grid"
                        .into(),
                );
            }
            (1, 0) => Element::U8,
            (1, 1) => Element::I8,
            (2, 0) => Element::U16,
            (2, 1) => Element::I16,
            (4, 0) => Element::U32,
            (4, 1) => Element::I32,
            (4, 2) => Element::F32,
            (8, 2) => Element::F64,
            _ => {
                return Err(format!(
                    "element size {size} bytes with sign flag {sign} is not a type of the \
                     Geosoft grid format (1, 2 or 4 bytes unsigned or signed, 4 or 8 bytes float)"
                ));
            }
        })
    }

    /// Bytes per element.
    fn size(self) -> usize {
        match self {
            Element::U8 | Element::I8 => 1,
            Element::U16 | Element::I16 => 2,
            Element::U32 | Element::I32 | Element::F32 => 4,
            Element::F64 => 8,
        }
    }

    /// The stored value of `b` (`size()` bytes), `None` for the type's
    /// dummy (module docs).
    fn stored(self, b: &[u8]) -> Option<f64> {
        let v = match self {
            Element::U8 => (b[0] != u8::MAX).then_some(f64::from(b[0]))?,
            Element::I8 => {
                let v = b[0] as i8;
                (v != -127).then_some(f64::from(v))?
            }
            Element::U16 => {
                let v = u16::from_le_bytes([b[0], b[1]]);
                (v != u16::MAX).then_some(f64::from(v))?
            }
            Element::I16 => {
                let v = i16::from_le_bytes([b[0], b[1]]);
                (v != -32767).then_some(f64::from(v))?
            }
            Element::U32 => {
                let v = u32::from_le_bytes(b[..4].try_into().expect("4 bytes"));
                (v != u32::MAX).then_some(f64::from(v))?
            }
            Element::I32 => {
                let v = i32::from_le_bytes(b[..4].try_into().expect("4 bytes"));
                (v != -i32::MAX).then_some(f64::from(v))?
            }
            Element::F32 => f64::from(f32::from_le_bytes(b[..4].try_into().expect("4 bytes"))),
            Element::F64 => f64::from_le_bytes(b[..8].try_into().expect("8 bytes")),
        };
        (!v.is_nan() && v > FLOAT_DUMMY).then_some(v)
    }
}

/// What the header says (module docs).
#[derive(Debug)]
struct Header {
    element: Element,
    compressed: bool,
    /// Elements per vector, vectors.
    ne: usize,
    nv: usize,
    /// Vectors are rows (`KX` = 1) or columns (−1).
    rows: bool,
    geometry: GridGeometry,
    zbase: f64,
    zmult: f64,
}

/// Reads a Geosoft grid (module docs). Its name is the file stem; its
/// coordinate system is the `.grd.xml` sidecar's, if any.
pub fn read(path: &Path) -> Result<Grid> {
    let bytes = fs::read(path).map_err(|e| open_error(path, e))?;
    let h = header(path, &bytes)?;
    let n = h.ne * h.nv;
    let size = h.element.size();
    let data: Cow<[u8]> = if h.compressed {
        fits_in_memory(path, h.ne, h.nv, aeromag_core::memory::available_bytes())?;
        Cow::Owned(decompress(path, &bytes, &h)?)
    } else {
        let data = &bytes[HEADER_BYTES..];
        if data.len() != n * size {
            return Err(read_error(
                path,
                format!(
                    "the header declares {} × {} values of {size} bytes ({} bytes), \
                     but {} bytes follow it",
                    h.ne,
                    h.nv,
                    n * size,
                    data.len()
                ),
            ));
        }
        Cow::Borrowed(data)
    };
    let g = h.geometry;
    let mut values = vec![f64::NAN; n];
    for (k, b) in data.chunks_exact(size).enumerate() {
        // Element e of vector v: a row's column, or a column's row.
        let (e, v) = (k % h.ne, k / h.ne);
        let node = if h.rows { v * g.nx + e } else { e * g.nx + v };
        if let Some(stored) = h.element.stored(b) {
            values[node] = stored / h.zmult + h.zbase;
        }
    }
    drop(data);
    drop(bytes);
    let grid = Grid {
        geometry: g,
        values,
        crs: sidecar_crs(path)?,
        name: stem(path),
        unit: String::new(),
    };
    super::check_values(path, &grid)?;
    Ok(grid)
}

/// Writes `grid` as a Geosoft grid, atomically, in the layout of the
/// float grids Oasis montaj 9.6 writes (uncompressed float32, `KX` 1, no
/// scaling; blank nodes the float dummy −10³²; the header's count,
/// minimum, maximum, mean and variance of the values, its median left 0
/// and its application area holding four dummies, as Oasis montaj
/// leaves them). The coordinate system is not written: Oasis montaj keeps
/// it in the `.gi` sidecar, whose format is not published (GXF carries
/// it). Written by naming the file with Oasis montaj's decoration,
/// `mag.grd(GRD)` ([`super::GridFormat::from_path`]).
pub fn write(path: &Path, grid: &Grid) -> Result<()> {
    super::check_grid(grid)?;
    write_atomic(path, |w| {
        w.write_all(&header_bytes(grid))?;
        let mut row = Vec::with_capacity(4 * grid.geometry.nx);
        for values in grid.values.chunks(grid.geometry.nx) {
            row.clear();
            for &v in values {
                let v = if v.is_nan() {
                    FLOAT_DUMMY as f32
                } else {
                    v as f32
                };
                row.extend(v.to_le_bytes());
            }
            w.write_all(&row)?;
        }
        Ok(())
    })
}

/// The 512-byte header [`write`] writes.
fn header_bytes(grid: &Grid) -> Vec<u8> {
    let g = grid.geometry;
    let set: Vec<f64> = grid
        .values
        .iter()
        .filter(|v| !v.is_nan())
        .map(|&v| f64::from(v as f32))
        .collect();
    let n = set.len() as f64;
    let mean = set.iter().sum::<f64>() / n;
    let variance = set.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    let (min, max) = set
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    let stat = |v: f64| {
        if set.is_empty() {
            FLOAT_DUMMY as f32
        } else {
            v as f32
        }
    };
    let mut h = Vec::with_capacity(HEADER_BYTES);
    for i in [4, 2, g.nx as i32, g.ny as i32, 1] {
        h.extend(i32::to_le_bytes(i));
    }
    for d in [g.cell, g.cell, g.x0, g.y0, 0.0, 0.0, 1.0] {
        h.extend(f64::to_le_bytes(d));
    }
    // LABEL, MAPNO, then PROJ, UNITX, UNITY, UNITZ.
    h.resize(156, 0);
    h.extend(i32::to_le_bytes(set.len() as i32));
    for f in [stat(min), stat(max), 0.0, stat(mean)] {
        h.extend(f32::to_le_bytes(f));
    }
    let variance = if set.len() > 1 { variance } else { 0.0 };
    h.extend(f64::to_le_bytes(variance));
    h.extend(i32::to_le_bytes(0));
    for _ in 0..4 {
        h.extend(f32::to_le_bytes(FLOAT_DUMMY as f32));
    }
    h.resize(HEADER_BYTES, 0);
    h
}

/// Parses and checks the 512-byte header.
fn header(path: &Path, bytes: &[u8]) -> Result<Header> {
    let mut f = Fields {
        path,
        bytes,
        pos: 0,
    };
    let (es, sf, ne, nv, kx) = (f.i32()?, f.i32()?, f.i32()?, f.i32()?, f.i32()?);
    let (de, dv, x0, y0, rot) = (f.f64()?, f.f64()?, f.f64()?, f.f64()?, f.f64()?);
    let (zbase, zmult) = (f.f64()?, f.f64()?);
    if bytes.len() < HEADER_BYTES {
        return Err(read_error(
            path,
            format!(
                "the file ends at byte {} inside its {HEADER_BYTES}-byte header",
                bytes.len()
            ),
        ));
    }
    let compressed = es > 1024;
    let element = Element::of(if compressed { es - 1024 } else { es }, sf)
        .map_err(|reason| read_error(path, format!("a Geosoft grid of {reason}")))?;
    let count = |n: i32, what: &str| {
        usize::try_from(n)
            .ok()
            .filter(|&n| n >= 1)
            .ok_or_else(|| read_error(path, format!("{n} {what} in the Geosoft header")))
    };
    let (ne, nv) = (count(ne, "elements per vector")?, count(nv, "vectors")?);
    let rows = match kx {
        1 => true,
        -1 => false,
        _ => {
            return Err(read_error(
                path,
                format!(
                    "storage order KX = {kx} (the first element in another corner than the \
                     south-west): only ±1 is read, the order Oasis montaj writes"
                ),
            ));
        }
    };
    north_up(path, rot)?;
    let (nx, ny, dx, dy) = if rows {
        (ne, nv, de, dv)
    } else {
        (nv, ne, dv, de)
    };
    let cell = square_cell(path, dx, dy)?;
    let geometry = checked_geometry(
        path,
        GridGeometry {
            x0,
            y0,
            cell,
            nx,
            ny,
        },
    )?;
    if !(zmult.is_finite() && zmult != 0.0 && zbase.is_finite()) {
        return Err(read_error(
            path,
            format!(
                "the values' scaling ZBASE {}, ZMULT {} (value = stored / ZMULT + ZBASE) \
                 is not usable",
                shown(zbase),
                shown(zmult)
            ),
        ));
    }
    Ok(Header {
        element,
        compressed,
        ne,
        nv,
        rows,
        geometry,
        zbase,
        zmult,
    })
}

/// The values of a compressed grid, block after block (module docs).
fn decompress(path: &Path, bytes: &[u8], h: &Header) -> Result<Vec<u8>> {
    let mut f = Fields {
        path,
        bytes,
        pos: HEADER_BYTES,
    };
    let ended = || {
        read_error(
            path,
            "the file ends inside the table of compressed blocks after its header",
        )
    };
    let _signature = f.i32().map_err(|_| ended())?;
    let method = f.i32().map_err(|_| ended())?;
    let (blocks, per_block) = (f.i32().map_err(|_| ended())?, f.i32().map_err(|_| ended())?);
    let fits = usize::try_from(per_block)
        .ok()
        .filter(|&p| p >= 1 && usize::try_from(blocks) == Ok(h.nv.div_ceil(p)));
    let Some(per_block) = fits else {
        return Err(read_error(
            path,
            format!(
                "{blocks} compressed blocks of {per_block} vectors do not hold the header's {} \
                 vectors",
                h.nv
            ),
        ));
    };
    let blocks = h.nv.div_ceil(per_block);
    // Each block's offset (8 bytes) and size (4): the table must be in the
    // file before anything is allocated for it.
    if bytes.len().saturating_sub(f.pos) / 12 < blocks {
        return Err(ended());
    }
    let offsets: Vec<i64> = (0..blocks).map(|_| f.i64()).collect::<Result<_>>()?;
    let sizes: Vec<i32> = (0..blocks).map(|_| f.i32()).collect::<Result<_>>()?;
    let vector_bytes = h.ne * h.element.size();
    // Grown block by block as the blocks decompress: a few bytes of header
    // may declare gigabytes.
    let mut data = Vec::new();
    for (b, (&offset, &size)) in offsets.iter().zip(&sizes).enumerate() {
        let block_error = |what: String| {
            read_error(
                path,
                format!("compressed block {} of {blocks}: {what}", b + 1),
            )
        };
        let stream = usize::try_from(offset)
            .ok()
            .zip(usize::try_from(size).ok())
            .filter(|&(o, s)| o >= f.pos && s >= 16 && o.checked_add(s).is_some())
            .and_then(|(o, s)| bytes.get(o + 16..o + s))
            .ok_or_else(|| {
                block_error(format!(
                    "offset {offset} and size {size} do not lie within the file's {} bytes \
                     after the table of blocks",
                    bytes.len()
                ))
            })?;
        let expected = per_block.min(h.nv - b * per_block) * vector_bytes;
        data.reserve(expected.min(1 << 26));
        let start = data.len();
        let read = flate2::read::ZlibDecoder::new(stream)
            .take(expected as u64 + 1)
            .read_to_end(&mut data);
        match read {
            Ok(got) if got == expected => {}
            Ok(got) => {
                return Err(block_error(format!(
                    "{got} bytes once decompressed, where its vectors take {expected}"
                )));
            }
            Err(e) => {
                data.truncate(start);
                return Err(block_error(format!(
                    "not a zlib stream ({e}; compression type {method}): only zlib, \
                     which Oasis montaj writes, is read; export the grid uncompressed or as GXF"
                )));
            }
        }
    }
    Ok(data)
}

/// The coordinate system the `.grd.xml` sidecar of `path` declares
/// (module docs); `None` without a sidecar or a `<projection>` this crate
/// does not know.
fn sidecar_crs(path: &Path) -> Result<Option<Crs>> {
    let mut xml_path = path.as_os_str().to_owned();
    xml_path.push(".xml");
    let Ok(xml) = fs::read_to_string(&xml_path) else {
        return Ok(None);
    };
    let Some(projection) = georeference_projection(&xml) else {
        return Ok(None);
    };
    let by = format!(
        "its sidecar {}",
        shown_text(&Path::new(&xml_path).display().to_string())
    );
    let attribute = |tag: &str, name: &str| attribute(tag, name).unwrap_or_default();
    let units = projection
        .find("<units")
        .map(|at| &projection[at..])
        .and_then(|u| u.find('>').map(|end| &u[..end]))
        .unwrap_or_default();
    let (unit, scale) = (attribute(units, "name"), attribute(units, "unit_scale"));
    let kind = attribute(projection, "type");
    if kind.eq_ignore_ascii_case("GEOGRAPHIC") || unit.to_ascii_lowercase().starts_with("deg") {
        return Err(not_metres(path, &by, &CoordinateUnit::Degree));
    }
    if let Ok(metres) = scale.trim().parse::<f64>()
        && (metres - 1.0).abs() > 1e-9
    {
        return Err(not_metres(path, &by, &CoordinateUnit::Other(unit, metres)));
    }
    let epsg = attribute(projection, "wellknown_epsg");
    Ok(epsg
        .trim()
        .parse()
        .ok()
        .and_then(crs_from_epsg)
        .or_else(|| {
            crs_from_wkt(&format!(
                "{} {}",
                attribute(projection, "name"),
                attribute(projection, "datum")
            ))
        }))
}

/// The `<projection …>…</projection>` element of the XML's
/// `<georeference>` (not those quoted in its lineage's parameters).
fn georeference_projection(xml: &str) -> Option<&str> {
    let georeference = &xml[xml.find("<georeference")?..];
    let georeference = &georeference[..georeference
        .find("</georeference>")
        .unwrap_or(georeference.len())];
    let start = georeference.find("<projection")?;
    let rest = &georeference[start..];
    Some(&rest[..rest.find("</projection>").unwrap_or(rest.len())])
}

/// The value of attribute `name` in the first tag of `tag` (`name="…"`),
/// its XML entities for quotes and ampersands undone.
fn attribute(tag: &str, name: &str) -> Option<String> {
    let head = &tag[..tag.find('>').unwrap_or(tag.len())];
    let key = format!(" {name}=\"");
    let at = head.find(&key)? + key.len();
    let value = &head[at..at + head[at..].find('"')?];
    Some(
        value
            .replace("&quot;", "\"")
            .replace("&apos;", "'")
            .replace("&amp;", "&"),
    )
}

#[cfg(test)]
mod tests {
    use super::super::read_grid;
    use super::*;
    use proptest::prelude::*;

    /// A Geosoft grid's bytes: `ne` × `nv` elements of `stored` (already
    /// in the element type's bytes), the header's fields as given.
    struct File {
        es: i32,
        sf: i32,
        ne: i32,
        nv: i32,
        kx: i32,
        spacing: [f64; 2],
        origin: [f64; 2],
        rotation: f64,
        scale: [f64; 2],
    }

    impl File {
        fn new(es: i32, sf: i32, ne: i32, nv: i32) -> Self {
            Self {
                es,
                sf,
                ne,
                nv,
                kx: 1,
                spacing: [25.0, 25.0],
                origin: [500_000.0, 6_000_000.0],
                rotation: 0.0,
                scale: [0.0, 1.0],
            }
        }

        fn header(&self) -> Vec<u8> {
            let mut h = Vec::with_capacity(HEADER_BYTES);
            for i in [self.es, self.sf, self.ne, self.nv, self.kx] {
                h.extend(i.to_le_bytes());
            }
            for d in [
                self.spacing[0],
                self.spacing[1],
                self.origin[0],
                self.origin[1],
                self.rotation,
                self.scale[0],
                self.scale[1],
            ] {
                h.extend(d.to_le_bytes());
            }
            h.resize(HEADER_BYTES, 0);
            h
        }

        fn plain(&self, data: &[u8]) -> Vec<u8> {
            let mut b = self.header();
            b.extend(data);
            b
        }

        /// Compressed as Oasis montaj does: blocks of `per_block` vectors.
        fn compressed(&self, data: &[u8], per_block: usize) -> Vec<u8> {
            use std::io::Write;
            let vector = data.len() / self.nv as usize;
            let blocks: Vec<Vec<u8>> = data
                .chunks(per_block * vector)
                .map(|chunk| {
                    let mut z = flate2::write::ZlibEncoder::new(
                        vec![
                            0x0f, 0x0e, 0xff, 0xfe, 0x12, 0x34, 0x56, 0x78, 2, 0, 0, 0, 1, 0, 0, 0,
                        ],
                        flate2::Compression::default(),
                    );
                    z.write_all(chunk).unwrap();
                    z.finish().unwrap()
                })
                .collect();
            let mut b = self.header();
            for i in [
                0xf8e7_d8c7_u32 as i32,
                2,
                blocks.len() as i32,
                per_block as i32,
            ] {
                b.extend(i.to_le_bytes());
            }
            let mut offset = b.len() + 12 * blocks.len();
            for block in &blocks {
                b.extend((offset as i64).to_le_bytes());
                offset += block.len();
            }
            for block in &blocks {
                b.extend((block.len() as i32).to_le_bytes());
            }
            for block in &blocks {
                b.extend(block);
            }
            b
        }
    }

    fn read_bytes(bytes: &[u8]) -> Result<Grid> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("g.grd");
        fs::write(&path, bytes).unwrap();
        read_grid(&path)
    }

    /// Each element type with its dummy, the scaling (stored / ZMULT +
    /// ZBASE), rows from the south: a 3 × 2 grid whose last node is blank.
    #[test]
    fn every_element_type_its_dummy_and_the_scaling() {
        let stored = [1.0, 2.0, 3.0, 4.0, 5.0];
        // ES, SF, a value's bytes, the dummy's.
        type Case = (i32, i32, fn(f64) -> Vec<u8>, Vec<u8>);
        let cases: [Case; 8] = [
            (1, 0, |v| vec![v as u8], vec![255]),
            (
                1,
                1,
                |v| vec![v as i8 as u8],
                (-127i8).to_le_bytes().to_vec(),
            ),
            (
                2,
                0,
                |v| (v as u16).to_le_bytes().to_vec(),
                u16::MAX.to_le_bytes().to_vec(),
            ),
            (
                2,
                1,
                |v| (v as i16).to_le_bytes().to_vec(),
                (-32767i16).to_le_bytes().to_vec(),
            ),
            (
                4,
                0,
                |v| (v as u32).to_le_bytes().to_vec(),
                u32::MAX.to_le_bytes().to_vec(),
            ),
            (
                4,
                1,
                |v| (v as i32).to_le_bytes().to_vec(),
                (-i32::MAX).to_le_bytes().to_vec(),
            ),
            (
                4,
                2,
                |v| (v as f32).to_le_bytes().to_vec(),
                (-1e32f32).to_le_bytes().to_vec(),
            ),
            (
                8,
                2,
                |v| v.to_le_bytes().to_vec(),
                (-1e32f64).to_le_bytes().to_vec(),
            ),
        ];
        for (es, sf, encode, dummy) in cases {
            let mut file = File::new(es, sf, 3, 2);
            file.scale = [100.0, 4.0];
            let mut data: Vec<u8> = stored.iter().flat_map(|&v| encode(v)).collect();
            data.extend(&dummy);
            for bytes in [file.plain(&data), {
                file.es += 1024;
                file.compressed(&data, 1)
            }] {
                let g = read_bytes(&bytes).unwrap_or_else(|e| panic!("{es} {sf}: {e}"));
                assert_eq!(
                    (g.geometry.nx, g.geometry.ny, g.geometry.x0, g.geometry.cell),
                    (3, 2, 500_000.0, 25.0)
                );
                let want: Vec<f64> = stored.iter().map(|v| v / 4.0 + 100.0).collect();
                assert_eq!(g.values[..5], want[..], "{es} {sf}");
                assert!(g.values[5].is_nan(), "{es} {sf}");
            }
        }
    }

    /// KX = −1 stores columns from the west, each from the south: the
    /// same grid as rows; the spacings swap with them.
    #[test]
    fn columns_are_the_same_grid_as_rows() {
        let rows: Vec<f64> = (0..12).map(|k| k as f64 * 1.5).collect();
        let (nx, ny) = (4usize, 3usize);
        let mut columns = Vec::new();
        for i in 0..nx {
            for j in 0..ny {
                columns.push(rows[j * nx + i]);
            }
        }
        let bytes = |v: &[f64]| -> Vec<u8> { v.iter().flat_map(|x| x.to_le_bytes()).collect() };
        let mut by_rows = File::new(8, 2, nx as i32, ny as i32);
        by_rows.spacing = [10.0, 10.0];
        let mut by_columns = File::new(8, 2, ny as i32, nx as i32);
        by_columns.kx = -1;
        by_columns.spacing = [10.0, 10.0];
        let a = read_bytes(&by_rows.plain(&bytes(&rows))).unwrap();
        let b = read_bytes(&by_columns.plain(&bytes(&columns))).unwrap();
        assert_eq!(a.geometry, b.geometry);
        assert_eq!(a.values, rows);
        assert_eq!(b.values, rows);
    }

    /// What the reader cannot take is refused, naming the file and why.
    #[test]
    fn what_cannot_be_read_is_refused_naming_the_file() {
        let data = vec![0u8; 4 * 6];
        let with = |f: &dyn Fn(&mut File)| {
            let mut file = File::new(4, 2, 3, 2);
            f(&mut file);
            file.plain(&data)
        };
        let mut compressed = File::new(1028, 2, 3, 2).compressed(&data, 1);
        let last = compressed.len() - 5;
        compressed[last] ^= 0xff;
        let mut lzrw = File::new(1028, 2, 3, 2).compressed(&data, 2);
        let table = HEADER_BYTES + 16 + 12;
        lzrw[table + 16] = 0x00;
        for (bytes, needle) in [
            (with(&|f| f.sf = 3), "colour (RGB) grid"),
            (
                with(&|f| {
                    f.es = 8;
                    f.sf = 1;
                }),
                "element size 8 bytes with sign flag 1",
            ),
            (with(&|f| f.kx = 2), "KX = 2"),
            (with(&|f| f.rotation = 30.0), "rotated by 30°"),
            (with(&|f| f.spacing = [10.0, 20.0]), "square cells"),
            (with(&|f| f.scale = [0.0, 0.0]), "ZMULT 0"),
            (with(&|f| f.scale = [f64::NAN, 1.0]), "ZBASE NaN"),
            (
                with(&|f| f.origin = [1e300, 0.0]),
                "coordinates must be within",
            ),
            (
                File::new(4, 2, 3, 2).plain(&data[..23]),
                "(24 bytes), but 23 bytes follow it",
            ),
            (
                File::new(4, 2, 3, 2).plain(&[data.clone(), vec![0]].concat()),
                "but 25 bytes follow it",
            ),
            (
                File::new(4, 2, 3, 2).header()[..300].to_vec(),
                "inside its 512-byte header",
            ),
            (compressed, "compressed block 2 of 2"),
            (lzrw, "not a zlib stream"),
            (
                File::new(1028, 2, 3, 2).compressed(&data, 1)[..HEADER_BYTES + 20].to_vec(),
                "table of compressed blocks",
            ),
            (
                {
                    let mut b = File::new(1028, 2, 3, 2).compressed(&data, 1);
                    b[HEADER_BYTES + 8] = 5;
                    b
                },
                "5 compressed blocks of 1 vectors",
            ),
            (
                {
                    let mut b = File::new(1028, 2, 3, 2).compressed(&data, 1);
                    b[HEADER_BYTES + 16..HEADER_BYTES + 24].copy_from_slice(&9999i64.to_le_bytes());
                    b
                },
                "offset 9999",
            ),
        ] {
            let e = read_bytes(&bytes).unwrap_err();
            assert!(e.is_bad_input(), "{needle}: {e}");
            let text = e.to_string();
            assert!(
                text.contains("g.grd") && text.contains(needle),
                "{needle}: {text}"
            );
        }
    }

    /// The `.grd.xml` sidecar Oasis montaj writes gives the coordinate
    /// system (its `wellknown_epsg`, or a UTM name on WGS 84); degrees and
    /// feet are refused; no sidecar, or an unknown projection: unknown.
    #[test]
    fn the_xml_sidecar_gives_the_coordinate_system() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("g.grd");
        fs::write(&path, File::new(4, 2, 3, 2).plain(&[0u8; 24])).unwrap();
        let xml = dir.path().join("g.grd.xml");
        // A projection quoted in the lineage's parameters does not count.
        let quoted = "<lineage><parameter name=\"IPJSET::PROJECTION\" \
                      value=\"&lt;projection type=&quot;GEOGRAPHIC&quot;\"/></lineage>";
        let sidecar = |projection: &str| {
            format!(
                "<?xml version=\"1.0\"?><gmd:MD_Metadata><geosoft><dataset>{quoted}\
                 <georeference><dataextents/>{projection}</georeference>\
                 </dataset></geosoft></gmd:MD_Metadata>"
            )
        };
        let utm37 = Some(crate::projection::Crs::Utm(
            crate::projection::UtmZone::new(37, true).unwrap(),
        ));
        for (projection, crs) in [
            (
                "<projection type=\"UTM\" name=\"WGS 84 / UTM zone 37N\" wellknown_epsg=\"32637\">\
                 <units name=\"m\" unit_scale=\"1\"/></projection>",
                utm37,
            ),
            (
                "<projection type=\"TRANSVERSE_MERCATOR\" name=\"WGS 84 / UTM zone 37N\" \
                 datum=\"WGS 84\"><units name=\"m\" unit_scale=\"1\"/></projection>",
                utm37,
            ),
            (
                "<projection type=\"UNKNOWN\"><units name=\"m\" unit_scale=\"1\"/></projection>",
                None,
            ),
        ] {
            fs::write(&xml, sidecar(projection)).unwrap();
            assert_eq!(read_grid(&path).unwrap().crs, crs, "{projection}");
        }
        for (projection, needle) in [
            (
                "<projection type=\"GEOGRAPHIC\" name=\"WGS 84\" wellknown_epsg=\"4326\">\
                 <units name=\"dega\" unit_scale=\"1\"/></projection>",
                "geographic coordinate system",
            ),
            (
                "<projection type=\"UTM\" name=\"NAD27 / UTM zone 17N (ftUS)\">\
                 <units name=\"ftUS\" unit_scale=\"0.3048006096\"/></projection>",
                "coordinates in \"ftUS\" (0.3048006096 m)",
            ),
        ] {
            fs::write(&xml, sidecar(projection)).unwrap();
            let e = read_grid(&path).unwrap_err();
            assert!(e.is_bad_input(), "{e}");
            let text = e.to_string();
            assert!(
                text.contains("g.grd.xml") && text.contains(needle),
                "{text}"
            );
        }
        fs::remove_file(&xml).unwrap();
        assert_eq!(read_grid(&path).unwrap().crs, None);
    }

    /// Written with the `(GRD)` decoration and read back: the same nodes
    /// and values (float32), blanks; the file is `g.grd`, the decoration
    /// not part of its name.
    #[test]
    fn a_written_grid_reads_back() {
        let dir = tempfile::tempdir().unwrap();
        let mut grid = super::super::test_support::sample_grid();
        grid.crs = None;
        let decorated = dir.path().join("g.grd(GRD)");
        assert_eq!(
            super::super::write_grid(&decorated, &grid).unwrap(),
            super::super::GridFormat::Geosoft
        );
        let file = dir.path().join("g.grd");
        assert_eq!(super::super::test_support::entries(dir.path()), ["g.grd"]);
        for path in [&file, &decorated] {
            let back = read_grid(path).unwrap();
            assert_eq!(back.geometry, grid.geometry);
            for (a, b) in grid.values.iter().zip(&back.values) {
                assert!(
                    a.is_nan() && b.is_nan() || f64::from(*a as f32) == *b,
                    "{a} {b}"
                );
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]
        /// Changed bytes anywhere in a plain or compressed grid give a
        /// grid or an error, never a panic.
        #[test]
        fn changed_bytes_never_panic(
            changes in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..6),
            compressed in any::<bool>(),
        ) {
            let data: Vec<u8> = (0..24u8).collect();
            let mut bytes = if compressed {
                File::new(1028, 2, 3, 2).compressed(&data, 1)
            } else {
                File::new(4, 2, 3, 2).plain(&data)
            };
            for (at, byte) in changes {
                let k = at.index(bytes.len());
                bytes[k] = byte;
            }
            let _ = read_bytes(&bytes);
        }
    }
}
