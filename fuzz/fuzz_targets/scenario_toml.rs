//! Scenario readers: fixed-wing (calibration, survey), helicopter, pod,
//! gradiometer and EM scenario files, parsed over their defaults and
//! validated (no simulation is run).
#![no_main]

use aeromag_gradiometry::config::GradiometerConfig;
use aeromag_sim::scenario::config::FixedWingConfig;
use aeromag_sim::scenario::helicopter::{HelicopterConfig, helicopter_defaults};
use aeromag_sim::scenario::pod::PodConfig;
use aeromag_sim::scenario::{ScenarioKind, calibration_defaults, survey_defaults};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let t = Some(text);
    let _ = FixedWingConfig::parse_over(
        calibration_defaults(false),
        ScenarioKind::Calibration,
        t,
        None,
    );
    let _ = FixedWingConfig::parse_over(survey_defaults(), ScenarioKind::Survey, t, None);
    let _ = HelicopterConfig::parse_over(helicopter_defaults(), t, None);
    let _ = PodConfig::parse_over(t, None);
    let _ = GradiometerConfig::from_toml(text);
    let _ = aeromag::em::parse_config(t, "fuzz.toml");
});
