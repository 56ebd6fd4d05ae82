//! From levelled lines to the map (issue 22).
//!
//! - [`survey`] — a flight's lines in UTM coordinates ([`ProjectedSurvey`]):
//!   the zone picked from the data or given, the lines' direction and
//!   spacing, and the grid's defaults that follow from them;
//! - [`gridding`] — [`grid_flight`]: a column of a flight on a grid by
//!   minimum curvature with tension, blanked away from the lines
//!   ([`SurveyGrid`]);
//! - [`derive`](mod@derive) — [`derive()`]: first vertical derivative,
//!   upward continuation or difference of grid files;
//! - [`microlevel`](mod@microlevel) — [`microlevel()`]: the corrugation left along the
//!   lines after levelling, removed by a directional filter of the grid
//!   and a correction per row ([`Microlevelled`]).

pub mod derive;
pub mod gridding;
pub mod microlevel;
pub mod survey;

pub use derive::{GridProduct, derive};
pub use gridding::{GridOptions, SurveyGrid, grid_flight};
pub use microlevel::{MicrolevelOptions, Microlevelled, microlevel};
pub use survey::{LineGeometry, ProjectedSurvey};

/// The magnetic columns a survey file may hold, the most processed first:
/// the default column to grid.
pub const MOST_PROCESSED: [&str; 6] = [
    "mag_comp_level_mlev",
    "mag_level_mlev",
    "mag_comp_level",
    "mag_level",
    "mag_comp",
    "mag",
];
