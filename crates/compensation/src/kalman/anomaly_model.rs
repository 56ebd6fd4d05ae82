//! The stochastic model of the external field along the track (state `X2`)
//! and its exact discretisation over the along-track distance.
//!
//! Seed `000_…` §7 (stochastic model of the anomalous field) and §11 (the
//! matrices `A₂₁, A₂₂, q₂₁, q₂₂, H₂`); spec `compensation.md`, "Method 2".
//!
//! ## Model
//!
//! The field at the sensor is expanded about a reference altitude `z0`:
//! `B0(s, z) = B^h(s) + B_z(s) Δz`, `Δz = alt − z0` (m, **up**), so `B_z` is the
//! derivative of the field modulus with respect to *altitude* (nT/m; it is
//! `−∂B/∂z` in the NED frame). Along the path length `s` (m):
//!
//! ```text
//! dB^h/ds = B^h_x,   dB^h_x/ds = B^h_xx,   dB^h_xx/ds = w₁(s),   E[w₁(s) w₁(s')] = q₁ δ(s − s')
//! dB_z/ds = B_zx,    dB_zx/ds = w₂(s),                          E[w₂(s) w₂(s')] = q₂ δ(s − s')
//! ```
//!
//! i.e. `B^h` is the third integral and `B_z` the second integral of white
//! noise along the path (the thesis writes the same with `d/dt = v d/ds`, `v`
//! the ground speed). The state is `X2 = (B^h, B^h_x, B^h_xx, B_z, B_zx)` in
//! nT, nT/m, nT/m², nT/m, nT/m². `B^h` also absorbs the main field, the
//! diurnal variation (a function of time, but `s ≈ v t`) and any constant.
//!
//! **Units of the intensities.** `w₁` is in nT/m³ and `δ(s)` in 1/m, so `q₁`
//! (and likewise `q₂`) is in **nT²/m⁵** — the one-sided spectral density of
//! the third (second) along-track derivative. Over a step `d` the
//! third derivative changes by `√(q₁ d)` nT/m² (1 σ).
//!
//! ## Exact discretisation over a step of length `d = ∫ v dt` (m)
//!
//! ```text
//! Φ₁ = [[1, d, d²/2], [0, 1, d], [0, 0, 1]],   Q₁ = q₁ [[d⁵/20, d⁴/8, d³/6], [d⁴/8, d³/3, d²/2], [d³/6, d²/2, d]]
//! Φ₂ = [[1, d], [0, 1]],                       Q₂ = q₂ [[d³/3, d²/2], [d²/2, d]]
//! ```
//!
//! (`Q = ∫₀^d e^{Aσ} b bᵀ e^{Aᵀσ} dσ`, Van Loan 1978). The filter needs a
//! factor `G`, `Q = G Gᵀ`: with `T = diag(d^{5/2}, d^{3/2}, d^{1/2})` and the
//! constant `M₁ = [[1/20, 1/8, 1/6], [1/8, 1/3, 1/2], [1/6, 1/2, 1]]`,
//! `Q₁ = q₁ T M₁ T`, so `G₁ = √q₁ T chol(M₁)` in closed form (and likewise
//! `G₂ = √q₂ diag(d^{3/2}, d^{1/2}) chol(M₂)`); no factorisation per step,
//! exact also for `d → 0`.
//!
//! ## Default intensities (calibration altitude)
//!
//! For a potential field observed at height `H` above its sources, the
//! spectrum is cut off at wavenumbers `k ≳ 1/H`, so the field decorrelates
//! over a path length of order `H`. If `σ_xx` is the RMS of the second
//! along-track derivative, a random walk that changes by about `σ_xx` over
//! `H` has `q₁ ≈ σ_xx²/H`, and `σ_xx ≈ σ_x/H` with `σ_x` the RMS along-track
//! gradient: `q₁ ≈ σ_x²/H³`. A realistic area (3 nT/100 m at 100 m above
//! ground) gives `σ_x ≈ 3·10⁻³ nT/m` at `H ≈ 3 km` above the sources,
//! `q₁ ≈ 3·10⁻¹⁶ nT²/m⁵`. The *path* adds curvature: in a turn of radius
//! `R` the along-track second derivative of a field with horizontal
//! gradient `g` jumps by `g/R` (main field: `g ≈ 3·10⁻³ nT/m`, `R ≈ 1.7 km`
//! at 90 m/s and 3°/s, so `≈ 2·10⁻⁶ nT/m²` per turn entry or exit); eight
//! such jumps over a 56 km box give `q₁ ≈ 8 (2·10⁻⁶)² / 56 km ≈ 6·10⁻¹⁶`.
//! The default is `q₁ = 10⁻¹⁵ nT²/m⁵`, which is also the maximum-likelihood
//! value of the true main field plus anomaly along the simulator's
//! calibration box (both areas). The vertical gradient has the same spectrum
//! up to a factor: `q₂ = 10⁻¹⁵`. `r = 4·10⁻⁴ nT²` (0.02 nT RMS: scalar
//! sensor noise, heading error and what the Tolles-Lawson model leaves).
//! [`super::tuning`] adjusts them by maximum likelihood on request.

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

/// Number of states of the field model `X2`.
pub const X2_DIM: usize = 5;
/// Index of `B^h` (nT) in `X2`.
pub const B_H: usize = 0;
/// Index of `B^h_x` (nT/m).
pub const B_H_X: usize = 1;
/// Index of `B^h_xx` (nT/m²).
pub const B_H_XX: usize = 2;
/// Index of `B_z` (nT/m, derivative with respect to altitude).
pub const B_Z: usize = 3;
/// Index of `B_zx` (nT/m²).
pub const B_Z_X: usize = 4;

/// Noise intensities of the model (module docs for the units).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct NoiseModel {
    /// `q₁`: spectral density of `d³B^h/ds³` along the path, nT²/m⁵.
    pub q1_nt2_per_m5: f64,
    /// `q₂`: spectral density of `d²B_z/ds²` along the path, nT²/m⁵.
    pub q2_nt2_per_m5: f64,
    /// `r`: variance of the scalar measurement noise per sample, nT².
    pub r_nt2: f64,
}

impl NoiseModel {
    /// Defaults for a calibration flight at ~3 km (module docs):
    /// `q₁ = q₂ = 10⁻¹⁵ nT²/m⁵`, `r = 4·10⁻⁴ nT²` (0.02 nT RMS).
    pub fn calibration_default() -> Self {
        Self {
            q1_nt2_per_m5: 1e-15,
            q2_nt2_per_m5: 1e-15,
            r_nt2: 4e-4,
        }
    }

    /// Whether every intensity is finite, `q ≥ 0` and `r > 0`.
    pub fn is_valid(&self) -> bool {
        self.q1_nt2_per_m5 >= 0.0
            && self.q2_nt2_per_m5 >= 0.0
            && self.r_nt2 > 0.0
            && self.q1_nt2_per_m5.is_finite()
            && self.q2_nt2_per_m5.is_finite()
            && self.r_nt2.is_finite()
    }
}

impl Default for NoiseModel {
    fn default() -> Self {
        Self::calibration_default()
    }
}

/// The (diffuse) prior of `X2` at the start of every contiguous run of data:
/// zero mean (the measurement is centred first), independent components
/// with these standard deviations.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct X2Prior {
    /// Standard deviation of `B^h`, nT (default 1000: diffuse for a centred
    /// reading).
    pub b_nt: f64,
    /// Standard deviation of `B^h_x`, nT/m (default 0.1, i.e. 10 nT/100 m).
    pub b_x_nt_per_m: f64,
    /// Standard deviation of `B^h_xx`, nT/m² (default 1e-4).
    pub b_xx_nt_per_m2: f64,
    /// Standard deviation of `B_z`, nT/m (default 0.1; the main field's
    /// vertical gradient is ≈ 0.02–0.03 nT/m).
    pub b_z_nt_per_m: f64,
    /// Standard deviation of `B_zx`, nT/m² (default 1e-4).
    pub b_zx_nt_per_m2: f64,
}

impl Default for X2Prior {
    fn default() -> Self {
        Self {
            b_nt: 1000.0,
            b_x_nt_per_m: 0.1,
            b_xx_nt_per_m2: 1e-4,
            b_z_nt_per_m: 0.1,
            b_zx_nt_per_m2: 1e-4,
        }
    }
}

impl X2Prior {
    /// The standard deviations in state order.
    pub fn stds(&self) -> [f64; X2_DIM] {
        [
            self.b_nt,
            self.b_x_nt_per_m,
            self.b_xx_nt_per_m2,
            self.b_z_nt_per_m,
            self.b_zx_nt_per_m2,
        ]
    }

    /// The prior factor (diagonal), `X2_DIM × X2_DIM`.
    pub fn factor(&self) -> DMatrix<f64> {
        DMatrix::from_diagonal(&nalgebra::DVector::from_row_slice(&self.stds()))
    }

    /// Whether every standard deviation is finite and positive.
    pub fn is_valid(&self) -> bool {
        self.stds().iter().all(|s| *s > 0.0 && s.is_finite())
    }
}

/// Exact transition over an along-track step (module docs) for given noise
/// intensities, with the Cholesky factors of `M₁`, `M₂` and `√q₁`, `√q₂`
/// computed once.
#[derive(Debug, Clone)]
pub struct AnomalyTransition {
    l1: [[f64; 3]; 3],
    l2: [[f64; 2]; 2],
    s1: f64,
    s2: f64,
}

impl AnomalyTransition {
    /// Precompute the constant factors for `noise`.
    pub fn new(noise: &NoiseModel) -> Self {
        // Lower Cholesky factor of M₁ = [[1/20, 1/8, 1/6], [1/8, 1/3, 1/2], [1/6, 1/2, 1]].
        let l00 = (1.0f64 / 20.0).sqrt();
        let l10 = (1.0 / 8.0) / l00;
        let l20 = (1.0 / 6.0) / l00;
        let l11 = (1.0 / 3.0 - l10 * l10).sqrt();
        let l21 = (0.5 - l20 * l10) / l11;
        let l22 = (1.0 - l20 * l20 - l21 * l21).sqrt();
        // M₂ = [[1/3, 1/2], [1/2, 1]].
        let m00 = (1.0f64 / 3.0).sqrt();
        let m10 = 0.5 / m00;
        let m11 = (1.0 - m10 * m10).sqrt();
        Self {
            l1: [[l00, 0.0, 0.0], [l10, l11, 0.0], [l20, l21, l22]],
            l2: [[m00, 0.0], [m10, m11]],
            s1: noise.q1_nt2_per_m5.max(0.0).sqrt(),
            s2: noise.q2_nt2_per_m5.max(0.0).sqrt(),
        }
    }

    /// Fill `phi` (5×5) and `g` (5×5, `Q = G Gᵀ`) for a step of `d ≥ 0` m.
    /// Panics if the matrices are not 5×5 (a programming error).
    pub fn fill(&self, d: f64, phi: &mut DMatrix<f64>, g: &mut DMatrix<f64>) {
        assert!(
            phi.shape() == (X2_DIM, X2_DIM) && g.shape() == (X2_DIM, X2_DIM),
            "field transition matrices must be 5×5"
        );
        let d = d.max(0.0);
        // Column-major: entry (i, j) at i + 5 j.
        let p = phi.as_mut_slice();
        p.fill(0.0);
        for i in 0..X2_DIM {
            p[i + X2_DIM * i] = 1.0;
        }
        p[B_H + X2_DIM * B_H_X] = d;
        p[B_H + X2_DIM * B_H_XX] = 0.5 * d * d;
        p[B_H_X + X2_DIM * B_H_XX] = d;
        p[B_Z + X2_DIM * B_Z_X] = d;
        let gs = g.as_mut_slice();
        gs.fill(0.0);
        let sd = d.sqrt();
        let t1 = [d * d * sd, d * sd, sd];
        for i in 0..3 {
            for j in 0..=i {
                gs[i + X2_DIM * j] = self.s1 * t1[i] * self.l1[i][j];
            }
        }
        let t2 = [d * sd, sd];
        for i in 0..2 {
            for j in 0..=i {
                gs[(B_Z + i) + X2_DIM * (B_Z + j)] = self.s2 * t2[i] * self.l2[i][j];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Q by numerical integration of e^{Aσ} b bᵀ e^{Aᵀσ} (Simpson), for the
    /// triple integrator, against G Gᵀ.
    #[test]
    fn noise_factor_reproduces_the_integrated_covariance() {
        let noise = NoiseModel {
            q1_nt2_per_m5: 2.5e-15,
            q2_nt2_per_m5: 7e-16,
            r_nt2: 1.0,
        };
        let tr = AnomalyTransition::new(&noise);
        let d = 9.0;
        let mut phi = DMatrix::zeros(5, 5);
        let mut g = DMatrix::zeros(5, 5);
        tr.fill(d, &mut phi, &mut g);
        let q = &g * g.transpose();
        // e^{Aσ} b for the triple integrator with b = e₃: (σ²/2, σ, 1); double: (σ, 1).
        let n = 2000;
        let h = d / n as f64;
        let mut qn = DMatrix::<f64>::zeros(5, 5);
        for k in 0..=n {
            let s = k as f64 * h;
            let w = if k == 0 || k == n {
                1.0
            } else if k % 2 == 1 {
                4.0
            } else {
                2.0
            };
            let u = [s * s / 2.0, s, 1.0];
            let v = [s, 1.0];
            for i in 0..3 {
                for j in 0..3 {
                    qn[(i, j)] += w * h / 3.0 * noise.q1_nt2_per_m5 * u[i] * u[j];
                }
            }
            for i in 0..2 {
                for j in 0..2 {
                    qn[(3 + i, 3 + j)] += w * h / 3.0 * noise.q2_nt2_per_m5 * v[i] * v[j];
                }
            }
        }
        for i in 0..5 {
            for j in 0..5 {
                assert!(
                    (q[(i, j)] - qn[(i, j)]).abs() <= 1e-10 * qn[(i, j)].abs().max(1e-30),
                    "Q[{i},{j}] {} vs {}",
                    q[(i, j)],
                    qn[(i, j)]
                );
            }
        }
        assert_eq!(phi[(0, 2)], 40.5);
        assert_eq!(phi[(3, 4)], 9.0);
    }

    #[test]
    fn zero_step_is_the_identity_without_noise() {
        let tr = AnomalyTransition::new(&NoiseModel::default());
        let mut phi = DMatrix::zeros(5, 5);
        let mut g = DMatrix::from_element(5, 5, 3.0);
        tr.fill(0.0, &mut phi, &mut g);
        assert_eq!(phi, DMatrix::identity(5, 5));
        assert!(g.iter().all(|v| *v == 0.0));
    }
}
