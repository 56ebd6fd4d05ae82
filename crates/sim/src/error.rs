//! The error type of `aeromag-sim`.
//!
//! Every fallible public function returns [`SimError`]; the simulator never
//! panics on bad input (a scenario file with a typo, an impossible number, a
//! date outside IGRF-14, an unwritable output directory).

use std::path::PathBuf;

/// Everything that can go wrong while configuring, running or writing a
/// simulation.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SimError {
    /// The scenario TOML could not be parsed (syntax, unknown field, wrong
    /// type). The message of the TOML parser names the line and column.
    #[error("scenario file: {message}")]
    ConfigParse {
        /// 1-based line of the file, when the parser names one (a value
        /// found wrong after merging over the defaults has none).
        line: Option<u64>,
        /// The parser's message.
        message: String,
    },
    /// A configuration value is outside its valid range.
    #[error("scenario value `{field}` is invalid: {reason}")]
    InvalidConfig {
        /// Dotted path of the field, e.g. `scalar.lag_s`.
        field: String,
        /// What is wrong and what is allowed.
        reason: String,
    },
    /// Values of the scenario file too large for the simulator: a
    /// simulated value came out NaN or infinite (the simulator models
    /// nothing as missing).
    #[error(
        "the scenario's values are too large for the simulator: the simulated `{column}` is {value} at sample {sample}{at}"
    )]
    Overflow {
        /// The output column.
        column: String,
        /// 1-based sample.
        sample: usize,
        /// The value (NaN or ±∞).
        value: f64,
        /// ` (time T s)` when the simulation has a time column.
        at: String,
    },
    /// The scenario's flight would be refused by aeromag's readers (its
    /// time or unit checks): values far beyond a real instrument's.
    #[error(
        "the scenario gives a flight aeromag's readers would refuse: {reason}; check the scenario's values (a sensor lag, speed or size far beyond a real one?)"
    )]
    Unreadable {
        /// The readers' message.
        reason: String,
    },
    /// An error of the core library (IGRF date range, dates, …).
    #[error(transparent)]
    Core(#[from] aeromag_core::CoreError),
    /// The trajectory generator could not realise the requested pattern.
    #[error("trajectory: {0}")]
    Trajectory(String),
    /// A numerical routine failed (an FFT length mismatch: a bug, reported
    /// instead of a panic).
    #[error("numerics: {0}")]
    Numerics(String),
    /// Writing an output file failed.
    #[error("cannot write `{path}`: {source}")]
    Write {
        /// The file that could not be written.
        path: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// Building the flight table of `aeromag-io` failed.
    #[error(transparent)]
    Io(#[from] aeromag_io::IoError),
    /// Serialising the scenario or the truth metadata failed.
    #[error("cannot serialise {what}: {reason}")]
    Serialize {
        /// What was being serialised.
        what: &'static str,
        /// The serialiser's message.
        reason: String,
    },
}

impl SimError {
    /// [`SimError::ConfigParse`] of a TOML parser's error on `text` (its
    /// span gives the line).
    pub fn toml(text: &str, e: &toml::de::Error) -> Self {
        SimError::ConfigParse {
            line: e
                .span()
                .map(|s| aeromag_core::error::line_of(text, s.start)),
            message: e.to_string(),
        }
    }

    /// [`SimError::ConfigParse`] without a line (a value found wrong after
    /// the file's table was merged over the defaults).
    pub fn config(message: impl Into<String>) -> Self {
        SimError::ConfigParse {
            line: None,
            message: message.into(),
        }
    }

    /// Whether the user's input caused the error: a scenario file that does
    /// not parse or holds an invalid value, a date outside IGRF-14, a
    /// pattern that cannot be flown. Running and writing failures are not.
    pub fn is_bad_input(&self) -> bool {
        match self {
            SimError::ConfigParse { .. }
            | SimError::InvalidConfig { .. }
            | SimError::Trajectory(_)
            | SimError::Overflow { .. }
            | SimError::Unreadable { .. } => true,
            SimError::Core(e) => e.is_bad_input(),
            SimError::Io(e) => e.is_bad_input(),
            SimError::Numerics(_) | SimError::Write { .. } | SimError::Serialize { .. } => false,
        }
    }
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, SimError>;

/// Shorthand for [`SimError::InvalidConfig`].
pub(crate) fn invalid(field: impl Into<String>, reason: impl Into<String>) -> SimError {
    SimError::InvalidConfig {
        field: field.into(),
        reason: reason.into(),
    }
}

/// Check that a configuration number is finite and strictly positive.
pub(crate) fn require_positive(field: &str, value: f64) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(invalid(
            field,
            format!("{value} must be a finite number > 0"),
        ))
    }
}

/// Check that a configuration number is finite and non-negative.
pub(crate) fn require_non_negative(field: &str, value: f64) -> Result<()> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(invalid(
            field,
            format!("{value} must be a finite number ≥ 0"),
        ))
    }
}

/// Check that a configuration number is finite.
pub(crate) fn require_finite(field: &str, value: f64) -> Result<()> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(invalid(field, format!("{value} must be finite")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scenario_problems_are_bad_input_and_failures_are_not() {
        assert!(
            SimError::ConfigParse {
                line: Some(3),
                message: "line 3".into()
            }
            .is_bad_input()
        );
        assert!(invalid("scalar.lag_s", "< 0").is_bad_input());
        assert!(!SimError::Numerics("fft".into()).is_bad_input());
        let w = SimError::Write {
            path: "/x".into(),
            source: std::io::Error::other("full"),
        };
        assert!(!w.is_bad_input());
    }
}
