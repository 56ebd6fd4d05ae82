//! aeromag errors as Python exceptions (classes in `aeromag/errors.py`):
//! bad input → `BadInputError` (a `ValueError`) with `file`, `line`, `row`
//! and `column`; a failed write → `OSError`; anything else (a fit that
//! failed on valid input) → `AeromagError`.

use pyo3::exceptions::PyOSError;
use pyo3::prelude::*;

/// The Python exception of a library error.
pub fn to_py(e: aeromag::Error) -> PyErr {
    Python::attach(|py| match exception(py, &e) {
        Ok(err) => err,
        Err(err) => err,
    })
}

fn exception(py: Python<'_>, e: &aeromag::Error) -> PyResult<PyErr> {
    let message = e.to_string();
    if let aeromag::Error::Write { .. } = e {
        return Ok(PyOSError::new_err(message));
    }
    let errors = py.import("aeromag.errors")?;
    let class = if e.is_bad_input() {
        "BadInputError"
    } else {
        "AeromagError"
    };
    let at = e.location();
    let exc = errors
        .getattr(class)?
        .call1((message, at.file, at.line, at.row, at.column))?;
    Ok(PyErr::from_value(exc))
}

/// `Result<T, aeromag::Error>` → `PyResult<T>`.
pub trait IntoPy<T> {
    fn py_err(self) -> PyResult<T>;
}

impl<T, E: Into<aeromag::Error>> IntoPy<T> for Result<T, E> {
    fn py_err(self) -> PyResult<T> {
        self.map_err(|e| to_py(e.into()))
    }
}

/// A bad-input error about an argument (a keyword option).
pub fn bad_argument(reason: impl Into<String>) -> PyErr {
    to_py(aeromag::Error::bad_input(reason))
}
