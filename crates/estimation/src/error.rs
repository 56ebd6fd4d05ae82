//! The error type of `aeromag-estimation`.

/// Everything that can go wrong in estimation.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum EstError {
    /// Fewer usable rows than unknowns.
    #[error("{rows} usable rows for {unknowns} unknowns: the problem is underdetermined")]
    Underdetermined { rows: usize, unknowns: usize },
    /// A row or value is not finite.
    #[error("non-finite value in {what}")]
    NonFinite { what: &'static str },
    /// Dimensions do not agree.
    #[error("dimension mismatch: {0}")]
    Dimension(String),
    /// The system cannot be solved (singular even with the ridge term).
    #[error("singular system: {0}")]
    Singular(String),
    /// An error at one step of a sequential estimator (filter, smoother).
    #[error("step {step}: {source}")]
    AtStep {
        /// The step (sample index) where it happened.
        step: usize,
        /// What went wrong.
        source: Box<EstError>,
    },
}

impl EstError {
    /// Whether the input data caused the error: too few rows for the
    /// unknowns, or a non-finite value. A singular system (the data do not
    /// determine the solution) and mismatched dimensions (a caller's bug)
    /// are not bad input.
    pub fn is_bad_input(&self) -> bool {
        match self {
            EstError::Underdetermined { .. } | EstError::NonFinite { .. } => true,
            EstError::Dimension(_) | EstError::Singular(_) => false,
            EstError::AtStep { source, .. } => source.is_bad_input(),
        }
    }
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, EstError>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn classification() {
        assert!(
            EstError::Underdetermined {
                rows: 1,
                unknowns: 2
            }
            .is_bad_input()
        );
        assert!(EstError::NonFinite { what: "row" }.is_bad_input());
        assert!(!EstError::Singular("A".into()).is_bad_input());
        let at = EstError::AtStep {
            step: 3,
            source: Box::new(EstError::Singular("P".into())),
        };
        assert!(!at.is_bad_input());
    }
}
