//! The single-file HTML report.

pub mod report;
pub mod section;
