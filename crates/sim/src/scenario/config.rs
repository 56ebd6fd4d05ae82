//! Scenario files: the TOML configuration shared by the fixed-wing
//! scenarios, its defaults and its parsing.
//!
//! A scenario file may set any subset of the fields; everything else takes
//! the scenario's default (documented on each field). Parsing is two-pass:
//!
//! 1. the user's text is parsed into the configuration type with
//!    `deny_unknown_fields`, so that a typo or a wrong type is reported with
//!    the TOML parser's line and column;
//! 2. the user's tables are merged over the scenario's full default
//!    configuration (tables merge key by key, arrays and values replace), and
//!    the result is the configuration used. It is written back, with every
//!    default filled in, next to the simulated data.
//!
//! One special rule: a file that sets `anomaly.area` but not
//! `anomaly.gradient_rms_nt_per_100m` gets the area preset's gradient.

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use super::ScenarioKind;
use super::installation::{
    CALIBRATION_LOAD_CYCLING, Installation, sgl_currents, sgl_fluxgates, sgl_scalars,
};
use crate::environment::anomaly::{AnomalyArea, AnomalyConfig};
use crate::environment::diurnal::DiurnalConfig;
use crate::error::{Result, SimError, invalid, require_finite, require_positive};
use crate::platform::aircraft::AircraftConfig;
use crate::sensor::base_station::BaseStationConfig;
use crate::sensor::fluxgate::FluxgateConfig;
use crate::sensor::nav::NavConfig;
use crate::sensor::scalar::ScalarSensorConfig;
use crate::trajectory::{FlightPlan, KinematicsConfig, TurbulenceConfig};

/// Date, time, place and sampling of a flight.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FlightConfig {
    /// Date of the flight, `YYYY-MM-DD` (UTC). Default `2025-06-15`.
    pub date: String,
    /// Start time, seconds after 00:00 UTC; the `time` column starts here.
    /// Default 36 000 (10:00 UTC).
    pub start_time_utc_s: f64,
    /// Sample rate of every channel, Hz. Default 10.
    pub sample_rate_hz: f64,
    /// Latitude of the local origin, deg. Default 56.30 (calibration), 56.00
    /// (survey).
    pub origin_lat_deg: f64,
    /// Longitude of the local origin, deg. Default 37.60 (calibration), 38.00
    /// (survey).
    pub origin_lon_deg: f64,
    /// Height of the (flat) terrain above the WGS84 ellipsoid, m. Default 150.
    pub terrain_alt_m: f64,
}

impl Default for FlightConfig {
    fn default() -> Self {
        Self {
            date: "2025-06-15".into(),
            start_time_utc_s: 36_000.0,
            sample_rate_hz: 10.0,
            origin_lat_deg: 56.0,
            origin_lon_deg: 38.0,
            terrain_alt_m: 150.0,
        }
    }
}

/// Seconds in a day: [`FlightConfig::start_time_utc_s`] is at most this.
pub const DAY_S: f64 = 86_400.0;

impl FlightConfig {
    /// Check the values.
    pub fn validate(&self) -> Result<()> {
        aeromag_core::time::Date::parse(&self.date)
            .map_err(|e| invalid("flight.date", e.to_string()))?;
        // A time of day: a start of 1e300 s was passed on as a date
        // 300 digits long, without the key's name.
        if !(0.0..=DAY_S).contains(&self.start_time_utc_s) {
            return Err(invalid(
                "flight.start_time_utc_s",
                format!(
                    "must be seconds after 00:00 UTC of flight.date, 0 … {DAY_S} (another day: set flight.date)"
                ),
            ));
        }
        require_positive("flight.sample_rate_hz", self.sample_rate_hz)?;
        if self.sample_rate_hz > 10_000.0 {
            return Err(invalid("flight.sample_rate_hz", "must be ≤ 10 000 Hz"));
        }
        if !self.origin_lat_deg.is_finite() || self.origin_lat_deg.abs() >= 89.0 {
            return Err(invalid(
                "flight.origin_lat_deg",
                "must be within ±89° (the local frame is undefined at the poles)",
            ));
        }
        require_finite("flight.origin_lon_deg", self.origin_lon_deg)?;
        require_finite("flight.terrain_alt_m", self.terrain_alt_m)
    }
}

/// The flight pattern of a scenario (calibration box, survey lines).
pub trait Pattern: Serialize + DeserializeOwned + Clone + Default + std::fmt::Debug {
    /// Check the values.
    fn validate(&self, flight: &FlightConfig, kin: &KinematicsConfig) -> Result<()>;
    /// The flight plan in the local frame (origin at `flight.origin_*`).
    fn plan(&self, flight: &FlightConfig, kin: &KinematicsConfig) -> Result<FlightPlan>;
}

/// The configuration of a fixed-wing scenario with pattern `P`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
#[serde(bound(
    serialize = "P: Serialize",
    deserialize = "P: DeserializeOwned + Default"
))]
pub struct FixedWingConfig<P> {
    /// Seed of every random process (ChaCha8 streams). Default 1. Must be
    /// < 2⁶³ (TOML integers are signed 64-bit).
    pub seed: u64,
    /// The magnetometers and current loops: `stinger` (default) or `sgl`
    /// (an SGL-like multi-sensor installation with 14 current loops,
    /// applied to the defaults before the file's own tables; see
    /// [`super::installation`]).
    #[serde(skip_serializing_if = "Installation::is_stinger")]
    pub installation: Installation,
    /// Date, time, origin and sampling.
    pub flight: FlightConfig,
    /// The flight pattern.
    pub pattern: P,
    /// Aircraft performance and autopilot.
    pub kinematics: KinematicsConfig,
    /// Turbulence.
    pub turbulence: TurbulenceConfig,
    /// Crustal anomaly.
    pub anomaly: AnomalyConfig,
    /// Diurnal variation.
    pub diurnal: DiurnalConfig,
    /// The aircraft's magnetic parts.
    pub aircraft: AircraftConfig,
    /// Scalar magnetometer.
    pub scalar: ScalarSensorConfig,
    /// Fluxgate.
    pub fluxgate: FluxgateConfig,
    /// Extra scalar magnetometers (`[[extra_scalars]]` tables, each a
    /// [`ScalarSensorConfig`]; unset fields take that type's defaults — lag
    /// 0 s, the stinger position — so set `position_m`). The first is
    /// recorded as `mag_2`, the next `mag_3`, … Default none. See
    /// [`super::fixed_wing`] ("Extra sensors").
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub extra_scalars: Vec<ScalarSensorConfig>,
    /// Extra fluxgates (`[[extra_fluxgates]]` tables, each a
    /// [`FluxgateConfig`]), recorded as `flux_b_x/y/z`, `flux_c_…`, … (at
    /// most 25). Default none.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub extra_fluxgates: Vec<FluxgateConfig>,
    /// GNSS/INS.
    pub nav: NavConfig,
    /// Base-station magnetometer.
    pub base_station: BaseStationConfig,
}

impl<P: Default> Default for FixedWingConfig<P> {
    fn default() -> Self {
        Self {
            seed: 1,
            installation: Installation::Stinger,
            flight: FlightConfig::default(),
            pattern: P::default(),
            kinematics: KinematicsConfig::default(),
            turbulence: TurbulenceConfig::default(),
            anomaly: AnomalyConfig::default(),
            diurnal: DiurnalConfig::default(),
            aircraft: AircraftConfig::default(),
            scalar: ScalarSensorConfig::default(),
            fluxgate: FluxgateConfig::default(),
            extra_scalars: Vec::new(),
            extra_fluxgates: Vec::new(),
            nav: NavConfig::default(),
            base_station: BaseStationConfig::default(),
        }
    }
}

impl<P: Pattern> FixedWingConfig<P> {
    /// Check every value.
    pub fn validate(&self) -> Result<()> {
        if self.seed > i64::MAX as u64 {
            return Err(invalid(
                "seed",
                "must be < 2^63 (TOML integers are signed 64-bit)",
            ));
        }
        self.flight.validate()?;
        self.kinematics.validate("kinematics")?;
        self.pattern.validate(&self.flight, &self.kinematics)?;
        self.turbulence.validate("turbulence")?;
        self.anomaly.validate("anomaly")?;
        self.diurnal.validate("diurnal")?;
        self.aircraft.validate("aircraft")?;
        self.scalar.validate("scalar")?;
        self.fluxgate.validate("fluxgate")?;
        if self.extra_scalars.len() > MAX_EXTRA_SCALARS {
            return Err(invalid(
                "extra_scalars",
                format!("at most {MAX_EXTRA_SCALARS} extra scalar sensors"),
            ));
        }
        if self.extra_fluxgates.len() > MAX_EXTRA_FLUXGATES {
            return Err(invalid(
                "extra_fluxgates",
                format!("at most {MAX_EXTRA_FLUXGATES} extra fluxgates (flux_b … flux_z)"),
            ));
        }
        for (i, s) in self.extra_scalars.iter().enumerate() {
            let p = format!("extra_scalars[{i}]");
            s.validate(&p)?;
            check_lever_arm(&p, s.position_m)?;
        }
        for (i, f) in self.extra_fluxgates.iter().enumerate() {
            let p = format!("extra_fluxgates[{i}]");
            f.validate(&p)?;
            check_lever_arm(&p, f.position_m)?;
        }
        self.nav.validate("nav")?;
        self.base_station.validate("base_station")
    }

    /// Parse a scenario file over `defaults` (module docs); `seed` overrides
    /// the file's seed.
    pub fn parse_over(
        defaults: Self,
        kind: ScenarioKind,
        text: Option<&str>,
        seed: Option<u64>,
    ) -> Result<Self> {
        let mut cfg = match text {
            None => defaults,
            Some(text) => {
                // Pass 1: syntax, unknown fields and types, with line numbers.
                let _: Self = toml::from_str(text).map_err(|e| SimError::toml(text, &e))?;
                let mut user = parse_table(text)?;
                apply_area_preset(&mut user);
                let mut defaults = defaults;
                if user.get("installation").and_then(|v| v.as_str()) == Some("sgl") {
                    defaults.apply_installation(Installation::Sgl, kind);
                }
                // Pass 2: merge over the scenario defaults.
                let mut base =
                    toml::Table::try_from(&defaults).map_err(|e| SimError::Serialize {
                        what: "default scenario",
                        reason: e.to_string(),
                    })?;
                merge(&mut base, user);
                toml::Value::Table(base)
                    .try_into()
                    .map_err(|e: toml::de::Error| {
                        SimError::config(format!("{} scenario: {e}", kind.name()))
                    })?
            }
        };
        if let Some(s) = seed {
            cfg.seed = s;
        }
        cfg.validate()?;
        Ok(cfg)
    }

    /// Apply an installation's preset (the SGL-like sensors and currents;
    /// nothing for the stinger pair). On a calibration flight the crew
    /// cycles the switched equipment ([`CALIBRATION_LOAD_CYCLING`]).
    pub fn apply_installation(&mut self, installation: Installation, kind: ScenarioKind) {
        self.installation = installation;
        if installation == Installation::Sgl {
            self.extra_scalars = sgl_scalars();
            self.extra_fluxgates = sgl_fluxgates();
            let cycling = match kind {
                ScenarioKind::Calibration | ScenarioKind::CalibrationTruncated => {
                    CALIBRATION_LOAD_CYCLING
                }
                _ => 1.0,
            };
            self.aircraft.currents = sgl_currents()
                .into_iter()
                .map(|c| c.cycled(cycling))
                .collect();
        }
    }

    /// The configuration as TOML, every default filled in, with a header.
    pub fn to_toml(&self, kind: ScenarioKind) -> Result<String> {
        let body = toml::to_string(self).map_err(|e| SimError::Serialize {
            what: "scenario",
            reason: e.to_string(),
        })?;
        Ok(format!(
            "# aeromag-sim scenario `{}` (aeromag-sim {}), every default filled in.\n\
             # Re-running `aeromag simulate {} --config <this file>` reproduces the data.\n\n{body}",
            kind.name(),
            env!("CARGO_PKG_VERSION"),
            kind.name()
        ))
    }
}

/// Most extra scalar sensors (`mag_2` … `mag_99`).
pub const MAX_EXTRA_SCALARS: usize = 98;
/// Most extra fluxgates (`flux_b` … `flux_z`).
pub const MAX_EXTRA_FLUXGATES: usize = 25;
/// Longest lever arm of an extra sensor, m: the anomaly grid is sized on the
/// main sensors' tracks, and an extra sensor must lie well inside its
/// margin and its continuation levels.
pub const MAX_EXTRA_LEVER_ARM_M: f64 = 50.0;

fn check_lever_arm(p: &str, r: [f64; 3]) -> Result<()> {
    let len = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
    if len > MAX_EXTRA_LEVER_ARM_M {
        return Err(invalid(
            format!("{p}.position_m"),
            format!("must be within {MAX_EXTRA_LEVER_ARM_M} m of the body origin"),
        ));
    }
    Ok(())
}

/// The column letter of extra fluxgate `j` (0-based): `b`, `c`, …
pub fn extra_fluxgate_letter(j: usize) -> char {
    (b'b' + j as u8) as char
}

/// If `[anomaly]` sets `area` but not the gradient, insert the preset.
fn apply_area_preset(user: &mut toml::Table) {
    let Some(toml::Value::Table(an)) = user.get_mut("anomaly") else {
        return;
    };
    if an.contains_key("gradient_rms_nt_per_100m") {
        return;
    }
    let area = match an.get("area").and_then(|v| v.as_str()) {
        Some("quiet") => AnomalyArea::Quiet,
        Some("realistic") => AnomalyArea::Realistic,
        _ => return,
    };
    an.insert(
        "gradient_rms_nt_per_100m".into(),
        toml::Value::Float(area.gradient_rms_nt_per_100m()),
    );
}

/// Merge `over` into `base`: tables recursively, everything else replaced.
fn merge(base: &mut toml::Table, over: toml::Table) {
    for (k, v) in over {
        match (base.get_mut(&k), v) {
            (Some(toml::Value::Table(b)), toml::Value::Table(o)) => merge(b, o),
            (_, v) => {
                base.insert(k, v);
            }
        }
    }
}

/// Every number of a scenario file is finite: TOML's `nan` and `inf` are
/// refused, naming the key (`anomaly.depth_m`, `pattern.legs[2].heading_deg`),
/// before any field is used (a NaN swing amplitude or an infinite yaw
/// went through to NaN columns, written as data).
pub fn check_finite_numbers(table: &toml::Table) -> Result<()> {
    fn walk(v: &toml::Value, path: &str) -> Result<()> {
        match v {
            toml::Value::Float(x) if !x.is_finite() => {
                Err(invalid(path, format!("{x} is not a finite number")))
            }
            toml::Value::Array(items) => items
                .iter()
                .enumerate()
                .try_for_each(|(i, x)| walk(x, &format!("{path}[{i}]"))),
            toml::Value::Table(t) => t.iter().try_for_each(|(k, x)| walk(x, &key(path, k))),
            _ => Ok(()),
        }
    }
    fn key(path: &str, k: &str) -> String {
        if path.is_empty() {
            k.to_string()
        } else {
            format!("{path}.{k}")
        }
    }
    table.iter().try_for_each(|(k, v)| walk(v, k))
}

/// A scenario file's text as a TOML table (syntax errors with the parser's
/// line and column), its numbers checked finite ([`check_finite_numbers`]).
pub fn parse_table(text: &str) -> Result<toml::Table> {
    let table: toml::Table = toml::from_str(text).map_err(|e| SimError::toml(text, &e))?;
    check_finite_numbers(&table)?;
    Ok(table)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn merge_keeps_unset_fields_and_replaces_arrays() {
        let mut base: toml::Table =
            toml::from_str("a = 1\n[t]\nx = 1\ny = 2\nlist = [1, 2]\n").unwrap();
        let over: toml::Table = toml::from_str("[t]\ny = 5\nlist = [3]\n").unwrap();
        merge(&mut base, over);
        assert_eq!(base["a"].as_integer(), Some(1));
        assert_eq!(base["t"]["x"].as_integer(), Some(1));
        assert_eq!(base["t"]["y"].as_integer(), Some(5));
        assert_eq!(base["t"]["list"].as_array().unwrap().len(), 1);
    }

    #[test]
    fn area_preset_fills_the_gradient_only_when_absent() {
        let mut u: toml::Table = toml::from_str("[anomaly]\narea = \"realistic\"\n").unwrap();
        apply_area_preset(&mut u);
        assert_eq!(
            u["anomaly"]["gradient_rms_nt_per_100m"].as_float(),
            Some(3.0)
        );
        let mut u: toml::Table =
            toml::from_str("[anomaly]\narea = \"realistic\"\ngradient_rms_nt_per_100m = 1.5\n")
                .unwrap();
        apply_area_preset(&mut u);
        assert_eq!(
            u["anomaly"]["gradient_rms_nt_per_100m"].as_float(),
            Some(1.5)
        );
    }
}
