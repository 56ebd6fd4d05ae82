//! Locating a dipole over a pass: detection, initialisation and the
//! square-root IEKF of [`crate::pass`] (spec `gradiometry.md`, "Estimator"
//! and "Convergence region"; seed `004_…`, fig. 3).
//!
//! **Tensor system** ([`locate_tensor`], state `(r, M)`):
//!
//! 1. *Detection*: the first epoch `j₀` whose white contrasts exceed
//!    `‖z_j‖ > k σ √9` (`k` = `detection_factor`); before it the object is
//!    not seen and nothing is estimated;
//! 2. *Initialisation* at `j₀`: a multi-start over a window of `W`
//!    epochs ([`window_multistart`]), or the plain IEKF from
//!    `initial_position_m` with zero moment (the seed's procedure,
//!    converging only from the half-space facing the source). One epoch
//!    far from the source does not suffice for the multi-start: at ranges
//!    ≫ the baseline, distant (position, moment) pairs fit one epoch's nine
//!    contrasts to the noise level; the change of the contrasts along the
//!    pass separates them;
//! 3. *Pass*: from the initial estimate with the wide diagonal prior
//!    (`prior_sigma_*`: the initialisation only provides the linearisation
//!    point, its information is not counted twice), the filter runs over
//!    `j₀, j₀+1, …` ([`crate::pass::run_pass`]), or with `passes > 1` the
//!    re-linearised passes of [`crate::pass::run_pass_relinearised`]
//!    (the whole-pass maximum a posteriori estimate, efficient against the
//!    Cramér–Rao bound). `MeasureS` is taken against that prior.
//!
//! **Scalar system** ([`locate_scalar`], position known): the state is the
//! total and the induced moment `(M, M_i)` of
//! [`crate::motion::motion_mv_induced`] (A·m², body frame; the model is
//! nearly linear in `M`) and the contrasts' offset `b` (nT) of
//! [`crate::sim::scalar_epochs`]; the filter runs over every epoch from a
//! zero moment, `M` and `M_i` independent with σ `prior_sigma_moment_am2`
//! per component (the offset's prior is the first epoch's process noise).
//! The output is the total moment `M` in the body frame with its σ: with a
//! constant heading `M_i` is not observed and `M` is estimated as by a
//! 3-state filter with the same prior.
//!
//! Each epoch's output carries the residual `‖z − h(x⁺)‖` (nT).
//!
//! The tensor system's forward model is the exact one
//! ([`DifferenceModel::Exact`], default) or, for comparison, the
//! gradient-tensor approximation ([`DifferenceModel::GradientTensor`],
//! [`crate::tensor_approx`]), chosen in [`LocateConfig::difference_model`].

use crate::convergence::candidate_starts;
use crate::error::{GradiometryError, Result, positive};
use crate::estimability::measure_s;
use crate::forward::{Forward, ScalarForward, TensorForward};
use crate::pass::{PassEpoch, PassStep, run_pass, run_pass_relinearised};
use crate::sr_iekf::{IekfConfig, SrState, iterate_epoch, prognosis};
pub use crate::tensor_approx::DifferenceModel;
use crate::tensor_approx::TensorApproxForward;
use nalgebra::{SMatrix, SVector, Vector3};

/// Settings of the pass estimator (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocateConfig {
    /// IEKF settings (σ = sensor noise, nT).
    pub iekf: IekfConfig,
    /// Detection threshold `k` of `‖z‖ > k σ √Z`.
    pub detection_factor: f64,
    /// Multi-start initialisation (else the plain IEKF from `initial_position_m`).
    pub multistart: bool,
    /// Start of the plain IEKF, body frame, m.
    pub initial_position_m: Vector3<f64>,
    /// Prior σ of each position component, m.
    pub prior_sigma_position_m: f64,
    /// Prior σ of each moment component, A·m².
    pub prior_sigma_moment_am2: f64,
    /// Epochs `W` of the multi-start window (≥ 1).
    pub window_epochs: usize,
    /// Passes (1 = filter only).
    pub passes: usize,
    /// Extra position noise root per step of the first of several passes, m.
    pub first_pass_extra_position_m: f64,
    /// Extra moment noise root per step of the first of several passes, A·m².
    pub first_pass_extra_moment_am2: f64,
    /// Forward model of the tensor differences in the estimator (default
    /// [`DifferenceModel::Exact`]; the scalar system is always exact).
    pub difference_model: DifferenceModel,
}

impl LocateConfig {
    /// Check the values (positive priors and threshold, finite start).
    pub fn validate(&self) -> Result<()> {
        positive("sigma_nt", self.iekf.sigma_nt)?;
        positive("detection_factor", self.detection_factor)?;
        positive("prior_sigma_position_m", self.prior_sigma_position_m)?;
        positive("prior_sigma_moment_am2", self.prior_sigma_moment_am2)?;
        if !self.initial_position_m.iter().all(|v| v.is_finite()) {
            return Err(GradiometryError::NotFinite {
                name: "initial_position_m",
            });
        }
        Ok(())
    }
}

/// One epoch's estimate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Located<const N: usize> {
    /// Posterior, iterations, convergence flag and `MeasureS`.
    pub step: PassStep<N>,
    /// Residual `‖z − h(x⁺)‖`, nT.
    pub residual_nt: f64,
}

fn with_residuals<const N: usize, const Z: usize, F: Forward<N, Z>>(
    epochs: &[PassEpoch<N, Z, F>],
    steps: Vec<PassStep<N>>,
) -> Vec<Located<N>> {
    steps
        .into_iter()
        .zip(epochs)
        .map(|(step, e)| Located {
            residual_nt: (e.z - e.model.eval(&step.posterior.x).0).norm(),
            step,
        })
        .collect()
}

fn run<const N: usize, const Z: usize, F: Forward<N, Z>>(
    prior: &SrState<N>,
    epochs: &[PassEpoch<N, Z, F>],
    cfg: &LocateConfig,
    extra: SVector<f64, N>,
) -> Result<Vec<PassStep<N>>> {
    if cfg.passes <= 1 {
        run_pass(prior, epochs, &cfg.iekf)
    } else {
        run_pass_relinearised(prior, epochs, &cfg.iekf, cfg.passes, &extra)
    }
}

/// Iterations per epoch of the window runs of [`window_multistart`].
pub const WINDOW_ITERATIONS: usize = 5;

/// Multi-start over a window: from every position of
/// [`candidate_starts`] (zero moment, diagonal prior `sigma`), the IEKF on
/// the first epoch of `window`; from each distinct solution (positions
/// more than 5 % of the range apart) the filter over the window (at most
/// [`WINDOW_ITERATIONS`] per epoch); the
/// final estimate is carried back to the first epoch through the inverse
/// transitions, `x̄_{j−1} = F_j⁻¹ (x̄_j − u_j)`, and scored by the whole
/// window's residual `Σ_j ‖z_j − h_j(x̄_j)‖²` (nT²). Returns `x̄_0` of the
/// best candidate (first on ties). The first epoch's transition is ignored.
pub fn window_multistart<F: Forward<6, 9>>(
    window: &[PassEpoch<6, 9, F>],
    iekf: &IekfConfig,
    sigma: &SVector<f64, 6>,
) -> Result<SVector<f64, 6>> {
    let Some(first) = window.first() else {
        return Err(GradiometryError::LengthMismatch {
            what: "multi-start window",
            got: 0,
            expected: 1,
        });
    };
    let inverses = window
        .iter()
        .skip(1)
        .map(|e| {
            e.transition
                .try_inverse()
                .ok_or(GradiometryError::Singular("transition"))
        })
        .collect::<Result<Vec<_>>>()?;
    // Single-epoch solutions from every candidate; candidates that reach
    // the same solution (positions within 5 % of the range) are run once.
    let mut seeds: Vec<SrState<6>> = Vec::new();
    for c in candidate_starts() {
        let x = SVector::<f64, 6>::from([c.x, c.y, c.z, 0.0, 0.0, 0.0]);
        let Ok(r) = iterate_epoch(&SrState::diagonal(x, sigma), &first.z, &first.model, iekf)
        else {
            continue;
        };
        let p = r.posterior.x.fixed_rows::<3>(0).into_owned();
        let seen = seeds
            .iter()
            .any(|s| (s.x.fixed_rows::<3>(0) - p).norm() <= 0.05 * p.norm());
        if !seen && r.posterior.x.iter().all(|v| v.is_finite()) {
            seeds.push(r.posterior);
        }
    }
    // Scoring only: a few iterations per epoch suffice to tell the
    // solutions apart (a wrong one would otherwise use the maximum count at
    // every epoch).
    let scoring = IekfConfig {
        max_iterations: iekf.max_iterations.min(WINDOW_ITERATIONS),
        ..*iekf
    };
    let mut best: Option<(f64, SVector<f64, 6>)> = None;
    for r in seeds {
        let Ok(steps) = run_pass(&r, &window[1..], &scoring) else {
            continue;
        };
        let mut xj = steps.last().map_or(r.x, |s| s.posterior.x);
        let mut cost = 0.0;
        for (j, e) in window.iter().enumerate().rev() {
            cost += (e.z - e.model.eval(&xj).0).norm_squared();
            if j > 0 {
                xj = inverses[j - 1] * (xj - e.offset);
            }
        }
        if cost.is_finite() && best.is_none_or(|(b, _)| cost < b) {
            best = Some((cost, xj));
        }
    }
    best.map(|(_, x)| x).ok_or(GradiometryError::NotFinite {
        name: "every multi-start run",
    })
}

/// Tensor system over a pass (module docs): `None` before detection (or
/// everywhere when the object is never detected). The estimator's forward
/// model is the exact one of the epochs or, with
/// [`DifferenceModel::GradientTensor`], the approximation of
/// [`crate::tensor_approx`] for the same geometry and background.
pub fn locate_tensor(
    epochs: &[PassEpoch<6, 9, TensorForward>],
    cfg: &LocateConfig,
) -> Result<Vec<Option<Located<6>>>> {
    match cfg.difference_model {
        DifferenceModel::Exact => locate_tensor_with(epochs, cfg),
        DifferenceModel::GradientTensor => {
            let approx: Vec<_> = epochs
                .iter()
                .map(|e| e.with_model(TensorApproxForward::from(e.model)))
                .collect();
            locate_tensor_with(&approx, cfg)
        }
    }
}

/// [`locate_tensor`] with the epochs' own forward model `F`.
fn locate_tensor_with<F: Forward<6, 9> + Clone>(
    epochs: &[PassEpoch<6, 9, F>],
    cfg: &LocateConfig,
) -> Result<Vec<Option<Located<6>>>> {
    cfg.validate()?;
    let threshold = cfg.detection_factor * cfg.iekf.sigma_nt * 3.0;
    let Some(j0) = epochs.iter().position(|e| e.z.norm() > threshold) else {
        return Ok(vec![None; epochs.len()]);
    };
    let (p, m) = (cfg.prior_sigma_position_m, cfg.prior_sigma_moment_am2);
    let sigma = SVector::<f64, 6>::from([p, p, p, m, m, m]);
    let e0 = &epochs[j0];
    let start = if cfg.multistart {
        let end = (j0 + cfg.window_epochs.max(1)).min(epochs.len());
        window_multistart(&epochs[j0..end], &cfg.iekf, &sigma)?
    } else {
        let r = cfg.initial_position_m;
        let x = SVector::<f64, 6>::from([r.x, r.y, r.z, 0.0, 0.0, 0.0]);
        iterate_epoch(&SrState::diagonal(x, &sigma), &e0.z, &e0.model, &cfg.iekf)?
            .posterior
            .x
    };
    // The pass starts at j₀: no transition into it.
    let mut tail = epochs[j0..].to_vec();
    tail[0].transition = SMatrix::identity();
    tail[0].offset = SVector::zeros();
    tail[0].s_q = SVector::zeros();
    let (dp, dm) = (
        cfg.first_pass_extra_position_m,
        cfg.first_pass_extra_moment_am2,
    );
    let steps = run(
        &SrState::diagonal(start, &sigma),
        &tail,
        cfg,
        SVector::<f64, 6>::from([dp, dp, dp, dm, dm, dm]),
    )?;
    let mut out = vec![None; j0];
    out.extend(with_residuals(&tail, steps).into_iter().map(Some));
    Ok(out)
}

/// The total moment `M` (A·m²) of the scalar system's state `(M, M_i, b)`,
/// with its covariance.
pub fn total_moment(x: &SrState<9>) -> SrState<3> {
    x.mapped(&SMatrix::<f64, 3, 9>::identity())
}

/// Scalar system over a pass (module docs): every epoch has an estimate of
/// the total moment `M` (its `MeasureS` against the prior propagated
/// without measurements; the first-pass extra noise on `M` only).
pub fn locate_scalar(
    epochs: &[PassEpoch<9, 3, ScalarForward>],
    cfg: &LocateConfig,
) -> Result<Vec<Located<3>>> {
    cfg.validate()?;
    let m = cfg.prior_sigma_moment_am2;
    let prior = SrState::diagonal(
        SVector::zeros(),
        &SVector::<f64, 9>::from([m, m, m, m, m, m, 0.0, 0.0, 0.0]),
    );
    let e = cfg.first_pass_extra_moment_am2;
    let extra = SVector::<f64, 9>::from([e, e, e, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    let steps = run(&prior, epochs, cfg, extra)?;
    // The last (or only) pass ran with the epochs' own process noise.
    let mut blind = prior;
    Ok(with_residuals(epochs, steps)
        .into_iter()
        .zip(epochs)
        .map(|(l, e)| {
            blind = prognosis(&blind, &e.transition, &e.s_q);
            let posterior = total_moment(&l.step.posterior);
            Located {
                step: PassStep {
                    posterior,
                    iterations: l.step.iterations,
                    converged: l.step.converged,
                    estimability: measure_s(&posterior, &total_moment(&blind)),
                    nis: l.step.nis,
                },
                residual_nt: l.residual_nt,
            }
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Geometry, Layout};
    use crate::motion::MotionNoise;
    use crate::sim::{Processing, Scenario, SystemMotion, simulate, tensor_epochs};

    #[test]
    fn nothing_is_estimated_before_detection_and_plain_start_can_fail_where_multistart_does_not() {
        let mut s = Scenario::new(
            SystemMotion::Mobile,
            Geometry::new(Layout::Tetrahedron, 1.0).unwrap(),
        );
        s.epochs = 600; // 120 m pass: 5 quiet seconds ≥ 50 m away
        s.object_yaw_rate_rad_s = 0.0;
        let sim = simulate(&s).unwrap();
        let p = Processing {
            quiet_epochs: 50,
            noise: MotionNoise {
                position_m_per_sqrt_s: 0.02,
                moment_am2_per_sqrt_s: 2.0,
                induced_per_rad: 0.0,
            },
            moment_scale_am2: 1500.0,
        };
        let epochs = tensor_epochs(&sim, &s.geometry, &p);
        let mut cfg = LocateConfig {
            iekf: IekfConfig::new(0.5).unwrap(),
            detection_factor: 30.0,
            multistart: true,
            // behind the system: the half-space away from the object
            initial_position_m: Vector3::new(0.0, -10.0, -3.0),
            prior_sigma_position_m: 20.0,
            prior_sigma_moment_am2: 3000.0,
            window_epochs: 30,
            passes: 1,
            first_pass_extra_position_m: 0.3,
            first_pass_extra_moment_am2: 30.0,
            difference_model: DifferenceModel::Exact,
        };
        let out = locate_tensor(&epochs, &cfg).unwrap();
        let j0 = out.iter().position(Option::is_some).unwrap();
        assert!(j0 > 50 && out[j0..].iter().all(Option::is_some));
        let mid = sim.len() / 2;
        let est = out[mid].unwrap();
        let dr = (est.step.posterior.x.fixed_rows::<3>(0) - sim[mid].true_position_m).norm();
        assert!(dr < 0.1, "{dr}");
        assert!(est.residual_nt < 3.0 * 0.5 * 3.0);
        cfg.multistart = false;
        let plain = locate_tensor(&epochs, &cfg).unwrap();
        let e = plain[j0].unwrap();
        let dr0 = (e.step.posterior.x.fixed_rows::<3>(0) - sim[j0].true_position_m).norm();
        eprintln!("plain start at detection: error {dr0:.2} m");
        assert!(
            dr0 > 1.0,
            "plain IEKF from the far half-space converged: {dr0}"
        );
    }
}
