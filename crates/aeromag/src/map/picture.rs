//! Pictures of grids: the map a survey processor looks at first, as PNG or
//! SVG (`aeromag grid --map`, `aeromag derive --map`, the demo's maps).
//!
//! A field is drawn in viridis with colour-shaded relief (each cell
//! darkened by its illumination from the north-east at 45°, which shows
//! short-wavelength detail and line-to-line stripes); a derivative or a
//! difference in diverging colours centred on zero, unshaded. Axes are
//! easting and northing in km at one scale on both (north up), blank
//! nodes light grey, the flight lines one grey pixel wide over the cells
//! ([`tracks`]).
//!
//! ```
//! use aeromag::grid::{Grid, GridGeometry};
//! use aeromag::map::picture::MapPicture;
//! let geometry = GridGeometry::covering(500_000.0, 503_900.0, 6_000_000.0, 6_002_900.0, 100.0)?;
//! let mut grid = Grid::blank(geometry, "mag_comp_level", "nT");
//! for (k, v) in grid.values.iter_mut().enumerate() {
//!     *v = ((k % geometry.nx) as f64 / 6.0).sin() * 20.0;
//! }
//! let svg = MapPicture::field(&grid).heatmap(&grid).to_svg()?;
//! assert!(svg.contains("mag_comp_level"));
//! # Ok::<(), aeromag::Error>(())
//! ```

use crate::error::{Error, Result};
use crate::map::ProjectedSurvey;
use aeromag_grid::Grid;
pub use aeromag_report::Colormap;
use aeromag_report::Heatmap;
use std::collections::BTreeMap;
use std::path::Path;

/// Size of a map written as PNG, pixels (the plot keeps the grid's aspect
/// ratio inside it).
pub const PNG_SIZE: (u32, u32) = (1200, 900);

/// How a grid is drawn ([`MapPicture::write`]).
#[derive(Debug, Clone, PartialEq)]
pub struct MapPicture {
    /// Title above the map.
    pub title: String,
    /// Colour-bar label, with its unit.
    pub label: String,
    /// The colours.
    pub colormap: Colormap,
    /// Colour-shaded relief ([`Heatmap::shaded`]).
    pub shaded: bool,
    /// Flight lines drawn over the cells: polylines in the grid's
    /// coordinates, m ([`tracks`]).
    pub tracks: Vec<Vec<(f64, f64)>>,
}

/// The picture formats, by the file's extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PictureFormat {
    /// PNG of [`PNG_SIZE`].
    Png,
    /// SVG (the cells one inline PNG, the text and lines vector).
    Svg,
}

impl PictureFormat {
    /// The format of a picture named `path`: `.png` or `.svg` (any case);
    /// bad input otherwise.
    pub fn of_path(path: &Path) -> Result<Self> {
        match aeromag_core::file_name::extension(path).as_str() {
            "png" => Ok(PictureFormat::Png),
            "svg" => Ok(PictureFormat::Svg),
            _ => Err(Error::bad_file(
                path.display().to_string(),
                "a map is written as PNG (.png) or SVG (.svg)",
            )),
        }
    }
}

impl MapPicture {
    /// A field map of `grid`: viridis with shaded relief, titled with the
    /// grid's name, the colour bar in its unit.
    pub fn field(grid: &Grid) -> Self {
        Self {
            title: grid.name.clone(),
            label: grid.unit.clone(),
            colormap: Colormap::Viridis,
            shaded: true,
            tracks: Vec::new(),
        }
    }

    /// A map of a signed quantity (a derivative, a difference): diverging
    /// colours centred on zero, unshaded.
    pub fn diverging(grid: &Grid) -> Self {
        Self {
            colormap: Colormap::Diverging,
            shaded: false,
            ..Self::field(grid)
        }
    }

    /// The picture with `tracks` drawn over the cells.
    pub fn with_tracks(self, tracks: Vec<Vec<(f64, f64)>>) -> Self {
        Self { tracks, ..self }
    }

    /// The heatmap of `grid` as this picture draws it (axes in km).
    pub fn heatmap(&self, grid: &Grid) -> Heatmap {
        let g = grid.geometry;
        let km = |v: f64| v / 1000.0;
        let mut h = Heatmap::new(
            self.title.clone(),
            "easting (km)",
            "northing (km)",
            (0..g.nx).map(|i| km(g.x(i))).collect(),
            (0..g.ny).map(|j| km(g.y(j))).collect(),
            grid.values.clone(),
            self.label.clone(),
        );
        h.colormap = self.colormap;
        h.equal_aspect = true;
        h.shaded = self.shaded;
        h.overlay = self
            .tracks
            .iter()
            .map(|t| t.iter().map(|&(x, y)| (km(x), km(y))).collect())
            .collect();
        h
    }

    /// Write the picture of `grid` to `path`, PNG or SVG by its extension
    /// ([`PictureFormat::of_path`]), atomically.
    pub fn write(&self, grid: &Grid, path: &Path) -> Result<PictureFormat> {
        let format = PictureFormat::of_path(path)?;
        let h = self.heatmap(grid);
        match format {
            PictureFormat::Png => h.to_png(path, PNG_SIZE.0, PNG_SIZE.1)?,
            PictureFormat::Svg => aeromag_io::atomic::write_file(path, h.to_svg()?.as_bytes())
                .map_err(|source| Error::Write {
                    path: path.to_path_buf(),
                    source,
                })?,
        }
        Ok(format)
    }
}

/// The flight lines of a projected survey as polylines, m: a point every
/// `step` rows of each line (rows on no line and rows without a position
/// left out), the lines in the order of their ids; none without a `line`
/// column.
pub fn tracks(survey: &ProjectedSurvey, step: usize) -> Vec<Vec<(f64, f64)>> {
    let mut lines: BTreeMap<i64, Vec<(f64, f64)>> = BTreeMap::new();
    if let Some(ids) = &survey.line_ids {
        for k in (0..ids.len()).step_by(step.max(1)) {
            if ids[k] != 0.0 && survey.x[k].is_finite() && survey.y[k].is_finite() {
                lines
                    .entry(ids[k] as i64)
                    .or_default()
                    .push((survey.x[k], survey.y[k]));
            }
        }
    }
    lines.into_values().collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use aeromag_grid::GridGeometry;

    fn grid() -> Grid {
        let geometry =
            GridGeometry::covering(500_000.0, 502_900.0, 6_000_000.0, 6_001_900.0, 100.0).unwrap();
        let mut g = Grid::blank(geometry, "mag_comp", "nT");
        for (k, v) in g.values.iter_mut().enumerate() {
            *v = if k % 97 == 0 {
                f64::NAN
            } else {
                (k as f64 / 11.0).sin()
            };
        }
        g
    }

    #[test]
    fn pictures_are_written_by_their_extension_and_the_same_bytes_twice() {
        let dir = tempfile::tempdir().unwrap();
        let g = grid();
        let p = MapPicture::field(&g).with_tracks(vec![vec![
            (500_000.0, 6_000_000.0),
            (502_000.0, 6_001_000.0),
        ]]);
        for (name, format, magic) in [
            ("m.png", PictureFormat::Png, &b"\x89PNG"[..]),
            ("m.svg", PictureFormat::Svg, &b"<svg"[..]),
        ] {
            let path = dir.path().join(name);
            assert_eq!(p.write(&g, &path).unwrap(), format);
            let bytes = std::fs::read(&path).unwrap();
            assert!(
                bytes.windows(magic.len()).take(200).any(|w| w == magic),
                "{name}"
            );
            p.write(&g, &path).unwrap();
            assert_eq!(
                std::fs::read(&path).unwrap(),
                bytes,
                "{name}: deterministic"
            );
        }
        let e = p.write(&g, &dir.path().join("m.jpg")).unwrap_err();
        assert!(
            e.is_bad_input() && e.to_string().contains("PNG (.png) or SVG (.svg)"),
            "{e}"
        );
    }

    #[test]
    fn a_field_is_shaded_and_a_difference_diverges() {
        let g = grid();
        let (f, d) = (
            MapPicture::field(&g).heatmap(&g),
            MapPicture::diverging(&g).heatmap(&g),
        );
        assert!(f.shaded && f.colormap == Colormap::Viridis && f.equal_aspect);
        assert!(!d.shaded && d.colormap == Colormap::Diverging);
        assert_eq!((f.x[0], f.y[0]), (500.0, 6000.0), "km");
        assert_eq!(f.title, "mag_comp");
        assert_eq!(f.colorbar_label, "nT");
    }
}
