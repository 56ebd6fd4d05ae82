//! A Tolles-Lawson model under the causal convention, on a whole flight.

use crate::compensate::{Compensator, OutputColumns};
use crate::error::{Error, Result};
use crate::flight::{Flight, GAP_FACTOR, SensorColumns, TlInputs};
use crate::observer::Observer;
use crate::tolles_lawson::{CompensateSensors, SensorsCompensated, SensorsModel, TL_OUTPUT};
use aeromag_compensation::model_file::TlModel;
use aeromag_compensation::tolles_lawson::online::OnlineTl;
use aeromag_compensation::tolles_lawson::segments::split_at_steps;
use aeromag_core::error::shown;

/// A model applied under the causal convention ([module docs](super)):
/// what an on-board compensator gives, sample for sample, on a recorded
/// flight.
#[derive(Debug, Clone)]
pub struct CausalTl {
    model: TlModel,
    max_step_s: f64,
}

/// The sample rates a causal compensation takes, Hz: a reading every
/// 100 s to 100 kHz. Runs break at gaps of a few sample intervals, so a
/// rate far off the data's breaks every step (or none).
pub const SAMPLE_RATE_RANGE_HZ: (f64, f64) = (0.01, 1e5);

impl CausalTl {
    /// `model` under the causal convention. Runs break at time steps over
    /// [`GAP_FACTOR`] × the sample interval: `1 / sample_rate_hz` when
    /// given, else the calibration flight's, recorded in the model
    /// (`fit.sample_interval_s`); a model file without it and no rate is
    /// bad input.
    pub fn new(model: &TlModel, sample_rate_hz: Option<f64>) -> Result<Self> {
        let (lo, hi) = SAMPLE_RATE_RANGE_HZ;
        let interval_s = match sample_rate_hz {
            Some(hz) if (lo..=hi).contains(&hz) => 1.0 / hz,
            Some(hz) => {
                return Err(Error::bad_input(format!(
                    "sample rate {} Hz: must be from {lo} to {hi:e} Hz",
                    shown(hz)
                )));
            }
            None => match model.fit.sample_interval_s {
                Some(s) if (lo..=hi).contains(&(1.0 / s)) => s,
                Some(s) => {
                    return Err(Error::bad_input(format!(
                        "the model's calibration sample interval {} s (fit.sample_interval_s) \
                         is not that of a sample rate from {lo} to {hi:e} Hz",
                        shown(s)
                    )));
                }
                None => {
                    return Err(Error::bad_input(
                        "the model file does not record its calibration's sample interval \
                         (written before it was): give the sample rate (--sample-rate HZ)",
                    ));
                }
            },
        };
        Ok(Self {
            model: model.clone(),
            max_step_s: GAP_FACTOR * interval_s,
        })
    }

    /// The longest time step within a run, s.
    pub fn max_step_s(&self) -> f64 {
        self.max_step_s
    }

    /// The model.
    pub fn model(&self) -> &TlModel {
        &self.model
    }

    /// The same compensation one sample at a time ([`OnlineTl`]).
    pub fn online(&self) -> Result<OnlineTl> {
        Ok(OnlineTl::new(
            &self.model.design,
            &self.model.coef(),
            self.max_step_s,
        )?)
    }
}

impl Compensator for CausalTl {
    fn output(&self) -> OutputColumns {
        TL_OUTPUT
    }

    /// `A c` under the causal convention on every run (usable rows, time
    /// steps at most [`CausalTl::max_step_s`]; line changes do not
    /// matter), NaN elsewhere.
    fn interference_observed(
        &self,
        flight: &Flight,
        _observer: &mut dyn Observer,
    ) -> Result<Vec<f64>> {
        self.interference_at(flight, &SensorColumns::default())
    }
}

impl CausalTl {
    /// The interference (nT) at the sensor `sensor` of `flight` under the
    /// causal convention, NaN outside the runs.
    pub fn interference_at(&self, flight: &Flight, sensor: &SensorColumns) -> Result<Vec<f64>> {
        crate::tolles_lawson::check_time_unit(&self.model, flight)?;
        let design = self.model.design.causal();
        let cols =
            TlInputs::of_sensor(flight, sensor)?.with_extras(flight, design.terms.extras())?;
        let (runs, _) = split_at_steps(cols.time, None, &cols.usable(), self.max_step_s, 1);
        let whole = cols.whole();
        let coef = self.model.coef();
        let mut out = vec![f64::NAN; flight.n_rows()];
        for r in runs {
            let s = whole.slice(r.clone());
            let v = design.interference_with(&coef, s.time, s.flux, s.channels);
            out[r].copy_from_slice(&v);
        }
        Ok(out)
    }
}

/// A multi-sensor model under the causal convention: each sensor's model
/// as [`CausalTl`] (each with the sample interval its model records, or
/// `sample_rate_hz`), the same columns as the batch path
/// ([`crate::tolles_lawson::SensorsCompensated`]).
#[derive(Debug, Clone)]
pub struct CausalSensors {
    model: SensorsModel,
    causal: Vec<CausalTl>,
}

impl CausalSensors {
    /// `model` under the causal convention (bad input as [`CausalTl::new`]).
    pub fn new(model: &SensorsModel, sample_rate_hz: Option<f64>) -> Result<Self> {
        let causal = model
            .sensors
            .iter()
            .map(|s| CausalTl::new(&s.model, sample_rate_hz))
            .collect::<Result<_>>()?;
        Ok(Self {
            model: model.clone(),
            causal,
        })
    }
}

impl CompensateSensors for CausalSensors {
    fn compensate(&self, flight: &Flight) -> Result<SensorsCompensated> {
        SensorsCompensated::of(&self.model, flight, |k, cols| {
            self.causal[k].interference_at(flight, cols)
        })
    }
}
