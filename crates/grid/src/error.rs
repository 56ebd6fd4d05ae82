//! The crate's error type.

use aeromag_core::error::shown;
use thiserror::Error;

/// Errors of the gridding library (bad input or settings, a failed write;
/// never a panic).
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum GridError {
    /// A setting that must be positive and finite is not (cell size,
    /// blanking distance, …).
    #[error("{name} must be positive and finite, got {}", shown(*value))]
    NotPositive {
        /// Name of the setting.
        name: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A setting outside its range.
    #[error("{name} = {} is out of range: {expected}", shown(*value))]
    OutOfRange {
        /// Name of the setting.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// What is allowed.
        expected: &'static str,
    },
    /// Input series of unequal lengths.
    #[error("length mismatch: {what} has {got} values, expected {expected}")]
    LengthMismatch {
        /// What was measured.
        what: &'static str,
        /// Actual length.
        got: usize,
        /// Expected length.
        expected: usize,
    },
    /// Too few usable (finite) points to grid, or a grid too large.
    #[error("cannot grid: {0}")]
    Data(String),
    /// A grid that cannot be filtered, differenced or written: too small,
    /// without a value, of other nodes than the grid it is taken from, a
    /// result that is not finite.
    #[error("{0}")]
    Unusable(String),
    /// A coordinate that cannot be projected (latitude beyond ±84°/−80° of
    /// UTM, NaN, a zone number outside 1–60).
    #[error("projection: {0}")]
    Projection(String),
    /// A grid file format this crate does not write (the extension decides).
    #[error(
        "unknown grid format '{0}': use .tif, .asc, .nc, .grd, .gxf or, for Oasis montaj's own, .grd(GRD)"
    )]
    UnknownFormat(String),
    /// A grid file that cannot be read: missing, truncated, or not in the
    /// format its extension says.
    #[error("reading '{path}': {reason}")]
    Read {
        /// The file.
        path: String,
        /// What is wrong.
        reason: String,
    },
    /// A grid file (or its `.prj`) that cannot be opened or read: missing,
    /// not readable, not text where text is expected.
    #[error("reading '{path}': {source}")]
    Open {
        /// The file.
        path: String,
        /// The operating system's reason.
        #[source]
        source: std::io::Error,
    },
    /// A node value of a grid file that is not a grid value: infinite, or
    /// larger in magnitude than [`MAX_VALUE`](crate::grid::MAX_VALUE)
    /// (float32's largest).
    /// (NaN is a blank node, not an error.)
    #[error(
        "reading '{path}': the value at row {row}, column {column} (from the north-west \
         corner, 1-based) is {}: grid values must be finite and within float32's range, \
         ±3.4e38",
        shown(*value)
    )]
    BadValue {
        /// The file.
        path: String,
        /// Row, 1-based, counted from the northern row.
        row: usize,
        /// Column, 1-based, counted from the western column.
        column: usize,
        /// The value read.
        value: f64,
    },
    /// A continuation height outside what changes the grid and stays
    /// meaningful for it ([`crate::products::height_range`]).
    #[error(
        "continuation height {} m is out of range: between {} and {} m for this grid \
         (1e-8 cell: lower heights change no value at float32 precision; 10 times the \
         grid's extent: higher ones leave only its mean)",
        shown(*value),
        shown(*min),
        shown(*max)
    )]
    Height {
        /// The height asked for, m.
        value: f64,
        /// The lowest allowed, m.
        min: f64,
        /// The highest allowed, m.
        max: f64,
    },
    /// The caller's cancellation probe stopped the computation
    /// ([`aeromag_core::cancel`]; not bad input).
    #[error(transparent)]
    Cancelled(#[from] aeromag_core::cancel::Cancelled),
    /// Writing a grid file failed.
    #[error("writing '{path}': {source}")]
    Write {
        /// The file.
        path: String,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
}

impl GridError {
    /// Whether the caller's input caused the error (everything but a failed
    /// write and a cancelled computation).
    pub fn is_bad_input(&self) -> bool {
        !matches!(self, GridError::Write { .. } | GridError::Cancelled(_))
    }
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, GridError>;

/// `Ok(v)` when `v` is finite and > 0, else [`GridError::NotPositive`].
pub(crate) fn positive(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(GridError::NotPositive { name, value })
    }
}
