//! Colours, the series palette, the theme of the plots and the embedded font.
//!
//! Text is rendered with DejaVu Sans (Bitstream Vera licence, see
//! `assets/LICENSE-DejaVu.txt`), compiled into the binary and registered with
//! plotters' `ab_glyph` font table, so PNG rendering needs no system font
//! library (no fontconfig, no freetype). SVG output names the family
//! [`FONT_FAMILY`], a CSS font list that starts with DejaVu Sans: a browser
//! that has it renders the text with exactly the metrics used for the layout,
//! others fall back to a similar sans-serif face.

use std::sync::OnceLock;

use plotters::style::{FontStyle, RGBColor};

use crate::error::{ReportError, Result};

/// An sRGB colour with 8 bits per channel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Rgb(pub u8, pub u8, pub u8);

impl Rgb {
    /// The colour as a plotters colour.
    pub(crate) fn to_plotters(self) -> RGBColor {
        RGBColor(self.0, self.1, self.2)
    }

    /// `#rrggbb` hex notation.
    pub fn to_hex(self) -> String {
        format!("#{:02x}{:02x}{:02x}", self.0, self.1, self.2)
    }
}

/// Default series colours, in order of use: the Okabe–Ito palette
/// (Okabe & Ito 2008, "Color Universal Design"), which stays distinguishable
/// for the common forms of colour blindness; its yellow is left out because it
/// is unreadable on white. Series past the seventh reuse the colours in order.
pub const PALETTE: [Rgb; 7] = [
    Rgb(0x00, 0x72, 0xb2), // blue
    Rgb(0xd5, 0x5e, 0x00), // vermillion
    Rgb(0x00, 0x9e, 0x73), // bluish green
    Rgb(0xcc, 0x79, 0xa7), // reddish purple
    Rgb(0xe6, 0x9f, 0x00), // orange
    Rgb(0x56, 0xb4, 0xe9), // sky blue
    Rgb(0x00, 0x00, 0x00), // black
];

/// The colour of the `index`-th series when it has no colour of its own.
pub fn palette_color(index: usize) -> Rgb {
    PALETTE[index % PALETTE.len()]
}

/// Font family written into SVG `font-family` attributes and registered with
/// plotters (the registration key is this whole string).
pub const FONT_FAMILY: &str = "DejaVu Sans, Verdana, sans-serif";

/// DejaVu Sans Book, embedded.
pub(crate) static FONT_BYTES: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// Registers the embedded font with plotters once per process.
///
/// Both the normal and the bold style map to the same face, so PNG and SVG
/// output use one weight throughout.
pub(crate) fn ensure_font() -> Result<()> {
    static REGISTERED: OnceLock<std::result::Result<(), String>> = OnceLock::new();
    REGISTERED
        .get_or_init(|| {
            for style in [FontStyle::Normal, FontStyle::Bold] {
                plotters::style::register_font(FONT_FAMILY, style, FONT_BYTES)
                    .map_err(|_| "DejaVuSans.ttf is not a valid font".to_string())?;
            }
            Ok(())
        })
        .clone()
        .map_err(ReportError::Font)
}

/// The colours and sizes shared by every plot.
pub(crate) mod theme {
    use super::Rgb;

    /// Text (titles, labels, tick labels).
    pub const TEXT: Rgb = Rgb(0x22, 0x22, 0x22);
    /// Tick labels, slightly lighter than titles.
    pub const TICK_TEXT: Rgb = Rgb(0x44, 0x44, 0x44);
    /// Axis lines and tick marks.
    pub const AXIS: Rgb = Rgb(0x55, 0x55, 0x55);
    /// Major grid lines.
    pub const GRID_MAJOR: Rgb = Rgb(0xdc, 0xdc, 0xdc);
    /// Minor grid lines (log axes).
    pub const GRID_MINOR: Rgb = Rgb(0xef, 0xef, 0xef);
    /// Heatmap cells whose value is NaN.
    pub const MISSING: Rgb = Rgb(0xd0, 0xd0, 0xd0);
    /// Text size of the title, in plotters units (SVG font-size = size / 1.24).
    pub const TITLE_SIZE: f64 = 21.0;
    /// Text size of axis descriptions and legend entries.
    pub const LABEL_SIZE: f64 = 17.0;
    /// Text size of tick labels.
    pub const TICK_SIZE: f64 = 15.5;
    /// Stroke width of series lines, in pixels.
    pub const LINE_WIDTH: u32 = 2;
    /// Radius of point markers, in pixels.
    pub const POINT_RADIUS: u32 = 3;
}
