//! # aeromag-estimation
//!
//! Estimation machinery shared by the subsystems.
//!
//! | module | contents |
//! |---|---|
//! | [`least_squares`] | streaming (chunked) ridge least squares with scaling, diagnostics |

pub mod error;
pub mod least_squares;

pub use error::{EstError, Result};
