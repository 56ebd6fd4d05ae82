//! Reference frames and rotations.

pub mod attitude;
pub mod blade;
pub mod geodetic;

pub use attitude::Attitude;
pub use geodetic::{Geodetic, WGS84_A, WGS84_F};
