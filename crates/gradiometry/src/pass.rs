//! The filter over a pass (seed fig. 1/3): for every epoch, `PrognosisFK`
//! with the motion model, the iterated scalar updates of
//! [`crate::sr_iekf::iterate_epoch`], and `MeasureS` against the same
//! prior propagated without measurements.
//!
//! Epoch `j` carries the transition *into* it, `x_j = F_j x_{j−1} + u_j`
//! with process-noise root `S_Q,j` (from [`crate::motion`]; use `F = I`,
//! `u = 0`, `S_Q = 0` for the first epoch, or an `S_Q` there that widens
//! the prior, as the scalar system's contrast offset of
//! [`crate::sim::scalar_epochs`]), its forward model (geometry,
//! background, known position for the scalar system) and its white
//! contrasts `z_j` (nT).
//!
//! **Re-linearised passes** ([`run_pass_relinearised`]): an EKF linearises
//! the first epochs about a poor estimate and keeps that information for
//! ever (over-confident, inefficient). After a pass, the final estimate is
//! carried back to the first epoch through the inverse transitions,
//! `x̄_{j−1} = F_j⁻¹ (x̄_j − u_j)`, and the pass is run again from the same
//! prior, now with every epoch linearised once about that trajectory `x̄_j`
//! (innovations `z_j − h_j(x̄_j) − H_j(x⁻_j − x̄_j)`). With a deterministic
//! motion model this is exactly one Gauss–Newton step of the whole-pass
//! maximum-a-posteriori problem in filter form; repeating converges to it.

use crate::error::{GradiometryError, Result};
use crate::estimability::measure_s;
use crate::forward::Forward;
use crate::sr_iekf::{IekfConfig, SrState, iterate_epoch, prognosis, update_linearised};
use nalgebra::{SMatrix, SVector};

/// One epoch of input.
#[derive(Debug, Clone, PartialEq)]
pub struct PassEpoch<const N: usize, const Z: usize, F> {
    /// Transition matrix into this epoch.
    pub transition: SMatrix<f64, N, N>,
    /// Known input `u` of the transition (m, A·m²).
    pub offset: SVector<f64, N>,
    /// Diagonal of the process-noise square root.
    pub s_q: SVector<f64, N>,
    /// Forward model of this epoch.
    pub model: F,
    /// White contrasts, nT.
    pub z: SVector<f64, Z>,
}

impl<const N: usize, const Z: usize, F> PassEpoch<N, Z, F> {
    /// The same epoch with another forward model.
    pub fn with_model<G>(&self, model: G) -> PassEpoch<N, Z, G> {
        PassEpoch {
            transition: self.transition,
            offset: self.offset,
            s_q: self.s_q,
            model,
            z: self.z,
        }
    }
}

/// One epoch of output.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PassStep<const N: usize> {
    /// Posterior estimate and square root.
    pub posterior: SrState<N>,
    /// Iterations used.
    pub iterations: usize,
    /// Residual at the noise level.
    pub converged: bool,
    /// `MeasureS` estimability per component.
    pub estimability: SVector<f64, N>,
    /// The epoch's normalised innovation squared
    /// `νᵀ (H P⁻ Hᵀ + σ² I)⁻¹ ν`, `ν = z − h(x⁻)` at the prior
    /// ([`normalised_innovation`]): about `Z` on average when the filter's
    /// covariance is honest.
    pub nis: f64,
}

/// The normalised innovation squared of measurement `z` against `prior`
/// (noise variance `sigma2`, nT²): `νᵀ (H P⁻ Hᵀ + σ² I)⁻¹ ν` with
/// `ν = z − h(x⁻)` and `H = ∂h/∂x` at the prior's estimate. A filter whose
/// covariance describes its errors gives `Z` on average (χ² with `Z`
/// degrees of freedom); one locked on a wrong solution, or whose process
/// noise is too small for how its state really moves, gives many times
/// that. NaN when the innovation covariance is not invertible.
pub fn normalised_innovation<const N: usize, const Z: usize, F: Forward<N, Z>>(
    prior: &SrState<N>,
    z: &SVector<f64, Z>,
    model: &F,
    sigma2: f64,
) -> f64 {
    let (hx, hj) = model.eval(&prior.x);
    let nu = z - hx;
    let hs = hj * prior.s;
    let cov = hs * hs.transpose() + SMatrix::<f64, Z, Z>::identity() * sigma2;
    match cov.cholesky() {
        Some(c) => nu.dot(&c.solve(&nu)),
        None => f64::NAN,
    }
}

/// Run the filter from `initial` over `epochs`.
pub fn run_pass<const N: usize, const Z: usize, F: Forward<N, Z>>(
    initial: &SrState<N>,
    epochs: &[PassEpoch<N, Z, F>],
    cfg: &IekfConfig,
) -> Result<Vec<PassStep<N>>> {
    run_pass_with_extra_noise(initial, epochs, cfg, &SVector::zeros())
}

/// [`run_pass`] with an extra process-noise root `extra_s_q` added (in
/// quadrature) to every epoch's `S_Q`: lets a first pass forget early
/// epochs linearised about a poor estimate.
pub fn run_pass_with_extra_noise<const N: usize, const Z: usize, F: Forward<N, Z>>(
    initial: &SrState<N>,
    epochs: &[PassEpoch<N, Z, F>],
    cfg: &IekfConfig,
    extra_s_q: &SVector<f64, N>,
) -> Result<Vec<PassStep<N>>> {
    let mut state = *initial;
    let mut blind = *initial;
    let mut out = Vec::with_capacity(epochs.len());
    for e in epochs {
        let s_q = e.s_q.zip_map(extra_s_q, |a, b| a.hypot(b));
        let mut prior = prognosis(&state, &e.transition, &s_q);
        prior.x += e.offset;
        blind = prognosis(&blind, &e.transition, &s_q);
        let r = iterate_epoch(&prior, &e.z, &e.model, cfg)?;
        state = r.posterior;
        out.push(PassStep {
            posterior: r.posterior,
            iterations: r.iterations,
            converged: r.converged,
            estimability: measure_s(&r.posterior, &blind),
            nis: normalised_innovation(&prior, &e.z, &e.model, cfg.sigma_nt * cfg.sigma_nt),
        });
    }
    Ok(out)
}

/// The trajectory `x̄_j` of a final estimate `x_final` (the state at the
/// last epoch) carried back through the inverse transitions,
/// `x̄_{j−1} = F_j⁻¹ (x̄_j − u_j)` (module docs); the first epoch's
/// transition is not used.
pub fn carried_back<const N: usize, const Z: usize, F>(
    x_final: &SVector<f64, N>,
    epochs: &[PassEpoch<N, Z, F>],
) -> Result<Vec<SVector<f64, N>>> {
    let mut traj = vec![*x_final; epochs.len()];
    for j in (1..epochs.len()).rev() {
        let e = &epochs[j];
        let finv = e
            .transition
            .try_inverse()
            .ok_or(GradiometryError::Singular("transition"))?;
        traj[j - 1] = finv * (traj[j] - e.offset);
    }
    Ok(traj)
}

/// [`run_pass_with_extra_noise`] (first pass, extra noise `first_extra_s_q`
/// per step), then `passes − 1` passes with the epochs' own `S_Q`,
/// linearised about the trajectory carried back from the previous final
/// estimate (module docs), stopping early once the final estimate moves by
/// less than `cfg.step_fraction` of its σ; the
/// iteration count of those passes is 1 and `converged` reports whether the
/// epoch residual is at the noise level (`k σ √Z`).
pub fn run_pass_relinearised<const N: usize, const Z: usize, F: Forward<N, Z>>(
    initial: &SrState<N>,
    epochs: &[PassEpoch<N, Z, F>],
    cfg: &IekfConfig,
    passes: usize,
    first_extra_s_q: &SVector<f64, N>,
) -> Result<Vec<PassStep<N>>> {
    let mut out = run_pass_with_extra_noise(initial, epochs, cfg, first_extra_s_q)?;
    let sigma2 = cfg.sigma_nt * cfg.sigma_nt;
    let threshold = cfg.residual_factor * cfg.sigma_nt * (Z as f64).sqrt();
    for _ in 1..passes {
        let Some(last) = out.last() else {
            return Ok(out);
        };
        let traj = carried_back(&last.posterior.x, epochs)?;
        let mut state = *initial;
        let mut blind = *initial;
        let mut next = Vec::with_capacity(epochs.len());
        for (e, xl) in epochs.iter().zip(&traj) {
            let mut prior = prognosis(&state, &e.transition, &e.s_q);
            prior.x += e.offset;
            blind = prognosis(&blind, &e.transition, &e.s_q);
            let nis = normalised_innovation(&prior, &e.z, &e.model, sigma2);
            let (hx, hj) = e.model.eval(xl);
            state = update_linearised(&prior, &e.z, xl, &hx, &hj, sigma2)?;
            if !state.x.iter().all(|v| v.is_finite()) {
                return Err(GradiometryError::NotFinite {
                    name: "pass estimate",
                });
            }
            let residual = (e.z - e.model.eval(&state.x).0).norm();
            next.push(PassStep {
                posterior: state,
                iterations: 1,
                converged: residual <= threshold,
                estimability: measure_s(&state, &blind),
                nis,
            });
        }
        let change = match (out.last(), next.last()) {
            (Some(a), Some(b)) => {
                let sig = b.posterior.sigma();
                (0..N).all(|k| {
                    (a.posterior.x[k] - b.posterior.x[k]).abs() <= cfg.step_fraction * sig[k]
                })
            }
            _ => true,
        };
        out = next;
        if change {
            break;
        }
    }
    Ok(out)
}
