//! The error type of `aeromag-estimation`.

/// Everything that can go wrong in estimation.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
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

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, EstError>;
