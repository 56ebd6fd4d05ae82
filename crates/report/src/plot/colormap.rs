//! Colour maps for heatmaps.
//!
//! * [`Colormap::Viridis`] — perceptually uniform, monotonic in lightness,
//!   readable in grey-scale and by colour-blind readers (Smith & van der Walt
//!   2015, public domain). The default.
//! * [`Colormap::Diverging`] — ColorBrewer RdBu reversed (blue = low,
//!   white = middle, red = high), for signed quantities such as residuals or
//!   anomalies; a heatmap using it centres its default value range on zero.
//!
//! Each map is a table of anchor colours at `t = k/(N−1)` with linear
//! interpolation in 8-bit sRGB between neighbours. The tables were generated
//! from matplotlib by `tools/reference/colormap_tables.py`, which also prints
//! the largest deviation of this interpolation from matplotlib's 256-entry
//! tables (2.83/255 for viridis, 1.96/255 for RdBu_r).

use crate::style::Rgb;

/// A colour map from a normalised value `t ∈ [0, 1]` to a colour.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Colormap {
    /// viridis (sequential, perceptually uniform).
    #[default]
    Viridis,
    /// Reversed ColorBrewer RdBu (diverging, white at `t = 0.5`).
    Diverging,
}

/// viridis anchors at t = k/32 (8-bit sRGB).
const VIRIDIS: [[u8; 3]; 33] = [
    [68, 1, 84],
    [71, 13, 96],
    [72, 24, 106],
    [72, 35, 116],
    [71, 45, 123],
    [69, 55, 129],
    [66, 64, 134],
    [62, 73, 137],
    [59, 82, 139],
    [55, 91, 141],
    [51, 99, 141],
    [47, 107, 142],
    [44, 114, 142],
    [41, 122, 142],
    [38, 130, 142],
    [35, 137, 142],
    [33, 145, 140],
    [31, 152, 139],
    [31, 160, 136],
    [34, 167, 133],
    [40, 174, 128],
    [50, 182, 122],
    [63, 188, 115],
    [78, 195, 107],
    [94, 201, 98],
    [112, 207, 87],
    [132, 212, 75],
    [152, 216, 62],
    [173, 220, 48],
    [194, 223, 35],
    [216, 226, 25],
    [236, 229, 27],
    [253, 231, 37],
];

/// Reversed ColorBrewer RdBu anchors at t = k/10 (8-bit sRGB).
const RDBU_R: [[u8; 3]; 11] = [
    [5, 48, 97],
    [32, 101, 171],
    [67, 147, 195],
    [144, 196, 221],
    [209, 229, 240],
    [247, 246, 246],
    [253, 219, 199],
    [243, 164, 129],
    [214, 96, 77],
    [177, 24, 43],
    [103, 0, 31],
];

impl Colormap {
    fn table(self) -> &'static [[u8; 3]] {
        match self {
            Colormap::Viridis => &VIRIDIS,
            Colormap::Diverging => &RDBU_R,
        }
    }

    /// The colour at `t`; `t` is clamped to `[0, 1]`, NaN maps to `t = 0`.
    pub fn color(self, t: f64) -> Rgb {
        let table = self.table();
        let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
        let pos = t * (table.len() - 1) as f64;
        let i = (pos.floor() as usize).min(table.len() - 2);
        let f = pos - i as f64;
        let mix = |c: usize| {
            let a = f64::from(table[i][c]);
            let b = f64::from(table[i + 1][c]);
            (a + f * (b - a)).round() as u8
        };
        Rgb(mix(0), mix(1), mix(2))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// matplotlib values printed by tools/reference/colormap_tables.py.
    #[test]
    fn matches_matplotlib_reference() {
        let cases = [
            (Colormap::Viridis, 0.0, [68.09, 1.24, 84.00]),
            (Colormap::Viridis, 0.1, [72.07, 35.94, 116.67]),
            (Colormap::Viridis, 0.37, [44.84, 112.53, 142.21]),
            (Colormap::Viridis, 0.5, [32.53, 144.57, 140.39]),
            (Colormap::Viridis, 0.9, [189.05, 222.73, 38.14]),
            (Colormap::Viridis, 1.0, [253.28, 231.07, 36.70]),
            (Colormap::Diverging, 0.0, [5.00, 48.00, 97.00]),
            (Colormap::Diverging, 0.1, [32.45, 100.94, 170.53]),
            (Colormap::Diverging, 0.37, [189.24, 218.96, 234.35]),
            (Colormap::Diverging, 0.5, [247.12, 246.45, 246.06]),
            (Colormap::Diverging, 0.9, [176.53, 23.53, 42.76]),
            (Colormap::Diverging, 1.0, [103.00, 0.00, 31.00]),
        ];
        for (map, t, want) in cases {
            let Rgb(r, g, b) = map.color(t);
            for (got, want) in [(r, want[0]), (g, want[1]), (b, want[2])] {
                // Table interpolation error (≤ 2.83) plus 8-bit rounding (0.5).
                assert!(
                    (f64::from(got) - want).abs() <= 3.33,
                    "{map:?}({t}): {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn clamps_and_handles_nan() {
        assert_eq!(Colormap::Viridis.color(-1.0), Rgb(68, 1, 84));
        assert_eq!(Colormap::Viridis.color(2.0), Rgb(253, 231, 37));
        assert_eq!(Colormap::Viridis.color(f64::NAN), Rgb(68, 1, 84));
    }

    #[test]
    fn viridis_lightness_increases() {
        // Rec. 709 luma of viridis must be strictly increasing in t.
        let luma =
            |c: Rgb| 0.2126 * f64::from(c.0) + 0.7152 * f64::from(c.1) + 0.0722 * f64::from(c.2);
        let mut prev = -1.0;
        for k in 0..=64 {
            let l = luma(Colormap::Viridis.color(k as f64 / 64.0));
            assert!(l > prev, "k = {k}");
            prev = l;
        }
    }
}
