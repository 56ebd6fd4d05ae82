//! [`IgrfModel`]: IGRF-14 Gauss coefficients interpolated at one epoch, the
//! fast path for evaluating the main field at many points (simulator).
//!
//! ## Geocentric → geodetic rotation
//!
//! The geodetic position is converted to geocentric `(r, θ, φ)` with
//! [`Geodetic::to_geocentric`]. With `ψ = φ_geodetic − (π/2 − θ)` (geodetic
//! minus geocentric latitude, ≤ 0.19° on WGS84) the components in the local
//! ellipsoidal north-east-down frame are
//!
//! ```text
//! X (north) = −B_θ cos ψ − B_r sin ψ
//! Y (east)  =  B_φ
//! Z (down)  =  B_θ sin ψ − B_r cos ψ
//! ```
//!
//! ## Gradient
//!
//! [`IgrfModel::gradient_ned_nt_per_m`] returns the Cartesian gradient tensor
//! `G_ij = ∂B_i/∂x_j` in the NED frame at the point (both `B` components and
//! displacements along the fixed N, E, D axes of that point), by central
//! differences of the Earth-fixed Cartesian field with step
//! [`GRADIENT_STEP_M`] = 20 m along each axis (6 extra field evaluations).
//! Truncation error `h²/6 · ∂³B ≈ 3·10⁻¹¹` of the gradient (dipole term,
//! `∂³B ~ 60|B|/r³`), rounding error `~ε|B|/h ≈ 10⁻¹² nT/m`. Measured: the
//! degree-1 gradient matches the analytic dipole tensor to ≤ 3·10⁻¹² nT/m
//! (relative ≤ 1.5·10⁻¹⁰); the full field's tensor is symmetric and traceless
//! (Laplace) to ~10⁻¹² nT/m for gradients of ~10⁻² nT/m, and changes by
//! ≤ 5·10⁻¹² nT/m when the step is halved or doubled.

use super::coefficients::{GaussCoefficients, MAX_DEGREE, igrf14, index};
use super::synthesis::{Recursion, recursion, synthesize};
use super::{IgrfField, IgrfGeocentric};
use crate::error::{CoreError, Result};
use crate::frames::Geodetic;
use nalgebra::{Matrix3, Vector3};
use std::f64::consts::FRAC_PI_2;

/// Central-difference step of [`IgrfModel::gradient_ned_nt_per_m`], m.
pub const GRADIENT_STEP_M: f64 = 20.0;

/// IGRF-14 at one epoch: Schmidt semi-normalised Gauss coefficients (nT)
/// interpolated to a decimal year, truncated at a maximum degree.
///
/// Build once per epoch (cost < 1 µs), then evaluate at many points with
/// [`field_geodetic`](Self::field_geodetic) /
/// [`field_geocentric`](Self::field_geocentric): no allocation, O(N²) with
/// N = 13 (~0.5 µs per point in release builds). These fast-path methods do not validate positions: non-finite input
/// gives non-finite output (never a panic). Use [`super::igrf_geodetic`] for a
/// checked single evaluation.
#[derive(Debug, Clone)]
pub struct IgrfModel {
    decimal_year: f64,
    max_degree: usize,
    coeffs: GaussCoefficients,
    rec: &'static Recursion,
}

impl IgrfModel {
    /// The full (degree 13) IGRF-14 at `decimal_year` (e.g. from
    /// [`crate::time::Date::decimal_year`]). `DateOutOfRange` outside
    /// 1900.0–2030.0; dates after 2025.0 use the predictive secular variation.
    pub fn new(decimal_year: f64) -> Result<Self> {
        Self::with_max_degree(decimal_year, MAX_DEGREE)
    }

    /// As [`new`](Self::new) but summing only degrees `1..=max_degree`
    /// (`1 ≤ max_degree ≤ 13`; degree 1 is the geocentric dipole).
    pub fn with_max_degree(decimal_year: f64, max_degree: usize) -> Result<Self> {
        let model = igrf14()?;
        if !(1..=model.max_degree).contains(&max_degree) {
            return Err(CoreError::InvalidArgument {
                name: "max_degree",
                reason: format!("{max_degree} is not in 1–{}", model.max_degree),
            });
        }
        let mut coeffs = model.at(decimal_year)?;
        for n in max_degree + 1..=MAX_DEGREE {
            for m in 0..=n {
                coeffs.g[index(n, m)] = 0.0;
                coeffs.h[index(n, m)] = 0.0;
            }
        }
        Ok(Self {
            decimal_year,
            max_degree,
            coeffs,
            rec: recursion(),
        })
    }

    /// The epoch, decimal year.
    pub fn decimal_year(&self) -> f64 {
        self.decimal_year
    }

    /// The maximum degree summed.
    pub fn max_degree(&self) -> usize {
        self.max_degree
    }

    /// Gauss coefficients `(g_n^m, h_n^m)` in nT at this epoch (zero above
    /// the truncation degree), `None` unless `1 ≤ n ≤ 13` and `m ≤ n`.
    pub fn gauss_nt(&self, n: usize, m: usize) -> Option<(f64, f64)> {
        ((1..=MAX_DEGREE).contains(&n) && m <= n)
            .then(|| (self.coeffs.g[index(n, m)], self.coeffs.h[index(n, m)]))
    }

    /// Field in geocentric spherical components at radius `r_m` (m),
    /// colatitude `colat_rad` and longitude `lon_rad` (module docs of
    /// `synthesis` for the equations). Finite at the poles.
    pub fn field_geocentric(&self, r_m: f64, colat_rad: f64, lon_rad: f64) -> IgrfGeocentric {
        let [br, bt, bp] = synthesize(
            &self.coeffs,
            self.max_degree,
            self.rec,
            r_m,
            colat_rad,
            lon_rad,
        );
        IgrfGeocentric {
            br_nt: br,
            btheta_nt: bt,
            bphi_nt: bp,
        }
    }

    /// Field (nT) in the geodetic north-east-down frame at a WGS84 position,
    /// rotated from geocentric components by `ψ` (module docs).
    pub fn field_geodetic(&self, pos: &Geodetic) -> IgrfField {
        let gc = pos.to_geocentric();
        let b = self.field_geocentric(gc.r_m, gc.colat_rad, gc.lon_rad);
        // ψ as in Geodetic::geodetic_minus_geocentric_lat, reusing `gc`.
        let psi = pos.lat_deg.to_radians() - (FRAC_PI_2 - gc.colat_rad);
        let (sp, cp) = psi.sin_cos();
        IgrfField {
            x_nt: -b.btheta_nt * cp - b.br_nt * sp,
            y_nt: b.bphi_nt,
            z_nt: b.btheta_nt * sp - b.br_nt * cp,
        }
    }

    /// Field (nT) in Earth-centred Earth-fixed Cartesian components at ECEF
    /// position `p_m` (m): `B = B_r e_r + B_θ e_θ + B_φ e_φ`.
    pub fn field_ecef_nt(&self, p_m: &Vector3<f64>) -> Vector3<f64> {
        let rho = p_m.x.hypot(p_m.y);
        let r = rho.hypot(p_m.z);
        let colat = rho.atan2(p_m.z);
        let lon = p_m.y.atan2(p_m.x);
        let b = self.field_geocentric(r, colat, lon);
        let (st, ct) = colat.sin_cos();
        let (sl, cl) = lon.sin_cos();
        let bh = b.br_nt * st + b.btheta_nt * ct; // horizontal-plane (equatorial) part
        Vector3::new(
            bh * cl - b.bphi_nt * sl,
            bh * sl + b.bphi_nt * cl,
            b.br_nt * ct - b.btheta_nt * st,
        )
    }

    /// Gradient tensor `G_ij = ∂B_i/∂x_j` (nT/m) in the NED frame at `pos`
    /// (i, j ∈ north, east, down), by central differences with step
    /// [`GRADIENT_STEP_M`]; absolute accuracy ~1e-12 nT/m, relative ~1e-10
    /// (module docs). Symmetric and traceless to that accuracy.
    pub fn gradient_ned_nt_per_m(&self, pos: &Geodetic) -> Matrix3<f64> {
        self.gradient_with_step(pos, GRADIENT_STEP_M)
    }

    /// Central-difference NED gradient with step `h` (m).
    fn gradient_with_step(&self, pos: &Geodetic, h: f64) -> Matrix3<f64> {
        let c_en = ned_to_ecef(pos);
        let p = Vector3::from(pos.to_ecef());
        let mut d_ecef = Matrix3::zeros(); // column j: ∂B_ecef/∂x_j
        for j in 0..3 {
            let u = c_en.column(j).into_owned();
            let diff = self.field_ecef_nt(&(p + u * h)) - self.field_ecef_nt(&(p - u * h));
            d_ecef.set_column(j, &(diff / (2.0 * h)));
        }
        c_en.transpose() * d_ecef
    }
}

/// Rotation taking NED components at a geodetic position to ECEF components
/// (columns: north, east, down unit vectors in ECEF).
fn ned_to_ecef(pos: &Geodetic) -> Matrix3<f64> {
    let (sl, cl) = pos.lat_deg.to_radians().sin_cos();
    let (so, co) = pos.lon_deg.to_radians().sin_cos();
    Matrix3::new(
        -sl * co,
        -so,
        -cl * co, //
        -sl * so,
        co,
        -cl * so, //
        cl,
        0.0,
        -sl,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::dipole::{dipole_field, dipole_gradient};
    use crate::{NT_PER_T, T_PER_NT};

    #[test]
    fn degree_argument_is_checked() {
        for n in [0, 14, 100] {
            assert!(matches!(
                IgrfModel::with_max_degree(2020.0, n),
                Err(CoreError::InvalidArgument {
                    name: "max_degree",
                    ..
                })
            ));
        }
        let m = IgrfModel::with_max_degree(2020.0, 3).unwrap();
        assert_eq!(m.max_degree(), 3);
        assert_eq!(m.decimal_year(), 2020.0);
        assert_eq!(m.gauss_nt(4, 0), Some((0.0, 0.0)));
        assert_eq!(m.gauss_nt(0, 0), None);
        assert_eq!(m.gauss_nt(3, 4), None);
        assert_eq!(m.gauss_nt(1, 0), Some((-29403.41, 0.0)));
        assert!(matches!(
            IgrfModel::new(2031.0),
            Err(CoreError::DateOutOfRange { .. })
        ));
    }

    /// Degree 1 alone is a geocentric dipole: μ0/(4π) m = a³ (g11, h11, g10).
    /// Compare field and gradient with the independent dipole formulas.
    #[test]
    fn degree_one_is_the_geocentric_dipole() {
        let model = IgrfModel::with_max_degree(2023.5, 1).unwrap();
        let (g10, _) = model.gauss_nt(1, 0).unwrap();
        let (g11, h11) = model.gauss_nt(1, 1).unwrap();
        let a3 = super::super::IGRF_REFERENCE_RADIUS_M.powi(3);
        let m_am2 = Vector3::new(g11, h11, g10) * (a3 * T_PER_NT / crate::MU0_OVER_4PI);
        for pos in [
            Geodetic::new(47.3, 8.5, 500.0),
            Geodetic::new(-63.0, -170.0, 9000.0),
            Geodetic::new(0.0, 90.0, 0.0),
            Geodetic::new(89.0, -30.0, 3000.0),
        ] {
            let p = Vector3::from(pos.to_ecef());
            let c_en = ned_to_ecef(&pos);
            let b_ref = c_en.transpose() * dipole_field(&m_am2, &p) * NT_PER_T;
            let b = model.field_geodetic(&pos).ned_nt();
            assert!((b - b_ref).amax() < 1e-8, "{b} vs {b_ref}");
            let b_ecef = model.field_ecef_nt(&p);
            assert!((c_en * b - b_ecef).amax() < 1e-8);
            let g_ref = c_en.transpose() * dipole_gradient(&m_am2, &p) * c_en * NT_PER_T;
            let g = model.gradient_ned_nt_per_m(&pos);
            let err = (g - g_ref).amax();
            assert!(err < 1e-9 * g_ref.amax(), "{err:e}");
        }
    }

    /// The full-degree gradient: symmetric, traceless (∇·B = 0, ∇×B = 0) and
    /// stable against halving the step (Richardson check of the truncation).
    #[test]
    fn full_gradient_is_symmetric_traceless_and_converged() {
        let model = IgrfModel::new(2026.2).unwrap();
        for pos in [
            Geodetic::new(55.0, 37.0, 300.0),
            Geodetic::new(-34.0, 18.0, 5000.0),
            Geodetic::new(89.9, 0.0, 0.0),
            Geodetic::new(3.0, -60.0, 1000.0),
        ] {
            let g = model.gradient_ned_nt_per_m(&pos);
            assert!(g.amax() > 1e-3 && g.amax() < 0.1, "{g}");
            assert!((g - g.transpose()).amax() < 1e-11, "asymmetry {g}");
            assert!(g.trace().abs() < 1e-11, "trace {}", g.trace());
            let g_half = model.gradient_with_step(&pos, 0.5 * GRADIENT_STEP_M);
            let g_double = model.gradient_with_step(&pos, 2.0 * GRADIENT_STEP_M);
            assert!((g - g_half).amax() < 1e-9 * g.amax());
            assert!((g - g_double).amax() < 1e-9 * g.amax());
            // Vertical gradient of a ~50 000 nT field is ~ −3|B|/r ~ 0.02 nT/m.
            let b = model.field_geodetic(&pos);
            assert!(g[(2, 2)].abs() > 0.5 * b.f_nt() / 6.4e6);
        }
    }

    proptest::proptest! {
        /// Anywhere and anytime: the NED field is the ECEF field rotated
        /// (same vector), the field is 360°-periodic in longitude, and the
        /// gradient is symmetric (curl-free) and traceless (divergence-free).
        #[test]
        fn invariants(
            lat in -90.0..=90.0_f64,
            lon in -180.0..180.0_f64,
            alt in 0.0..20_000.0_f64,
            year in 1900.0..=2030.0_f64,
        ) {
            let model = IgrfModel::new(year).unwrap();
            let pos = Geodetic::new(lat, lon, alt);
            let b = model.field_geodetic(&pos);
            let b_ecef = model.field_ecef_nt(&Vector3::from(pos.to_ecef()));
            proptest::prop_assert!((ned_to_ecef(&pos) * b.ned_nt() - b_ecef).amax() < 1e-8);
            let b360 = model.field_geodetic(&Geodetic::new(lat, lon + 360.0, alt));
            proptest::prop_assert!((b.ned_nt() - b360.ned_nt()).amax() < 1e-8);
            let g = model.gradient_ned_nt_per_m(&pos);
            proptest::prop_assert!((g - g.transpose()).amax() < 1e-11, "{}", g);
            proptest::prop_assert!(g.trace().abs() < 1e-11, "{}", g.trace());
        }
    }

    #[test]
    fn geodetic_equals_projected_ecef() {
        let model = IgrfModel::new(1987.3).unwrap();
        for pos in [
            Geodetic::new(12.0, 34.0, 56.0),
            Geodetic::new(-71.0, -123.0, 7000.0),
        ] {
            let b = model.field_geodetic(&pos).ned_nt();
            let b_ecef = model.field_ecef_nt(&Vector3::from(pos.to_ecef()));
            assert!((ned_to_ecef(&pos) * b - b_ecef).amax() < 1e-8);
        }
    }
}
