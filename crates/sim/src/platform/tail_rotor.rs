//! A helicopter's tail rotor: magnetised, conducting blades turning in a
//! plane of their own at a rate geared to the main rotor (spec
//! `helicopter.md` part A, "the main (and tail) rotor"; seed `000_…` §13:
//! the fast part comes from the moving magnetised elements of the main and
//! tail rotor blades).
//!
//! The blades are the thin rods of [`super::rotor`] with the same hard,
//! soft and eddy-current magnetisation ([`BladeConfig`]); only their frame
//! differs. The hub frame has `z` along the rotor's angular velocity
//! (`spin_axis`, body axes) and `x` towards a blade at azimuth 0
//! (`zero_azimuth`); it maps to body axes by
//! [`aeromag_core::frames::blade::body_from_hub`]. Blade `j` of `N` at
//! azimuth `ψ_t + 2πj/N` with a constant coning `β` has body axes
//! `C R(ψ_t + 2πj/N, β)`.
//!
//! The tail rotor is driven through the gearbox from the main rotor, so its
//! phase is `ψ_t = k ψ + φ_0` (`k` the gear ratio, `φ_0` the phase offset,
//! `ψ` the main rotor's phase including its speed variation): it has its
//! own rate (`k f_r`, not a harmonic of `f_r` for a non-integer `k`) but no
//! speed variation of its own. Its blades do not flap with the load.

use aeromag_core::frames::blade::{blade_axes, body_from_hub};
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

use super::rotor::{BladeConfig, BladeSpan, EddyInput, RotorState, blade, blades_field_nt};
use crate::error::{Result, invalid, require_finite, require_non_negative, require_positive};
use aeromag_core::NT_PER_T;

/// The tail rotor (module docs). The defaults are a Mi-8-like three-blade
/// tail rotor on the left of the fin, 12.7 m behind the main rotor shaft.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TailRotorConfig {
    /// Hub position, body axes, m. Default (−12.7, −1.0, −2.4).
    pub hub_m: [f64; 3],
    /// Direction of the angular velocity, body axes. Default (0, −1, 0)
    /// (the axis points to the left; seen from the left, the blades turn
    /// clockwise).
    pub spin_axis: [f64; 3],
    /// Body direction of a blade at azimuth 0. Default (0, 0, −1) (up).
    pub zero_azimuth: [f64; 3],
    /// Start of the magnetised span from the hub, m. Default 0.3.
    pub root_m: f64,
    /// Tail rotor radius (blade tip), m. Default 1.95.
    pub radius_m: f64,
    /// Tail rotor speed over main rotor speed. Default 4.37 (21.1 Hz at
    /// the default 290 rpm: between the main rotor's 4th and 5th harmonic).
    pub gear_ratio: f64,
    /// Phase of blade 0 when the main rotor's blade 0 is at azimuth 0, deg.
    /// Default 37.
    pub phase_offset_deg: f64,
    /// Constant coning, deg. Default 1.
    pub coning_deg: f64,
    /// The blades. Default three steel-spar blades, each different: hard
    /// 2.4–3.3 A·m along the spar (±10 % across), χA ≈ 1.2·10⁻² m² along
    /// and 2·10⁻³ m² across, eddy gain ≈ 60 A·m per T/s with τ ≈ 4 ms.
    pub blades: Vec<BladeConfig>,
}

impl Default for TailRotorConfig {
    fn default() -> Self {
        Self {
            hub_m: [-12.7, -1.0, -2.4],
            spin_axis: [0.0, -1.0, 0.0],
            zero_azimuth: [0.0, 0.0, -1.0],
            root_m: 0.3,
            radius_m: 1.95,
            gear_ratio: 4.37,
            phase_offset_deg: 37.0,
            coning_deg: 1.0,
            blades: vec![
                blade([2.8, 0.25, -0.2], 12.0, 2.0, 60.0, 0.004),
                blade([2.4, -0.2, 0.3], 13.0, 2.2, 55.0, 0.005),
                blade([3.3, 0.1, 0.1], 11.5, 1.8, 65.0, 0.0035),
            ],
        }
    }
}

impl TailRotorConfig {
    /// Check the values (`p` names the table in messages).
    pub fn validate(&self, p: &str) -> Result<()> {
        for (name, v) in [
            ("hub_m", self.hub_m),
            ("spin_axis", self.spin_axis),
            ("zero_azimuth", self.zero_azimuth),
        ] {
            for (i, x) in v.iter().enumerate() {
                require_finite(&format!("{p}.{name}[{i}]"), *x)?;
            }
        }
        if body_from_hub(self.spin_axis, self.zero_azimuth).is_none() {
            return Err(invalid(
                format!("{p}.zero_azimuth"),
                "spin_axis and zero_azimuth must be non-zero and not parallel",
            ));
        }
        require_non_negative(&format!("{p}.root_m"), self.root_m)?;
        require_positive(&format!("{p}.radius_m"), self.radius_m)?;
        if self.radius_m <= self.root_m {
            return Err(invalid(format!("{p}.radius_m"), "must exceed root_m"));
        }
        require_positive(&format!("{p}.gear_ratio"), self.gear_ratio)?;
        require_finite(&format!("{p}.phase_offset_deg"), self.phase_offset_deg)?;
        require_finite(&format!("{p}.coning_deg"), self.coning_deg)?;
        if self.blades.len() < 2 {
            return Err(invalid(format!("{p}.blades"), "at least two blades"));
        }
        for (i, b) in self.blades.iter().enumerate() {
            b.validate(&format!("{p}.blades[{i}]"))?;
        }
        Ok(())
    }

    /// Rotation from the hub frame to body axes (module docs).
    pub fn body_from_hub(&self) -> Matrix3<f64> {
        body_from_hub(self.spin_axis, self.zero_azimuth).unwrap_or_else(Matrix3::identity)
    }

    /// Tail rotor phase `ψ_t = k ψ + φ_0` (rad) for the main rotor's phase
    /// `ψ` (rad).
    pub fn phase_rad(&self, main_phase_rad: f64) -> f64 {
        self.gear_ratio * main_phase_rad + self.phase_offset_deg.to_radians()
    }
}

/// Largest rotation of the tail rotor within one substep of the eddy-current
/// integration, rad.
const MAX_SUBSTEP_ROTATION_RAD: f64 = 0.05;

/// The tail rotor's field (nT, body axes) at `sensor_m` for the external
/// body field `b_nt` (nT), driven by the main rotor's `state`.
///
/// The eddy currents are integrated between samples
/// ([`EddyInput::Substepped`]): the phase and the field are interpolated
/// linearly within a sample, and the blade-frame rate is the exact
/// `d(R_jᵀ B)/dt = R_jᵀ (dB/dt − ω × B)`, `ω = Ω_t C ẑ`.
pub fn tail_rotor_field_nt(
    cfg: &TailRotorConfig,
    state: &RotorState,
    sensor_m: [f64; 3],
    b_nt: &[Vector3<f64>],
    dt_s: f64,
) -> Vec<Vector3<f64>> {
    tail_field_with_step(cfg, state, sensor_m, b_nt, dt_s, MAX_SUBSTEP_ROTATION_RAD)
}

/// [`tail_rotor_field_nt`] with at most `max_step_rad` of rotation per
/// substep of the eddy-current integration.
fn tail_field_with_step(
    cfg: &TailRotorConfig,
    state: &RotorState,
    sensor_m: [f64; 3],
    b_nt: &[Vector3<f64>],
    dt_s: f64,
    max_step_rad: f64,
) -> Vec<Vector3<f64>> {
    let n = b_nt.len().min(state.phase_rad.len());
    let c = cfg.body_from_hub();
    let spin = c.column(2).into_owned();
    let nb = cfg.blades.len() as f64;
    let beta = cfg.coning_deg.to_radians();
    let psi: Vec<f64> = state.phase_rad[..n]
        .iter()
        .map(|p| cfg.phase_rad(*p))
        .collect();
    let blade =
        |psi_t: f64, j: usize| c * blade_axes(psi_t + std::f64::consts::TAU * j as f64 / nb, beta);
    let max_step = psi
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(0.0, f64::max);
    let substeps = (max_step / max_step_rad).ceil().max(1.0) as usize;
    let rate = |k: usize, f: f64, j: usize| {
        let k1 = (k + 1).min(n - 1);
        let dpsi = psi[k1] - psi[k];
        let db = (b_nt[k1] - b_nt[k]) / NT_PER_T;
        let b = b_nt[k] / NT_PER_T + db * f;
        let omega = spin * (dpsi / dt_s);
        blade(psi[k] + f * dpsi, j).transpose() * (db / dt_s - omega.cross(&b))
    };
    blades_field_nt(
        &BladeSpan::new(cfg.hub_m, cfg.root_m, cfg.radius_m),
        &cfg.blades,
        &|k, j| blade(psi[k], j),
        &EddyInput::Substepped {
            substeps,
            rate: &rate,
        },
        sensor_m,
        &b_nt[..n],
        dt_s,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blades_turn_in_the_tail_rotor_plane_at_the_geared_rate() {
        let cfg = TailRotorConfig::default();
        cfg.validate("tail_rotor").unwrap();
        let c = cfg.body_from_hub();
        let axis = Vector3::from(cfg.spin_axis).normalize();
        for psi in [0.0, 0.4, 2.0] {
            let r = c * blade_axes(cfg.phase_rad(psi), 0.0);
            // An unconed blade lies in the plane normal to the axis.
            assert!(r.column(0).dot(&axis).abs() < 1e-14);
        }
        // Blade 0 points up when ψ_t = 0.
        let up = c * blade_axes(0.0, 0.0);
        assert!((up.column(0) - Vector3::new(0.0, 0.0, -1.0)).norm() < 1e-14);
        assert!((cfg.phase_rad(1.0) - cfg.phase_rad(0.0) - cfg.gear_ratio).abs() < 1e-14);
        let bad = TailRotorConfig {
            zero_azimuth: [0.0, 2.0, 0.0],
            ..TailRotorConfig::default()
        };
        assert!(bad.validate("tail_rotor").is_err());
    }

    /// The eddy-current integration between samples has converged: the
    /// field with the default substeps (≤ 0.05 rad of rotation each) and
    /// with four times as many differ by < 1 % of the eddy-current part.
    #[test]
    fn eddy_currents_between_samples_have_converged() {
        let n = 400;
        let dt = 0.01;
        let omega = 2.0 * std::f64::consts::PI * 290.0 / 60.0;
        let state = RotorState {
            phase_rad: (0..n).map(|k| omega * k as f64 * dt).collect(),
            omega_rad_s: vec![omega; n],
            coning_rad: vec![0.07; n],
            tilt_lon_rad: vec![0.0; n],
            tilt_lat_rad: vec![0.0; n],
        };
        let b: Vec<Vector3<f64>> = (0..n)
            .map(|k| Vector3::new(15e3, 2e3 * (0.3 * k as f64 * dt).sin(), 48e3))
            .collect();
        let sensor = [-10.0, 0.0, 0.3];
        let cfg = TailRotorConfig::default();
        let no_eddy = TailRotorConfig {
            blades: cfg
                .blades
                .iter()
                .map(|b| BladeConfig {
                    eddy_am_per_t_s: 0.0,
                    ..b.clone()
                })
                .collect(),
            ..cfg.clone()
        };
        let full = tail_rotor_field_nt(&cfg, &state, sensor, &b, dt);
        let static_part = tail_rotor_field_nt(&no_eddy, &state, sensor, &b, dt);
        let fine =
            tail_field_with_step(&cfg, &state, sensor, &b, dt, MAX_SUBSTEP_ROTATION_RAD / 4.0);
        let (mut d2, mut e2) = (0.0, 0.0);
        for k in 50..n {
            d2 += (full[k] - fine[k]).norm_squared();
            e2 += (full[k] - static_part[k]).norm_squared();
        }
        assert!(e2 > 0.0);
        assert!(
            (d2 / e2).sqrt() < 0.01,
            "relative change {}",
            (d2 / e2).sqrt()
        );
    }
}
