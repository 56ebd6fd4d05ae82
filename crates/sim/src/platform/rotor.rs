//! The main rotor of a helicopter: magnetised, conducting thin blades
//! rotating with coning and tip-path-plane tilt (spec `simulator.md`,
//! "Platform interference truth — helicopter"; spec `helicopter.md` part A;
//! seed `000_…` chapter 3, §§14–17).
//!
//! This is the *truth* model, deliberately richer than the estimators' blade
//! model of `aeromag-compensation::rotor`.
//!
//! ## Geometry (body frame: x forward, y right, z down)
//!
//! The hub is at `hub_m`. Blade `j` (of `N`) has azimuth
//! `ψ_j = ψ + 2π j/N`, measured from the nose towards the right side (the
//! rotor turns clockwise seen from above, as on the Mi-8; its angular
//! velocity is `ω = (0, 0, Ω)`, `Ω = dψ/dt > 0`), and flap angle
//! `β_j = β_0 + a_1 cos ψ_j + b_1 sin ψ_j` (coning `β_0`, longitudinal and
//! lateral tilt of the tip-path plane `a_1`, `b_1`; a positive angle raises
//! the blade). The blade's unit vectors are
//!
//! * along: `r_p = (cos β cos ψ, cos β sin ψ, −sin β)`,
//! * lead (direction of motion): `e_l = (−sin ψ, cos ψ, 0)`,
//! * up (flap normal): `e_u = e_l × r_p`,
//!
//! and `R_j = [r_p e_l e_u]` maps blade to body axes.
//!
//! ## Magnetisation (per metre of blade, uniform from root to tip)
//!
//! * hard: `R_j h_j`, `h_j` in blade axes (A·m²/m = A·m), different for
//!   every blade (mostly along the spar, small chord and flap parts);
//! * soft: `(χA_∥/μ0) r_p r_pᵀ B + (χA_⊥/μ0)(I − r_p r_pᵀ) B` (`χA` the
//!   susceptibility × cross-section, m²);
//! * eddy currents: `−g_j R_j y_j`, `τ_j dy_j/dt + y_j = d(R_jᵀ B)/dt` — a
//!   first-order lag of the rate of change of the field *seen by the
//!   rotating blade*, `R_jᵀ (dB/dt − ω × B)` (g in A·m per T/s).
//!
//! The field at a sensor is `ΔB = Σ_j D_I,j m_j`, with the dipole integral
//! `D_I,j = ∫_{ρ0}^{ρ1} D(p_s − hub − s r_p) ds` evaluated by 24-point
//! Gauss–Legendre quadrature (< 10⁻⁶ relative error for sensors more
//! than 2 m from the blade line, test `gauss_legendre_integrates_the_dipole_line`).
//!
//! ## Rotor state
//!
//! Load factor `n = cos θ / cos φ + V θ̇ / g` from the attitude; coning
//! `β_0 = coning_deg + coning_per_g_deg (n − 1)`, tilt
//! `a_1 = tilt_lon_deg + tilt_per_pitch_rate_s θ̇`, `b_1 = tilt_per_roll_rate_s φ̇`,
//! each lagged by `flap_tau_s`. Rotor speed
//! `Ω = Ω_0 (1 + δ − droop (n − 1))`, `δ` a Gauss–Markov process of RMS
//! `speed_rms_frac`, clamped to ±`speed_max_frac` (default ±1 %).

use aeromag_core::field::dipole::dipole_matrix;
use aeromag_core::{MU0_OVER_4PI, NT_PER_T};
use nalgebra::{Matrix3, Vector3};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::error::{Result, invalid, require_finite, require_non_negative, require_positive};

const MU0: f64 = 4.0 * std::f64::consts::PI * MU0_OVER_4PI;
use crate::numerics::lag::lag_zoh;
use crate::random::gauss_markov::gauss_markov;
use crate::random::normal;

/// One blade's magnetic parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BladeConfig {
    /// Hard magnetisation per metre in blade axes (along, lead, up), A·m.
    pub hard_am: [f64; 3],
    /// Susceptibility × cross-section along the spar, m².
    pub soft_along_m2: f64,
    /// Susceptibility × cross-section across the spar, m².
    pub soft_across_m2: f64,
    /// Eddy gain `g`, A·m per T/s of blade-frame field rate.
    pub eddy_am_per_t_s: f64,
    /// Eddy time constant, s.
    pub eddy_tau_s: f64,
}

impl BladeConfig {
    /// Check the values (`f` names the blade in messages).
    pub fn validate(&self, f: &str) -> Result<()> {
        for (k, x) in self.hard_am.iter().enumerate() {
            require_finite(&format!("{f}.hard_am[{k}]"), *x)?;
        }
        require_finite(&format!("{f}.soft_along_m2"), self.soft_along_m2)?;
        require_finite(&format!("{f}.soft_across_m2"), self.soft_across_m2)?;
        require_finite(&format!("{f}.eddy_am_per_t_s"), self.eddy_am_per_t_s)?;
        require_positive(&format!("{f}.eddy_tau_s"), self.eddy_tau_s)
    }
}

/// The main rotor.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RotorConfig {
    /// Hub position in body axes, m. Default (0, 0, −2.6).
    pub hub_m: [f64; 3],
    /// Distance from the hub to the magnetised blade root, m. Default 0.8.
    pub root_m: f64,
    /// Rotor radius (blade tip), m. Default 7.5.
    pub radius_m: f64,
    /// Nominal rotor speed, rev/min. Default 290 (4.83 Hz; blade passing
    /// 19.3 Hz with 4 blades).
    pub rpm: f64,
    /// RMS of the random rotor-speed variation, fraction. Default 0.005.
    pub speed_rms_frac: f64,
    /// Maximum speed deviation, fraction. Default 0.01 (±1 %).
    pub speed_max_frac: f64,
    /// Correlation time of the speed variation, s. Default 8.
    pub speed_tau_s: f64,
    /// Speed droop per g of extra load, fraction. Default 0.004.
    pub droop_per_g: f64,
    /// Coning angle at 1 g, deg. Default 4.
    pub coning_deg: f64,
    /// Extra coning per g of extra load, deg. Default 3.
    pub coning_per_g_deg: f64,
    /// Steady longitudinal tip-path-plane tilt, deg (positive: blade over
    /// the nose raised). Default −1.5 (disc tilted forward in cruise).
    pub tilt_lon_deg: f64,
    /// Longitudinal tilt per pitch rate, deg per deg/s. Default 0.4.
    pub tilt_per_pitch_rate_s: f64,
    /// Lateral tilt per roll rate, deg per deg/s. Default 0.4.
    pub tilt_per_roll_rate_s: f64,
    /// Lag of the flapping response, s. Default 0.3.
    pub flap_tau_s: f64,
    /// Write the recorded rotor phase channel `rotor_phase`. Default true.
    pub phase_channel: bool,
    /// Noise of the recorded rotor phase, deg RMS. Default 0.2.
    pub phase_noise_deg: f64,
    /// The blades (their number is the blade count). Default four blades
    /// with steel spars: hard 1.1–1.9 A·m along the spar (±10 % across),
    /// χA ≈ 2.5·10⁻² m² along and 5·10⁻³ m² across, eddy gain
    /// ≈ 150 A·m per T/s with τ ≈ 10 ms, each different; ≈ 3 nT RMS of
    /// rotor interference at the default nose-boom sensor.
    pub blades: Vec<BladeConfig>,
}

/// A blade from its hard magnetisation (A·m, blade axes), χA along and
/// across the spar in 10⁻³ m², eddy gain (A·m per T/s) and time constant
/// (s): the defaults' shorthand.
pub(crate) fn blade(hard: [f64; 3], along: f64, across: f64, eddy: f64, tau: f64) -> BladeConfig {
    BladeConfig {
        hard_am: hard,
        soft_along_m2: along / 1e3,
        soft_across_m2: across / 1e3,
        eddy_am_per_t_s: eddy,
        eddy_tau_s: tau,
    }
}

impl Default for RotorConfig {
    fn default() -> Self {
        Self {
            hub_m: [0.0, 0.0, -2.6],
            root_m: 0.8,
            radius_m: 7.5,
            rpm: 290.0,
            speed_rms_frac: 0.005,
            speed_max_frac: 0.01,
            speed_tau_s: 8.0,
            droop_per_g: 0.004,
            coning_deg: 4.0,
            coning_per_g_deg: 3.0,
            tilt_lon_deg: -1.5,
            tilt_per_pitch_rate_s: 0.4,
            tilt_per_roll_rate_s: 0.4,
            flap_tau_s: 0.3,
            phase_channel: true,
            phase_noise_deg: 0.2,
            blades: vec![
                blade([1.50, 0.15, -0.10], 25.0, 5.0, 150.0, 0.010),
                blade([1.10, -0.10, 0.15], 27.5, 6.0, 130.0, 0.012),
                blade([1.90, 0.05, 0.05], 23.0, 4.5, 170.0, 0.009),
                blade([1.30, 0.20, -0.15], 26.0, 5.5, 145.0, 0.011),
            ],
        }
    }
}

impl RotorConfig {
    /// Check the values.
    pub fn validate(&self, p: &str) -> Result<()> {
        for (i, x) in self.hub_m.iter().enumerate() {
            require_finite(&format!("{p}.hub_m[{i}]"), *x)?;
        }
        require_non_negative(&format!("{p}.root_m"), self.root_m)?;
        require_positive(&format!("{p}.radius_m"), self.radius_m)?;
        if self.radius_m <= self.root_m {
            return Err(invalid(format!("{p}.radius_m"), "must exceed root_m"));
        }
        require_positive(&format!("{p}.rpm"), self.rpm)?;
        for (n, v) in [
            ("speed_rms_frac", self.speed_rms_frac),
            ("speed_max_frac", self.speed_max_frac),
            ("droop_per_g", self.droop_per_g),
            ("phase_noise_deg", self.phase_noise_deg),
        ] {
            require_non_negative(&format!("{p}.{n}"), v)?;
        }
        if self.speed_max_frac >= 0.5 {
            return Err(invalid(format!("{p}.speed_max_frac"), "must be < 0.5"));
        }
        require_positive(&format!("{p}.speed_tau_s"), self.speed_tau_s)?;
        require_positive(&format!("{p}.flap_tau_s"), self.flap_tau_s)?;
        for (n, v) in [
            ("coning_deg", self.coning_deg),
            ("coning_per_g_deg", self.coning_per_g_deg),
            ("tilt_lon_deg", self.tilt_lon_deg),
            ("tilt_per_pitch_rate_s", self.tilt_per_pitch_rate_s),
            ("tilt_per_roll_rate_s", self.tilt_per_roll_rate_s),
        ] {
            require_finite(&format!("{p}.{n}"), v)?;
        }
        if self.blades.len() < 2 {
            return Err(invalid(format!("{p}.blades"), "at least two blades"));
        }
        for (i, b) in self.blades.iter().enumerate() {
            b.validate(&format!("{p}.blades[{i}]"))?;
        }
        Ok(())
    }

    /// A rotor that satisfies the assumptions of the thesis' simplified
    /// model (seed `000_…` §16; spec `helicopter.md`, "Simplified, linear
    /// model"): the blades turn uniformly (no speed variation, no droop) in
    /// one plane fixed in the body (constant cone and tilt), the hard
    /// magnetisation lies along the blade, the soft magnetisation along the
    /// blade only, and the eddy currents follow the field without lag
    /// (`τ` = 0.1 ms, `ω τ` = 0.003 rad). Otherwise the default rotor, with
    /// the default blades' along-spar values.
    pub fn simplified() -> Self {
        let d = Self::default();
        Self {
            speed_rms_frac: 0.0,
            droop_per_g: 0.0,
            coning_per_g_deg: 0.0,
            tilt_per_pitch_rate_s: 0.0,
            tilt_per_roll_rate_s: 0.0,
            blades: d
                .blades
                .iter()
                .map(|b| BladeConfig {
                    hard_am: [b.hard_am[0], 0.0, 0.0],
                    soft_across_m2: 0.0,
                    eddy_tau_s: 1e-4,
                    ..b.clone()
                })
                .collect(),
            ..d
        }
    }

    /// Nominal rotor frequency, Hz.
    pub fn nominal_hz(&self) -> f64 {
        self.rpm / 60.0
    }
}

/// The rotor's state along the flight.
#[derive(Debug, Clone)]
pub struct RotorState {
    /// True rotor phase `ψ` (azimuth of blade 0), rad, unwrapped.
    pub phase_rad: Vec<f64>,
    /// Rotor angular speed `Ω`, rad/s.
    pub omega_rad_s: Vec<f64>,
    /// Coning `β_0`, rad.
    pub coning_rad: Vec<f64>,
    /// Longitudinal tilt `a_1`, rad.
    pub tilt_lon_rad: Vec<f64>,
    /// Lateral tilt `b_1`, rad.
    pub tilt_lat_rad: Vec<f64>,
}

/// Central difference derivative (one-sided at the ends), per second.
fn derivative(x: &[f64], dt: f64) -> Vec<f64> {
    let n = x.len();
    (0..n)
        .map(|k| {
            let (a, b) = (k.saturating_sub(1), (k + 1).min(n - 1));
            if b > a {
                (x[b] - x[a]) / ((b - a) as f64 * dt)
            } else {
                0.0
            }
        })
        .collect()
}

impl RotorState {
    /// The rotor state for true roll `φ`, pitch `θ` (rad) and speed `V`
    /// (m/s) sampled every `dt_s` (module docs).
    pub fn generate(
        cfg: &RotorConfig,
        roll_rad: &[f64],
        pitch_rad: &[f64],
        speed_m_s: &[f64],
        dt_s: f64,
        rng: &mut ChaCha8Rng,
    ) -> Self {
        const G: f64 = 9.806_65;
        let n = roll_rad.len();
        let p = derivative(roll_rad, dt_s);
        let q = derivative(pitch_rad, dt_s);
        let load: Vec<f64> = (0..n)
            .map(|k| pitch_rad[k].cos() / roll_rad[k].cos() + speed_m_s[k] * q[k] / G)
            .collect();
        let lag = |u: Vec<f64>| {
            let y0 = u.first().copied().unwrap_or(0.0);
            lag_zoh(&u, dt_s, cfg.flap_tau_s, y0)
        };
        let coning = lag(load
            .iter()
            .map(|l| (cfg.coning_deg + cfg.coning_per_g_deg * (l - 1.0)).to_radians())
            .collect());
        let tilt_lon = lag(q
            .iter()
            .map(|q| cfg.tilt_lon_deg.to_radians() + cfg.tilt_per_pitch_rate_s * q)
            .collect());
        let tilt_lat = lag(p.iter().map(|p| cfg.tilt_per_roll_rate_s * p).collect());
        let delta = gauss_markov(rng, n, dt_s, cfg.speed_rms_frac, cfg.speed_tau_s);
        let omega0 = 2.0 * std::f64::consts::PI * cfg.nominal_hz();
        let omega: Vec<f64> = (0..n)
            .map(|k| {
                let d = (delta[k] - cfg.droop_per_g * (load[k] - 1.0))
                    .clamp(-cfg.speed_max_frac, cfg.speed_max_frac);
                omega0 * (1.0 + d)
            })
            .collect();
        // Trapezoidal phase, random start.
        let mut phase = Vec::with_capacity(n);
        let mut psi = normal(rng).rem_euclid(1.0) * std::f64::consts::TAU;
        for k in 0..n {
            if k > 0 {
                psi += 0.5 * (omega[k - 1] + omega[k]) * dt_s;
            }
            phase.push(psi);
        }
        Self {
            phase_rad: phase,
            omega_rad_s: omega,
            coning_rad: coning,
            tilt_lon_rad: tilt_lon,
            tilt_lat_rad: tilt_lat,
        }
    }

    /// Blade axes `R_j = [r_p e_l e_u]` of blade `j` of `blades` at sample `k`.
    pub fn blade_axes(&self, k: usize, j: usize, blades: usize) -> Matrix3<f64> {
        let psi = self.phase_rad[k] + std::f64::consts::TAU * j as f64 / blades as f64;
        let beta = self.coning_rad[k]
            + self.tilt_lon_rad[k] * psi.cos()
            + self.tilt_lat_rad[k] * psi.sin();
        aeromag_core::frames::blade::blade_axes(psi, beta)
    }
}

/// Nodes and weights of the `n`-point Gauss–Legendre rule on [−1, 1]
/// (Newton iteration on `P_n` from the Chebyshev guesses).
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-15 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

/// The rotor's field (nT, body axes) at `sensor_m` for the external body
/// field `b_nt` (nT) along the flight.
pub fn rotor_field_nt(
    cfg: &RotorConfig,
    state: &RotorState,
    sensor_m: [f64; 3],
    b_nt: &[Vector3<f64>],
    dt_s: f64,
) -> Vec<Vector3<f64>> {
    let n = b_nt.len().min(state.phase_rad.len());
    let nb = cfg.blades.len();
    blades_field_nt(
        &BladeSpan::new(cfg.hub_m, cfg.root_m, cfg.radius_m),
        &cfg.blades,
        &|k, j| state.blade_axes(k, j, nb),
        &EddyInput::Sampled,
        sensor_m,
        &b_nt[..n],
        dt_s,
    )
}

/// How the eddy-current state `y_j` of a blade (`τ dy_j/dt + y_j =
/// d(R_jᵀ B)/dt`, T/s, blade axes) is computed.
pub enum EddyInput<'a> {
    /// From the sampled blade-frame field: forward differences, lagged with
    /// a zero-order hold (the main rotor: 0.3 rad of rotation per sample at
    /// 100 Hz).
    Sampled,
    /// Integrated between samples in `substeps` zero-order-hold steps, with
    /// the rate given at any time: `rate(k, f, j)` is `d(R_jᵀ B)/dt` (T/s)
    /// of blade `j` at time `(k + f)·dt`, `0 ≤ f < 1`. For rotors that turn
    /// through a large angle within a sample (a tail rotor: 1.3 rad at
    /// 100 Hz), where differences of samples do not resolve the rotation.
    Substepped {
        /// Steps per sample interval.
        substeps: usize,
        /// The rate.
        rate: &'a dyn Fn(usize, f64, usize) -> Vector3<f64>,
    },
}

impl EddyInput<'_> {
    /// `y_j` at every sample for the blade-frame field `bb` (T) of blade
    /// `j` with time constant `tau_s`.
    fn state(&self, j: usize, bb: &[Vector3<f64>], tau_s: f64, dt_s: f64) -> Vec<Vector3<f64>> {
        let n = bb.len();
        match self {
            EddyInput::Sampled => {
                let lagged: [Vec<f64>; 3] = std::array::from_fn(|c| {
                    let u: Vec<f64> = (0..n)
                        .map(|k| {
                            if k + 1 < n {
                                (bb[k + 1][c] - bb[k][c]) / dt_s
                            } else {
                                0.0
                            }
                        })
                        .collect();
                    let y0 = u.first().copied().unwrap_or(0.0);
                    lag_zoh(&u, dt_s, tau_s, y0)
                });
                (0..n)
                    .map(|k| Vector3::new(lagged[0][k], lagged[1][k], lagged[2][k]))
                    .collect()
            }
            EddyInput::Substepped { substeps, rate } => {
                let m = (*substeps).max(1);
                let a = (-dt_s / (m as f64 * tau_s)).exp();
                let mut out = Vec::with_capacity(n);
                if n == 0 {
                    return out;
                }
                let mut y = rate(0, 0.0, j);
                out.push(y);
                for k in 0..n - 1 {
                    for s in 0..m {
                        let u = rate(k, (s as f64 + 0.5) / m as f64, j);
                        y = y * a + u * (1.0 - a);
                    }
                    out.push(y);
                }
                out
            }
        }
    }
}

/// Where a rotor's magnetised blades are: the hub (body axes, m) and the
/// magnetised span from `root_m` to `radius_m` along each blade.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BladeSpan {
    /// Hub position, body axes, m.
    pub hub_m: [f64; 3],
    /// Start of the magnetised span, m.
    pub root_m: f64,
    /// Blade tip, m.
    pub radius_m: f64,
}

impl BladeSpan {
    /// The span of blades from `root_m` to `radius_m` of a hub at `hub_m`.
    pub fn new(hub_m: [f64; 3], root_m: f64, radius_m: f64) -> Self {
        Self {
            hub_m,
            root_m,
            radius_m,
        }
    }
}

/// The field (nT, body axes) at `sensor_m` of rotating blades with the
/// magnetisation of the module docs, for the external body field `b_nt`
/// (nT): `axes(k, j)` gives blade `j`'s axes `[r_p e_l e_u]` in body axes
/// at sample `k`, `eddy` how the eddy currents follow the rotation. Shared
/// by the main and the tail rotor.
pub fn blades_field_nt(
    span: &BladeSpan,
    blades: &[BladeConfig],
    axes: &dyn Fn(usize, usize) -> Matrix3<f64>,
    eddy: &EddyInput,
    sensor_m: [f64; 3],
    b_nt: &[Vector3<f64>],
    dt_s: f64,
) -> Vec<Vector3<f64>> {
    let n = b_nt.len();
    let gl = gauss_legendre(24);
    let (r0, r1) = (span.root_m, span.radius_m);
    let a = Vector3::from(sensor_m) - Vector3::from(span.hub_m);
    let mut out = vec![Vector3::zeros(); n];
    for (j, bl) in blades.iter().enumerate() {
        // Blade-frame field rate, lagged: y_j.
        let axes: Vec<Matrix3<f64>> = (0..n).map(|k| axes(k, j)).collect();
        let bb: Vec<Vector3<f64>> = (0..n)
            .map(|k| axes[k].transpose() * b_nt[k] / NT_PER_T)
            .collect();
        let lagged = eddy.state(j, &bb, bl.eddy_tau_s, dt_s);
        let hard = Vector3::from(bl.hard_am);
        for k in 0..n {
            let rj = &axes[k];
            let rp = rj.column(0).into_owned();
            let mut di = Matrix3::zeros();
            for &(x, w) in &gl {
                let s = 0.5 * (r1 - r0) * x + 0.5 * (r1 + r0);
                di += dipole_matrix(&(a - s * rp)) * (0.5 * (r1 - r0) * w);
            }
            let bt = b_nt[k] / NT_PER_T;
            let along = rp * rp.dot(&bt);
            let y = lagged[k];
            let m = rj * hard
                + along * (bl.soft_along_m2 / MU0)
                + (bt - along) * (bl.soft_across_m2 / MU0)
                - rj * y * bl.eddy_am_per_t_s;
            out[k] += di * m * NT_PER_T;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::{Stream, rng_for};

    #[test]
    fn gauss_legendre_integrates_the_dipole_line() {
        // ∫ x^k over [-1, 1] exactly for k ≤ 2n−1.
        let gl = gauss_legendre(24);
        for k in 0..48 {
            let q: f64 = gl.iter().map(|(x, w)| w * x.powi(k)).sum();
            let exact = if k % 2 == 1 {
                0.0
            } else {
                2.0 / (k as f64 + 1.0)
            };
            assert!((q - exact).abs() < 1e-13, "k={k}: {q} vs {exact}");
        }
        // A line of dipoles seen from 1 m: compare with fine Simpson.
        let a = Vector3::new(3.0, 1.5, 1.5);
        let u = Vector3::new(1.0, 0.0, 0.0);
        let mut gq = Matrix3::zeros();
        for &(x, w) in &gl {
            let s = 3.0 * x + 4.0;
            gq += dipole_matrix(&(a - s * u)) * 3.0 * w;
        }
        let m = 20_000;
        let h = 6.0 / m as f64;
        let mut simpson = Matrix3::zeros();
        for i in 0..=m {
            simpson += dipole_matrix(&(a - (1.0 + i as f64 * h) * u))
                * (h * aeromag_core::quadrature::simpson_weight(i, m));
        }
        let rel = (gq - simpson).norm() / simpson.norm();
        assert!(rel < 1e-6, "relative error {rel}");
    }

    #[test]
    fn blade_axes_are_orthonormal_and_rotor_speed_stays_within_bounds() {
        let cfg = RotorConfig::default();
        let n = 2000;
        let dt = 0.01;
        let roll: Vec<f64> = (0..n).map(|k| 0.17 * (k as f64 * dt).sin()).collect();
        let pitch = vec![0.02; n];
        let v = vec![40.0; n];
        let st = RotorState::generate(
            &cfg,
            &roll,
            &pitch,
            &v,
            dt,
            &mut rng_for(1, Stream::Turbulence),
        );
        let w0 = 2.0 * std::f64::consts::PI * cfg.nominal_hz();
        for k in (0..n).step_by(37) {
            assert!((st.omega_rad_s[k] / w0 - 1.0).abs() <= 0.01 + 1e-12);
            let r = st.blade_axes(k, 1, 4);
            assert!((r.transpose() * r - Matrix3::identity()).norm() < 1e-12);
        }
        // coning follows the load (1/cos φ ≥ 1): never below the 1-g value
        // by more than the pitch-rate term allows.
        let c_min = st.coning_rad.iter().copied().fold(f64::INFINITY, f64::min);
        let c_max = st
            .coning_rad
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max);
        assert!(c_max - c_min > 0.01_f64.to_radians());
    }
}
