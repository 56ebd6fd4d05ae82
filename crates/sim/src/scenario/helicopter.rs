//! The `helicopter` scenario: a fuselage of magnetised and conducting parts
//! plus a main rotor of magnetised, conducting blades (spec `simulator.md`,
//! `helicopter.md` part A; seed `000_…` chapter 3).
//!
//! The flight is the calibration box of [`super::calibration`] flown at
//! helicopter speed (40 m/s) and low altitude (150 m above the terrain, a
//! realistic anomaly) with roll, pitch and yaw manoeuvres, sampled at
//! 100 Hz. The manoeuvres change the load factor and the body rates, hence
//! the coning and the tilt of the tip-path plane ([`RotorState`]).
//!
//! The pipeline reuses the fixed-wing one ([`super::fixed_wing::run`]) for
//! the trajectory, the environment, the fuselage (the [`crate::platform::
//! aircraft`] parts model) and the sensors, then adds the rotor's field
//! ([`rotor_field_nt`]) at the scalar sensor and the fluxgate:
//!
//! * `mag += |B + ΔB_f + ΔB_r| − |B + ΔB_f|` (exact modulus; `ΔB_f` the
//!   fuselage field, `ΔB_r` the rotor's);
//! * `flux += M ΔB_r` (`M` the fluxgate's scale/orthogonality/misalignment
//!   matrix; the fluxgate model is linear in the field).
//!
//! The scalar sensor's optional lag is *not* applied to the rotor part, so
//! the default lag of this scenario is 0 s.
//!
//! The scenario file is the fixed-wing file plus a `[rotor]` table
//! ([`RotorConfig`]) and, optionally, a `[tail_rotor]` table
//! ([`TailRotorConfig`]; an empty table takes its defaults): its field
//! `ΔB_t` is added with the main rotor's, `ΔB_r` below standing for both
//! in the `flux` and `true_rotor_x/y/z` columns.
//!
//! ## Extra columns
//!
//! | column | unit | meaning |
//! |---|---|---|
//! | `rotor_phase` | deg | recorded rotor phase in [0, 360) (if `rotor.phase_channel`) |
//! | `true_rotor_phase` | deg | true phase of blade 0, unwrapped |
//! | `true_rotor_hz` | Hz | true rotor frequency `Ω/2π` |
//! | `true_coning`, `true_tilt_lon`, `true_tilt_lat` | deg | true flap angles |
//! | `true_rotor` | nT | rotor part of the scalar reading (exact, see above; main and tail rotor) |
//! | `true_tail_rotor` | nT | the tail rotor's share of it, `|B + ΔB_f + ΔB_r + ΔB_t| − |B + ΔB_f + ΔB_r|` (with a tail rotor) |
//! | `true_fuselage` | nT | fuselage part `|B + ΔB_f| − |B|` |
//! | `true_rotor_x/y/z` | nT | rotor field at the scalar sensor, body axes |
//!
//! `true_interf = true_fuselage + true_rotor` and `true_interf_x/y/z`
//! include the rotor.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use super::ScenarioKind;
use super::calibration::CalibrationPattern;
use super::config::{FixedWingConfig, FlightConfig};
use super::fixed_wing;
use crate::environment::anomaly::{AnomalyArea, AnomalyConfig};
use crate::error::{Result, SimError};
use crate::output::{Column, Simulation};
use crate::platform::rotor::{RotorConfig, RotorState, rotor_field_nt};
use crate::platform::tail_rotor::{TailRotorConfig, tail_rotor_field_nt};
use crate::random::{Stream, normal, rng_for};
use crate::sensor::fluxgate::FluxgateConfig;
use crate::sensor::scalar::ScalarSensorConfig;
use crate::trajectory::KinematicsConfig;

/// The helicopter scenario's configuration: the fixed-wing file (flight,
/// pattern, fuselage parts in `aircraft`, sensors …) plus the rotor.
#[derive(Debug, Clone, PartialEq)]
pub struct HelicopterConfig {
    /// Everything but the rotor.
    pub base: FixedWingConfig<CalibrationPattern>,
    /// The main rotor.
    pub rotor: RotorConfig,
    /// The tail rotor, if modelled (a `[tail_rotor]` table; an empty table
    /// takes the defaults of [`TailRotorConfig`]). Default none.
    pub tail_rotor: Option<TailRotorConfig>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RotorTable {
    rotor: RotorConfig,
    #[serde(skip_serializing_if = "Option::is_none")]
    tail_rotor: Option<TailRotorConfig>,
}

/// The default helicopter scenario: 100 Hz, 40 m/s, box at 300 m (150 m
/// above the terrain) with 3 cycles of each manoeuvre per leg, realistic
/// anomaly, scalar sensor on a nose boom (5.0, 0, 0.6) m, fluxgate at
/// (4.5, 0, 0.6) m, the default rotor.
pub fn helicopter_defaults() -> HelicopterConfig {
    let pattern = CalibrationPattern {
        altitude_m: 300.0,
        cycles: 3,
        lead_in_s: 15.0,
        gap_s: 5.0,
        tail_s: 10.0,
        ..CalibrationPattern::full()
    };
    HelicopterConfig {
        base: FixedWingConfig {
            flight: FlightConfig {
                sample_rate_hz: 100.0,
                origin_lat_deg: 55.80,
                origin_lon_deg: 37.90,
                ..FlightConfig::default()
            },
            pattern,
            kinematics: KinematicsConfig {
                speed_m_s: 40.0,
                l1_distance_m: 300.0,
                ..KinematicsConfig::default()
            },
            turbulence: crate::trajectory::TurbulenceConfig::calibration(),
            anomaly: AnomalyConfig::with_area(AnomalyArea::Realistic),
            scalar: ScalarSensorConfig {
                position_m: [5.0, 0.0, 0.6],
                lag_s: 0.0,
                ..ScalarSensorConfig::default()
            },
            fluxgate: FluxgateConfig {
                position_m: [4.5, 0.0, 0.6],
                ..FluxgateConfig::default()
            },
            ..FixedWingConfig::default()
        },
        rotor: RotorConfig::default(),
        tail_rotor: None,
    }
}

impl HelicopterConfig {
    /// Parse a scenario file over `defaults`: the `[rotor]` table into
    /// [`RotorConfig`] (unset fields take their defaults), the rest as a
    /// fixed-wing file ([`FixedWingConfig::parse_over`]). `seed` overrides
    /// the file's seed. Syntax errors carry the file's line and column;
    /// errors in the non-rotor tables are reported against the file with
    /// the `[rotor]` table removed (re-serialised), so their line numbers
    /// may differ from the user's file.
    pub fn parse_over(defaults: Self, text: Option<&str>, seed: Option<u64>) -> Result<Self> {
        let kind = ScenarioKind::Helicopter;
        let Some(text) = text else {
            defaults.validate()?;
            let base = FixedWingConfig::parse_over(defaults.base, kind, None, seed)?;
            return Ok(Self { base, ..defaults });
        };
        let mut user = super::config::parse_table(text)?;
        let rotor = match user.remove("rotor") {
            None => defaults.rotor,
            Some(v) => v
                .try_into::<RotorConfig>()
                .map_err(|e| SimError::config(format!("[rotor]: {e}")))?,
        };
        let tail_rotor = match user.remove("tail_rotor") {
            None => defaults.tail_rotor,
            Some(v) => Some(
                v.try_into::<TailRotorConfig>()
                    .map_err(|e| SimError::config(format!("[tail_rotor]: {e}")))?,
            ),
        };
        let rest = toml::to_string(&user).map_err(|e| SimError::Serialize {
            what: "scenario",
            reason: e.to_string(),
        })?;
        let base = FixedWingConfig::parse_over(defaults.base, kind, Some(&rest), seed)?;
        let cfg = Self {
            base,
            rotor,
            tail_rotor,
        };
        cfg.validate()?;
        Ok(cfg)
    }

    /// Check the rotor tables.
    pub fn validate(&self) -> Result<()> {
        self.rotor.validate("rotor")?;
        match &self.tail_rotor {
            Some(t) => t.validate("tail_rotor"),
            None => Ok(()),
        }
    }

    /// The configuration as TOML, every default filled in.
    pub fn to_toml(&self) -> Result<String> {
        let base = self.base.to_toml(ScenarioKind::Helicopter)?;
        let rotor = toml::to_string(&RotorTable {
            rotor: self.rotor.clone(),
            tail_rotor: self.tail_rotor.clone(),
        })
        .map_err(|e| SimError::Serialize {
            what: "rotor",
            reason: e.to_string(),
        })?;
        Ok(format!("{base}\n{rotor}"))
    }
}

fn column<'a>(cols: &'a [Column], name: &str) -> Result<&'a [f64]> {
    cols.iter()
        .find(|c| c.name == name)
        .map(|c| c.values.as_slice())
        .ok_or_else(|| SimError::Trajectory(format!("internal: column `{name}` missing")))
}

fn vectors(cols: &[Column], prefix: &str) -> Result<Vec<Vector3<f64>>> {
    let x = column(cols, &format!("{prefix}_x"))?;
    let y = column(cols, &format!("{prefix}_y"))?;
    let z = column(cols, &format!("{prefix}_z"))?;
    Ok((0..x.len())
        .map(|k| Vector3::new(x[k], y[k], z[k]))
        .collect())
}

fn set(cols: &mut [Column], name: &str, f: impl Fn(usize, f64) -> f64) {
    if let Some(c) = cols.iter_mut().find(|c| c.name == name) {
        for (k, v) in c.values.iter_mut().enumerate() {
            *v = f(k, *v);
        }
    }
}

/// Run the helicopter scenario (module docs).
pub fn run(cfg: &HelicopterConfig) -> Result<Simulation> {
    cfg.validate()?;
    if !cfg.base.installation.is_stinger() {
        return Err(crate::error::invalid(
            "installation",
            "the helicopter scenario has the stinger installation only",
        ));
    }
    if !cfg.base.extra_scalars.is_empty() || !cfg.base.extra_fluxgates.is_empty() {
        return Err(crate::error::invalid(
            "extra_scalars",
            "extra sensors are not supported by the helicopter scenario \
             (the rotor's field is added at the main sensors only)",
        ));
    }
    let mut sim = fixed_wing::run(&cfg.base, ScenarioKind::Helicopter)?;
    let dt = 1.0 / cfg.base.flight.sample_rate_hz;
    let cols = &sim.columns;
    let rad = |name: &str| -> Result<Vec<f64>> {
        Ok(column(cols, name)?.iter().map(|d| d.to_radians()).collect())
    };
    let roll = rad("true_roll")?;
    let pitch = rad("true_pitch")?;
    let (vn, ve, vd) = (
        column(cols, "true_vn")?,
        column(cols, "true_ve")?,
        column(cols, "true_vd")?,
    );
    let speed: Vec<f64> = (0..vn.len())
        .map(|k| (vn[k] * vn[k] + ve[k] * ve[k] + vd[k] * vd[k]).sqrt())
        .collect();
    let b_ext = vectors(cols, "true_ext")?;
    let d_fus = vectors(cols, "true_interf")?;
    let mut rng = rng_for(cfg.base.seed, Stream::HelicopterRotor);
    let state = RotorState::generate(&cfg.rotor, &roll, &pitch, &speed, dt, &mut rng);
    let mut r_s = rotor_field_nt(&cfg.rotor, &state, cfg.base.scalar.position_m, &b_ext, dt);
    let mut r_f = rotor_field_nt(&cfg.rotor, &state, cfg.base.fluxgate.position_m, &b_ext, dt);
    let n = b_ext.len();
    let fus: Vec<f64> = (0..n)
        .map(|k| (b_ext[k] + d_fus[k]).norm() - b_ext[k].norm())
        .collect();
    // The tail rotor's part of the scalar reading, on top of the main rotor.
    let tail = match &cfg.tail_rotor {
        None => None,
        Some(t) => {
            let t_s = tail_rotor_field_nt(t, &state, cfg.base.scalar.position_m, &b_ext, dt);
            let t_f = tail_rotor_field_nt(t, &state, cfg.base.fluxgate.position_m, &b_ext, dt);
            let part: Vec<f64> = (0..n)
                .map(|k| {
                    let main = b_ext[k] + d_fus[k] + r_s[k];
                    (main + t_s[k]).norm() - main.norm()
                })
                .collect();
            for k in 0..n {
                r_s[k] += t_s[k];
                r_f[k] += t_f[k];
            }
            Some(part)
        }
    };
    let rot: Vec<f64> = (0..n)
        .map(|k| (b_ext[k] + d_fus[k] + r_s[k]).norm() - (b_ext[k] + d_fus[k]).norm())
        .collect();
    let m = cfg.base.fluxgate.matrix();
    let mf: Vec<Vector3<f64>> = r_f.iter().map(|r| m * r).collect();
    let cols = &mut sim.columns;
    set(cols, "mag", |k, v| v + rot[k]);
    set(cols, "true_interf", |k, v| v + rot[k]);
    for (i, a) in ["x", "y", "z"].iter().enumerate() {
        set(cols, &format!("flux_{a}"), |k, v| v + mf[k][i]);
        set(cols, &format!("true_flux_{a}"), |k, v| v + r_f[k][i]);
        set(cols, &format!("true_interf_{a}"), |k, v| v + r_s[k][i]);
    }
    let mut add = |name: &str, unit: &'static str, description: &str, values: Vec<f64>| {
        cols.push(Column {
            name: name.into(),
            unit,
            description: description.into(),
            values,
        })
    };
    if cfg.rotor.phase_channel {
        let mut prng = rng_for(cfg.base.seed, Stream::HelicopterRotorPhase);
        let rec: Vec<f64> = state
            .phase_rad
            .iter()
            .map(|p| {
                (p.to_degrees() + cfg.rotor.phase_noise_deg * normal(&mut prng)).rem_euclid(360.0)
            })
            .collect();
        add(
            "rotor_phase",
            "deg",
            "recorded rotor phase (azimuth of blade 0 from the nose, towards the right), [0, 360)",
            rec,
        );
    }
    let deg = |v: &[f64]| v.iter().map(|x| x.to_degrees()).collect::<Vec<f64>>();
    add(
        "true_rotor_phase",
        "deg",
        "true rotor phase, unwrapped",
        deg(&state.phase_rad),
    );
    add(
        "true_rotor_hz",
        "Hz",
        "true rotor frequency",
        state
            .omega_rad_s
            .iter()
            .map(|w| w / std::f64::consts::TAU)
            .collect(),
    );
    add(
        "true_coning",
        "deg",
        "true coning angle",
        deg(&state.coning_rad),
    );
    add(
        "true_tilt_lon",
        "deg",
        "true longitudinal tip-path-plane tilt",
        deg(&state.tilt_lon_rad),
    );
    add(
        "true_tilt_lat",
        "deg",
        "true lateral tip-path-plane tilt",
        deg(&state.tilt_lat_rad),
    );
    add(
        "true_rotor",
        "nT",
        "rotor part of the scalar reading |B+ΔB_f+ΔB_r| − |B+ΔB_f|",
        rot.clone(),
    );
    if let Some(part) = tail {
        add(
            "true_tail_rotor",
            "nT",
            "tail rotor part of the scalar reading |B+ΔB_f+ΔB_r+ΔB_t| − |B+ΔB_f+ΔB_r| (included in true_rotor)",
            part,
        );
    }
    add(
        "true_fuselage",
        "nT",
        "fuselage part of the scalar reading |B+ΔB_f| − |B|",
        fus,
    );
    for (i, a) in ["x", "y", "z"].iter().enumerate() {
        add(
            &format!("true_rotor_{a}"),
            "nT",
            "rotor field at the scalar sensor, body axes",
            r_s.iter().map(|r| r[i]).collect(),
        );
    }
    // Truth metadata and scenario file.
    let mut truth: serde_json::Value =
        serde_json::from_str(&sim.truth_json).map_err(|e| SimError::Serialize {
            what: "truth metadata",
            reason: e.to_string(),
        })?;
    let mean = rot.iter().sum::<f64>() / n.max(1) as f64;
    let rms = (rot.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n.max(1) as f64).sqrt();
    if let Some(obj) = truth.as_object_mut() {
        obj.insert(
            "rotor".into(),
            serde_json::json!({
                "config": &cfg.rotor,
                "tail_rotor": &cfg.tail_rotor,
                "true_rotor_mean_nt": mean,
                "true_rotor_std_nt": rms,
                "blade_passing_hz": cfg.rotor.nominal_hz() * cfg.rotor.blades.len() as f64,
            }),
        );
        obj.insert(
            "columns".into(),
            serde_json::json!(sim.columns.iter().map(|c| serde_json::json!({ "name": c.name, "unit": c.unit, "description": c.description })).collect::<Vec<_>>()),
        );
    }
    sim.truth_json = serde_json::to_string_pretty(&truth).map_err(|e| SimError::Serialize {
        what: "truth metadata",
        reason: e.to_string(),
    })?;
    sim.scenario_toml = cfg.to_toml()?;
    Ok(sim)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SHORT: &str = "[pattern]\ncycles = 1\nlead_in_s = 5.0\ngap_s = 2.0\ntail_s = 3.0\nlegs = [{ heading_deg = 0.0, manoeuvres = [\"roll\"] }, { heading_deg = 90.0, manoeuvres = [\"pitch\"] }]\n";

    #[test]
    fn helicopter_adds_rotor_and_keeps_the_sum_rules() {
        let cfg =
            HelicopterConfig::parse_over(helicopter_defaults(), Some(SHORT), Some(3)).unwrap();
        let sim = run(&cfg).unwrap();
        let c = |n: &str| sim.column(n).unwrap();
        let (mag, ext, int, he, lag, noise) = (
            c("mag"),
            c("true_external"),
            c("true_interf"),
            c("true_heading_error"),
            c("true_lag"),
            c("true_mag_noise"),
        );
        for k in 0..mag.len() {
            let s = ext[k] + int[k] + he[k] + lag[k] + noise[k];
            assert!((mag[k] - s).abs() < 1e-6, "k={k}");
            assert!((int[k] - c("true_fuselage")[k] - c("true_rotor")[k]).abs() < 1e-9);
        }
        let rot = c("true_rotor");
        let m = rot.iter().sum::<f64>() / rot.len() as f64;
        let rms = (rot.iter().map(|x| (x - m).powi(2)).sum::<f64>() / rot.len() as f64).sqrt();
        // A rotor interference of a few nT (≈ 10× an aeroplane's manoeuvre part).
        assert!(rms > 0.5 && rms < 50.0, "rotor rms {rms}");
        let hz = c("true_rotor_hz");
        assert!(
            hz.iter()
                .all(|f| (f / (290.0 / 60.0) - 1.0).abs() <= 0.01 + 1e-12)
        );
        assert!(sim.column("rotor_phase").is_some());
        // Scenario file round trip.
        let again =
            HelicopterConfig::parse_over(helicopter_defaults(), Some(&sim.scenario_toml), None)
                .unwrap();
        assert_eq!(again, cfg);
    }

    #[test]
    fn the_tail_rotor_adds_its_part_and_round_trips() {
        let text = format!("{SHORT}[tail_rotor]\n");
        let cfg =
            HelicopterConfig::parse_over(helicopter_defaults(), Some(&text), Some(3)).unwrap();
        assert_eq!(cfg.tail_rotor, Some(TailRotorConfig::default()));
        let sim = run(&cfg).unwrap();
        let c = |n: &str| sim.column(n).unwrap();
        let plain = run(
            &HelicopterConfig::parse_over(helicopter_defaults(), Some(SHORT), Some(3)).unwrap(),
        )
        .unwrap();
        let (rot, tail, rot0) = (
            c("true_rotor"),
            c("true_tail_rotor"),
            plain.column("true_rotor").unwrap(),
        );
        for k in 0..rot.len() {
            // The tail's part is what it adds to the main rotor's (same seed).
            assert!((rot[k] - rot0[k] - tail[k]).abs() < 1e-9, "k={k}");
        }
        let m = tail.iter().sum::<f64>() / tail.len() as f64;
        let rms = (tail.iter().map(|x| (x - m).powi(2)).sum::<f64>() / tail.len() as f64).sqrt();
        // 18 m from the nose-boom sensor: a small part.
        assert!(rms > 1e-3 && rms < 0.1, "tail rotor rms {rms}");
        let again =
            HelicopterConfig::parse_over(helicopter_defaults(), Some(&sim.scenario_toml), None)
                .unwrap();
        assert_eq!(again, cfg);
        assert!(
            HelicopterConfig::parse_over(
                helicopter_defaults(),
                Some("[tail_rotor]\nspin_axis = [0.0, 0.0, 0.0]\n"),
                None
            )
            .is_err()
        );
    }

    #[test]
    fn same_seed_is_bit_identical() {
        let run_with = |seed| {
            let cfg = HelicopterConfig::parse_over(helicopter_defaults(), Some(SHORT), Some(seed))
                .unwrap();
            run(&cfg).unwrap()
        };
        let (a, b, c) = (run_with(5), run_with(5), run_with(6));
        let bits = |s: &Simulation, n: &str| -> Vec<u64> {
            s.column(n).unwrap().iter().map(|v| v.to_bits()).collect()
        };
        for n in ["mag", "true_rotor", "rotor_phase", "flux_x"] {
            assert_eq!(bits(&a, n), bits(&b, n), "{n}");
        }
        assert_ne!(bits(&a, "true_rotor"), bits(&c, "true_rotor"));
    }

    #[test]
    fn unknown_rotor_fields_are_rejected() {
        assert!(
            HelicopterConfig::parse_over(helicopter_defaults(), Some("[rotor]\nrpmm = 3\n"), None)
                .is_err()
        );
        assert!(
            HelicopterConfig::parse_over(
                helicopter_defaults(),
                Some("[rotor]\nblades = []\n"),
                None
            )
            .is_err()
        );
    }
}
