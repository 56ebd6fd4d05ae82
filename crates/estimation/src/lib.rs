//! # aeromag-estimation
//!
//! Estimation machinery shared by the subsystems.
//!
//! | module | contents |
//! |---|---|
//! | [`least_squares`] | streaming (chunked) ridge least squares with scaling, diagnostics |
//! | [`kalman`] | square-root Kalman filter (scalar updates), RTS smoother, innovations and likelihood |
//! | [`optimize`] | derivative-free minimisation (Nelder–Mead) |
//! | [`stats`] | distributions used by model-selection tests (χ²) |
//! | [`error`] | [`EstError`], with `is_bad_input()` |

pub mod error;
pub mod kalman;
pub mod least_squares;
pub mod optimize;
pub mod stats;

pub use error::{EstError, Result};
