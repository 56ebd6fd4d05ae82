//! Levelling at crossovers (`aeromag level`) and the figures of a
//! compensated flight (`aeromag report`'s FOM, IR, residuals).

use crate::errors::{IntoPy, bad_argument};
use crate::flight::{FlightArg, PyFlight};
use crate::progress::PyProgress;
use aeromag::level::{LevelFitChoices, LevelOptions, Levelled, level as lib_level};
use aeromag::score::score as lib_score;
use aeromag::{Flight, LeverArm, ReferenceChannels};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// `"none"`, `"auto"`, a column or a list of columns.
pub fn reference_channels(
    v: Option<&Bound<'_, PyAny>>,
    default: ReferenceChannels,
) -> PyResult<ReferenceChannels> {
    let Some(v) = v.filter(|v| !v.is_none()) else {
        return Ok(default);
    };
    let text = if v.is_instance_of::<pyo3::types::PyString>() {
        v.str()?.to_string()
    } else {
        let cols: Vec<String> = v.extract().map_err(|_| {
            bad_argument("reference must be 'auto', 'none', a column or a list of columns")
        })?;
        cols.join(",")
    };
    text.parse::<ReferenceChannels>().py_err()
}

/// Level a survey at its line/tie crossovers with the `k·d|B0|/dt` term
/// (the keywords are `aeromag level`'s flags, `--lambda` → `ridge_lambda`).
#[pyfunction]
#[pyo3(signature = (flight, value=None, lever_arm=None, rate_of=None, tie_only=false, drift=false,
    no_altitude_term=false, no_robust=false, ridge_lambda=None, reference=None, ties=None, xy=None,
    utm_zone=None, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn level(
    py: Python<'_>,
    flight: FlightArg<'_>,
    value: Option<String>,
    lever_arm: Option<[f64; 3]>,
    rate_of: Option<String>,
    tie_only: bool,
    drift: bool,
    no_altitude_term: bool,
    no_robust: bool,
    ridge_lambda: Option<f64>,
    reference: Option<Bound<'_, PyAny>>,
    ties: Option<Vec<String>>,
    xy: Option<(String, String)>,
    utm_zone: Option<&str>,
    progress: Option<Py<PyAny>>,
) -> PyResult<PyLevelled> {
    let fit = LevelFitChoices {
        tie_only,
        drift,
        no_altitude_term,
        no_robust,
        ridge_lambda: ridge_lambda.unwrap_or(LevelFitChoices::default().ridge_lambda),
    };
    let opts = LevelOptions {
        value,
        rate_of,
        lever_arm_m: lever_arm,
        projected: crate::map::projected(xy),
        zone: crate::map::zone(utm_zone)?,
        reference: reference_channels(reference.as_ref(), ReferenceChannels::None)?,
        fit: fit.config(),
        ties: ties.unwrap_or_default(),
        ..LevelOptions::default()
    };
    let mut obs = PyProgress::new(progress);
    let result = py.detach(|| lib_level(&flight.inner, &opts, &mut obs));
    obs.finish()?;
    Ok(PyLevelled {
        levelled: result.py_err()?,
        flight: flight.inner.clone(),
    })
}

/// A levelled survey: the levelled column, flags, `k`, line levels, the
/// crossover table.
#[pyclass(name = "Levelled", module = "aeromag._aeromag", frozen)]
pub struct PyLevelled {
    levelled: Levelled,
    flight: Flight,
}

#[pymethods]
impl PyLevelled {
    /// The column levelled (`mag_comp` when present, else `mag`).
    #[getter]
    fn value_column(&self) -> String {
        self.levelled.value_column.clone()
    }

    /// The name of the levelled column, `<value>_level`.
    #[getter]
    fn output_column(&self) -> String {
        self.levelled.output_column()
    }

    /// The levelled series, nT (NaN where not levelled).
    #[getter]
    fn levelled<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.levelled.levelling.levelled.value_nt)
    }

    /// Per-row flags: 0 levelled, 1 on a line without crossovers, 2 not on
    /// a line, 3 a missing value.
    #[getter]
    fn flags<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.levelled.flags())
    }

    /// The `d|B0|/dt` coefficient k and its standard deviation, s.
    #[getter]
    fn k_s(&self) -> (f64, f64) {
        let f = &self.levelled.levelling.fit;
        (f.k_s, f.k_std_s)
    }

    /// Crossover differences RMS: before, model residual, levelled series (nT).
    #[getter]
    fn rms_nt<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let f = &self.levelled.levelling.fit;
        let d = PyDict::new(py);
        d.set_item("before", f.rms_before_nt)?;
        d.set_item("after", f.rms_after_nt)?;
        d.set_item("levelled", f.rms_levelled_nt)?;
        Ok(d)
    }

    /// Per line: (label, crossovers, offset nT, offset std nT, drift nT,
    /// drift std nT).
    #[getter]
    fn line_levels(&self) -> Vec<(String, usize, f64, f64, f64, f64)> {
        self.levelled
            .levelling
            .fit
            .lines
            .iter()
            .map(|l| {
                let label = self
                    .levelled
                    .lines
                    .label(l.label)
                    .map_or(l.label.to_string(), String::from);
                (
                    label,
                    l.crossovers,
                    l.offset_nt,
                    l.offset_std_nt,
                    l.drift_nt,
                    l.drift_std_nt,
                )
            })
            .collect()
    }

    /// The crossover table (as `aeromag level --crossovers` writes it).
    fn crossovers(&self) -> PyResult<PyFlight> {
        let t = self.levelled.crossover_table().py_err()?;
        Ok(PyFlight::new(Flight::from_table(t).py_err()?))
    }

    /// The flight with the levelled column and `level_flag` added (as
    /// `aeromag level --out` writes it).
    fn to_flight(&self) -> PyResult<PyFlight> {
        let mut t = self.flight.table().clone();
        self.levelled.add_to(&mut t).py_err()?;
        Ok(PyFlight::new(Flight::from_table(t).py_err()?))
    }

    /// Notes and warnings.
    #[getter]
    fn notes(&self) -> Vec<String> {
        self.levelled.notes.iter().map(|n| n.to_string()).collect()
    }

    /// Pickling (and `copy.deepcopy`): the result and its flight
    /// ([`levelled_from_state`]).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<crate::pickle::Reduced<'py>> {
        let state = crate::pickle::to_cbor(py, "levelled survey", &self.levelled)?;
        let flight = Py::new(py, PyFlight::new(self.flight.clone()))?;
        let args = (state, flight).into_pyobject(py)?;
        Ok((
            crate::pickle::constructor(py, "_levelled_from_state")?,
            args,
        ))
    }

    fn __repr__(&self) -> String {
        let l = &self.levelled;
        let f = &l.levelling.fit;
        format!(
            "<aeromag.Levelled {} → {}: {} lines, {} crossovers, RMS {:.4} → {:.4} nT, k {:.4} s>",
            l.value_column,
            l.output_column(),
            f.lines.len(),
            l.levelling.crossovers.crossovers.len(),
            f.rms_before_nt,
            f.rms_levelled_nt,
            f.k_s
        )
    }
}

/// Rebuild a pickled levelled survey (the constructor of
/// `Levelled.__reduce__`): the result's state and its flight. Bad input
/// when the state is not a levelled survey's or its series do not have
/// one value per row of the flight.
#[pyfunction]
#[pyo3(name = "_levelled_from_state")]
pub fn levelled_from_state(state: &[u8], flight: PyRef<'_, PyFlight>) -> PyResult<PyLevelled> {
    let what = "levelled survey";
    let levelled: Levelled = crate::pickle::from_cbor(what, state)?;
    let flight = flight.inner.clone();
    let l = &levelled.levelling;
    for (series, len) in [
        ("levelled series", l.levelled.value_nt.len()),
        ("flags", l.levelled.flag.len()),
        ("derivative", l.derivative_nt_per_s.len()),
        ("line ids", levelled.lines.ids.len()),
    ] {
        crate::pickle::check_rows(what, series, len, &flight)?;
    }
    Ok(PyLevelled { levelled, flight })
}

/// The figures of a compensated flight (needs `mag_comp`, as written by
/// compensation): FOM before and after over the detected manoeuvres, the
/// improvement ratio, and for simulated flights the residuals against the
/// truth. A dict, as `aeromag report` writes figures.json.
#[pyfunction]
#[pyo3(signature = (flight, reference=None, lever_arm=None, decimal_year=None))]
pub fn score(
    py: Python<'_>,
    flight: FlightArg<'_>,
    reference: Option<Bound<'_, PyAny>>,
    lever_arm: Option<[f64; 3]>,
    decimal_year: Option<f64>,
) -> PyResult<String> {
    let reference = reference_channels(reference.as_ref(), ReferenceChannels::Auto)?
        .resolve(&flight.inner)
        .py_err()?;
    let lever = lever_arm.map(|arm_m| LeverArm {
        arm_m,
        decimal_year: decimal_year.unwrap_or(aeromag::tolles_lawson::DEFAULT_DECIMAL_YEAR),
    });
    let fig = py
        .detach(|| lib_score(&flight.inner, &reference, lever.as_ref()))
        .py_err()?;
    serde_json::to_string(&fig).map_err(|e| bad_argument(e.to_string()))
}
