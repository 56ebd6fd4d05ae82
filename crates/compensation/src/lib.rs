//! # aeromag-compensation
//!
//! Fixed-wing magnetic interference ("deviation") compensation, spec
//! `compensation.md`, seed `000_…` chapters 1–2.
//!
//! | module | contents |
//! |---|---|
//! | [`metrics`] | FOM, manoeuvre detection, improvement ratio |
//! | [`tolles_lawson`] | the Tolles-Lawson/Leliak design matrix and its fits |

pub mod error;
pub mod kalman;
pub mod levelling;
pub mod metrics;
pub mod model_file;
pub mod observability;
pub mod pod;
pub mod reference_field;
pub mod rotor;
pub mod tolles_lawson;

pub use error::{CompError, Result};
