//! # aeromag-gradiometry
//!
//! Magnetic parameters of an object (a dipole moment `M`, A·m², at position
//! `r`, m) from remote gradiometer differences — spec `gradiometry.md`, seed
//! `004_…` (Pavlov, Karshakov, Goldin).
//!
//! - [`geometry`] — four-sensor layouts (tetrahedron, cross, planar);
//! - [`decorrelate`] — the orthonormal contrasts that whiten the differences;
//! - [`forward`] — `ForwardMT` / `ForwardMV` with analytic Jacobians;
//! - [`tensor_approx`] — the gradient-tensor (linear) approximation of the differences, for comparison;
//! - [`sr_iekf`] — square-root IEKF (`PrognosisFK`, `ProcessingFK`, per-epoch iteration) on
//!   the triangular toolkit of `aeromag_estimation::kalman`;
//! - [`pass`] — the filter over the epochs of a pass, re-linearised passes;
//! - [`motion`] — `MotionMT` / `MotionMV`;
//! - [`estimability`] — `MeasureS`, as μ = σ⁺/σ⁰ (0 = determined; `aeromag_core::estimability`);
//! - [`crlb`] — Cramér–Rao bound;
//! - [`efficiency`] — Monte-Carlo efficiency RMS/CRLB of the pass estimator;
//! - [`locate`] — detection, initialisation and the filter over a pass;
//! - [`config`] — the `gradiometer` scenario file (TOML);
//! - [`convergence`] — the seed's fig. 2 convergence map and a multi-start initialisation;
//! - [`sim`] — the simulator scenario `gradiometer`;
//! - [`parallel`] — index-parallel map over scoped threads (results independent of the thread count; from `aeromag-core`);
//! - [`error`] — [`GradiometryError`], with `is_bad_input()`.

#![warn(missing_docs)]

pub mod decorrelate;
pub mod error;
pub mod forward;
pub mod geometry;

pub use error::{GradiometryError, Result};
pub mod config;
pub mod convergence;
pub mod crlb;
pub mod efficiency;
pub mod estimability;
pub mod locate;
pub mod motion;
pub use aeromag_core::parallel;
pub mod pass;
pub mod sim;
pub mod sr_iekf;
pub mod tensor_approx;
