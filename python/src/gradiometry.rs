//! Dipole estimation from gradiometer passes (`aeromag dipole locate`,
//! `aeromag dipole crlb`, `aeromag simulate gradiometer`).

use crate::errors::{IntoPy, warn, whole_opt};
use crate::flight::{FlightArg, PyFlight};
use aeromag::gradiometry::{
    LocateSettings, crlb, locate_pass, parse_name, read_config, read_pass, simulate_pass,
};
use aeromag::{Flight, Note};
use pyo3::prelude::*;
use std::path::PathBuf;

/// Locate a magnetic dipole along a gradiometer pass (the keywords are
/// `aeromag dipole locate`'s flags; `config` a scenario file, which also
/// describes the system). Returns the track as a Flight: per epoch the
/// estimated position (m, body frame), moment (A·m²), their standard
/// deviations, detection and convergence flags, as `--out` writes it.
/// The command's warnings (time gaps in the pass, innovations that say the
/// filter's σ do not describe its errors) are raised as
/// `aeromag.AeromagWarning`.
#[pyfunction]
#[pyo3(signature = (flight, config=None, gradiometer=None, layout=None, baseline_m=None,
    noise_nt=None, passes=None, multistart=None))]
#[allow(clippy::too_many_arguments)]
pub fn locate_dipole(
    py: Python<'_>,
    flight: FlightArg<'_>,
    config: Option<PathBuf>,
    gradiometer: Option<&str>,
    layout: Option<&str>,
    baseline_m: Option<f64>,
    noise_nt: Option<f64>,
    passes: Option<Bound<'_, PyAny>>,
    multistart: Option<bool>,
) -> PyResult<PyFlight> {
    let passes: Option<usize> = whole_opt("passes", passes.as_ref())?;
    let mut cfg = read_config(config.as_deref()).py_err()?;
    LocateSettings {
        gradiometer: gradiometer
            .map(|g| parse_name("gradiometer", g, "tensor or scalar"))
            .transpose()
            .py_err()?,
        layout: layout
            .map(|l| parse_name("layout", l, "tetrahedron, cross or planar"))
            .transpose()
            .py_err()?,
        baseline_m,
        noise_nt,
        passes,
        multistart,
    }
    .apply(&mut cfg)
    .py_err()?;
    let mut notes = Vec::new();
    let table = py.detach(|| -> aeromag::Result<_> {
        let pass = read_pass(&flight.inner, &cfg)?;
        notes.extend(pass.notes);
        let track = locate_pass(&cfg, &pass.epochs, &pass.positions_m)?;
        notes.extend(track.inconsistency_warning().map(Note::warning));
        let time: Vec<f64> = pass.epochs.iter().map(|e| e.t_s).collect();
        track.to_table(&time)
    });
    warn(py, &notes)?;
    Ok(PyFlight::new(Flight::from_table(table.py_err()?).py_err()?))
}

/// The Cramér–Rao bound of a configured pass (`aeromag dipole crlb
/// --json`), as JSON text.
#[pyfunction]
#[pyo3(signature = (config=None))]
pub fn dipole_crlb(py: Python<'_>, config: Option<PathBuf>) -> PyResult<String> {
    let cfg = read_config(config.as_deref()).py_err()?;
    let report = py.detach(|| crlb(&cfg)).py_err()?;
    Ok(report.to_json().to_string())
}

/// A simulated gradiometer pass with truth (`aeromag simulate
/// gradiometer`), from a scenario file and a seed.
#[pyfunction]
#[pyo3(signature = (config=None, seed=None))]
pub fn simulate_gradiometer(
    py: Python<'_>,
    config: Option<PathBuf>,
    seed: Option<Bound<'_, PyAny>>,
) -> PyResult<PyFlight> {
    let seed: Option<u64> = whole_opt("seed", seed.as_ref())?;
    let mut cfg = read_config(config.as_deref()).py_err()?;
    if let Some(s) = seed {
        cfg.seed = s;
    }
    let table = py.detach(|| simulate_pass(&cfg)).py_err()?;
    Ok(PyFlight::new(Flight::from_table(table).py_err()?))
}
