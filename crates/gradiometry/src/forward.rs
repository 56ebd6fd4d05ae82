//! Forward functions (seed `ForwardMT`, `ForwardMV`; eqs. 5, 16, 20, 28) with
//! analytic Jacobians (the seed's `JacobianH`, which it evaluates by finite
//! differences — kept here only as a test check).
//!
//! Frame and units: everything in the gradiometer's body frame; positions
//! in m, moments in A·m², fields in nT. The state position `r` is the
//! dipole's position relative to the measuring centre, so sensor `i` sees
//! the dipole at displacement `ρ_i = δr_i − r` and reads
//!
//! ```text
//! B_i = B_bg + G_bg δr_i + 10⁹ · μ0/(4π|ρ_i|³) (3 e eᵀ − I) M         (nT)
//! ∂B_i/∂M = 10⁹ D(ρ_i),   ∂B_i/∂r = −10⁹ G_dip(M, ρ_i)
//! ```
//!
//! (`D`, `G_dip` from `aeromag_core::field::dipole`). The background field
//! `B_bg` and its gradient `G_bg` (Earth's field from IGRF, rotated into the
//! body frame with the attitude for a mobile system) are known; the uniform
//! part cancels in the tensor contrasts but sets the direction of the
//! modulus for scalar sensors:
//!
//! ```text
//! F_i = |B_i|,   ∂F_i/∂M = u_iᵀ 10⁹ D(ρ_i),   u_i = B_i/|B_i|
//! ```
//!
//! The measurements are the white contrasts of [`crate::decorrelate`]:
//! 9 for the tensor system (state `(r, M)`, 6 components; stationary system
//! with a moving object and mobile system with a fixed object alike — the
//! motion enters through [`crate::motion`]), 3 for the scalar system (state
//! `M`, position known).

use crate::decorrelate::contrast_matrix;
use crate::geometry::Geometry;
use aeromag_core::NT_PER_T;
use aeromag_core::field::dipole::{dipole_field, dipole_gradient, dipole_matrix};
use aeromag_core::field::igrf::IgrfModel;
use aeromag_core::frames::Attitude;
use aeromag_core::frames::geodetic::Geodetic;
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

/// A measurement model `z = h(x)` with Jacobian `H = ∂h/∂x`, state
/// dimension `N`, measurement dimension `Z` (white contrasts, unit noise
/// after division by the sensor σ).
pub trait Forward<const N: usize, const Z: usize> {
    /// `(h(x), ∂h/∂x)`.
    fn eval(&self, x: &SVector<f64, N>) -> (SVector<f64, Z>, SMatrix<f64, Z, N>);
}

/// Known background field (nT) and gradient (nT/m) at the measuring
/// centre, body frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Background {
    /// Uniform part, nT.
    pub field_nt: Vector3<f64>,
    /// Gradient `∂B_i/∂x_j`, nT/m.
    pub gradient_nt_per_m: Matrix3<f64>,
}

impl Background {
    /// No background (pure dipole).
    pub fn zero() -> Self {
        Self {
            field_nt: Vector3::zeros(),
            gradient_nt_per_m: Matrix3::zeros(),
        }
    }

    /// From NED field and gradient and the system's attitude:
    /// `B_b = C_bn B_n`, `G_b = C_bn G_n C_nb`.
    pub fn from_ned(
        field_ned_nt: &Vector3<f64>,
        gradient_ned: &Matrix3<f64>,
        att: &Attitude,
    ) -> Self {
        let c_bn = att.c_bn();
        Self {
            field_nt: c_bn * field_ned_nt,
            gradient_nt_per_m: c_bn * gradient_ned * c_bn.transpose(),
        }
    }

    /// The IGRF field and gradient at `pos`, rotated into the body frame of
    /// attitude `att` ([`Background::from_ned`]).
    pub fn from_igrf(igrf: &IgrfModel, pos: &Geodetic, att: &Attitude) -> Self {
        Self::from_ned(
            &igrf.field_geodetic(pos).ned_nt(),
            &igrf.gradient_ned_nt_per_m(pos),
            att,
        )
    }

    /// Background at sensor offset `d` (m), nT.
    pub fn at(&self, d: &Vector3<f64>) -> Vector3<f64> {
        self.field_nt + self.gradient_nt_per_m * d
    }
}

/// Tensor gradiometer (four vector sensors): state `(r, M)`, 9 contrasts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TensorForward {
    /// Sensor layout.
    pub geometry: Geometry,
    /// Known background.
    pub background: Background,
}

impl TensorForward {
    /// Sensor readings (nT) for dipole position `r` (m) and moment `m` (A·m²).
    pub fn readings(&self, r: &Vector3<f64>, m: &Vector3<f64>) -> [Vector3<f64>; 4] {
        self.geometry
            .offsets_m()
            .map(|d| self.background.at(&d) + dipole_field(m, &(d - r)) * NT_PER_T)
    }
}

impl TensorForward {
    /// Least-squares moment (A·m²) for an assumed position `r` (m) from one
    /// epoch's contrasts `z` (nT): the model is linear in `M`,
    /// `z − h(r, 0) = H_M(r) M`, so `M = (H_Mᵀ H_M)⁻¹ H_Mᵀ (z − h(r, 0))`.
    /// A closed-form start for the moment; `None` when `H_M` is singular.
    pub fn moment_least_squares(
        &self,
        r: &Vector3<f64>,
        z: &SVector<f64, 9>,
    ) -> Option<Vector3<f64>> {
        let mut x = SVector::<f64, 6>::zeros();
        x.fixed_rows_mut::<3>(0).copy_from(r);
        let (h0, h) = self.eval(&x);
        let hm = h.fixed_columns::<3>(3).into_owned();
        let n = hm.transpose() * hm;
        n.cholesky().map(|c| c.solve(&(hm.transpose() * (z - h0))))
    }
}

impl Forward<6, 9> for TensorForward {
    fn eval(&self, x: &SVector<f64, 6>) -> (SVector<f64, 9>, SMatrix<f64, 9, 6>) {
        let r = x.fixed_rows::<3>(0).into_owned();
        let m = x.fixed_rows::<3>(3).into_owned();
        let t = contrast_matrix();
        let mut z = SVector::<f64, 9>::zeros();
        let mut h = SMatrix::<f64, 9, 6>::zeros();
        for (i, d) in self.geometry.offsets_m().iter().enumerate() {
            let rho = d - r;
            // B = D(ρ) M: one call gives the field and ∂B/∂M.
            let db_dm = dipole_matrix(&rho) * NT_PER_T;
            let b = self.background.at(d) + db_dm * m;
            let db_dr = -dipole_gradient(&m, &rho) * NT_PER_T;
            for j in 0..3 {
                let w = t[(j, i)];
                z.fixed_rows_mut::<3>(3 * j).axpy(w, &b, 1.0);
                let mut blk = h.fixed_view_mut::<3, 3>(3 * j, 0);
                blk += db_dr * w;
                let mut blk = h.fixed_view_mut::<3, 3>(3 * j, 3);
                blk += db_dm * w;
            }
        }
        (z, h)
    }
}

/// Scalar gradiometer (four scalar sensors): state `M`, known dipole
/// position, 3 contrasts of the moduli.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScalarForward {
    /// Sensor layout.
    pub geometry: Geometry,
    /// Known background (its uniform part matters here).
    pub background: Background,
    /// Known dipole position relative to the measuring centre, m.
    pub position_m: Vector3<f64>,
}

impl ScalarForward {
    /// Modulus readings (nT) for moment `m` (A·m²).
    pub fn readings(&self, m: &Vector3<f64>) -> [f64; 4] {
        self.geometry.offsets_m().map(|d| {
            (self.background.at(&d) + dipole_field(m, &(d - self.position_m)) * NT_PER_T).norm()
        })
    }
}

impl Forward<3, 3> for ScalarForward {
    fn eval(&self, x: &SVector<f64, 3>) -> (SVector<f64, 3>, SMatrix<f64, 3, 3>) {
        let t = contrast_matrix();
        let mut z = Vector3::zeros();
        let mut h = Matrix3::zeros();
        for (i, d) in self.geometry.offsets_m().iter().enumerate() {
            let rho = d - self.position_m;
            let dm = dipole_matrix(&rho) * NT_PER_T;
            let b = self.background.at(d) + dm * x;
            let f = b.norm();
            let u = if f > 0.0 { b / f } else { Vector3::zeros() };
            let row = u.transpose() * dm;
            for j in 0..3 {
                z[j] += t[(j, i)] * f;
                let mut hr = h.row_mut(j);
                hr += row * t[(j, i)];
            }
        }
        (z, h)
    }
}

/// The scalar system's filter state `(M, M_i, b)`: the total and the
/// induced moment (A·m², [`crate::motion::motion_mv_induced`]) and a
/// constant offset `b` of the three contrasts (nT, what the bias removal of
/// [`crate::sim::scalar_epochs`] leaves): `h(M, M_i, b) = h(M) + b`,
/// `∂h/∂(M, M_i, b) = [H, 0, I]` with `H = ∂h/∂M` of the 3-state model.
impl Forward<9, 3> for ScalarForward {
    fn eval(&self, x: &SVector<f64, 9>) -> (SVector<f64, 3>, SMatrix<f64, 3, 9>) {
        let (z, h) = self.eval(&x.fixed_rows::<3>(0).into_owned());
        let mut h9 = SMatrix::<f64, 3, 9>::zeros();
        h9.fixed_columns_mut::<3>(0).copy_from(&h);
        h9.fixed_columns_mut::<3>(6).fill_with_identity();
        (z + x.fixed_rows::<3>(6), h9)
    }
}

/// Central finite-difference Jacobian of a [`Forward`] with per-component
/// steps `step` (the seed's `JacobianH`, eq. 11/26); used to check the
/// analytic Jacobians.
pub fn jacobian_fd<const N: usize, const Z: usize, F: Forward<N, Z>>(
    f: &F,
    x: &SVector<f64, N>,
    step: &SVector<f64, N>,
) -> SMatrix<f64, Z, N> {
    let mut j = SMatrix::<f64, Z, N>::zeros();
    for k in 0..N {
        let mut xp = *x;
        let mut xm = *x;
        xp[k] += step[k];
        xm[k] -= step[k];
        let d = (f.eval(&xp).0 - f.eval(&xm).0) / (2.0 * step[k]);
        j.set_column(k, &d);
    }
    j
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Layout;

    fn earth() -> Background {
        let g = Matrix3::new(
            0.01, 0.002, -0.003, 0.002, -0.004, 0.001, -0.003, 0.001, -0.006,
        );
        Background {
            field_nt: Vector3::new(15000.0, 2000.0, 48000.0),
            gradient_nt_per_m: g,
        }
    }

    #[test]
    fn tensor_jacobian_matches_finite_differences() {
        for layout in [Layout::Tetrahedron, Layout::Cross, Layout::Planar] {
            let f = TensorForward {
                geometry: Geometry::new(layout, 1.0).unwrap(),
                background: earth(),
            };
            let x = SVector::<f64, 6>::from([3.0, -1.5, 2.2, 40.0, -70.0, 55.0]);
            let (_, h) = f.eval(&x);
            let step = SVector::<f64, 6>::from([1e-4, 1e-4, 1e-4, 1e-3, 1e-3, 1e-3]);
            let hfd = jacobian_fd(&f, &x, &step);
            let rel = (h - hfd).norm() / h.norm();
            assert!(rel < 1e-7, "{layout:?}: rel {rel:e}");
        }
    }

    #[test]
    fn scalar_jacobian_matches_finite_differences() {
        let f = ScalarForward {
            geometry: Geometry::new(Layout::Tetrahedron, 1.5).unwrap(),
            background: earth(),
            position_m: Vector3::new(4.0, 1.0, -2.0),
        };
        let x = Vector3::new(300.0, -120.0, 80.0);
        let (_, h) = f.eval(&x);
        let hfd = jacobian_fd(&f, &x, &Vector3::repeat(1e-2));
        let rel = (h - hfd).norm() / h.norm();
        assert!(rel < 1e-7, "rel {rel:e}");
        // total and induced moment and an offset: the total's model plus the offset
        let x9 = SVector::<f64, 9>::from([100.0, -20.0, 30.0, 200.0, -100.0, 50.0, 0.1, -0.2, 0.3]);
        let (z9, h9): (SVector<f64, 3>, _) = f.eval(&x9);
        let m = Vector3::new(100.0, -20.0, 30.0);
        assert!((z9 - f.eval(&m).0 - Vector3::new(0.1, -0.2, 0.3)).norm() < 1e-9);
        let hfd9 = jacobian_fd(&f, &x9, &SVector::repeat(1e-2));
        assert!((h9 - hfd9).norm() / h9.norm() < 1e-7);
    }

    #[test]
    fn moment_least_squares_recovers_the_moment_at_the_true_position() {
        let f = TensorForward {
            geometry: Geometry::new(Layout::Tetrahedron, 1.0).unwrap(),
            background: earth(),
        };
        let x = SVector::<f64, 6>::from([3.0, -1.5, 2.2, 40.0, -70.0, 55.0]);
        let (z, _) = f.eval(&x);
        let m = f
            .moment_least_squares(&Vector3::new(3.0, -1.5, 2.2), &z)
            .unwrap();
        assert!((m - Vector3::new(40.0, -70.0, 55.0)).norm() < 1e-8);
    }

    #[test]
    fn contrasts_match_readings_and_cancel_the_uniform_field() {
        let geometry = Geometry::new(Layout::Cross, 1.0).unwrap();
        let with = TensorForward {
            geometry,
            background: earth(),
        };
        let mut uniform = earth();
        uniform.field_nt = Vector3::zeros();
        let without = TensorForward {
            geometry,
            background: uniform,
        };
        let x = SVector::<f64, 6>::from([3.0, -1.5, 2.2, 40.0, -70.0, 55.0]);
        let (z1, _) = with.eval(&x);
        let (z2, _) = without.eval(&x);
        assert!((z1 - z2).norm() < 1e-9);
        let b = with.readings(
            &Vector3::new(3.0, -1.5, 2.2),
            &Vector3::new(40.0, -70.0, 55.0),
        );
        assert!((crate::decorrelate::contrasts_vector(&b) - z1).norm() < 1e-9);
    }
}
