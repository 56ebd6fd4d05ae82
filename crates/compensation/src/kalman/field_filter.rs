//! Pass 1 without the coefficients in the state: the field filter applied
//! to the reading and to every design column, the coefficients integrated
//! out ([`AugmentedFilter`], de Jong 1991).
//!
//! With the coefficients constant, the joint filter's likelihood, final
//! coefficients, their covariance and the field given the coefficients at
//! any sample (the smoother's restart points) follow from the field filter
//! of `n_f = order + 2` states alone, run on `m + 1` right-hand sides. The
//! coefficients then no longer link the runs: groups of runs are filtered
//! on all cores and their sums added in run order. The noise tuning
//! ([`super::tuning`]) evaluates its likelihood this way, and
//! [`super::fit::CoefficientPass::Augmented`] fits the coefficients this
//! way; what it cannot give is the joint filter's sequential innovations
//! (each made with the coefficients estimated from the samples before).

use super::anomaly_model::{AnomalyTransition, B_H, NoiseModel, StepTransition, X2Prior};
use super::joint_filter::est;
use crate::error::{CompError, Result};
use aeromag_estimation::kalman::AugmentedFilter;

/// Samples per group of runs filtered on one thread (a fixed partition:
/// the same sums, the same bits, with any number of threads).
pub const SAMPLES_PER_GROUP: usize = 2048;

/// Contiguous groups of runs, each of at least [`SAMPLES_PER_GROUP`]
/// samples (the last may be shorter), from the runs' lengths.
pub fn groups_of_runs(lengths: impl IntoIterator<Item = usize>) -> Vec<std::ops::Range<usize>> {
    let mut groups = Vec::new();
    let (mut from, mut samples, mut count) = (0, 0, 0);
    for len in lengths {
        samples += len;
        count += 1;
        if samples >= SAMPLES_PER_GROUP {
            groups.push(from..count);
            from = count;
            samples = 0;
        }
    }
    if from < count {
        groups.push(from..count);
    }
    groups
}

/// One filter over the groups of runs that `parts` were filtered over, in
/// order (their sums added in that order: the same bits however the groups
/// were shared out). [`CompError::UnusableData`] if there are none.
pub fn merge_in_order(parts: impl IntoIterator<Item = AugmentedFilter>) -> Result<AugmentedFilter> {
    let mut total: Option<AugmentedFilter> = None;
    for mut f in parts {
        match total.as_mut() {
            None => total = Some(f),
            Some(t) => t.merge(&mut f).map_err(est)?,
        }
    }
    total.ok_or_else(|| CompError::data("no usable samples".to_string()))
}

/// The noise intensities and the field prior are usable: a
/// [`CompError::InvalidSetting`] naming the bad one otherwise.
pub fn check_field_model(noise: &NoiseModel, x2_prior: &X2Prior) -> Result<()> {
    if !noise.is_valid() {
        return Err(CompError::setting(format!(
            "invalid noise intensities {noise:?} (q ≥ 0, r > 0, finite)"
        )));
    }
    if !x2_prior.is_valid() {
        return Err(CompError::setting(format!(
            "invalid field prior {x2_prior:?} (positive, finite)"
        )));
    }
    Ok(())
}

/// The field filter over one group of runs: the transition for each step
/// (recomputed only when the step length changes) and the measurement row
/// `h = e_{B^h} + Δz e_{B_z}`.
pub struct FieldFilter {
    filter: AugmentedFilter,
    transition: StepTransition,
    h: Vec<f64>,
    b_z: usize,
    r_nt2: f64,
}

impl FieldFilter {
    /// A filter with the field prior `x2_prior`, the transition for the
    /// noise intensities in use, white-noise variance `r_nt2` and the
    /// coefficients' prior means and standard deviations.
    pub fn new(
        x2_prior: &X2Prior,
        transition: &AnomalyTransition,
        r_nt2: f64,
        coef_mean: &[f64],
        coef_std: &[f64],
    ) -> Result<Self> {
        if !x2_prior.is_valid() {
            return Err(CompError::setting(format!(
                "invalid field prior {x2_prior:?} (positive, finite)"
            )));
        }
        if !(r_nt2 > 0.0 && r_nt2.is_finite()) {
            return Err(CompError::setting(format!(
                "white-noise variance {r_nt2} nT² must be finite and > 0"
            )));
        }
        let dim = x2_prior.dim();
        let mut h = vec![0.0; dim];
        h[B_H] = 1.0;
        Ok(Self {
            filter: AugmentedFilter::new(&x2_prior.factor(), coef_mean, coef_std).map_err(est)?,
            transition: StepTransition::new(transition.clone()),
            h,
            b_z: x2_prior.b_z(),
            r_nt2,
        })
    }

    /// One sample: a new run starts here (`first`), or the field moves on
    /// by `d_m` metres; then the design row `row`, altitude offset `dz_m`
    /// and centred reading `y_nt`.
    pub fn step(&mut self, first: bool, d_m: f64, row: &[f64], dz_m: f64, y_nt: f64) -> Result<()> {
        if first {
            self.filter.start_run().map_err(est)?;
        } else {
            let (phi, g) = self.transition.step(d_m)?;
            self.filter.predict(phi, g).map_err(est)?;
        }
        self.h[self.b_z] = dz_m;
        self.filter
            .update(&self.h, row, y_nt, self.r_nt2)
            .map_err(est)?;
        Ok(())
    }

    /// The underlying filter (its sums, the field given the coefficients).
    pub fn filter(&self) -> &AugmentedFilter {
        &self.filter
    }

    /// The underlying filter, to merge or solve.
    pub fn into_filter(self) -> AugmentedFilter {
        self.filter
    }
}
