//! Input checks shared by the filter and spectrum code: every public entry
//! point validates its arguments here and returns a [`CoreError`] instead of
//! panicking.

use crate::error::{CoreError, Result};

/// Error unless every sample of `x` is finite; the error names the first bad index.
pub(crate) fn check_finite(name: &'static str, x: &[f64]) -> Result<()> {
    // Blocks without an early exit inside vectorise; the position is only
    // searched for when a block fails.
    if x.chunks(256)
        .all(|c| c.iter().fold(true, |ok, v| ok & v.is_finite()))
    {
        return Ok(());
    }
    match x.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(CoreError::NonFinite { name, index }),
        None => Ok(()),
    }
}

/// Error unless `len ≥ min`.
pub(crate) fn check_len(name: &'static str, len: usize, min: usize) -> Result<()> {
    if len < min {
        Err(CoreError::TooShort { name, len, min })
    } else {
        Ok(())
    }
}

/// Error unless `v` is finite and strictly positive.
pub(crate) fn check_positive(name: &'static str, v: f64) -> Result<()> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(invalid(name, format!("must be finite and > 0, got {v}")))
    }
}

/// Shorthand for [`CoreError::InvalidArgument`].
pub(crate) fn invalid(name: &'static str, reason: impl Into<String>) -> CoreError {
    CoreError::InvalidArgument {
        name,
        reason: reason.into(),
    }
}
