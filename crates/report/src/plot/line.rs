//! Line, step and scatter plots ([`LinePlot`]) of one or more [`Series`].
//!
//! Drawing rules (all documented behaviour, none of them an error):
//!
//! * NaN and ±∞ in `x` or `y` are gaps: the line is broken there; a sample
//!   with finite neighbours on neither side is drawn as a dot.
//! * On a log axis (`log_x`, `log_y`) values ≤ 0 are gaps too (they have no
//!   logarithm), e.g. the DC bin of a spectrum.
//! * The automatic x view is the data extent (tight for lines and steps, 3 %
//!   padding when a series has point markers); the automatic y view is the
//!   extent of the samples inside the x view plus 5 % padding. Given ranges
//!   are used as is and lines are clipped to them (Liang–Barsky).
//! * Series longer than 4 vertices per pixel column are decimated to the
//!   first/min/max/last vertex of each column (see `decimate.rs`), so peaks
//!   survive and a 10⁶-sample series gives a small SVG.
//! * Colours come from [`PALETTE`](crate::PALETTE) in series order unless a
//!   series sets its own; the legend (above the plot, never over the data)
//!   lists every series with a non-empty name.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::axis::{Extent, Scale, view_range};
use super::canvas::{
    self, AxisSpec, Canvas, Figure, LegendEntry, Margins, Marker, X_PX_PER_LABEL, Y_PX_PER_LABEL,
};
use super::clip::{Rect, clip_polyline};
use super::decimate::{decimate_line, decimate_points};
use crate::error::{ReportError, Result};
use crate::style::{Rgb, palette_color, theme};

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SeriesStyle {
    /// Straight segments between consecutive samples.
    #[default]
    Line,
    /// A filled circle at each sample, no line.
    Points,
    /// Post-step: `y[i]` holds from `x[i]` to `x[i+1]` (piecewise-constant
    /// data such as flags, line numbers or sample-and-hold values).
    Step,
}

/// One data series: samples `(x[i], y[i])` in data units.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Series {
    /// Legend text; empty → not listed in the legend.
    pub name: String,
    /// Abscissae.
    pub x: Vec<f64>,
    /// Ordinates; must have the same length as `x`.
    pub y: Vec<f64>,
    /// Line, points or steps.
    pub style: SeriesStyle,
    /// Colour; `None` → the next palette colour.
    pub color: Option<Rgb>,
}

impl Series {
    /// A [`SeriesStyle::Line`] series.
    pub fn line(name: impl Into<String>, x: Vec<f64>, y: Vec<f64>) -> Self {
        Series {
            name: name.into(),
            x,
            y,
            style: SeriesStyle::Line,
            color: None,
        }
    }

    /// A [`SeriesStyle::Points`] series.
    pub fn points(name: impl Into<String>, x: Vec<f64>, y: Vec<f64>) -> Self {
        Series {
            style: SeriesStyle::Points,
            ..Series::line(name, x, y)
        }
    }

    /// A [`SeriesStyle::Step`] series.
    pub fn step(name: impl Into<String>, x: Vec<f64>, y: Vec<f64>) -> Self {
        Series {
            style: SeriesStyle::Step,
            ..Series::line(name, x, y)
        }
    }

    /// The same series with an explicit colour.
    pub fn with_color(mut self, color: Rgb) -> Self {
        self.color = Some(color);
        self
    }

    /// Runs of consecutive drawable samples in axis units; for steps the
    /// runs already contain the horizontal/vertical step vertices.
    fn pieces(&self, sx: Scale, sy: Scale) -> Vec<Vec<(f64, f64)>> {
        let mut pieces = Vec::new();
        let mut current: Vec<(f64, f64)> = Vec::new();
        for (&x, &y) in self.x.iter().zip(&self.y) {
            match (sx.to_axis(x), sy.to_axis(y)) {
                (Some(ax), Some(ay)) => {
                    if self.style == SeriesStyle::Step
                        && let Some(&(_, prev_y)) = current.last()
                    {
                        current.push((ax, prev_y));
                    }
                    current.push((ax, ay));
                }
                _ => {
                    if !current.is_empty() {
                        pieces.push(std::mem::take(&mut current));
                    }
                }
            }
        }
        if !current.is_empty() {
            pieces.push(current);
        }
        pieces
    }
}

/// A 2-D plot of one or more series with automatic nice ticks and a legend.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LinePlot {
    /// Title above the plot.
    pub title: String,
    /// x-axis description, with units, e.g. `"time (s)"`.
    pub x_label: String,
    /// y-axis description, with units, e.g. `"residual (nT)"`.
    pub y_label: String,
    /// The data, drawn in order (later series on top).
    pub series: Vec<Series>,
    /// Logarithmic x axis (values ≤ 0 are not drawn).
    pub log_x: bool,
    /// Logarithmic y axis (values ≤ 0 are not drawn).
    pub log_y: bool,
    /// Fixed x view `(lo, hi)` in data units; `None` → automatic.
    pub x_range: Option<(f64, f64)>,
    /// Fixed y view `(lo, hi)` in data units; `None` → automatic.
    pub y_range: Option<(f64, f64)>,
}

impl LinePlot {
    /// An empty plot with title and axis descriptions.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        LinePlot {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            ..LinePlot::default()
        }
    }

    /// Adds a series (builder style).
    pub fn with_series(mut self, series: Series) -> Self {
        self.series.push(series);
        self
    }

    /// Log–log axes (builder style), e.g. for spectra.
    pub fn log_log(mut self) -> Self {
        self.log_x = true;
        self.log_y = true;
        self
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

    fn check_lengths(&self) -> Result<()> {
        for s in &self.series {
            if s.x.len() != s.y.len() {
                return Err(ReportError::LengthMismatch {
                    series: s.name.clone(),
                    x_len: s.x.len(),
                    y_len: s.y.len(),
                });
            }
        }
        Ok(())
    }
}

impl Figure for LinePlot {
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        _canvas: &mut Canvas,
    ) -> Result<()> {
        self.check_lengths()?;
        let (sx, sy) = (Scale::from_log(self.log_x), Scale::from_log(self.log_y));
        let pieces: Vec<Vec<Vec<(f64, f64)>>> =
            self.series.iter().map(|s| s.pieces(sx, sy)).collect();

        // View ranges in axis units.
        let mut x_ext = Extent::default();
        pieces
            .iter()
            .flatten()
            .flatten()
            .for_each(|p| x_ext.add(p.0));
        let has_points = self.series.iter().any(|s| s.style == SeriesStyle::Points);
        let x_pad = if has_points { 0.03 } else { 0.0 };
        let x_view = view_range(sx, self.x_range, x_ext.get(), x_pad, "x", &self.title)?;
        let mut y_ext = Extent::default();
        pieces
            .iter()
            .flatten()
            .flatten()
            .filter(|p| p.0 >= x_view.0 && p.0 <= x_view.1)
            .for_each(|p| y_ext.add(p.1));
        let y_view = view_range(sy, self.y_range, y_ext.get(), 0.05, "y", &self.title)?;

        let colors: Vec<Rgb> = self
            .series
            .iter()
            .enumerate()
            .map(|(i, s)| s.color.unwrap_or_else(|| palette_color(i)))
            .collect();
        let legend: Vec<LegendEntry> = self
            .series
            .iter()
            .zip(&colors)
            .filter(|(s, _)| !s.name.is_empty())
            .map(|(s, &color)| LegendEntry {
                name: s.name.clone(),
                color,
                marker: match s.style {
                    SeriesStyle::Points => Marker::Dot,
                    SeriesStyle::Line | SeriesStyle::Step => Marker::Line,
                },
            })
            .collect();
        let area = canvas::draw_header(root, &self.title, &legend)?;
        let (aw, ah) = area.dim_in_pixel();
        let x = AxisSpec::new(&self.x_label, sx, x_view, aw as i32 - 120, X_PX_PER_LABEL);
        let y = AxisSpec::new(&self.y_label, sy, y_view, ah as i32 - 80, Y_PX_PER_LABEL);
        let mut chart = canvas::build_chart(&area, &x, &y, Margins::default())?;
        canvas::draw_axes(&mut chart, &x, &y, true)?;

        let (px0, py0, px1, py1) = canvas::plot_rect(&chart);
        let (cols, rows) = ((px1 - px0).max(1) as usize, (py1 - py0).max(1) as usize);
        let view = Rect {
            x0: x_view.0,
            x1: x_view.1,
            y0: y_view.0,
            y1: y_view.1,
        };
        for ((series, pieces), color) in self.series.iter().zip(&pieces).zip(&colors) {
            let color = color.to_plotters();
            match series.style {
                SeriesStyle::Points => {
                    let inside: Vec<(f64, f64)> = pieces
                        .iter()
                        .flatten()
                        .copied()
                        .filter(|&p| view.contains(p))
                        .collect();
                    // Markers are ~2 px apart at most in the de-duplication grid.
                    let kept = decimate_points(&inside, x_view, y_view, cols / 2, rows / 2);
                    chart
                        .draw_series(
                            kept.into_iter()
                                .map(|p| Circle::new(p, theme::POINT_RADIUS, color.filled())),
                        )
                        .map_err(ReportError::draw)?;
                }
                SeriesStyle::Line | SeriesStyle::Step => {
                    for piece in pieces.iter().flat_map(|p| clip_polyline(p, &view)) {
                        if piece.len() == 1 {
                            chart
                                .draw_series(std::iter::once(Circle::new(
                                    piece[0],
                                    theme::LINE_WIDTH,
                                    color.filled(),
                                )))
                                .map_err(ReportError::draw)?;
                            continue;
                        }
                        let drawn = decimate_line(&piece, x_view, cols);
                        chart
                            .draw_series(LineSeries::new(
                                drawn,
                                color.stroke_width(theme::LINE_WIDTH),
                            ))
                            .map_err(ReportError::draw)?;
                    }
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pieces_break_at_nan_and_non_positive_on_log() {
        let s = Series::line(
            "a",
            vec![1.0, 2.0, 3.0, 4.0, 5.0],
            vec![1.0, f64::NAN, 3.0, 4.0, -1.0],
        );
        let p = s.pieces(Scale::Linear, Scale::Linear);
        assert_eq!(
            p,
            vec![vec![(1.0, 1.0)], vec![(3.0, 3.0), (4.0, 4.0), (5.0, -1.0)]]
        );
        let p = s.pieces(Scale::Linear, Scale::Log);
        assert_eq!(p.len(), 2);
        assert_eq!(p[1], vec![(3.0, 3f64.log10()), (4.0, 4f64.log10())]);
    }

    #[test]
    fn step_pieces_hold_the_previous_value() {
        let s = Series::step("s", vec![0.0, 1.0, 2.0], vec![5.0, 6.0, 7.0]);
        let p = s.pieces(Scale::Linear, Scale::Linear);
        assert_eq!(
            p,
            vec![vec![
                (0.0, 5.0),
                (1.0, 5.0),
                (1.0, 6.0),
                (2.0, 6.0),
                (2.0, 7.0)
            ]]
        );
    }
}
