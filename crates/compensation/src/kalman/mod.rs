//! Method 2: the Kalman filter and smoother with a stochastic model of the
//! external field (the thesis' method).
//!
//! Spec `compensation.md`, "Method 2"; seed `000_…` §7 (models), §9 (the
//! scalar measurement model), §11 (reduction to a standard linear
//! estimation problem and its block structure).
//!
//! ## Why
//!
//! The band-pass least squares of Method 1 assumes the external field has
//! no energy in the pass band. Geology, the vertical gradient sampled by
//! altitude changes during pitch manoeuvres, and the diurnal variation leak
//! into the fit and bias the coefficients. Here the external field is a
//! random process along the track, estimated jointly with the coefficients,
//! and nothing is filtered away.
//!
//! ## The estimation problem
//!
//! ```text
//! X  = (X2, X1)                      (field states first, constants last: cheap time update)
//! X2 = (B^h, B^h_x, B^h_xx, B_z, B_zx)  field at z0, its along-track derivatives, vertical gradient
//! X1 = Tolles-Lawson coefficients     (constant: dX1/ds = 0, no process noise)
//! y_k = mag_k − y_ref = H1_k X1 + B^h_k + Δz_k B_z,k + v_k,   v_k ~ N(0, r),  Δz = alt − z0
//! ```
//!
//! `H1_k` is the design row of [`crate::tolles_lawson`] (any [`TermSet`],
//! default `p3,i5,e8`; the physical derivative convention by default), `z0`
//! the mean altitude, `y_ref` the mean reading (a constant that `B^h`
//! absorbs; removing it only keeps numbers small). The field model and its
//! exact discretisation over the along-track distance are in
//! [`anomaly_model`]; the units of `q₁, q₂` are nT²/m⁵ and of `r` nT².
//!
//! ## Two passes, and why they give the smoother's answer
//!
//! The coefficients are constant, so their smoothed estimate (given all
//! data) equals their filtered estimate after the last sample:
//! `E[X1 | y_1..N] = X̂1_{N|N}`. **Pass 1** ([`joint_filter`]) therefore only
//! runs the square-root filter of the full state forward, in `O(n²)` memory,
//! and keeps `X̂1` and its covariance `P1`.
//!
//! For the field states, condition on `X1`: the field prior does not depend
//! on `X1`, so `E[X2_k | y, X1]` is the Kalman smoother of the 5-state model
//! on the readings `y_k − H1_k X1` — a linear function of the data, hence
//! affine in `X1`: `E[X2_k | y, X1] = a_k + B_k X1`. By the tower property,
//!
//! ```text
//! E[X2_k | y] = E[ E[X2_k | y, X1] | y ] = a_k + B_k E[X1 | y] = a_k + B_k X̂1,
//! ```
//!
//! which is that 5-state smoother run on `y_k − H1_k X̂1`. **Pass 2**
//! ([`field_smoother`]) does exactly this, run by run, with the checkpointed
//! square-root smoother of `aeromag-estimation` (means only: the
//! modified Bryson–Frazier recursion; memory `O(√N · 5²)`
//! beyond the outputs). Its restart points come from pass 1 for free: the
//! joint filter's conditional of `X2` given `X1`, evaluated at `X̂1`, is the
//! 5-state filter's estimate at that sample. Its covariances would be conditional on `X1`; the
//! unconditional ones add `B_k P1 B_kᵀ` (not computed: only the means are
//! output). The equality with a full-state RTS smoother is tested.
//!
//! ## Runs
//!
//! Each input segment is split at samples with a missing value (mag, flux,
//! altitude, speed); at the start of every run the field states restart from
//! their diffuse prior ([`anomaly_model::X2Prior`]) independent of the
//! rest, while `X1` and its covariance carry over. Unusable samples get NaN
//! in every output series and are counted in a warning.
//!
//! ## Outputs
//!
//! [`KalmanFit`]: the coefficients with standard deviations `√diag(P1)`, the
//! prior and posterior covariances of `X1` (for estimability measures
//! `μ_i = √(P_post,ii / P_prior,ii)`), the noise intensities used (the
//! documented defaults, or tuned by maximum likelihood on request,
//! [`tuning`]), per-sample compensated reading, smoothed
//! external field and innovations, and the same diagnostics as the
//! least-squares fit; [`KalmanFit::to_model`] writes the model file.
//!
//! | file | contents |
//! |---|---|
//! | [`anomaly_model`] | field model, units, exact discretisation, defaults |
//! | [`track`] | ground speed, along-track steps |
//! | [`rows`] | streaming design rows in chunks |
//! | [`joint_filter`] | pass 1: the joint square-root filter |
//! | [`field_filter`] | pass 1 and the tuning's likelihood without the coefficients in the state (the runs on all cores) |
//! | [`field_smoother`] | pass 2: the 5-state smoother given `X̂1` |
//! | [`tuning`] | maximum-likelihood tuning of `q₁, q₂, r` (Nelder–Mead) |
//! | [`fit`] | the whole method, outputs, diagnostics |
//! | [`online`] | the forward filter run online, coefficients adapting |
//!
//! [`TermSet`]: crate::tolles_lawson::TermSet

pub mod altitude;
pub mod anomaly_model;
pub mod field_filter;
pub mod field_smoother;
pub mod fit;
pub mod joint_filter;
pub mod online;
pub mod rows;
pub mod track;
pub mod tuning;

pub use anomaly_model::{DEFAULT_ORDER, NoiseModel, ORDERS, THESIS_ORDER, X2Prior, q1_unit};
pub use fit::{
    CANCEL_ROWS, CoefficientPass, KalmanConfig, KalmanFit, KalmanSegment, KalmanSeries, fit_kalman,
    fit_kalman_cancellable, fit_kalman_exact, fit_kalman_exact_cancellable,
};
pub use joint_filter::JointFilter;
pub use track::{ground_speed_from_positions, ground_speed_from_velocity};
pub use tuning::{TuningConfig, TuningReport};

#[cfg(test)]
mod tests;
