//! Errors of the EM positioning crate.

use thiserror::Error;

/// Everything that can go wrong in detection, calibration and positioning.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum EmError {
    /// A caller-supplied argument is out of its domain.
    #[error("invalid argument: {0}")]
    InvalidArgument(String),
    /// A matrix that must be invertible is (numerically) singular.
    #[error("singular matrix: {0}")]
    Singular(String),
    /// Input data are inconsistent with the model (e.g. non-finite values).
    #[error("invalid data: {0}")]
    InvalidData(String),
    /// An error from the core crate (filters, windows).
    #[error(transparent)]
    Core(#[from] aeromag_core::CoreError),
}
