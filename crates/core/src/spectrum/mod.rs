//! Spectral estimation: Welch's averaged, modified periodogram
//! ([`welch`](mod@welch)) with per-segment detrending ([`detrend`]).
//!
//! Used to judge compensation quality (the residual's spectrum in the
//! manoeuvre band) and to check simulated noise against its specification.
//! Results equal SciPy's `signal.welch` (tests in
//! `tests/filter_reference.rs`).

pub mod detrend;
pub mod welch;

pub use detrend::{Detrend, detrend_in_place};
pub use welch::{Psd, Scaling, WelchConfig, welch};
