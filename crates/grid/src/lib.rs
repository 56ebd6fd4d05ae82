//! # aeromag-grid
//!
//! From survey lines to the map (issue 22):
//!
//! - [`grid`] — [`Grid`] and [`GridGeometry`]: node-registered grids in
//!   projected metres, NaN for blank nodes;
//! - [`projection`] — WGS 84 / UTM ([`projection::Utm`]), the zone picked
//!   from the data or given, and the [`projection::Crs`] the files carry;
//! - [`gridding`] — minimum curvature with tension (Smith & Wessel 1990)
//!   and blanking by distance from the data;
//! - [`products`] — first vertical derivative and upward continuation by FFT;
//! - [`format`](mod@format) — GeoTIFF, ESRI ASCII grid and netCDF (COARDS) files;
//! - [`error`] — [`GridError`], with `is_bad_input()`.

#![warn(missing_docs)]

pub mod error;
pub mod format;
pub mod grid;
pub mod gridding;
pub mod products;
pub mod projection;

pub use error::{GridError, Result};

/// Median of a non-empty slice (reordered in place); mean of the two
/// middle values for an even count. Serves the UTM zone of a survey's
/// points and bi-directional gridding's sample spacing.
pub(crate) fn median(v: &mut [f64]) -> f64 {
    let (m, even) = (v.len() / 2, v.len().is_multiple_of(2));
    let (below, &mut hi, _) = v.select_nth_unstable_by(m, f64::total_cmp);
    if even {
        let lo = below.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        0.5 * (lo + hi)
    } else {
        hi
    }
}
pub use grid::{Grid, GridGeometry, GridStats};

#[cfg(test)]
mod tests {
    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(super::median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(super::median(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
        assert_eq!(super::median(&mut [7.0]), 7.0);
    }
}
