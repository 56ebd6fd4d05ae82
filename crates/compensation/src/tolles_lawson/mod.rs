//! The Tolles-Lawson / Leliak interference model.

pub mod design;
pub mod fit_ls;
pub mod segments;
pub mod terms;

pub use terms::{Convention, TermGroup, TermSet, DEFAULT_BT_SCALE_NT};
