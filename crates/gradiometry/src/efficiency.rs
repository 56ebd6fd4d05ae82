//! Monte-Carlo efficiency of the pass estimator against the Cramér–Rao
//! bound (spec `gradiometry.md`, "Accuracy against the physical limit":
//! `RMS/CRLB ≤ 1.2` for position and moment in well-posed cases, for the
//! stationary and the mobile system).
//!
//! For `trials` independent noise draws (scenario seeds `first_seed`,
//! `first_seed + 1`, …) the scenario is simulated, the estimator of
//! [`crate::locate`] runs over the pass, and its final-epoch error
//! `e = x̂ − x` is collected. The bound is that of the last epoch of the
//! noise-free pass with the known motion ([`crate::crlb::crlb`], via
//! [`tensor_pass_crlb`] / [`scalar_pass_crlb`]). Reported:
//!
//! ```text
//! per parameter k:  η_k = √(mean e_k²) / √CRLB_kk
//! per block b:      η_b = √(mean ‖e_b‖²) / √trace CRLB_bb    (position, moment)
//! ```
//!
//! `η = 1` is an efficient estimator; `η < 1` by more than the Monte-Carlo
//! scatter (≈ 1/√(2·trials)) would mean the bound or the errors are wrong.
//! Also reported: the bias `‖mean e_b‖ / √trace CRLB_bb` per block and the
//! trials beyond [`OUTLIER_SIGMAS`] `√trace CRLB_bb`.
//!
//! [`approximation_range_study`] runs the same Monte Carlo with the exact
//! differences and with the gradient-tensor approximation of
//! [`crate::tensor_approx`] over a set of range/baseline ratios (seed
//! `004_…`, sect. 3).
//!
//! The trials run on up to `threads` threads; every trial is independent and
//! seeded, and the errors are reduced in trial order, so the result is
//! bit-identical for any thread count.

use crate::crlb::{crlb, efficiency};
use crate::error::{GradiometryError, Result};
use crate::forward::{Forward, ScalarForward};
use crate::geometry::{Geometry, Layout};
use crate::locate::{DifferenceModel, LocateConfig, locate_scalar, locate_tensor};
use crate::motion::MotionNoise;
use crate::pass::PassEpoch;
use crate::sim::{
    Gradiometer, Processing, Scenario, SimEpoch, SystemMotion, scalar_epochs, simulate,
    tensor_epochs,
};
use crate::sr_iekf::IekfConfig;
use aeromag_core::frames::Attitude;
use aeromag_core::parallel::parallel_map;
use nalgebra::{SMatrix, SVector, Vector3};

/// Result of a Monte-Carlo run.
#[derive(Debug, Clone, PartialEq)]
pub struct Efficiency {
    /// Parameter names in state order (`x_m, y_m, z_m, mx_am2, my_am2,
    /// mz_am2`; the scalar system has only the moment).
    pub names: Vec<&'static str>,
    /// RMS error of each parameter (m or A·m²).
    pub rms: Vec<f64>,
    /// `√CRLB_kk` of each parameter (m or A·m²).
    pub crlb_sigma: Vec<f64>,
    /// `η_k = rms_k / crlb_sigma_k`.
    pub per_parameter: Vec<f64>,
    /// Block efficiency of the position (tensor system only).
    pub position: Option<f64>,
    /// Block efficiency of the moment.
    pub moment: f64,
    /// Mean error of each parameter (m or A·m²).
    pub mean: Vec<f64>,
    /// Block bias of the position, `‖mean e_b‖ / √trace CRLB_bb` (tensor
    /// system only).
    pub position_bias: Option<f64>,
    /// Block bias of the moment.
    pub moment_bias: f64,
    /// Trials whose error in a block exceeds [`OUTLIER_SIGMAS`] times
    /// `√trace CRLB_bb` (a failed start or a diverged pass; an efficient
    /// estimator practically never does that).
    pub outliers: usize,
    /// Number of trials.
    pub trials: usize,
}

/// Threshold of [`Efficiency::outliers`], in units of `√trace CRLB_bb`.
pub const OUTLIER_SIGMAS: f64 = 5.0;

impl Efficiency {
    /// The worse of the position and moment block efficiencies.
    pub fn worst_block(&self) -> f64 {
        self.position.map_or(self.moment, |p| p.max(self.moment))
    }
}

/// The well-posed case of the efficiency figures: the default scenario with
/// `motion` and a `layout` of 1 m baseline, 100 epochs (a 20 m pass, range
/// ≤ 12 m, strong signal from the first epoch), no sensor bias, no natural
/// variations (they tilt the total field, which the scalar model takes from
/// IGRF), constant object heading (moment fixed in the body frame), and for
/// the mobile system a tilted, turned attitude (3°, −2°, 10°).
pub fn well_posed(motion: SystemMotion, layout: Layout) -> Result<Scenario> {
    let mut s = Scenario::new(motion, Geometry::new(layout, 1.0)?);
    s.epochs = 100;
    s.variation_nt = 0.0;
    s.vector_sensor.bias_sigma_nt = 0.0;
    s.scalar_sensor.bias_sigma_nt = 0.0;
    s.object_yaw_rate_rad_s = 0.0;
    if motion == SystemMotion::Mobile {
        s.system_attitude = Attitude::from_degrees(3.0, -2.0, 10.0);
    }
    Ok(s)
}

/// Processing of the well-posed case: the IGRF background in the model, no
/// bias removal, a deterministic motion model (no process noise).
pub fn deterministic_processing() -> Processing {
    Processing {
        quiet_epochs: 0,
        noise: MotionNoise {
            position_m_per_sqrt_s: 0.0,
            moment_am2_per_sqrt_s: 0.0,
            induced_per_rad: 0.0,
        },
        moment_scale_am2: 0.0,
    }
}

/// Estimator settings of the well-posed case for sensor noise `sigma_nt`:
/// detection at `‖z‖ > 10 σ √9`, multi-start, prior σ 20 m and
/// 5000 A·m², up to 10 re-linearised passes (first-pass extra noise
/// 0.3 m and 30 A·m² per step).
pub fn efficient_locate(sigma_nt: f64) -> Result<LocateConfig> {
    let c = LocateConfig {
        iekf: IekfConfig::new(sigma_nt)?,
        detection_factor: 10.0,
        multistart: true,
        initial_position_m: Vector3::new(10.0, 0.0, 0.0),
        prior_sigma_position_m: 20.0,
        prior_sigma_moment_am2: 5000.0,
        window_epochs: 30,
        passes: 10,
        first_pass_extra_position_m: 0.3,
        first_pass_extra_moment_am2: 30.0,
        difference_model: DifferenceModel::Exact,
    };
    c.validate()?;
    Ok(c)
}

fn bound<const N: usize, const Z: usize, F: Forward<N, Z> + Copy>(
    epochs: &[PassEpoch<N, Z, F>],
    truth: &[SVector<f64, N>],
    sigma_nt: f64,
) -> Result<SMatrix<f64, N, N>> {
    let models: Vec<F> = epochs.iter().map(|e| e.model).collect();
    let trans: Vec<_> = epochs.iter().map(|e| e.transition).collect();
    crlb(&models, truth, &trans, sigma_nt)
}

/// True tensor state `(r, M)` of a simulated epoch.
pub fn tensor_truth(e: &SimEpoch) -> SVector<f64, 6> {
    let (r, m) = (e.true_position_m, e.true_moment_am2);
    SVector::<f64, 6>::from([r.x, r.y, r.z, m.x, m.y, m.z])
}

/// CRLB (covariance, m and A·m²) of `(r, M)` at the last epoch of `sim`
/// for the tensor system: the true states, the IGRF background and the
/// known motion of the simulation, white contrasts of σ `sigma_nt` (nT).
/// Any prefix `&sim[..=j]` gives the bound at epoch `j`.
pub fn tensor_pass_crlb(
    sim: &[SimEpoch],
    geometry: &Geometry,
    sigma_nt: f64,
) -> Result<SMatrix<f64, 6, 6>> {
    let epochs = tensor_epochs(sim, geometry, &deterministic_processing());
    let truth: Vec<_> = sim.iter().map(tensor_truth).collect();
    bound(&epochs, &truth, sigma_nt)
}

/// CRLB of the total moment `M` (A·m²)² at the last epoch of `sim` for
/// the scalar system at the known (true) positions, the whole moment turning
/// with the object (the estimator's permanent and induced parts cannot be
/// told apart while the heading is constant, as in [`well_posed`]: their
/// 6-state information is singular); otherwise as [`tensor_pass_crlb`].
pub fn scalar_pass_crlb(
    sim: &[SimEpoch],
    geometry: &Geometry,
    sigma_nt: f64,
) -> Result<SMatrix<f64, 3, 3>> {
    let pos: Vec<_> = sim.iter().map(|e| e.true_position_m).collect();
    // The total moment's model: the permanent part's transition, exact for
    // the sum while the object's heading is constant.
    let epochs: Vec<PassEpoch<3, 3, ScalarForward>> =
        scalar_epochs(sim, geometry, &pos, &deterministic_processing(), sigma_nt)?
            .into_iter()
            .map(|e| PassEpoch {
                transition: e.transition.fixed_view::<3, 3>(0, 0).into_owned(),
                offset: e.offset.fixed_rows::<3>(0).into_owned(),
                s_q: e.s_q.fixed_rows::<3>(0).into_owned(),
                model: e.model,
                z: e.z,
            })
            .collect();
    let truth: Vec<_> = sim.iter().map(|e| e.true_moment_am2).collect();
    bound(&epochs, &truth, sigma_nt)
}

/// Final-epoch error of one trial.
fn trial_error<const N: usize>(
    base: &Scenario,
    gradiometer: Gradiometer,
    processing: &Processing,
    cfg: &LocateConfig,
    seed: u64,
) -> Result<SVector<f64, N>> {
    let s = Scenario {
        seed,
        ..base.clone()
    };
    let sim = simulate(&s)?;
    let last = sim.last().ok_or(GradiometryError::LengthMismatch {
        what: "epochs",
        got: 0,
        expected: 1,
    })?;
    let err: Vec<f64> = match gradiometer {
        Gradiometer::Tensor => {
            let out = locate_tensor(&tensor_epochs(&sim, &s.geometry, processing), cfg)?;
            let est = out
                .last()
                .copied()
                .flatten()
                .ok_or(GradiometryError::NotFinite {
                    name: "estimate (object never detected)",
                })?;
            (est.step.posterior.x - tensor_truth(last))
                .iter()
                .copied()
                .collect()
        }
        Gradiometer::Scalar => {
            let pos: Vec<_> = sim.iter().map(|e| e.true_position_m).collect();
            let input = scalar_epochs(&sim, &s.geometry, &pos, processing, cfg.iekf.sigma_nt)?;
            let out = locate_scalar(&input, cfg)?;
            let est = out
                .last()
                .ok_or(GradiometryError::NotFinite { name: "estimate" })?;
            (est.step.posterior.x - last.true_moment_am2)
                .iter()
                .copied()
                .collect()
        }
    };
    if err.len() != N {
        return Err(GradiometryError::LengthMismatch {
            what: "state",
            got: err.len(),
            expected: N,
        });
    }
    Ok(SVector::from_column_slice(&err))
}

fn monte_carlo_n<const N: usize>(
    base: &Scenario,
    gradiometer: Gradiometer,
    cfg: &LocateConfig,
    trials: usize,
    first_seed: u64,
    threads: usize,
) -> Result<Vec<SVector<f64, N>>> {
    let processing = deterministic_processing();
    let results = parallel_map(trials, threads, |k| {
        trial_error::<N>(base, gradiometer, &processing, cfg, first_seed + k as u64)
    });
    results.into_iter().collect()
}

fn summarise<const N: usize>(
    errors: &[SVector<f64, N>],
    bound: &SMatrix<f64, N, N>,
    names: &[&'static str],
    has_position: bool,
) -> Result<Efficiency> {
    let n = errors.len().max(1) as f64;
    let rms: Vec<f64> = (0..N)
        .map(|k| (errors.iter().map(|e| e[k] * e[k]).sum::<f64>() / n).sqrt())
        .collect();
    let crlb_sigma: Vec<f64> = (0..N).map(|k| bound[(k, k)].sqrt()).collect();
    let per_parameter = rms.iter().zip(&crlb_sigma).map(|(r, s)| r / s).collect();
    let mean: Vec<f64> = (0..N)
        .map(|k| errors.iter().map(|e| e[k]).sum::<f64>() / n)
        .collect();
    let bias = |start: usize| {
        let m2: f64 = mean[start..start + 3].iter().map(|v| v * v).sum();
        let b2: f64 = (start..start + 3).map(|k| bound[(k, k)]).sum();
        (m2 / b2).sqrt()
    };
    let blocks: &[usize] = if has_position { &[0, 3] } else { &[0] };
    let outliers = errors
        .iter()
        .filter(|e| {
            blocks.iter().any(|&b| {
                let tr: f64 = (b..b + 3).map(|k| bound[(k, k)]).sum();
                e.fixed_rows::<3>(b).norm_squared() > OUTLIER_SIGMAS * OUTLIER_SIGMAS * tr
            })
        })
        .count();
    let (position, moment, position_bias, moment_bias) = if has_position {
        (
            Some(efficiency(errors, bound, 0, 3)?),
            efficiency(errors, bound, 3, 3)?,
            Some(bias(0)),
            bias(3),
        )
    } else {
        (None, efficiency(errors, bound, 0, 3)?, None, bias(0))
    };
    Ok(Efficiency {
        names: names.to_vec(),
        rms,
        crlb_sigma,
        per_parameter,
        position,
        moment,
        mean,
        position_bias,
        moment_bias,
        outliers,
        trials: errors.len(),
    })
}

/// Monte-Carlo efficiency of [`locate_tensor`] / [`locate_scalar`] with
/// settings `cfg` on scenario `base` (its seed is replaced by
/// `first_seed + k` in trial `k`), with the deterministic processing of
/// [`deterministic_processing`]; module docs. Errors when `trials` is 0,
/// the bound is singular or a trial fails.
pub fn monte_carlo(
    base: &Scenario,
    gradiometer: Gradiometer,
    cfg: &LocateConfig,
    trials: usize,
    first_seed: u64,
    threads: usize,
) -> Result<Efficiency> {
    if trials == 0 {
        return Err(GradiometryError::NotPositive {
            name: "trials",
            value: 0.0,
        });
    }
    // The bound does not depend on the noise draw: the noise-free truth of
    // the first seed gives it.
    let sim = simulate(&Scenario {
        seed: first_seed,
        ..base.clone()
    })?;
    match gradiometer {
        Gradiometer::Tensor => {
            let b = tensor_pass_crlb(&sim, &base.geometry, base.vector_sensor.noise_nt)?;
            let e = monte_carlo_n::<6>(base, gradiometer, cfg, trials, first_seed, threads)?;
            summarise(
                &e,
                &b,
                &["x_m", "y_m", "z_m", "mx_am2", "my_am2", "mz_am2"],
                true,
            )
        }
        Gradiometer::Scalar => {
            let b = scalar_pass_crlb(&sim, &base.geometry, base.scalar_sensor.noise_nt)?;
            let e = monte_carlo_n::<3>(base, gradiometer, cfg, trials, first_seed, threads)?;
            summarise(&e, &b, &["mx_am2", "my_am2", "mz_am2"], false)
        }
    }
}

/// One range of [`approximation_range_study`].
#[derive(Debug, Clone, PartialEq)]
pub struct RangePoint {
    /// Closest-approach distance over baseline (dimensionless).
    pub range_over_baseline: f64,
    /// Baseline of the layout, m.
    pub baseline_m: f64,
    /// The estimator with the exact differences.
    pub exact: Efficiency,
    /// The estimator with the gradient-tensor approximation
    /// ([`crate::tensor_approx`]).
    pub approx: Efficiency,
    /// The approximation's error on the noise-free pass, position block,
    /// `‖e_r‖ / √trace CRLB_rr`: its model bias alone.
    pub approx_noise_free_position: f64,
    /// … moment block, `‖e_M‖ / √trace CRLB_MM`.
    pub approx_noise_free_moment: f64,
}

/// The exact differences against the gradient-tensor approximation as a
/// function of range over baseline (seed `004_…`, sect. 3: the linear
/// formulation is justified only when the range far exceeds the size of
/// the system).
///
/// The pass of `base` (tensor system: object, motion, sensor noise) is
/// kept, with its closest-approach distance `R = |(y₀, z₀)|`, and the
/// `layout` is scaled to the baseline `R / ratio` for each of `ratios`.
/// At each ratio [`monte_carlo`] runs twice with the same seeds
/// (`first_seed + k`, hence the same noise draws): with `cfg` set to
/// [`DifferenceModel::Exact`] and to [`DifferenceModel::GradientTensor`];
/// and the approximation runs once more on the pass without white sensor
/// noise (seed `first_seed`), which isolates its model bias. The truth is
/// always the exact simulator and the bound that of the exact model (the
/// physics), so the approximation's RMS/CRLB and bias show what its model
/// error costs. Bit-identical for any `threads` (that of [`monte_carlo`]).
pub fn approximation_range_study(
    base: &Scenario,
    layout: Layout,
    cfg: &LocateConfig,
    ratios: &[f64],
    trials: usize,
    first_seed: u64,
    threads: usize,
) -> Result<Vec<RangePoint>> {
    let (y0, z0) = base.offset_east_down_m;
    let range = crate::error::positive("closest-approach distance", y0.hypot(z0))?;
    let with_model = |model| LocateConfig {
        difference_model: model,
        ..*cfg
    };
    ratios
        .iter()
        .map(|&ratio| {
            let ratio = crate::error::positive("range_over_baseline", ratio)?;
            let s = Scenario {
                geometry: Geometry::new(layout, range / ratio)?,
                ..base.clone()
            };
            let run = |model| {
                monte_carlo(
                    &s,
                    Gradiometer::Tensor,
                    &with_model(model),
                    trials,
                    first_seed,
                    threads,
                )
            };
            let exact = run(DifferenceModel::Exact)?;
            let approx = run(DifferenceModel::GradientTensor)?;
            let mut quiet = s.clone();
            quiet.vector_sensor.noise_nt = 0.0;
            let e0 = trial_error::<6>(
                &quiet,
                Gradiometer::Tensor,
                &deterministic_processing(),
                &with_model(DifferenceModel::GradientTensor),
                first_seed,
            )?;
            let block = |start: usize| {
                let b2: f64 = approx.crlb_sigma[start..start + 3]
                    .iter()
                    .map(|v| v * v)
                    .sum();
                e0.fixed_rows::<3>(start).norm() / b2.sqrt()
            };
            Ok(RangePoint {
                range_over_baseline: ratio,
                baseline_m: range / ratio,
                approx_noise_free_position: block(0),
                approx_noise_free_moment: block(3),
                exact,
                approx,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn result_does_not_depend_on_the_thread_count_and_zero_trials_is_an_error() {
        let s = Scenario {
            epochs: 30,
            ..well_posed(SystemMotion::Stationary, Layout::Tetrahedron).unwrap()
        };
        let cfg = efficient_locate(s.scalar_sensor.noise_nt).unwrap();
        let a = monte_carlo(&s, Gradiometer::Scalar, &cfg, 5, 10, 1).unwrap();
        let b = monte_carlo(&s, Gradiometer::Scalar, &cfg, 5, 10, 3).unwrap();
        assert_eq!(a, b);
        assert_eq!(a.trials, 5);
        assert!(a.position.is_none() && a.names.len() == 3);
        assert!(monte_carlo(&s, Gradiometer::Scalar, &cfg, 0, 10, 1).is_err());
    }

    #[test]
    fn range_study_does_not_depend_on_the_thread_count_and_checks_its_ratios() {
        let s = well_posed(SystemMotion::Stationary, Layout::Tetrahedron).unwrap();
        let cfg = efficient_locate(s.vector_sensor.noise_nt).unwrap();
        let run = |threads, ratios: &[f64]| {
            approximation_range_study(&s, Layout::Tetrahedron, &cfg, ratios, 3, 7, threads)
        };
        let a = run(1, &[4.0]).unwrap();
        assert_eq!(a, run(3, &[4.0]).unwrap());
        assert_eq!(a.len(), 1);
        assert!((a[0].baseline_m * 4.0 - 40f64.sqrt()).abs() < 1e-12);
        // same seeds, same bound: only the estimator's model differs
        assert_eq!(a[0].exact.crlb_sigma, a[0].approx.crlb_sigma);
        assert_ne!(a[0].exact.rms, a[0].approx.rms);
        assert!(run(1, &[0.0]).is_err());
    }
}
