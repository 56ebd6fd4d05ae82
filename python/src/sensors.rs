//! Several scalar sensors in one run (`aeromag calibrate --mag A,B,…`):
//! [`calibrate_sensors`] fits one Tolles-Lawson model per sensor with the
//! keyword options of `TollesLawson`, optionally in the reference-sensor
//! mode, and returns the multi-sensor model file as `SensorsModel`, which
//! applies itself and scores a compensated flight (`aeromag report`).

use crate::errors::IntoPy;
use crate::flight::{FlightArg, PyFlight};
use crate::progress::PyProgress;
use crate::tolles_lawson::PyTlModel;
use aeromag::{
    CompensateSensors, Flight, ModelFile, Note, ReferenceChannels, SensorColumns, SensorSet,
    SensorsModel,
};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// Fit one model per scalar sensor `mag` (columns, e.g. `mag_1_uc`) with
/// the vector magnetometers `vector` (none, one prefix for all, or one per
/// sensor) and the keyword options `params` of `TollesLawson`; with
/// `reference_sensor`, the other sensors are fitted against that sensor's
/// compensated reading (or an already compensated column). The GIL is
/// released while fitting.
#[pyfunction]
#[pyo3(signature = (flight, mag, params, vector=None, reference_sensor=None, progress=None))]
pub fn calibrate_sensors(
    py: Python<'_>,
    flight: FlightArg<'_>,
    mag: Vec<String>,
    params: &Bound<'_, PyDict>,
    vector: Option<Vec<String>>,
    reference_sensor: Option<String>,
    progress: Option<Py<PyAny>>,
) -> PyResult<PySensorsModel> {
    let opts = crate::tolles_lawson::options(params)?;
    let set = SensorSet {
        sensors: SensorColumns::list(&flight.inner, &mag, &vector.unwrap_or_default()).py_err()?,
        reference: reference_sensor,
    };
    let mut obs = PyProgress::new(progress);
    let result = py.detach(|| aeromag::calibrate_sensors(&flight.inner, &set, &opts, &mut obs));
    obs.finish()?;
    let cal = result.py_err()?;
    Ok(PySensorsModel {
        model: cal.model,
        notes: cal.notes,
    })
}

/// One Tolles-Lawson model per scalar sensor: the model file of
/// `aeromag calibrate --mag A,B,…`; it applies itself to flights.
#[pyclass(name = "SensorsModel", module = "aeromag._aeromag", frozen)]
pub struct PySensorsModel {
    pub(crate) model: SensorsModel,
    pub(crate) notes: Vec<Note>,
}

#[pymethods]
impl PySensorsModel {
    /// The sensors' names (`mag_3`), the stems of their output columns.
    #[getter]
    fn sensors(&self) -> Vec<String> {
        self.model.sensors.iter().map(|s| s.name.clone()).collect()
    }

    /// The sensors' scalar columns (`mag_3_uc`).
    #[getter]
    fn columns(&self) -> Vec<String> {
        self.model.sensors.iter().map(|s| s.mag.clone()).collect()
    }

    /// The reference each sensor was fitted against (None: the
    /// calibration's reference channels).
    #[getter]
    fn reference_sensors(&self) -> Vec<Option<String>> {
        self.model
            .sensors
            .iter()
            .map(|s| s.reference_sensor.clone())
            .collect()
    }

    /// Each sensor's model, in order.
    #[getter]
    fn models(&self) -> Vec<PyTlModel> {
        self.model
            .sensors
            .iter()
            .map(|s| PyTlModel::of(s.model.clone()))
            .collect()
    }

    /// Notes and warnings of the fits ("warning: …", "note: …").
    #[getter]
    fn notes(&self) -> Vec<String> {
        self.notes.iter().map(|n| n.to_string()).collect()
    }

    /// The output columns on `flight`: `<name>_interf` and `<name>_comp`
    /// per sensor, `<name>_grad` (compensated minus the first sensor's)
    /// for the others, nT (NaN where a model cannot be applied).
    fn compensate<'py>(
        &self,
        py: Python<'py>,
        flight: FlightArg<'_>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let out = py
            .detach(|| self.model.compensate(&flight.inner))
            .py_err()?;
        let d = PyDict::new(py);
        for (name, v) in out.columns() {
            d.set_item(name, PyArray1::from_vec(py, v))?;
        }
        Ok(d)
    }

    /// The flight with the output columns added, as `aeromag compensate
    /// --out` writes it.
    fn apply(&self, py: Python<'_>, flight: FlightArg<'_>) -> PyResult<PyFlight> {
        let f = py
            .detach(|| -> aeromag::Result<Flight> {
                let mut table = flight.inner.table().clone();
                self.model.compensate(&flight.inner)?.add_to(&mut table)?;
                Flight::from_table(table)
            })
            .py_err()?;
        Ok(PyFlight::new(f))
    }

    /// The figures of `aeromag report` for a flight with the output columns
    /// (`apply`): per sensor FOM, IR, residual versus truth (simulation),
    /// the term groups' RMS and shares, and the current channels against
    /// what compensation left. `reference`: known external-field channels
    /// removed first (default: those the sensors were fitted with).
    #[pyo3(signature = (flight, reference=None))]
    fn score<'py>(
        &self,
        py: Python<'py>,
        flight: FlightArg<'_>,
        reference: Option<&str>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let reference = match reference {
            Some(r) => r
                .parse::<ReferenceChannels>()
                .and_then(|r| r.resolve(&flight.inner))
                .py_err()?,
            None => self
                .model
                .sensors
                .iter()
                .find(|s| s.reference_sensor.is_none())
                .map(|s| s.model.reference.clone())
                .unwrap_or_default(),
        };
        let fig = py
            .detach(|| aeromag::score::score_sensors(&flight.inner, &self.model, &reference))
            .py_err()?;
        let text = serde_json::to_string(&fig)
            .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))?;
        py.import("json")?.call_method1("loads", (text,))
    }

    /// The model file's text (JSON), byte for byte what the CLI writes.
    fn to_json(&self) -> PyResult<String> {
        self.model.json().py_err()
    }

    /// Write the model file (atomically), as `aeromag calibrate --model`.
    fn save(&self, path: PathBuf) -> PyResult<()> {
        self.model.write(&path).py_err()
    }

    /// Pickling (and `copy.deepcopy`): the model file's text and the notes
    /// ([`crate::pickle`]).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<crate::pickle::Reduced<'py>> {
        crate::pickle::reduce_model(py, self.model.json().py_err()?, &self.notes, None)
    }

    fn __len__(&self) -> usize {
        self.model.sensors.len()
    }

    fn __repr__(&self) -> String {
        format!(
            "<aeromag.SensorsModel {} sensors: {}>",
            self.model.sensors.len(),
            self.sensors().join(", ")
        )
    }
}
