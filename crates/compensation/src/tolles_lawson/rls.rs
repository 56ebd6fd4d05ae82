//! Recursive least squares with exponential forgetting: the textbook
//! adaptive alternative to the online Kalman filter
//! ([`crate::kalman::online`]), for comparison (issue 21).
//!
//! The parameters are the coefficients and one offset `o` that stands for
//! the external field, `y_k = h_k · c + o + v_k`. With forgetting factor
//! `λ_k = exp(−Δt_k / τ)` (memory `τ`, s):
//!
//! ```text
//! e = y − [h, 1]·θ,   g = P [h, 1]ᵀ / (r + [h, 1] P [h, 1]ᵀ),   θ ← θ + g e,
//! P ← (P − g [h, 1] P) / λ_k
//! ```
//!
//! (Ljung & Söderström 1983, §2.6; `P` is symmetrised after each step.)
//! Unlike the Kalman filter it has no model of the field: geology and the
//! diurnal variation that the single offset cannot follow go into the
//! coefficients, and in straight flight, when the rows hardly change, `P`
//! grows as `λ^{−k}` in the unexcited directions ("wind-up") until an
//! excitation throws the coefficients. That is why the adaptive default is
//! the Kalman filter; this one shows what it avoids. The offset's variance
//! is reset at every run start (the field jumps across a gap).

use super::adaptive::{AdaptiveStep, CoefficientEstimator, OUTLIER_NIS, Update};
use crate::error::{CompError, Result};
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// The shortest memory of [`Rls`], s. The coefficients creep over tens of
/// minutes; a memory of a few dozen samples per coefficient lets them
/// follow the field and the noise instead. On the simulated calibration
/// flight (10 Hz, 18 terms) a memory of 30 s made the interference 311 nT
/// where it is 23 nT (60 s: 23.2 nT); five minutes holds 3000 samples at
/// 10 Hz and 300 at 1 Hz.
pub const MIN_MEMORY_S: f64 = 300.0;

/// Settings of [`Rls`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct RlsSettings {
    /// Memory `τ`, s (default 1800: half an hour; at least
    /// [`MIN_MEMORY_S`]).
    pub memory_s: f64,
    /// Variance of the reading's noise `r`, nT² (default 0.01).
    pub noise_nt2: f64,
    /// Prior standard deviation of the offset, nT (default 1000: diffuse).
    pub offset_std_nt: f64,
    /// Smallest starting standard deviation of a coefficient (default 0.01).
    pub coef_std_floor: f64,
    /// Fit first differences of the reading and the rows within a run
    /// (default): the field's slow part drops out with the offset.
    pub differenced: bool,
}

impl Default for RlsSettings {
    fn default() -> Self {
        Self {
            memory_s: 1800.0,
            noise_nt2: 0.01,
            offset_std_nt: 1000.0,
            coef_std_floor: 0.01,
            differenced: true,
        }
    }
}

/// Recursive least squares with forgetting ([module docs](self)).
#[derive(Debug, Clone)]
pub struct Rls {
    settings: RlsSettings,
    /// `θ = (c, o)`.
    theta: DVector<f64>,
    p: DMatrix<f64>,
    h: DVector<f64>,
    ph: DVector<f64>,
    /// The run's previous row and reading (differenced fits).
    prev: Option<(Vec<f64>, f64)>,
}

impl Rls {
    /// Start at the coefficients `coef` with standard deviations `coef_std`
    /// (NaN: unknown, the floor is used). Bad settings are
    /// [`CompError::InvalidSetting`].
    pub fn new(coef: &[f64], coef_std: &[f64], settings: RlsSettings) -> Result<Self> {
        let shown = aeromag_core::error::shown;
        if !(settings.memory_s >= MIN_MEMORY_S && settings.memory_s.is_finite()) {
            return Err(CompError::setting(format!(
                "recursive least squares: a memory of {} s (--memory): it must be finite and at least \
                 {MIN_MEMORY_S} s",
                shown(settings.memory_s)
            )));
        }
        let ok = |v: f64| v > 0.0 && v.is_finite();
        for (name, v) in [
            ("noise variance (nT²)", settings.noise_nt2),
            ("offset standard deviation (nT)", settings.offset_std_nt),
            (
                "coefficient standard deviation floor",
                settings.coef_std_floor,
            ),
        ] {
            if !ok(v) {
                return Err(CompError::setting(format!(
                    "recursive least squares: a {name} of {} must be finite and > 0",
                    shown(v)
                )));
            }
        }
        if coef_std.len() != coef.len() {
            return Err(CompError::setting(format!(
                "recursive least squares: {} coefficients but {} standard deviations",
                coef.len(),
                coef_std.len()
            )));
        }
        let m = coef.len();
        let mut theta = DVector::zeros(m + 1);
        theta.rows_mut(0, m).copy_from_slice(coef);
        let mut p = DMatrix::zeros(m + 1, m + 1);
        for (k, s) in coef_std.iter().enumerate() {
            let s = if s.is_finite() {
                s.max(settings.coef_std_floor)
            } else {
                settings.coef_std_floor
            };
            p[(k, k)] = s * s;
        }
        p[(m, m)] = settings.offset_std_nt.powi(2);
        Ok(Self {
            settings,
            theta,
            p,
            h: DVector::zeros(m + 1),
            ph: DVector::zeros(m + 1),
            prev: None,
        })
    }

    fn m(&self) -> usize {
        self.theta.len() - 1
    }
}

impl CoefficientEstimator for Rls {
    fn coefficients(&self) -> &[f64] {
        &self.theta.as_slice()[..self.m()]
    }

    fn coefficient_std(&self) -> Vec<f64> {
        (0..self.m())
            .map(|k| self.p[(k, k)].max(0.0).sqrt())
            .collect()
    }

    fn start_run(&mut self) -> Result<()> {
        let m = self.m();
        self.p[(m, m)] += self.settings.offset_std_nt.powi(2);
        self.prev = None;
        Ok(())
    }

    fn update(&mut self, step: &AdaptiveStep) -> Result<Update> {
        let m = self.m();
        if step.row.len() != m || !step.y_nt.is_finite() || step.dt_s.is_nan() || step.dt_s < 0.0 {
            return Err(CompError::data(format!(
                "RLS step: row of {} for {m} coefficients, y {} nT, dt {} s",
                step.row.len(),
                step.y_nt,
                step.dt_s
            )));
        }
        let mut y = step.y_nt;
        if self.settings.differenced {
            let Some((row0, y0)) = &self.prev else {
                self.prev = Some((step.row.to_vec(), step.y_nt));
                return Ok(Update::Learnt);
            };
            for ((h, r), r0) in self.h.iter_mut().zip(step.row).zip(row0) {
                *h = r - r0;
            }
            self.h[m] = 0.0;
            y -= y0;
        } else {
            self.h.rows_mut(0, m).copy_from_slice(step.row);
            self.h[m] = 1.0;
        }
        self.p.mul_to(&self.h, &mut self.ph);
        let alpha = self.settings.noise_nt2 + self.h.dot(&self.ph);
        if !(alpha > 0.0 && alpha.is_finite()) {
            return Err(CompError::data(format!(
                "RLS step: innovation variance {alpha}"
            )));
        }
        let e = y - self.h.dot(&self.theta);
        // An outlier is left out, and so is its row as the next difference's
        // start.
        let within = e * e <= OUTLIER_NIS * alpha;
        if !within {
            return Ok(Update::Outlier);
        }
        if self.settings.differenced {
            self.prev = Some((step.row.to_vec(), step.y_nt));
        }
        self.theta.axpy(e / alpha, &self.ph, 1.0);
        // P ← (P − Ph (Ph)ᵀ / α) / λ, symmetric by construction.
        let lambda = (-step.dt_s / self.settings.memory_s).exp();
        self.p.ger(-1.0 / alpha, &self.ph, &self.ph, 1.0);
        self.p /= lambda;
        Ok(Update::Learnt)
    }

    fn boxed_clone(&self) -> Box<dyn CoefficientEstimator> {
        Box::new(self.clone())
    }
}
