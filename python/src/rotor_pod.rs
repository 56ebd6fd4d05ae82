//! Helicopter rotor and towed-pod models (`aeromag rotor fit|apply`,
//! `aeromag pod fit|apply`): fitted on a flight, they apply themselves to
//! flights like the Tolles-Lawson model.

use crate::errors::{IntoPy, bad_argument, whole_opt};
use crate::flight::{FlightArg, PyFlight};
use crate::progress::PyProgress;
use aeromag::pod::{PodModelFile, PodSetup, apply_pod, fit_pod as lib_fit_pod};
use aeromag::rotor::{
    RotorChoices, RotorModelFile, RotorOptions, RotorPreset, fit_rotor as lib_fit_rotor,
};
use aeromag::{Compensator, ModelFile, Note};
use numpy::PyArray1;
use pyo3::prelude::*;
use std::path::PathBuf;

/// A rotor or a pod model.
// One per Python model object: the variants' sizes do not matter.
#[allow(clippy::large_enum_variant)]
pub enum AnyModel {
    Rotor(RotorModelFile),
    Pod(PodModelFile),
}

impl AnyModel {
    fn compensator(&self) -> &(dyn Compensator + Sync) {
        match self {
            AnyModel::Rotor(m) => m,
            AnyModel::Pod(m) => m,
        }
    }

    fn json(&self) -> aeromag::Result<String> {
        match self {
            AnyModel::Rotor(m) => m.json(),
            AnyModel::Pod(m) => m.json(),
        }
    }

    fn write(&self, path: &std::path::Path) -> aeromag::Result<()> {
        match self {
            AnyModel::Rotor(m) => m.write(path),
            AnyModel::Pod(m) => m.write(path),
        }
    }
}

/// A fitted helicopter-rotor or towed-pod model (the model file of `aeromag
/// rotor fit` / `aeromag pod fit`); it applies itself to flights.
#[pyclass(name = "Model", module = "aeromag._aeromag", frozen)]
pub struct PyModel {
    pub model: AnyModel,
    pub notes: Vec<Note>,
}

#[pymethods]
impl PyModel {
    /// `helicopter-rotor` or `towed-pod`.
    #[getter]
    fn kind(&self) -> &'static str {
        match &self.model {
            AnyModel::Rotor(_) => "helicopter-rotor",
            AnyModel::Pod(_) => "towed-pod",
        }
    }

    /// The fitted parameters (rotor: the blade model's; pod: the method's
    /// coefficients).
    #[getter]
    fn coef<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let v = match &self.model {
            AnyModel::Rotor(m) => m.model.params.clone(),
            AnyModel::Pod(m) => m.coefficients.clone(),
        };
        PyArray1::from_vec(py, v)
    }

    /// Notes and warnings of the fit.
    #[getter]
    fn notes(&self) -> Vec<String> {
        self.notes.iter().map(|n| n.to_string()).collect()
    }

    /// The modelled interference of every row of `flight`, nT (NaN where
    /// it cannot be computed).
    fn interference<'py>(
        &self,
        py: Python<'py>,
        flight: FlightArg<'_>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        crate::apply::interference(py, self.model.compensator(), &flight)
    }

    /// `mag` minus the modelled interference, nT.
    fn compensate<'py>(
        &self,
        py: Python<'py>,
        flight: FlightArg<'_>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        crate::apply::compensate(py, self.model.compensator(), &flight)
    }

    /// The flight with the model's output columns added, as `apply --out`
    /// writes it.
    fn apply(&self, py: Python<'_>, flight: FlightArg<'_>) -> PyResult<PyFlight> {
        crate::apply::apply(py, self.model.compensator(), &flight)
    }

    /// Per heading of a pod flight: (heading °, first row, end row, rate of
    /// interference removed); empty for a rotor model.
    fn heading_rates(&self, flight: FlightArg<'_>) -> PyResult<Vec<(f64, usize, usize, f64)>> {
        let AnyModel::Pod(m) = &self.model else {
            return Ok(Vec::new());
        };
        let a = apply_pod(m, &flight.inner).py_err()?;
        Ok(a.per_heading
            .iter()
            .map(|h| (h.heading_deg, h.rows[0], h.rows[1], h.rate))
            .collect())
    }

    /// The model file's text (JSON), what the CLI writes.
    fn to_json(&self) -> PyResult<String> {
        self.model.json().py_err()
    }

    /// Write the model file (atomically).
    fn save(&self, path: PathBuf) -> PyResult<()> {
        self.model.write(&path).py_err()
    }

    /// Pickling (and `copy.deepcopy`): the model file's text and the notes
    /// ([`crate::pickle`]).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<crate::pickle::Reduced<'py>> {
        crate::pickle::reduce_model(py, self.model.json().py_err()?, &self.notes, None)
    }

    fn __repr__(&self) -> String {
        format!("<aeromag.Model {}>", self.kind())
    }
}

/// Fit the helicopter main-rotor model (`aeromag rotor fit`; the keywords
/// are its flags).
#[pyfunction]
#[pyo3(signature = (flight, preset=None, hub_m=None, sensor_m=None, blade_span_m=None, blades=None,
    coning_deg=None, tilt_lon_deg=None, phase_column=None, estimate_phase=false, rotor_hz=None,
    window_s=None, tail_rotor=false, tail_hub_m=None, tail_spin_axis=None, tail_zero_azimuth=None,
    tail_blade_span_m=None, tail_blades=None, gear_ratio=None, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn fit_rotor(
    py: Python<'_>,
    flight: FlightArg<'_>,
    preset: Option<&str>,
    hub_m: Option<[f64; 3]>,
    sensor_m: Option<[f64; 3]>,
    blade_span_m: Option<[f64; 2]>,
    blades: Option<Bound<'_, PyAny>>,
    coning_deg: Option<f64>,
    tilt_lon_deg: Option<f64>,
    phase_column: Option<String>,
    estimate_phase: bool,
    rotor_hz: Option<[f64; 2]>,
    window_s: Option<f64>,
    tail_rotor: bool,
    tail_hub_m: Option<[f64; 3]>,
    tail_spin_axis: Option<[f64; 3]>,
    tail_zero_azimuth: Option<[f64; 3]>,
    tail_blade_span_m: Option<[f64; 2]>,
    tail_blades: Option<Bound<'_, PyAny>>,
    gear_ratio: Option<f64>,
    progress: Option<Py<PyAny>>,
) -> PyResult<PyModel> {
    let preset = preset
        .map(|p| {
            RotorPreset::ALL
                .into_iter()
                .find(|k| k.name() == p)
                .ok_or_else(|| {
                    let names: Vec<&str> = RotorPreset::ALL.iter().map(|k| k.name()).collect();
                    bad_argument(format!(
                        "unknown rotor preset '{p}' (presets: {})",
                        names.join(", ")
                    ))
                })
        })
        .transpose()?;
    let opts = RotorOptions::from_choices(&RotorChoices {
        preset,
        hub_m,
        sensor_m,
        blade_span_m,
        blades: whole_opt("blades", blades.as_ref())?,
        coning_deg,
        tilt_lon_deg,
        phase_column,
        estimate_phase,
        rotor_hz,
        window_s,
        tail_rotor,
        tail_hub_m,
        tail_spin_axis,
        tail_zero_azimuth,
        tail_blade_span_m,
        tail_blades: whole_opt("tail_blades", tail_blades.as_ref())?,
        gear_ratio,
    })
    .py_err()?;
    let mut obs = PyProgress::new(progress);
    let result = py.detach(|| lib_fit_rotor(&flight.inner, &opts, &mut obs));
    obs.finish()?;
    let fit = result.py_err()?;
    Ok(PyModel {
        model: AnyModel::Rotor(fit.model),
        notes: fit.notes,
    })
}

/// Fit the towed-pod model (`aeromag pod fit`; the keywords are its flags;
/// `method` is `dipole-array` (default), `two-step` or `joint`;
/// `source_points` the dipole positions (m) of the dipole-array method;
/// `progress` a callable `progress(stage, done, total)`).
#[pyfunction]
#[pyo3(signature = (flight, cable_length_m, inclination_deg, attach_m=None, declination_deg=0.0,
    grad_north_nt_per_km=0.0, grad_up_nt_per_km=0.0, method="dipole-array", source_points=None,
    progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn fit_pod(
    py: Python<'_>,
    flight: FlightArg<'_>,
    cable_length_m: f64,
    inclination_deg: f64,
    attach_m: Option<[f64; 3]>,
    declination_deg: f64,
    grad_north_nt_per_km: f64,
    grad_up_nt_per_km: f64,
    method: &str,
    source_points: Option<Vec<[f64; 3]>>,
    progress: Option<Py<PyAny>>,
) -> PyResult<PyModel> {
    let method = aeromag::pod::PodMethod::ALL
        .into_iter()
        .find(|m| m.name() == method)
        .ok_or_else(|| {
            bad_argument(format!(
                "method must be dipole-array, two-step or joint, got '{method}'"
            ))
        })?;
    let setup = PodSetup {
        cable_length_m,
        attach_m: attach_m.unwrap_or_default(),
        inclination_deg,
        declination_deg,
        grad_north_nt_per_km,
        grad_up_nt_per_km,
    };
    let mut obs = PyProgress::new(progress);
    let result = py.detach(|| {
        lib_fit_pod(
            &flight.inner,
            &setup,
            method,
            source_points.as_deref(),
            &mut obs,
        )
    });
    obs.finish()?;
    let fit = result.py_err()?;
    Ok(PyModel {
        model: AnyModel::Pod(fit.model),
        notes: fit.notes,
    })
}
