//! The crate's error type.

use aeromag_core::error::shown;
use thiserror::Error;

/// Errors of the gradiometry library (bad configuration or input; never a panic).
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum GradiometryError {
    /// A length, noise level or count that must be positive and finite is not.
    #[error("{name} must be positive and finite, got {}", shown(*value))]
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
    /// A value outside its physically meaningful range (the message gives
    /// the range).
    #[error("{name} must be in {min}…{max}, got {}", shown(*value))]
    OutOfRange {
        /// Name of the parameter (the scenario-file key or the flag).
        name: &'static str,
        /// The offending value.
        value: f64,
        /// Smallest allowed value.
        min: f64,
        /// Largest allowed value.
        max: f64,
    },
    /// The estimate left the solution the data support: a failed fit (not
    /// bad input).
    #[error("estimate diverged: {0}")]
    Diverged(String),
    /// The four sensor offsets do not span three dimensions or are too close.
    #[error("degenerate gradiometer geometry: {0}")]
    DegenerateGeometry(String),
    /// A covariance square root or information matrix is singular.
    #[error("singular matrix in {0}")]
    Singular(&'static str),
    /// A scenario file that does not parse or holds an invalid value (the
    /// message names the field, and the line and column for syntax errors).
    #[error("scenario file: {message}")]
    Config {
        /// 1-based line of the file, for a syntax or type error the TOML
        /// parser places (`None` for a value found wrong afterwards).
        line: Option<u64>,
        /// What is wrong.
        message: String,
    },
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
    /// singular matrix (the data do not determine the estimate) and a
    /// diverged estimate is a value, geometry, scenario file or length the
    /// caller gave.
    pub fn is_bad_input(&self) -> bool {
        !matches!(
            self,
            GradiometryError::Singular(_) | GradiometryError::Diverged(_)
        )
    }
}

impl GradiometryError {
    /// [`GradiometryError::Config`] without a line.
    pub fn config(message: impl Into<String>) -> Self {
        GradiometryError::Config {
            line: None,
            message: message.into(),
        }
    }

    /// [`GradiometryError::Config`] of a TOML parser's error on `text`
    /// (its span gives the line).
    pub fn toml(text: &str, e: &toml::de::Error) -> Self {
        GradiometryError::Config {
            line: e
                .span()
                .map(|s| aeromag_core::error::line_of(text, s.start)),
            message: e.to_string(),
        }
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

/// `Ok(v)` when `min ≤ v ≤ max` (so finite), else
/// [`GradiometryError::OutOfRange`].
pub(crate) fn in_range(name: &'static str, value: f64, min: f64, max: f64) -> Result<f64> {
    if (min..=max).contains(&value) {
        Ok(value)
    } else {
        Err(GradiometryError::OutOfRange {
            name,
            value,
            min,
            max,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_a_singular_matrix_is_not_bad_input() {
        assert!(GradiometryError::NotFinite { name: "x" }.is_bad_input());
        assert!(GradiometryError::config("bad").is_bad_input());
        assert!(!GradiometryError::Singular("information").is_bad_input());
        assert!(!GradiometryError::Diverged("passes".into()).is_bad_input());
        let e = in_range("estimator.passes", 1e300, 1.0, 100.0).unwrap_err();
        assert!(e.is_bad_input());
        assert_eq!(
            e.to_string(),
            "estimator.passes must be in 1…100, got 1e300"
        );
    }
}
