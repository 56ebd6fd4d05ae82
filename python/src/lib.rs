//! The Rust extension of the `aeromag` Python package (`aeromag._aeromag`).
//!
//! Thin bindings over the `aeromag` library: every function calls one
//! library entry point, as the CLI does, so Python and CLI give the same
//! numbers from the same code. The Pythonic layer (estimator classes,
//! pandas, progress bars) is in `python/aeromag/*.py`.
//!
//! | module | what |
//! |---|---|
//! | [`flight`] | `Flight`, `read_flight` |
//! | [`tolles_lawson`] | `calibrate`, `TlModel`, `load_model`, `observability` |
//! | [`level`] | `level`, `Levelled`, `score` |
//! | [`map`] | `grid_flight`, `Grid`, `read_grid`, `microlevel`, `Microlevelled` |
//! | [`rotor_pod`] | `fit_rotor`, `fit_pod`, `Model` |
//! | [`gradiometry`] | `locate_dipole`, `dipole_crlb`, `simulate_gradiometer` |
//! | [`em`] | `simulate_em`, `detect_em`, `calibrate_em`, `locate_em` |
//! | [`fields`] | `igrf` |
//! | [`simulate`] | `simulate` |
//! | [`apply`] | what every model does to a flight (interference, compensate, apply) |
//! | [`errors`] | library errors → `BadInputError`, `AeromagError`, `OSError` |
//! | [`progress`] | progress callbacks from the library's observer |
//! | [`pickle`] | pickling of the models, grids, flights and results: their `__reduce__` constructors |

mod apply;
mod em;
mod errors;
mod fields;
mod flight;
mod gradiometry;
mod level;
mod map;
mod online;
mod pickle;
mod progress;
mod rotor_pod;
mod sensors;
mod simulate;
mod tolles_lawson;

use pyo3::prelude::*;

#[pymodule]
fn _aeromag(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<flight::PyFlight>()?;
    m.add_function(wrap_pyfunction!(flight::read_flight, m)?)?;
    m.add_function(wrap_pyfunction!(flight::flight_from_state, m)?)?;
    m.add_class::<tolles_lawson::PyTlModel>()?;
    m.add_class::<online::PyOnline>()?;
    m.add_function(wrap_pyfunction!(tolles_lawson::calibrate, m)?)?;
    m.add_function(wrap_pyfunction!(tolles_lawson::check_calibrate_options, m)?)?;
    m.add_function(wrap_pyfunction!(tolles_lawson::calibrate_defaults, m)?)?;
    m.add_function(wrap_pyfunction!(tolles_lawson::load_model, m)?)?;
    m.add_function(wrap_pyfunction!(pickle::model_from_json, m)?)?;
    m.add_function(wrap_pyfunction!(tolles_lawson::observability, m)?)?;
    m.add_class::<sensors::PySensorsModel>()?;
    m.add_function(wrap_pyfunction!(sensors::calibrate_sensors, m)?)?;
    m.add_class::<rotor_pod::PyModel>()?;
    m.add_function(wrap_pyfunction!(rotor_pod::fit_rotor, m)?)?;
    m.add_function(wrap_pyfunction!(rotor_pod::fit_pod, m)?)?;
    m.add_function(wrap_pyfunction!(gradiometry::locate_dipole, m)?)?;
    m.add_function(wrap_pyfunction!(gradiometry::dipole_crlb, m)?)?;
    m.add_function(wrap_pyfunction!(gradiometry::simulate_gradiometer, m)?)?;
    m.add_class::<level::PyLevelled>()?;
    m.add_function(wrap_pyfunction!(level::level, m)?)?;
    m.add_function(wrap_pyfunction!(level::levelled_from_state, m)?)?;
    m.add_function(wrap_pyfunction!(level::score, m)?)?;
    m.add_class::<map::PyGrid>()?;
    m.add_class::<map::PyMicrolevelled>()?;
    m.add_function(wrap_pyfunction!(map::grid_flight, m)?)?;
    m.add_function(wrap_pyfunction!(map::read_grid, m)?)?;
    m.add_function(wrap_pyfunction!(map::grid_from_state, m)?)?;
    m.add_function(wrap_pyfunction!(map::microlevel, m)?)?;
    m.add_function(wrap_pyfunction!(map::microlevelled_from_state, m)?)?;
    m.add_function(wrap_pyfunction!(fields::igrf, m)?)?;
    m.add_function(wrap_pyfunction!(fields::decimal_year, m)?)?;
    m.add_function(wrap_pyfunction!(simulate::simulate, m)?)?;
    m.add_class::<em::PyEmDetection>()?;
    m.add_class::<em::PyEmCalibration>()?;
    m.add_class::<em::PyEmPoses>()?;
    m.add_function(wrap_pyfunction!(em::simulate_em, m)?)?;
    m.add_function(wrap_pyfunction!(em::detect_em, m)?)?;
    m.add_function(wrap_pyfunction!(em::calibrate_em, m)?)?;
    m.add_function(wrap_pyfunction!(em::em_calibration_from_json, m)?)?;
    m.add_function(wrap_pyfunction!(em::locate_em, m)?)?;
    m.add_function(wrap_pyfunction!(em::em_detection_from_state, m)?)?;
    m.add_function(wrap_pyfunction!(em::em_poses_from_state, m)?)?;
    Ok(())
}
