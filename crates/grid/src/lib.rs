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
//! - [`format`](mod@format) — GeoTIFF, ESRI ASCII grid, netCDF (COARDS) and GXF files;
//! - [`error`] — [`GridError`], with `is_bad_input()`.

#![warn(missing_docs)]

pub mod error;
pub mod format;
pub mod grid;
pub mod gridding;
pub mod products;
pub mod projection;

pub use error::{GridError, Result};

/// Median of a non-empty slice (reordered in place): the UTM zone of a
/// survey's points and bi-directional gridding's sample spacing
/// ([`aeromag_core::median::median_in_place`]; an empty slice gives NaN).
pub(crate) fn median(v: &mut [f64]) -> f64 {
    aeromag_core::median::median_in_place(v).unwrap_or(f64::NAN)
}
pub use grid::{Grid, GridGeometry, GridStats};
