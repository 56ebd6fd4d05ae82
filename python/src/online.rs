//! `aeromag.OnlineCompensator`: a Tolles-Lawson model applied sample by
//! sample (latency 0, the causal convention), pushed one sample or one
//! block at a time ([`aeromag::online`]).

use crate::errors::{IntoPy, bad_argument};
use crate::tolles_lawson::PyTlModel;
use aeromag::TlModel;
use aeromag::online::{
    Adapt, AdaptOptions, CausalTl, Navigation, OnlineEngine, OnlineSample, StreamFlag,
};
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// A model compensating samples as they arrive.
///
/// `OnlineCompensator(model, sample_rate=None, adapt=None)`: `model` a
/// `TlModel`; a run breaks at time steps over 1.5 / `sample_rate` (default:
/// the calibration's sample interval, recorded in the model). `adapt`:
/// `None` (the model's coefficients, the values of `compensate --causal`),
/// `"kalman"` or `"rls"` (the coefficients updated by every compensated
/// sample, as `aeromag stream --adapt`; the Kalman filter learns only from
/// samples with a ground speed). Each sample's `comp_flag` is that of
/// `aeromag stream`: 0 compensated, 1 missing value, 2 compensated after a
/// gap (run restarted), 3 time going back (ignored).
#[pyclass(name = "OnlineCompensator", module = "aeromag._aeromag")]
pub struct PyOnline {
    online: OnlineEngine,
    channels: Vec<String>,
    names: Vec<String>,
    max_step_s: f64,
}

#[pymethods]
impl PyOnline {
    #[new]
    #[pyo3(signature = (model, sample_rate = None, adapt = None))]
    fn new(model: &PyTlModel, sample_rate: Option<f64>, adapt: Option<&str>) -> PyResult<Self> {
        Self::of(model.inner(), sample_rate, adapt)
    }

    /// When adapting, the current coefficients: a dict of `name`, `value`
    /// and `std` (lists in column order); `None` with the model's fixed
    /// coefficients.
    #[getter]
    fn coefficients<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some((values, std)) = self.online.coefficients() else {
            return Ok(None);
        };
        let d = PyDict::new(py);
        d.set_item("name", self.names.clone())?;
        d.set_item("value", values.to_vec())?;
        d.set_item("std", std)?;
        Ok(Some(d))
    }

    /// When adapting, the samples not learnt from as outliers (their
    /// innovation beyond 100 standard deviations; they are compensated with
    /// the coefficients of the time); `None` with the model's fixed
    /// coefficients.
    #[getter]
    fn outliers(&self) -> Option<u64> {
        self.online.outliers()
    }

    /// The extra channels a sample carries, in order (the model's current
    /// channels, e.g. `cur_strb`).
    #[getter]
    fn channels(&self) -> Vec<String> {
        self.channels.clone()
    }

    /// The longest time step within a run, s.
    #[getter]
    fn max_step_s(&self) -> f64 {
        self.max_step_s
    }

    /// One sample: time (s), the vector field `(x, y, z)` (body frame, nT),
    /// the scalar reading (nT), the channels in [`channels`] order, and when
    /// adapting the ground speed (m/s) and altitude (m). Returns
    /// `(mag_interf, mag_comp, comp_flag)` (NaN when not compensated).
    #[pyo3(signature = (time, flux, mag, channels = Vec::new(), speed = f64::NAN, alt = f64::NAN))]
    fn push(
        &mut self,
        time: f64,
        flux: (f64, f64, f64),
        mag: f64,
        channels: Vec<f64>,
        speed: f64,
        alt: f64,
    ) -> PyResult<(f64, f64, u8)> {
        self.check_channels(channels.len())?;
        let o = self.online.push(
            &OnlineSample {
                time_s: time,
                flux_nt: [flux.0, flux.1, flux.2],
                mag_nt: mag,
                channels: &channels,
            },
            Navigation {
                speed_m_s: speed,
                alt_m: alt,
            },
        );
        Ok((
            o.interference_nt,
            o.compensated_nt,
            StreamFlag::from(o.status) as u8,
        ))
    }

    /// A block of samples (arrays of one length), in order, continuing the
    /// state: `channels` a list of arrays in [`channels`] order or a dict
    /// by name; when adapting, `speed` (m/s) and `alt` (m) arrays. Returns
    /// a dict of `mag_interf`, `mag_comp` (float arrays) and `comp_flag`
    /// (uint8 array). The same values as pushing the samples one by one,
    /// with the GIL released.
    #[pyo3(signature = (time, flux_x, flux_y, flux_z, mag, channels = None, speed = None, alt = None))]
    #[allow(clippy::too_many_arguments)]
    fn push_block<'py>(
        &mut self,
        py: Python<'py>,
        time: &Bound<'py, PyAny>,
        flux_x: &Bound<'py, PyAny>,
        flux_y: &Bound<'py, PyAny>,
        flux_z: &Bound<'py, PyAny>,
        mag: &Bound<'py, PyAny>,
        channels: Option<&Bound<'py, PyAny>>,
        speed: Option<&Bound<'py, PyAny>>,
        alt: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let chans: Vec<PyReadonlyArray1<'py, f64>> = match channels {
            None => Vec::new(),
            Some(c) => match c.cast::<PyDict>() {
                Ok(d) => self
                    .channels
                    .iter()
                    .map(|n| {
                        let a = d
                            .get_item(n)?
                            .ok_or_else(|| bad_argument(format!("channels has no `{n}`")))?;
                        float_array(&format!("channels[{n:?}]"), &a)
                    })
                    .collect::<PyResult<_>>()?,
                Err(_) => c
                    .try_iter()?
                    .enumerate()
                    .map(|(k, a)| float_array(&format!("channels[{k}]"), &a?))
                    .collect::<PyResult<_>>()?,
            },
        };
        self.check_channels(chans.len())?;
        let cols = [
            ("time", time),
            ("flux_x", flux_x),
            ("flux_y", flux_y),
            ("flux_z", flux_z),
            ("mag", mag),
        ]
        .map(|(name, a)| float_array(name, a));
        let cols: Vec<PyReadonlyArray1<'py, f64>> = cols.into_iter().collect::<PyResult<_>>()?;
        let nav = [("speed", speed), ("alt", alt)].map(|(name, a)| {
            a.filter(|a| !a.is_none())
                .map(|a| float_array(name, a))
                .transpose()
        });
        let nav: Vec<Option<PyReadonlyArray1<'py, f64>>> =
            nav.into_iter().collect::<PyResult<_>>()?;
        let cols: Vec<&[f64]> = cols
            .iter()
            .map(|a| a.as_slice())
            .collect::<Result<_, _>>()?;
        let ch: Vec<&[f64]> = chans
            .iter()
            .map(|a| a.as_slice())
            .collect::<Result<_, _>>()?;
        let nav: Vec<Option<&[f64]>> = nav
            .iter()
            .map(|a| a.as_ref().map(|a| a.as_slice()).transpose())
            .collect::<Result<_, _>>()?;
        let n = cols[0].len();
        if cols
            .iter()
            .chain(&ch)
            .chain(nav.iter().flatten())
            .any(|c| c.len() != n)
        {
            return Err(bad_argument("the arrays of a block must have one length"));
        }
        let online = &mut self.online;
        let (interf, comp, flag) = py.detach(|| {
            let (mut interf, mut comp, mut flag) = (
                Vec::with_capacity(n),
                Vec::with_capacity(n),
                Vec::with_capacity(n),
            );
            let mut row = vec![0.0; ch.len()];
            for k in 0..n {
                for (v, c) in row.iter_mut().zip(&ch) {
                    *v = c[k];
                }
                let at = |c: Option<&[f64]>| c.map_or(f64::NAN, |c| c[k]);
                let o = online.push(
                    &OnlineSample {
                        time_s: cols[0][k],
                        flux_nt: [cols[1][k], cols[2][k], cols[3][k]],
                        mag_nt: cols[4][k],
                        channels: &row,
                    },
                    Navigation {
                        speed_m_s: at(nav[0]),
                        alt_m: at(nav[1]),
                    },
                );
                interf.push(o.interference_nt);
                comp.push(o.compensated_nt);
                flag.push(StreamFlag::from(o.status) as u8);
            }
            (interf, comp, flag)
        });
        let d = PyDict::new(py);
        d.set_item("mag_interf", PyArray1::from_vec(py, interf))?;
        d.set_item("mag_comp", PyArray1::from_vec(py, comp))?;
        d.set_item("comp_flag", PyArray1::from_vec(py, flag))?;
        Ok(d)
    }

    /// Forget the stream: the next sample starts a run whatever its time.
    fn reset(&mut self) {
        self.online.reset();
    }

    fn __repr__(&self) -> String {
        format!(
            "OnlineCompensator(channels={:?}, max_step_s={})",
            self.channels, self.max_step_s
        )
    }
}

/// `value` as a contiguous one-dimensional float64 array (a view when it
/// is one already): a strided slice, integers, a list or a pandas Series
/// are taken (a strided or integer array was "not contiguous" or "cannot
/// be converted to 'PyArray<T, D>'"); complex values, text or another
/// shape are a TypeError naming `name`.
fn float_array<'py>(name: &str, value: &Bound<'py, PyAny>) -> PyResult<PyReadonlyArray1<'py, f64>> {
    let np = value.py().import("numpy")?;
    let wrong = |what: String| pyo3::exceptions::PyTypeError::new_err(format!("{name} {what}"));
    let arr = np
        .call_method1("asarray", (value,))
        .map_err(|e| wrong(format!("must be an array of numbers: {e}")))?;
    let kind: String = arr.getattr("dtype")?.getattr("kind")?.extract()?;
    if !matches!(kind.as_str(), "f" | "i" | "u" | "b") {
        return Err(wrong(format!(
            "must be an array of real numbers, not of NumPy dtype kind '{kind}'"
        )));
    }
    let a = np.call_method1("ascontiguousarray", (&arr, "float64"))?;
    let a = a
        .cast_into::<PyArray1<f64>>()
        .map_err(|_| wrong("must be one-dimensional".to_string()))?;
    Ok(a.readonly())
}

impl PyOnline {
    /// The online compensator of `model` ([`PyOnline::new`]).
    pub fn of(model: &TlModel, sample_rate: Option<f64>, adapt: Option<&str>) -> PyResult<Self> {
        let causal = CausalTl::new(model, sample_rate).py_err()?;
        let adapt = adapt.map(str::parse::<Adapt>).transpose().py_err()?;
        Ok(Self {
            online: causal.engine(adapt, &AdaptOptions::default()).py_err()?,
            names: model.design.column_names(),
            channels: model
                .design
                .terms
                .extras()
                .iter()
                .map(|x| x.channel.clone())
                .collect(),
            max_step_s: causal.max_step_s(),
        })
    }

    fn check_channels(&self, got: usize) -> PyResult<()> {
        if got == self.channels.len() {
            Ok(())
        } else {
            Err(bad_argument(format!(
                "the model takes {} channels ({}), got {got}",
                self.channels.len(),
                self.channels.join(", ")
            )))
        }
    }
}
