//! The magnetic interference of a fixed-wing aircraft: magnetised and
//! conducting parts at positions in the airframe.
//!
//! This is the *truth* model of the simulator (spec `simulator.md`,
//! "Platform interference truth"; seed `000_…` §4, §7: permanent, induced and
//! eddy-current sources of the Leliak model), deliberately richer than the
//! Tolles–Lawson formula the estimators fit. All vectors are in the body
//! frame (x forward, y right wing, z down), positions in metres from the
//! navigation reference point (body origin).
//!
//! With `B` the external field in body axes (T), `r = p_sensor − p_part` and
//! `D(r) = μ0/(4π|r|³)(3 e eᵀ − I)` the dipole matrix
//! ([`aeromag_core::field::dipole::dipole_matrix`]):
//!
//! * **Permanent** (hard iron): moment `m_p` fixed in the body (A·m²);
//!   field `D(r) m_p`. A part's moment may creep, `m_p(t) = m_p + ṁ_p t`
//!   with `t` the hours since the flight's start (`permanent_creep_am2_per_h`,
//!   default 0): the slow change of an aircraft's magnetization over a long
//!   survey (vibration, temperature, a magnetised tool left on board) that
//!   an adaptive compensator must follow (issue 21).
//! * **Induced** (soft iron): `m = (X V/μ0) B` with a full, not necessarily
//!   symmetric, susceptibility-volume matrix `X V` (m³; demagnetisation and
//!   shape anisotropy included); field `D(r) (X V/μ0) B`.
//! * **Eddy currents**: each conducting structure is a loop of area `A`,
//!   unit normal `n`, resistance `R` and time constant `τ = L/R`. Faraday's
//!   law `L di/dt + R i = −A n·dB/dt` gives the first-order lag
//!   `τ di/dt + i = −(A/R) n·dB/dt` driven by the rate of change of the
//!   external field in body axes (rotation of the aircraft and motion through
//!   the field); moment `m = i A n`, field `D(r) A n i`. For `ωτ ≪ 1` this is
//!   Tolles–Lawson's `M dB/dt`; at manoeuvre frequencies (0.1–0.3 Hz) and
//!   `τ` = 0.1–1 s the lag is not negligible. Discretised exactly for a body
//!   field that is linear between samples
//!   ([`crate::numerics::lag::lag_zoh`] with the per-step rate).
//! * **On-board currents** (optional): a loop of area `A`, normal `n`
//!   carrying the current `I(t)` of a recorded channel; moment `I A n`.
//!
//! The field of every part is evaluated with the exact dipole formula at the
//! scalar sensor and, separately, at the fluxgate. The parts are driven by
//! the external field at the scalar sensor (the field differs across the
//! airframe by ≲ 1e-5 relative, a ≪ 1e-3 nT effect on the interference).
//!
//! ## Default aircraft (a twin-engine turboprop with a tail stinger)
//!
//! Scalar sensor at `(−9.5, 0, −0.6)` m (stinger tip), fluxgate at
//! `(−8.0, 0, −0.5)` m (stinger root). Parts (positions m, moments A·m²,
//! `X V` in 10⁻³ m³):
//!
//! | part | position | permanent | induced `X V` (xx, yy, zz; xy, xz, yx, yz, zx, zy) |
//! |---|---|---|---|
//! | left engine | (1.0, −3.2, 0.2) | (50, 15, −30) | (360, 180, 240; 45, −30, 15, 60, −24, 36) |
//! | right engine | (1.0, 3.2, 0.2) | (−36, 10, 24) | (330, 165, 255; −36, 27, 18, −54, 21, 30) |
//! | landing gear / centre section | (0.5, 0, 1.2) | (20, −8, 25) | (120, 75, 90; 15, 9, −12, 18, 6, −9) |
//! | avionics and battery bay | (−3.0, 0.5, 0.1) | (1.2, 0.6, −0.8) | (2, 1.5, 1.5; 0.2, 0, 0.1, −0.1, 0.3, 0) |
//! | tail fittings and trim actuator | (−7.2, 0, −1.1) | (−1.2, 0.25, 2.6) | (12, 7.5, 9; 1.2, 0, 0.75, −0.45, 0.9, 0.3) |
//! | fin spar hardware | (−8.6, 0, −2.1) | — | (3, 1.5, 4.5; 0.3, −0.2, 0.15, 0.4, 0, −0.15) |
//!
//! Eddy loops (position; normal; area m²; resistance µΩ; τ s): tail cone
//! skin (−7.6, 0, −0.3; x; 0.5; 200; 0.15), fin box (−8.4, 0, −1.6; y; 0.6;
//! 400; 0.3), left wing box (0.3, −4.5, 0; z; 6; 220; 0.6), right wing box
//! (0.3, 4.5, 0; z; 6; 220; 0.6), fuselage frames (−2.5, 0, 0; x; 2.5; 120;
//! 0.25), stabiliser (−7.6, 0, −0.6; z; 1.5; 800; 0.4).
//!
//! On the default calibration flight (field 53 100 nT, inclination ≈ 72°)
//! this gives an interference vector of ≈ 32 nT at the stinger; its effect
//! on the total field is −20 to +2 nT depending on the heading (28 nT range);
//! the manoeuvres move it by 3–3.5 nT peak to peak (roll), 4.7–8 nT (pitch)
//! and 0.4–2.4 nT (yaw), an uncompensated figure of merit of ≈ 44 nT; the
//! eddy-current part is 0.02–0.6 nT peak to peak (0.07 nT RMS in the
//! manoeuvres); at the fluxgate the interference is ≈ 560 nT. (Measured by
//! `tests/scenarios.rs`; every run's truth JSON holds its own statistics.)

use aeromag_core::field::dipole::dipole_matrix;
use aeromag_core::{MU0_OVER_4PI, NT_PER_T, T_PER_NT};
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

use crate::error::{Result, invalid, require_finite, require_positive};

/// μ0, T·m/A.
const MU0: f64 = 4.0 * std::f64::consts::PI * MU0_OVER_4PI;

/// A magnetised part: permanent moment and/or induced magnetisation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MagneticPart {
    /// Name (for the truth metadata).
    pub name: String,
    /// Position in the body frame, m.
    pub position_m: [f64; 3],
    /// Permanent moment, body frame, A·m² (at the flight's start).
    pub permanent_am2: [f64; 3],
    /// Change of the permanent moment per hour of flight, body frame,
    /// A·m²/h (0: a fixed moment).
    pub permanent_creep_am2_per_h: [f64; 3],
    /// Susceptibility times volume `X V`, body frame, m³ (rows of the 3×3
    /// matrix; induced moment `m = X V B/μ0`).
    pub susceptibility_volume_m3: [[f64; 3]; 3],
}

impl Default for MagneticPart {
    fn default() -> Self {
        Self {
            name: String::new(),
            position_m: [0.0; 3],
            permanent_am2: [0.0; 3],
            permanent_creep_am2_per_h: [0.0; 3],
            susceptibility_volume_m3: [[0.0; 3]; 3],
        }
    }
}

/// A conducting loop carrying eddy currents.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EddyLoop {
    /// Name.
    pub name: String,
    /// Centre, body frame, m.
    pub position_m: [f64; 3],
    /// Normal of the loop, body frame (normalised on use).
    pub normal: [f64; 3],
    /// Area, m².
    pub area_m2: f64,
    /// Resistance, Ω.
    pub resistance_ohm: f64,
    /// Time constant `L/R`, s.
    pub tau_s: f64,
}

/// A loop of on-board wiring carrying a recorded current.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CurrentLoop {
    /// Name; the recorded channel is `cur_<name>` (A). Lower-case letters,
    /// digits and `_`.
    pub name: String,
    /// Centre, body frame, m.
    pub position_m: [f64; 3],
    /// Normal, body frame (normalised on use).
    pub normal: [f64; 3],
    /// Effective area (turns × area), m².
    pub area_m2: f64,
    /// Mean current, A.
    pub mean_a: f64,
    /// Load switched on and off at random times, A.
    pub switched_a: f64,
    /// Mean number of switching events per hour.
    pub switches_per_hour: f64,
    /// RMS of the slow load fluctuation (Gauss–Markov), A.
    pub fluctuation_a: f64,
    /// Correlation time of the fluctuation, s.
    pub fluctuation_tau_s: f64,
    /// White noise of the recorded current channel, A RMS.
    pub channel_noise_a: f64,
    /// How the switched load `switched_a` varies in time (default: on and
    /// off at random, `switches_per_hour`).
    pub pattern: CurrentPattern,
    /// Time constant of an eddy-like lagged field response, s: the loop's
    /// field follows the current through a first-order lag (currents induced
    /// in nearby structure by a switching load). 0: the field follows the
    /// current at once.
    pub field_lag_s: f64,
}

/// The time pattern of a current loop's switched load, as on-board
/// equipment draws it (seed and spec: currents that "switch and ramp").
/// The load is `switched_a × p(t)` with `p` below.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum CurrentPattern {
    /// `p ∈ {0, 1}`, toggled at the events of a Poisson process of rate
    /// `switches_per_hour` (de-icing, a transmitter).
    #[default]
    Telegraph,
    /// Strobe light: `p = 1` for `pulse_s` every `period_s` (random phase).
    Strobe {
        /// Flash period, s.
        period_s: f64,
        /// Flash length, s (less than the period).
        pulse_s: f64,
    },
    /// Motor runs (flaps, trim): runs start at the events of a Poisson
    /// process of rate `runs_per_hour`, last `run_s`, and ramp up and down
    /// linearly over `ramp_s` at each end.
    Runs {
        /// Mean number of runs per hour.
        runs_per_hour: f64,
        /// Length of a run, s (at least twice `ramp_s`).
        run_s: f64,
        /// Ramp time at start and end, s.
        ramp_s: f64,
    },
    /// Pump or compressor cycle: on for `duty × period_s` every `period_s`
    /// (random phase).
    Cycle {
        /// Cycle period, s.
        period_s: f64,
        /// Fraction of the period on, 0–1.
        duty: f64,
    },
    /// Fan or heater levels: `p` jumps to one of `levels` (drawn at random)
    /// at the events of a Poisson process of rate `changes_per_hour`.
    Levels {
        /// The levels, as fractions of `switched_a`.
        levels: Vec<f64>,
        /// Mean number of level changes per hour.
        changes_per_hour: f64,
    },
    /// Servo activity: `p` is a first-order Gauss–Markov process of unit
    /// RMS and bandwidth `bandwidth_hz` (correlation time `1/(2π·bw)`).
    Servo {
        /// Bandwidth, Hz.
        bandwidth_hz: f64,
    },
}

impl CurrentLoop {
    /// The loop with its switching events `factor` times as frequent: the
    /// telegraph's switches, the motor's runs and the fan's level changes
    /// (periodic patterns — strobe, pump cycle — and servo activity are
    /// left as they are). Used for a calibration flight in which the crew
    /// cycles the equipment.
    pub fn cycled(mut self, factor: f64) -> Self {
        self.switches_per_hour *= factor;
        match &mut self.pattern {
            CurrentPattern::Runs { runs_per_hour, .. } => *runs_per_hour *= factor,
            CurrentPattern::Levels {
                changes_per_hour, ..
            } => *changes_per_hour *= factor,
            CurrentPattern::Telegraph
            | CurrentPattern::Strobe { .. }
            | CurrentPattern::Cycle { .. }
            | CurrentPattern::Servo { .. } => {}
        }
        self
    }
}

impl CurrentPattern {
    /// Error naming the first invalid field (`path` names the pattern).
    fn validate(&self, path: &str) -> Result<()> {
        let bad =
            |field: &str, reason: &str| Err(invalid(format!("{path}.{field}"), reason.to_string()));
        match self {
            CurrentPattern::Telegraph => {}
            CurrentPattern::Strobe { period_s, pulse_s } => {
                require_positive(&format!("{path}.period_s"), *period_s)?;
                if !(*pulse_s > 0.0 && pulse_s < period_s) {
                    return bad("pulse_s", "must be > 0 and less than period_s");
                }
            }
            CurrentPattern::Runs {
                runs_per_hour,
                run_s,
                ramp_s,
            } => {
                crate::error::require_non_negative(
                    &format!("{path}.runs_per_hour"),
                    *runs_per_hour,
                )?;
                crate::error::require_non_negative(&format!("{path}.ramp_s"), *ramp_s)?;
                if !(run_s.is_finite() && *run_s > 0.0 && *run_s >= 2.0 * ramp_s) {
                    return bad("run_s", "must be finite, > 0 and at least twice ramp_s");
                }
            }
            CurrentPattern::Cycle { period_s, duty } => {
                require_positive(&format!("{path}.period_s"), *period_s)?;
                if !(0.0..=1.0).contains(duty) {
                    return bad("duty", "must be between 0 and 1");
                }
            }
            CurrentPattern::Levels {
                levels,
                changes_per_hour,
            } => {
                crate::error::require_non_negative(
                    &format!("{path}.changes_per_hour"),
                    *changes_per_hour,
                )?;
                if levels.is_empty() || !levels.iter().all(|l| l.is_finite()) {
                    return bad("levels", "must be a non-empty list of finite numbers");
                }
            }
            CurrentPattern::Servo { bandwidth_hz } => {
                require_positive(&format!("{path}.bandwidth_hz"), *bandwidth_hz)?;
            }
        }
        Ok(())
    }
}

impl Default for CurrentLoop {
    fn default() -> Self {
        Self {
            name: "avionics".into(),
            position_m: [-3.0, 0.4, 0.3],
            normal: [0.0, 0.0, 1.0],
            area_m2: 0.05,
            mean_a: 20.0,
            switched_a: 8.0,
            switches_per_hour: 12.0,
            fluctuation_a: 0.5,
            fluctuation_tau_s: 30.0,
            channel_noise_a: 0.02,
            pattern: CurrentPattern::Telegraph,
            field_lag_s: 0.0,
        }
    }
}

/// The aircraft's magnetic parts.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AircraftConfig {
    /// Magnetised parts (defaults in the module docs).
    pub parts: Vec<MagneticPart>,
    /// Eddy-current loops (defaults in the module docs).
    pub eddy: Vec<EddyLoop>,
    /// On-board current loops. Default: none.
    pub currents: Vec<CurrentLoop>,
}

fn part(name: &str, p: [f64; 3], m: [f64; 3], d: [f64; 3], o: [f64; 6]) -> MagneticPart {
    // Given in 10⁻³ m³; division keeps the decimal values exact in the TOML.
    let s = 1e3;
    MagneticPart {
        name: name.into(),
        position_m: p,
        permanent_am2: m,
        permanent_creep_am2_per_h: [0.0; 3],
        susceptibility_volume_m3: [
            [d[0] / s, o[0] / s, o[1] / s],
            [o[2] / s, d[1] / s, o[3] / s],
            [o[4] / s, o[5] / s, d[2] / s],
        ],
    }
}

fn eddy(name: &str, p: [f64; 3], n: [f64; 3], area: f64, r_uohm: f64, tau: f64) -> EddyLoop {
    EddyLoop {
        name: name.into(),
        position_m: p,
        normal: n,
        area_m2: area,
        resistance_ohm: r_uohm / 1e6,
        tau_s: tau,
    }
}

impl Default for AircraftConfig {
    fn default() -> Self {
        Self {
            parts: vec![
                part(
                    "left engine",
                    [1.0, -3.2, 0.2],
                    [50.0, 15.0, -30.0],
                    [360.0, 180.0, 240.0],
                    [45.0, -30.0, 15.0, 60.0, -24.0, 36.0],
                ),
                part(
                    "right engine",
                    [1.0, 3.2, 0.2],
                    [-36.0, 10.0, 24.0],
                    [330.0, 165.0, 255.0],
                    [-36.0, 27.0, 18.0, -54.0, 21.0, 30.0],
                ),
                part(
                    "landing gear",
                    [0.5, 0.0, 1.2],
                    [20.0, -8.0, 25.0],
                    [120.0, 75.0, 90.0],
                    [15.0, 9.0, -12.0, 18.0, 6.0, -9.0],
                ),
                part(
                    "avionics bay",
                    [-3.0, 0.5, 0.1],
                    [1.2, 0.6, -0.8],
                    [2.0, 1.5, 1.5],
                    [0.2, 0.0, 0.1, -0.1, 0.3, 0.0],
                ),
                part(
                    "tail fittings",
                    [-7.2, 0.0, -1.1],
                    [-1.2, 0.25, 2.6],
                    [12.0, 7.5, 9.0],
                    [1.2, 0.0, 0.75, -0.45, 0.9, 0.3],
                ),
                part(
                    "fin spar",
                    [-8.6, 0.0, -2.1],
                    [0.0, 0.0, 0.0],
                    [3.0, 1.5, 4.5],
                    [0.3, -0.2, 0.15, 0.4, 0.0, -0.15],
                ),
            ],
            eddy: vec![
                eddy(
                    "tail cone skin",
                    [-7.6, 0.0, -0.3],
                    [1.0, 0.0, 0.0],
                    0.5,
                    200.0,
                    0.15,
                ),
                eddy(
                    "fin box",
                    [-8.4, 0.0, -1.6],
                    [0.0, 1.0, 0.0],
                    0.6,
                    400.0,
                    0.3,
                ),
                eddy(
                    "left wing box",
                    [0.3, -4.5, 0.0],
                    [0.0, 0.0, 1.0],
                    6.0,
                    220.0,
                    0.6,
                ),
                eddy(
                    "right wing box",
                    [0.3, 4.5, 0.0],
                    [0.0, 0.0, 1.0],
                    6.0,
                    220.0,
                    0.6,
                ),
                eddy(
                    "fuselage frames",
                    [-2.5, 0.0, 0.0],
                    [1.0, 0.0, 0.0],
                    2.5,
                    120.0,
                    0.25,
                ),
                eddy(
                    "stabiliser",
                    [-7.6, 0.0, -0.6],
                    [0.0, 0.0, 1.0],
                    1.5,
                    800.0,
                    0.4,
                ),
            ],
            currents: Vec::new(),
        }
    }
}

fn unit(v: [f64; 3], field: &str) -> Result<Vector3<f64>> {
    let n = Vector3::from(v);
    let norm = n.norm();
    if !(norm.is_finite() && norm > 0.0) {
        return Err(invalid(
            field,
            "the normal must be a non-zero finite vector",
        ));
    }
    Ok(n / norm)
}

fn finite3(field: &str, v: &[f64; 3]) -> Result<()> {
    for (i, x) in v.iter().enumerate() {
        require_finite(&format!("{field}[{i}]"), *x)?;
    }
    Ok(())
}

impl AircraftConfig {
    /// Check the values.
    pub fn validate(&self, p: &str) -> Result<()> {
        for (i, m) in self.parts.iter().enumerate() {
            let f = format!("{p}.parts[{i}]");
            finite3(&format!("{f}.position_m"), &m.position_m)?;
            finite3(&format!("{f}.permanent_am2"), &m.permanent_am2)?;
            finite3(
                &format!("{f}.permanent_creep_am2_per_h"),
                &m.permanent_creep_am2_per_h,
            )?;
            for (r, row) in m.susceptibility_volume_m3.iter().enumerate() {
                finite3(&format!("{f}.susceptibility_volume_m3[{r}]"), row)?;
            }
        }
        for (i, l) in self.eddy.iter().enumerate() {
            let f = format!("{p}.eddy[{i}]");
            finite3(&format!("{f}.position_m"), &l.position_m)?;
            unit(l.normal, &format!("{f}.normal"))?;
            require_positive(&format!("{f}.area_m2"), l.area_m2)?;
            require_positive(&format!("{f}.resistance_ohm"), l.resistance_ohm)?;
            require_positive(&format!("{f}.tau_s"), l.tau_s)?;
        }
        let mut names = std::collections::BTreeSet::new();
        for (i, c) in self.currents.iter().enumerate() {
            let f = format!("{p}.currents[{i}]");
            if c.name.is_empty()
                || !c
                    .name
                    .chars()
                    .all(|ch| ch.is_ascii_lowercase() || ch.is_ascii_digit() || ch == '_')
            {
                return Err(invalid(
                    format!("{f}.name"),
                    format!(
                        "`{}` must be non-empty lower-case letters, digits or `_` (it names the column cur_<name>)",
                        c.name
                    ),
                ));
            }
            if !names.insert(c.name.clone()) {
                return Err(invalid(
                    format!("{f}.name"),
                    format!("`{}` is used twice", c.name),
                ));
            }
            finite3(&format!("{f}.position_m"), &c.position_m)?;
            unit(c.normal, &format!("{f}.normal"))?;
            require_positive(&format!("{f}.area_m2"), c.area_m2)?;
            for (n, v) in [
                ("mean_a", c.mean_a),
                ("switched_a", c.switched_a),
                ("switches_per_hour", c.switches_per_hour),
                ("fluctuation_a", c.fluctuation_a),
                ("channel_noise_a", c.channel_noise_a),
            ] {
                crate::error::require_non_negative(&format!("{f}.{n}"), v)?;
            }
            require_positive(&format!("{f}.fluctuation_tau_s"), c.fluctuation_tau_s)?;
            crate::error::require_non_negative(&format!("{f}.field_lag_s"), c.field_lag_s)?;
            c.pattern.validate(&format!("{f}.pattern"))?;
        }
        Ok(())
    }
}

/// The aircraft's field at one sensor position, precomputed as
/// `ΔB = K + L B + Σ_l f_l i_l + Σ_c g_c I_c` (all in T; `L` dimensionless).
#[derive(Debug, Clone)]
pub struct InterferenceAt {
    /// Permanent field `Σ D(r) m_p` at the flight's start, T.
    pub permanent_t: Vector3<f64>,
    /// Its change per hour `Σ D(r) ṁ_p`, T/h.
    pub permanent_creep_t_per_h: Vector3<f64>,
    /// Induced matrix `Σ D(r) X V/μ0` (T per T).
    pub induced: Matrix3<f64>,
    /// Field per ampere of each eddy loop `D(r) A n`, T/A.
    pub eddy_per_a: Vec<Vector3<f64>>,
    /// Field per ampere of each current loop, T/A.
    pub current_per_a: Vec<Vector3<f64>>,
}

/// Contributions of the interference at one sample (T, body frame).
#[derive(Debug, Clone, Copy, Default)]
pub struct Contributions {
    /// Permanent part.
    pub permanent: Vector3<f64>,
    /// Induced part.
    pub induced: Vector3<f64>,
    /// Eddy-current part.
    pub eddy: Vector3<f64>,
    /// On-board currents.
    pub current: Vector3<f64>,
}

impl Contributions {
    /// The total `ΔB`, T.
    pub fn total(&self) -> Vector3<f64> {
        self.permanent + self.induced + self.eddy + self.current
    }
}

impl InterferenceAt {
    /// Precompute the interference at `sensor_m` (body frame, m).
    pub fn new(cfg: &AircraftConfig, sensor_m: [f64; 3]) -> Result<Self> {
        let s = Vector3::from(sensor_m);
        let mut permanent_t = Vector3::zeros();
        let mut permanent_creep_t_per_h = Vector3::zeros();
        let mut induced = Matrix3::zeros();
        for p in &cfg.parts {
            let d = dipole_matrix(&(s - Vector3::from(p.position_m)));
            permanent_t += d * Vector3::from(p.permanent_am2);
            permanent_creep_t_per_h += d * Vector3::from(p.permanent_creep_am2_per_h);
            let xv = Matrix3::from_row_slice(&p.susceptibility_volume_m3.concat());
            induced += d * xv / MU0;
        }
        let eddy_per_a = cfg
            .eddy
            .iter()
            .enumerate()
            .map(|(i, l)| {
                Ok(dipole_matrix(&(s - Vector3::from(l.position_m)))
                    * unit(l.normal, &format!("aircraft.eddy[{i}].normal"))?
                    * l.area_m2)
            })
            .collect::<Result<Vec<_>>>()?;
        let current_per_a = cfg
            .currents
            .iter()
            .enumerate()
            .map(|(i, l)| {
                Ok(dipole_matrix(&(s - Vector3::from(l.position_m)))
                    * unit(l.normal, &format!("aircraft.currents[{i}].normal"))?
                    * l.area_m2)
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Self {
            permanent_t,
            permanent_creep_t_per_h,
            induced,
            eddy_per_a,
            current_per_a,
        })
    }

    /// Contributions `hours` after the flight's start for external body
    /// field `b_t` (T), eddy currents `eddy_a` and on-board currents `cur_a`
    /// (A).
    pub fn contributions(
        &self,
        hours: f64,
        b_t: &Vector3<f64>,
        eddy_a: &[f64],
        cur_a: &[f64],
    ) -> Contributions {
        let mut eddy = Vector3::zeros();
        for (f, i) in self.eddy_per_a.iter().zip(eddy_a) {
            eddy += f * *i;
        }
        let mut current = Vector3::zeros();
        for (f, i) in self.current_per_a.iter().zip(cur_a) {
            current += f * *i;
        }
        Contributions {
            permanent: self.permanent_t + self.permanent_creep_t_per_h * hours,
            induced: self.induced * b_t,
            eddy,
            current,
        }
    }
}

/// Eddy currents (A) of every loop at every sample: `eddy[l][k]`.
///
/// `b_body_nt[k]` is the external field in body axes at sample `k` (nT),
/// taken as linear between samples: the drive of loop `l` over step `k` is
/// `u = −(A/R) n·(B_{k+1} − B_k)/Δt` and `i_{k+1} = a i_k + (1 − a) u`,
/// `a = e^(−Δt/τ)` (exact). The loops start in the steady state of the first
/// step's rate.
pub fn eddy_currents(
    cfg: &AircraftConfig,
    b_body_nt: &[Vector3<f64>],
    dt_s: f64,
) -> Result<Vec<Vec<f64>>> {
    let n = b_body_nt.len();
    cfg.eddy
        .iter()
        .enumerate()
        .map(|(i, l)| {
            let nrm = unit(l.normal, &format!("aircraft.eddy[{i}].normal"))?;
            let g = -l.area_m2 / l.resistance_ohm * T_PER_NT / dt_s;
            let mut u: Vec<f64> = (0..n.saturating_sub(1))
                .map(|k| g * nrm.dot(&(b_body_nt[k + 1] - b_body_nt[k])))
                .collect();
            let i0 = u.first().copied().unwrap_or(0.0);
            u.push(0.0);
            Ok(crate::numerics::lag::lag_zoh(&u, dt_s, l.tau_s, i0))
        })
        .collect()
}

/// Convert tesla to nanotesla.
pub fn nt(v: Vector3<f64>) -> Vector3<f64> {
    v * NT_PER_T
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn induced_part_is_linear_and_not_symmetric_in_general() {
        let cfg = AircraftConfig::default();
        let at = InterferenceAt::new(&cfg, [-9.5, 0.0, -0.6]).unwrap();
        let b = Vector3::new(1.5e-5, 2e-6, 4.8e-5);
        let c1 = at.contributions(0.0, &b, &[0.0; 6], &[]);
        let c2 = at.contributions(0.0, &(b * 2.0), &[0.0; 6], &[]);
        assert!((c2.induced - 2.0 * c1.induced).norm() < 1e-24);
        assert!((at.induced - at.induced.transpose()).norm() > 1e-3 * at.induced.norm());
        // the permanent part does not depend on the field
        assert_eq!(c1.permanent, c2.permanent);
    }

    #[test]
    fn eddy_current_of_a_ramp_is_a_first_order_lag() {
        // Field rotating into the loop normal at a constant rate from t = 1 s.
        let cfg = AircraftConfig {
            // R = 100 µΩ
            eddy: vec![eddy(
                "test",
                [-8.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                1.0,
                100.0,
                0.4,
            )],
            ..Default::default()
        };
        let dt = 0.1;
        let rate_nt_s = 5000.0;
        let b: Vec<Vector3<f64>> = (0..60)
            .map(|k| {
                let t = k as f64 * dt;
                Vector3::new(rate_nt_s * (t - 1.0).max(0.0), 0.0, 50_000.0)
            })
            .collect();
        let i = eddy_currents(&cfg, &b, dt).unwrap();
        let i_inf = -1.0 / 1e-4 * rate_nt_s * 1e-9; // −(A/R) dB/dt, A
        for (k, &ik) in i[0].iter().enumerate() {
            let t = k as f64 * dt;
            let expect = if t <= 1.0 + 1e-9 {
                0.0
            } else {
                i_inf * (1.0 - (-(t - 1.0) / 0.4).exp())
            };
            assert!(
                (ik - expect).abs() < 1e-12 * i_inf.abs(),
                "k={k}: {ik} vs {expect}"
            );
        }
    }

    #[test]
    fn bad_parts_are_rejected() {
        let mut cfg = AircraftConfig::default();
        cfg.eddy[0].normal = [0.0; 3];
        assert!(cfg.validate("aircraft").is_err());
        let cfg = AircraftConfig {
            currents: vec![CurrentLoop {
                name: "Bad Name".into(),
                ..Default::default()
            }],
            ..Default::default()
        };
        assert!(cfg.validate("aircraft").is_err());
    }
}
