//! Scenarios: what to fly, where, with which aircraft and sensors — and the
//! single entry point [`simulate`].
//!
//! | scenario | pattern | default area |
//! |---|---|---|
//! | `calibration` | full four-heading box with roll/pitch/yaw manoeuvres at 3000 m ([`calibration`]) | quiet |
//! | `calibration_truncated` | the truncated box (≈ 73 % of the time) | quiet |
//! | `survey` | 20 lines + 5 tie lines at 100 m above ground, turbulence ([`survey`]) | realistic gradients, two dipoles |
//! | `helicopter` | the box at 40 m/s, 150 m above ground, 100 Hz, fuselage + main rotor ([`helicopter`]) | realistic |
//! | `pod` | straight headings with pitch/roll/yaw manoeuvres, pod on a 40 m cable under a dipole-array helicopter, 20 Hz ([`pod`]; its own flat configuration [`pod::PodConfig`]) | gradients 5.91 / −25.91 nT/km |
//!
//! All fixed-wing scenarios share the configuration of [`config`] and the
//! pipeline of [`fixed_wing`] (the same aircraft and sensors; only the
//! pattern and a few defaults differ: speed 90 vs 70 m/s, turbulence,
//! anomaly area, origin, scalar-sensor lag 0 vs 0.1 s).
//!
//! Later scenarios (helicopter, pod, em, gradiometer) add a variant to
//! [`ScenarioKind`] and their own module.

pub mod calibration;
pub mod config;
pub mod fixed_wing;
pub mod helicopter;
pub mod installation;
pub mod pod;
pub mod survey;

use crate::environment::anomaly::{AnomalyArea, AnomalyConfig};
use crate::environment::sources::default_survey_sources;
use crate::error::Result;
use crate::output::Simulation;
use crate::sensor::scalar::ScalarSensorConfig;
use crate::trajectory::{KinematicsConfig, TurbulenceConfig};
use calibration::CalibrationPattern;
use config::{FixedWingConfig, FlightConfig};
use survey::SurveyPattern;

/// The scenarios the simulator can run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ScenarioKind {
    /// Full calibration box.
    Calibration,
    /// Truncated calibration box (seed `000_…` fig. 2b).
    CalibrationTruncated,
    /// Survey lines and tie lines.
    Survey,
    /// Helicopter with a main rotor ([`helicopter`]).
    Helicopter,
    /// Towed magnetometer pod under a helicopter ([`pod`]).
    Pod,
}

impl ScenarioKind {
    /// Every scenario.
    pub const ALL: [ScenarioKind; 5] = [
        Self::Calibration,
        Self::CalibrationTruncated,
        Self::Survey,
        Self::Helicopter,
        Self::Pod,
    ];

    /// The name used on the command line and in file names.
    pub fn name(self) -> &'static str {
        match self {
            Self::Calibration => "calibration",
            Self::CalibrationTruncated => "calibration_truncated",
            Self::Survey => "survey",
            Self::Helicopter => "helicopter",
            Self::Pod => "pod",
        }
    }
}

impl std::fmt::Display for ScenarioKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for ScenarioKind {
    type Err = crate::error::SimError;

    /// Parse a scenario name (`calibration`, `calibration_truncated` or
    /// `calibration-truncated`, `survey`, `helicopter`, `pod`).
    fn from_str(s: &str) -> Result<Self> {
        let norm = s.trim().to_ascii_lowercase().replace('-', "_");
        Self::ALL
            .into_iter()
            .find(|k| k.name() == norm)
            .ok_or_else(|| {
                crate::error::invalid(
                    "scenario",
                    format!(
                        "unknown scenario `{s}`; known: {}",
                        Self::ALL.map(|k| k.name()).join(", ")
                    ),
                )
            })
    }
}

/// The default configuration of a calibration scenario.
pub fn calibration_defaults(truncated: bool) -> FixedWingConfig<CalibrationPattern> {
    FixedWingConfig {
        flight: FlightConfig {
            origin_lat_deg: 56.30,
            origin_lon_deg: 37.60,
            ..FlightConfig::default()
        },
        pattern: if truncated {
            CalibrationPattern::truncated()
        } else {
            CalibrationPattern::full()
        },
        kinematics: KinematicsConfig {
            speed_m_s: 90.0,
            ..KinematicsConfig::default()
        },
        turbulence: TurbulenceConfig::calibration(),
        anomaly: AnomalyConfig::with_area(AnomalyArea::Quiet),
        scalar: ScalarSensorConfig {
            lag_s: 0.0,
            ..ScalarSensorConfig::default()
        },
        ..FixedWingConfig::default()
    }
}

/// The default configuration of the survey scenario.
pub fn survey_defaults() -> FixedWingConfig<SurveyPattern> {
    FixedWingConfig {
        flight: FlightConfig {
            origin_lat_deg: 56.00,
            origin_lon_deg: 38.00,
            ..FlightConfig::default()
        },
        pattern: SurveyPattern::default(),
        kinematics: KinematicsConfig {
            speed_m_s: 70.0,
            ..KinematicsConfig::default()
        },
        turbulence: TurbulenceConfig::survey(),
        anomaly: AnomalyConfig {
            dipoles: default_survey_sources(),
            ..AnomalyConfig::with_area(AnomalyArea::Realistic)
        },
        scalar: ScalarSensorConfig {
            lag_s: 0.1,
            ..ScalarSensorConfig::default()
        },
        ..FixedWingConfig::default()
    }
}

/// Run scenario `kind`.
///
/// `config_toml` is the text of a scenario file (any subset of the fields;
/// the rest take the scenario's defaults), `seed` overrides the file's seed.
/// Errors: a scenario file that does not parse or names an unknown field
/// ([`crate::SimError::ConfigParse`], with line and column), an invalid value
/// ([`crate::SimError::InvalidConfig`]), a date outside IGRF-14, a plan that
/// cannot be flown.
pub fn simulate(
    kind: ScenarioKind,
    config_toml: Option<&str>,
    seed: Option<u64>,
) -> Result<Simulation> {
    let sim = match kind {
        ScenarioKind::Calibration | ScenarioKind::CalibrationTruncated => {
            let defaults = calibration_defaults(kind == ScenarioKind::CalibrationTruncated);
            let cfg = FixedWingConfig::parse_over(defaults, kind, config_toml, seed)?;
            fixed_wing::run(&cfg, kind)
        }
        ScenarioKind::Survey => {
            let cfg = FixedWingConfig::parse_over(survey_defaults(), kind, config_toml, seed)?;
            fixed_wing::run(&cfg, kind)
        }
        ScenarioKind::Helicopter => {
            let cfg = helicopter::HelicopterConfig::parse_over(
                helicopter::helicopter_defaults(),
                config_toml,
                seed,
            )?;
            helicopter::run(&cfg)
        }
        ScenarioKind::Pod => pod::run(&pod::PodConfig::parse_over(config_toml, seed)?),
    }?;
    sim.check_finite()?;
    Ok(sim)
}

/// The default scenario file of `kind` (every field, TOML), a starting point
/// for users.
pub fn default_config_toml(kind: ScenarioKind) -> Result<String> {
    match kind {
        ScenarioKind::Calibration | ScenarioKind::CalibrationTruncated => {
            calibration_defaults(kind == ScenarioKind::CalibrationTruncated)
                .to_toml(kind)
                .map(with_installation_choice)
        }
        ScenarioKind::Survey => survey_defaults()
            .to_toml(kind)
            .map(with_installation_choice),
        ScenarioKind::Helicopter => helicopter::helicopter_defaults().to_toml(),
        ScenarioKind::Pod => pod::PodConfig::default().to_toml(),
    }
}

/// A fixed-wing default scenario file with the installation key, which the
/// default (`stinger`) leaves out of the file, shown as a comment before
/// `seed`: the one key a user could not see to change.
fn with_installation_choice(text: String) -> String {
    const CHOICE: &str = "# installation = \"stinger\" (the default: the stinger pair mag, flux_x/y/z) or \"sgl\"\n\
                          # (an SGL-like installation: mag_1_uc … mag_5_uc, flux_a … flux_d and 14 current loops)\n";
    match text.find("\nseed = ") {
        Some(k) => format!("{}{CHOICE}{}", &text[..=k], &text[k + 1..]),
        None => text,
    }
}
