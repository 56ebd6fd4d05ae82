//! `aeromag.Flight`: a flight record (columns of equal length) read from a
//! file or built from arrays, checked as the CLI checks it.

use crate::errors::{IntoPy, bad_argument};
use aeromag::io::{
    ColumnData, FlightTable, SharedBuffer, TableSnapshot, Values, table_from_columns,
};
use aeromag::{ColumnMap, Flight, ReadOptions, RowSelection, Sensors};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::PyKeyError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::path::PathBuf;
use std::sync::Arc;

/// A flight record: named columns of equal length (numbers, or text such
/// as line labels `L1010`), with the canonical names (`time`, `mag`,
/// `flux_x`, …) mapped onto the file's names.
#[pyclass(name = "Flight", module = "aeromag._aeromag", frozen)]
pub struct PyFlight {
    pub inner: Flight,
}

impl PyFlight {
    pub fn new(inner: Flight) -> Self {
        Self { inner }
    }
}

/// A `flight` argument: an `aeromag.Flight`, else a TypeError that names
/// the argument and what makes a flight. PyO3 names the argument only in a
/// note ("while processing 'flight'"), which `str(e)` leaves out and Python
/// before 3.11 drops: "'str' object is not an instance of 'Flight'" was all
/// it said. Every Python function and method taking a flight calls it
/// `flight`.
pub struct FlightArg<'a>(&'a PyFlight);

impl<'a, 'py> FromPyObject<'a, 'py> for FlightArg<'a> {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        match obj.cast::<PyFlight>() {
            Ok(f) => Ok(FlightArg(f.get())),
            Err(_) => Err(pyo3::exceptions::PyTypeError::new_err(format!(
                "flight must be an aeromag.Flight (read_flight, simulate, Flight.from_dict or \
                 Flight.from_pandas), got {}",
                obj.get_type()
                    .name()
                    .map_or_else(|_| "?".to_string(), |n| n.to_string())
            ))),
        }
    }
}

impl std::ops::Deref for FlightArg<'_> {
    type Target = PyFlight;

    fn deref(&self) -> &PyFlight {
        self.0
    }
}

/// The memory of a one-dimensional contiguous float64 NumPy array, read by
/// a column in place (no copy): the array is kept alive by the reference
/// held here, and the column never writes it (changes copy first). Like
/// every zero-copy library, this assumes Python does not change the array
/// while an aeromag call is reading it.
#[derive(Debug)]
struct NumpyBuffer {
    _array: Py<PyArray1<f64>>,
    ptr: *const f64,
    len: usize,
}

// SAFETY: the buffer only reads memory that the held array keeps alive and
// in place (a NumPy array referenced from elsewhere cannot be resized);
// `Py` itself is Send + Sync.
unsafe impl Send for NumpyBuffer {}
unsafe impl Sync for NumpyBuffer {}

impl SharedBuffer for NumpyBuffer {
    fn values(&self) -> &[f64] {
        // SAFETY: `ptr` and `len` describe the contiguous data of the array
        // held in `_array` (taken from NumPy's own slice of it), valid
        // while it lives.
        unsafe { std::slice::from_raw_parts(self.ptr, self.len) }
    }
}

impl NumpyBuffer {
    /// The array's values as column values without a copy (an empty array
    /// as an empty vector).
    fn share(array: Bound<'_, PyArray1<f64>>) -> PyResult<Values> {
        let (ptr, len) = {
            let view = array.readonly();
            let s = view.as_slice()?;
            (s.as_ptr(), s.len())
        };
        if len == 0 {
            return Ok(Values::Owned(Vec::new()));
        }
        Ok(Values::Shared(Arc::new(NumpyBuffer {
            _array: array.unbind(),
            ptr,
            len,
        })))
    }
}

/// Canonical columns that hold numbers (every one but `line`).
const NUMERIC_CANONICAL: [&str; 16] = [
    "time", "lat", "lon", "alt", "vn", "ve", "vd", "roll", "pitch", "yaw", "mag", "flux_x",
    "flux_y", "flux_z", "diurnal", "igrf",
];

/// One column of `Flight.from_dict`: numbers as float64 (copied unless
/// `copy` is false and the array is contiguous float64; a masked array's
/// masked values NaN; an object array of numbers and `None` as numbers,
/// `None` NaN), text arrays as text (`None` as an empty, missing cell).
fn column_from_py(
    np: &Bound<'_, PyModule>,
    name: &str,
    v: &Bound<'_, PyAny>,
    copy: bool,
) -> PyResult<ColumnData> {
    let one_d = |a: &Bound<'_, PyAny>| -> PyResult<()> {
        if a.getattr("ndim")?.extract::<usize>()? != 1 {
            return Err(bad_argument(format!(
                "column '{name}' must be one-dimensional"
            )));
        }
        Ok(())
    };
    let ma = np.getattr("ma")?;
    let masked = ma.call_method1("isMaskedArray", (v,))?.extract::<bool>()?;
    let mut arr = if masked {
        // Masked values are missing: filled with NaN (numbers) once the
        // array is float64.
        let kind: String = v.getattr("dtype")?.getattr("kind")?.extract()?;
        if !matches!(kind.as_str(), "f" | "i" | "u" | "b") {
            return Err(bad_argument(format!(
                "column '{name}' is a masked array of NumPy dtype kind '{kind}'; give numbers"
            )));
        }
        let f = v.call_method1("astype", ("float64",))?;
        ma.call_method1("filled", (f, f64::NAN))?
    } else {
        np.call_method1("asarray", (v,))?
    };
    let mut kind: String = arr.getattr("dtype")?.getattr("kind")?.extract()?;
    if kind == "O" {
        one_d(&arr)?;
        // Numbers and None only: a number column (pandas gives object
        // arrays for numbers with None).
        let items: Vec<Bound<'_, PyAny>> = arr
            .call_method0("tolist")?
            .try_iter()?
            .collect::<PyResult<_>>()?;
        let numeric = items.iter().all(|x| {
            x.is_none()
                || (!x.is_instance_of::<pyo3::types::PyString>()
                    && !x.is_instance_of::<pyo3::types::PyBytes>()
                    && x.extract::<f64>().is_ok())
        });
        if numeric && !items.is_empty() {
            let values: Vec<f64> = items
                .iter()
                .map(|x| {
                    if x.is_none() {
                        Ok(f64::NAN)
                    } else {
                        x.extract::<f64>()
                    }
                })
                .collect::<PyResult<_>>()?;
            arr = np.call_method1("asarray", (values,))?;
            kind = "f".into();
        }
    }
    Ok(match kind.as_str() {
        "f" | "i" | "u" | "b" => {
            let a = np
                .call_method1("ascontiguousarray", (&arr, "float64"))?
                .cast_into::<PyArray1<f64>>()
                .map_err(|_| bad_argument(format!("column '{name}' must be one-dimensional")))?;
            let values = if copy {
                Values::Owned(a.readonly().as_slice()?.to_vec())
            } else {
                NumpyBuffer::share(a)?
            };
            ColumnData::numeric(values)
        }
        "U" | "S" | "O" => {
            one_d(&arr)?;
            let text: Vec<String> = arr
                .call_method0("tolist")?
                .try_iter()?
                .map(|x| {
                    x.and_then(|x| {
                        if x.is_none() {
                            Ok(String::new())
                        } else {
                            x.str().map(|s| s.to_string())
                        }
                    })
                })
                .collect::<PyResult<_>>()?;
            ColumnData::Text(text)
        }
        other => {
            return Err(bad_argument(format!(
                "column '{name}' has NumPy dtype kind '{other}'; give numbers or text"
            )));
        }
    })
}

/// How to read: the `--columns`, `--mag`, `--vector`, `--lines` and
/// `--time-range` choices of the CLI, parsed by the same library calls.
pub fn read_options(
    columns: Option<&str>,
    mag: Option<String>,
    vector: Option<String>,
    lines: Option<&str>,
    time_range: Option<&str>,
) -> PyResult<ReadOptions> {
    Ok(ReadOptions {
        columns: match columns {
            Some(m) => ColumnMap::parse(m).py_err()?,
            None => ColumnMap::new(),
        },
        sensors: Sensors { mag, vector },
        rows: RowSelection::parse(lines, time_range).py_err()?,
        ..ReadOptions::default()
    })
}

/// A label or a list of labels as the CLI's comma list.
fn comma_list(v: Option<&Bound<'_, PyAny>>) -> PyResult<Option<String>> {
    let Some(v) = v.filter(|v| !v.is_none()) else {
        return Ok(None);
    };
    if v.is_instance_of::<pyo3::types::PyString>() || v.extract::<f64>().is_ok() {
        return Ok(Some(v.str()?.to_string()));
    }
    let parts: Vec<String> = v
        .try_iter()?
        .map(|x| x.and_then(|x| x.str().map(|s| s.to_string())))
        .collect::<PyResult<_>>()?;
    if parts.is_empty() {
        // "--lines: '' has an empty label".
        return Err(bad_argument(
            "lines: an empty list selects no line (None keeps every row)",
        ));
    }
    Ok(Some(parts.join(",")))
}

/// `{"mag": "mag_1_uc"}` or `"mag=mag_1_uc"` as the CLI's `--columns`.
fn column_map(v: Option<&Bound<'_, PyAny>>) -> PyResult<Option<String>> {
    let Some(v) = v.filter(|v| !v.is_none()) else {
        return Ok(None);
    };
    if let Ok(d) = v.cast::<PyDict>() {
        let pairs: Vec<String> = d
            .iter()
            .map(|(k, v)| Ok(format!("{}={}", k.str()?, v.str()?)))
            .collect::<PyResult<_>>()?;
        return Ok(Some(pairs.join(",")));
    }
    Ok(Some(v.str()?.to_string()))
}

/// The library's reading options for Python's arguments.
fn python_read_options(
    columns: Option<&Bound<'_, PyAny>>,
    mag: Option<String>,
    vector: Option<String>,
    lines: Option<&Bound<'_, PyAny>>,
    time_range: Option<(f64, f64)>,
) -> PyResult<ReadOptions> {
    let range = time_range.map(|(a, b)| format!("{a:?},{b:?}"));
    read_options(
        column_map(columns)?.as_deref(),
        mag,
        vector,
        comma_list(lines)?.as_deref(),
        range.as_deref(),
    )
}

/// Read a flight file (CSV, Geosoft XYZ or HDF5) with the Python layer's
/// choices already turned into the CLI's strings.
#[pyfunction]
#[pyo3(signature = (path, columns=None, mag=None, vector=None, lines=None, time_range=None, fields=None))]
#[allow(clippy::too_many_arguments)]
pub fn read_flight(
    py: Python<'_>,
    path: PathBuf,
    columns: Option<Bound<'_, PyAny>>,
    mag: Option<String>,
    vector: Option<String>,
    lines: Option<Bound<'_, PyAny>>,
    time_range: Option<(f64, f64)>,
    fields: Option<Vec<String>>,
) -> PyResult<PyFlight> {
    let mut opts = python_read_options(columns.as_ref(), mag, vector, lines.as_ref(), time_range)?;
    if let Some(names) = &fields {
        opts.fields = aeromag::Fields::Only(names.clone());
    }
    let flight = py.detach(|| Flight::read_with(&path, &opts)).py_err()?;
    // A field asked for that the file lacks (a typo) gave a flight without
    // it and no word.
    // (A pattern, `true_*`, may match nothing.)
    if let Some(missing) = fields.iter().flatten().find(|n| {
        let t = flight.table();
        !n.contains(['*', '?'])
            && t.get(n).is_none()
            && !t.column_names().iter().any(|c| c.eq_ignore_ascii_case(n))
    }) {
        return Err(bad_argument(format!(
            "fields: '{}' has no field '{missing}'; its fields: {}",
            path.display(),
            flight.table().present_columns()
        )));
    }
    Ok(PyFlight::new(flight))
}

#[pymethods]
impl PyFlight {
    /// A flight from arrays named as in the files (`{"tt": …, "mag_1_uc":
    /// …}` or canonical names): numbers as float64 (NaN = missing), text
    /// columns (str arrays or lists) kept as text. The same mapping,
    /// selection and checks as a file.
    ///
    /// The arrays are copied (`copy=True`), so that changing them
    /// afterwards changes nothing in the flight, whose checks (time going
    /// forward, finite values, …) were made on what it holds. With
    /// `copy=False` one-dimensional contiguous float64 arrays are read in
    /// place (no copy, for large flights): the caller must then not change
    /// them while the flight is in use — a changed array is read as it is,
    /// without those checks. aeromag itself never writes them. Object
    /// arrays of numbers and `None` are numbers (`None` missing); a masked
    /// array's masked values are missing.
    #[staticmethod]
    #[pyo3(signature = (data, columns=None, mag=None, vector=None, lines=None, time_range=None, copy=true))]
    #[allow(clippy::too_many_arguments)]
    fn from_dict(
        py: Python<'_>,
        data: &Bound<'_, PyDict>,
        columns: Option<Bound<'_, PyAny>>,
        mag: Option<String>,
        vector: Option<String>,
        lines: Option<Bound<'_, PyAny>>,
        time_range: Option<(f64, f64)>,
        copy: bool,
    ) -> PyResult<PyFlight> {
        let opts = python_read_options(columns.as_ref(), mag, vector, lines.as_ref(), time_range)?;
        let np = py.import("numpy")?;
        let mut cols: Vec<(String, ColumnData)> = Vec::with_capacity(data.len());
        for (k, v) in data.iter() {
            let name: String = k
                .extract()
                .map_err(|_| bad_argument(format!("column names must be str, got {k}")))?;
            let col = column_from_py(&np, &name, &v, copy)?;
            cols.push((name, col));
        }
        let flight = py
            .detach(|| {
                table_from_columns(cols, &opts)
                    .map_err(aeromag::Error::from)
                    .and_then(Flight::from_table)
            })
            .py_err()?;
        // A number column given as text (an object or str array) was found
        // only by the first call that used it.
        for name in NUMERIC_CANONICAL {
            if let Some(text) = flight.text_column(name) {
                let first = text.iter().position(|t| t.trim().parse::<f64>().is_err());
                return Err(bad_argument(format!(
                    "column '{name}' holds text{}: give numbers (NaN or None for missing values)",
                    first.map_or(String::new(), |r| format!(
                        " ({} at row {r})",
                        aeromag::core::error::shown_text(&text[r])
                    ))
                )));
            }
        }
        Ok(PyFlight::new(flight))
    }

    /// A flight from a pandas DataFrame, its columns named as in the files
    /// (`Flight.from_dict` of its columns, `copy` as there).
    #[staticmethod]
    #[pyo3(signature = (df, columns=None, mag=None, vector=None, lines=None, time_range=None, copy=true))]
    #[allow(clippy::too_many_arguments)]
    fn from_pandas(
        py: Python<'_>,
        df: &Bound<'_, PyAny>,
        columns: Option<Bound<'_, PyAny>>,
        mag: Option<String>,
        vector: Option<String>,
        lines: Option<Bound<'_, PyAny>>,
        time_range: Option<(f64, f64)>,
        copy: bool,
    ) -> PyResult<PyFlight> {
        let data = PyDict::new(py);
        let names = df.getattr("columns").map_err(|_| {
            pyo3::exceptions::PyTypeError::new_err(format!(
                "from_pandas takes a pandas DataFrame, got {}",
                df.get_type()
                    .name()
                    .map_or("an object".into(), |n| n.to_string())
            ))
        })?;
        for name in names.try_iter()? {
            let name = name?;
            let values = df.get_item(&name)?.call_method0("to_numpy")?;
            data.set_item(name.str()?, values)?;
        }
        Self::from_dict(py, &data, columns, mag, vector, lines, time_range, copy)
    }

    /// Every column as a dict of NumPy arrays (file names).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for name in self.inner.column_names() {
            d.set_item(name, self.__getitem__(py, name)?)?;
        }
        Ok(d)
    }

    /// A pandas DataFrame of every column (needs pandas).
    fn to_pandas<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let pd = py.import("pandas")?;
        pd.call_method1("DataFrame", (self.to_dict(py)?,))
    }

    /// A polars DataFrame of every column (needs polars).
    fn to_polars<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let pl = py.import("polars")?;
        pl.call_method1("DataFrame", (self.to_dict(py)?,))
    }

    /// Write the flight as CSV (as the CLI writes tables: atomically,
    /// numbers in their shortest exact form, integer columns as read).
    fn to_csv(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        py.detach(|| aeromag::io::write_csv(self.inner.table(), &path))
            .py_err()
    }

    /// Write the flight as Geosoft XYZ (`/` header of the column names,
    /// `*` for missing values, the line labels a column; as the CLI writes
    /// `--out X.xyz`): bad input for a column name or text cell the format
    /// cannot hold.
    fn to_xyz(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        py.detach(|| aeromag::io::write_xyz(self.inner.table(), &path))
            .py_err()
    }

    /// Write the flight as HDF5 in the MagNav/SGL layout (one 1-D dataset
    /// per column at the root: float64, int64 for integer columns, UTF-8
    /// strings for text; as the CLI writes `--out X.h5`), which h5py and
    /// MagNav.jl read: bad input for a column name HDF5 cannot hold (`/`).
    fn to_hdf5(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        py.detach(|| aeromag::io::write_hdf5(self.inner.table(), &path))
            .py_err()
    }

    /// Write the flight as a MATLAB v5 MAT-file (one n × 1 variable per
    /// column: double, int64 for integer columns, a space-padded char
    /// matrix for text; as the CLI writes `--out X.mat`), in the format of
    /// MATLAB's `load` (checked with scipy.io.loadmat): bad input for a
    /// column name that is not a MATLAB variable name.
    fn to_mat(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        py.detach(|| aeromag::io::write_mat5(self.inner.table(), &path))
            .py_err()
    }

    /// Number of rows.
    fn __len__(&self) -> usize {
        self.inner.n_rows()
    }

    /// The column `name` (a file name, or a canonical name such as `mag`
    /// through the mapping) as a new NumPy array: float64 for numbers, str
    /// for text columns.
    fn __getitem__<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        if let Some(v) = self.inner.column(name) {
            return Ok(PyArray1::from_slice(py, v).into_any());
        }
        if let Some(t) = self.inner.text_column(name) {
            let list = PyList::new(py, t)?;
            return py.import("numpy")?.call_method1("array", (list,));
        }
        Err(PyKeyError::new_err(format!(
            "no column '{name}' in {} (columns: {})",
            self.inner.label(),
            self.inner.column_names().join(", ")
        )))
    }

    fn __contains__(&self, name: &str) -> bool {
        self.inner.get(name).is_some()
    }

    /// The columns, as the file names them (derived canonical columns,
    /// such as `lat` from the radians of `ins_lat`, included).
    #[getter]
    fn columns(&self) -> Vec<String> {
        self.inner
            .column_names()
            .into_iter()
            .map(String::from)
            .collect()
    }

    /// The file's columns that were not read, because `read_flight` was
    /// asked for others only (`fields=`), in file order.
    #[getter]
    fn unread_columns(&self) -> Vec<String> {
        self.inner
            .unread_columns()
            .into_iter()
            .map(String::from)
            .collect()
    }

    /// What the file holds beside its fields, not read into the flight:
    /// `(name, what)` pairs such as `("TL_data.A_a", "a 1000 × 18
    /// matrix")` for a MATLAB MAT-file's scalars, matrices and text; empty
    /// for the other formats.
    #[getter]
    fn not_read(&self) -> Vec<(String, String)> {
        self.inner
            .not_read()
            .iter()
            .map(|n| (n.name.clone(), n.what.clone()))
            .collect()
    }

    /// Canonical name → the file's column that plays it (`{"mag":
    /// "mag_1_uc", …}`).
    #[getter]
    fn mapping(&self) -> Vec<(String, String)> {
        self.inner
            .mapping()
            .iter()
            .map(|m| (m.canonical.clone(), m.file_column.clone()))
            .collect()
    }

    /// The file read (None for a flight built in memory).
    #[getter]
    fn file(&self) -> Option<String> {
        self.inner.source().map(|p| p.display().to_string())
    }

    /// The warnings raised when the flight was read and checked (named
    /// kinds: field range, radians, …).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.inner
            .warnings()
            .iter()
            .map(|n| n.message.clone())
            .collect()
    }

    /// Pickling (and `copy.deepcopy`): the table's snapshot and its
    /// numbers ([`flight_from_state`]).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<crate::pickle::Reduced<'py>> {
        let (snapshot, numbers) = self.inner.table().snapshot();
        let layout = serde_json::to_string(&snapshot)
            .map_err(|e| bad_argument(format!("this flight cannot be pickled: {e}")))?;
        let args = (layout, crate::pickle::f64_bytes(py, &numbers)?).into_pyobject(py)?;
        Ok((crate::pickle::constructor(py, "_flight_from_state")?, args))
    }

    fn __repr__(&self) -> String {
        format!(
            "<aeromag.Flight {}: {} rows, {} columns>",
            self.inner.label(),
            self.inner.n_rows(),
            self.inner.columns().len()
        )
    }
}

/// Rebuild a pickled flight (the constructor of `Flight.__reduce__`): the
/// table's snapshot (JSON) and the bytes of its numeric columns, one after
/// the other. Bad input when they do not make a table, or the table is not
/// a flight (checked as `Flight.from_dict` checks one).
#[pyfunction]
#[pyo3(name = "_flight_from_state")]
pub fn flight_from_state(py: Python<'_>, layout: &str, numbers: &[u8]) -> PyResult<PyFlight> {
    let what = "pickled flight";
    let snapshot: TableSnapshot = serde_json::from_str(layout)
        .map_err(|e| bad_argument(format!("{what}: its layout is not readable ({e})")))?;
    let numbers = crate::pickle::f64s_from_bytes(&format!("{what}: its numbers"), numbers)?;
    let flight = py
        .detach(|| {
            FlightTable::from_snapshot(snapshot, numbers)
                .map_err(aeromag::Error::from)
                .and_then(Flight::from_table)
        })
        .py_err()?;
    Ok(PyFlight::new(flight))
}
