//! The blade model: rotor geometry, blade axes and the dipole integral along
//! a blade (spec `helicopter.md` part A "Blade model"; seed `000_…` §§14–15).
//!
//! A blade is a thin rod from `ρ0` to `ρ1` along the unit vector `r_p` from
//! the hub, uniformly magnetised with moment density `m` (A·m²/m = A·m).
//! Its field at the sensor is `ΔB = D_I m`, the *dipole integral*
//!
//! `D_I = ∫_{ρ0}^{ρ1} D(a − s r_p) ds`, `D(r) = μ0/(4π) (3 r rᵀ/|r|⁵ − I/|r|³)`,
//!
//! with `a` the sensor position relative to the hub. Writing
//! `|a − s u|² = (s − p)² + h²` (`p = a·u`, `h² = |a|² − p²`, `t = s − p`,
//! `q = t² + h²`) the integral is analytic:
//!
//! `D_I = μ0/(4π) [3 (a aᵀ J0 − (a uᵀ + u aᵀ) J1 + u uᵀ J2) − I K0]`,
//!
//! `K0 = [t/(h²√q)]`, `J0 = [G0]`, `J1 = [G1 + p G0]`,
//! `J2 = [G2 + 2p G1 + p² G0]`, with `G0 = t(2t² + 3h²)/(3h⁴ q^{3/2})`,
//! `G1 = −1/(3 q^{3/2})`, `G2 = t³/(3h² q^{3/2})`, each evaluated between
//! `t = ρ0 − p` and `t = ρ1 − p`.
//!
//! Blade axes (body frame x forward, y right, z down): blade `j` of `N` at
//! azimuth `ψ_j = ψ + 2πj/N` (from the nose towards the right; rotor
//! angular velocity `ω = (0, 0, dψ/dt)`), flap angle
//! `β_j = β0 + a1 cos ψ_j + b1 sin ψ_j`:
//! `r_p = (cos β cos ψ, cos β sin ψ, −sin β)`, `e_l = (−sin ψ, cos ψ, 0)`,
//! `e_u = e_l × r_p`.

use aeromag_core::MU0_OVER_4PI;
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

use crate::error::{CompError, Result};

/// The rotor geometry assumed by the model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RotorGeometry {
    /// Hub position, body axes, m.
    pub hub_m: [f64; 3],
    /// Scalar-sensor position, body axes, m.
    pub sensor_m: [f64; 3],
    /// Start of the magnetised span from the hub, m.
    pub root_m: f64,
    /// End of the magnetised span (blade tip), m.
    pub tip_m: f64,
    /// Number of blades.
    pub blades: usize,
    /// Direction of the rotor's angular velocity, body axes. Default
    /// (0, 0, 1): a main rotor turning clockwise seen from above.
    #[serde(default = "main_spin_axis")]
    pub spin_axis: [f64; 3],
    /// Body direction of a blade at azimuth 0. Default (1, 0, 0), the nose.
    #[serde(default = "main_zero_azimuth")]
    pub zero_azimuth: [f64; 3],
}

fn main_spin_axis() -> [f64; 3] {
    [0.0, 0.0, 1.0]
}

fn main_zero_azimuth() -> [f64; 3] {
    [1.0, 0.0, 0.0]
}

/// Most blades of a rotor (main rotors have 2 to 8, tail rotors up to 10 or
/// so): each blade carries its own parameters, and 100 000 blades ran the
/// fit out of memory.
pub const MAX_BLADES: usize = 16;

/// Largest distance of a rotor hub, a sensor or a blade tip from the body
/// frame's origin, m. The largest rotors are about 16 m in radius and a
/// sensor sits on the airframe; a hub or sensor 10³⁰ m away made every
/// regressor underflow and the fit wrote a model of zeros with exit 0.
pub const MAX_ROTOR_EXTENT_M: f64 = 100.0;

/// Shortest magnetised blade span (tip − root) taken, m: shorter is no
/// blade (a span of 10⁻³⁰⁰ m gave zero regressors and a model of zeros,
/// written with exit 0).
pub const MIN_BLADE_SPAN_M: f64 = 0.01;

/// Largest flap angle taken, rad (30°): a coning or tilt beyond is not a
/// rotor cone (1e300° was fitted and reported as a mean coning of 10¹⁷°).
pub const MAX_FLAP_RAD: f64 = std::f64::consts::FRAC_PI_6;

/// Flap angles of the rotor cone (rad): coning `β0` and the tip-path-plane
/// tilts `a1` (longitudinal), `b1` (lateral).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct FlapAngles {
    /// Coning `β0`, rad.
    pub coning_rad: f64,
    /// Longitudinal tilt `a1`, rad.
    pub tilt_lon_rad: f64,
    /// Lateral tilt `b1`, rad.
    pub tilt_lat_rad: f64,
}

impl RotorGeometry {
    /// A main rotor (rotor plane normal to the body z axis, azimuth from
    /// the nose towards the right) with the hub and the sensor at `hub_m`
    /// and `sensor_m` (body axes, m), magnetised from `root_m` to `tip_m`
    /// from the hub, with `blades` blades.
    pub fn main_rotor(
        hub_m: [f64; 3],
        sensor_m: [f64; 3],
        root_m: f64,
        tip_m: f64,
        blades: usize,
    ) -> Self {
        Self {
            hub_m,
            sensor_m,
            root_m,
            tip_m,
            blades,
            spin_axis: main_spin_axis(),
            zero_azimuth: main_zero_azimuth(),
        }
    }

    /// The same rotor in another plane: angular velocity along
    /// `spin_axis`, azimuth 0 towards `zero_azimuth` (body axes; e.g. a
    /// tail rotor).
    pub fn with_plane(self, spin_axis: [f64; 3], zero_azimuth: [f64; 3]) -> Self {
        Self {
            spin_axis,
            zero_azimuth,
            ..self
        }
    }

    /// Rotation from the rotor's hub frame (z along the angular velocity,
    /// x towards azimuth 0) to body axes; errors for a degenerate plane.
    pub fn body_from_hub(&self) -> Result<Matrix3<f64>> {
        aeromag_core::frames::blade::body_from_hub(self.spin_axis, self.zero_azimuth).ok_or_else(
            || {
                CompError::setting(
                    "rotor geometry: spin_axis and zero_azimuth must be non-zero and not parallel",
                )
            },
        )
    }

    /// Check the geometry: hub and sensor within [`MAX_ROTOR_EXTENT_M`] of
    /// the body frame's origin, `0 ≤ root < tip ≤` [`MAX_ROTOR_EXTENT_M`]
    /// with a magnetised span of at least [`MIN_BLADE_SPAN_M`], 2 to
    /// [`MAX_BLADES`] blades and a rotor plane. The message names the value
    /// that is wrong.
    pub fn validate(&self) -> Result<()> {
        use aeromag_core::error::shown;
        let bad = |m: String| Err(CompError::setting(format!("rotor geometry: {m}")));
        for (name, p) in [("hub_m", self.hub_m), ("sensor_m", self.sensor_m)] {
            if p.iter().any(|x| x.is_nan() || x.abs() > MAX_ROTOR_EXTENT_M) {
                return bad(format!(
                    "{name} ({}) m must be finite and within ±{MAX_ROTOR_EXTENT_M} m of the body frame's origin",
                    p.map(shown).join(", ")
                ));
            }
        }
        let (root, tip) = (self.root_m, self.tip_m);
        if !((0.0..MAX_ROTOR_EXTENT_M).contains(&root)
            && tip <= MAX_ROTOR_EXTENT_M
            && tip - root >= MIN_BLADE_SPAN_M)
        {
            return bad(format!(
                "blade span root_m {}, tip_m {} m: need 0 ≤ root < tip ≤ {MAX_ROTOR_EXTENT_M} m with tip − root ≥ {MIN_BLADE_SPAN_M} m",
                shown(root),
                shown(tip)
            ));
        }
        if !(2..=MAX_BLADES).contains(&self.blades) {
            return bad(format!(
                "{} blades: 2 to {MAX_BLADES} required",
                self.blades
            ));
        }
        self.body_from_hub().map(|_| ())
    }

    /// Sensor relative to the hub, body axes, m.
    pub fn sensor_from_hub(&self) -> Vector3<f64> {
        Vector3::from(self.sensor_m) - Vector3::from(self.hub_m)
    }
}

/// Blade axes `[r_p e_l e_u]` (columns) of the blade at azimuth `psi_rad`
/// (module docs).
pub fn blade_axes(psi_rad: f64, f: &FlapAngles) -> Matrix3<f64> {
    let beta = f.coning_rad + f.tilt_lon_rad * psi_rad.cos() + f.tilt_lat_rad * psi_rad.sin();
    aeromag_core::frames::blade::blade_axes(psi_rad, beta)
}

/// The dipole integral `D_I` (T per A·m of moment density) of a rod from
/// `rho0_m` to `rho1_m` along the unit vector `u`, seen from `a` (m,
/// relative to the hub); analytic (module docs).
///
/// Errors: the sensor on the rod's line (`h < 10⁻⁶ m`).
pub fn dipole_integral(
    a: &Vector3<f64>,
    u: &Vector3<f64>,
    rho0_m: f64,
    rho1_m: f64,
) -> Result<Matrix3<f64>> {
    let p = a.dot(u);
    let h2 = a.norm_squared() - p * p;
    if h2.is_nan() || h2 <= 1e-12 {
        return Err(CompError::data(
            "dipole integral: the sensor lies on the blade's line",
        ));
    }
    let prim = |t: f64| {
        let q = t * t + h2;
        let q32 = q * q.sqrt();
        let k0 = t / (h2 * q.sqrt());
        let g0 = t * (2.0 * t * t + 3.0 * h2) / (3.0 * h2 * h2 * q32);
        let g1 = -1.0 / (3.0 * q32);
        let g2 = t * t * t / (3.0 * h2 * q32);
        [k0, g0, g1 + p * g0, g2 + 2.0 * p * g1 + p * p * g0]
    };
    let (lo, hi) = (prim(rho0_m - p), prim(rho1_m - p));
    let [k0, j0, j1, j2] = std::array::from_fn(|i| hi[i] - lo[i]);
    let m = 3.0
        * (a * a.transpose() * j0 - (a * u.transpose() + u * a.transpose()) * j1
            + u * u.transpose() * j2)
        - Matrix3::identity() * k0;
    Ok(m * MU0_OVER_4PI)
}

#[cfg(test)]
mod tests {
    use super::*;
    use aeromag_core::field::dipole::dipole_matrix;
    use proptest::prelude::*;

    #[test]
    fn absurd_geometries_are_refused_naming_the_value() {
        let ok = RotorGeometry::main_rotor([0.0, 0.0, -2.6], [5.0, 0.0, 0.6], 0.8, 7.5, 4);
        ok.validate().unwrap();
        // Each was taken: a hub or sensor 10³⁰ m away and a span of
        // 10⁻³⁰⁰ m gave a model of zeros (exit 0), 1e308 the message "the
        // sensor lies on the blade's line", a tip of 1e308 m a NaN design.
        type Edit = fn(&mut RotorGeometry);
        let cases: [(Edit, &str); 6] = [
            (|g| g.hub_m[0] = 1e30, "hub_m"),
            (|g| g.sensor_m[2] = -1e308, "sensor_m"),
            (|g| g.sensor_m[1] = f64::NAN, "sensor_m"),
            (|g| (g.root_m, g.tip_m) = (1e-300, 1e-299), "blade span"),
            (|g| g.tip_m = 1e308, "blade span"),
            (|g| g.blades = 17, "blades"),
        ];
        for (edit, what) in cases {
            let mut g = ok.clone();
            edit(&mut g);
            let e = g.validate().unwrap_err();
            let msg = e.to_string();
            assert!(e.is_bad_input() && msg.contains(what), "{msg}");
            assert!(!msg.contains("00000000000"), "{msg}");
        }
    }

    fn simpson(a: &Vector3<f64>, u: &Vector3<f64>, r0: f64, r1: f64) -> Matrix3<f64> {
        let m = 20_000;
        let h = (r1 - r0) / m as f64;
        (0..=m)
            .map(|i| {
                dipole_matrix(&(a - (r0 + i as f64 * h) * u))
                    * (h * aeromag_core::quadrature::simpson_weight(i, m))
            })
            .sum()
    }

    proptest! {
        #[test]
        fn analytic_integral_matches_quadrature(
            ax in -8.0..8.0f64, ay in -8.0..8.0f64, az in 1.0..5.0f64,
            th in 0.0..std::f64::consts::TAU, r0 in 0.0..1.5f64, len in 2.0..8.0f64,
        ) {
            let a = Vector3::new(ax, ay, az);
            let u = Vector3::new(th.cos(), th.sin(), 0.05);
            let u = u / u.norm();
            let exact = dipole_integral(&a, &u, r0, r0 + len).unwrap();
            let num = simpson(&a, &u, r0, r0 + len);
            prop_assert!((exact - num).norm() <= 1e-7 * num.norm(), "{exact} vs {num}");
        }
    }

    #[test]
    fn sensor_on_the_blade_line_is_an_error_and_axes_are_orthonormal() {
        let u = Vector3::new(1.0, 0.0, 0.0);
        assert!(dipole_integral(&Vector3::new(9.0, 0.0, 0.0), &u, 1.0, 7.0).is_err());
        let f = FlapAngles {
            coning_rad: 0.07,
            tilt_lon_rad: -0.02,
            tilt_lat_rad: 0.01,
        };
        let r = blade_axes(1.3, &f);
        assert!((r.transpose() * r - Matrix3::identity()).norm() < 1e-12);
    }
}
