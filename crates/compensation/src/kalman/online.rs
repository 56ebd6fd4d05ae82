//! The thesis' forward Kalman filter run online: the coefficients `X1` and
//! the field states `X2` updated as the aircraft flies (issue 21's adaptive
//! mode), one [`super::JointFilter`] step per sample.
//!
//! The model is that of [`super`] (module docs there): `y_k = H1_k X1 +
//! B^h_k + Δz_k B_z,k + v_k` with the along-track field chain `X2`. Three
//! changes for a stream of hours:
//!
//! - **The field includes the time variations.** No base station on
//!   board: the diurnal variation and its micropulsations are part of the
//!   field, and the chain's `q₁` is the calibration default × 10³
//!   ([`NoiseModel::on_board_for`], where the factor is measured).
//!
//! - **The permanent coefficients may drift.** The thesis' `X1` is
//!   constant, so its covariance shrinks like `1/N` and after hours the
//!   filter can no longer follow a magnetisation that creeps. Here the
//!   permanent terms (`p_x, p_y, p_z`: the aircraft's permanent moment,
//!   what creeps) are random walks of intensity `σ_p` (nT/√h,
//!   [`OnlineKalmanSettings::permanent_drift_nt_per_sqrt_h`]); the induced
//!   and eddy terms (the aircraft's shape and materials) stay constant.
//!   A random walk's variance grows by `σ_p² Δt`: the filter weights the
//!   last `≈ σ_v / σ_p` hours (with `σ_v` how well one hour of flight
//!   determines `p`), neither forgets the calibration at once nor clings
//!   to it for ever. Without drift (`σ_p = 0`) the filter is the thesis'.
//! - **The start is the calibration.** `X1` starts at the model's
//!   coefficients with their standard deviations (floored at
//!   [`OnlineKalmanSettings::coef_std_floor`], times
//!   [`OnlineKalmanSettings::coef_std_scale`]): the filter corrects the
//!   calibration rather than learning from nothing, and the field states
//!   start diffuse at every run ([`super::X2Prior`]).
//!
//! The reading is centred by the first reading (a constant that `B^h`
//! absorbs) and the altitude by the first altitude (`Δz`; 0 when the
//! altitude is unknown). Cost per sample: one Carlson update of
//! `n_f + m` states and a time update of the `n_f + 3` leading ones
//! (`n_f` field states): `O((n_f + m)²)`.
//!
//! ```
//! use aeromag_compensation::kalman::online::{OnlineKalman, OnlineKalmanSettings};
//! use aeromag_compensation::tolles_lawson::adaptive::{AdaptiveTl, Navigation};
//! use aeromag_compensation::tolles_lawson::online::OnlineSample;
//! use aeromag_compensation::tolles_lawson::{Design, TermSet};
//! let design = Design::new(TermSet::parse("p3")?);
//! let kalman = OnlineKalman::new(&design, &[10.0, 0.0, 0.0], &[1.0; 3], &OnlineKalmanSettings::default())?;
//! let mut tl = AdaptiveTl::new(&design, 0.15, Box::new(kalman))?;
//! let nav = Navigation { speed_m_s: 70.0, alt_m: 3000.0 };
//! let out = tl.push(&OnlineSample { time_s: 0.0, flux_nt: [50_000.0, 0.0, 0.0], mag_nt: 50_010.0, channels: &[] }, nav);
//! assert_eq!(out.compensated_nt, 50_000.0);
//! assert_eq!(tl.coefficient_std().len(), 3);
//! # Ok::<(), aeromag_compensation::CompError>(())
//! ```

use super::anomaly_model::{NoiseModel, X2Prior};
use super::joint_filter::JointFilter;
use crate::error::{CompError, Result};
use crate::tolles_lawson::Design;
use crate::tolles_lawson::adaptive::{AdaptiveStep, CoefficientEstimator, OUTLIER_NIS, Update};
use crate::tolles_lawson::terms::Column;
use serde::{Deserialize, Serialize};

/// The largest random walk of the permanent coefficients
/// ([`OnlineKalmanSettings::permanent_drift_nt_per_sqrt_h`]), nT/√h: a
/// hundred times the default, 50 nT in an hour, far beyond an airframe's
/// creep.
pub const MAX_PERMANENT_DRIFT_NT_PER_SQRT_H: f64 = 50.0;

/// Settings of the online Kalman filter ([module docs](self)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct OnlineKalmanSettings {
    /// Noise intensities of the field model and the reading (default
    /// [`NoiseModel::on_board_for`] the default order: no base station on
    /// board, the time variations are part of the field).
    pub noise: NoiseModel,
    /// Order and prior of the field states at every run start.
    pub field_prior: X2Prior,
    /// Random-walk intensity of the permanent coefficients, nT/√h
    /// (default 0.5: a permanent term may wander by ≈ 0.5 nT in an hour,
    /// 1.1 nT in five). Larger follows a creep with less lag but lets the
    /// coefficients jitter: on the demo's 5-hour creeping flight (17 nT of
    /// creep on `p_x`), calibration seeds 1–6, last hour over first
    /// 0.35–1.41 at 0.5, 0.41–1.58 at 1, 0.65–1.69 at 2 nT/√h.
    pub permanent_drift_nt_per_sqrt_h: f64,
    /// Smallest starting standard deviation of a coefficient, in its own
    /// units (default 0.01; a least-squares model's standard deviations
    /// can be tiny, or NaN when unknown).
    pub coef_std_floor: f64,
    /// Factor on the model's standard deviations at the start (default 3:
    /// a calibration's statistical error understates its error on another
    /// flight).
    pub coef_std_scale: f64,
    /// Which coefficients the filter estimates (default all); the others
    /// keep the model's values.
    pub terms: AdaptedTerms,
}

/// Which coefficients adapt ([module docs](self)).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum AdaptedTerms {
    /// The permanent terms only (what creeps); the induced and eddy terms
    /// keep the calibration's values. On the 5-hour creeping flight at
    /// 3000 m (seed 3) it does worse than [`AdaptedTerms::All`], 0.33–0.89
    /// nT per hour against 0.12–0.16: the flight also corrects the
    /// calibration's induced and eddy terms.
    Permanent,
    /// Every coefficient (the thesis' `X1`).
    #[default]
    All,
}

impl Default for OnlineKalmanSettings {
    fn default() -> Self {
        Self {
            noise: NoiseModel::on_board_for(X2Prior::default().order),
            field_prior: X2Prior::default(),
            permanent_drift_nt_per_sqrt_h: 0.5,
            coef_std_floor: 0.01,
            coef_std_scale: 3.0,
            terms: AdaptedTerms::All,
        }
    }
}

/// The thesis' filter as a [`CoefficientEstimator`] ([module docs](self)).
#[derive(Debug, Clone)]
pub struct OnlineKalman {
    filter: JointFilter,
    /// State order of the estimated coefficients: the drifting
    /// (permanent) columns first; `order[j]` is the column of the filter's
    /// coefficient `j`.
    order: Vec<usize>,
    /// The columns held at the model's values.
    held: Vec<usize>,
    /// The coefficients in column order, after the last update.
    coef: Vec<f64>,
    row: Vec<f64>,
    y_ref: Option<f64>,
    z0: Option<f64>,
    /// `Σ ν²/σ²` and the number of updates.
    nis: (f64, u64),
}

impl OnlineKalman {
    /// The filter for `design`, starting at the model's coefficients `coef`
    /// with standard deviations `coef_std` (column order; NaN: unknown).
    /// Bad settings are [`CompError::InvalidSetting`].
    pub fn new(
        design: &Design,
        coef: &[f64],
        coef_std: &[f64],
        settings: &OnlineKalmanSettings,
    ) -> Result<Self> {
        let n = design.n_columns();
        if coef.len() != n || coef_std.len() != n {
            return Err(CompError::setting(format!(
                "{} coefficients and {} standard deviations for a design of {n} columns",
                coef.len(),
                coef_std.len()
            )));
        }
        let (floor, scale) = (settings.coef_std_floor, settings.coef_std_scale);
        if !(floor > 0.0 && floor.is_finite() && scale > 0.0 && scale.is_finite()) {
            return Err(CompError::setting(format!(
                "coefficient prior: floor {floor} and scale {scale} must be finite and > 0"
            )));
        }
        let drift = settings.permanent_drift_nt_per_sqrt_h;
        if !(0.0..=MAX_PERMANENT_DRIFT_NT_PER_SQRT_H).contains(&drift) {
            return Err(CompError::setting(format!(
                "permanent drift {} nT/√h must be from 0 to {MAX_PERMANENT_DRIFT_NT_PER_SQRT_H}",
                aeromag_core::error::shown(drift)
            )));
        }
        settings.noise.check(settings.field_prior.order)?;
        let permanent = design
            .terms
            .column_indices(|c| matches!(c, Column::Direction(_)));
        let mut order = permanent.clone();
        let others = (0..n).filter(|k| !permanent.contains(k));
        let held: Vec<usize> = match settings.terms {
            AdaptedTerms::Permanent => others.collect(),
            AdaptedTerms::All => {
                order.extend(others);
                Vec::new()
            }
        };
        let mean: Vec<f64> = order.iter().map(|&k| coef[k]).collect();
        let std: Vec<f64> = order
            .iter()
            .map(|&k| {
                let s = coef_std[k] * scale;
                if s.is_finite() { s.max(floor) } else { floor }
            })
            .collect();
        let per_sqrt_s = drift / 3600f64.sqrt();
        let filter = JointFilter::new(&mean, &std, &settings.field_prior, settings.noise)?
            .with_drift(&vec![per_sqrt_s; permanent.len()])?;
        Ok(Self {
            filter,
            row: vec![0.0; order.len()],
            order,
            held,
            coef: coef.to_vec(),
            y_ref: None,
            z0: None,
            nis: (0.0, 0),
        })
    }
}

impl CoefficientEstimator for OnlineKalman {
    fn coefficients(&self) -> &[f64] {
        &self.coef
    }

    /// Held coefficients have standard deviation 0 (not estimated).
    fn coefficient_std(&self) -> Vec<f64> {
        let s = self.filter.coefficient_std();
        let mut out = vec![0.0; self.coef.len()];
        for (j, &k) in self.order.iter().enumerate() {
            out[k] = s[j];
        }
        out
    }

    fn start_run(&mut self) -> Result<()> {
        self.filter.start_run()
    }

    fn update(&mut self, step: &AdaptiveStep) -> Result<Update> {
        for (r, &k) in self.row.iter_mut().zip(&self.order) {
            *r = step.row[k];
        }
        let held: f64 = self.held.iter().map(|&k| step.row[k] * self.coef[k]).sum();
        let y = step.y_nt - held;
        let y_ref = *self.y_ref.get_or_insert(y);
        let dz_m = match (self.z0, step.alt_m.is_finite()) {
            (Some(z0), true) => step.alt_m - z0,
            (None, true) => {
                self.z0 = Some(step.alt_m);
                0.0
            }
            (_, false) => 0.0,
        };
        let (nu, used) = self.filter.step_gated(
            step.along_track_m,
            step.dt_s,
            &self.row,
            dz_m,
            y - y_ref,
            OUTLIER_NIS,
        )?;
        if !used {
            return Ok(Update::Outlier);
        }
        let z = nu.normalized();
        self.nis = (self.nis.0 + z * z, self.nis.1 + 1);
        for (j, &k) in self.order.iter().enumerate() {
            self.coef[k] = self.filter.coefficients()[j];
        }
        Ok(Update::Learnt)
    }

    fn needs_speed(&self) -> bool {
        true
    }

    fn mean_nis(&self) -> Option<f64> {
        (self.nis.1 > 0).then(|| self.nis.0 / self.nis.1 as f64)
    }

    fn boxed_clone(&self) -> Box<dyn CoefficientEstimator> {
        Box::new(self.clone())
    }
}
