//! The error type of `aeromag-compensation`.

/// Everything that can go wrong in compensation.
#[derive(Debug, thiserror::Error)]
pub enum CompError {
    /// Bad term specification.
    #[error("invalid Tolles-Lawson terms: {0}")]
    InvalidTerms(String),
    /// Input data unusable for the requested operation.
    #[error("{0}")]
    BadData(String),
    /// An error from the core crate (filters, validation).
    #[error(transparent)]
    Core(#[from] aeromag_core::CoreError),
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, CompError>;
