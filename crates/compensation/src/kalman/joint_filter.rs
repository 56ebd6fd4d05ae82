//! Pass 1: the forward square-root Kalman filter of the joint state
//! `X = (X2, X1)` — the field model first, the constant Tolles-Lawson
//! coefficients last.
//!
//! ```text
//! X2_k = Φ(d_k) X2_{k−1} + G(d_k) w_k           (field model, super::anomaly_model)
//! X1_k = X1_{k−1}                                (coefficients: no process noise)
//! y_k  = H1_k X1 + B^h_k + Δz_k B_z,k + v_k,   v_k ~ N(0, r)
//! ```
//!
//! with `y = mag − y_ref` (a constant removed for numerical range; `B^h`
//! absorbs it), `H1_k` the design row and `Δz = alt − z0`. Ordering the
//! constant states last makes the time update touch only the `n + 2` field rows
//! of the factor ([`SqrtKalmanFilter::predict_leading`]): a step costs
//! `O(n²)` for the Carlson update plus `O(n_f n)` for the prediction (`n_f = order + 2` field states), and the
//! memory is `O(n²)` whatever the flight length.
//!
//! At the start of every contiguous run of data the field states are
//! re-initialised from their diffuse prior, independent of everything else
//! ([`SqrtKalmanFilter::reset_leading`]); the coefficients and their
//! covariance carry over. After the last sample, `X1` and its covariance
//! `P1 = U_c U_cᵀ` are the estimate from the whole flight (a constant's
//! filtered estimate at the end is also its smoothed estimate).

use super::anomaly_model::{AnomalyTransition, B_H, NoiseModel, StepTransition, X2Prior};
use super::field_filter::check_field_model;
use crate::error::{CompError, Result};
use aeromag_estimation::kalman::{Innovation, LeadingConditional, SqrtKalmanFilter};
use nalgebra::{DMatrix, DVector};

/// The pass-1 filter (module docs).
#[derive(Debug, Clone)]
pub struct JointFilter {
    filter: SqrtKalmanFilter,
    m: usize,
    noise: NoiseModel,
    /// Number of field states and the index of `B_z` among them.
    x2_dim: usize,
    b_z: usize,
    x2_factor: DMatrix<f64>,
    x1_prior_cov: DMatrix<f64>,
    transition: StepTransition,
    h: Vec<f64>,
    fresh: bool,
    /// Random-walk intensities of the first coefficients (online
    /// adaptation, [`Self::with_drift`]), coefficient units per √s; empty:
    /// every coefficient constant (the thesis).
    drift_per_sqrt_s: Vec<f64>,
    /// `Φ`, `G` over the field states and the drifting coefficients.
    phi_drift: DMatrix<f64>,
    g_drift: DMatrix<f64>,
}

impl JointFilter {
    /// A filter for `m = coef_prior_mean.len()` coefficients with prior mean
    /// `coef_prior_mean` and independent prior standard deviations
    /// `coef_prior_std` (coefficient units, > 0), the field prior `x2_prior`
    /// and the noise intensities `noise`.
    pub fn new(
        coef_prior_mean: &[f64],
        coef_prior_std: &[f64],
        x2_prior: &X2Prior,
        noise: NoiseModel,
    ) -> Result<Self> {
        let m = coef_prior_mean.len();
        if coef_prior_std.len() != m || coef_prior_std.iter().any(|s| !(*s > 0.0 && s.is_finite()))
        {
            return Err(CompError::setting(
                "coefficient prior: one finite positive standard deviation per coefficient",
            ));
        }
        check_field_model(&noise, x2_prior)?;
        let x2_dim = x2_prior.dim();
        let n = x2_dim + m;
        let mut x0 = vec![0.0; n];
        x0[x2_dim..].copy_from_slice(coef_prior_mean);
        let mut s0 = DMatrix::zeros(n, n);
        let x2_factor = x2_prior.factor();
        s0.view_mut((0, 0), (x2_dim, x2_dim)).copy_from(&x2_factor);
        for (j, s) in coef_prior_std.iter().enumerate() {
            s0[(x2_dim + j, x2_dim + j)] = *s;
        }
        let filter = SqrtKalmanFilter::new(&x0, &s0).map_err(est)?;
        Ok(Self {
            filter,
            m,
            noise,
            x2_dim,
            b_z: x2_prior.b_z(),
            x2_factor,
            x1_prior_cov: DMatrix::from_diagonal(&DVector::from_iterator(
                m,
                coef_prior_std.iter().map(|s| s * s),
            )),
            transition: StepTransition::new(AnomalyTransition::new(&noise, x2_prior.order)),
            h: vec![0.0; n],
            fresh: true,
            drift_per_sqrt_s: Vec::new(),
            phi_drift: DMatrix::zeros(0, 0),
            g_drift: DMatrix::zeros(0, 0),
        })
    }

    /// Let the first `drift_per_sqrt_s.len()` coefficients drift as random
    /// walks, `dX1_j/dt = w_j`, `E[w_j(t) w_j(t')] = σ_j² δ(t − t')`, with
    /// `σ_j = drift_per_sqrt_s[j]` (coefficient units per √s): their
    /// variance grows by `σ_j² Δt` per step of [`Self::step_timed`]. The
    /// thesis' coefficients are constant; an online filter over hours lets
    /// the permanent terms follow a creeping magnetisation
    /// ([`super::online`]). A negative or non-finite intensity, or more than
    /// `m`, is [`CompError::InvalidSetting`].
    pub fn with_drift(mut self, drift_per_sqrt_s: &[f64]) -> Result<Self> {
        if drift_per_sqrt_s.len() > self.m
            || drift_per_sqrt_s
                .iter()
                .any(|s| !(*s >= 0.0 && s.is_finite()))
        {
            return Err(CompError::setting(format!(
                "coefficient drift: at most {} finite intensities ≥ 0, got {drift_per_sqrt_s:?}",
                self.m
            )));
        }
        let k = self.x2_dim + drift_per_sqrt_s.len();
        self.drift_per_sqrt_s = drift_per_sqrt_s.to_vec();
        self.phi_drift = DMatrix::identity(k, k);
        self.g_drift = DMatrix::zeros(k, k);
        Ok(self)
    }

    /// Number of coefficients `m`.
    pub fn n_coefficients(&self) -> usize {
        self.m
    }

    /// Start a new contiguous run: the field states get their prior again,
    /// independent of the coefficients; the next step is not predicted.
    pub fn start_run(&mut self) -> Result<()> {
        self.filter
            .reset_leading(&vec![0.0; self.x2_dim], &self.x2_factor)
            .map_err(est)?;
        self.fresh = true;
        Ok(())
    }

    /// One sample: predict over the path length `d_m` (m, ignored on the
    /// first sample of a run), then update with the design row `h1` (length
    /// `m`), the altitude offset `dz_m = alt − z0` (m) and the centred
    /// reading `y_nt` (nT). Returns the innovation.
    pub fn step(&mut self, d_m: f64, h1: &[f64], dz_m: f64, y_nt: f64) -> Result<Innovation> {
        self.step_timed(d_m, 0.0, h1, dz_m, y_nt)
    }

    /// [`Self::step`] over a step of `dt_s` seconds: the drifting
    /// coefficients ([`Self::with_drift`]) gain their variance `σ² dt_s`
    /// in the same time update (none at a run's first sample).
    pub fn step_timed(
        &mut self,
        d_m: f64,
        dt_s: f64,
        h1: &[f64],
        dz_m: f64,
        y_nt: f64,
    ) -> Result<Innovation> {
        self.step_gated(d_m, dt_s, h1, dz_m, y_nt, f64::INFINITY)
            .map(|(nu, _)| nu)
    }

    /// [`Self::step_timed`], the update left out when the normalised
    /// innovation squared `ν²/σ²` exceeds `gate_nis` (an outlier: the
    /// estimate is only predicted). Returns the innovation and whether it
    /// was used.
    pub fn step_gated(
        &mut self,
        d_m: f64,
        dt_s: f64,
        h1: &[f64],
        dz_m: f64,
        y_nt: f64,
        gate_nis: f64,
    ) -> Result<(Innovation, bool)> {
        if h1.len() != self.m {
            return Err(CompError::data(format!(
                "design row of length {} for {} coefficients",
                h1.len(),
                self.m
            )));
        }
        if !self.fresh {
            let (phi, g) = self.transition.step(d_m)?;
            if self.drift_per_sqrt_s.is_empty() {
                self.filter.predict_leading(phi, g).map_err(est)?;
            } else {
                if !(dt_s >= 0.0 && dt_s.is_finite()) {
                    return Err(CompError::setting(format!(
                        "time step {dt_s} s must be finite and ≥ 0"
                    )));
                }
                let f = self.x2_dim;
                self.phi_drift.view_mut((0, 0), (f, f)).copy_from(phi);
                self.g_drift.view_mut((0, 0), (f, f)).copy_from(g);
                for (j, s) in self.drift_per_sqrt_s.iter().enumerate() {
                    self.g_drift[(f + j, f + j)] = s * dt_s.sqrt();
                }
                self.filter
                    .predict_leading(&self.phi_drift, &self.g_drift)
                    .map_err(est)?;
            }
        }
        self.fresh = false;
        self.h[..self.x2_dim].fill(0.0);
        self.h[B_H] = 1.0;
        self.h[self.b_z] = dz_m;
        self.h[self.x2_dim..].copy_from_slice(h1);
        let r = self.noise.r_nt2;
        if gate_nis.is_finite() {
            let nu = self.filter.innovation(&self.h, y_nt, r).map_err(est)?;
            // NaN too: no innovation to learn from.
            let within = nu.value * nu.value <= gate_nis * nu.variance;
            if !within {
                return Ok((nu, false));
            }
        }
        Ok((self.filter.update(&self.h, y_nt, r).map_err(est)?, true))
    }

    /// The current coefficient estimate `X1`.
    pub fn coefficients(&self) -> &[f64] {
        &self.filter.state().as_slice()[self.x2_dim..]
    }

    /// The current field-state estimate `X2`.
    pub fn field_state(&self) -> &[f64] {
        &self.filter.state().as_slice()[..self.x2_dim]
    }

    /// The standard deviations of the coefficients, `√diag(U_c U_cᵀ)`.
    pub fn coefficient_std(&self) -> Vec<f64> {
        (self.x2_dim..self.x2_dim + self.m)
            .map(|i| self.filter.variance(i).sqrt())
            .collect()
    }

    /// The covariance of the coefficients, `U_c U_cᵀ` (`m × m`).
    pub fn coefficient_covariance(&self) -> DMatrix<f64> {
        self.filter.trailing_covariance(self.x2_dim)
    }

    /// The upper-triangular factor `U_c` of the coefficient covariance.
    pub fn coefficient_factor(&self) -> DMatrix<f64> {
        self.filter
            .factor()
            .view((self.x2_dim, self.x2_dim), (self.m, self.m))
            .into_owned()
    }

    /// The field states given the coefficients, from the current joint
    /// estimate ([`SqrtKalmanFilter::leading_conditional`]): with `X1 = X̂1`
    /// of the whole flight it is the filtered estimate of pass 2 at this
    /// sample, a restart point for the smoother.
    pub fn field_conditional(&self) -> Result<LeadingConditional> {
        self.filter.leading_conditional(self.x2_dim).map_err(est)
    }

    /// The prior covariance of the coefficients (diagonal).
    pub fn coefficient_prior_covariance(&self) -> &DMatrix<f64> {
        &self.x1_prior_cov
    }
}

/// Map an estimation error into this crate's error.
pub(crate) fn est(e: aeromag_estimation::EstError) -> CompError {
    CompError::estimation("Kalman filter")(e)
}
