//! Square-root iterated extended Kalman filter (seed `004_…`, tables 1–2,
//! fig. 1/3; spec `gradiometry.md`, "Estimator").
//!
//! The covariance is kept as an **upper-triangular** square root,
//! `P = S Sᵀ`, and both steps are those of the project's square-root Kalman
//! toolkit ([`aeromag_estimation::kalman`], also used by the compensation's
//! filter), so the factor never goes through `P`:
//!
//! **Prediction** ([`prognosis`], the seed's `PrognosisFK`):
//! `x⁻ = F x⁺`, and `S⁻` is the upper-triangular factor with
//! `S⁻ S⁻ᵀ = F S⁺ S⁺ᵀ Fᵀ + S_Q S_Qᵀ`, obtained by re-triangularising the
//! wide factor `[S_Q, F S⁺]` with Householder reflections
//! ([`triangularize_upper`]).
//!
//! **Scalar update** ([`processing`], `ProcessingFK`): for a measurement
//! `y = h x + v`, `var v = σ²`, innovation `ν`, Carlson's triangular form
//! of the square-root update ([`carlson_update`]):
//!
//! ```text
//! f = Sᵀ h,  α = fᵀ f + σ²,  K = S f / α,  x ← x + K ν,
//! S ← triangular S⁺ with S⁺ S⁺ᵀ = S (I − f fᵀ/α) Sᵀ = P − K hᵀ P
//! ```
//!
//! (The seed writes the update in Potter's form, `S ← S − β (S f) fᵀ`,
//! which gives a full factor of the same `P`; the triangular one costs half
//! and keeps the prediction's input triangular.)
//!
//! **Iteration per epoch** ([`iterate_epoch`]): with prior `(x⁻, S⁻)` and
//! the epoch's white contrasts `z` (noise σ each), relinearise at the
//! current iterate `x_i` and process the `Z` scalar contrasts one at a time
//! from the prior, with innovations
//! `ν_j = z_j − h_j(x_i) − H_j (x_cur − x_i)` (the IEKF of Bell & Cathey
//! in sequential form). Stop when the residual `‖z − h(x_{i+1})‖` is at the
//! noise level (`≤ k σ √Z`, the seed's eqs. 19/30) and the step is below a
//! small fraction of the posterior σ, or after a maximum count.

use crate::error::{GradiometryError, Result, positive};
use crate::forward::Forward;
use aeromag_estimation::kalman::carlson::carlson_update;
use aeromag_estimation::kalman::triangularize::triangularize_upper;
use nalgebra::{SMatrix, SVector};

/// State estimate and covariance square root (`P = S Sᵀ`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SrState<const N: usize> {
    /// State estimate (m, A·m²).
    pub x: SVector<f64, N>,
    /// Covariance square root `S` (`P = S Sᵀ`), **upper triangular** (the
    /// entries below the diagonal are zero and never read), same units as
    /// `x`.
    pub s: SMatrix<f64, N, N>,
}

impl<const N: usize> SrState<N> {
    /// State with a diagonal prior of standard deviations `sigma`.
    pub fn diagonal(x: SVector<f64, N>, sigma: &SVector<f64, N>) -> Self {
        Self {
            x,
            s: SMatrix::from_diagonal(sigma),
        }
    }

    /// Standard deviations `√diag(S Sᵀ)` (row norms of `S`).
    pub fn sigma(&self) -> SVector<f64, N> {
        SVector::from_fn(|i, _| self.s.row(i).norm())
    }

    /// The state of `y = T x` (`M ≤ N` components): estimate `T x` and
    /// the upper-triangular root of `T S Sᵀ Tᵀ`, re-triangularised from the
    /// wide factor `T S` ([`triangularize_upper`]).
    pub fn mapped<const M: usize>(&self, t: &SMatrix<f64, M, N>) -> SrState<M> {
        assert!(
            M <= N && N <= MAX_STATES,
            "a map to at most the {N} states of at most {MAX_STATES}"
        );
        let ts = t * self.s;
        let mut buf = [0.0; MAX_STATES * MAX_STATES];
        let a = &mut buf[..M * N];
        for i in 0..M {
            for j in 0..N {
                a[i * N + j] = ts[(i, j)];
            }
        }
        let mut work = [0.0; MAX_STATES];
        triangularize_upper(a, M, N, &mut work[..N]);
        SrState {
            x: t * self.x,
            s: SMatrix::from_fn(|i, j| a[i * N + N - M + j]),
        }
    }
}

/// Largest state dimension of the filter (the scalar system's permanent and
/// induced moment and contrast offset: 9).
const MAX_STATES: usize = 9;

/// `PrognosisFK`: `x⁻ = F x`, `S⁻ = tri([diag(s_q), F S])` (module docs).
pub fn prognosis<const N: usize>(
    state: &SrState<N>,
    f: &SMatrix<f64, N, N>,
    s_q: &SVector<f64, N>,
) -> SrState<N> {
    let fs = f * state.s;
    // The wide factor, row-major, N × 2N: the process-noise columns first
    // (stack buffers: this runs for every epoch of every start of a map).
    let c = 2 * N;
    assert!(
        N <= MAX_STATES,
        "the gradiometer filter has at most {MAX_STATES} states"
    );
    let mut buf = [0.0; 2 * MAX_STATES * MAX_STATES];
    let a = &mut buf[..N * c];
    for i in 0..N {
        a[i * c + i] = s_q[i];
        for j in 0..N {
            a[i * c + N + j] = fs[(i, j)];
        }
    }
    let mut work = [0.0; 2 * MAX_STATES];
    triangularize_upper(a, N, c, &mut work);
    SrState {
        x: f * state.x,
        s: SMatrix::from_fn(|i, j| a[i * c + N + j]),
    }
}

/// `ProcessingFK`: the scalar update with measurement row `h`, innovation
/// `nu` and measurement variance `sigma2 > 0` (Carlson's triangular form,
/// module docs). Errors (state untouched) on a non-finite row or
/// innovation.
pub fn processing<const N: usize>(
    state: &mut SrState<N>,
    h: &SVector<f64, N>,
    nu: f64,
    sigma2: f64,
) -> Result<()> {
    // Carlson's update takes the measurement y with ν = y − hᵀx.
    let y = nu + h.dot(&state.x);
    let mut gain = [0.0; N];
    assert!(
        N <= MAX_STATES,
        "the gradiometer filter has at most {MAX_STATES} states"
    );
    let mut work = [0.0; 3 * MAX_STATES];
    carlson_update(
        state.s.as_mut_slice(),
        state.x.as_mut_slice(),
        h.as_slice(),
        y,
        sigma2,
        &mut gain,
        &mut work[..3 * N],
    )
    .map_err(|_| GradiometryError::NotFinite {
        name: "IEKF measurement or its row",
    })?;
    Ok(())
}

/// One pass of the `Z` scalar updates from `prior`, linearised about `x_lin`
/// where the model gives `h(x_lin) = hx`, `∂h/∂x = hj`; innovations
/// `ν_j = z_j − h_j(x_lin) − H_j (x_cur − x_lin)`, variance `sigma2` (nT²).
pub fn update_linearised<const N: usize, const Z: usize>(
    prior: &SrState<N>,
    z: &SVector<f64, Z>,
    x_lin: &SVector<f64, N>,
    hx: &SVector<f64, Z>,
    hj: &SMatrix<f64, Z, N>,
    sigma2: f64,
) -> Result<SrState<N>> {
    let mut post = *prior;
    for j in 0..Z {
        let row = hj.row(j).transpose();
        let nu = z[j] - hx[j] - row.dot(&(post.x - x_lin));
        processing(&mut post, &row, nu, sigma2)?;
    }
    Ok(post)
}

/// Settings of the per-epoch iteration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IekfConfig {
    /// Noise σ of each white contrast (nT) — equal to the sensor noise σ.
    pub sigma_nt: f64,
    /// Maximum iterations per epoch.
    pub max_iterations: usize,
    /// `k` of the residual threshold `k σ √Z`.
    pub residual_factor: f64,
    /// Stop only when every state change is below this fraction of the
    /// posterior σ (0 disables the step test: the seed's residual-only rule).
    pub step_fraction: f64,
}

impl IekfConfig {
    /// σ (nT), 30 iterations, `k = 1.5`, step fraction 0.01.
    pub fn new(sigma_nt: f64) -> Result<Self> {
        positive("sigma_nt", sigma_nt)?;
        Ok(Self {
            sigma_nt,
            max_iterations: 30,
            residual_factor: 1.5,
            step_fraction: 0.01,
        })
    }
}

/// Outcome of one epoch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EpochResult<const N: usize> {
    /// Posterior estimate and square root.
    pub posterior: SrState<N>,
    /// Iterations used (≥ 1).
    pub iterations: usize,
    /// Residual `‖z − h(x⁺)‖` (nT).
    pub residual_nt: f64,
    /// Residual at the noise level when the iteration stopped.
    pub converged: bool,
}

/// One IEKF epoch: iterate scalar updates from `prior` until the stop rule
/// (module docs). Errors only on a non-finite estimate.
pub fn iterate_epoch<const N: usize, const Z: usize, F: Forward<N, Z>>(
    prior: &SrState<N>,
    z: &SVector<f64, Z>,
    model: &F,
    cfg: &IekfConfig,
) -> Result<EpochResult<N>> {
    let sigma2 = cfg.sigma_nt * cfg.sigma_nt;
    let threshold = cfg.residual_factor * cfg.sigma_nt * (Z as f64).sqrt();
    let mut xi = prior.x;
    let (mut hx, mut hj) = model.eval(&xi);
    let mut post = *prior;
    let mut iterations = 0;
    let mut residual = (z - hx).norm();
    let mut converged = false;
    while iterations < cfg.max_iterations.max(1) {
        iterations += 1;
        post = update_linearised(prior, z, &xi, &hx, &hj, sigma2)?;
        if !post.x.iter().all(|v| v.is_finite()) {
            return Err(GradiometryError::NotFinite {
                name: "IEKF estimate",
            });
        }
        let step = post.x - xi;
        xi = post.x;
        (hx, hj) = model.eval(&xi);
        residual = (z - hx).norm();
        if residual <= threshold {
            converged = true;
            if cfg.step_fraction == 0.0 {
                break;
            }
            let sig = post.sigma();
            if (0..N).all(|k| step[k].abs() <= cfg.step_fraction * sig[k]) {
                break;
            }
        } else {
            converged = false;
        }
    }
    Ok(EpochResult {
        posterior: post,
        iterations,
        residual_nt: residual,
        converged,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scalar_update_matches_the_covariance_form() {
        let s = SMatrix::<f64, 3, 3>::new(2.0, 0.5, -0.3, 0.0, 1.0, 0.2, 0.0, 0.0, 0.7);
        let mut st = SrState {
            x: SVector::<f64, 3>::zeros(),
            s,
        };
        let p = s * s.transpose();
        let h = SVector::<f64, 3>::new(0.3, -1.0, 2.0);
        let r = 0.4;
        processing(&mut st, &h, 1.7, r).unwrap();
        let ph = p * h;
        let k = ph / (h.dot(&ph) + r);
        let p_plus = p - k * ph.transpose();
        assert!((st.s * st.s.transpose() - p_plus).norm() < 1e-12);
        assert!((st.x - k * 1.7).norm() < 1e-12);
    }

    proptest::proptest! {
        /// The triangular update keeps `S Sᵀ` equal to the covariance-form
        /// posterior and the estimate equal to `x + K ν` for any upper-
        /// triangular prior root, measurement row and variance.
        #[test]
        fn scalar_update_is_exact(
            d in proptest::collection::vec(0.1f64..10.0, 4),
            off in proptest::collection::vec(-3.0f64..3.0, 6),
            h in proptest::collection::vec(-5.0f64..5.0, 4),
            r in 1e-4f64..100.0,
            nu in -10.0f64..10.0,
        ) {
            let mut s = SMatrix::<f64, 4, 4>::from_diagonal(&SVector::<f64, 4>::from_column_slice(&d));
            let mut k = 0;
            for i in 1..4 {
                for j in 0..i {
                    s[(j, i)] = off[k];
                    k += 1;
                }
            }
            let h = SVector::<f64, 4>::from_column_slice(&h);
            let p = s * s.transpose();
            let mut st = SrState { x: SVector::<f64, 4>::zeros(), s };
            processing(&mut st, &h, nu, r).unwrap();
            let ph = p * h;
            let gain = ph / (h.dot(&ph) + r);
            let p_plus = p - gain * ph.transpose();
            proptest::prop_assert!((st.s * st.s.transpose() - p_plus).norm() <= 1e-9 * (1.0 + p.norm()));
            proptest::prop_assert!((st.x - gain * nu).norm() <= 1e-9 * (1.0 + (gain * nu).norm()));
        }
    }

    #[test]
    fn a_mapped_state_has_the_mapped_covariance() {
        let s = SMatrix::<f64, 3, 3>::new(2.0, 0.5, -0.3, 0.0, 1.0, 0.2, 0.0, 0.0, 0.7);
        let st = SrState {
            x: SVector::<f64, 3>::new(1.0, 2.0, 3.0),
            s,
        };
        let t = SMatrix::<f64, 2, 3>::new(1.0, 0.0, 1.0, 0.5, -1.0, 0.0);
        let y = st.mapped(&t);
        let p = t * s * s.transpose() * t.transpose();
        assert!((y.s * y.s.transpose() - p).norm() < 1e-12);
        assert!((y.x - t * st.x).norm() < 1e-15);
        assert_eq!(y.s[(1, 0)], 0.0);
    }

    #[test]
    fn prognosis_matches_the_covariance_form() {
        let s = SMatrix::<f64, 3, 3>::new(2.0, 0.5, -0.3, 0.0, 1.0, 0.2, 0.0, 0.0, 0.7);
        let f = SMatrix::<f64, 3, 3>::new(1.0, 0.1, 0.0, 0.0, 1.0, 0.2, 0.05, 0.0, 1.0);
        let q = SVector::<f64, 3>::new(0.1, 0.2, 0.3);
        let x = SVector::<f64, 3>::new(1.0, 2.0, 3.0);
        let out = prognosis(&SrState { x, s }, &f, &q);
        let p =
            f * s * s.transpose() * f.transpose() + SMatrix::from_diagonal(&q.component_mul(&q));
        assert!((out.s * out.s.transpose() - p).norm() < 1e-12);
        assert!((out.x - f * x).norm() < 1e-15);
        // upper triangular, as the scalar update needs it
        assert_eq!(
            out.s[(1, 0)].abs() + out.s[(2, 0)].abs() + out.s[(2, 1)].abs(),
            0.0
        );
    }
}
