//! GeoTIFF: one float32 band, uncompressed strips, rows from the NORTH
//! row to the southern, west to east (TIFF 6.0 and OGC GeoTIFF 1.1,
//! written with the `tiff` crate; the GeoTIFF tags are ours).
//!
//! Georeferencing, **PixelIsArea** (`GTRasterTypeGeoKey` = 1): each pixel
//! is the cell of side `cell` centred on its node, so the tie point
//! raster (0, 0) — the north-western corner of the north-western pixel —
//! is the model point `(x0 − cell/2, y_max + cell/2)`, half a cell out of
//! the north-western node. Every GeoTIFF reader (also those that ignore the
//! raster type) then puts pixel centres on the nodes, and GDAL reports the
//! geotransform `[x0 − cell/2, cell, 0, y_max + cell/2, 0, −cell]` with
//! `AREA_OR_POINT=Area`.
//!
//! | tag | value |
//! | --- | --- |
//! | ModelPixelScaleTag (33550) | `cell, cell, 0` |
//! | ModelTiepointTag (33922) | `0, 0, 0, x0 − cell/2, y_max + cell/2, 0` |
//! | GeoKeyDirectoryTag (34735) | version 1.1.0 and the keys below |
//! | GeoAsciiParamsTag (34737) | the citation, `|`-terminated |
//! | GDAL_METADATA (42112) | band description (grid name) and unit type (unit) |
//! | GDAL_NODATA (42113) | `-99999` ([`NODATA`]: blank nodes) |
//!
//! GeoKeys: `GTModelTypeGeoKey` (1024) = 1 (projected), `GTRasterTypeGeoKey`
//! (1025) = 1 (PixelIsArea), `GTCitationGeoKey` (1026) = the CRS name
//! (e.g. `WGS 84 / UTM zone 37N`), `ProjectedCSTypeGeoKey` (3072) = the
//! EPSG code, `ProjLinearUnitsGeoKey` (3076) = 9001 (metre). Without a CRS
//! the file has no `ProjectedCSTypeGeoKey` (a user-defined projected
//! system in metres) and the citation says so.
//!
//! Reading ([`read`]) accepts a single-band north-up GeoTIFF of square
//! pixels in metres (a geographic model type, `GTModelTypeGeoKey` = 2, or
//! a `ProjLinearUnitsGeoKey` of feet, miles or kilometres is refused)
//! with a tie point and a pixel scale, of either raster type (a
//! PixelIsPoint tie point is a node), of any sample type, whose strips or
//! tiles hold the image its header declares (an uncompressed strip
//! exactly its rows × `ImageWidth` samples), uncompressed or compressed
//! with Deflate, LZW or PackBits and the horizontal or floating-point
//! predictor, as GDAL, QGIS and ArcGIS export grids (`COMPRESS=DEFLATE`,
//! `PREDICTOR=3`: they were refused, "compression method Deflate is
//! unsupported"). ZSTD, which the `tiff` crate decodes through a C
//! library, is not read.

use std::fs::File;
use std::io::{self, BufReader, Seek, Write};
use std::path::Path;

use tiff::decoder::{Decoder, DecodingResult, Limits};
use tiff::encoder::{TiffEncoder, colortype::Gray32Float};
use tiff::tags::Tag;
use tiff::{ColorType, TiffError};

use super::{
    CoordinateUnit, NODATA, check_declared_size, check_grid, check_values, checked_geometry,
    crs_from_epsg, label_from_file, not_metres, open_error, read_error, stem, write_atomic,
};
use crate::error::Result;
use crate::grid::{Grid, GridGeometry};
use aeromag_core::error::shown;

/// GeoKey ids (OGC GeoTIFF 1.1, annex).
mod key {
    pub const MODEL_TYPE: u16 = 1024;
    pub const RASTER_TYPE: u16 = 1025;
    pub const CITATION: u16 = 1026;
    pub const PROJECTED_CRS: u16 = 3072;
    pub const PROJ_LINEAR_UNITS: u16 = 3076;
    /// `ModelTypeProjected`.
    pub const PROJECTED: u16 = 1;
    /// `ModelTypeGeographic`: longitude and latitude, degrees.
    pub const GEOGRAPHIC: u16 = 2;
    /// `RasterPixelIsArea`.
    pub const PIXEL_IS_AREA: u16 = 1;
    /// `RasterPixelIsPoint`.
    pub const PIXEL_IS_POINT: u16 = 2;
    /// `Linear_Meter`.
    pub const METRE: u16 = 9001;
    /// EPSG linear units a `ProjLinearUnitsGeoKey` may name, and their
    /// length in metres (EPSG dataset; other codes are left as metres).
    pub const LINEAR_UNITS: [(u16, &str, f64); 6] = [
        (METRE, "metre", 1.0),
        (9002, "foot", 0.3048),
        (9003, "US survey foot", 1200.0 / 3937.0),
        (9030, "nautical mile", 1852.0),
        (9035, "statute mile", 1609.344),
        (9036, "kilometre", 1000.0),
    ];
}

/// The `GDAL_METADATA` tag (XML), not named by the `tiff` crate.
const GDAL_METADATA: Tag = Tag::Unknown(42112);

/// Writes `grid` as a GeoTIFF to `path`, atomically (module docs for the
/// layout). Errors as
/// [`write_grid`](super::write_grid).
pub fn write(path: &Path, grid: &Grid) -> Result<()> {
    check_grid(grid)?;
    write_atomic(path, |w| encode(w, grid).map_err(tiff_to_io))
}

fn tiff_to_io(e: TiffError) -> io::Error {
    match e {
        TiffError::IoError(e) => e,
        e => io::Error::other(e.to_string()),
    }
}

/// The GeoKey directory and the GeoAsciiParams of `grid`.
fn geokeys(grid: &Grid) -> (Vec<u16>, String) {
    let citation = match &grid.crs {
        Some(crs) => crs.name(),
        None => "unknown projected coordinate system (metre)".to_string(),
    };
    let ascii = format!("{}|", citation.replace('|', "/"));
    let mut keys: Vec<[u16; 4]> = vec![
        [key::MODEL_TYPE, 0, 1, key::PROJECTED],
        [key::RASTER_TYPE, 0, 1, key::PIXEL_IS_AREA],
        [
            key::CITATION,
            Tag::GeoAsciiParamsTag.to_u16(),
            ascii.len() as u16,
            0,
        ],
    ];
    if let Some(crs) = &grid.crs {
        keys.push([key::PROJECTED_CRS, 0, 1, crs.epsg()]);
    }
    keys.push([key::PROJ_LINEAR_UNITS, 0, 1, key::METRE]);
    let mut dir = vec![1, 1, 0, keys.len() as u16];
    dir.extend(keys.iter().flatten());
    (dir, ascii)
}

/// Escapes text for XML, non-ASCII as character references (the TIFF
/// ASCII type is 7-bit).
fn xml_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            c if c.is_ascii() && !c.is_ascii_control() => out.push(c),
            c => out.push_str(&format!("&#{};", c as u32)),
        }
    }
    out
}

fn xml_unescape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    let mut rest = s;
    while let Some(p) = rest.find('&') {
        out.push_str(&rest[..p]);
        rest = &rest[p..];
        let Some(end) = rest.find(';') else { break };
        let entity = &rest[1..end];
        let c = match entity {
            "amp" => Some('&'),
            "lt" => Some('<'),
            "gt" => Some('>'),
            "quot" => Some('"'),
            "apos" => Some('\''),
            _ => entity
                .strip_prefix("#x")
                .and_then(|h| u32::from_str_radix(h, 16).ok())
                .or_else(|| entity.strip_prefix('#').and_then(|d| d.parse().ok()))
                .and_then(char::from_u32),
        };
        match c {
            Some(c) => {
                out.push(c);
                rest = &rest[end + 1..];
            }
            None => {
                out.push('&');
                rest = &rest[1..];
            }
        }
    }
    out.push_str(rest);
    out
}

fn encode<W: Write + Seek>(w: &mut W, grid: &Grid) -> std::result::Result<(), TiffError> {
    let g = &grid.geometry;
    let (nx, ny) = (
        u32::try_from(g.nx).map_err(|_| TiffError::IntSizeError)?,
        u32::try_from(g.ny).map_err(|_| TiffError::IntSizeError)?,
    );
    let mut tiff = TiffEncoder::new(w)?;
    let mut image = tiff.new_image::<Gray32Float>(nx, ny)?;
    let half = g.cell / 2.0;
    let (geokeys, ascii) = geokeys(grid);
    let metadata = format!(
        concat!(
            "<GDALMetadata>\n",
            "  <Item name=\"DESCRIPTION\" sample=\"0\" role=\"description\">{}</Item>\n",
            "  <Item name=\"UNITTYPE\" sample=\"0\" role=\"unittype\">{}</Item>\n",
            "</GDALMetadata>"
        ),
        xml_escape(&grid.name),
        xml_escape(&grid.unit)
    );
    let dir = image.encoder();
    dir.write_tag(Tag::ModelPixelScaleTag, &[g.cell, g.cell, 0.0][..])?;
    dir.write_tag(
        Tag::ModelTiepointTag,
        &[0.0, 0.0, 0.0, g.x0 - half, g.y_max() + half, 0.0][..],
    )?;
    dir.write_tag(Tag::GeoKeyDirectoryTag, &geokeys[..])?;
    dir.write_tag(Tag::GeoAsciiParamsTag, ascii.as_str())?;
    dir.write_tag(GDAL_METADATA, metadata.as_str())?;
    dir.write_tag(Tag::GdalNodata, format!("{NODATA}").as_str())?;
    // Strip by strip, from the northern row.
    let nodata = NODATA as f32;
    let mut row = g.ny;
    let mut strip = Vec::new();
    while row > 0 {
        let rows = (image.next_strip_sample_count() as usize / g.nx).min(row);
        strip.clear();
        for j in (row - rows..row).rev() {
            let values = &grid.values[g.index(0, j)..g.index(0, j) + g.nx];
            strip.extend(
                values
                    .iter()
                    .map(|&v| if v.is_nan() { nodata } else { v as f32 }),
            );
        }
        image.write_strip(&strip)?;
        row -= rows;
    }
    image.finish()
}

/// A TIFF decoder's error in words: the file ending inside a structure
/// said "failed to fill whole buffer".
fn tiff_reason(e: TiffError) -> String {
    match e {
        TiffError::IoError(io) if io.kind() == std::io::ErrorKind::UnexpectedEof => {
            "the file ends inside the TIFF structure (truncated or damaged)".to_string()
        }
        TiffError::LimitsExceeded => format!(
            "a tag declares more values than a GeoTIFF holds (over {}; damaged)",
            aeromag_core::memory::size_text(TAG_VALUES_BYTES as u64)
        ),
        e => e.to_string(),
    }
}

/// Checks, before the decoder reads them, that the strips (or tiles) hold
/// the image the header declares: each lies inside the file, and when
/// uncompressed each holds exactly its rows of `nx` samples of `bits` bits
/// (`StripByteCounts`), the last strip at least its rows and at most a
/// full strip (some writers pad it), a tile exactly `TileWidth ×
/// TileLength` samples. The decoder reads an uncompressed strip from its
/// offset for as many bytes as the declared width and rows need, whatever
/// its byte count: an `ImageWidth` one larger than the data (a corrupt
/// tag) read on past the strip into the file's metadata, every row
/// shifted by one more pixel, and `derive` wrote that skewed grid.
/// (Compressed chunks are bounded by their byte counts in the decoder: a
/// short one is an error there.)
fn check_chunks<R: std::io::Read + Seek>(
    dec: &mut Decoder<R>,
    path: &Path,
    (nx, ny): (u32, u32),
    bits: u8,
    compressed: bool,
    file_len: u64,
) -> Result<()> {
    let err = |e: TiffError| read_error(path, tiff_reason(e));
    let tiled = dec.find_tag(Tag::TileOffsets).map_err(err)?.is_some();
    let (kind, offsets_tag, counts_tag) = if tiled {
        ("tile", Tag::TileOffsets, Tag::TileByteCounts)
    } else {
        ("strip", Tag::StripOffsets, Tag::StripByteCounts)
    };
    let offsets = dec.get_tag_u64_vec(offsets_tag).map_err(err)?;
    let counts = dec.get_tag_u64_vec(counts_tag).map_err(err)?;
    if offsets.len() != counts.len() {
        return Err(read_error(
            path,
            format!(
                "{} {kind} offsets but {} {kind} byte counts",
                offsets.len(),
                counts.len()
            ),
        ));
    }
    let row_bytes = |width: u64| width.saturating_mul(u64::from(bits)).div_ceil(8);
    // Rows of a strip (or a tile's size); saturating products, as the
    // tags of a corrupt file may be up to 2³² each.
    let (rows_per_chunk, width) = if tiled {
        let mut tile = |t: Tag| dec.find_tag_unsigned::<u64>(t).map_err(err);
        (
            tile(Tag::TileLength)?.unwrap_or(0),
            tile(Tag::TileWidth)?.unwrap_or(0),
        )
    } else {
        let rows = dec
            .find_tag_unsigned::<u64>(Tag::RowsPerStrip)
            .map_err(err)?
            .unwrap_or(u64::from(ny));
        (rows.clamp(1, u64::from(ny)), u64::from(nx))
    };
    let n = offsets.len();
    for (k, (&offset, &count)) in offsets.iter().zip(&counts).enumerate() {
        if offset.checked_add(count).is_none_or(|end| end > file_len) {
            return Err(read_error(
                path,
                format!(
                    "{kind} {} of {n} ({count} bytes at byte {offset}) ends past the end of \
                     the file ({file_len} bytes): truncated or damaged",
                    k + 1
                ),
            ));
        }
        if compressed {
            continue;
        }
        let full = rows_per_chunk.saturating_mul(row_bytes(width));
        let (least, most) = if tiled {
            (full, full)
        } else {
            let first_row = (k as u64).saturating_mul(rows_per_chunk);
            let rows = rows_per_chunk.min(u64::from(ny).saturating_sub(first_row));
            let least = rows * row_bytes(width);
            (least, if k + 1 == n { full } else { least })
        };
        if !(least..=most).contains(&count) {
            let need = if least == most {
                format!("{least}")
            } else {
                format!("{least} to {most}")
            };
            return Err(read_error(
                path,
                format!(
                    "{kind} {} of {n} holds {count} bytes, but the header's {nx} × {ny} \
                     pixels of {bits} bits (ImageWidth × ImageLength) need {need}: the image \
                     size does not match its data (a damaged header)",
                    k + 1
                ),
            ));
        }
    }
    Ok(())
}

/// Most memory one tag's values may take while the tags are read (the
/// `tiff` decoder's own `Value`s, about 24 bytes each): 64 MiB, far above
/// any GeoTIFF's tie points, GeoKeys or GDAL metadata.
const TAG_VALUES_BYTES: usize = 64 << 20;

/// Reads a GeoTIFF (module docs for what is accepted). The name and unit
/// come from `GDAL_METADATA` (else the file stem and no unit), the CRS
/// from `ProjectedCSTypeGeoKey` when it is a WGS 84 / UTM code.
pub fn read(path: &Path) -> Result<Grid> {
    let file = File::open(path).map_err(|e| open_error(path, e))?;
    let err = |e: TiffError| read_error(path, tiff_reason(e));
    // Tags first, under a limit on the memory of one tag's values: a
    // corrupt count (the fuzz target's: 40 GB declared in a 655-byte file)
    // must be an error, not an allocation that aborts the process. The
    // image's size is checked against the file below, and then decoded
    // without a limit.
    let mut limits = Limits::unlimited();
    limits.decoding_buffer_size = TAG_VALUES_BYTES;
    let mut dec = Decoder::new(BufReader::new(file))
        .map_err(err)?
        .with_limits(limits);
    let (nx, ny) = dec.dimensions().map_err(err)?;
    if !matches!(dec.colortype().map_err(err)?, ColorType::Gray(_)) {
        return Err(read_error(path, "not a single-band image"));
    }
    let scale = dec.get_tag_f64_vec(Tag::ModelPixelScaleTag).map_err(err)?;
    let tie = dec.get_tag_f64_vec(Tag::ModelTiepointTag).map_err(err)?;
    if scale.len() < 2 || tie.len() < 6 {
        return Err(read_error(path, "no pixel scale or tie point"));
    }
    let (sx, sy) = (scale[0], scale[1]);
    if (sx - sy).abs() > 1e-9 * sx.abs() {
        return Err(read_error(
            path,
            format!("pixels of {} × {}: not square", shown(sx), shown(sy)),
        ));
    }
    let keys = match dec.find_tag(Tag::GeoKeyDirectoryTag).map_err(err)? {
        Some(v) => v.into_u16_vec().map_err(err)?,
        None => vec![],
    };
    let geokey = |id: u16| {
        keys.get(4..)
            .unwrap_or_default()
            .chunks_exact(4)
            .find(|k| k[0] == id && k[1] == 0)
            .map(|k| k[3])
    };
    // Coordinates in metres only (module docs).
    if geokey(key::MODEL_TYPE) == Some(key::GEOGRAPHIC) {
        let by = "its GTModelTypeGeoKey (2, geographic)";
        return Err(not_metres(path, by, &CoordinateUnit::Degree));
    }
    if let Some(code) = geokey(key::PROJ_LINEAR_UNITS)
        && let Some((_, name, metres)) = key::LINEAR_UNITS.iter().find(|u| u.0 == code)
        && code != key::METRE
    {
        let by = format!("its ProjLinearUnitsGeoKey ({code})");
        let unit = CoordinateUnit::Other(name.to_string(), *metres);
        return Err(not_metres(path, &by, &unit));
    }
    let point = geokey(key::RASTER_TYPE) == Some(key::PIXEL_IS_POINT);
    // The node of pixel (0, 0): the tie point's pixel (i, j) at (x, y).
    let shift = if point { 0.0 } else { 0.5 };
    let x0 = tie[3] + (shift - tie[0]) * sx;
    let y_north = tie[4] - (shift - tie[1]) * sy;
    let geometry = checked_geometry(
        path,
        GridGeometry {
            x0,
            y0: y_north - (ny as f64 - 1.0) * sy,
            cell: sx,
            nx: nx as usize,
            ny: ny as usize,
        },
    )?;
    // Before the decoder allocates the image: uncompressed samples take
    // their full size in the file; compressed ones at least 1/4096 of it
    // (LZW's best case, a 12-bit code for 4096 bytes; deflate's is 1/1032).
    let bytes = f64::from(dec.colortype().map_err(err)?.bit_depth()) / 8.0;
    let compressed = dec
        .find_tag_unsigned::<u16>(Tag::Compression)
        .map_err(err)?
        .is_some_and(|c| c != 1);
    let file_len = std::fs::metadata(path)
        .map_err(|e| read_error(path, e))?
        .len();
    check_declared_size(
        path,
        geometry.nx,
        geometry.ny,
        if compressed { bytes / 4096.0 } else { bytes },
        file_len,
    )?;
    let bits = dec.colortype().map_err(err)?.bit_depth();
    check_chunks(&mut dec, path, (nx, ny), bits, compressed, file_len)?;
    let nodata: Option<f64> = dec
        .find_tag(Tag::GdalNodata)
        .map_err(err)?
        .and_then(|v| v.into_string().ok())
        .and_then(|s| {
            s.trim_matches(|c: char| c == '\0' || c.is_whitespace())
                .parse()
                .ok()
        });
    let metadata = dec
        .find_tag(GDAL_METADATA)
        .map_err(err)?
        .and_then(|v| v.into_string().ok())
        .unwrap_or_default();
    let item = |role: &str| {
        let open = format!("role=\"{role}\">");
        let start = metadata.find(&open)? + open.len();
        let end = metadata[start..].find('<')?;
        Some(xml_unescape(&metadata[start..start + end]))
    };
    let mut dec = dec.with_limits(Limits::unlimited());
    let values: Vec<f64> = match dec.read_image().map_err(err)? {
        DecodingResult::F32(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::F64(v) => v,
        DecodingResult::U8(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::I8(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::U16(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::I16(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::U32(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::I32(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::U64(v) => v.into_iter().map(|x| x as f64).collect(),
        DecodingResult::I64(v) => v.into_iter().map(|x| x as f64).collect(),
        DecodingResult::F16(v) => v.into_iter().map(f64::from).collect(),
    };
    if values.len() != geometry.len() {
        return Err(read_error(
            path,
            format!("{} samples for {} × {} pixels", values.len(), nx, ny),
        ));
    }
    let mut grid = Grid::blank(
        geometry,
        &label_from_file(&item("description").unwrap_or_else(|| stem(path))),
        &label_from_file(&item("unittype").unwrap_or_default()),
    );
    // Nodata compared as the file's float32 (GDAL's rule for Float32).
    let blank = |v: f64| Some(v) == nodata || nodata.is_some_and(|n| v as f32 == n as f32);
    for (r, row) in values.chunks_exact(geometry.nx).enumerate() {
        let j = geometry.ny - 1 - r;
        for (i, &v) in row.iter().enumerate() {
            grid.values[geometry.index(i, j)] = if blank(v) { f64::NAN } else { v };
        }
    }
    check_values(path, &grid)?;
    grid.crs = geokey(key::PROJECTED_CRS).and_then(|c| crs_from_epsg(c.into()));
    Ok(grid)
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::super::{GridFormat, read_grid, write_grid};
    use super::*;

    /// GeoTIFFs compressed as GDAL, QGIS and ArcGIS export grids: the
    /// sample grid through `gdal_translate` with each compression and
    /// predictor (and tiles, and as float64) reads back to the same nodes,
    /// values and blanks. Skipped (with a message) when GDAL is not on PATH.
    #[test]
    fn compressed_and_tiled_geotiffs_written_by_gdal_are_read() {
        if !gdal_runs("gdal_translate") {
            return;
        }
        let dir = tempfile::tempdir().unwrap();
        let plain = dir.path().join("plain.tif");
        let grid = sample_grid();
        write_grid(&plain, &grid).unwrap();
        for options in [
            &["-co", "COMPRESS=DEFLATE"][..],
            &["-co", "COMPRESS=LZW"],
            &["-co", "COMPRESS=PACKBITS"],
            &["-co", "COMPRESS=DEFLATE", "-co", "PREDICTOR=3"],
            &[
                "-co",
                "COMPRESS=LZW",
                "-co",
                "PREDICTOR=2",
                "-ot",
                "Float64",
            ],
            &[
                "-co",
                "COMPRESS=DEFLATE",
                "-co",
                "TILED=YES",
                "-co",
                "BLOCKXSIZE=16",
                "-co",
                "BLOCKYSIZE=16",
            ],
        ] {
            let out = dir.path().join("c.tif");
            gdal_translate(options, &plain, &out);
            let back = read_grid(&out).unwrap_or_else(|e| panic!("{options:?}: {e}"));
            assert_same_grid(&grid, &back);
        }
    }

    #[test]
    fn geotiff_tags_decode_back() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("g.tif");
        let grid = sample_grid();
        assert_eq!(write_grid(&path, &grid).unwrap(), GridFormat::GeoTiff);
        let mut dec = Decoder::new(BufReader::new(File::open(&path).unwrap())).unwrap();
        assert_eq!(dec.dimensions().unwrap(), (5, 4));
        assert_eq!(dec.colortype().unwrap(), ColorType::Gray(32));
        assert_eq!(dec.get_tag_u16_vec(Tag::SampleFormat).unwrap(), [3]); // IEEE float
        assert_eq!(
            dec.get_tag_f64_vec(Tag::ModelPixelScaleTag).unwrap(),
            [50.0, 50.0, 0.0]
        );
        // PixelIsArea: the corner half a cell north-west of the NW node.
        assert_eq!(
            dec.get_tag_f64_vec(Tag::ModelTiepointTag).unwrap(),
            [0.0, 0.0, 0.0, 499_975.0, 6_000_225.0, 0.0]
        );
        let keys = dec.get_tag_u16_vec(Tag::GeoKeyDirectoryTag).unwrap();
        let citation = "WGS 84 / UTM zone 37N|";
        assert_eq!(
            keys,
            [
                1,
                1,
                0,
                5, //
                1024,
                0,
                1,
                1, // projected
                1025,
                0,
                1,
                1, // PixelIsArea
                1026,
                34737,
                citation.len() as u16,
                0, // citation
                3072,
                0,
                1,
                32637, // EPSG
                3076,
                0,
                1,
                9001, // metre
            ]
        );
        let ascii = dec
            .get_tag(Tag::GeoAsciiParamsTag)
            .unwrap()
            .into_string()
            .unwrap();
        assert_eq!(ascii, citation);
        let nodata = dec.get_tag(Tag::GdalNodata).unwrap().into_string().unwrap();
        assert_eq!(nodata, "-99999");
        let meta = dec.get_tag(GDAL_METADATA).unwrap().into_string().unwrap();
        assert!(meta.contains("role=\"unittype\">nT</Item>"), "{meta}");
        let DecodingResult::F32(v) = dec.read_image().unwrap() else {
            panic!("not float32")
        };
        // The first row is the northern one (j = 3), its last node blank.
        assert_eq!(
            v[..5],
            [3000.1235, 3001.1235, 3002.1235, 3003.1235, -99999.0]
        );
        // The last row is the southern one (j = 0), node 1 blank.
        assert_eq!(
            v[15..],
            [0.12345679, -99999.0, 2.1234567, 3.1234567, 4.123457]
        );

        assert_same_grid(&grid, &read_grid(&path).unwrap());
        let back = read(&path).unwrap();
        assert_eq!(
            (back.name.as_str(), back.unit.as_str()),
            ("magnetic anomaly", "nT")
        );
    }

    #[test]
    fn geotiff_without_crs_is_user_defined() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("g.tiff");
        let mut grid = sample_grid();
        grid.crs = None;
        grid.name = "B<&>é".into();
        write_grid(&path, &grid).unwrap();
        let mut dec = Decoder::new(BufReader::new(File::open(&path).unwrap())).unwrap();
        let keys = dec.get_tag_u16_vec(Tag::GeoKeyDirectoryTag).unwrap();
        assert_eq!(keys[3], 4);
        assert!(!keys.chunks_exact(4).skip(1).any(|k| k[0] == 3072));
        assert!(
            keys.chunks_exact(4)
                .skip(1)
                .any(|k| k == [3076, 0, 1, 9001])
        );
        let back = read(&path).unwrap();
        assert_same_grid(&grid, &back);
        assert_eq!(back.name, grid.name);
    }

    #[test]
    fn geotiff_of_many_strips_keeps_the_row_order() {
        // 300 × 900 float32 rows of 1200 bytes: strips of 834 rows, so the
        // last strip is short.
        let geometry = GridGeometry {
            x0: 0.0,
            y0: 0.0,
            cell: 1.0,
            nx: 300,
            ny: 900,
        };
        let mut grid = Grid::blank(geometry, "z", "");
        for (k, v) in grid.values.iter_mut().enumerate() {
            *v = k as f64;
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("big.tif");
        write_grid(&path, &grid).unwrap();
        let back = read_grid(&path).unwrap();
        assert_eq!(back.values, grid.values);
        assert_eq!(back.geometry, geometry);
        assert_eq!(back.crs, None);
    }

    #[test]
    fn xml_escapes_round_trip() {
        let s = "a<b>&\"c\" é ∂";
        assert_eq!(xml_unescape(&xml_escape(s)), s);
        assert!(xml_escape(s).is_ascii());
        assert_eq!(xml_unescape("&#x41;&bogus;&"), "A&bogus;&");
    }

    /// The bytes of a written GeoTIFF with the value of tag `tag` in its
    /// first IFD set to `value` (a little-endian file: tag, type, count,
    /// value in 12-byte entries).
    fn patched_tag(bytes: &[u8], tag: u16, value: u32) -> Vec<u8> {
        let mut b = bytes.to_vec();
        assert_eq!(&b[..2], b"II");
        let ifd = u32::from_le_bytes(b[4..8].try_into().unwrap()) as usize;
        let n = u16::from_le_bytes(b[ifd..ifd + 2].try_into().unwrap()) as usize;
        let entry = (0..n)
            .map(|k| ifd + 2 + 12 * k)
            .find(|&e| u16::from_le_bytes(b[e..e + 2].try_into().unwrap()) == tag)
            .unwrap();
        match u16::from_le_bytes(b[entry + 2..entry + 4].try_into().unwrap()) {
            3 => b[entry + 8..entry + 10].copy_from_slice(&(value as u16).to_le_bytes()),
            4 => b[entry + 8..entry + 12].copy_from_slice(&value.to_le_bytes()),
            t => panic!("type {t}"),
        }
        b
    }

    #[test]
    fn a_corrupt_geotiff_is_refused_with_a_short_message_before_allocating() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("g.tif");
        write_grid(&path, &sample_grid()).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        // A pixel scale of ~10³⁰⁰ m: shown in exponent form.
        let fifty = 50.0f64.to_le_bytes();
        let at = bytes
            .windows(16)
            .position(|w| w[..8] == fifty && w[8..] == fifty)
            .unwrap();
        let mut b = bytes.clone();
        b[at..at + 8].copy_from_slice(&9.745314011399999e300f64.to_le_bytes());
        let bad = dir.path().join("scale.tif");
        std::fs::write(&bad, &b).unwrap();
        let e = read(&bad).unwrap_err().to_string();
        assert!(
            e.contains("scale.tif") && e.contains("9.745314011399999e300"),
            "{e}"
        );
        assert!(e.len() < 150, "{e}");
        // 15800 × 15800 float32 pixels declared in a file of a few hundred
        // bytes: refused from the header (2 GB were allocated).
        let b = patched_tag(&patched_tag(&bytes, 256, 15800), 257, 15800);
        let big = dir.path().join("big.tif");
        std::fs::write(&big, &b).unwrap();
        let e = read(&big).unwrap_err();
        assert!(e.is_bad_input());
        let e = e.to_string();
        assert!(
            e.contains("big.tif") && e.contains("15800 × 15800") && e.contains("but the file has"),
            "{e}"
        );
        // A TIFF header and then junk, and a file cut in its tags: said
        // "failed to fill whole buffer".
        for (name, b) in [
            ("junk.tif", b"II*\x00junk".to_vec()),
            ("cut.tif", bytes[..bytes.len().min(40)].to_vec()),
        ] {
            let p = dir.path().join(name);
            std::fs::write(&p, &b).unwrap();
            let e = read(&p).unwrap_err();
            assert!(e.is_bad_input());
            let e = e.to_string();
            assert!(
                e.contains(name) && e.contains("truncated or damaged"),
                "{e}"
            );
        }
    }

    /// A tag whose count declares 40 GB in a 655-byte file (found by the
    /// `grid` fuzz target; the decoder's limits were off, and the
    /// allocation aborted the process): an error naming the file.
    #[test]
    fn a_tag_larger_than_its_file_is_refused_without_allocating_it() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data/hostile/huge_tag_count.tif");
        let e = read(&path).unwrap_err();
        assert!(e.is_bad_input(), "{e}");
        let text = e.to_string();
        assert!(
            text.contains("huge_tag_count.tif") && text.contains("a tag declares more values"),
            "{text}"
        );
    }

    /// An `ImageWidth` (or `ImageLength`) that does not match the strip:
    /// one more column than the data was read on past the strip into the
    /// file's metadata, a skewed grid and exit 0 (finding 19); one fewer
    /// read a grid sheared the other way. Both are refused naming the
    /// file and the sizes; the same in a file of many strips.
    #[test]
    fn an_image_size_that_does_not_match_the_strips_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("g.tif");
        write_grid(&path, &sample_grid()).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        // 5 × 4 float32: one strip of 80 bytes.
        for (tag, value, need) in [
            (256, 6, "need 96"),
            (256, 4, "need 64"),
            (257, 5, "need 100"),
            (257, 3, "need 60"),
        ] {
            let bad = dir.path().join(format!("w{tag}_{value}.tif"));
            std::fs::write(&bad, patched_tag(&bytes, tag, value)).unwrap();
            let e = read(&bad).unwrap_err();
            assert!(e.is_bad_input());
            let e = e.to_string();
            assert!(
                e.contains(&format!("w{tag}_{value}.tif"))
                    && e.contains("strip 1 of 1 holds 80 bytes")
                    && e.contains(need),
                "{e}"
            );
        }
        // 300 × 900 rows in strips of 834 rows: a width of 299 is
        // refused at the first strip.
        let mut grid = Grid::blank(
            GridGeometry {
                x0: 0.0,
                y0: 0.0,
                cell: 1.0,
                nx: 300,
                ny: 900,
            },
            "z",
            "",
        );
        grid.values.fill(1.0);
        let big = dir.path().join("big.tif");
        write_grid(&big, &grid).unwrap();
        let bytes = std::fs::read(&big).unwrap();
        std::fs::write(&big, patched_tag(&bytes, 256, 299)).unwrap();
        let e = read(&big).unwrap_err().to_string();
        assert!(
            e.contains("strip 1 of 2 holds 1000800 bytes") && e.contains("need 997464"),
            "{e}"
        );
        // A strip whose byte count runs past the end of the file.
        let bytes = std::fs::read(&path).unwrap();
        std::fs::write(&path, patched_tag(&bytes, 279, 100_000)).unwrap();
        let e = read(&path).unwrap_err().to_string();
        assert!(
            e.contains("strip 1 of 1 (100000 bytes at byte") && e.contains("ends past the end"),
            "{e}"
        );
    }

    /// A GeoTIFF of a geographic model (degrees) or in feet was read as
    /// metres (finding 08): now refused naming the file and the key.
    #[test]
    fn a_geotiff_not_in_metres_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("g.tif");
        write_grid(&path, &sample_grid()).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let key = |k: [u16; 4]| k.iter().flat_map(|v| v.to_le_bytes()).collect::<Vec<u8>>();
        for (from, to, named, what) in [
            (
                [1024, 0, 1, 1],
                [1024, 0, 1, 2],
                "GTModelTypeGeoKey (2, geographic)",
                "a geographic coordinate system",
            ),
            (
                [3076, 0, 1, 9001],
                [3076, 0, 1, 9003],
                "ProjLinearUnitsGeoKey (9003)",
                "coordinates in \"US survey foot\" (0.3048006096012192 m)",
            ),
        ] {
            let (from, to) = (key(from), key(to));
            let at = bytes.windows(8).position(|w| w == from).unwrap();
            let mut b = bytes.clone();
            b[at..at + 8].copy_from_slice(&to);
            let bad = dir.path().join("bad.tif");
            std::fs::write(&bad, &b).unwrap();
            let e = read(&bad).unwrap_err();
            assert!(e.is_bad_input());
            let e = e.to_string();
            assert!(
                e.contains("bad.tif")
                    && e.contains(&format!("its {named} declares {what}"))
                    && e.contains("in metres (e.g. UTM)"),
                "{e}"
            );
        }
    }
}
