//! The PNG drawing backend: plotters' bitmap backend with better text and
//! thick lines.
//!
//! Two things of plotters' bitmap rendering are not good enough for a report:
//!
//! * **Text.** plotters' `ab_glyph` renderer places each glyph at the pen
//!   position without its left side bearing, so spacing is uneven
//!   ("tim e"). [`PngBackend::draw_text`] lays glyphs out itself with
//!   ab_glyph: advance widths, kerning, side bearings and sub-pixel
//!   positions, anti-aliased by blending the glyph coverage. The baseline is
//!   placed as plotters' SVG backend asks the browser to place it
//!   (`dy = 0.76 em` for top-anchored text, `±0.5 ex` for centre/bottom, with
//!   `em = size / 1.24`), so PNG and SVG output look alike.
//! * **Thick lines.** plotters fills each thick segment as a thin polygon,
//!   which leaves gaps on steep segments of a noisy trace.
//!   [`PngBackend::draw_path`] walks every segment with Bresenham's algorithm
//!   and stamps a square brush of the stroke width, which is gap-free.
//!
//! Everything else is delegated to the bitmap backend.

use ab_glyph::{Font, FontRef, PxScale, ScaleFont, point};
use plotters::backend::BitMapBackend;
use plotters_backend::text_anchor::{HPos, VPos};
use plotters_backend::{
    BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingBackend, DrawingErrorKind,
    FontTransform,
};

use crate::style::FONT_BYTES;

/// Ratio of plotters' text size to the CSS font size (plotters' SVG backend
/// writes `font-size = size / 1.24`).
const SIZE_PER_EM: f64 = 1.24;
/// x-height of DejaVu Sans in em (1120 / 2048 font units).
const X_HEIGHT_EM: f64 = 0.547;

type Error<'a> = DrawingErrorKind<<BitMapBackend<'a> as DrawingBackend>::ErrorType>;

/// Bitmap backend with our text and thick-line rendering.
pub(crate) struct PngBackend<'a> {
    inner: BitMapBackend<'a>,
    font: Option<FontRef<'static>>,
}

impl<'a> PngBackend<'a> {
    /// Draws into an RGB buffer of `size.0 · size.1 · 3` bytes.
    pub fn with_buffer(buf: &'a mut [u8], size: (u32, u32)) -> Self {
        PngBackend {
            inner: BitMapBackend::with_buffer(buf, size),
            // The embedded font is known-good; if it ever failed to parse we
            // fall back to plotters' own text rendering.
            font: FontRef::try_from_slice(FONT_BYTES).ok(),
        }
    }

    /// Stamps a `w × w` square centred on `(x, y)`.
    fn stamp(
        &mut self,
        (x, y): BackendCoord,
        w: i32,
        color: BackendColor,
    ) -> Result<(), Error<'a>> {
        let lo = -(w - 1) / 2;
        for dy in lo..lo + w {
            for dx in lo..lo + w {
                self.inner.draw_pixel((x + dx, y + dy), color)?;
            }
        }
        Ok(())
    }
}

impl<'a> DrawingBackend for PngBackend<'a> {
    type ErrorType = <BitMapBackend<'a> as DrawingBackend>::ErrorType;

    fn get_size(&self) -> (u32, u32) {
        self.inner.get_size()
    }

    fn ensure_prepared(&mut self) -> Result<(), Error<'a>> {
        self.inner.ensure_prepared()
    }

    fn present(&mut self) -> Result<(), Error<'a>> {
        self.inner.present()
    }

    fn draw_pixel(&mut self, point: BackendCoord, color: BackendColor) -> Result<(), Error<'a>> {
        self.inner.draw_pixel(point, color)
    }

    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Result<(), Error<'a>> {
        self.inner.draw_line(from, to, style)
    }

    fn draw_rect<S: BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Result<(), Error<'a>> {
        self.inner.draw_rect(upper_left, bottom_right, style, fill)
    }

    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Result<(), Error<'a>> {
        let width = style.stroke_width() as i32;
        let color = style.color();
        if width <= 1 || color.alpha < 1.0 {
            // Thin lines are exact in plotters; translucent thick lines would
            // be over-blended by overlapping stamps.
            return self.inner.draw_path(path, style);
        }
        let mut prev: Option<BackendCoord> = None;
        for p in path {
            match prev {
                None => self.stamp(p, width, color)?,
                Some(a) => {
                    // Bresenham from a (exclusive) to p (inclusive).
                    let (dx, dy) = ((p.0 - a.0).abs(), -(p.1 - a.1).abs());
                    let (sx, sy) = ((p.0 - a.0).signum(), (p.1 - a.1).signum());
                    let (mut x, mut y, mut err) = (a.0, a.1, dx + dy);
                    while (x, y) != p {
                        let e2 = 2 * err;
                        if e2 >= dy {
                            err += dy;
                            x += sx;
                        }
                        if e2 <= dx {
                            err += dx;
                            y += sy;
                        }
                        self.stamp((x, y), width, color)?;
                    }
                }
            }
            prev = Some(p);
        }
        Ok(())
    }

    fn draw_circle<S: BackendStyle>(
        &mut self,
        center: BackendCoord,
        radius: u32,
        style: &S,
        fill: bool,
    ) -> Result<(), Error<'a>> {
        self.inner.draw_circle(center, radius, style, fill)
    }

    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Result<(), Error<'a>> {
        self.inner.fill_polygon(vert, style)
    }

    fn draw_text<T: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &T,
        pos: BackendCoord,
    ) -> Result<(), Error<'a>> {
        let Some(font) = self.font.clone() else {
            return self.inner.draw_text(text, style, pos);
        };
        let color = style.color();
        if color.alpha == 0.0 || text.is_empty() {
            return Ok(());
        }
        let em = (style.size() / SIZE_PER_EM) as f32;
        let units = font.units_per_em().unwrap_or(2048.0);
        let scale = PxScale::from(em * font.height_unscaled() / units);
        let scaled = font.as_scaled(scale);

        // Pen positions (advance + kerning), then the anchor offset.
        let mut pens = Vec::with_capacity(text.len());
        let mut caret = 0.0f32;
        let mut prev = None;
        for c in text.chars() {
            let id = scaled.glyph_id(c);
            if let Some(p) = prev {
                caret += scaled.kern(p, id);
            }
            pens.push((id, caret));
            caret += scaled.h_advance(id);
            prev = Some(id);
        }
        let dx = match style.anchor().h_pos {
            HPos::Left => 0.0,
            HPos::Center => -caret / 2.0,
            HPos::Right => -caret,
        };
        let dy = match style.anchor().v_pos {
            VPos::Top => 0.76 * em,
            VPos::Center => 0.5 * X_HEIGHT_EM as f32 * em,
            VPos::Bottom => -0.5 * X_HEIGHT_EM as f32 * em,
        };
        let transform = style.transform();
        let rotate = |x: i32, y: i32| match transform {
            FontTransform::Rotate90 => (-y, x),
            FontTransform::Rotate180 => (-x, -y),
            FontTransform::Rotate270 => (y, -x),
            _ => (x, y),
        };
        for (id, pen) in pens {
            let glyph = id.with_scale_and_position(scale, point(dx + pen, dy));
            let Some(outline) = font.outline_glyph(glyph) else {
                continue; // e.g. a space
            };
            let b = outline.px_bounds();
            let (bx, by) = (b.min.x as i32, b.min.y as i32);
            let mut result = Ok(());
            outline.draw(|gx, gy, coverage| {
                if result.is_err() || coverage < 1.0 / 255.0 {
                    return;
                }
                let (ox, oy) = rotate(bx + gx as i32, by + gy as i32);
                let c = BackendColor {
                    alpha: color.alpha * f64::from(coverage.min(1.0)),
                    rgb: color.rgb,
                };
                result = self.inner.draw_pixel((pos.0 + ox, pos.1 + oy), c);
            });
            result?;
        }
        Ok(())
    }

    fn blit_bitmap(
        &mut self,
        pos: BackendCoord,
        size: (u32, u32),
        src: &[u8],
    ) -> Result<(), Error<'a>> {
        self.inner.blit_bitmap(pos, size, src)
    }
}
