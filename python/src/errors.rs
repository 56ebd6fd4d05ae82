//! aeromag errors as Python exceptions (classes in `aeromag/errors.py`):
//! bad input → `BadInputError` (a `ValueError`) with `file`, `line`, `row`
//! and `column`, a missing input file → `MissingFileError` (also a
//! `FileNotFoundError`); a failed write → the `OSError` of its `errno`
//! with `filename`; anything else (a fit that
//! failed on valid input) → `AeromagError`; a cancelled call →
//! `KeyboardInterrupt` (the library stops only when asked to, and the
//! Python layer asks only on Ctrl-C).

use pyo3::exceptions::PyKeyboardInterrupt;
use pyo3::prelude::*;

/// The Python exception of a library error.
pub fn to_py(e: aeromag::Error) -> PyErr {
    Python::attach(|py| match exception(py, &e) {
        Ok(err) => err,
        Err(err) => err,
    })
}

fn exception(py: Python<'_>, e: &aeromag::Error) -> PyResult<PyErr> {
    // The row selection's messages name the CLI's options; here they are
    // keyword arguments ("--lines: no row has the line label …").
    let message = e
        .to_string()
        .replace("--lines: ", "lines: ")
        .replace("--time-range: ", "time_range: ");
    if e.is_cancelled() {
        return Ok(PyKeyboardInterrupt::new_err(message));
    }
    let errors = py.import("aeromag.errors")?;
    let at = e.location();
    let os = e.os_error();
    if e.is_write_failure() {
        let errno = os.and_then(std::io::Error::raw_os_error);
        let exc = errors
            .getattr("_os_error")?
            .call1((message, errno, at.file))?;
        return Ok(PyErr::from_value(exc));
    }
    let class = if os.is_some_and(|o| o.kind() == std::io::ErrorKind::NotFound) {
        "MissingFileError"
    } else if e.is_bad_input() {
        "BadInputError"
    } else {
        "AeromagError"
    };
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

/// A whole-number argument `name` as `T`: a negative or too large one is
/// bad input naming it, a non-integer a TypeError naming it (PyO3's
/// `OverflowError: can't convert negative int to unsigned` named none).
pub fn whole<T: TryFrom<u128>>(name: &str, v: &Bound<'_, PyAny>) -> PyResult<T> {
    let i: i128 = v.extract().map_err(|_| {
        pyo3::exceptions::PyTypeError::new_err(format!(
            "{name} must be a whole number, got {}",
            repr_of(v)
        ))
    })?;
    if i < 0 {
        return Err(bad_argument(format!(
            "{name} must not be negative, got {i}"
        )));
    }
    u128::try_from(i)
        .ok()
        .and_then(|u| T::try_from(u).ok())
        .ok_or_else(|| bad_argument(format!("{name}: {i} is too large")))
}

/// `repr(v)` for a message (`?` when it has none).
pub fn repr_of(v: &Bound<'_, PyAny>) -> String {
    v.repr().map_or_else(|_| "?".to_string(), |r| r.to_string())
}

/// [`whole`] of an optional argument.
pub fn whole_opt<T: TryFrom<u128>>(
    name: &str,
    v: Option<&Bound<'_, PyAny>>,
) -> PyResult<Option<T>> {
    v.filter(|v| !v.is_none())
        .map(|v| whole(name, v))
        .transpose()
}

/// A bad-input error about an argument (a keyword option).
pub fn bad_argument(reason: impl Into<String>) -> PyErr {
    to_py(aeromag::Error::bad_input(reason))
}

/// Raises each warning of `notes` (not the plain notes) with
/// `warnings.warn(message, aeromag.AeromagWarning)`, pointing at the
/// caller's line: for calls whose result has no `notes` of its own (a
/// model applied to a flight, a located dipole's track).
pub fn warn(py: Python<'_>, notes: &[aeromag::Note]) -> PyResult<()> {
    if !notes.iter().any(aeromag::Note::is_warning) {
        return Ok(());
    }
    let warnings = py.import("warnings")?;
    let category = py.import("aeromag.errors")?.getattr("AeromagWarning")?;
    for n in notes.iter().filter(|n| n.is_warning()) {
        warnings.call_method1("warn", (n.message.as_str(), &category, 1))?;
    }
    Ok(())
}
