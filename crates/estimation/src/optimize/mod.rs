//! Derivative-free minimisation.
//!
//! | file | algorithm |
//! |---|---|
//! | [`nelder_mead`](mod@nelder_mead) | the Nelder–Mead simplex method (used to tune noise intensities by maximum likelihood) |

pub mod nelder_mead;

pub use nelder_mead::{NelderMeadOptions, NelderMeadResult, nelder_mead};
