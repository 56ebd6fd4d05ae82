//! The error type of `aeromag-compensation`.
//!
//! [`CompError::is_bad_input`] tells the caller's input (settings, data,
//! model files: fixing them fixes the call) from a method that failed on
//! valid input (a singular or diverging fit, a numerical failure).

use aeromag_estimation::EstError;

/// Everything that can go wrong in compensation.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CompError {
    /// A term specification that cannot be parsed or used (bad input).
    #[error("invalid Tolles-Lawson terms: {reason}")]
    InvalidTerms {
        /// What is wrong and what is allowed.
        reason: String,
    },
    /// A setting or argument outside its domain: a pass band, a ridge
    /// parameter, noise intensities, a geometry (bad input).
    #[error("{reason}")]
    InvalidSetting {
        /// What is wrong and what is allowed.
        reason: String,
    },
    /// Data the operation cannot use: too few rows or segments, series of
    /// different lengths, non-finite values, time not increasing (bad
    /// input).
    #[error("{reason}")]
    UnusableData {
        /// What is wrong with the data.
        reason: String,
    },
    /// A model file that does not parse or fails its checks (bad input).
    #[error("{origin}: {reason}")]
    ModelFile {
        /// The file (or other origin) as given.
        origin: String,
        /// 1-based line of the file, for a syntax error the JSON parser
        /// places (its message says the line and column too).
        line: Option<u64>,
        /// What is wrong.
        reason: String,
    },
    /// The data are valid but do not determine the estimate: a singular
    /// system or covariance (a failure, not bad input).
    #[error("{reason}")]
    Singular {
        /// What is singular.
        reason: String,
    },
    /// A method failed on valid input: an unstable filter design, a search
    /// that did not converge, a worker thread that failed (not bad input).
    #[error("{reason}")]
    Failed {
        /// What failed.
        reason: String,
    },
    /// An error of the estimation machinery, with where it happened;
    /// classified by the estimation error itself.
    #[error("{context}: {source}")]
    Estimation {
        /// Where (e.g. `least-squares fit failed`).
        context: String,
        /// The estimation error.
        source: EstError,
    },
    /// An error from the core crate (filters, validation).
    #[error(transparent)]
    Core(#[from] aeromag_core::CoreError),
    /// The caller's cancellation probe stopped the computation
    /// ([`aeromag_core::cancel`]; not bad input).
    #[error(transparent)]
    Cancelled(#[from] aeromag_core::cancel::Cancelled),
    /// Serialising a model failed (a bug, reported instead of a panic).
    #[error("cannot serialise {what}: {reason}")]
    Serialize {
        /// What was being serialised.
        what: &'static str,
        /// The serialiser's message.
        reason: String,
    },
}

impl CompError {
    /// Whether the caller's input caused the error: invalid terms,
    /// settings, data or model files, and the estimation or core errors
    /// that say so; `false` for singular or failed fits and serialisation.
    pub fn is_bad_input(&self) -> bool {
        match self {
            CompError::InvalidTerms { .. }
            | CompError::InvalidSetting { .. }
            | CompError::UnusableData { .. }
            | CompError::ModelFile { .. } => true,
            CompError::Singular { .. }
            | CompError::Failed { .. }
            | CompError::Serialize { .. }
            | CompError::Cancelled(_) => false,
            CompError::Estimation { source, .. } => source.is_bad_input(),
            CompError::Core(e) => e.is_bad_input(),
        }
    }

    /// [`CompError::InvalidSetting`].
    pub fn setting(reason: impl Into<String>) -> Self {
        CompError::InvalidSetting {
            reason: reason.into(),
        }
    }

    /// [`CompError::ModelFile`] of `origin`, without a line.
    pub fn model_file(origin: &str, reason: impl Into<String>) -> Self {
        CompError::ModelFile {
            origin: origin.to_string(),
            line: None,
            reason: reason.into(),
        }
    }

    /// [`CompError::UnusableData`].
    pub fn data(reason: impl Into<String>) -> Self {
        CompError::UnusableData {
            reason: reason.into(),
        }
    }

    /// The error with `context` (where it happened) before its message;
    /// the classification is kept.
    pub fn at(self, context: impl std::fmt::Display) -> Self {
        match self {
            CompError::InvalidTerms { reason } => CompError::InvalidTerms {
                reason: format!("{context}: {reason}"),
            },
            CompError::InvalidSetting { reason } => CompError::InvalidSetting {
                reason: format!("{context}: {reason}"),
            },
            CompError::UnusableData { reason } => CompError::UnusableData {
                reason: format!("{context}: {reason}"),
            },
            CompError::Singular { reason } => CompError::Singular {
                reason: format!("{context}: {reason}"),
            },
            CompError::Failed { reason } => CompError::Failed {
                reason: format!("{context}: {reason}"),
            },
            CompError::Estimation { context: c, source } => CompError::Estimation {
                context: format!("{context}: {c}"),
                source,
            },
            other => other,
        }
    }

    /// [`CompError::Estimation`] with its context.
    pub fn estimation(context: impl Into<String>) -> impl FnOnce(EstError) -> Self {
        let context = context.into();
        move |source| CompError::Estimation { context, source }
    }
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, CompError>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn input_errors_and_failures_are_told_apart() {
        assert!(CompError::setting("λ < 0").is_bad_input());
        assert!(CompError::data("3 rows").is_bad_input());
        assert!(CompError::model_file("m.json", "not JSON").is_bad_input());
        assert!(!CompError::Singular { reason: "P".into() }.is_bad_input());
        assert!(!CompError::Failed { reason: "x".into() }.is_bad_input());
        let under = EstError::Underdetermined {
            rows: 3,
            unknowns: 16,
        };
        assert!(CompError::estimation("fit")(under).is_bad_input());
        let singular = EstError::Singular("normal equations".into());
        let e = CompError::estimation("least-squares fit failed")(singular);
        assert!(!e.is_bad_input());
        assert_eq!(
            e.to_string(),
            "least-squares fit failed: singular system: normal equations"
        );
    }
}
