//! The crate's error type.

use thiserror::Error;

/// Errors of the gradiometry library (bad configuration or input; never a panic).
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum GradiometryError {
    /// A length, noise level or count that must be positive and finite is not.
    #[error("{name} must be positive and finite, got {value}")]
    NotPositive {
        /// Name of the parameter.
        name: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A value that must be finite is NaN or infinite.
    #[error("{name} must be finite")]
    NotFinite {
        /// Name of the parameter.
        name: &'static str,
    },
    /// The four sensor offsets do not span three dimensions or are too close.
    #[error("degenerate gradiometer geometry: {0}")]
    DegenerateGeometry(String),
    /// A covariance square root or information matrix is singular.
    #[error("singular matrix in {0}")]
    Singular(&'static str),
    /// A scenario file that does not parse or holds an invalid value (the
    /// message names the field, and the line and column for syntax errors).
    #[error("scenario file: {0}")]
    Config(String),
    /// Inconsistent input lengths.
    #[error("length mismatch: {what} has {got}, expected {expected}")]
    LengthMismatch {
        /// What was measured.
        what: &'static str,
        /// Actual length.
        got: usize,
        /// Expected length.
        expected: usize,
    },
}

impl GradiometryError {
    /// Whether the caller's input caused the error: every variant but a
    /// singular matrix (the data do not determine the estimate) is a value,
    /// geometry, scenario file or length the caller gave.
    pub fn is_bad_input(&self) -> bool {
        !matches!(self, GradiometryError::Singular(_))
    }
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, GradiometryError>;

/// `Ok(v)` when `v` is finite and > 0, else [`GradiometryError::NotPositive`].
pub(crate) fn positive(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(GradiometryError::NotPositive { name, value })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_a_singular_matrix_is_not_bad_input() {
        assert!(GradiometryError::NotFinite { name: "x" }.is_bad_input());
        assert!(GradiometryError::Config("bad".into()).is_bad_input());
        assert!(!GradiometryError::Singular("information").is_bad_input());
    }
}
