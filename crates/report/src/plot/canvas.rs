//! The drawing harness shared by every plot: output backends (SVG string,
//! PNG file), raster layers, the title/legend header, axes with our own ticks,
//! and the plot frame.
//!
//! A plot implements [`Figure::draw`] once against a generic plotters
//! `DrawingBackend`; [`render_svg`] and [`render_png`] run it on the SVG and
//! bitmap backends. Rasters (heatmap cells, colour bars) go through
//! [`Canvas::raster`]: on the bitmap backend they are painted pixel by pixel
//! (nearest-neighbour scaling); in SVG they become one `<image>` element with
//! an inline PNG `data:` URI, drawn under the axes, so a 500 × 500 grid costs
//! a few kilobytes instead of 250 000 `<rect>` elements.

use std::fmt::Write as _;
use std::path::Path;

use plotters::coord::Shift;
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::axis::Scale;
use super::bitmap::PngBackend;
use super::ticks::Ticks;
use crate::encode;
use crate::error::{ReportError, Result};
use crate::style::{FONT_FAMILY, Rgb, ensure_font, theme};
use crate::{MAX_SIZE_PX, MIN_SIZE_PX};

/// One axis of a chart as a plotters coordinate: a linear map of axis units
/// with our own major ticks (labelled, bold grid) and minor ticks (light
/// grid) instead of plotters' key-point algorithm.
#[derive(Clone)]
pub(crate) struct AxisCoord {
    inner: RangedCoordf64,
    major: Vec<f64>,
    minor: Vec<f64>,
}

impl Ranged for AxisCoord {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.inner.map(value, limit)
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            self.minor.clone()
        } else {
            self.major.clone()
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.inner.range()
    }
}

/// The coordinate system of every chart: axis units on both axes.
pub(crate) type Coords = Cartesian2d<AxisCoord, AxisCoord>;

/// An RGB image to be shown scaled over a pixel rectangle of the figure.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Raster {
    /// Top-left corner of the destination rectangle, figure pixels.
    pub origin: (i32, i32),
    /// Size of the destination rectangle, figure pixels.
    pub size: (u32, u32),
    /// Image width in pixels (columns of `rgb`).
    pub img_w: u32,
    /// Image height in pixels (rows of `rgb`, top to bottom).
    pub img_h: u32,
    /// `img_w · img_h · 3` bytes of 8-bit RGB.
    pub rgb: Vec<u8>,
}

/// Where rasters go: painted now (bitmap) or collected for SVG `<image>`s.
pub(crate) enum Canvas {
    /// Paint into the backend immediately.
    Paint,
    /// Collect; [`render_svg`] inlines them under everything else.
    Collect(Vec<Raster>),
}

impl Canvas {
    /// Shows `raster` on `root`.
    pub fn raster<DB: DrawingBackend>(
        &mut self,
        root: &DrawingArea<DB, Shift>,
        raster: Raster,
    ) -> Result<()> {
        match self {
            Canvas::Collect(list) => list.push(raster),
            Canvas::Paint => {
                let (w, h) = raster.size;
                for py in 0..h {
                    let sy = (u64::from(py) * u64::from(raster.img_h) / u64::from(h)) as usize;
                    for px in 0..w {
                        let sx = (u64::from(px) * u64::from(raster.img_w) / u64::from(w)) as usize;
                        let i = 3 * (sy * raster.img_w as usize + sx);
                        let c = RGBColor(raster.rgb[i], raster.rgb[i + 1], raster.rgb[i + 2]);
                        root.draw_pixel(
                            (raster.origin.0 + px as i32, raster.origin.1 + py as i32),
                            &c,
                        )
                        .map_err(ReportError::draw)?;
                    }
                }
            }
        }
        Ok(())
    }
}

/// Something that can be drawn on any plotters backend.
pub(crate) trait Figure {
    /// Draws the whole figure on `root` (already filled white).
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        canvas: &mut Canvas,
    ) -> Result<()>;
}

fn check_size(width: u32, height: u32) -> Result<()> {
    let ok = |v: u32| (MIN_SIZE_PX..=MAX_SIZE_PX).contains(&v);
    if ok(width) && ok(height) {
        Ok(())
    } else {
        Err(ReportError::InvalidSize { width, height })
    }
}

/// Renders `fig` as a standalone SVG document of `width × height` pixels.
pub(crate) fn render_svg(fig: &impl Figure, width: u32, height: u32) -> Result<String> {
    check_size(width, height)?;
    ensure_font()?;
    let mut svg = String::new();
    let mut canvas = Canvas::Collect(Vec::new());
    {
        let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(ReportError::draw)?;
        fig.draw(&root, &mut canvas)?;
        root.present().map_err(ReportError::draw)?;
    }
    if let Canvas::Collect(rasters) = canvas
        && !rasters.is_empty()
    {
        svg = insert_rasters(svg, &rasters)?;
    }
    Ok(svg)
}

/// Inserts `<image>` elements right after the white background rectangle.
fn insert_rasters(svg: String, rasters: &[Raster]) -> Result<String> {
    let mut images = String::new();
    for r in rasters {
        let png = encode::png_rgb(r.img_w, r.img_h, &r.rgb)?;
        // `write!` to a String cannot fail.
        let _ = writeln!(
            images,
            "<image x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" preserveAspectRatio=\"none\" \
             image-rendering=\"optimizeSpeed\" style=\"image-rendering:pixelated\" \
             href=\"data:image/png;base64,{}\"/>",
            r.origin.0,
            r.origin.1,
            r.size.0,
            r.size.1,
            encode::base64(&png)
        );
    }
    let at = svg
        .find("<rect")
        .and_then(|start| svg[start..].find("/>\n").map(|end| start + end + 3))
        .ok_or_else(|| ReportError::Draw("SVG has no background rectangle".into()))?;
    let mut out = String::with_capacity(svg.len() + images.len());
    out.push_str(&svg[..at]);
    out.push_str(&images);
    out.push_str(&svg[at..]);
    Ok(out)
}

/// Renders `fig` into a `width × height` PNG file at `path` (parent folders
/// are created).
pub(crate) fn render_png(fig: &impl Figure, path: &Path, width: u32, height: u32) -> Result<()> {
    check_size(width, height)?;
    ensure_font()?;
    let mut rgb = vec![0u8; width as usize * height as usize * 3];
    {
        let root = PngBackend::with_buffer(&mut rgb, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(ReportError::draw)?;
        fig.draw(&root, &mut Canvas::Paint)?;
        root.present().map_err(ReportError::draw)?;
    }
    let png = encode::png_rgb(width, height, &rgb)?;
    crate::write_file(path, &png)
}

/// Text style in the embedded font.
pub(crate) fn text_style(size: f64, color: Rgb) -> TextStyle<'static> {
    (FONT_FAMILY, size).into_font().color(&color.to_plotters())
}

/// Width and height of `text` in pixels.
pub(crate) fn text_size<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    style: &TextStyle,
) -> Result<(u32, u32)> {
    if text.is_empty() {
        return Ok((0, 0));
    }
    area.estimate_text_size(text, style)
        .map_err(ReportError::draw)
}

/// How a legend entry shows its series.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Marker {
    /// A short line.
    Line,
    /// A filled circle.
    Dot,
}

/// One legend entry.
#[derive(Debug, Clone)]
pub(crate) struct LegendEntry {
    pub name: String,
    pub color: Rgb,
    pub marker: Marker,
}

const OUTER_MARGIN: i32 = 12;
const SWATCH_W: i32 = 26;

/// Draws the title and the legend row(s) at the top of `root` and returns the
/// area below them.
pub(crate) fn draw_header<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    legend: &[LegendEntry],
) -> Result<DrawingArea<DB, Shift>> {
    let (width, _) = root.dim_in_pixel();
    let width = width as i32;
    let mut y = OUTER_MARGIN;
    if !title.is_empty() {
        let style =
            text_style(theme::TITLE_SIZE, theme::TEXT).pos(Pos::new(HPos::Center, VPos::Top));
        root.draw(&Text::new(title.to_string(), (width / 2, y), style))
            .map_err(ReportError::draw)?;
        y += (theme::TITLE_SIZE * 1.35) as i32;
    }
    if !legend.is_empty() {
        let style = text_style(theme::LABEL_SIZE, theme::TEXT);
        let row_h = (theme::LABEL_SIZE * 1.35) as i32;
        // Lay entries out in rows, each row centred.
        let mut rows: Vec<Vec<(&LegendEntry, i32)>> = vec![Vec::new()];
        let mut row_w = 0;
        let max_w = width - 2 * OUTER_MARGIN;
        for e in legend {
            let w = SWATCH_W + 6 + text_size(root, &e.name, &style)?.0 as i32;
            let gap = if row_w > 0 { 22 } else { 0 };
            if row_w > 0 && row_w + gap + w > max_w {
                rows.push(Vec::new());
                row_w = 0;
            }
            let gap = if row_w > 0 { 22 } else { 0 };
            row_w += gap + w;
            if let Some(row) = rows.last_mut() {
                row.push((e, w));
            }
        }
        for row in rows {
            let total: i32 = row.iter().map(|(_, w)| *w).sum::<i32>() + 22 * (row.len() as i32 - 1);
            let mut x = (width - total) / 2;
            let cy = y + row_h / 2;
            for (e, w) in row {
                let color = e.color.to_plotters();
                match e.marker {
                    Marker::Line => root
                        .draw(&PathElement::new(
                            vec![(x, cy), (x + SWATCH_W, cy)],
                            color.stroke_width(3),
                        ))
                        .map_err(ReportError::draw)?,
                    Marker::Dot => root
                        .draw(&Circle::new(
                            (x + SWATCH_W / 2, cy),
                            theme::POINT_RADIUS + 1,
                            color.filled(),
                        ))
                        .map_err(ReportError::draw)?,
                }
                let label = style.pos(Pos::new(HPos::Left, VPos::Center));
                root.draw(&Text::new(e.name.clone(), (x + SWATCH_W + 6, cy), label))
                    .map_err(ReportError::draw)?;
                x += w + 22;
            }
            y += row_h;
        }
    }
    let (_, rest) = root.split_vertically(y + 4);
    Ok(rest)
}

/// One axis of a chart, in axis units.
#[derive(Debug, Clone)]
pub(crate) struct AxisSpec {
    /// Axis description (with units).
    pub label: String,
    /// View range in axis units, `lo < hi`.
    pub view: (f64, f64),
    /// Ticks for the view.
    pub ticks: Ticks,
}

impl AxisSpec {
    /// Builds the axis with ticks spaced for an axis `length_px` long that
    /// should have a label every `px_per_label` pixels or more.
    pub fn new(
        label: &str,
        scale: Scale,
        view: (f64, f64),
        length_px: i32,
        px_per_label: i32,
    ) -> Self {
        let max_intervals = (length_px / px_per_label).clamp(2, 12) as usize;
        AxisSpec {
            label: label.to_string(),
            view,
            ticks: scale.ticks(view.0, view.1, max_intervals),
        }
    }
}

/// Pixels per x label and per y label used to choose tick counts.
pub(crate) const X_PX_PER_LABEL: i32 = 95;
/// See [`X_PX_PER_LABEL`].
pub(crate) const Y_PX_PER_LABEL: i32 = 45;
const TICK_MARK: i32 = 5;

/// Sizes of the label areas left of and below a chart in `area` whose y tick
/// labels are `y_labels`, plus the right margin that keeps the last x label
/// inside the figure.
pub(crate) fn label_areas<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    y_labels: &[String],
    x_labels: &[String],
    y_desc: &str,
) -> Result<(u32, u32, u32)> {
    let tick = text_style(theme::TICK_SIZE, theme::TICK_TEXT);
    let desc = text_style(theme::LABEL_SIZE, theme::TEXT);
    let mut widest = 0;
    for l in y_labels {
        widest = widest.max(text_size(area, l, &tick)?.0);
    }
    let desc_h = if y_desc.is_empty() {
        0
    } else {
        text_size(area, y_desc, &desc)?.1 + 10
    };
    let left = widest + 2 * TICK_MARK as u32 + 6 + desc_h;
    let tick_h = text_size(area, "0", &tick)?.1;
    let bottom = 2 * TICK_MARK as u32 + tick_h + 10 + (theme::LABEL_SIZE * 1.3) as u32;
    let last_x = x_labels.last().map(String::as_str).unwrap_or("");
    let right = (text_size(area, last_x, &tick)?.0 / 2 + 6).max(18);
    Ok((left, bottom, right))
}

/// Extra margins around a chart, pixels (colour bar, equal aspect ratio).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct Margins {
    pub top: u32,
    pub right: u32,
    pub bottom: u32,
    pub left: u32,
}

/// Builds a chart on `area` with the given axes, label area sizes from
/// [`label_areas`] and `extra` margins. Building draws nothing.
pub(crate) fn build_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    x: &AxisSpec,
    y: &AxisSpec,
    extra: Margins,
) -> Result<ChartContext<'a, DB, Coords>> {
    let (left, bottom, right) = label_areas(area, &y.ticks.labels, &x.ticks.labels, &y.label)?;
    let coord = |a: &AxisSpec| AxisCoord {
        inner: (a.view.0..a.view.1).into(),
        major: a.ticks.major.clone(),
        minor: a.ticks.minor.clone(),
    };
    let (xr, yr) = (coord(x), coord(y));
    ChartBuilder::on(area)
        .margin_top(10 + extra.top)
        .margin_left(OUTER_MARGIN as u32 + extra.left)
        .margin_bottom(6 + extra.bottom)
        .margin_right(right + extra.right)
        .x_label_area_size(bottom)
        .y_label_area_size(left)
        .build_cartesian_2d(xr, yr)
        .map_err(ReportError::draw)
}

/// Draws grid (when `grid`), axes, ticks, tick labels, axis descriptions and
/// a frame around the plotting area.
pub(crate) fn draw_axes<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Coords>,
    x: &AxisSpec,
    y: &AxisSpec,
    grid: bool,
) -> Result<()> {
    let fx = |v: &f64| x.ticks.label_for(*v);
    let fy = |v: &f64| y.ticks.label_for(*v);
    let mut mesh = chart.configure_mesh();
    mesh.bold_line_style(theme::GRID_MAJOR.to_plotters().stroke_width(1))
        .light_line_style(theme::GRID_MINOR.to_plotters().stroke_width(1))
        .axis_style(theme::AXIS.to_plotters().stroke_width(1))
        .set_all_tick_mark_size(TICK_MARK)
        .label_style(text_style(theme::TICK_SIZE, theme::TICK_TEXT))
        .axis_desc_style(text_style(theme::LABEL_SIZE, theme::TEXT))
        .x_desc(x.label.as_str())
        .y_desc(y.label.as_str())
        .x_label_formatter(&fx)
        .y_label_formatter(&fy);
    if !grid {
        mesh.disable_mesh();
    }
    mesh.draw().map_err(ReportError::draw)?;
    draw_frame(chart)
}

/// A 1-pixel box around the plotting area.
fn draw_frame<DB: DrawingBackend>(chart: &ChartContext<'_, DB, Coords>) -> Result<()> {
    let (xr, yr) = chart.plotting_area().get_pixel_range();
    let area = chart.plotting_area().strip_coord_spec();
    let w = xr.end - xr.start - 1;
    let h = yr.end - yr.start - 1;
    area.draw(&PathElement::new(
        vec![(0, 0), (w, 0), (w, h), (0, h), (0, 0)],
        theme::AXIS.to_plotters().stroke_width(1),
    ))
    .map_err(ReportError::draw)
}

/// Pixel rectangle `(x0, y0, x1, y1)` of the chart's plotting area in figure
/// coordinates (x1, y1 exclusive).
pub(crate) fn plot_rect<DB: DrawingBackend>(
    chart: &ChartContext<'_, DB, Coords>,
) -> (i32, i32, i32, i32) {
    let (xr, yr) = chart.plotting_area().get_pixel_range();
    (xr.start, yr.start, xr.end, yr.end)
}
