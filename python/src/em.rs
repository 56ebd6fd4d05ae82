//! Low-frequency EM positioning of a towed bird, as the CLI's `aeromag em`
//! chains it: `simulate_em` (raw record, system, KNOWN, truth) →
//! `detect_em` → `calibrate_em` → `locate_em`. Each step calls the
//! library's entry point ([`aeromag::em`]) and can write the same file as
//! the CLI step (`save`); each result also gives its table as NumPy arrays
//! (`to_dict`), parsed from that same file text, so Python and CLI numbers
//! are the same bits.

use crate::errors::{IntoPy, bad_argument, whole_opt};
use crate::progress::PyProgress;
use aeromag::Note;
use aeromag::core::filter::Window;
use aeromag::em::calibration::CalibrationFile;
use aeromag::em::detection::FieldEpoch;
use aeromag::em::files::{load_table, read_detected, read_system};
use aeromag::em::sim::detected_csv;
use aeromag::em::{
    DetectOptions, EmCalibration, HalfSpace, Poses, calibrate, detect, known_points, locate,
    parse_config, simulate_to_dir,
};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::{Path, PathBuf};

/// A CSV text written by the library (header, numbers, empty = missing)
/// as a dict of float64 arrays in column order.
fn csv_arrays<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyDict>> {
    let mut lines = text.lines();
    let names: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let mut cols: Vec<Vec<f64>> = vec![Vec::new(); names.len()];
    for line in lines {
        for (c, cell) in cols.iter_mut().zip(line.split(',')) {
            c.push(if cell.is_empty() {
                f64::NAN
            } else {
                cell.parse()
                    .map_err(|_| bad_argument(format!("not a number: '{cell}'")))?
            });
        }
    }
    let d = PyDict::new(py);
    for (n, c) in names.iter().zip(cols) {
        d.set_item(n, PyArray1::from_vec(py, c))?;
    }
    Ok(d)
}

/// Write `text` to `path` atomically (the CLI's way), as an `OSError`.
fn save(path: &Path, text: String) -> PyResult<()> {
    aeromag::io::atomic::write_file(path, text)
        .map_err(|e| aeromag::Error::write(path, e))
        .py_err()
}

/// The half-space of a normal `(nx, ny, nz)`, through the CLI's parser of
/// `--half-space NX,NY,NZ` (Rust prints floats so that they read back
/// exactly).
/// Any sequence of three numbers is taken (a list or an array was refused:
/// "'list' object is not an instance of 'tuple'").
fn half_space(normal: [f64; 3]) -> PyResult<HalfSpace> {
    format!("{},{},{}", normal[0], normal[1], normal[2])
        .parse::<HalfSpace>()
        .py_err()
}

fn note_texts(notes: &[Note]) -> Vec<String> {
    notes.iter().map(|n| n.to_string()).collect()
}

/// Detected complex field vectors of a raw EM record (`aeromag em detect`).
#[pyclass(name = "EmDetection", module = "aeromag._aeromag", frozen)]
#[derive(serde::Serialize, serde::Deserialize)]
pub struct PyEmDetection {
    epochs: Vec<FieldEpoch>,
    #[pyo3(get)]
    sample_rate_hz: f64,
    #[pyo3(get)]
    window_len: usize,
    #[pyo3(get)]
    polarization_ratio_rms: f64,
    #[pyo3(get)]
    notes: Vec<String>,
}

#[pymethods]
impl PyEmDetection {
    /// Number of detector epochs (blocks of `window_len` samples).
    fn __len__(&self) -> usize {
        self.epochs.len()
    }

    /// The detected-vector table as float64 arrays: `time_s` (block
    /// centre, s), `h{i}_{x,y,z}_{re,im}_t` (field of dipole i, T),
    /// `xi{i}_{x,y,z}_{re,im}` (pilot-measured sensitivity), `pol_ratio_{i}`.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        csv_arrays(py, &detected_csv(&self.epochs))
    }

    /// Write the detected-vector CSV of `aeromag em detect`.
    fn save(&self, path: PathBuf) -> PyResult<()> {
        save(&path, detected_csv(&self.epochs))
    }

    /// Pickling (and `copy.deepcopy`): the epochs and figures
    /// ([`em_detection_from_state`]).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<crate::pickle::Reduced<'py>> {
        let args = (crate::pickle::to_cbor(py, "EM detection", self)?,).into_pyobject(py)?;
        Ok((
            crate::pickle::constructor(py, "_em_detection_from_state")?,
            args,
        ))
    }

    fn __repr__(&self) -> String {
        format!(
            "EmDetection({} epochs of {} samples at {} Hz)",
            self.epochs.len(),
            self.window_len,
            self.sample_rate_hz
        )
    }
}

/// Detect the complex field vectors of the raw record `raw` (synchronous
/// detection, pilot correction; seed 001 eqs. 2–4).
#[pyfunction]
#[pyo3(signature = (raw, window_len=None, window="blackman-harris", pilot=true, system=None, progress=None))]
pub fn detect_em(
    py: Python<'_>,
    raw: PathBuf,
    window_len: Option<Bound<'_, PyAny>>,
    window: &str,
    pilot: bool,
    system: Option<PathBuf>,
    progress: Option<Py<PyAny>>,
) -> PyResult<PyEmDetection> {
    let defaults = DetectOptions::default();
    let opts = DetectOptions {
        window_len: whole_opt("window_len", window_len.as_ref())?.unwrap_or(defaults.window_len),
        window: match window {
            "blackman-harris" => Window::BlackmanHarris,
            "nuttall" => Window::Nuttall,
            other => {
                return Err(bad_argument(format!(
                    "window must be 'blackman-harris' or 'nuttall', got '{other}'"
                )));
            }
        },
        pilot,
        system: system.as_deref().map(read_system).transpose().py_err()?,
    };
    let mut obs = PyProgress::new(progress);
    let d = py.detach(|| detect(&raw, &opts, &mut obs));
    obs.finish()?;
    let d = d.py_err()?;
    Ok(PyEmDetection {
        epochs: d.epochs,
        sample_rate_hz: d.sample_rate_hz,
        window_len: d.window_len,
        polarization_ratio_rms: d.polarization_ratio_rms,
        notes: note_texts(&d.notes),
    })
}

/// Detected epochs from a detection or a detected-vector CSV path.
fn epochs_of(detected: &Bound<'_, PyAny>) -> PyResult<Vec<FieldEpoch>> {
    if let Ok(d) = detected.cast::<PyEmDetection>() {
        return Ok(d.get().epochs.clone());
    }
    let path: PathBuf = detected
        .extract()
        .map_err(|_| bad_argument("detected must be an EmDetection or a CSV path"))?;
    read_detected(&path).py_err()
}

/// The three calibration stages of an EM system (`aeromag em calibrate`).
#[pyclass(name = "EmCalibration", module = "aeromag._aeromag", frozen)]
pub struct PyEmCalibration {
    inner: EmCalibration,
}

#[pymethods]
impl PyEmCalibration {
    /// RMS polarisation ratio of the detected fields before calibration.
    #[getter]
    fn polarization_ratio_before(&self) -> f64 {
        self.inner.polarization_ratio_before
    }
    /// … after stage 1 (≈ 0 for a clean field).
    #[getter]
    fn polarization_ratio_after(&self) -> f64 {
        self.inner.polarization_ratio_after
    }
    /// Size of the fitted transmitter distortion |S|.
    #[getter]
    fn transmitter_distortion(&self) -> f64 {
        self.inner.transmitter_distortion
    }
    /// Angle of the attitude correction, deg.
    #[getter]
    fn attitude_correction_deg(&self) -> f64 {
        self.inner.attitude_correction_deg
    }
    /// The calibration file's JSON text (as `aeromag em calibrate` writes).
    fn to_json(&self) -> PyResult<String> {
        self.inner.file.to_json().py_err()
    }
    /// Write the calibration file of `aeromag em calibrate`.
    fn save(&self, path: PathBuf) -> PyResult<()> {
        save(&path, self.inner.file.to_json().py_err()?)
    }
    /// Pickling (and `copy.deepcopy`): the calibration file's text and the
    /// fit's four figures ([`em_calibration_from_json`]).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<crate::pickle::Reduced<'py>> {
        let c = &self.inner;
        let args = (
            c.file.to_json().py_err()?,
            c.polarization_ratio_before,
            c.polarization_ratio_after,
            c.transmitter_distortion,
            c.attitude_correction_deg,
        )
            .into_pyobject(py)?;
        Ok((
            crate::pickle::constructor(py, "_em_calibration_from_json")?,
            args,
        ))
    }
    fn __repr__(&self) -> String {
        let c = &self.inner.file.fit;
        format!(
            "EmCalibration({} epochs, {} known positions, {} known attitude(s))",
            c.epochs, c.known_positions, c.known_attitudes
        )
    }
}

/// Rebuild a pickled EM calibration (the constructor of
/// `EmCalibration.__reduce__`): the calibration file's text, read and
/// checked as `locate_em` reads the file (bad input when it is not one),
/// and the fit's figures.
#[pyfunction]
#[pyo3(name = "_em_calibration_from_json")]
pub fn em_calibration_from_json(
    text: &str,
    polarization_ratio_before: f64,
    polarization_ratio_after: f64,
    transmitter_distortion: f64,
    attitude_correction_deg: f64,
) -> PyResult<PyEmCalibration> {
    let file = CalibrationFile::from_json(text)
        .map_err(|e| aeromag::Error::bad_file("pickled EM calibration", e.to_string()))
        .py_err()?;
    Ok(PyEmCalibration {
        inner: EmCalibration {
            file,
            polarization_ratio_before,
            polarization_ratio_after,
            transmitter_distortion,
            attitude_correction_deg,
        },
    })
}

/// Fit the three calibration stages (polarisation from all epochs;
/// transmitter geometry from the known positions; attitude from the known
/// attitude) from detected vectors, a KNOWN CSV and the system JSON.
#[pyfunction]
#[pyo3(signature = (detected, known, system, half_space=[-1.0, 0.0, 1.0]),
       text_signature = "(detected, known, system, half_space=(-1.0, 0.0, 1.0))")]
pub fn calibrate_em(
    py: Python<'_>,
    detected: &Bound<'_, PyAny>,
    known: PathBuf,
    system: PathBuf,
    half_space: [f64; 3],
) -> PyResult<PyEmCalibration> {
    let h = self::half_space(half_space)?;
    let epochs = epochs_of(detected)?;
    let system = read_system(&system).py_err()?;
    let known = known_points(&load_table(&known).py_err()?, &epochs).py_err()?;
    let inner = py
        .detach(|| calibrate(&epochs, &known, &system, &h))
        .py_err()?;
    Ok(PyEmCalibration { inner })
}

/// The calibrated pose of the bird at every epoch (`aeromag em locate`).
#[pyclass(name = "EmPoses", module = "aeromag._aeromag", frozen)]
pub struct PyEmPoses {
    inner: Poses,
}

#[pymethods]
impl PyEmPoses {
    fn __len__(&self) -> usize {
        self.inner.poses.len()
    }
    /// Epochs that could not be located (their pose columns are NaN).
    #[getter]
    fn failed(&self) -> usize {
        self.inner.failed()
    }
    /// Epochs whose sign of r was decided by continuity near the
    /// half-space plane.
    #[getter]
    fn by_continuity(&self) -> usize {
        self.inner.by_continuity()
    }
    /// Notes and warnings of the location ("warning: …"), as `aeromag em
    /// locate` prints them: epochs not located, a half-space other than
    /// the one the calibration was fitted with.
    #[getter]
    fn notes(&self) -> Vec<String> {
        note_texts(&self.inner.notes)
    }
    /// The poses as float64 arrays: `time_s`; `x_m, y_m, z_m` (transmitter
    /// frame, m); `range_m`; `roll_deg, pitch_deg, yaw_deg` (Z-Y-X, deg);
    /// `pol_ratio_1..3`; `residual_rel`; `hemisphere_by_continuity` (0/1);
    /// `status` (0 located, 1 failed).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        csv_arrays(py, &self.inner.to_csv())
    }
    /// Write the pose CSV of `aeromag em locate`.
    fn save(&self, path: PathBuf) -> PyResult<()> {
        save(&path, self.inner.to_csv())
    }
    /// Pickling (and `copy.deepcopy`): the poses and notes
    /// ([`em_poses_from_state`]).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<crate::pickle::Reduced<'py>> {
        let state = crate::pickle::to_cbor(py, "EM poses", &self.inner)?;
        let args = (state,).into_pyobject(py)?;
        Ok((
            crate::pickle::constructor(py, "_em_poses_from_state")?,
            args,
        ))
    }

    fn __repr__(&self) -> String {
        format!(
            "EmPoses({} epochs, {} failed)",
            self.inner.poses.len(),
            self.inner.failed()
        )
    }
}

/// Rebuild a pickled EM detection (the constructor of
/// `EmDetection.__reduce__`); bad input when the state is not one.
#[pyfunction]
#[pyo3(name = "_em_detection_from_state")]
pub fn em_detection_from_state(state: &[u8]) -> PyResult<PyEmDetection> {
    crate::pickle::from_cbor("EM detection", state)
}

/// Rebuild pickled EM poses (the constructor of `EmPoses.__reduce__`); bad
/// input when the state is not theirs.
#[pyfunction]
#[pyo3(name = "_em_poses_from_state")]
pub fn em_poses_from_state(state: &[u8]) -> PyResult<PyEmPoses> {
    Ok(PyEmPoses {
        inner: crate::pickle::from_cbor("EM poses", state)?,
    })
}

/// Locate the bird at every epoch with a calibration (an `EmCalibration`
/// or the path of a calibration file).
#[pyfunction]
#[pyo3(signature = (detected, calibration, half_space=[-1.0, 0.0, 1.0], progress=None),
       text_signature = "(detected, calibration, half_space=(-1.0, 0.0, 1.0), progress=None)")]
pub fn locate_em(
    py: Python<'_>,
    detected: &Bound<'_, PyAny>,
    calibration: &Bound<'_, PyAny>,
    half_space: [f64; 3],
    progress: Option<Py<PyAny>>,
) -> PyResult<PyEmPoses> {
    let h = self::half_space(half_space)?;
    let epochs = epochs_of(detected)?;
    let file = if let Ok(c) = calibration.cast::<PyEmCalibration>() {
        c.get().inner.file.clone()
    } else {
        let path: PathBuf = calibration
            .extract()
            .map_err(|_| bad_argument("calibration must be an EmCalibration or a file path"))?;
        let text = aeromag::model_file::read_text_file(&path).py_err()?;
        CalibrationFile::from_json(&text)
            .map_err(|e| aeromag::Error::bad_file(path.display().to_string(), e.to_string()))
            .py_err()?
    };
    let mut obs = PyProgress::new(progress);
    let poses = py.detach(|| locate(&epochs, &file, &h, &mut obs));
    obs.finish()?;
    Ok(PyEmPoses {
        inner: poses.py_err()?,
    })
}

/// Simulate an EM positioning flight into the folder `out` (the files of
/// `aeromag em simulate`); returns their paths and counts.
#[pyfunction]
#[pyo3(signature = (out, config=None, seed=None, known_positions=None),
       text_signature = "(out, config=None, seed=None, known_positions=8)")]
pub fn simulate_em<'py>(
    py: Python<'py>,
    out: PathBuf,
    config: Option<PathBuf>,
    seed: Option<Bound<'py, PyAny>>,
    known_positions: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let seed: Option<u64> = whole_opt("seed", seed.as_ref())?;
    let known_positions: usize = whole_opt("known_positions", known_positions.as_ref())?
        .unwrap_or(aeromag::em::DEFAULT_KNOWN);
    let text = config
        .as_deref()
        .map(aeromag::model_file::read_text_file)
        .transpose()
        .py_err()?;
    let origin = config
        .as_deref()
        .map_or_else(|| "defaults".to_string(), |p| p.display().to_string());
    let mut cfg = parse_config(text.as_deref(), &origin).py_err()?;
    if let Some(s) = seed {
        cfg.seed = s;
    }
    let files = py
        .detach(|| simulate_to_dir(&cfg, known_positions, &out))
        .py_err()?;
    let d = PyDict::new(py);
    for (k, p) in [
        ("raw", &files.raw),
        ("system", &files.system),
        ("known", &files.known),
        ("truth", &files.truth),
        ("scenario", &files.scenario),
    ] {
        d.set_item(k, p.display().to_string())?;
    }
    d.set_item("frames", files.frames)?;
    d.set_item("epochs", files.epochs)?;
    Ok(d)
}
