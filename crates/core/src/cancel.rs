//! Stopping a long computation between its steps.
//!
//! A long loop of the workspace (the Kalman noise tuning's evaluations,
//! minimum curvature's sweeps) takes a *cancellation probe*, a
//! `&mut dyn FnMut() -> bool` asked on the calling thread between steps
//! (a few milliseconds to a few tens of milliseconds apart): when it
//! returns `true` the computation stops with [`Cancelled`]. The probe is
//! asked often, so it must be cheap (a notebook's probe re-takes Python's
//! lock at most every 50 ms and otherwise only reads a clock). A result is
//! the same to the bit whether a probe was asked or not.
//!
//! ```
//! use aeromag_core::cancel::{Cancelled, check, never};
//!
//! let mut asked = 0;
//! let mut after_two = || {
//!     asked += 1;
//!     asked > 2
//! };
//! assert_eq!(check(&mut after_two), Ok(()));
//! assert_eq!(check(&mut after_two), Ok(()));
//! assert_eq!(check(&mut after_two), Err(Cancelled));
//! assert_eq!(check(&mut never), Ok(()));
//! ```

/// A computation was stopped by its cancellation probe (not bad input).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("cancelled")]
pub struct Cancelled;

/// `Err(Cancelled)` when the probe `cancel` says to stop.
pub fn check(cancel: &mut dyn FnMut() -> bool) -> Result<(), Cancelled> {
    if cancel() { Err(Cancelled) } else { Ok(()) }
}

/// The probe of a computation nobody cancels: always `false`.
pub fn never() -> bool {
    false
}
