//! The International Geomagnetic Reference Field, 14th generation (IGRF-14),
//! in f64.
//!
//! IGRF-14 is the IAGA Working Group V-MOD main-field model released in
//! November 2024 (coefficients: <https://doi.org/10.5281/zenodo.14012302>;
//! the method and format are those of IGRF-13, Alken et al. 2021, *Earth,
//! Planets and Space* 73:49). It gives the field of internal (core) origin
//! as a spherical-harmonic expansion of a scalar potential to degree 13,
//! with Gauss coefficients every five years 1900.0–2025.0 and a predictive
//! secular variation to 2030.0. Spec: `spec/simulator.md` § Fields ("Main
//! field: IGRF-14 at each position and time") and `spec/README.md` (in-house
//! IGRF with `ppigrf` as the test oracle).
//!
//! ```text
//! V(r,θ,φ,t) = a Σ_{n=1..13} (a/r)^{n+1} Σ_{m=0..n} [g_n^m(t) cos mφ + h_n^m(t) sin mφ] P_n^m(cos θ)
//! B = −∇V        (a = 6371.2 km, P_n^m Schmidt semi-normalised, g, h in nT)
//! ```
//!
//! * `coefficients` — the embedded IAGA `.shc` file, parsed once, and
//!   the interpolation in time (linear in elapsed days between epochs, the
//!   `ppigrf` convention; 2025–2030 is the secular-variation extrapolation).
//! * `synthesis` — recursive Legendre functions and the geocentric
//!   components `B_r, B_θ, B_φ`, finite at the poles.
//! * [`IgrfModel`] — coefficients at one epoch; geocentric, geodetic (NED) and
//!   ECEF field, and the NED gradient tensor.
//!
//! Outputs are in nT (the unit of the coefficients and of survey data files);
//! multiply by [`crate::T_PER_NT`] for tesla. Validated against `ppigrf` 2.1.0
//! (`tools/reference/igrf_reference.py`, `tests/igrf_reference.rs`).

mod coefficients;
mod model;
mod synthesis;

pub use coefficients::MAX_DEGREE;
pub use model::{GRADIENT_STEP_M, IgrfModel};
pub use synthesis::IGRF_REFERENCE_RADIUS_M;

use crate::error::{CoreError, Result};
use crate::frames::Geodetic;
use nalgebra::Vector3;

/// First year of IGRF-14 validity (decimal year).
pub const IGRF_FIRST_YEAR: f64 = 1900.0;
/// Last year of IGRF-14 validity (decimal year; 2025–2030 is predictive).
pub const IGRF_LAST_YEAR: f64 = 2030.0;
/// Smallest geocentric radius accepted by [`igrf_geodetic`], m: the
/// core–mantle boundary (3480 km), below which the potential of the core
/// field is not source-free.
pub const CORE_RADIUS_M: f64 = 3_480_000.0;

/// Main-field vector in the local geodetic (ellipsoidal) frame, nT:
/// `X` north, `Y` east, `Z` down (the geomagnetic X, Y, Z elements).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct IgrfField {
    /// North component X, nT.
    pub x_nt: f64,
    /// East component Y, nT.
    pub y_nt: f64,
    /// Down component Z, nT.
    pub z_nt: f64,
}

impl IgrfField {
    /// Total intensity `F = √(X² + Y² + Z²)`, nT.
    pub fn f_nt(&self) -> f64 {
        self.h_nt().hypot(self.z_nt)
    }

    /// Horizontal intensity `H = √(X² + Y²)`, nT.
    pub fn h_nt(&self) -> f64 {
        self.x_nt.hypot(self.y_nt)
    }

    /// Declination `D = atan2(Y, X)`, degrees east of geodetic north
    /// (0 where `H = 0`).
    pub fn declination_deg(&self) -> f64 {
        self.y_nt.atan2(self.x_nt).to_degrees()
    }

    /// Inclination `I = atan2(Z, H)`, degrees, positive downward (±90 where
    /// `H = 0`).
    pub fn inclination_deg(&self) -> f64 {
        self.z_nt.atan2(self.h_nt()).to_degrees()
    }

    /// The vector `(X, Y, Z)` in NED, nT.
    pub fn ned_nt(&self) -> Vector3<f64> {
        Vector3::new(self.x_nt, self.y_nt, self.z_nt)
    }
}

/// Main-field vector in geocentric spherical components, nT.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IgrfGeocentric {
    /// Radial component `B_r` (outward), nT.
    pub br_nt: f64,
    /// Colatitude component `B_θ` (southward), nT.
    pub btheta_nt: f64,
    /// Longitude component `B_φ` (eastward), nT.
    pub bphi_nt: f64,
}

/// IGRF-14 field (nT, geodetic NED) at a WGS84 position and decimal year
/// (see [`crate::time::Date::decimal_year`]), full degree 13.
///
/// Errors: `DateOutOfRange` outside 1900.0–2030.0; `InvalidArgument` for a
/// non-finite coordinate, `|lat| > 90°`, or a point below [`CORE_RADIUS_M`].
/// For many points at one epoch build an [`IgrfModel`] once instead.
pub fn igrf_geodetic(pos: &Geodetic, decimal_year: f64) -> Result<IgrfField> {
    check_position(pos)?;
    Ok(IgrfModel::new(decimal_year)?.field_geodetic(pos))
}

fn check_position(pos: &Geodetic) -> Result<()> {
    let bad = |name, reason: String| Err(CoreError::InvalidArgument { name, reason });
    if !(-90.0..=90.0).contains(&pos.lat_deg) {
        return bad("lat_deg", format!("{} is not in −90…90", pos.lat_deg));
    }
    if !pos.lon_deg.is_finite() {
        return bad("lon_deg", format!("{} is not finite", pos.lon_deg));
    }
    if !pos.alt_m.is_finite() || pos.to_geocentric().r_m < CORE_RADIUS_M {
        return bad(
            "alt_m",
            format!("{} m is not finite or is below the core", pos.alt_m),
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::time::Date;

    #[test]
    fn field_elements() {
        let b = IgrfField {
            x_nt: 3.0,
            y_nt: 4.0,
            z_nt: 12.0,
        };
        assert_eq!(b.h_nt(), 5.0);
        assert_eq!(b.f_nt(), 13.0);
        assert!((b.declination_deg() - 4.0_f64.atan2(3.0).to_degrees()).abs() < 1e-12);
        assert!((b.inclination_deg() - 12.0_f64.atan2(5.0).to_degrees()).abs() < 1e-12);
        let v = IgrfField {
            x_nt: 0.0,
            y_nt: 0.0,
            z_nt: -1.0,
        };
        assert_eq!((v.declination_deg(), v.inclination_deg()), (0.0, -90.0));
    }

    #[test]
    fn plausible_values() {
        // Mid-latitude northern hemisphere: strong downward Z, F 45–60 µT.
        let y = Date::parse("2025-06-01").unwrap().decimal_year();
        let b = igrf_geodetic(&Geodetic::new(55.75, 37.62, 0.0), y).unwrap();
        assert!(b.f_nt() > 45_000.0 && b.f_nt() < 60_000.0, "{b:?}");
        assert!(b.inclination_deg() > 60.0 && b.inclination_deg() < 80.0);
        // South Atlantic Anomaly: F < 24 000 nT near (−26°, −50°) in 2025.
        let saa = igrf_geodetic(&Geodetic::new(-26.0, -50.0, 0.0), y).unwrap();
        assert!(saa.f_nt() < 24_000.0 && saa.z_nt < 0.0, "{saa:?}");
    }

    #[test]
    fn validity_constants_match_the_file() {
        let m = coefficients::igrf14().unwrap();
        assert_eq!(
            (m.first_year(), m.last_year()),
            (IGRF_FIRST_YEAR, IGRF_LAST_YEAR)
        );
        assert_eq!(m.max_degree, MAX_DEGREE);
    }

    #[test]
    fn dates_out_of_range_are_errors() {
        let p = Geodetic::new(10.0, 20.0, 0.0);
        for y in [1899.99, 2030.01, 2100.0, f64::NAN] {
            assert!(matches!(
                igrf_geodetic(&p, y),
                Err(CoreError::DateOutOfRange { .. })
            ));
        }
        assert!(igrf_geodetic(&p, IGRF_FIRST_YEAR).is_ok());
        assert!(igrf_geodetic(&p, IGRF_LAST_YEAR).is_ok());
    }

    #[test]
    fn bad_positions_are_errors() {
        for p in [
            Geodetic::new(90.5, 0.0, 0.0),
            Geodetic::new(f64::NAN, 0.0, 0.0),
            Geodetic::new(0.0, f64::INFINITY, 0.0),
            Geodetic::new(0.0, 0.0, f64::NAN),
            Geodetic::new(0.0, 0.0, -4.0e6),
        ] {
            assert!(
                matches!(
                    igrf_geodetic(&p, 2020.0),
                    Err(CoreError::InvalidArgument { .. })
                ),
                "{p:?}"
            );
        }
    }

    /// At and next to the poles the field is finite and continuous, and the
    /// horizontal vector expressed in ECEF does not depend on the longitude
    /// used to define the (degenerate) NED frame at the pole.
    #[test]
    fn poles_are_finite_and_continuous() {
        let model = IgrfModel::new(2024.0).unwrap();
        for lat in [90.0, -90.0] {
            let mut ecef = Vec::new();
            for lon in [0.0, 45.0, -120.0, 180.0] {
                let pole = Geodetic::new(lat, lon, 1000.0);
                let b = model.field_geodetic(&pole);
                assert!(b.x_nt.is_finite() && b.y_nt.is_finite() && b.z_nt.is_finite());
                // 1 mm (≈ 1e-8°) away along the same meridian.
                let near = Geodetic::new(lat - lat.signum() * 1e-8, lon, 1000.0);
                let bn = model.field_geodetic(&near);
                assert!((b.ned_nt() - bn.ned_nt()).amax() < 1e-4, "{b:?} vs {bn:?}");
                ecef.push(model.field_ecef_nt(&Vector3::from(pole.to_ecef())));
                // Exactly on the axis in geocentric coordinates, too.
                let colat = if lat > 0.0 { 0.0 } else { std::f64::consts::PI };
                let g = model.field_geocentric(6.4e6, colat, lon.to_radians());
                assert!(g.br_nt.is_finite() && g.btheta_nt.is_finite() && g.bphi_nt.is_finite());
            }
            for v in &ecef[1..] {
                assert!((v - ecef[0]).amax() < 1e-6, "{v} vs {}", ecef[0]);
            }
            // Gradient stays finite at the pole.
            let g = model.gradient_ned_nt_per_m(&Geodetic::new(lat, 0.0, 0.0));
            assert!(g.iter().all(|v| v.is_finite()));
        }
    }

    /// Truncation removes exactly the higher-degree terms: the difference
    /// between degree N and N−1 equals the degree-N-only synthesis, and the
    /// high degrees contribute little (the spectrum falls with degree).
    #[test]
    fn degree_truncation() {
        let y = 2012.7;
        let pos = Geodetic::new(-12.0, 77.0, 2000.0);
        let full = IgrfModel::new(y).unwrap().field_geodetic(&pos).ned_nt();
        let b = |n| {
            IgrfModel::with_max_degree(y, n)
                .unwrap()
                .field_geodetic(&pos)
                .ned_nt()
        };
        assert_eq!(b(13), full);
        let dipole = b(1);
        assert!((full - dipole).norm() > 1000.0 && (full - dipole).norm() < 0.5 * full.norm());
        // Degrees 11–13 contribute of order 10 nT at the surface (ppigrf: 9.85 nT here).
        let high = (full - b(10)).norm();
        assert!(high > 1.0 && high < 30.0, "{high}");
        // Degree-1 field decays exactly as r⁻³ along a radius.
        let m1 = IgrfModel::with_max_degree(y, 1).unwrap();
        let f1 = m1.field_geocentric(7.0e6, 0.8, 1.2);
        let f2 = m1.field_geocentric(14.0e6, 0.8, 1.2);
        assert!((f1.br_nt / f2.br_nt - 8.0).abs() < 1e-12);
        assert!((f1.btheta_nt / f2.btheta_nt - 8.0).abs() < 1e-12);
    }
}
