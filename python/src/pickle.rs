//! Pickling of the models, grids, flights and EM calibrations (and so
//! `copy.deepcopy`, and results returned from `multiprocessing` or
//! `concurrent.futures` workers): each class's `__reduce__` returns a
//! module-level constructor of `aeromag._aeromag` with the object's state,
//! which that constructor checks as it would check a file (a corrupt
//! payload is a `BadInputError`, never a panic). The models' constructor
//! and helpers are here; the grid's, flight's and EM calibration's are
//! beside their classes.
//!
//! The state is lossless. A model travels as its model file's text: every
//! float is written in its shortest exact form and read back to the same
//! bits (the workspace turns on serde_json's `float_roundtrip`); the model
//! files' NaN standard deviations and infinite condition numbers are
//! written `null` and read back as such. Its notes travel as JSON (text
//! only), and float arrays (the Kalman series, a grid's nodes, a flight's
//! numeric columns) as their bytes, so NaN and every other value keep their
//! bits. A flight travels as its table's snapshot (JSON: names, text
//! columns, mapping, source file, file lines; `aeromag::io::TableSnapshot`)
//! beside its numbers, and is checked again as a flight when rebuilt. An EM
//! calibration travels as its calibration file's text and its fit's
//! figures. The other results (a levelled or micro-levelled survey, an EM
//! detection or its poses) travel as their library value in CBOR
//! ([`to_cbor`], [`from_cbor`]: every float read back as written, NaN as
//! NaN), with the flight they belong to, and are checked against it when
//! rebuilt.

use crate::errors::{IntoPy, bad_argument};
use crate::rotor_pod::{AnyModel, PyModel};
use crate::sensors::PySensorsModel;
use crate::tolles_lawson::PyTlModel;
use aeromag::compensation::model_file::TL_SENSORS_KIND;
use aeromag::pod::{POD_KIND, PodModelFile};
use aeromag::rotor::{ROTOR_KIND, RotorModelFile};
use aeromag::{ModelFile, Note, SensorsModel, TlModel};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyTuple};

/// What `__reduce__` returns: the constructor and its arguments.
pub type Reduced<'py> = (Bound<'py, PyAny>, Bound<'py, PyTuple>);

/// The constructor `name` of `aeromag._aeromag`, looked up in the module
/// (pickle stores a function by its module and name, and checks that this
/// finds the very object it was given).
pub fn constructor<'py>(py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
    py.import("aeromag._aeromag")?.getattr(name)
}

/// Float values as their bytes (native order: a pickle goes between
/// processes of one machine, or of machines of one byte order).
pub fn f64_bytes<'py>(py: Python<'py>, values: &[f64]) -> PyResult<Bound<'py, PyBytes>> {
    PyBytes::new_with(py, std::mem::size_of_val(values), |bytes| {
        for (b, v) in bytes.chunks_exact_mut(8).zip(values) {
            b.copy_from_slice(&v.to_ne_bytes());
        }
        Ok(())
    })
}

/// The floats of [`f64_bytes`]; bad input naming `what` when the length is
/// not a whole number of floats.
pub fn f64s_from_bytes(what: &str, bytes: &[u8]) -> PyResult<Vec<f64>> {
    let chunks = bytes.chunks_exact(8);
    if !chunks.remainder().is_empty() {
        return Err(bad_argument(format!(
            "{what}: {} bytes are not a whole number of 8-byte floats",
            bytes.len()
        )));
    }
    Ok(chunks
        .map(|c| f64::from_ne_bytes(c.try_into().unwrap_or_default()))
        .collect())
}

/// `__reduce__` of a model: [`model_from_json`] with the model file's text
/// `text`, the fit's `notes` and, for a Kalman fit with `series=True`, the
/// five series.
pub fn reduce_model<'py>(
    py: Python<'py>,
    text: String,
    notes: &[Note],
    series: Option<&[Vec<f64>; 5]>,
) -> PyResult<Reduced<'py>> {
    let notes = serde_json::to_string(notes).map_err(|e| bad_argument(e.to_string()))?;
    let series = series.map(|s| f64_bytes(py, &s.concat())).transpose()?;
    let args = (text, notes, series).into_pyobject(py)?;
    Ok((constructor(py, "_model_from_json")?, args))
}

/// Where a pickled model's errors say it came from.
const PICKLED: &str = "pickled model";

/// The model of a model file's text, of the class its `kind` tells
/// (`TlModel`, `SensorsModel` or `Model`), with `notes` and `series` (the
/// Kalman series of a `TlModel`); `origin` names the text in errors.
/// Text that is not JSON or names no known kind is read as a
/// Tolles-Lawson model, whose error then says what is wrong.
pub fn model_of_text(
    py: Python<'_>,
    text: &str,
    origin: &str,
    notes: Vec<Note>,
    series: Option<[Vec<f64>; 5]>,
) -> PyResult<Py<PyAny>> {
    let kind = serde_json::from_str::<serde_json::Value>(text)
        .ok()
        .and_then(|v| v.get("kind")?.as_str().map(String::from));
    let kind = kind.as_deref().unwrap_or_default();
    if series.is_some() && [ROTOR_KIND, POD_KIND, TL_SENSORS_KIND].contains(&kind) {
        return Err(bad_argument(format!(
            "{origin}: a `{kind}` model has no Kalman series"
        )));
    }
    let model = match kind {
        ROTOR_KIND => Py::new(
            py,
            PyModel {
                model: AnyModel::Rotor(RotorModelFile::parse(text, origin).py_err()?),
                notes,
            },
        )?
        .into_any(),
        POD_KIND => Py::new(
            py,
            PyModel {
                model: AnyModel::Pod(PodModelFile::parse(text, origin).py_err()?),
                notes,
            },
        )?
        .into_any(),
        TL_SENSORS_KIND => Py::new(
            py,
            PySensorsModel {
                model: SensorsModel::parse(text, origin).py_err()?,
                notes,
            },
        )?
        .into_any(),
        _ => Py::new(
            py,
            PyTlModel {
                model: TlModel::parse(text, origin).py_err()?,
                notes,
                series,
            },
        )?
        .into_any(),
    };
    Ok(model)
}

/// Rebuild a pickled model (the constructor of the models' `__reduce__`):
/// the model file's `text`, the fit's `notes` (JSON) and the Kalman
/// `series` (the bytes of five float arrays of one length, one after the
/// other). Bad input when any of them is not what a model pickles.
#[pyfunction]
#[pyo3(name = "_model_from_json", signature = (text, notes = "[]", series = None))]
pub fn model_from_json(
    py: Python<'_>,
    text: &str,
    notes: &str,
    series: Option<&[u8]>,
) -> PyResult<Py<PyAny>> {
    let notes: Vec<Note> = serde_json::from_str(notes)
        .map_err(|e| bad_argument(format!("{PICKLED}: its notes are not readable ({e})")))?;
    let series = series
        .map(|bytes| {
            let values = f64s_from_bytes(&format!("{PICKLED}: its series"), bytes)?;
            if values.len() % 5 != 0 {
                return Err(bad_argument(format!(
                    "{PICKLED}: its series hold {} values, not five series of one length",
                    values.len()
                )));
            }
            let n = values.len() / 5;
            Ok(std::array::from_fn(|k| values[k * n..(k + 1) * n].to_vec()))
        })
        .transpose()?;
    model_of_text(py, text, PICKLED, notes, series)
}

/// `value` as CBOR bytes, for a result's `__reduce__`; `what` names it in
/// the error (none is expected: the results hold numbers and text).
pub fn to_cbor<'py, T: serde::Serialize>(
    py: Python<'py>,
    what: &str,
    value: &T,
) -> PyResult<Bound<'py, PyBytes>> {
    let mut bytes = Vec::new();
    ciborium::into_writer(value, &mut bytes)
        .map_err(|e| bad_argument(format!("this {what} cannot be pickled: {e}")))?;
    Ok(PyBytes::new(py, &bytes))
}

/// The value of [`to_cbor`]'s bytes; bad input naming the pickled `what`
/// when they are not one.
pub fn from_cbor<T: serde::de::DeserializeOwned>(what: &str, bytes: &[u8]) -> PyResult<T> {
    ciborium::from_reader(bytes)
        .map_err(|e| bad_argument(format!("pickled {what}: its state is not readable ({e})")))
}

/// Bad input unless the pickled `what`'s `series` has one value per row of
/// its `flight`.
pub fn check_rows(what: &str, series: &str, len: usize, flight: &aeromag::Flight) -> PyResult<()> {
    if len != flight.n_rows() {
        return Err(bad_argument(format!(
            "pickled {what}: its {series} has {len} values for a flight of {} rows",
            flight.n_rows()
        )));
    }
    Ok(())
}
