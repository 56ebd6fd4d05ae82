//! From levelled lines to the map (issue 22).
//!
//! - [`survey`] — a flight's lines in UTM coordinates ([`ProjectedSurvey`]):
//!   the zone picked from the data or given, or positions already projected
//!   ([`ProjectedColumns`]: a Geosoft XYZ's `X`, `Y`), the lines' direction
//!   and spacing, and the grid's defaults that follow from them;
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
pub mod picture;
pub mod survey;

pub use derive::{GridProduct, derive};
pub use gridding::{GridOptions, SurveyGrid, grid_flight};
pub use microlevel::{MicrolevelOptions, Microlevelled, microlevel};
pub use survey::{LineGeometry, PROJECTED_NAMES, ProjectedColumns, ProjectedSurvey};

/// The note of a grid written to a file `format` that does not record
/// its coordinate system (Geosoft's grid), when it has one.
pub fn crs_not_written(
    format: aeromag_grid::format::GridFormat,
    grid: &aeromag_grid::Grid,
) -> Option<crate::Note> {
    let crs = grid.crs.filter(|_| !format.keeps_crs())?;
    Some(crate::Note::note(format!(
        "the Geosoft grid does not record its coordinate system ({}): Oasis montaj keeps it \
         in a .gi file, whose format is not published; set it there, or write .gxf or .tif, \
         which record it",
        crs.name()
    )))
}

/// The processing stages of a survey's magnetic columns, the most
/// processed first (suffixes of the column: micro-levelled levelled,
/// levelled, as compensated or recorded): the default column to grid is
/// the first stage the file has, and within a stage the compensated
/// reading before the uncompensated ([`crate::flight::default_column`]):
/// `mag_comp_level_mlev`, `mag_<k>_comp_level_mlev`, `mag_level_mlev`,
/// `mag_comp_level`, …, `mag_comp`, `mag_<k>_comp`, `mag`.
pub const PROCESSING_STAGES: [&str; 3] = ["_level_mlev", "_level", ""];
