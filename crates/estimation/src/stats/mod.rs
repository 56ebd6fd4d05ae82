//! Distributions used by model-selection tests.

pub mod chi_square;

pub use chi_square::{chi_square_cdf, chi_square_quantile};
