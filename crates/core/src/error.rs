//! The error type of `aeromag-core`.

/// Everything that can go wrong in `aeromag-core`.
///
/// Functions return an error instead of panicking on bad input (NaN,
/// empty series, impossible filter specifications, out-of-range dates).
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum CoreError {
    /// An argument is outside its valid domain.
    #[error("invalid argument `{name}`: {reason}")]
    InvalidArgument { name: &'static str, reason: String },
    /// A series contains a non-finite value where none is allowed.
    #[error("non-finite value in `{name}` at index {index}")]
    NonFinite { name: &'static str, index: usize },
    /// A series is too short for the requested operation.
    #[error("`{name}` has {len} samples; at least {min} are needed")]
    TooShort {
        name: &'static str,
        len: usize,
        min: usize,
    },
    /// A date lies outside the validity of a model.
    #[error("date {year:.3} is outside the model's validity {first:.1}–{last:.1}")]
    DateOutOfRange { year: f64, first: f64, last: f64 },
    /// A coefficient or data file could not be parsed.
    #[error("cannot parse {what}: {reason}")]
    Parse { what: &'static str, reason: String },
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, CoreError>;
