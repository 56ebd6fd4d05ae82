//! A column of a survey on a grid.

use super::PROCESSING_STAGES;
use super::survey::{LineGeometry, ProjectedColumns, ProjectedSurvey};
use crate::error::{Error, Result};
use crate::flight::Flight;
use crate::observer::{Note, Notes, Observer};
use aeromag_core::error::shown;
use aeromag_grid::format::GridFormat;
use aeromag_grid::grid::MIN_CELL;
use aeromag_grid::gridding::{
    Bidirectional, BlockMeans, LinePoints, MinCurvature, MinCurvatureReport, Points, blank_beyond,
    distance_to_data,
};
use aeromag_grid::projection::{Crs, UtmZone};
use aeromag_grid::{Grid, GridGeometry};
use std::path::Path;

/// How the nodes are computed from the lines.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum GridMethod {
    /// Minimum curvature with tension (Smith & Wessel 1990; GMT `surface`).
    #[default]
    MinCurvature,
    /// Along the traverse lines, then across them by the Akima spline
    /// (tie lines are not used).
    Bidirectional,
}

/// Settings of [`grid_flight`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct GridOptions {
    /// The column to grid; `None`: the most processed magnetic column of
    /// the file, compensated first, any case ([`PROCESSING_STAGES`],
    /// [`crate::flight::default_column`]).
    pub column: Option<String>,
    /// Node spacing, m; `None`: a quarter of the line spacing, rounded
    /// down to 1, 2, 2.5 or 5 × 10ᵏ m.
    pub cell_m: Option<f64>,
    /// Nodes farther than this from the data are blank, m; `None`: the
    /// line spacing (5 cells without lines).
    pub blanking_m: Option<f64>,
    /// The UTM zone latitude and longitude are projected to; `None`: the
    /// zone of the data. With projected columns: the zone they are in (the
    /// grid's coordinate system); `None`: a system not given (the grid has
    /// none).
    pub zone: Option<UtmZone>,
    /// Positions already projected (easting and northing, m) in place of
    /// `lat`/`lon`; `None`: `lat`/`lon`, or, in a flight without them, the
    /// projected columns it has ([`ProjectedColumns::found_in`]).
    pub projected: Option<ProjectedColumns>,
    /// The sensor's lever arm (body frame x, y, z, m, from the navigation
    /// point): grid at the sensor's positions. `None`: at `lat`/`lon`.
    pub lever_arm_m: Option<[f64; 3]>,
    /// The grid's nodes; `None`: covering the data, at `cell_m`, nodes on
    /// multiples of the cell. Give it to grid several columns on the same
    /// nodes.
    pub geometry: Option<GridGeometry>,
    /// The method.
    pub method: GridMethod,
    /// Minimum-curvature settings (tension 0.25 by default).
    pub min_curvature: MinCurvature,
}

/// A survey column on a grid ([`grid_flight`]): the grid, and how it was
/// made.
#[derive(Debug, Clone)]
pub struct SurveyGrid {
    /// The grid (CRS: the UTM zone; blank nodes NaN).
    pub grid: Grid,
    /// The column gridded.
    pub column: String,
    /// The flight's rows in the grid's coordinates, and its lines'
    /// direction and spacing.
    pub survey: ProjectedSurvey,
    /// The blanking distance used, m.
    pub blanking_m: f64,
    /// Nodes left blank: beyond the blanking distance, or without a value
    /// from the method.
    pub blanked_nodes: usize,
    /// Rows gridded (on a line, finite position and value).
    pub rows_used: usize,
    /// How the minimum-curvature solution converged (no levels for the
    /// bi-directional method).
    pub report: MinCurvatureReport,
    /// Notes and warnings raised.
    pub notes: Vec<Note>,
}

impl SurveyGrid {
    /// Write the grid; the format follows the extension (`.tif`, `.asc`,
    /// `.nc`).
    pub fn write(&self, path: &Path) -> Result<GridFormat> {
        let format = Self::format_of(path)?;
        format.write(path, &self.grid)?;
        Ok(format)
    }

    /// The grid format [`Self::write`] uses for `path`, by its extension;
    /// bad input for any other. Call it before the gridding: an unknown
    /// extension (`g.png`) was reported only after the whole solve.
    pub fn format_of(path: &Path) -> Result<GridFormat> {
        Ok(GridFormat::from_path(path)?)
    }
}

/// Grid a column of `flight` (module docs of [`crate::map`]).
///
/// Rows on a line (label ≠ 0; every row without a `line` column) with a
/// finite position and value are projected to UTM and gridded by minimum
/// curvature with tension over their extent; nodes farther than the
/// blanking distance from any data are blank.
///
/// ```
/// use aeromag::map::{GridOptions, grid_flight};
/// use aeromag::simulate::{ScenarioKind, simulate_flight};
/// use aeromag::Silent;
/// let pattern = "[pattern]\nline_count = 6\nline_length_m = 3000.0\ntie_count = 0\n";
/// let survey = simulate_flight(ScenarioKind::Survey, Some(pattern), Some(3))?;
/// let g = grid_flight(&survey, &GridOptions::default(), &mut Silent)?;
/// assert_eq!(g.column, "mag");
/// assert!((g.survey.lines.unwrap().spacing_m - 500.0).abs() < 5.0);
/// assert_eq!(g.grid.geometry.cell, 100.0);
/// # Ok::<(), aeromag::Error>(())
/// ```
pub fn grid_flight(
    flight: &Flight,
    opts: &GridOptions,
    observer: &mut dyn Observer,
) -> Result<SurveyGrid> {
    grid_flight_finest(flight, opts, None, observer)
}

/// The warning for a cell finer than [`FINE_CELL_LINE_SPACINGS`] of the
/// line spacing, named `[fine-cell]`: the grid shows nothing the lines do
/// not sample, and its nodes, which minimum curvature relaxes hundreds of
/// times each, grow as the inverse square of the cell (a 0.5 m cell on
/// lines 500 m apart: 56 million nodes, 62 000 times the default's).
fn fine_cell_warning(geometry: &GridGeometry, lines: Option<&LineGeometry>) -> Option<String> {
    let l = lines?;
    let cell = geometry.cell;
    (cell < FINE_CELL_LINE_SPACINGS * l.spacing_m).then(|| {
        let times = (l.default_cell_m() / cell).powi(2);
        format!(
            "the cell {} m is finer than {FINE_CELL_LINE_SPACINGS} line spacings ({:.1} m between the lines): {} × {} nodes, {} times as many as at the default cell ({} m), with no more detail than the lines sample; a quarter to a tenth of the spacing is usual [fine-cell]",
            shown(cell),
            l.spacing_m,
            geometry.nx,
            geometry.ny,
            if times < 10.0 { format!("{times:.1}") } else { format!("{times:.0}") },
            shown(l.default_cell_m()),
        )
    })
}

/// The flight's positions as `opts` has them: `lat`/`lon` projected, or
/// projected columns named or found ([`GridOptions::projected`]), of
/// which a note says where they come from and a warning `[no-crs]` that
/// the grid will have no coordinate system without a zone.
fn survey_of(flight: &Flight, opts: &GridOptions, notes: &mut Notes) -> Result<ProjectedSurvey> {
    let given = opts.projected.as_ref();
    let lever_arm = opts.lever_arm_m.is_some();
    let Some(columns) = ProjectedColumns::chosen(flight, given, lever_arm, notes)? else {
        return ProjectedSurvey::of(flight, opts.zone, opts.lever_arm_m);
    };
    if opts.zone.is_none() {
        notes.warn(format!(
            "the grid has no coordinate system: {} and {} are taken as metres on a plane; give their UTM zone (--utm-zone) to have it written with the grid [no-crs]",
            columns.easting, columns.northing
        ));
    }
    ProjectedSurvey::of_columns(flight, &columns, opts.zone)
}

/// The warning for a minimum-curvature solve stopped by the sweep limit,
/// with how far the grid may be from the converged one
/// ([`LevelReport::remaining_estimate`](aeromag_grid::gridding::LevelReport::remaining_estimate)):
/// GMT's sweep limit (500) is kept, so that grids match GMT's at its
/// defaults, and a survey whose solve needs more (the simulated survey:
/// 1101 sweeps) is told what stopping costs. `None` when it converged.
pub(crate) fn not_converged_warning(report: &MinCurvatureReport) -> Option<String> {
    if report.converged {
        return None;
    }
    let last = report.levels.last()?;
    let off = last.remaining_estimate();
    let off = if off.is_finite() {
        format!(
            "the grid may be about {} from the converged one",
            aeromag_core::error::figure(off)
        )
    } else {
        "the changes no longer shrink, so how far the grid is from the converged one is unknown"
            .to_string()
    };
    Some(format!(
        "minimum curvature stopped after {} sweeps with a change of {:.3e} (limit {:.3e}): {off} (the change shrinking by {:.4} a sweep); \
         raise the sweep limit (--max-sweeps) or the convergence limit (--convergence)",
        report.final_sweeps(),
        last.max_change,
        report.convergence_limit,
        last.decay_per_sweep,
    ))
}

/// The finest cell, in line spacings, `grid` takes without the warning
/// `[fine-cell]`; the finest `microlevel` takes at all
/// ([`super::microlevel::MIN_CELL_LINE_SPACINGS`]).
pub const FINE_CELL_LINE_SPACINGS: f64 = super::microlevel::MIN_CELL_LINE_SPACINGS;

/// [`grid_flight`], a given cell finer than `finest` line spacings (when
/// the survey has lines) being bad input: micro-levelling's working grid
/// ([`super::microlevel::MIN_CELL_LINE_SPACINGS`]).
pub(crate) fn grid_flight_finest(
    flight: &Flight,
    opts: &GridOptions,
    finest: Option<f64>,
    observer: &mut dyn Observer,
) -> Result<SurveyGrid> {
    let mut notes = Notes::new(observer);
    let column = match &opts.column {
        Some(c) => c.clone(),
        None => {
            let d = crate::flight::default_column(flight, &PROCESSING_STAGES, "--column")?;
            if let Some(w) = d.warning {
                notes.warn(w);
            }
            d.name
        }
    };
    // A magnetic column is checked as one (tesla, 1e300); any other (a
    // height, a time) only for infinities, which a grid dropped silently.
    let magnetic =
        column.starts_with("mag") || aeromag_io::MAGNETIC_COLUMNS.contains(&column.as_str());
    let values = if magnetic {
        flight.field_values(&column)?
    } else {
        let v = flight.require(&column)?;
        if let Some(k) = v.iter().position(|x| x.is_infinite()) {
            return Err(flight.bad_value(
                k,
                flight.resolve(&column).unwrap_or(&column),
                "the value is infinite: a corrupted cell? leave a missing value's cell empty",
            ));
        }
        v
    };
    notes.stage("projecting");
    notes.check_cancelled()?;
    let survey = survey_of(flight, opts, &mut notes)?;
    if let Some(w) = survey.off_track_warning(flight) {
        notes.warn(w);
    }
    if let Some(w) = &survey.missing_labels {
        notes.warn(w.clone());
    }
    let cell = match (opts.geometry.map(|g| g.cell).or(opts.cell_m), &survey.lines) {
        (Some(c), Some(l)) if finest.is_some_and(|f| c < f * l.spacing_m) => {
            let f = finest.unwrap_or_default();
            return Err(Error::bad_input(format!(
                "the cell {} m is finer than {f} line spacings ({:.1} m between the lines): give at least {:.1} m (the default is a quarter of the spacing)",
                shown(c),
                l.spacing_m,
                f * l.spacing_m
            )));
        }
        (Some(c), _) => c,
        (None, Some(l)) if l.default_cell_m() < MIN_CELL => {
            return Err(Error::bad_file(
                flight.label(),
                format!(
                    "its lines are {:.3e} m apart, which gives no cell size (at least {} m): \
                     positions in another unit, or a corrupted file? give the cell size",
                    l.spacing_m,
                    shown(MIN_CELL)
                ),
            ));
        }
        (None, Some(l)) => l.default_cell_m(),
        (None, None) => {
            return Err(Error::bad_file(
                flight.label(),
                "has no survey lines to choose a cell size from (no `line` column, or fewer than two lines): give the cell size",
            ));
        }
    };
    let blanking = match (opts.blanking_m, &survey.lines) {
        (Some(b), _) => b,
        (None, Some(l)) => l.spacing_m,
        (None, None) => 5.0 * cell,
    };
    if !(blanking.is_finite() && blanking > 0.0) {
        return Err(Error::bad_input(format!(
            "the blanking distance {blanking} m must be positive"
        )));
    }
    let (mut x, mut y, mut z, mut line) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut missing = 0usize;
    for k in 0..values.len() {
        if !survey.on_line(k) {
            continue;
        }
        if values[k].is_finite() && survey.x[k].is_finite() && survey.y[k].is_finite() {
            x.push(survey.x[k]);
            y.push(survey.y[k]);
            z.push(values[k]);
            line.push(survey.line_ids.as_ref().map_or(0, |ids| ids[k] as i64));
        } else {
            missing += 1;
        }
    }
    if missing > 0 {
        notes.note(format!(
            "{missing} rows on lines have no {column} or no position and are not gridded"
        ));
    }
    let points = Points::new(&x, &y, &z)?;
    let (x0, x1, y0, y1) = points.extent().ok_or_else(|| {
        Error::bad_file(
            flight.label(),
            format!("no row on a line has a finite {column} and position"),
        )
    })?;
    let geometry = match opts.geometry {
        Some(g) => g,
        None => GridGeometry::covering(x0, x1, y0, y1, cell)?,
    };
    if let Some(w) = fine_cell_warning(&geometry, survey.lines.as_ref()) {
        notes.warn(w);
    }
    notes.stage("gridding");
    notes.check_cancelled()?;
    let (mut grid_values, report) = match (opts.method, &survey.lines) {
        (GridMethod::MinCurvature, _) => {
            opts.min_curvature
                .grid_cancellable(points, geometry, &mut || notes.cancelled())?
        }
        (GridMethod::Bidirectional, Some(l)) => {
            // Tie lines are left out (`traverse_ids` is ascending).
            let keep: Vec<usize> = (0..line.len())
                .filter(|&k| l.traverse_ids.binary_search(&line[k]).is_ok())
                .collect();
            let pick = |s: &[f64]| keep.iter().map(|&k| s[k]).collect::<Vec<f64>>();
            let (bx, by, bz) = (pick(&x), pick(&y), pick(&z));
            let bl: Vec<i64> = keep.iter().map(|&k| line[k]).collect();
            let values = Bidirectional {
                direction_deg: l.direction_deg,
                max_gap_cells: 4.0,
            }
            .grid(
                LinePoints {
                    x: &bx,
                    y: &by,
                    z: &bz,
                    line: &bl,
                },
                geometry,
            )?;
            (
                values,
                MinCurvatureReport::not_run(&BlockMeans::of(points, &geometry)),
            )
        }
        (GridMethod::Bidirectional, None) => {
            return Err(Error::bad_file(
                flight.label(),
                "bi-directional gridding needs survey lines (a `line` column with at least two parallel lines)",
            ));
        }
    };
    if let Some(w) = not_converged_warning(&report) {
        notes.warn(w);
    }
    let distance = distance_to_data(&geometry, &BlockMeans::of(points, &geometry));
    let blanked = blank_beyond(&mut grid_values, &distance, blanking);
    let grid = Grid {
        geometry,
        values: grid_values,
        crs: survey.zone.map(Crs::Utm),
        name: column.clone(),
        // A magnetic column's unit is nT, and so is an unknown one's (a
        // field, `true_anomaly`); a known field's is its own (`alt`: m; it
        // was nT for any column).
        unit: match magnetic {
            true => "nT".into(),
            false => aeromag_io::known_field(&column).map_or("nT".into(), |f| f.unit.into()),
        },
    };
    Ok(SurveyGrid {
        grid,
        column,
        survey,
        blanking_m: blanking,
        blanked_nodes: blanked,
        rows_used: x.len(),
        report,
        notes: notes.into_notes(),
    })
}
