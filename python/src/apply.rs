//! What every fitted model does to a flight (any [`Compensator`]: the
//! Tolles-Lawson, rotor and pod models), with the GIL released; the model
//! classes' `interference`, `compensate` and `apply` call these.

use crate::errors::IntoPy;
use crate::flight::PyFlight;
use aeromag::Compensator;
use numpy::PyArray1;
use pyo3::prelude::*;

/// The modelled interference of every row, nT.
pub fn interference<'py>(
    py: Python<'py>,
    model: &(dyn Compensator + Sync),
    flight: &PyFlight,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let v = py.detach(|| model.interference(&flight.inner)).py_err()?;
    Ok(PyArray1::from_vec(py, v))
}

/// `mag` minus the modelled interference, nT.
pub fn compensate<'py>(
    py: Python<'py>,
    model: &(dyn Compensator + Sync),
    flight: &PyFlight,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let c = py.detach(|| model.compensated(&flight.inner)).py_err()?;
    Ok(PyArray1::from_vec(py, c))
}

/// The flight with the model's output columns added.
pub fn apply(
    py: Python<'_>,
    model: &(dyn Compensator + Sync),
    flight: &PyFlight,
) -> PyResult<PyFlight> {
    let f = py
        .detach(|| {
            model
                .compensate(&flight.inner)
                .and_then(|c| c.into_flight(flight.inner.clone()))
        })
        .py_err()?;
    Ok(PyFlight::new(f))
}
