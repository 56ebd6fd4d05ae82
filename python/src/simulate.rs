//! The physical simulator (`aeromag simulate`): flights with truth.

use crate::errors::{IntoPy, bad_argument, whole_opt};
use crate::flight::PyFlight;
use aeromag::sim::ScenarioKind;
use aeromag::simulate::{simulate_flight, simulate_flight_file};
use pyo3::prelude::*;

/// Simulate a scenario (`calibration`, `calibration_truncated`, `survey`,
/// `helicopter`, `pod`) with a seed and a scenario configuration (TOML
/// text, or the path of a scenario file: its errors name it and their
/// line); the flight carries the `true_…` columns.
#[pyfunction]
#[pyo3(signature = (scenario, seed=None, config=None, config_path=None))]
pub fn simulate(
    py: Python<'_>,
    scenario: &str,
    seed: Option<Bound<'_, PyAny>>,
    config: Option<String>,
    config_path: Option<std::path::PathBuf>,
) -> PyResult<PyFlight> {
    let seed: Option<u64> = whole_opt("seed", seed.as_ref())?;
    let wanted = scenario.replace('-', "_");
    let kind = ScenarioKind::ALL
        .into_iter()
        .find(|k| k.name() == wanted)
        .ok_or_else(|| {
            let names: Vec<&str> = ScenarioKind::ALL.iter().map(|k| k.name()).collect();
            bad_argument(format!(
                "unknown scenario '{scenario}' (scenarios: {})",
                names.join(", ")
            ))
        })?;
    let flight = py
        .detach(|| match &config_path {
            Some(path) => simulate_flight_file(kind, Some(path), seed),
            None => simulate_flight(kind, config.as_deref(), seed),
        })
        .py_err()?;
    Ok(PyFlight::new(flight))
}
