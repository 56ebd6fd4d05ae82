//! Compensation quality metrics (spec `compensation.md`, "Metrics").

pub mod fom;
pub mod improvement;
pub mod maneuvers;
pub mod residual;

pub use fom::{figure_of_merit, FomReport, FomWindow};
pub use improvement::{band_pass_segments, improvement_ratio};
pub use residual::{residual_by_line, LineResidual};
pub use maneuvers::{detect_maneuvers, Axis, Maneuver, ManeuverDetection};
