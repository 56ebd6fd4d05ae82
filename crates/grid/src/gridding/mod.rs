//! Gridding of scattered (line) data.
//!
//! - [`points`] — the data to grid and their block means per node;
//! - [`min_curvature`] — minimum curvature with tension (Smith & Wessel 1990);
//! - [`good_size`] — the slightly larger grid it is solved on, as GMT chooses it;
//! - [`bidirectional`] — line-based gridding: along the lines, then across (Akima);
//! - [`blanking`] — blank nodes farther than a distance from the data.

pub mod bidirectional;
pub mod blanking;
pub mod good_size;
pub mod min_curvature;
pub mod points;

pub use bidirectional::{Bidirectional, LinePoints};
pub use blanking::{blank_beyond, distance_to_data};
pub use min_curvature::{MinCurvature, MinCurvatureReport};
pub use points::{BlockMeans, Points};
