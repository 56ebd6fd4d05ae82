//! Plots (SVG/PNG) and the single-file HTML report of aeromag.
//!
//! Spec: `README.md` (architecture, `report/`) and `data-formats.md`
//! ("`aeromag demo` writes DIR/index.html (single file, plots inline) and the
//! PNG/SVG plots"). Readers are processors of airborne surveys who open the
//! report in a browser, so the output aims at print quality: nice tick
//! values, units on every axis, colour-blind-safe series colours, a
//! perceptual colour map, and a report that is one file with no external
//! resources.
//!
//! # Plots
//!
//! * [`LinePlot`] of [`Series`] (line, points or post-step; NaN = gap;
//!   optional log axes on which values ≤ 0 are gaps; fixed or automatic
//!   ranges; min/max decimation per pixel column so 10⁶ samples give a small
//!   SVG with every peak kept).
//! * [`Heatmap`] of a rectilinear grid with a colour bar ([`Colormap`]).
//!
//! Both render to an SVG string (`to_svg`, `to_svg_sized`) or a PNG file
//! (`to_png`). Text uses the embedded DejaVu Sans through plotters'
//! `ab_glyph` backend: no system font library is needed.
//!
//! ```
//! use aeromag_report::{LinePlot, Series};
//! let t: Vec<f64> = (0..100).map(|i| i as f64 * 0.1).collect();
//! let y: Vec<f64> = t.iter().map(|t| (2.0 * t).sin()).collect();
//! let svg = LinePlot::new("Residual", "time (s)", "residual (nT)")
//!     .with_series(Series::line("LS", t, y))
//!     .to_svg()?;
//! assert!(svg.starts_with("<svg"));
//! # Ok::<(), aeromag_report::ReportError>(())
//! ```
//!
//! # Report
//!
//! [`Report`] collects sections, paragraphs, [`Table`]s, key–value lists and
//! SVG figures and writes one deterministic, self-contained HTML file.
//!
//! ```
//! use aeromag_report::{Report, Table};
//! let mut r = Report::new("Calibration flight");
//! r.section("Figures of merit")
//!     .key_values(vec![("FOM before (nT)".into(), "2.31".into())])
//!     .table(Table::new(vec!["method".into(), "rms (nT)".into()],
//!                       vec![vec!["LS".into(), "0.071".into()]], "Residuals"));
//! let html = r.to_html();
//! assert!(html.contains("Figures of merit"));
//! ```
//!
//! A [`ReportSection`] is a section built apart (each study builds its
//! own) and appended to a report later.
//!
//! | module | contents |
//! |---|---|
//! | [`plot`] | line plots, heat maps, colour maps, ticks, PNG/SVG output |
//! | [`html`] | the report and its sections |
//! | [`style`] | colours, the series palette, the plot theme and the embedded font |
//! | [`error`] | [`ReportError`], with `is_bad_input()` |

mod encode;
pub mod error;
pub mod html;
pub mod plot;
pub mod style;

pub use error::{ReportError, Result};
pub use html::report::{Report, Table};
pub use html::section::{Block, ReportSection};
pub use plot::colormap::Colormap;
pub use plot::heatmap::Heatmap;
pub use plot::line::{LinePlot, Series, SeriesStyle};
pub use style::{PALETTE, Rgb};

/// Default SVG size in pixels (width, height): fits the report's content
/// column at 1:1 and scales down on narrow screens.
pub const DEFAULT_SIZE: (u32, u32) = (900, 500);

/// Smallest accepted image width or height, pixels.
pub const MIN_SIZE_PX: u32 = 160;

/// Largest accepted image width or height, pixels.
pub const MAX_SIZE_PX: u32 = 8192;

/// Writes `bytes` to `path` atomically (a temporary renamed when complete,
/// [`aeromag_io::atomic`]), creating missing parent folders.
pub(crate) fn write_file(path: &std::path::Path, bytes: &[u8]) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| ReportError::io(dir, e))?;
    }
    aeromag_io::atomic::write_file(path, bytes).map_err(|e| ReportError::io(path, e))
}
