//! The error type of `aeromag-report`.
//!
//! Every public fallible function returns [`ReportError`]; nothing in this
//! crate panics on user data (bad lengths, NaN, empty series, non-positive
//! values on a log axis, unwritable paths all come back as errors or are
//! handled as documented).

use std::path::PathBuf;

/// Errors of plotting and report writing.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReportError {
    /// Writing an output file (or creating its folder) failed.
    #[error("cannot write {path}: {source}")]
    Io {
        /// The file or folder that could not be written.
        path: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: std::io::Error,
    },
    /// A series has x and y vectors of different lengths.
    #[error("series '{series}': x has {x_len} values but y has {y_len}")]
    LengthMismatch {
        /// Name of the offending series.
        series: String,
        /// Length of `x`.
        x_len: usize,
        /// Length of `y`.
        y_len: usize,
    },
    /// Nothing drawable: every value is NaN/infinite (or non-positive on a log
    /// axis), or the plot has no series at all.
    #[error("plot '{title}' has no finite data to draw")]
    NoData {
        /// Title of the plot.
        title: String,
    },
    /// A user-given axis range is unusable (not finite, empty, reversed, or
    /// non-positive on a log axis).
    #[error("invalid {axis} range: {reason}")]
    InvalidRange {
        /// `"x"`, `"y"` or `"value"`.
        axis: &'static str,
        /// What is wrong with it.
        reason: String,
    },
    /// Image size too small to hold the axes (minimum
    /// [`MIN_SIZE_PX`](crate::MIN_SIZE_PX) in each direction) or too large
    /// (maximum [`MAX_SIZE_PX`](crate::MAX_SIZE_PX)).
    #[error("invalid image size {width}x{height} px")]
    InvalidSize {
        /// Requested width in pixels.
        width: u32,
        /// Requested height in pixels.
        height: u32,
    },
    /// Heatmap `values` does not hold `x.len() * y.len()` numbers.
    #[error("heatmap '{title}': expected {expected} values (x.len() * y.len()), got {got}")]
    ShapeMismatch {
        /// Title of the heatmap.
        title: String,
        /// `x.len() * y.len()`.
        expected: usize,
        /// `values.len()`.
        got: usize,
    },
    /// Heatmap cell-centre coordinates are empty, not finite or not strictly
    /// increasing.
    #[error("heatmap '{title}': {axis} coordinates {reason}")]
    InvalidGrid {
        /// Title of the heatmap.
        title: String,
        /// `"x"` or `"y"`.
        axis: &'static str,
        /// What is wrong with them.
        reason: String,
    },
    /// The embedded font could not be registered with plotters.
    #[error("cannot load the embedded font: {0}")]
    Font(String),
    /// The drawing backend failed (this is a bug or an out-of-memory condition,
    /// never a data problem).
    #[error("drawing failed: {0}")]
    Draw(String),
    /// PNG encoding failed.
    #[error("PNG encoding failed: {0}")]
    Png(String),
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, ReportError>;

impl ReportError {
    /// Whether the caller's data or arguments caused the error (lengths,
    /// no finite data, ranges, sizes, grids); writing, fonts, drawing and
    /// encoding failures are not.
    pub fn is_bad_input(&self) -> bool {
        match self {
            ReportError::LengthMismatch { .. }
            | ReportError::NoData { .. }
            | ReportError::InvalidRange { .. }
            | ReportError::InvalidSize { .. }
            | ReportError::ShapeMismatch { .. }
            | ReportError::InvalidGrid { .. } => true,
            ReportError::Io { .. }
            | ReportError::Font(_)
            | ReportError::Draw(_)
            | ReportError::Png(_) => false,
        }
    }

    /// Wraps an I/O error with the path it concerns.
    pub(crate) fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        ReportError::Io {
            path: path.into(),
            source,
        }
    }

    /// Converts any plotters drawing error into [`ReportError::Draw`].
    pub(crate) fn draw(err: impl std::fmt::Display) -> Self {
        ReportError::Draw(err.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn data_problems_are_bad_input_and_drawing_failures_are_not() {
        assert!(ReportError::NoData { title: "t".into() }.is_bad_input());
        assert!(!ReportError::Draw("backend".into()).is_bad_input());
        assert!(!ReportError::io("/x", std::io::Error::other("full")).is_bad_input());
    }
}
