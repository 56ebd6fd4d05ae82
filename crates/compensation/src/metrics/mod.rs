//! Compensation quality metrics (spec `compensation.md`, "Metrics").

pub mod fom;
pub mod maneuvers;

pub use fom::{figure_of_merit, FomReport, FomWindow};
pub use maneuvers::{detect_maneuvers, Axis, Maneuver, ManeuverDetection};
