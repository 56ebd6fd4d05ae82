//! Micro-levelling: removal of the corrugation left along the lines after
//! tie-line levelling (Minty 1991, *Simple micro-levelling for
//! aeromagnetic data*, Exploration Geophysics 22, 591–592).
//!
//! 1. The column is gridded ([`grid_flight`](super::gridding::grid_flight), minimum curvature).
//! 2. The corrugation is isolated on the grid by a high-pass Butterworth
//!    filter (cut-off wavelength `cutoff_line_spacings` × the line
//!    spacing) times a directional cosine filter aligned with the lines
//!    ([`Spectral::Corrugation`]): stripes along the lines pass, the
//!    geology mostly does not.
//! 3. The corrugation grid is sampled (bilinearly) at every row on a line
//!    and reduced to a correction per line: by default one level per line,
//!    the median of the samples (level errors are constant along a line;
//!    geology the filter let through — an anomaly crossed by one line only
//!    is elongated along it on the grid — is local, and the median ignores
//!    it); with `along_line_m`, a running mean over that length of track
//!    (for level errors that drift along long lines).
//! 4. The correction is minus that; the micro-levelled column is the
//!    column plus the correction.
//!
//! The crossovers of lines and tie lines check the correction: levelled
//! data agree at them, so a correction that follows level errors leaves
//! their differences as they were, and one that follows geology the line
//! spacing undersamples (a source crossed by one line only is a stripe on
//! the grid) raises them. Their RMS before and after is reported, with a
//! warning when micro-levelling raises it by more than half.

use super::gridding::{GridOptions, grid_flight_finest};
use super::survey::LineGeometry;
use crate::error::{Error, InFile, Result};
use crate::flight::{Flight, LineLabels};
use crate::io::FlightTable;
use crate::observer::{Note, Notes, Observer};
use aeromag_compensation::levelling::{CrossoverSide, SurveyTracks, TrackConfig, find_crossovers};
use aeromag_core::error::shown;
use aeromag_grid::gridding::{MinCurvature, MinCurvatureReport};
use aeromag_grid::products::{Corrugation, Spectral, apply};
use aeromag_grid::projection::UtmZone;

/// Settings of [`microlevel`].
#[derive(Debug, Clone, PartialEq)]
pub struct MicrolevelOptions {
    /// The column (default: the most processed magnetic column, as
    /// [`grid_flight`](super::gridding::grid_flight)).
    pub column: Option<String>,
    /// Cell of the working grid, m (default as [`grid_flight`](super::gridding::grid_flight)).
    pub cell_m: Option<f64>,
    /// UTM zone (as [`GridOptions::zone`]).
    pub zone: Option<UtmZone>,
    /// Positions already projected (as [`GridOptions::projected`]).
    pub projected: Option<super::survey::ProjectedColumns>,
    /// The sensor's lever arm, m (as [`GridOptions::lever_arm_m`]).
    pub lever_arm_m: Option<[f64; 3]>,
    /// Cut-off wavelength of the high-pass, in line spacings (default 4).
    pub cutoff_line_spacings: f64,
    /// Length of an along-line running mean of the correction, m; `None`
    /// (default): one level per line, the median of its samples.
    pub along_line_m: Option<f64>,
    /// Power of the directional cosine filter (default 2).
    pub cosine_power: f64,
    /// Gridding settings.
    pub min_curvature: MinCurvature,
}

impl Default for MicrolevelOptions {
    fn default() -> Self {
        Self {
            column: None,
            cell_m: None,
            zone: None,
            projected: None,
            lever_arm_m: None,
            cutoff_line_spacings: 4.0,
            along_line_m: None,
            cosine_power: 2.0,
            min_curvature: MinCurvature::default(),
        }
    }
}

/// The result of [`microlevel`]: the correction of every row and what it
/// amounts to.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Microlevelled {
    /// The column micro-levelled.
    pub column: String,
    /// Per row, the correction, nT (0 off the lines).
    pub correction: Vec<f64>,
    /// Per row, the micro-levelled value.
    pub values: Vec<f64>,
    /// The lines' geometry the filter used.
    pub lines: LineGeometry,
    /// Cell of the working grid, m.
    pub cell_m: f64,
    /// The along-line running mean used, m (`None`: a level per line).
    pub along_line_m: Option<f64>,
    /// RMS of the correction over the rows on lines, nT.
    pub correction_rms_nt: f64,
    /// Largest |correction|, nT.
    pub correction_max_nt: f64,
    /// RMS of the crossover differences before and after the correction,
    /// nT (`None` without crossovers, e.g. no `time` column or no ties).
    pub crossover_rms_nt: Option<(f64, f64)>,
    /// How the working grid's minimum curvature converged (a grid that
    /// has not is also a warning, naming the settings to raise).
    pub gridding: MinCurvatureReport,
    /// Notes and warnings.
    pub notes: Vec<Note>,
}

impl Microlevelled {
    /// The micro-levelled column's name: `<column>_mlev`.
    pub fn output_column(&self) -> String {
        format!("{}_mlev", self.column)
    }

    /// The correction's column name: `<column>_mlev_corr`.
    pub fn correction_column(&self) -> String {
        format!("{}_mlev_corr", self.column)
    }

    /// Add the micro-levelled column and the correction to `table`.
    pub fn add_to(&self, table: &mut FlightTable) -> Result<()> {
        table.add_column(&self.output_column(), self.values.clone())?;
        table.add_column(&self.correction_column(), self.correction.clone())?;
        Ok(())
    }
}

/// The finest working-grid cell micro-levelling takes, in line spacings
/// (1/50: 10 m at a 500 m spacing). The stripes it removes are a line
/// spacing wide and the data are a spacing apart, so a finer cell resolves
/// nothing more, while the gridding's cost grows as the inverse square of
/// the cell or faster: on a 3 × 3 km survey at 500 m spacing a 10 m cell
/// took 2.5 s, 5 m 13 s, and 1 m more than a minute.
pub const MIN_CELL_LINE_SPACINGS: f64 = 0.02;

/// The shortest cut-off micro-levelling takes, in line spacings. Level
/// errors of single lines make stripes whose wavelength across the lines
/// is two line spacings or more; the order-8 high-pass keeps
/// `1/(1 + (λ/λc)¹⁶)` of a wavelength `λ` across the lines, so with its
/// cut-off `λc` at one line spacing it keeps 1.5·10⁻⁵ of the shortest
/// stripes and the correction is next to nothing (`--cutoff 1e-300` gave
/// a correction of zero with exit 0). At two line spacings it keeps half
/// of them; Minty's (1991) default is four.
pub const MIN_CUTOFF_LINE_SPACINGS: f64 = 2.0;

/// Micro-level a column of a levelled survey (module docs).
pub fn microlevel(
    flight: &Flight,
    opts: &MicrolevelOptions,
    observer: &mut dyn Observer,
) -> Result<Microlevelled> {
    let mut notes = Notes::new(observer);
    if opts.cutoff_line_spacings.is_nan() || opts.cutoff_line_spacings < MIN_CUTOFF_LINE_SPACINGS {
        return Err(Error::bad_input(format!(
            "the cut-off {} line spacings is below {MIN_CUTOFF_LINE_SPACINGS}: the stripes between \
             adjacent lines are {MIN_CUTOFF_LINE_SPACINGS} line spacings and more across them, and a \
             high-pass with a shorter cut-off takes them for geology (the correction would be next to nothing)",
            shown(opts.cutoff_line_spacings)
        )));
    }
    let gridded = grid_flight_finest(
        flight,
        &GridOptions {
            column: opts.column.clone(),
            cell_m: opts.cell_m,
            zone: opts.zone,
            projected: opts.projected.clone(),
            lever_arm_m: opts.lever_arm_m,
            // The filter needs the whole grid: nothing is blanked here.
            blanking_m: Some(f64::MAX),
            min_curvature: opts.min_curvature,
            ..GridOptions::default()
        },
        Some(MIN_CELL_LINE_SPACINGS),
        &mut notes,
    )?;
    let column = gridded.column.clone();
    let out = format!("{column}_mlev");
    if flight.get(&out).is_some() {
        return Err(Error::bad_file(
            flight.label(),
            format!("already has `{out}`"),
        ));
    }
    let lines = gridded.survey.lines.clone().ok_or_else(|| {
        Error::bad_file(
            flight.label(),
            "micro-levelling needs survey lines (a `line` column with at least two parallel lines)",
        )
    })?;
    let along = opts.along_line_m.unwrap_or(8.0 * lines.spacing_m);
    if !(along.is_finite() && along > 0.0) {
        return Err(Error::bad_input(format!(
            "the along-line length {} m must be positive",
            shown(along)
        )));
    }
    let cutoff_m = opts.cutoff_line_spacings * lines.spacing_m;
    if !cutoff_m.is_finite() {
        return Err(Error::bad_input(format!(
            "the cut-off {} line spacings of {} m is no wavelength",
            shown(opts.cutoff_line_spacings),
            shown(lines.spacing_m)
        )));
    }
    notes.stage("filtering the grid");
    notes.check_cancelled()?;
    let corrugation = apply(
        &gridded.grid,
        Spectral::Corrugation(Corrugation {
            line_direction_deg: lines.direction_deg,
            cutoff_wavelength_m: cutoff_m,
            order: 8,
            cosine_power: opts.cosine_power,
        }),
    )?;
    notes.stage("correcting the lines");
    notes.check_cancelled()?;
    let survey = &gridded.survey;
    let ids = survey.line_ids.as_deref().unwrap_or(&[]);
    let value = flight.field_values(&column)?;
    let n = value.len();
    // Per row on a line: the corrugation there (NaN outside the grid).
    let sampled: Vec<f64> = (0..n)
        .map(|k| {
            if ids.get(k).is_some_and(|&id| id != 0.0) {
                corrugation.sample(survey.x[k], survey.y[k])
            } else {
                f64::NAN
            }
        })
        .collect();
    let smooth = match opts.along_line_m {
        Some(along) => along_line_mean(&survey.x, &survey.y, ids, &sampled, along),
        None => line_medians(ids, &sampled),
    };
    let mut correction = vec![0.0; n];
    for k in 0..n {
        if smooth[k].is_finite() {
            correction[k] = -smooth[k];
        }
    }
    let on_line: Vec<f64> = (0..n)
        .filter(|&k| ids.get(k).is_some_and(|&id| id != 0.0))
        .map(|k| correction[k])
        .collect();
    let rms = (on_line.iter().map(|c| c * c).sum::<f64>() / on_line.len().max(1) as f64).sqrt();
    let max = on_line.iter().fold(0.0f64, |m, c| m.max(c.abs()));
    let values: Vec<f64> = value.iter().zip(&correction).map(|(v, c)| v + c).collect();
    let crossover_rms_nt = crossover_check(flight, value, &correction)?;
    if gridded.survey.position_columns != ["lat", "lon"] {
        notes.note(
            "the correction is not checked at the crossovers of lines and ties: `level` finds them from lat/lon, which are not used here"
                .to_string(),
        );
    }
    // A rise below the printed resolution is none (a constant column gave
    // "raises … from 0.000 to 0.000 nT").
    const RESOLUTION_NT: f64 = 1e-3;
    if let Some((before, after)) = crossover_rms_nt
        && after > 1.5 * before + RESOLUTION_NT
    {
        notes.warn(format!(
            "micro-levelling raises the crossover differences from {before:.3} to {after:.3} nT RMS: \
             the correction follows geology the line spacing undersamples, not level errors; \
             check the maps before using it"
        ));
    }
    Ok(Microlevelled {
        column,
        correction,
        values,
        lines,
        cell_m: gridded.grid.geometry.cell,
        along_line_m: opts.along_line_m,
        correction_rms_nt: rms,
        correction_max_nt: max,
        crossover_rms_nt,
        gridding: gridded.report.clone(),
        notes: notes.into_notes(),
    })
}

/// The RMS of the crossover differences of `value` and of `value +
/// correction` (nT), at the crossings of lines and ties (as `level` finds
/// them); `None` when the flight has no `time` column or no crossover.
fn crossover_check(
    flight: &Flight,
    value: &[f64],
    correction: &[f64],
) -> Result<Option<(f64, f64)>> {
    let (Some(time), Some(lat), Some(lon)) = (
        flight.column("time"),
        flight.column("lat"),
        flight.column("lon"),
    ) else {
        return Ok(None);
    };
    let labels = LineLabels::of(flight, &[])?;
    let nan = vec![f64::NAN; value.len()];
    let alt = flight.column("alt").unwrap_or(&nan);
    let tracks = SurveyTracks {
        time,
        lat,
        lon,
        alt,
        line: &labels.ids,
        value,
        sensed: None,
    };
    let config = TrackConfig {
        pairing: labels.pairing(),
        ..TrackConfig::default()
    };
    // The differences only: no derivative is needed.
    let zeros = vec![0.0; value.len()];
    let set = find_crossovers(&tracks, &zeros, None, &config).in_file(&flight.label())?;
    if set.crossovers.is_empty() {
        return Ok(None);
    }
    let at = |s: &CrossoverSide| {
        let next = (s.row + 1).min(correction.len() - 1);
        correction[s.row] * (1.0 - s.fraction) + correction[next] * s.fraction
    };
    let n = set.crossovers.len() as f64;
    let (mut before, mut after) = (0.0, 0.0);
    for x in &set.crossovers {
        let d = x.difference_nt();
        before += d * d;
        after += (d + at(&x.a) - at(&x.b)).powi(2);
    }
    Ok(Some(((before / n).sqrt(), (after / n).sqrt())))
}

/// Per row, the median of the finite `v` of its line (id ≠ 0; NaN for rows
/// on no line or lines without a finite value).
fn line_medians(ids: &[f64], v: &[f64]) -> Vec<f64> {
    let mut by_line: std::collections::BTreeMap<i64, Vec<f64>> = Default::default();
    for (id, x) in ids.iter().zip(v) {
        if *id != 0.0 && x.is_finite() {
            by_line.entry(*id as i64).or_default().push(*x);
        }
    }
    let medians: std::collections::BTreeMap<i64, f64> = by_line
        .into_iter()
        .map(|(id, mut xs)| {
            xs.sort_by(f64::total_cmp);
            let n = xs.len();
            let m = if n % 2 == 1 {
                xs[n / 2]
            } else {
                0.5 * (xs[n / 2 - 1] + xs[n / 2])
            };
            (id, m)
        })
        .collect();
    ids.iter()
        .map(|id| {
            if *id == 0.0 {
                f64::NAN
            } else {
                medians.get(&(*id as i64)).copied().unwrap_or(f64::NAN)
            }
        })
        .collect()
}

/// The running mean of `v` over `window_m` of track, within each run of
/// rows of one line (consecutive rows with the same id ≠ 0); NaN values
/// are left out of the means, rows without any finite value in their
/// window are NaN. O(n) with two pointers over the cumulative distance.
fn along_line_mean(x: &[f64], y: &[f64], ids: &[f64], v: &[f64], window_m: f64) -> Vec<f64> {
    let n = v.len();
    let mut out = vec![f64::NAN; n];
    let mut start = 0;
    while start < n {
        let id = ids.get(start).copied().unwrap_or(0.0);
        let mut end = start + 1;
        while end < n && ids[end] == id {
            end += 1;
        }
        if id != 0.0 {
            // Cumulative distance along the run.
            let mut s = vec![0.0; end - start];
            for k in start + 1..end {
                let d = ((x[k] - x[k - 1]).powi(2) + (y[k] - y[k - 1]).powi(2)).sqrt();
                s[k - start] = s[k - 1 - start] + if d.is_finite() { d } else { 0.0 };
            }
            let (mut lo, mut hi) = (0usize, 0usize);
            let (mut sum, mut count) = (0.0, 0usize);
            for i in 0..end - start {
                while hi < end - start && s[hi] <= s[i] + 0.5 * window_m {
                    if v[start + hi].is_finite() {
                        sum += v[start + hi];
                        count += 1;
                    }
                    hi += 1;
                }
                while s[lo] < s[i] - 0.5 * window_m {
                    if v[start + lo].is_finite() {
                        sum -= v[start + lo];
                        count -= 1;
                    }
                    lo += 1;
                }
                if count > 0 {
                    out[start + i] = sum / count as f64;
                }
            }
        }
        start = end;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_medians_ignore_a_local_anomaly() {
        let ids = [1.0, 1.0, 1.0, 1.0, 1.0, 0.0, 2.0, 2.0];
        let v = [0.5, 0.5, 9.0, 0.5, 0.4, 3.0, -1.0, -2.0];
        let m = line_medians(&ids, &v);
        assert_eq!(&m[..5], &[0.5; 5]);
        assert!(m[5].is_nan());
        assert_eq!(&m[6..], &[-1.5, -1.5]);
    }

    #[test]
    fn the_along_line_mean_stays_within_each_line() {
        let x: Vec<f64> = (0..10).map(|k| (k % 5) as f64 * 10.0).collect();
        let y = vec![0.0; 10];
        let ids = [1.0, 1.0, 1.0, 1.0, 1.0, 2.0, 2.0, 2.0, 2.0, 2.0];
        let v = [1.0, 1.0, f64::NAN, 1.0, 1.0, 5.0, 5.0, 5.0, 5.0, 5.0];
        let m = along_line_mean(&x, &y, &ids, &v, 25.0);
        assert!(m[..5].iter().all(|&a| a == 1.0), "{m:?}");
        assert!(m[5..].iter().all(|&a| a == 5.0), "{m:?}");
    }
}
