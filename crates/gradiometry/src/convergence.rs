//! Convergence map of the tensor IEKF (seed `004_…`, fig. 2; spec
//! `gradiometry.md`, "Convergence region") and a multi-start initialisation
//! that converges from every start.
//!
//! **Case** ([`ConvergenceCase::seed_fig2`]): a dipole at (5, 0, 0.306) m
//! from the measuring centre with |M| = 100 A·m², sensor noise σ = 1 nT,
//! one epoch of the 9 white contrasts (one seeded noise draw, the same for
//! every start); the IEKF starts from position `r₀` on an `n³` grid over
//! the cube `[−a, a]³` with zero moment and a wide diagonal prior, and
//! iterates (sr_iekf) up to `max_iterations`. A start *converges* when the
//! residual reaches the noise level and the estimate is within
//! `tolerance_m` of the true position.
//!
//! Zero initial moment makes the first linearisation blind to the position
//! (`∂B/∂r ∝ M`): the first iteration fits the moment for the assumed
//! position, then position and moment move together. The plain IEKF cannot
//! cross the plane through the centre orthogonal to the source direction
//! (the seed's half-space), which this map reproduces.
//!
//! **Initialisation** ([`Initialisation::MultiStart`]): run the IEKF from
//! the given start and from a fixed, data-independent set of candidate
//! starts (the 26 directions of the cube's faces, edges and corners at
//! ranges 3 and 10 m), and keep the result with the smallest residual
//! (ties broken by order). The candidates do not depend on the start, so
//! they are run once per data set and shared by every start of the map.
//!
//! Parallel over threads ([`aeromag_core::parallel::parallel_map`]); each start is
//! independent, so the map is identical for any thread count.

use crate::error::{GradiometryError, Result, positive};
use crate::forward::{Background, Forward, TensorForward};
use crate::geometry::{Geometry, Layout};
use crate::sr_iekf::{EpochResult, IekfConfig, SrState, iterate_epoch};
use aeromag_core::parallel::parallel_map;
use aeromag_core::random::{normal, stream};
use nalgebra::{SVector, Vector3};

/// Configuration of a convergence map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConvergenceCase {
    /// Gradiometer layout.
    pub geometry: Geometry,
    /// True dipole position relative to the centre, m.
    pub position_m: Vector3<f64>,
    /// True moment, A·m².
    pub moment_am2: Vector3<f64>,
    /// Sensor noise σ per component, nT.
    pub sigma_nt: f64,
    /// Half width `a` of the start cube, m.
    pub half_width_m: f64,
    /// Grid points per axis `n` (≥ 2).
    pub grid_n: usize,
    /// Prior σ of each position component, m.
    pub prior_sigma_position_m: f64,
    /// Prior σ of each moment component, A·m².
    pub prior_sigma_moment_am2: f64,
    /// Position tolerance of a converged start, m.
    pub tolerance_m: f64,
    /// IEKF settings.
    pub iekf: IekfConfig,
    /// Noise seed.
    pub seed: u64,
}

impl ConvergenceCase {
    /// The seed's fig. 2 case on an `n³` grid (tetrahedron, 1 m baseline,
    /// moment 100 A·m² along (1, 1, 1)/√3, prior σ 20 m and 1000 A·m²,
    /// tolerance 0.5 m, at most 30 iterations with the residual-only stop rule).
    pub fn seed_fig2(grid_n: usize) -> Self {
        let geometry = match Geometry::new(Layout::Tetrahedron, 1.0) {
            Ok(g) => g,
            Err(_) => unreachable!("constant layout is valid"),
        };
        let iekf = IekfConfig {
            sigma_nt: 1.0,
            max_iterations: 30,
            residual_factor: 1.5,
            step_fraction: 0.0,
        };
        Self {
            geometry,
            position_m: Vector3::new(5.0, 0.0, 0.306),
            moment_am2: Vector3::new(1.0, 1.0, 1.0).normalize() * 100.0,
            sigma_nt: 1.0,
            half_width_m: 20.0,
            grid_n,
            prior_sigma_position_m: 20.0,
            prior_sigma_moment_am2: 1000.0,
            tolerance_m: 0.5,
            iekf,
            seed: 4,
        }
    }

    fn validate(&self) -> Result<()> {
        positive("sigma_nt", self.sigma_nt)?;
        positive("half_width_m", self.half_width_m)?;
        positive("prior_sigma_position_m", self.prior_sigma_position_m)?;
        positive("prior_sigma_moment_am2", self.prior_sigma_moment_am2)?;
        positive("tolerance_m", self.tolerance_m)?;
        if self.grid_n < 2 {
            return Err(GradiometryError::NotPositive {
                name: "grid_n - 1",
                value: self.grid_n as f64 - 1.0,
            });
        }
        Ok(())
    }

    /// Start position of grid index `(i, j, k)` (x fastest), m.
    pub fn start(&self, i: usize, j: usize, k: usize) -> Vector3<f64> {
        let a = self.half_width_m;
        let step = 2.0 * a / (self.grid_n - 1) as f64;
        Vector3::new(
            -a + step * i as f64,
            -a + step * j as f64,
            -a + step * k as f64,
        )
    }

    fn model(&self) -> TensorForward {
        TensorForward {
            geometry: self.geometry,
            background: Background::zero(),
        }
    }

    /// The epoch's noisy contrasts (seeded), nT.
    pub fn measurement(&self) -> SVector<f64, 9> {
        let mut x = SVector::<f64, 6>::zeros();
        x.fixed_rows_mut::<3>(0).copy_from(&self.position_m);
        x.fixed_rows_mut::<3>(3).copy_from(&self.moment_am2);
        let (z, _) = self.model().eval(&x);
        let mut rng = stream(self.seed, 0);
        // Sensor noise is white per sensor axis; the orthonormal contrasts of
        // white noise are white with the same σ.
        z + SVector::<f64, 9>::from_fn(|_, _| self.sigma_nt * normal(&mut rng))
    }

    fn prior(&self, start: &Vector3<f64>) -> SrState<6> {
        let mut x = SVector::<f64, 6>::zeros();
        x.fixed_rows_mut::<3>(0).copy_from(start);
        let p = self.prior_sigma_position_m;
        let m = self.prior_sigma_moment_am2;
        SrState::diagonal(x, &SVector::<f64, 6>::from([p, p, p, m, m, m]))
    }
}

/// Which starting procedure the map uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Initialisation {
    /// The plain IEKF from the grid start (seed fig. 2).
    None,
    /// Best of the grid start and the fixed candidate set (module docs).
    MultiStart,
}

/// Result of one start.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StartOutcome {
    /// IEKF iterations used (of the winning run for multi-start).
    pub iterations: u16,
    /// Converged to the true source (residual and tolerance).
    pub converged: bool,
}

/// A convergence map over the `n³` grid, index `i + n (j + n k)`.
#[derive(Debug, Clone, PartialEq)]
pub struct ConvergenceMap {
    /// Grid points per axis.
    pub n: usize,
    /// Outcome per start.
    pub outcomes: Vec<StartOutcome>,
}

impl ConvergenceMap {
    /// Fraction of converged starts.
    pub fn converged_fraction(&self) -> f64 {
        self.outcomes.iter().filter(|o| o.converged).count() as f64
            / self.outcomes.len().max(1) as f64
    }

    /// Converged fraction among the starts with `pred(start)` true.
    pub fn fraction_where(
        &self,
        case: &ConvergenceCase,
        pred: impl Fn(&Vector3<f64>) -> bool,
    ) -> f64 {
        let (mut hit, mut all) = (0usize, 0usize);
        for (idx, o) in self.outcomes.iter().enumerate() {
            let (i, j, k) = (
                idx % self.n,
                (idx / self.n) % self.n,
                idx / (self.n * self.n),
            );
            if pred(&case.start(i, j, k)) {
                all += 1;
                hit += o.converged as usize;
            }
        }
        hit as f64 / all.max(1) as f64
    }

    /// Iterations on the slice `index` across `axis` (0 = x, 1 = y,
    /// 2 = z) as an `n×n` row-major grid whose columns run along the lower
    /// remaining axis and rows along the higher one (slice z: column x,
    /// row y); `None` where the start failed.
    pub fn slice(&self, axis: usize, index: usize) -> Vec<Option<u16>> {
        let n = self.n;
        let f = index.min(n - 1);
        (0..n * n)
            .map(|cell| {
                let (c, r) = (cell % n, cell / n);
                let (i, j, k) = match axis {
                    0 => (f, c, r),
                    1 => (c, f, r),
                    _ => (c, r, f),
                };
                let o = self.outcomes[i + n * (j + n * k)];
                o.converged.then_some(o.iterations)
            })
            .collect()
    }
}

/// A finished IEKF run: estimate, residual, iterations.
#[derive(Debug, Clone, Copy)]
struct Run {
    x: SVector<f64, 6>,
    residual: f64,
    iterations: u16,
    reached: bool,
}

fn run_from(
    case: &ConvergenceCase,
    model: &TensorForward,
    z: &SVector<f64, 9>,
    start: &Vector3<f64>,
) -> Run {
    match iterate_epoch(&case.prior(start), z, model, &case.iekf) {
        Ok(r) => Run {
            x: r.posterior.x,
            residual: r.residual_nt,
            iterations: r.iterations as u16,
            reached: r.converged,
        },
        Err(_) => Run {
            x: SVector::zeros(),
            residual: f64::INFINITY,
            iterations: case.iekf.max_iterations as u16,
            reached: false,
        },
    }
}

/// The fixed candidate starts of [`Initialisation::MultiStart`]: 26
/// directions × ranges {3, 10} m.
pub fn candidate_starts() -> Vec<Vector3<f64>> {
    let mut out = Vec::with_capacity(52);
    for range in [3.0, 10.0] {
        for a in -1i32..=1 {
            for b in -1i32..=1 {
                for c in -1i32..=1 {
                    if (a, b, c) != (0, 0, 0) {
                        out.push(Vector3::new(a as f64, b as f64, c as f64).normalize() * range);
                    }
                }
            }
        }
    }
    out
}

/// Multi-start initialisation of the tensor IEKF on one epoch: run
/// [`iterate_epoch`] from every position of [`candidate_starts`] (zero
/// moment, diagonal prior σ `prior_sigma_position_m` per axis and
/// `prior_sigma_moment_am2`), keep the smallest residual (first on ties).
/// Use it to start a pass at the first epoch with a clear signal.
pub fn multistart_epoch(
    model: &TensorForward,
    z: &SVector<f64, 9>,
    cfg: &IekfConfig,
    prior_sigma_position_m: f64,
    prior_sigma_moment_am2: f64,
) -> Result<EpochResult<6>> {
    positive("prior_sigma_position_m", prior_sigma_position_m)?;
    positive("prior_sigma_moment_am2", prior_sigma_moment_am2)?;
    let (p, m) = (prior_sigma_position_m, prior_sigma_moment_am2);
    let sig = SVector::<f64, 6>::from([p, p, p, m, m, m]);
    let mut best: Option<EpochResult<6>> = None;
    for s in candidate_starts() {
        let x = SVector::<f64, 6>::from([s.x, s.y, s.z, 0.0, 0.0, 0.0]);
        let Ok(r) = iterate_epoch(&SrState::diagonal(x, &sig), z, model, cfg) else {
            continue;
        };
        if best.is_none_or(|b| r.residual_nt < b.residual_nt) {
            best = Some(r);
        }
    }
    best.ok_or(GradiometryError::NotFinite {
        name: "every multi-start run",
    })
}

/// Run the convergence map on `threads` threads (≥ 1); bit-identical for
/// any thread count.
pub fn convergence_map(
    case: &ConvergenceCase,
    init: Initialisation,
    threads: usize,
) -> Result<ConvergenceMap> {
    case.validate()?;
    let model = case.model();
    let z = case.measurement();
    let best_candidate = match init {
        Initialisation::None => None,
        Initialisation::MultiStart => {
            let r = multistart_epoch(
                &model,
                &z,
                &case.iekf,
                case.prior_sigma_position_m,
                case.prior_sigma_moment_am2,
            )?;
            Some(Run {
                x: r.posterior.x,
                residual: r.residual_nt,
                iterations: r.iterations as u16,
                reached: r.converged,
            })
        }
    };
    let n = case.grid_n;
    let outcomes = parallel_map(n * n * n, threads, |idx| {
        let s = case.start(idx % n, (idx / n) % n, idx / (n * n));
        let mut run = run_from(case, &model, &z, &s);
        if let Some(b) = best_candidate
            && b.residual < run.residual
        {
            run = b;
        }
        let pos = run.x.fixed_rows::<3>(0).into_owned();
        let ok = run.reached && (pos - case.position_m).norm() <= case.tolerance_m;
        StartOutcome {
            iterations: run.iterations,
            converged: ok,
        }
    });
    Ok(ConvergenceMap { n, outcomes })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plain_iekf_converges_only_from_the_source_half_space() {
        let case = ConvergenceCase::seed_fig2(9);
        let map = convergence_map(&case, Initialisation::None, 2).unwrap();
        let dir = case.position_m.normalize();
        // Starts more than 1 m off the separating plane, within 15 m (the
        // seed's hemisphere) on the source side, anywhere on the other side.
        let near = map.fraction_where(&case, |s| s.dot(&dir) > 1.0 && s.norm() < 15.0);
        let far = map.fraction_where(&case, |s| s.dot(&dir) < -1.0);
        eprintln!(
            "plain: all {:.3} source side {near:.3} other side {far:.3}",
            map.converged_fraction()
        );
        assert!(near > 0.15, "source half-space fraction {near}");
        assert!(far < 0.03, "opposite half-space fraction {far}");
        assert!(near > 10.0 * far);
    }

    #[test]
    fn multistart_converges_from_every_start_and_is_thread_independent() {
        let case = ConvergenceCase::seed_fig2(9);
        let map = convergence_map(&case, Initialisation::MultiStart, 2).unwrap();
        eprintln!("multistart: {:.3}", map.converged_fraction());
        assert_eq!(map.converged_fraction(), 1.0);
        let one = convergence_map(&case, Initialisation::MultiStart, 1).unwrap();
        assert_eq!(one, map);
    }
}
