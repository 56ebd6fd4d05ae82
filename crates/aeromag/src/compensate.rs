//! Models that remove interference from a flight's scalar reading, and the
//! columns they add to it.
//!
//! Every model of this library — the Tolles-Lawson model of a fixed-wing
//! aircraft ([`TlModel`](crate::TlModel)), the helicopter rotor model and
//! the towed-pod model — applies itself to a flight through the
//! [`Compensator`] trait: `model.interference(&flight)` is the modelled
//! interference of every row (nT; NaN where it cannot be computed), and
//! `model.compensate(&flight)` the flight with `mag − interference`.

use crate::error::{Error, Result};
use crate::flight::Flight;
use crate::observer::{Note, Notes, Observer, Silent};
use aeromag_io::FlightTable;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The columns a compensation adds to a flight, and why a row may be left
/// uncompensated (for the message).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OutputColumns {
    /// Modelled interference, nT (e.g. `mag_interf`).
    pub interference: &'static str,
    /// 0 compensated, 1 not (e.g. `comp_flag`).
    pub flag: &'static str,
    /// Why a row can be left uncompensated, in words.
    pub why_missing: &'static str,
    /// What may make this model's interference beyond any magnetic field
    /// on a flight, in words (the end of that error's message).
    pub why_beyond: &'static str,
}

/// The compensated reading, always this column.
pub const COMPENSATED: &str = "mag_comp";

/// A model that removes interference from a flight's scalar reading `mag`.
///
/// Implementors provide [`Compensator::output`] and
/// [`Compensator::interference_observed`]; the rest follows.
///
/// ```
/// use aeromag::prelude::*;
/// use aeromag::simulate::{ScenarioKind, simulate_flight};
/// let cal = simulate_flight(ScenarioKind::Calibration, None, Some(1))?;
/// let model: TlModel = calibrate(&cal, &CalibrateOptions::default(), &mut Silent)?.model;
/// // Any model (Tolles-Lawson, rotor, pod file) applies itself to a flight.
/// let survey = simulate_flight(ScenarioKind::Survey, None, Some(2))?;
/// let out = model.compensate(&survey)?;
/// let table = out.into_flight(survey)?; // + mag_interf, mag_comp, comp_flag
/// assert!(table.column("mag_comp").is_some());
/// # Ok::<(), aeromag::Error>(())
/// ```
pub trait Compensator {
    /// The columns this model's compensation adds.
    fn output(&self) -> OutputColumns;

    /// The modelled interference of every row of `flight`, nT (NaN where
    /// an input is missing or the row cannot be compensated); notes and
    /// warnings (a flight that does not look like the one the model was
    /// fitted on) go to `observer`.
    fn interference_observed(
        &self,
        flight: &Flight,
        observer: &mut dyn Observer,
    ) -> Result<Vec<f64>>;

    /// The modelled interference of every row of `flight`, nT (NaN where
    /// it cannot be computed); bad input naming the first row where a
    /// value is beyond any magnetic field ([`aeromag_io::MAX_FIELD_NT`]:
    /// a model file that does not fit the flight).
    fn interference(&self, flight: &Flight) -> Result<Vec<f64>> {
        self.interference_checked(flight, &mut Silent)
    }

    /// [`Compensator::interference`], its notes and warnings going to
    /// `observer`.
    fn interference_checked(
        &self,
        flight: &Flight,
        observer: &mut dyn Observer,
    ) -> Result<Vec<f64>> {
        let v = self.interference_observed(flight, observer)?;
        check_interference(flight, self.output(), &v)?;
        Ok(v)
    }

    /// The interference, the compensated reading and the flags of every
    /// row, with the notes raised (bad input where the interference is
    /// beyond any magnetic field, as [`Compensator::interference`]).
    fn compensate_observed(
        &self,
        flight: &Flight,
        observer: &mut dyn Observer,
    ) -> Result<Compensated> {
        let mut notes = Notes::new(observer);
        let interference_nt = self.interference_observed(flight, &mut notes)?;
        let mut out = Compensated::new(flight, self.output(), interference_nt)?;
        out.notes = notes.into_notes();
        Ok(out)
    }

    /// The interference, the compensated reading and the flags of every row.
    fn compensate(&self, flight: &Flight) -> Result<Compensated> {
        self.compensate_observed(flight, &mut Silent)
    }

    /// The compensated reading alone (nT, NaN where not compensated):
    /// [`Compensated::compensated_nt`], computed in the place of the
    /// interference instead of beside it (one flight-long buffer, not two).
    fn compensated(&self, flight: &Flight) -> Result<Vec<f64>> {
        self.compensated_observed(flight, &mut Silent)
    }

    /// [`Compensator::compensated`], its notes and warnings going to
    /// `observer`.
    fn compensated_observed(
        &self,
        flight: &Flight,
        observer: &mut dyn Observer,
    ) -> Result<Vec<f64>> {
        let mut out = self.interference_checked(flight, observer)?;
        minus_from_mag(flight, &mut out)?;
        Ok(out)
    }
}

/// Bad input, naming the first row, where a modelled interference
/// `interference_nt` of `flight` is infinite or beyond any magnetic field
/// ([`aeromag_io::MAX_FIELD_NT`]): the inputs are checked to be within it,
/// so such a value comes from a model file that does not fit the flight
/// (an edited or corrupted coefficient or `bt_scale`, another aircraft's
/// terms); written out, it would pass for a compensated reading. NaN is a
/// row the model could not be applied to, not an error.
pub(crate) fn check_interference(
    flight: &Flight,
    output: OutputColumns,
    interference_nt: &[f64],
) -> Result<()> {
    match interference_nt.iter().position(|v| beyond_any_field(*v)) {
        Some(row) => Err(interference_error(
            flight,
            output,
            row,
            interference_nt[row],
        )),
        None => Ok(()),
    }
}

/// `|v| > MAX_FIELD_NT`, ∞ included (NaN not).
fn beyond_any_field(v: f64) -> bool {
    v.abs() > aeromag_io::MAX_FIELD_NT
}

fn interference_error(flight: &Flight, output: OutputColumns, row: usize, v: f64) -> Error {
    flight.bad_row(
        row,
        format!(
            "the model's interference here is {v:e} nT, beyond any magnetic field (at most {:e} nT in magnitude): the model does not fit this flight ({})",
            aeromag_io::MAX_FIELD_NT,
            output.why_beyond
        ),
    )
}

/// `values ← mag − values` on the rows both have (`values` cut to them),
/// on the cores by parts.
fn minus_from_mag(flight: &Flight, values: &mut Vec<f64>) -> Result<()> {
    let mag = flight.require("mag")?;
    values.truncate(mag.len());
    let threads = aeromag_core::parallel::threads();
    aeromag_core::parallel::for_each_part_mut(values, threads, 1 << 16, |a, part| {
        for (v, m) in part.iter_mut().zip(&mag[a..]) {
            *v = m - *v;
        }
    });
    Ok(())
}

/// A flight's reading with a model's interference removed, row by row.
#[derive(Debug, Clone, PartialEq)]
pub struct Compensated {
    /// Column names.
    pub output: OutputColumns,
    /// Modelled interference, nT (NaN = not compensated).
    pub interference_nt: Vec<f64>,
    /// `mag − interference`, nT (NaN = not compensated).
    pub compensated_nt: Vec<f64>,
    /// Rows that could not be compensated.
    pub missing: usize,
    /// Notes and warnings of the model's application.
    pub notes: Vec<Note>,
}

impl Compensated {
    /// `mag − interference` of `flight`; bad input naming the first row
    /// where the interference is beyond any magnetic field
    /// ([`aeromag_io::MAX_FIELD_NT`]: a model that does not fit the flight).
    pub fn new(flight: &Flight, output: OutputColumns, interference_nt: Vec<f64>) -> Result<Self> {
        let mag = flight.require("mag")?;
        let n = interference_nt.len().min(mag.len());
        // Zeroed (fresh pages, first written by the parts' threads); the
        // difference and the count of rows not compensated in one pass on
        // the cores.
        let mut compensated_nt = vec![0.0; n];
        let missing = AtomicUsize::new(0);
        // The first row beyond any field (check_interference), found in
        // the same pass.
        let beyond = AtomicUsize::new(usize::MAX);
        let threads = aeromag_core::parallel::threads();
        aeromag_core::parallel::for_each_part_mut(
            &mut compensated_nt,
            threads,
            1 << 16,
            |a, part| {
                let interference = &interference_nt[a..a + part.len()];
                for ((c, m), i) in part.iter_mut().zip(&mag[a..]).zip(interference) {
                    *c = m - i;
                }
                let not = interference.iter().filter(|v| !v.is_finite()).count();
                missing.fetch_add(not, Ordering::Relaxed);
                if let Some(k) = interference.iter().position(|v| beyond_any_field(*v)) {
                    beyond.fetch_min(a + k, Ordering::Relaxed);
                }
            },
        );
        let tail = interference_nt[n..]
            .iter()
            .position(|v| beyond_any_field(*v));
        let first = Some(beyond.into_inner())
            .filter(|&row| row < n)
            .or(tail.map(|k| n + k));
        if let Some(row) = first {
            return Err(interference_error(
                flight,
                output,
                row,
                interference_nt[row],
            ));
        }
        let missing = missing.into_inner()
            + interference_nt[n..]
                .iter()
                .filter(|v| !v.is_finite())
                .count();
        Ok(Self {
            output,
            interference_nt,
            compensated_nt,
            missing,
            notes: Vec::new(),
        })
    }

    /// 0 for a compensated row, 1 for one that is not.
    pub fn flags(&self) -> Vec<f64> {
        self.interference_nt
            .iter()
            .map(|v| if v.is_finite() { 0.0 } else { 1.0 })
            .collect()
    }

    /// Add the interference, [`COMPENSATED`] and flag columns to `table`
    /// (bad input if one of them exists already).
    pub fn add_to(self, table: &mut FlightTable) -> Result<()> {
        check_new_columns(
            table,
            [self.output.interference, COMPENSATED, self.output.flag],
        )?;
        let flags = self.flags();
        table.add_column(self.output.interference, self.interference_nt)?;
        table.add_column(COMPENSATED, self.compensated_nt)?;
        table.add_integer_column(self.output.flag, flags)?;
        Ok(())
    }

    /// The flight with the three columns added.
    pub fn into_flight(self, mut flight: Flight) -> Result<Flight> {
        self.add_to(flight.table_mut())?;
        Ok(flight)
    }

    /// The flight's table with the three columns added.
    pub fn into_table(self, flight: Flight) -> Result<FlightTable> {
        Ok(self.into_flight(flight)?.into_table())
    }
}

/// Bad input when `table` already reads a column as one of `names`, the
/// columns a compensation adds: a column of that name ("rename it first"),
/// or one the column map reads under it (`--columns mag_comp=COMPMAG1` on
/// `compensate`: the map is the thing to change; the file's column, left
/// unmapped, is written as it is beside the new one).
pub(crate) fn check_new_columns<'a>(
    table: &FlightTable,
    names: impl IntoIterator<Item = &'a str>,
) -> Result<()> {
    for name in names {
        let Some(column) = table.resolve(name) else {
            continue;
        };
        let mapped = table.mapping().iter().any(|m| m.canonical == name);
        let message = if mapped {
            format!(
                "the column map reads its column '{column}' as `{name}`, a column the \
                 compensation adds; leave `{name}` out of the map ('{column}' is then kept as it is \
                 beside the new `{name}`)"
            )
        } else if column == name {
            format!("already has a column `{name}`; rename it first")
        } else {
            format!("already has a column '{column}', read as `{name}`; rename it first")
        };
        return Err(Error::bad_file(table.file_label(), message));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `mag − interference` row by row and the rows not compensated
    /// counted, on a flight long enough to be worked on in parts, with
    /// missing values on either side of the parts' boundary.
    #[test]
    fn compensated_is_mag_minus_interference_with_its_missing_rows() {
        let n = 3 * (1 << 16) + 11;
        let mag: Vec<f64> = (0..n).map(|k| 50_000.0 + (k as f64 * 0.01).sin()).collect();
        let mut interference: Vec<f64> = (0..n).map(|k| (k as f64 * 0.003).cos() * 20.0).collect();
        let holes = [0, (1 << 16) - 1, 1 << 16, n / 2, n - 1];
        for &k in &holes {
            interference[k] = f64::NAN;
        }
        let mut t = FlightTable::new();
        t.add_column("time", (0..n).map(|k| k as f64 * 0.1).collect())
            .unwrap();
        t.add_column("mag", mag.clone()).unwrap();
        let flight = Flight::from_table(t).unwrap();
        let output = OutputColumns {
            interference: "mag_interf",
            flag: "comp_flag",
            why_missing: "test",
            why_beyond: "test",
        };
        // Beyond any field (∞ included) in several parts: the first such
        // row is named, whichever part's thread finds its own first.
        for (rows, first) in [(vec![7], 7), (vec![3 * (1 << 16) + 3, 70_000], 70_000)] {
            let mut bad = interference.clone();
            for &r in &rows {
                bad[r] = if r == 7 { f64::INFINITY } else { -2e6 };
            }
            let e = Compensated::new(&flight, output, bad).unwrap_err();
            assert!(e.is_bad_input(), "{e}");
            assert!(
                e.to_string().contains(&format!("data row {}:", first + 1)),
                "{e}"
            );
        }
        let out = Compensated::new(&flight, output, interference.clone()).unwrap();
        assert_eq!(out.missing, holes.len());
        assert_eq!(out.compensated_nt.len(), n);
        for k in 0..n {
            let want = mag[k] - interference[k];
            let got = out.compensated_nt[k];
            assert!(
                got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan()),
                "row {k}"
            );
        }
    }
}
