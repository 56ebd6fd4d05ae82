//! Heatmaps ([`Heatmap`]) of a value on a rectilinear grid, with a colour bar.
//!
//! The grid is given by cell-centre coordinates `x[ix]`, `y[iy]` (strictly
//! increasing, any spacing) and row-major values `values[iy·nx + ix]`; row 0
//! (`y[0]`) is at the bottom. Cell edges are the midpoints between centres,
//! the outer edges lie half a spacing beyond the first/last centre (a single
//! centre gets a cell of width 1). Colour = colormap((v − lo)/(hi − lo)) with
//! values outside `[lo, hi]` clamped; NaN cells are drawn light grey.
//!
//! The default value range `[lo, hi]` is the finite minimum and maximum; with
//! [`Colormap::Diverging`] it is `±max|v|` so that white means zero.
//!
//! In SVG the cells are one inline PNG (`<image>`): for a uniform grid the
//! PNG has one pixel per cell, scaled with `image-rendering: pixelated`; for
//! a non-uniform grid it is resampled at the plot's pixel resolution.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::axis::Scale;
use super::canvas::{
    self, AxisSpec, Canvas, Figure, Margins, Raster, X_PX_PER_LABEL, Y_PX_PER_LABEL, text_size,
    text_style,
};
use super::colormap::Colormap;
use super::ticks;
use crate::error::{ReportError, Result};
use crate::style::{Rgb, theme};

/// A colour-coded grid of values with a colour bar.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Heatmap {
    /// Title above the plot.
    pub title: String,
    /// x-axis description with units.
    pub x_label: String,
    /// y-axis description with units.
    pub y_label: String,
    /// Cell-centre x coordinates, strictly increasing (`nx` values).
    pub x: Vec<f64>,
    /// Cell-centre y coordinates, strictly increasing (`ny` values).
    pub y: Vec<f64>,
    /// `nx · ny` values, row-major: `values[iy * nx + ix]`; NaN = no data.
    pub values: Vec<f64>,
    /// Colour-bar description with units, e.g. `"anomaly (nT)"`.
    pub colorbar_label: String,
    /// Colour map (default viridis).
    pub colormap: Colormap,
    /// Fixed value range `(lo, hi)` of the colour bar; `None` → automatic.
    pub value_range: Option<(f64, f64)>,
    /// One metre per pixel on both axes (maps in easting/northing): the plot
    /// area shrinks to the data's aspect ratio and is centred.
    pub equal_aspect: bool,
    /// Colour-shaded relief: each cell's colour is darkened by the
    /// illumination of the surface from the north-east at 45° elevation
    /// (the gradient scaled so that its RMS slope is 45°), as magnetic maps
    /// are drawn to show short-wavelength detail and stripes.
    pub shaded: bool,
    /// Polylines drawn over the cells in data coordinates (flight lines),
    /// one dark grey pixel wide.
    pub overlay: Vec<Vec<(f64, f64)>>,
}

/// Width reserved right of the plot for the colour bar, excluding labels.
const BAR_GAP: i32 = 18;
const BAR_W: i32 = 18;
/// Pixels per colour-bar label.
const BAR_PX_PER_LABEL: i32 = 45;

impl Heatmap {
    /// A heatmap with viridis colours and an automatic value range.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
        x: Vec<f64>,
        y: Vec<f64>,
        values: Vec<f64>,
        colorbar_label: impl Into<String>,
    ) -> Self {
        Heatmap {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            x,
            y,
            values,
            colorbar_label: colorbar_label.into(),
            ..Heatmap::default()
        }
    }

    /// SVG document of [`DEFAULT_SIZE`](crate::DEFAULT_SIZE) pixels.
    pub fn to_svg(&self) -> Result<String> {
        let (w, h) = crate::DEFAULT_SIZE;
        self.to_svg_sized(w, h)
    }

    /// SVG document of `width × height` pixels.
    pub fn to_svg_sized(&self, width: u32, height: u32) -> Result<String> {
        canvas::render_svg(self, width, height)
    }

    /// Writes a `width × height` PNG to `path` (parent folders are created).
    pub fn to_png(&self, path: impl AsRef<Path>, width: u32, height: u32) -> Result<()> {
        canvas::render_png(self, path.as_ref(), width, height)
    }

    /// Cell edges of one axis (`n + 1` values).
    fn edges(&self, centres: &[f64], axis: &'static str) -> Result<Vec<f64>> {
        let bad = |reason: &str| ReportError::InvalidGrid {
            title: self.title.clone(),
            axis,
            reason: reason.to_string(),
        };
        if centres.is_empty() {
            return Err(bad("are empty"));
        }
        if centres.iter().any(|v| !v.is_finite()) {
            return Err(bad("contain NaN or infinity"));
        }
        if centres.windows(2).any(|w| w[1] <= w[0]) {
            return Err(bad("are not strictly increasing"));
        }
        let n = centres.len();
        if n == 1 {
            return Ok(vec![centres[0] - 0.5, centres[0] + 0.5]);
        }
        let mut e = Vec::with_capacity(n + 1);
        e.push(centres[0] - 0.5 * (centres[1] - centres[0]));
        e.extend(centres.windows(2).map(|w| 0.5 * (w[0] + w[1])));
        e.push(centres[n - 1] + 0.5 * (centres[n - 1] - centres[n - 2]));
        Ok(e)
    }

    /// Colour-bar range.
    fn value_range(&self) -> Result<(f64, f64)> {
        if let Some((lo, hi)) = self.value_range {
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(ReportError::InvalidRange {
                    axis: "value",
                    reason: format!("({lo}, {hi}) must be finite with lo < hi"),
                });
            }
            return Ok((lo, hi));
        }
        let finite = self.values.iter().copied().filter(|v| v.is_finite());
        let (lo, hi) = finite.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
        if lo > hi {
            return Err(ReportError::NoData {
                title: self.title.clone(),
            });
        }
        let (lo, hi) = match self.colormap {
            Colormap::Diverging => {
                let m = lo.abs().max(hi.abs());
                (-m, m)
            }
            Colormap::Viridis => (lo, hi),
        };
        if lo < hi {
            Ok((lo, hi))
        } else if lo == 0.0 {
            Ok((-1.0, 1.0))
        } else {
            Ok((lo - 0.01 * lo.abs(), hi + 0.01 * hi.abs()))
        }
    }

    fn color_of(&self, v: f64, (lo, hi): (f64, f64)) -> Rgb {
        if v.is_finite() {
            self.colormap.color((v - lo) / (hi - lo))
        } else {
            theme::MISSING
        }
    }

    /// Per cell, the brightness factor of [`Heatmap::shaded`]
    /// (`0.55 + 0.45 · max(0, n̂·l̂)`; 1 for blank cells and unshaded maps).
    fn shading(&self) -> Vec<f64> {
        let (nx, ny) = (self.x.len(), self.y.len());
        let mut f = vec![1.0; nx * ny];
        if !self.shaded || nx < 2 || ny < 2 {
            return f;
        }
        let v = |i: usize, j: usize| self.values[j * nx + i];
        // Central (one-sided at the edges) differences, per unit of x and y.
        let grad = |i: usize, j: usize| {
            let (i0, i1) = (i.saturating_sub(1), (i + 1).min(nx - 1));
            let (j0, j1) = (j.saturating_sub(1), (j + 1).min(ny - 1));
            (
                (v(i1, j) - v(i0, j)) / (self.x[i1] - self.x[i0]),
                (v(i, j1) - v(i, j0)) / (self.y[j1] - self.y[j0]),
            )
        };
        let g: Vec<(f64, f64)> = (0..nx * ny).map(|k| grad(k % nx, k / nx)).collect();
        let finite: Vec<f64> = g
            .iter()
            .filter(|(a, b)| a.is_finite() && b.is_finite())
            .map(|(a, b)| a * a + b * b)
            .collect();
        if finite.is_empty() {
            return f;
        }
        let rms = (finite.iter().sum::<f64>() / finite.len() as f64).sqrt();
        if rms.is_nan() || rms <= 0.0 {
            return f;
        }
        let (az, el) = (45f64.to_radians(), 45f64.to_radians());
        let light = (el.cos() * az.sin(), el.cos() * az.cos(), el.sin());
        for (fk, (gx, gy)) in f.iter_mut().zip(&g) {
            if gx.is_finite() && gy.is_finite() {
                let (px, py) = (gx / rms, gy / rms);
                let n = (1.0 + px * px + py * py).sqrt();
                let cos_i = (-px * light.0 - py * light.1 + light.2) / n;
                *fk = 0.55 + 0.45 * cos_i.max(0.0);
            }
        }
        f
    }

    /// The cell raster: one pixel per cell for uniform grids, else sampled
    /// at `w × h` pixels. Rows top (max y) to bottom.
    fn cell_image(
        &self,
        xe: &[f64],
        ye: &[f64],
        w: u32,
        h: u32,
        range: (f64, f64),
    ) -> (u32, u32, Vec<u8>) {
        let nx = self.x.len();
        let (img_w, img_h) = if is_uniform(xe) && is_uniform(ye) {
            (nx as u32, self.y.len() as u32)
        } else {
            (w.max(1), h.max(1))
        };
        // Cell index of each image column / row by pixel-centre lookup.
        let lookup = |edges: &[f64], n_px: u32, i: u32| -> usize {
            let (lo, hi) = (edges[0], edges[edges.len() - 1]);
            let v = lo + (f64::from(i) + 0.5) / f64::from(n_px) * (hi - lo);
            edges.partition_point(|&e| e <= v).clamp(1, edges.len() - 1) - 1
        };
        let cols: Vec<usize> = (0..img_w).map(|i| lookup(xe, img_w, i)).collect();
        let shade = self.shading();
        let mut rgb = Vec::with_capacity(img_w as usize * img_h as usize * 3);
        for row in 0..img_h {
            // Image row 0 is the top = largest y.
            let iy = lookup(ye, img_h, img_h - 1 - row);
            for &ix in &cols {
                let k = iy * nx + ix;
                let Rgb(r, g, b) = self.color_of(self.values[k], range);
                let f = shade[k];
                let dim = |c: u8| (f64::from(c) * f).round().clamp(0.0, 255.0) as u8;
                rgb.extend_from_slice(&[dim(r), dim(g), dim(b)]);
            }
        }
        (img_w, img_h, rgb)
    }
}

/// The largest `(w, h)` inside `avail` pixels with `w / h = spans.0 / spans.1`.
fn fit_aspect(avail: (i32, i32), spans: (f64, f64)) -> (i32, i32) {
    let scale = (f64::from(avail.0) / spans.0).min(f64::from(avail.1) / spans.1);
    (
        ((spans.0 * scale).round() as i32).clamp(1, avail.0.max(1)),
        ((spans.1 * scale).round() as i32).clamp(1, avail.1.max(1)),
    )
}

/// Whether edges are equally spaced to 10⁻⁶ of the mean spacing.
fn is_uniform(edges: &[f64]) -> bool {
    let n = edges.len() - 1;
    let mean = (edges[n] - edges[0]) / n as f64;
    edges
        .windows(2)
        .all(|w| ((w[1] - w[0]) - mean).abs() <= 1e-6 * mean.abs())
}

impl Figure for Heatmap {
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        canvas: &mut Canvas,
    ) -> Result<()> {
        let xe = self.edges(&self.x, "x")?;
        let ye = self.edges(&self.y, "y")?;
        let expected = self.x.len() * self.y.len();
        if self.values.len() != expected {
            return Err(ReportError::ShapeMismatch {
                title: self.title.clone(),
                expected,
                got: self.values.len(),
            });
        }
        let range = self.value_range()?;

        let area = canvas::draw_header(root, &self.title, &[])?;
        let (aw, ah) = area.dim_in_pixel();
        let plot_h = ah as i32 - 80;
        let bar_ticks = ticks::linear_ticks(
            range.0,
            range.1,
            (plot_h / BAR_PX_PER_LABEL).clamp(2, 10) as usize,
        );
        let tick_style = text_style(theme::TICK_SIZE, theme::TICK_TEXT);
        let label_style = text_style(theme::LABEL_SIZE, theme::TEXT);
        let mut widest = 0;
        for l in &bar_ticks.labels {
            widest = widest.max(text_size(&area, l, &tick_style)?.0 as i32);
        }
        let desc_h = text_size(&area, &self.colorbar_label, &label_style)?.1 as i32;
        let bar_space = BAR_GAP + BAR_W + 8 + widest + 10 + desc_h + 6;

        let x_view = (xe[0], xe[xe.len() - 1]);
        let y_view = (ye[0], ye[ye.len() - 1]);
        let axes = |len: (i32, i32)| {
            (
                AxisSpec::new(&self.x_label, Scale::Linear, x_view, len.0, X_PX_PER_LABEL),
                AxisSpec::new(&self.y_label, Scale::Linear, y_view, len.1, Y_PX_PER_LABEL),
            )
        };
        let mut margins = Margins {
            right: bar_space as u32,
            ..Margins::default()
        };
        let (mut x, mut y) = axes((aw as i32 - 120 - bar_space, plot_h));
        if self.equal_aspect {
            // Shrink the plot to one scale on both axes: tick density first
            // for the shrunk size, then exact margins for those ticks.
            let spans = (x_view.1 - x_view.0, y_view.1 - y_view.0);
            let free = |x: &AxisSpec, y: &AxisSpec| -> Result<(i32, i32)> {
                let c = canvas::build_chart(&area, x, y, margins)?;
                let (x0, y0, x1, y1) = canvas::plot_rect(&c);
                Ok((x1 - x0, y1 - y0))
            };
            (x, y) = axes(fit_aspect(free(&x, &y)?, spans));
            let avail = free(&x, &y)?;
            let (w, h) = fit_aspect(avail, spans);
            let (dw, dh) = ((avail.0 - w).max(0) as u32, (avail.1 - h).max(0) as u32);
            margins.left = dw / 2;
            margins.right += dw - dw / 2;
            margins.top = dh / 2;
            margins.bottom = dh - dh / 2;
        }
        let mut chart = canvas::build_chart(&area, &x, &y, margins)?;

        // Cells, under the axes.
        let (px0, py0, px1, py1) = canvas::plot_rect(&chart);
        let (w, h) = ((px1 - px0).max(1) as u32, (py1 - py0).max(1) as u32);
        let (img_w, img_h, rgb) = self.cell_image(&xe, &ye, w, h, range);
        canvas.raster(
            root,
            Raster {
                origin: (px0, py0),
                size: (w, h),
                img_w,
                img_h,
                rgb,
            },
        )?;
        let line_style = theme::AXIS.to_plotters().stroke_width(1);
        for line in &self.overlay {
            chart
                .draw_series(LineSeries::new(line.iter().copied(), line_style))
                .map_err(ReportError::draw)?;
        }
        canvas::draw_axes(&mut chart, &x, &y, false)?;

        // Colour bar: a 1 × 256 raster, top = hi.
        let bx = px1 + BAR_GAP;
        let steps = 256u32;
        let mut bar = Vec::with_capacity(steps as usize * 3);
        for k in 0..steps {
            let t = 1.0 - (f64::from(k) + 0.5) / f64::from(steps);
            let Rgb(r, g, b) = self.colormap.color(t);
            bar.extend_from_slice(&[r, g, b]);
        }
        canvas.raster(
            root,
            Raster {
                origin: (bx, py0),
                size: (BAR_W as u32, h),
                img_w: 1,
                img_h: steps,
                rgb: bar,
            },
        )?;
        let axis = theme::AXIS.to_plotters().stroke_width(1);
        let bottom = py1 - 1;
        root.draw(&PathElement::new(
            vec![
                (bx, py0),
                (bx + BAR_W, py0),
                (bx + BAR_W, bottom),
                (bx, bottom),
                (bx, py0),
            ],
            axis,
        ))
        .map_err(ReportError::draw)?;
        let label_pos = tick_style.pos(Pos::new(HPos::Left, VPos::Center));
        for (v, label) in bar_ticks.major.iter().zip(&bar_ticks.labels) {
            let ty =
                bottom - ((v - range.0) / (range.1 - range.0) * f64::from(h - 1)).round() as i32;
            root.draw(&PathElement::new(
                vec![(bx + BAR_W, ty), (bx + BAR_W + 5, ty)],
                axis,
            ))
            .map_err(ReportError::draw)?;
            root.draw(&Text::new(
                label.clone(),
                (bx + BAR_W + 8, ty),
                label_pos.clone(),
            ))
            .map_err(ReportError::draw)?;
        }
        if !self.colorbar_label.is_empty() {
            // Reads bottom to top like the y-axis description; with a
            // top anchor the rotated text extends to the right of `lx`.
            let style = label_style
                .transform(FontTransform::Rotate270)
                .pos(Pos::new(HPos::Center, VPos::Top));
            let lx = bx + BAR_W + 8 + widest + 10;
            root.draw(&Text::new(
                self.colorbar_label.clone(),
                (lx, (py0 + py1) / 2),
                style,
            ))
            .map_err(ReportError::draw)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(nx: usize, ny: usize) -> Heatmap {
        let x: Vec<f64> = (0..nx).map(|i| i as f64).collect();
        let y: Vec<f64> = (0..ny).map(|i| 10.0 * i as f64).collect();
        let values = (0..nx * ny).map(|k| k as f64).collect();
        Heatmap::new("h", "x (m)", "y (m)", x, y, values, "v (nT)")
    }

    #[test]
    fn shading_darkens_slopes_facing_away_from_the_light() {
        // A ramp rising to the north-east is lit head-on on its slope…
        let x: Vec<f64> = (0..5).map(f64::from).collect();
        let ramp = |s: f64| {
            (0..25)
                .map(|k| s * ((k % 5) as f64 + (k / 5) as f64))
                .collect()
        };
        let mut h = Heatmap::new("h", "x", "y", x.clone(), x.clone(), ramp(-1.0), "v");
        h.shaded = true;
        let towards = h.shading()[12];
        h.values = ramp(1.0);
        let away = h.shading()[12];
        assert!(towards > away, "{towards} {away}");
        h.shaded = false;
        assert!(h.shading().iter().all(|&f| f == 1.0));
    }

    #[test]
    fn edges_are_midpoints() {
        let h = grid(3, 2);
        assert_eq!(
            h.edges(&[0.0, 1.0, 3.0], "x").unwrap(),
            vec![-0.5, 0.5, 2.0, 4.0]
        );
        assert_eq!(h.edges(&[5.0], "x").unwrap(), vec![4.5, 5.5]);
        assert!(h.edges(&[0.0, 0.0], "x").is_err());
        assert!(h.edges(&[], "x").is_err());
        assert!(h.edges(&[0.0, f64::NAN], "x").is_err());
    }

    #[test]
    fn uniform_image_is_one_pixel_per_cell_top_row_first() {
        let h = grid(3, 2);
        let xe = h.edges(&h.x, "x").unwrap();
        let ye = h.edges(&h.y, "y").unwrap();
        let (w, hh, rgb) = h.cell_image(&xe, &ye, 300, 200, (0.0, 5.0));
        assert_eq!((w, hh), (3, 2));
        // Top-left pixel = cell (ix 0, iy 1) = value 3 → t = 0.6.
        let c = Colormap::Viridis.color(0.6);
        assert_eq!(&rgb[0..3], &[c.0, c.1, c.2]);
        // Bottom-right pixel = cell (ix 2, iy 0) = value 2 → t = 0.4.
        let c = Colormap::Viridis.color(0.4);
        assert_eq!(&rgb[15..18], &[c.0, c.1, c.2]);
    }

    #[test]
    fn non_uniform_image_samples_cells_by_edges() {
        let mut h = grid(3, 1);
        h.x = vec![0.0, 1.0, 3.0]; // edges -0.5, 0.5, 2, 4 (span 4.5)
        let xe = h.edges(&h.x, "x").unwrap();
        let ye = h.edges(&h.y, "y").unwrap();
        let (w, _, rgb) = h.cell_image(&xe, &ye, 9, 1, (0.0, 2.0));
        assert_eq!(w, 9);
        // Pixel centres at -0.25, 0.25 | 0.75 .. 1.75 | 2.25 .. 3.75 → 2, 3, 4 pixels.
        let idx: Vec<u8> = rgb
            .chunks(3)
            .map(|p| {
                (0..3u8)
                    .find(|&v| {
                        let c = Colormap::Viridis.color(f64::from(v) / 2.0);
                        p == [c.0, c.1, c.2]
                    })
                    .unwrap_or(99)
            })
            .collect();
        assert_eq!(idx, vec![0, 0, 1, 1, 1, 2, 2, 2, 2]);
    }

    #[test]
    fn diverging_range_is_symmetric_and_nan_is_grey() {
        let mut h = grid(2, 1);
        h.values = vec![-1.0, 3.0];
        h.colormap = Colormap::Diverging;
        assert_eq!(h.value_range().unwrap(), (-3.0, 3.0));
        assert_eq!(h.color_of(f64::NAN, (0.0, 1.0)), theme::MISSING);
        h.values = vec![f64::NAN, f64::NAN];
        assert!(matches!(h.value_range(), Err(ReportError::NoData { .. })));
    }
}
