//! Compensation quality metrics (spec `compensation.md`, "Metrics").

pub mod fom;
pub mod improvement;
pub mod maneuvers;
pub mod residual;

pub use fom::{FomReport, FomWindow, figure_of_merit};
pub use improvement::{band_pass_segments, improvement_ratio};
pub use maneuvers::{Axis, Maneuver, ManeuverDetection, detect_maneuvers};
pub use residual::{LineLabel, LineResidual, residual_by_line};
