//! Errors of the EM positioning crate.

use thiserror::Error;

/// Everything that can go wrong in detection, calibration and positioning.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum EmError {
    /// A caller-supplied argument or setting is out of its domain (bad
    /// input).
    #[error("invalid argument: {reason}")]
    InvalidArgument {
        /// What is wrong and what is allowed.
        reason: String,
    },
    /// A matrix that must be invertible is (numerically) singular: the data
    /// do not determine the result (a failure, not bad input).
    #[error("singular matrix: {what}")]
    Singular {
        /// Which matrix, and why when known.
        what: String,
    },
    /// Input data are inconsistent with the model or malformed (e.g.
    /// non-finite values, a truncated record) (bad input).
    #[error("invalid data: {reason}")]
    InvalidData {
        /// What is wrong.
        reason: String,
    },
    /// A method ran on valid input but gave no usable result (e.g. no epoch
    /// located) (a failure, not bad input).
    #[error("{what}")]
    Failed {
        /// What failed, with the figures and likely causes.
        what: String,
    },
    /// An error from the core crate (filters, windows).
    #[error(transparent)]
    Core(#[from] aeromag_core::CoreError),
}

impl EmError {
    /// Whether the caller's input caused the error: invalid arguments and
    /// data; not a singular matrix.
    pub fn is_bad_input(&self) -> bool {
        match self {
            EmError::InvalidArgument { .. } | EmError::InvalidData { .. } => true,
            EmError::Singular { .. } | EmError::Failed { .. } => false,
            EmError::Core(e) => e.is_bad_input(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn classification() {
        assert!(EmError::InvalidArgument { reason: "x".into() }.is_bad_input());
        assert!(EmError::InvalidData { reason: "x".into() }.is_bad_input());
        assert!(!EmError::Singular { what: "M".into() }.is_bad_input());
        assert!(!EmError::Failed { what: "M".into() }.is_bad_input());
    }
}
