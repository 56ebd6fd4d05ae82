//! Pass 2: the smoothed external field of one run, given the coefficient
//! estimate — a 5-state square-root filter and fixed-interval smoother
//! ([`aeromag_estimation::kalman::smooth_from_checkpoints`], so memory is
//! `O(√N)` beyond the output).
//!
//! The smoother restarts the 5-state filter from checkpoints every `L`
//! samples. They come from pass 1 at no extra filtering cost: the joint
//! filter's conditional distribution of `X2` given `X1`
//! (`E[X2 | X1] = x̂2 + U_b U_c⁻¹ (X1 − x̂1)`, factor `U_a`,
//! [`super::JointFilter::field_conditional`]; from the field filter's
//! right-hand sides with [`super::CoefficientPass::Augmented`],
//! [`aeromag_estimation::kalman::AugmentedFilter::conditional`]) evaluated
//! at the final `X̂1` *is* the filtered estimate of pass 2 at that sample. So pass 2 re-runs
//! the 5-state filter once, block by block, and smooths backward.
//!
//! Why this equals the joint smoother (module docs of [`super`]): the field
//! states of different runs are independent given `X1`, and within a run
//! `E[X2_k | y, X1]` is the smoother of `X2` on `y_k − H1_k X1`, affine in
//! `X1`; averaging over the posterior of `X1` replaces `X1` by its mean
//! `X̂1`. So the smoothed field is the smoother run on the compensated
//! reading `y_k − H1_k X̂1` with the same prior and noise as pass 1.
//!
//! The measurement is `c_k − y_ref = B^h_k + Δz_k B_z,k + v_k` with `c` the
//! compensated reading; the output is the external field at the sensor,
//! `y_ref + B^h_k + Δz_k B_z,k` (nT).

use super::anomaly_model::{AnomalyTransition, B_H, NoiseModel, X2Prior};
use super::joint_filter::est;
use super::track::step_length;
use crate::error::Result;
use aeromag_estimation::kalman::{Checkpoint, StateSpaceModel, smooth_from_checkpoints};
use nalgebra::DMatrix;

/// The field model of one run (indices `offset..offset+len` of the slices).
pub struct FieldModel<'a> {
    /// Time, s.
    pub time: &'a [f64],
    /// Ground speed, m/s.
    pub speed_m_s: &'a [f64],
    /// Altitude, m.
    pub alt_m: &'a [f64],
    /// Compensated reading `mag − H1 X̂1`, nT.
    pub compensated_nt: &'a [f64],
    /// First sample of the run.
    pub offset: usize,
    /// Samples in the run.
    pub len: usize,
    /// The constant removed from the reading, nT.
    pub y_ref_nt: f64,
    /// Reference altitude `z0`, m.
    pub z0_m: f64,
    /// Noise intensities.
    pub noise: NoiseModel,
    /// Field prior.
    pub prior: X2Prior,
    /// Transition helper (built for `noise` and `prior.order`).
    pub transition: AnomalyTransition,
}

impl StateSpaceModel for FieldModel<'_> {
    fn dim(&self) -> usize {
        self.prior.dim()
    }
    fn steps(&self) -> usize {
        self.len
    }
    fn prior(&self, x0: &mut [f64], s0: &mut DMatrix<f64>) {
        x0.fill(0.0);
        s0.copy_from(&self.prior.factor());
    }
    fn noise_dim(&self) -> usize {
        self.prior.dim()
    }
    fn transition(&self, k: usize, phi: &mut DMatrix<f64>, g: &mut DMatrix<f64>) {
        let d = step_length(self.time, self.speed_m_s, self.offset + k);
        self.transition.fill(d, phi, g);
    }
    fn measurement(&self, k: usize, h: &mut [f64]) -> Option<(f64, f64)> {
        let i = self.offset + k;
        h.fill(0.0);
        h[B_H] = 1.0;
        h[self.prior.b_z()] = self.alt_m[i] - self.z0_m;
        Some((self.compensated_nt[i] - self.y_ref_nt, self.noise.r_nt2))
    }
}

/// Smooth the run from the filtered `checkpoints` (run-local steps; see
/// [`smooth_from_checkpoints`]) and write the external field (nT) into
/// `external[offset..offset+len]`.
pub fn smooth_field(
    model: &FieldModel,
    checkpoints: &[Checkpoint],
    external: &mut [f64],
) -> Result<()> {
    smooth_from_checkpoints(model, checkpoints, false, |k, x, _| {
        let i = model.offset + k;
        external[i] =
            model.y_ref_nt + x[B_H] + (model.alt_m[i] - model.z0_m) * x[model.prior.b_z()];
    })
    .map_err(est)
}
