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
pub use grid::{Grid, GridGeometry, GridStats};
