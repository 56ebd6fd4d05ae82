//! Adaptive online compensation from a model file: the coefficients
//! follow the aircraft as it flies (`aeromag stream --adapt kalman|rls`).

use super::causal::CausalTl;
use crate::error::{Error, Result};
use crate::flight::{Flight, SensorColumns, TlInputs};
use crate::tolles_lawson::ground_speed;
use aeromag_compensation::kalman::NoiseModel;
use aeromag_compensation::kalman::online::{OnlineKalman, OnlineKalmanSettings};
use aeromag_compensation::model_file::{KalmanSettings, MethodSettings};
use aeromag_compensation::tolles_lawson::adaptive::{AdaptiveTl, CoefficientEstimator, Navigation};
use aeromag_compensation::tolles_lawson::online::{
    OnlineOutput, OnlineSample, OnlineTl, SampleStatus,
};
use aeromag_compensation::tolles_lawson::rls::{Rls, RlsSettings};
use serde::{Deserialize, Serialize};

/// How the coefficients adapt.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Adapt {
    /// The thesis' forward Kalman filter with the field states
    /// ([`aeromag_compensation::kalman::online`]).
    Kalman,
    /// Recursive least squares with forgetting, for comparison
    /// ([`aeromag_compensation::tolles_lawson::rls`]).
    Rls,
}

impl Adapt {
    /// `kalman` or `rls`.
    pub fn name(self) -> &'static str {
        match self {
            Adapt::Kalman => "kalman",
            Adapt::Rls => "rls",
        }
    }
}

impl std::str::FromStr for Adapt {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "kalman" => Ok(Adapt::Kalman),
            "rls" => Ok(Adapt::Rls),
            _ => Err(Error::bad_input(format!(
                "unknown adaptation `{s}`: kalman or rls"
            ))),
        }
    }
}

/// The adaptive estimator and its settings.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct AdaptOptions {
    /// The Kalman filter's settings. The field-model order is the model
    /// file's when it records one (a Kalman model), with the on-board
    /// intensities of that order ([`NoiseModel::on_board_for`]; the model's
    /// own were tuned with the base station subtracted).
    pub kalman: OnlineKalmanSettings,
    /// `q₁` of the field model, nT²/m^(2n−1), instead of the on-board
    /// default (`stream --field-q1`).
    pub field_q1: Option<f64>,
    /// The RLS settings.
    pub rls: RlsSettings,
}

/// A model applied sample by sample with fixed or adapting coefficients:
/// what `aeromag stream` and Python's `OnlineCompensator` run.
#[derive(Debug, Clone)]
pub enum OnlineEngine {
    /// The model's coefficients ([`OnlineTl`]).
    Fixed(Box<OnlineTl>),
    /// Coefficients adapting as the samples arrive ([`AdaptiveTl`]).
    Adaptive(Box<AdaptiveTl>),
}

impl OnlineEngine {
    /// Compensate one sample (the navigation is used only when adapting).
    /// An interference beyond any magnetic field
    /// ([`aeromag_io::MAX_FIELD_NT`]: a model file that does not belong to
    /// the data) is no compensated value: the sample is `Missing`.
    pub fn push(&mut self, sample: &OnlineSample, nav: Navigation) -> OnlineOutput {
        self.push_told(sample, nav).0
    }

    /// [`OnlineEngine::push`], and whether the sample is `Missing` because
    /// its interference was beyond any magnetic field (for a message).
    pub fn push_told(&mut self, sample: &OnlineSample, nav: Navigation) -> (OnlineOutput, bool) {
        let o = match self {
            OnlineEngine::Fixed(o) => o.push(sample),
            OnlineEngine::Adaptive(a) => a.push(sample, nav),
        };
        // NaN too: neither is a compensated value.
        let within_any_field = o.interference_nt.abs() <= aeromag_io::MAX_FIELD_NT;
        if o.status.is_compensated() && !within_any_field {
            (OnlineOutput::not(SampleStatus::Missing), true)
        } else {
            (o, false)
        }
    }

    /// When adapting, the samples not learnt from as outliers
    /// ([`aeromag_compensation::tolles_lawson::adaptive::OUTLIER_NIS`]).
    pub fn outliers(&self) -> Option<u64> {
        match self {
            OnlineEngine::Fixed(_) => None,
            OnlineEngine::Adaptive(a) => Some(a.outliers()),
        }
    }

    /// Forget the stream's run state (adapted coefficients are kept).
    pub fn reset(&mut self) {
        match self {
            OnlineEngine::Fixed(o) => o.reset(),
            OnlineEngine::Adaptive(a) => a.reset(),
        }
    }

    /// When adapting, the current coefficients and their standard
    /// deviations (column order).
    pub fn coefficients(&self) -> Option<(&[f64], Vec<f64>)> {
        match self {
            OnlineEngine::Fixed(_) => None,
            OnlineEngine::Adaptive(a) => Some((a.coefficients(), a.coefficient_std())),
        }
    }
}

impl CausalTl {
    /// The model applied sample by sample: its own coefficients
    /// (`adapt = None`) or adapting with `adapt`.
    pub fn engine(&self, adapt: Option<Adapt>, opts: &AdaptOptions) -> Result<OnlineEngine> {
        Ok(match adapt {
            None => OnlineEngine::Fixed(Box::new(self.online()?)),
            Some(a) => OnlineEngine::Adaptive(Box::new(self.adaptive(a, opts)?)),
        })
    }

    /// The model's coefficients adapting sample by sample with `adapt`,
    /// seeded with the model's values and standard deviations.
    pub fn adaptive(&self, adapt: Adapt, opts: &AdaptOptions) -> Result<AdaptiveTl> {
        let model = self.model();
        let coef = model.coef();
        let std: Vec<f64> = model.coefficients.iter().map(|c| c.std).collect();
        let estimator: Box<dyn CoefficientEstimator> = match adapt {
            Adapt::Kalman => {
                let mut settings = opts.kalman.clone();
                if let MethodSettings::Kalman(KalmanSettings {
                    field_order: Some(order),
                    ..
                }) = &model.method
                    && *order != settings.field_prior.order
                {
                    settings.field_prior.order = *order;
                    settings.noise = NoiseModel::on_board_for(*order);
                }
                if let Some(q1) = opts.field_q1 {
                    settings.noise.q1 = q1;
                }
                Box::new(OnlineKalman::new(&model.design, &coef, &std, &settings)?)
            }
            Adapt::Rls => Box::new(Rls::new(&coef, &std, opts.rls)?),
        };
        Ok(AdaptiveTl::new(
            &model.design,
            self.max_step_s(),
            estimator,
        )?)
    }

    /// A whole recorded flight compensated sample by sample by the
    /// adaptive compensator: the interference of every row (NaN where not
    /// compensated) and the coefficients with their standard deviations
    /// every `every_s` seconds (the first compensated sample, then the
    /// first after each multiple). The ground speed comes from `vn`, `ve`
    /// (else the positions), the altitude from `alt` when present.
    pub fn adapt_flight(
        &self,
        flight: &Flight,
        adapt: Adapt,
        opts: &AdaptOptions,
        every_s: f64,
    ) -> Result<AdaptedFlight> {
        let mut tl = self.adaptive(adapt, opts)?;
        let design = self.model().design.clone();
        let cols = TlInputs::of_sensor(flight, &SensorColumns::default())?
            .with_extras(flight, design.terms.extras())?;
        let speed = ground_speed(flight)?;
        let alt = flight.column("alt");
        let mut channels = vec![0.0; cols.channels.len()];
        let mut snapshots = Vec::new();
        let mut next_s = f64::NEG_INFINITY;
        let interference_nt = (0..flight.n_rows())
            .map(|k| {
                for (c, s) in channels.iter_mut().zip(&cols.channels) {
                    *c = s[k];
                }
                let sample = OnlineSample {
                    time_s: cols.time[k],
                    flux_nt: cols.flux.map(|f| f[k]),
                    mag_nt: cols.mag[k],
                    channels: &channels,
                };
                let nav = Navigation {
                    speed_m_s: speed[k],
                    alt_m: alt.map_or(f64::NAN, |a| a[k]),
                };
                let out = tl.push(&sample, nav);
                if out.status.is_compensated() && sample.time_s >= next_s {
                    snapshots.push(CoefficientSnapshot {
                        time_s: sample.time_s,
                        values: tl.coefficients().to_vec(),
                        std: tl.coefficient_std(),
                    });
                    next_s = if every_s > 0.0 {
                        (sample.time_s / every_s).floor() * every_s + every_s
                    } else {
                        f64::INFINITY
                    };
                }
                out.interference_nt
            })
            .collect();
        let time_s = cols.time.iter().rev().copied().find(|t| t.is_finite());
        Ok(AdaptedFlight {
            interference_nt,
            last: CoefficientSnapshot {
                time_s: time_s.unwrap_or(f64::NAN),
                values: tl.coefficients().to_vec(),
                std: tl.coefficient_std(),
            },
            snapshots,
            mean_nis: tl.mean_nis(),
            failed_updates: tl.failed_updates(),
            outliers: tl.outliers(),
        })
    }
}

/// The coefficients at one time.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CoefficientSnapshot {
    /// Time, s.
    pub time_s: f64,
    /// Coefficients, column order.
    pub values: Vec<f64>,
    /// Their standard deviations.
    pub std: Vec<f64>,
}

/// A flight compensated by the adaptive compensator
/// ([`CausalTl::adapt_flight`]).
#[derive(Debug, Clone, PartialEq)]
pub struct AdaptedFlight {
    /// Interference of every row, nT (NaN where not compensated).
    pub interference_nt: Vec<f64>,
    /// The coefficients along the flight.
    pub snapshots: Vec<CoefficientSnapshot>,
    /// The coefficients after the flight's last sample.
    pub last: CoefficientSnapshot,
    /// The Kalman filter's mean normalised innovation squared (≈ 1 when its
    /// field model fits the flight; `None` for RLS).
    pub mean_nis: Option<f64>,
    /// Samples the estimator could not learn from (numerically).
    pub failed_updates: u64,
    /// Samples not learnt from as outliers
    /// ([`aeromag_compensation::tolles_lawson::adaptive::OUTLIER_NIS`]).
    pub outliers: u64,
}
