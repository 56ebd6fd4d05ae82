//! What every fitted model does to a flight (any [`Compensator`]: the
//! Tolles-Lawson, rotor and pod models), with the GIL released; the model
//! classes' `interference`, `compensate` and `apply` call these. The
//! warnings the CLI prints when it applies a model (a sample rate other
//! than the model's, dropouts bridged) are raised as Python warnings of
//! the category `aeromag.AeromagWarning`.

use crate::errors::IntoPy;
use crate::errors::warn;
use crate::flight::PyFlight;
use crate::progress::PyProgress;
use aeromag::Compensator;
use numpy::PyArray1;
use pyo3::prelude::*;

/// The modelled interference of every row, nT.
pub fn interference<'py>(
    py: Python<'py>,
    model: &(dyn Compensator + Sync),
    flight: &PyFlight,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let mut notes = PyProgress::new(None);
    let v = py.detach(|| model.interference_checked(&flight.inner, &mut notes));
    warn(py, &notes.notes)?;
    Ok(PyArray1::from_vec(py, v.py_err()?))
}

/// `mag` minus the modelled interference, nT.
pub fn compensate<'py>(
    py: Python<'py>,
    model: &(dyn Compensator + Sync),
    flight: &PyFlight,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let mut notes = PyProgress::new(None);
    let c = py.detach(|| model.compensated_observed(&flight.inner, &mut notes));
    warn(py, &notes.notes)?;
    Ok(PyArray1::from_vec(py, c.py_err()?))
}

/// The flight with the model's output columns added.
pub fn apply(
    py: Python<'_>,
    model: &(dyn Compensator + Sync),
    flight: &PyFlight,
) -> PyResult<PyFlight> {
    let mut notes = PyProgress::new(None);
    let f = py.detach(|| {
        model
            .compensate_observed(&flight.inner, &mut notes)
            .and_then(|c| c.into_flight(flight.inner.clone()))
    });
    warn(py, &notes.notes)?;
    Ok(PyFlight::new(f.py_err()?))
}
