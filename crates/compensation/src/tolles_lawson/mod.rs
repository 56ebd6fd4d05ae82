//! The Tolles-Lawson / Leliak interference model.

pub mod terms;

pub use terms::{Convention, TermGroup, TermSet, DEFAULT_BT_SCALE_NT};
