//! A flight: a table of time series read from a file (or built in
//! memory), checked once, and the views the workflows take of it.
//!
//! - [`Flight`] — the table with the warnings its checks raised;
//! - [`TlInputs`] — the columns of a Tolles-Lawson fit or compensation,
//!   the usable-row rule and the segments ([`SegmentRule`]);
//! - [`ReferenceChannels`] — the known external-field channels removed from
//!   the scalar reading before a fit or a score;
//! - [`default_column`] — the magnetic column `level`, `grid` and
//!   `microlevel` take when none is named (compensated first, any case);
//! - [`LeverArm`] and [`sensor_track`] — where the sensor is relative to
//!   the navigation point;
//! - [`position_glitches`] — rows whose position jumps off the track faster
//!   than anything flies.
//!
//! Files hold nT, m, s and degrees; frames are NED and body (x forward,
//! y right, z down). Columns have the canonical names of
//! `spec/data-formats.md` (`time`, `lat`, `lon`, `alt`, `roll`, `pitch`,
//! `yaw`, `mag`, `flux_x`, …) after the column map.

mod default_column;
mod line_labels;
mod reference;
mod segments;
mod tl_inputs;

pub use aeromag_compensation::reference_field::LeverArm;
pub use aeromag_io::{MAX_GROUND_SPEED_M_S, MIN_JUMP_M, position_glitches};
pub(crate) use default_column::find_column;
pub use default_column::{DefaultColumn, default_column, default_column_fields};
pub use line_labels::LineLabels;
pub(crate) use reference::NOT_FIELDS;
pub(crate) use reference::reduced;
pub use reference::{ReferenceChannels, reference_sum};
pub use segments::{GAP_FACTOR, SegmentRule, Segments, finite_segments};
pub use tl_inputs::{SensorColumns, TlInputs};

use crate::error::{Error, InFile, Result};
use crate::observer::Note;
use aeromag_io::{ColumnMap, FlightTable, ReadOptions};
use std::path::Path;

/// A flight table, read and checked: time strictly increasing where there
/// is a `time` column (bad input otherwise), and the plausibility of units
/// (a `mag` in tesla, a fluxgate magnitude far from `mag`) as warnings.
///
/// `Flight` dereferences to [`FlightTable`]: `flight.require("mag")?` is the
/// column in nT (NaN = missing), `flight.file_label()` the file's name.
///
/// ```
/// use aeromag::{Flight, FlightTable};
/// let mut t = FlightTable::new();
/// t.add_column("time", vec![0.0, 0.1, 0.2])?;
/// t.add_column("mag", vec![50_000.0, 50_001.0, 50_000.5])?;
/// let flight = Flight::from_table(t)?;
/// assert_eq!(flight.n_rows(), 3);
/// assert!(flight.warnings().is_empty());
/// # Ok::<(), aeromag::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct Flight {
    table: FlightTable,
    warnings: Vec<Note>,
    /// The median time step, s, once worked out ([`Flight::median_step_s`];
    /// the checked columns never change).
    median_step: std::sync::OnceLock<f64>,
    /// A text `line` column numbered by label, once worked out
    /// ([`Flight::line_numbers`]).
    text_line_numbers: std::sync::OnceLock<Option<Vec<f64>>>,
}

impl Flight {
    /// Read a CSV or Geosoft XYZ flight file with the default options (MagNav
    /// names recognised) and check it.
    pub fn read(path: impl AsRef<Path>) -> Result<Flight> {
        Self::read_with(path, &ReadOptions::default())
    }

    /// Read a flight file with its canonical names mapped by `columns` (e.g.
    /// `mag=mag_1_uc,flux_x=flux_a_x`) and check it.
    pub fn read_mapped(path: impl AsRef<Path>, columns: &ColumnMap) -> Result<Flight> {
        Self::read_with(
            path,
            &ReadOptions {
                columns: columns.clone(),
                ..ReadOptions::default()
            },
        )
    }

    /// Read a flight file with explicit reading options and check it.
    pub fn read_with(path: impl AsRef<Path>, opts: &ReadOptions) -> Result<Flight> {
        Self::from_table(aeromag_io::read_table(path.as_ref(), opts)?)
    }

    /// Check a table built in memory (or read otherwise) and wrap it.
    pub fn from_table(table: FlightTable) -> Result<Flight> {
        if table.column("time").is_some() {
            aeromag_io::check_time(&table)?;
        }
        let warnings = aeromag_io::check_units(&table)?
            .into_iter()
            .map(|w| Note::warning(w.to_string()))
            .collect();
        Ok(Flight {
            table,
            warnings,
            median_step: Default::default(),
            text_line_numbers: Default::default(),
        })
    }

    /// Wrap a table that is not a flight record (a crossover table, a
    /// detected-vector file): no time or unit checks.
    pub(crate) fn unchecked(table: FlightTable) -> Flight {
        Flight {
            table,
            warnings: Vec::new(),
            median_step: Default::default(),
            text_line_numbers: Default::default(),
        }
    }

    /// The `line` column as numbers, text labels (`L1020`, `T901`,
    /// `1003.1` beside `1003.10`) numbered by label
    /// ([`FlightTable::line_numbers`]): what splits the flight at line
    /// changes and tells the rows on a line (not 0). `None` without a
    /// `line` column.
    pub fn line_numbers(&self) -> Option<&[f64]> {
        if let Some(v) = self.table.column("line") {
            return Some(v);
        }
        self.text_line_numbers
            .get_or_init(|| self.table.line_numbers().map(std::borrow::Cow::into_owned))
            .as_deref()
    }

    /// The table.
    pub fn table(&self) -> &FlightTable {
        &self.table
    }

    /// The table, to add columns to or write.
    pub fn into_table(self) -> FlightTable {
        self.table
    }

    /// The table, to add result columns (never to change the checked ones).
    pub(crate) fn table_mut(&mut self) -> &mut FlightTable {
        &mut self.table
    }

    /// Add a column of results (bad input if the name exists).
    pub fn add_column(&mut self, name: &str, values: Vec<f64>) -> Result<()> {
        Ok(self.table.add_column(name, values)?)
    }

    /// The warnings of the unit checks (empty when nothing looks wrong).
    pub fn warnings(&self) -> &[Note] {
        &self.warnings
    }

    /// The file's name as messages give it.
    pub fn label(&self) -> String {
        self.table.file_label()
    }

    /// The navigation point's `lat`, `lon` (deg), `alt` (m) and the attitude
    /// `roll`, `pitch`, `yaw` (deg): what moving a lever arm needs.
    pub fn nav_and_attitude(&self) -> Result<[&[f64]; 6]> {
        Ok([
            self.require("lat")?,
            self.require("lon")?,
            self.require("alt")?,
            self.require("roll")?,
            self.require("pitch")?,
            self.require("yaw")?,
        ])
    }

    /// A bad-input error at `row` (0-based) and `column` of this flight,
    /// with the file's line when it is known.
    pub fn bad_value(&self, row: usize, column: &str, reason: impl Into<String>) -> Error {
        self.bad_at(row, Some(column.to_string()), reason.into())
    }

    /// A bad-input error about the column `name` (canonical or the file's;
    /// named as the file spells it) as a whole, no one row to blame.
    pub fn bad_column(&self, name: &str, reason: impl Into<String>) -> Error {
        Error::BadInput {
            file: Some(self.label()),
            line: None,
            row: None,
            column: Some(self.resolve(name).unwrap_or(name).to_string()),
            reason: reason.into(),
        }
    }

    /// A bad-input error at `row` (0-based) of this flight as a whole (no
    /// one column to blame), with the file's line when it is known.
    pub fn bad_row(&self, row: usize, reason: impl Into<String>) -> Error {
        self.bad_at(row, None, reason.into())
    }

    fn bad_at(&self, row: usize, column: Option<String>, reason: String) -> Error {
        Error::BadInput {
            file: Some(self.label()),
            line: self.line_of_row(row),
            row: Some(self.file_row(row)),
            column,
            reason,
        }
    }

    /// The column `name` as a model's or an estimator's input: as
    /// [`FlightTable::require`], and bad input when it is (or is mapped
    /// onto) a simulation truth column (`true_…`), which they never read
    /// (`calibrate --extra true_interf` fitted the truth; `--columns` and
    /// the sensor choices are checked on reading).
    pub fn measured(&self, name: &str) -> Result<&[f64]> {
        let column = self.resolve(name).unwrap_or(name);
        if aeromag_io::is_truth_column(column) {
            return Err(Error::bad_file(
                self.label(),
                format!(
                    "`{column}`{} is a simulation truth column; models and estimators never read truth",
                    if column == name {
                        String::new()
                    } else {
                        format!(" (as {name})")
                    }
                ),
            ));
        }
        Ok(self.require(name)?)
    }

    /// The magnetic column `name` that a survey command levels or grids
    /// (`mag_comp`, `mag_level`, a column chosen with --value/--column):
    /// bad input naming the first row where a value is infinite or beyond
    /// any magnetic field ([`aeromag_io::MAX_FIELD_NT`]: `inf` and 1e300
    /// were levelled into `inf` and dropped from a grid without a word),
    /// or when every value is below 10⁻³ in magnitude (tesla: the unit
    /// checks test `mag` and the reference columns, not a compensated or
    /// levelled column), or when it reads as a total field in microtesla.
    /// Missing values (NaN) pass.
    pub fn field_values(&self, name: &str) -> Result<&[f64]> {
        let v = self.require(name)?;
        if let Some(k) = v
            .iter()
            .position(|x| x.is_infinite() || x.abs() > aeromag_io::MAX_FIELD_NT)
        {
            return Err(self.bad_value(
                k,
                self.resolve(name).unwrap_or(name),
                format!(
                    "{} is no magnetic field value in nT (at most {} in magnitude): a corrupted cell? leave a missing value's cell empty",
                    aeromag_core::error::shown(v[k]),
                    aeromag_core::error::shown(aeromag_io::MAX_FIELD_NT)
                ),
            ));
        }
        let max = v
            .iter()
            .filter(|x| x.is_finite())
            .fold(f64::NEG_INFINITY, |m, x| m.max(x.abs()));
        if max > 0.0 && max < 1e-3 {
            return Err(self.bad_column(
                name,
                format!(
                    "every value is below 1e-3 in magnitude (largest {max:.3e}): tesla? the values must be in nT (multiply by 1e9)"
                ),
            ));
        }
        // A total field in µT (`level`, `grid` and `microlevel` took a
        // `mag_comp` of 53 "nT"); an anomaly of such values is told apart
        // by its spread ([`aeromag_io::reads_as_microtesla`]).
        let (median, min, max) = aeromag_io::column_spread(v);
        if let Some(m) = median
            && aeromag_io::reads_as_microtesla(m, Some((min, max)))
        {
            return Err(self.bad_column(
                name,
                format!(
                    "median |value| = {} looks like microtesla (Earth's field is 22 to 67 µT): the values must be in nT (multiply by 1000)",
                    aeromag_core::error::shown(m)
                ),
            ));
        }
        Ok(v)
    }

    /// A numeric column whose every value must be finite: bad input naming
    /// the first cell that is not a number (the reader keeps such a column
    /// as text) or that is missing, NaN or infinite.
    pub fn finite(&self, name: &str) -> Result<&[f64]> {
        if let Some(text) = self.text_column(name)
            && let Some(row) = text.iter().position(|c| c.trim().parse::<f64>().is_err())
        {
            return Err(self.bad_value(row, name, format!("'{}' is not a number", text[row])));
        }
        let v = self.require(name)?;
        if let Some(row) = v.iter().position(|x| !x.is_finite()) {
            return Err(self.bad_value(row, name, "value is missing, NaN or infinite"));
        }
        Ok(v)
    }

    /// The median of the positive finite time steps, s (0 if there are
    /// none; [`aeromag_compensation::tolles_lawson::segments::median_step`]),
    /// worked out once per flight: a fit, its segments, its sample rate and
    /// a compensation on the same flight share it (a pass over every step,
    /// 19 ms at 10⁷ samples).
    pub fn median_step_s(&self) -> Result<f64> {
        let time = self.require("time")?;
        Ok(*self
            .median_step
            .get_or_init(|| aeromag_compensation::tolles_lawson::segments::median_step(time)))
    }

    /// Sample rate from the median time step, Hz (bad input without two
    /// increasing time stamps).
    pub fn sample_rate_hz(&self) -> Result<f64> {
        let dt = self.median_step_s()?;
        if dt > 0.0 {
            Ok(1.0 / dt)
        } else {
            Err(Error::bad_file(
                self.label(),
                "fewer than two increasing time samples",
            ))
        }
    }

    /// The vector magnetometer the MagNav preset chose for `flux_x/y/z`
    /// in a file with several (SGL: fluxgates A–D, `flux_a_x` or
    /// `FLUXA_X`), for a report: `FLUXB_X, FLUXB_Y, FLUXB_Z`; `None` when
    /// the file's own `flux_x/y/z`, the column map or `--vector` chose.
    pub fn preset_vector(&self) -> Option<String> {
        let file = |c: &str| {
            self.mapping()
                .iter()
                .find(|m| m.canonical == c && m.origin == aeromag_io::MapOrigin::MagNavPreset)
                .map(|m| m.file_column.clone())
        };
        let [x, y, z] = ["flux_x", "flux_y", "flux_z"].map(file);
        Some(format!("{}, {}, {}", x?, y?, z?))
    }

    /// Canonical column name → the file's column name, for a model file.
    pub fn column_map_of(&self, names: &[&str]) -> std::collections::BTreeMap<String, String> {
        names
            .iter()
            .map(|c| (c.to_string(), self.resolve(c).unwrap_or(c).to_string()))
            .collect()
    }
}

impl std::ops::Deref for Flight {
    type Target = FlightTable;
    fn deref(&self) -> &FlightTable {
        &self.table
    }
}

impl From<Flight> for FlightTable {
    fn from(f: Flight) -> FlightTable {
        f.table
    }
}

/// The sensor's track `[lat (deg), lon (deg), alt (m)]`: the navigation
/// point's (`lat`, `lon`, `alt`) moved by the lever arm `arm_m` (body frame,
/// m) with the attitude (`roll`, `pitch`, `yaw`).
pub fn sensor_track(flight: &Flight, arm_m: [f64; 3]) -> Result<[Vec<f64>; 3]> {
    sensor_track_at(flight, flight.require("alt")?, arm_m)
}

/// [`sensor_track`] with the navigation altitude `alt` (m) given instead of
/// the table's `alt` column (e.g. a cleaned copy of it).
pub fn sensor_track_at(flight: &Flight, alt: &[f64], arm_m: [f64; 3]) -> Result<[Vec<f64>; 3]> {
    let [lat, lon, _, roll, pitch, yaw] = flight.nav_and_attitude()?;
    aeromag_compensation::levelling::sensor_positions(lat, lon, alt, roll, pitch, yaw, arm_m)
        .in_file(&flight.label())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A compensated total field in µT was levelled and gridded as nT
    /// (`score` refused it); an anomaly of the same median but its spread,
    /// and a total field in nT, are taken.
    #[test]
    fn a_total_field_in_microtesla_is_no_field_value() {
        let n = 500;
        let mut t = FlightTable::new();
        t.add_column("time", (0..n).map(|k| k as f64).collect())
            .unwrap();
        let total = |k: usize| 53_000.0 + 40.0 * (k as f64 / 30.0).sin();
        t.add_column("mag_comp", (0..n).map(|k| total(k) / 1000.0).collect())
            .unwrap();
        t.add_column("mag_nt", (0..n).map(total).collect()).unwrap();
        t.add_column(
            "anomaly",
            (0..n)
                .map(|k| 53.0 + 40.0 * (k as f64 / 30.0).sin())
                .collect(),
        )
        .unwrap();
        let f = Flight::from_table(t).unwrap();
        let e = f.field_values("mag_comp").unwrap_err();
        assert!(
            e.is_bad_input() && e.to_string().contains("microtesla"),
            "{e}"
        );
        assert!(f.field_values("mag_nt").is_ok());
        assert!(f.field_values("anomaly").is_ok());
    }

    /// After `--lines`, a bad cell is named by the file's data row and line.
    #[test]
    fn bad_values_name_the_files_data_row_after_a_selection() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f.csv");
        std::fs::write(
            &path,
            "time,line,mag\n0,1,50000\n1,1,50000\n2,2,50000\n3,2,\n4,2,50000\n",
        )
        .unwrap();
        let opts = ReadOptions {
            rows: aeromag_io::RowSelection::parse(Some("2"), None).unwrap(),
            ..ReadOptions::default()
        };
        let f = Flight::read_with(&path, &opts).unwrap();
        assert_eq!(f.n_rows(), 3);
        let e = f.finite("mag").unwrap_err().to_string();
        assert!(e.contains("line 5 (data row 4), column 'mag'"), "{e}");
    }
}
