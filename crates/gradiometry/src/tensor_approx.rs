//! The gradient-tensor (linear) approximation of the tensor gradiometer's
//! differences — the model seed `004_…` argues *against* (sect. 3, opening
//! paragraphs: "the linear formulation neglects the displacement of the
//! sensors relative to each other; the gradient differences are taken as
//! components of the tensor referred to the geometric centre of the
//! system; this is justified when the distance to the source far exceeds
//! the size of the system … when the baseline is comparable to the range,
//! the linear formulation is not accurate enough and the exact differences
//! should be used"; spec `gradiometry.md`, "Measuring systems"). It exists
//! here to measure where that argument bites
//! ([`crate::efficiency::approximation_range_study`]).
//!
//! Frame and units as in [`crate::forward`]: body frame, `r` the dipole's
//! position relative to the measuring centre (m), `M` in A·m², fields in
//! nT. The exact model reads each sensor at `ρ_i = δr_i − r`; the
//! approximation expands every sensor's field to first order about the
//! centre, `ρ = −r`:
//!
//! ```text
//! B_i − B_j ≈ (G_bg + G(M, ρ)) (δr_i − δr_j)                           (nT)
//! G(M, ρ)   = 10⁹ · 3μ0/(4π|ρ|⁵) [(M·ρ) I + M ρᵀ + ρ Mᵀ − 5 (M·ρ) ρρᵀ/|ρ|²]   (nT/m)
//! ```
//!
//! so the white contrasts of [`crate::decorrelate`] (rows `T_j` of the
//! contrast matrix, `Σ_i T_ji = 0`) become, with the contrast lever
//! `a_j = Σ_i T_ji δr_i` (m),
//!
//! ```text
//! z_j = (G_bg + G(M, ρ)) a_j                                            (nT)
//! ```
//!
//! (the uniform background cancels exactly, as in the exact model). The
//! error against the exact differences is the second-order Taylor term,
//! relative size `O(baseline/range)`.
//!
//! **Jacobian** (analytic). `G(M, ρ) a` is symmetric in `M ↔ a`, so
//! `∂z_j/∂M = G(a_j, ρ)`. With `s = M·ρ`, `t = a·ρ`, `u = M·a`,
//! `q = |ρ|²`, `k = 10⁹ μ0/(4π)` and
//! `g = s a + t M + u ρ − 5 s t ρ/q` (so `G(M, ρ) a = 3k g q^{−5/2}`):
//!
//! ```text
//! ∂g/∂ρ    = a Mᵀ + M aᵀ + u I − 5 [ρ (t Mᵀ + s aᵀ)/q + (s t/q) I − 2 s t ρρᵀ/q²]
//! ∂z_j/∂ρ  = 3k [q^{−5/2} ∂g/∂ρ − 5 q^{−7/2} g ρᵀ]                      (nT/m)
//! ∂z_j/∂r  = −∂z_j/∂ρ
//! ```

use crate::decorrelate::contrast_matrix;
use crate::forward::{Background, Forward, TensorForward};
use crate::geometry::Geometry;
use aeromag_core::field::dipole::{MIN_DISTANCE_M, dipole_gradient};
use aeromag_core::{MU0_OVER_4PI, NT_PER_T};
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

/// The forward model of the tensor gradiometer's differences used by the
/// estimator ([`crate::locate::LocateConfig::difference_model`]). The
/// simulator always computes the exact physics. In scenario files
/// `"exact"`, `"gradient_tensor"`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DifferenceModel {
    /// The exact sensor differences ([`TensorForward`]; the seed's choice).
    #[default]
    Exact,
    /// The gradient-tensor approximation at the measuring centre
    /// ([`TensorApproxForward`], module docs).
    GradientTensor,
}

/// Tensor gradiometer under the gradient-tensor approximation: state
/// `(r, M)`, 9 contrasts (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TensorApproxForward {
    /// Sensor layout.
    pub geometry: Geometry,
    /// Known background.
    pub background: Background,
}

impl From<TensorForward> for TensorApproxForward {
    fn from(f: TensorForward) -> Self {
        Self {
            geometry: f.geometry,
            background: f.background,
        }
    }
}

impl TensorApproxForward {
    /// The contrast levers `a_j = Σ_i T_ji δr_i` (m), `j = 0, 1, 2`.
    pub fn levers_m(&self) -> [Vector3<f64>; 3] {
        let t = contrast_matrix();
        let d = self.geometry.offsets_m();
        std::array::from_fn(|j| (0..4).map(|i| d[i] * t[(j, i)]).sum())
    }
}

/// `∂(G(M, ρ) a)/∂ρ` (T/m per m, i.e. T/m²) of a dipole `m` (A·m²) at
/// displacement `rho` (m, dipole to observer), for a lever `a` (m); module
/// docs. Zero below [`MIN_DISTANCE_M`], like the core dipole functions.
fn gradient_lever_derivative(
    m: &Vector3<f64>,
    rho: &Vector3<f64>,
    a: &Vector3<f64>,
) -> Matrix3<f64> {
    let q = rho.norm_squared();
    if q < MIN_DISTANCE_M * MIN_DISTANCE_M {
        return Matrix3::zeros();
    }
    let (s, t, u) = (m.dot(rho), a.dot(rho), m.dot(a));
    let g = a * s + m * t + rho * u - rho * (5.0 * s * t / q);
    let dg = a * m.transpose() + m * a.transpose() + Matrix3::identity() * u
        - (rho * (m.transpose() * t + a.transpose() * s) / q + Matrix3::identity() * (s * t / q)
            - rho * rho.transpose() * (2.0 * s * t / (q * q)))
            * 5.0;
    let q52 = q * q * q.sqrt();
    (dg / q52 - g * rho.transpose() * (5.0 / (q52 * q))) * (3.0 * MU0_OVER_4PI)
}

impl Forward<6, 9> for TensorApproxForward {
    fn eval(&self, x: &SVector<f64, 6>) -> (SVector<f64, 9>, SMatrix<f64, 9, 6>) {
        let r = x.fixed_rows::<3>(0).into_owned();
        let m = x.fixed_rows::<3>(3).into_owned();
        let rho = -r;
        let g = self.background.gradient_nt_per_m + dipole_gradient(&m, &rho) * NT_PER_T;
        let mut z = SVector::<f64, 9>::zeros();
        let mut h = SMatrix::<f64, 9, 6>::zeros();
        for (j, a) in self.levers_m().iter().enumerate() {
            z.fixed_rows_mut::<3>(3 * j).copy_from(&(g * a));
            h.fixed_view_mut::<3, 3>(3 * j, 0)
                .copy_from(&(-gradient_lever_derivative(&m, &rho, a) * NT_PER_T));
            h.fixed_view_mut::<3, 3>(3 * j, 3)
                .copy_from(&(dipole_gradient(a, &rho) * NT_PER_T));
        }
        (z, h)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::forward::jacobian_fd;
    use crate::geometry::Layout;

    fn earth() -> Background {
        Background {
            field_nt: Vector3::new(15000.0, 2000.0, 48000.0),
            gradient_nt_per_m: Matrix3::new(
                0.01, 0.002, -0.003, 0.002, -0.004, 0.001, -0.003, 0.001, -0.006,
            ),
        }
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        for layout in [Layout::Tetrahedron, Layout::Cross, Layout::Planar] {
            let f = TensorApproxForward {
                geometry: Geometry::new(layout, 1.0).unwrap(),
                background: earth(),
            };
            for x in [
                [3.0, -1.5, 2.2, 40.0, -70.0, 55.0],
                [-0.8, 6.0, -2.0, 900.0, 300.0, -200.0],
            ] {
                let x = SVector::<f64, 6>::from(x);
                let (_, h) = f.eval(&x);
                let step = SVector::<f64, 6>::from([1e-4, 1e-4, 1e-4, 1e-3, 1e-3, 1e-3]);
                let hfd = jacobian_fd(&f, &x, &step);
                let rel = (h - hfd).norm() / h.norm();
                assert!(rel < 1e-7, "{layout:?}: rel {rel:e}");
            }
        }
    }

    /// Relative error `‖z_approx − z_exact‖ / ‖z_exact‖` (pure dipole) for
    /// baselines `b` at a fixed position: first order in `b/range`.
    #[test]
    fn converges_to_the_exact_differences_at_first_order_in_baseline_over_range() {
        let x = SVector::<f64, 6>::from([5.0, 2.0, -3.0, 800.0, -300.0, 200.0]);
        let range = x.fixed_rows::<3>(0).norm();
        for layout in [Layout::Tetrahedron, Layout::Cross, Layout::Planar] {
            let rel = |b: f64| {
                let exact = TensorForward {
                    geometry: Geometry::new(layout, b).unwrap(),
                    background: Background::zero(),
                };
                let (ze, _) = exact.eval(&x);
                let (za, _) = TensorApproxForward::from(exact).eval(&x);
                (za - ze).norm() / ze.norm()
            };
            let mut prev = rel(range / 4.0);
            for k in 3..9 {
                let ratio = f64::from(1u32 << k); // range/baseline 8 … 256
                let e = rel(range / ratio);
                let order = (prev / e).log2();
                assert!(
                    (0.9..1.1).contains(&order),
                    "{layout:?} range/baseline {ratio}: order {order}"
                );
                // the first-order coefficient is O(1)
                assert!(e * ratio > 0.1 && e * ratio < 10.0, "{layout:?}: {e}");
                prev = e;
            }
            assert!(prev < 0.05, "{layout:?}: {prev}");
        }
    }

    #[test]
    fn gradient_levers_sum_the_contrasts_of_the_offsets() {
        let f = TensorApproxForward {
            geometry: Geometry::new(Layout::Cross, 2.0).unwrap(),
            background: earth(),
        };
        // a uniform gradient alone: the approximation is exact
        let exact = TensorForward {
            geometry: f.geometry,
            background: f.background,
        };
        let x = SVector::<f64, 6>::from([1e6, 0.0, 0.0, 0.0, 0.0, 0.0]);
        let (za, _) = f.eval(&x);
        let (ze, _) = exact.eval(&x);
        assert!((za - ze).norm() < 1e-9, "{}", (za - ze).norm());
        assert_eq!(DifferenceModel::default(), DifferenceModel::Exact);
    }
}
