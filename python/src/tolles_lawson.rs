//! Tolles-Lawson calibration (`aeromag calibrate`) and the fitted model
//! (`aeromag compensate`): the Python layer's `TollesLawson` estimator
//! calls [`calibrate`] with its keyword options, which are turned into the
//! library's [`CalibrateSettings`] as the CLI's flags are.

use crate::errors::{IntoPy, bad_argument, whole};
use crate::flight::{FlightArg, PyFlight};
use crate::progress::PyProgress;
use aeromag::compensation::kalman::NoiseModel;
use aeromag::compensation::tolles_lawson::{Convention, ExtraRequest, Magnitude, TermSet};
use aeromag::core::time::Date;
use aeromag::{
    CalibrateOptions, CalibrateSettings, EddyLag, ExtraSelection, Method, ModelFile, Note,
    ReferenceChannels, TlModel, calibrate as lib_calibrate,
};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// The keyword options, in the order of the CLI's `calibrate --help`.
const OPTIONS: [&str; 20] = [
    "method",
    "tune",
    "no_tune",
    "kalman_noise",
    "field_order",
    "series",
    "extra",
    "extra_selection",
    "magnitude",
    "terms",
    "convention",
    "ridge_lambda",
    "band",
    "trim",
    "bt_scale",
    "no_split_lines",
    "reference",
    "eddy_lag",
    "lever_arm",
    "date",
];

/// A keyword option's value as the library's type.
fn parse_settings(params: &Bound<'_, PyDict>) -> PyResult<CalibrateSettings> {
    let mut s = CalibrateSettings::default();
    let mut no_tune = false;
    for (k, v) in params.iter() {
        let key: String = k.extract()?;
        if v.is_none() {
            // None: the library's default, except a band of None (fit
            // unfiltered data, the CLI's `--band none`).
            if key == "band" {
                s.band_hz = Some(None);
            }
            if !OPTIONS.contains(&key.as_str()) {
                return Err(unknown(&key));
            }
            continue;
        }
        let text = || -> PyResult<String> {
            // A list (of lags, of channels) is the CLI's comma list.
            if let Ok(items) = v.extract::<Vec<Bound<'_, PyAny>>>()
                && !v.is_instance_of::<pyo3::types::PyString>()
            {
                let parts: Vec<String> = items
                    .iter()
                    .map(|x| x.str().map(|s| s.to_string()))
                    .collect::<PyResult<_>>()?;
                return Ok(parts.join(","));
            }
            Ok(v.str()?.to_string())
        };
        // A wrong type named the option only in a note ("while processing
        // 'params'"), which str(e) leaves out.
        let flag = || -> PyResult<bool> {
            v.extract::<bool>().map_err(|_| {
                pyo3::exceptions::PyTypeError::new_err(format!(
                    "{key} must be True or False, got {}",
                    crate::errors::repr_of(&v)
                ))
            })
        };
        let number = |what: &str| -> PyResult<f64> {
            v.extract::<f64>()
                .map_err(|_| bad_argument(format!("{key} must be {what}, got {v}")))
        };
        match key.as_str() {
            "method" => {
                s.method = match text()?.to_ascii_lowercase().as_str() {
                    "ls" => Method::Ls,
                    "kalman" => Method::Kalman,
                    other => {
                        return Err(bad_argument(format!(
                            "method must be 'ls' or 'kalman', got '{other}'"
                        )));
                    }
                }
            }
            "tune" => s.tune = Some(flag()?),
            "no_tune" => no_tune = flag()?,
            "kalman_noise" => {
                let q: [f64; 3] = v
                    .extract()
                    .map_err(|_| bad_argument("kalman_noise must be (q1, q2, r)"))?;
                s.kalman_noise = Some(NoiseModel {
                    q1: q[0],
                    q2_nt2_per_m5: q[1],
                    r_nt2: q[2],
                });
            }
            "field_order" => s.field_order = Some(whole("field_order", &v)?),
            "series" => s.series = flag()?,
            "terms" => s.terms = Some(TermSet::parse(&text()?).py_err()?),
            "extra" => s.extra = ExtraRequest::parse_list(&text()?).py_err()?,
            "extra_selection" => s.extra_selection = text()?.parse::<ExtraSelection>().py_err()?,
            "magnitude" => s.magnitude = Some(text()?.parse::<Magnitude>().py_err()?),
            "convention" => s.convention = Some(text()?.parse::<Convention>().py_err()?),
            "ridge_lambda" => s.ridge_lambda = Some(number("a number ≥ 0")?),
            "band" => {
                s.band_hz = Some(if text()?.eq_ignore_ascii_case("none") {
                    None
                } else {
                    let b: (f64, f64) = v.extract().map_err(|_| {
                        bad_argument(format!("band must be (lo, hi) in Hz or None, got {v}"))
                    })?;
                    Some(b)
                })
            }
            "trim" => {
                s.trim = Some(
                    v.extract()
                        .map_err(|_| bad_argument(format!("trim must be an int ≥ 0, got {v}")))?,
                )
            }
            "bt_scale" => s.bt_scale_nt = Some(number("a number > 0 (nT)")?),
            "no_split_lines" => s.no_split_lines = flag()?,
            "reference" => s.reference = text()?.parse::<ReferenceChannels>().py_err()?,
            "eddy_lag" => s.eddy_lag = Some(text()?.parse::<EddyLag>().py_err()?),
            "lever_arm" => {
                s.lever_arm_m = Some(
                    v.extract()
                        .map_err(|_| bad_argument("lever_arm must be (x, y, z) in m"))?,
                )
            }
            "date" => {
                s.decimal_year = Some(match v.extract::<f64>() {
                    Ok(y) => y,
                    Err(_) => Date::parse(&text()?).py_err()?.decimal_year(),
                })
            }
            _ => return Err(unknown(&key)),
        }
    }
    if no_tune {
        if s.tune == Some(true) {
            return Err(bad_argument(
                "tune=True and no_tune=True contradict each other",
            ));
        }
        s.tune = Some(false);
    }
    Ok(s)
}

fn unknown(key: &str) -> PyErr {
    bad_argument(format!(
        "unknown option '{key}' (options: {})",
        OPTIONS.join(", ")
    ))
}

/// The library's options for these keyword options (bad input if one is
/// not valid), without fitting: what `TollesLawson.fit` will use.
pub fn options(params: &Bound<'_, PyDict>) -> PyResult<CalibrateOptions> {
    parse_settings(params)?.options().py_err()
}

/// Check the keyword options of `TollesLawson` (raises BadInputError).
#[pyfunction]
pub fn check_calibrate_options(params: &Bound<'_, PyDict>) -> PyResult<()> {
    options(params).map(|_| ())
}

/// The defaults of the keyword options, as the library has them.
#[pyfunction]
pub fn calibrate_defaults(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let o = CalibrateOptions::default();
    let d = PyDict::new(py);
    d.set_item("method", "ls")?;
    d.set_item("terms", o.ls.design.terms.to_string())?;
    d.set_item("convention", o.ls.design.convention.to_string())?;
    d.set_item("ridge_lambda", o.ls.lambda)?;
    d.set_item("band", o.ls.band_hz)?;
    d.set_item("trim", o.ls.trim)?;
    d.set_item("bt_scale", o.ls.design.bt_scale_nt)?;
    d.set_item("reference", o.reference.to_string())?;
    d.set_item("date", aeromag::tolles_lawson::DEFAULT_DECIMAL_YEAR)?;
    Ok(d)
}

/// Fit a Tolles-Lawson model on a calibration flight (the GIL is
/// released while fitting; `progress(stage, done, total)` is called).
#[pyfunction]
#[pyo3(signature = (flight, params, progress=None))]
pub fn calibrate(
    py: Python<'_>,
    flight: FlightArg<'_>,
    params: &Bound<'_, PyDict>,
    progress: Option<Py<PyAny>>,
) -> PyResult<PyTlModel> {
    let opts = options(params)?;
    let mut obs = PyProgress::new(progress);
    let result = py.detach(|| lib_calibrate(&flight.inner, &opts, &mut obs));
    obs.finish()?;
    let cal = result.py_err()?;
    let series = cal
        .kalman
        .as_ref()
        .and_then(|k| k.series.as_ref())
        .map(|s| s.columns().map(|c| c.to_vec()));
    Ok(PyTlModel {
        model: cal.model,
        notes: cal.notes,
        series,
    })
}

/// A fitted Tolles-Lawson model: what `aeromag calibrate` writes as the
/// model file; it applies itself to flights.
#[pyclass(name = "TlModel", module = "aeromag._aeromag", frozen)]
pub struct PyTlModel {
    pub(crate) model: TlModel,
    pub(crate) notes: Vec<Note>,
    pub(crate) series: Option<[Vec<f64>; 5]>,
}

impl PyTlModel {
    /// A model without notes or series (read from a file, or one sensor's
    /// of a multi-sensor model).
    pub fn of(model: TlModel) -> Self {
        Self {
            model,
            notes: Vec::new(),
            series: None,
        }
    }

    /// The model.
    pub fn inner(&self) -> &TlModel {
        &self.model
    }
}

#[pymethods]
impl PyTlModel {
    /// Coefficient values, in `terms` order (units per term: nT for the
    /// permanent terms, nT per `bt_scale` nT for the induced and eddy
    /// terms; see the model file's documentation).
    #[getter]
    fn coef<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.model.coef())
    }

    /// Standard deviations of the coefficients (same units).
    #[getter]
    fn coef_std<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.model.coefficients.iter().map(|c| c.std).collect())
    }

    /// Term names (`p1` … `e9`, `l1_…`, `bias`).
    #[getter]
    fn terms(&self) -> Vec<String> {
        self.model
            .coefficients
            .iter()
            .map(|c| c.name.clone())
            .collect()
    }

    /// `ls` or `kalman`.
    #[getter]
    fn method(&self) -> String {
        self.model.method.name().to_string()
    }

    /// Notes and warnings of the fit ("warning: …", "note: …").
    #[getter]
    fn notes(&self) -> Vec<String> {
        self.notes.iter().map(|n| n.to_string()).collect()
    }

    /// Rows used, legs, residual RMS (nT) and condition number of the fit.
    #[getter]
    fn fit_stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let f = &self.model.fit;
        let d = PyDict::new(py);
        d.set_item("rows", f.rows)?;
        d.set_item("segments", f.segments)?;
        d.set_item("residual_rms_nt", f.residual_rms_nt)?;
        d.set_item("condition", f.condition)?;
        Ok(d)
    }

    /// The Kalman method's per-row series (with `series=True`): reading
    /// (reference removed), compensated, smoothed field, innovation and
    /// its standard deviation, nT, NaN where a row was not used.
    #[getter]
    fn series<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(s) = &self.series else {
            return Ok(None);
        };
        let d = PyDict::new(py);
        for (name, values) in aeromag::tolles_lawson::KALMAN_SERIES.iter().zip(s) {
            d.set_item(*name, PyArray1::from_slice(py, values))?;
        }
        Ok(Some(d))
    }

    /// The modelled interference of every row of `flight`, nT (NaN where
    /// an input is missing).
    fn interference<'py>(
        &self,
        py: Python<'py>,
        flight: FlightArg<'_>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        crate::apply::interference(py, &self.model, &flight)
    }

    /// `mag` minus the modelled interference, nT (NaN where it cannot be
    /// computed). `causal=True`: as on board (`aeromag compensate
    /// --causal`; the values of `OnlineCompensator`), runs broken at steps
    /// over 1.5 / `sample_rate` (default: the calibration's interval).
    #[pyo3(signature = (flight, causal = false, sample_rate = None))]
    fn compensate<'py>(
        &self,
        py: Python<'py>,
        flight: FlightArg<'_>,
        causal: bool,
        sample_rate: Option<f64>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        if causal {
            let c = aeromag::online::CausalTl::new(&self.model, sample_rate).py_err()?;
            crate::apply::compensate(py, &c, &flight)
        } else if sample_rate.is_some() {
            Err(bad_argument("sample_rate is for causal=True"))
        } else {
            crate::apply::compensate(py, &self.model, &flight)
        }
    }

    /// An `OnlineCompensator` of this model (`adapt`: None, "kalman" or
    /// "rls").
    #[pyo3(signature = (sample_rate = None, adapt = None))]
    fn online(
        &self,
        sample_rate: Option<f64>,
        adapt: Option<&str>,
    ) -> PyResult<crate::online::PyOnline> {
        crate::online::PyOnline::of(&self.model, sample_rate, adapt)
    }

    /// The flight with the compensation columns added (`mag_comp`,
    /// `mag_interf`, `comp_flag`), as `aeromag compensate --out` writes it.
    fn apply(&self, py: Python<'_>, flight: FlightArg<'_>) -> PyResult<PyFlight> {
        crate::apply::apply(py, &self.model, &flight)
    }

    /// The model file's text (JSON), byte for byte what the CLI writes.
    fn to_json(&self) -> PyResult<String> {
        self.model.json().py_err()
    }

    /// Write the model file (atomically: a temporary file renamed when
    /// complete), as `aeromag calibrate --model` does.
    fn save(&self, path: PathBuf) -> PyResult<()> {
        self.model.write(&path).py_err()
    }

    /// Pickling (and `copy.deepcopy`): the model file's text, the notes
    /// and the series ([`crate::pickle`]).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<crate::pickle::Reduced<'py>> {
        crate::pickle::reduce_model(
            py,
            self.model.json().py_err()?,
            &self.notes,
            self.series.as_ref(),
        )
    }

    fn __repr__(&self) -> String {
        format!(
            "<aeromag.TlModel {} terms, method {}, residual {:.4} nT RMS>",
            self.model.coefficients.len(),
            self.model.method.name(),
            self.model.fit.residual_rms_nt
        )
    }
}

/// Read a model file written by the CLI or `save`: a Tolles-Lawson model
/// (`TlModel`), a multi-sensor model (`SensorsModel`), or a rotor or pod
/// model (`Model`), by the file's `kind`.
#[pyfunction]
pub fn load_model(py: Python<'_>, path: PathBuf) -> PyResult<Py<PyAny>> {
    let text = aeromag::model_file::read_text_file(&path).py_err()?;
    crate::pickle::model_of_text(py, &text, &path.display().to_string(), Vec::new(), None)
}

/// What a calibration flight determines (`aeromag observability`): per
/// coefficient the estimability μ (0 determined, 1 left at its prior), the
/// standard deviation, the effect uncertainty in nT and the verdict; the
/// rank, condition number and weak combinations.
#[pyfunction]
#[pyo3(signature = (flight, terms=None, lever_arm=None, decimal_year=None, progress=None))]
pub fn observability(
    py: Python<'_>,
    flight: FlightArg<'_>,
    terms: Option<&str>,
    lever_arm: Option<[f64; 3]>,
    decimal_year: Option<f64>,
    progress: Option<Py<PyAny>>,
) -> PyResult<String> {
    let terms = match terms {
        Some(t) => TermSet::parse(t).py_err()?,
        None => aeromag::compensation::tolles_lawson::Design::default().terms,
    };
    let lever = lever_arm.map(|arm_m| aeromag::LeverArm {
        arm_m,
        decimal_year: decimal_year.unwrap_or(aeromag::tolles_lawson::DEFAULT_DECIMAL_YEAR),
    });
    let mut obs = PyProgress::new(progress);
    let result = py.detach(|| aeromag::observability(&flight.inner, &terms, lever, &mut obs));
    obs.finish()?;
    let o = result.py_err()?;
    let v = serde_json::json!({
        "rows": o.rows,
        "rank": o.observability.rank,
        "condition": o.observability.condition,
        "eigenvalues": o.observability.eigenvalues,
        "weak_combinations": o.observability.weak_combinations,
        "coefficients": o.coefficients,
        "undetermined": o.undetermined(),
        "notes": o.notes.iter().map(|n| n.to_string()).collect::<Vec<_>>(),
    });
    Ok(v.to_string())
}
