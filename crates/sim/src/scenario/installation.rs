//! Magnetometer installations of the fixed-wing scenarios: the stinger
//! pair (default) or an SGL-like multi-sensor installation with on-board
//! current loops, and the column names each uses.
//!
//! `installation = "sgl"` in a scenario file (calibration, survey) applies
//! [`sgl_preset`] to the scenario's defaults before the file's own tables
//! are merged, so a file may still set `extra_scalars`,
//! `extra_fluxgates` or `aircraft.currents` itself.
//!
//! ## The SGL-like installation
//!
//! After the fixed-wing aircraft Signal Geophysics flies for MagNav.jl's
//! data: a tail stinger and four cabin scalar magnetometers, four
//! fluxgates, and 14 recorded currents (SGL's channel names).
//!
//! * Scalar sensors (body frame, m): `mag_1_uc` the stinger at
//!   (−9.5, 0, −0.6); cabin `mag_2_uc` (−2.0, 0, −0.3), `mag_3_uc`
//!   (−1.0, −0.4, −0.3), `mag_4_uc` (0.5, 0.4, −0.3), `mag_5_uc`
//!   (1.5, 0, −0.4).
//! * Fluxgates: `flux_a` at the stinger root (−8.0, 0, −0.5); `flux_b`
//!   (−2.0, 0.3, −0.3), `flux_c` (0, −0.3, −0.3), `flux_d` (1.5, 0.3, −0.4).
//! * Current loops ([`sgl_currents`]; recorded as `cur_<name>`): the strobe
//!   lights' wiring (`strb`, flashes of 0.15 s every 1.2 s), the flap
//!   motor (`flap`, 10 s runs with 1.5 s ramps, 40 per hour; its field lags
//!   by 0.3 s), the fuel pump (`tank`, on 40 % of a 45 s cycle), the air
//!   conditioning (`ac_hi`, `ac_lo`, fan levels; `ac_hi`'s field lags by
//!   0.5 s), three servos (`srvo_o`, `srvo_m`, `srvo_i`, 0.3 Hz activity),
//!   the heater (`heat`, on and off, field lag 0.8 s), the transmitter
//!   (`com_1`), and bus and battery currents (`acpwr`, `outpwr`, `bat_1`,
//!   `bat_2`: slow load changes, wired far from the sensors, so that they
//!   barely matter: a real flight records channels that do not).
//! * On a calibration flight the crew cycles the switched equipment
//!   ([`CALIBRATION_LOAD_CYCLING`] times the survey's switching rate), as
//!   compensation procedures for electrical loads ask: a load's three
//!   direction terms are determined only when it switches at several
//!   headings, and a 10-minute box at the survey's rates switches the
//!   heater or the flap on one or two of its four legs.
//!
//! Columns follow the SGL HDF5 layout: the stinger sensor is `mag_1_uc`
//! (not `mag`), the cabin sensors `mag_2_uc` … `mag_5_uc`, the fluxgates
//! `flux_a_x` … `flux_d_z`; truth per scalar sensor `k` = 1 … 5:
//! `true_interf_k`, `true_external_k` and `true_interf_current_k` (the
//! currents' part of the interference, projected on the external field).
//! [`sgl_name`] maps the stinger installation's names onto these.

use serde::{Deserialize, Serialize};

use crate::platform::aircraft::{CurrentLoop, CurrentPattern};
use crate::sensor::fluxgate::FluxgateConfig;
use crate::sensor::scalar::ScalarSensorConfig;

/// How much more often the SGL-like installation's switched equipment
/// (telegraph loads, flap runs, fan levels) switches on a calibration
/// flight than on a survey ([`CurrentLoop::cycled`]).
pub const CALIBRATION_LOAD_CYCLING: f64 = 3.0;

/// Which magnetometers the aircraft carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Installation {
    /// The stinger pair (`mag`, `flux_x/y/z`) and whatever extra sensors
    /// the file adds.
    #[default]
    Stinger,
    /// The SGL-like installation (module docs).
    Sgl,
}

impl Installation {
    /// True for the default.
    pub fn is_stinger(&self) -> bool {
        *self == Installation::Stinger
    }
}

/// The cabin scalar sensors of the SGL-like installation (`mag_2_uc` …).
pub fn sgl_scalars() -> Vec<ScalarSensorConfig> {
    [
        [-2.0, 0.0, -0.3],
        [-1.0, -0.4, -0.3],
        [0.5, 0.4, -0.3],
        [1.5, 0.0, -0.4],
    ]
    .into_iter()
    .map(|p| ScalarSensorConfig {
        position_m: p,
        ..ScalarSensorConfig::default()
    })
    .collect()
}

/// The cabin fluxgates of the SGL-like installation (`flux_b` … `flux_d`).
pub fn sgl_fluxgates() -> Vec<FluxgateConfig> {
    [[-2.0, 0.3, -0.3], [0.0, -0.3, -0.3], [1.5, 0.3, -0.4]]
        .into_iter()
        .map(|p| FluxgateConfig {
            position_m: p,
            ..FluxgateConfig::default()
        })
        .collect()
}

/// A loop; `mean`, `switched` and `fluct` in A, `noise` the channel's
/// white noise (A RMS).
#[allow(clippy::too_many_arguments)]
fn wire(
    name: &str,
    position_m: [f64; 3],
    normal: [f64; 3],
    area_m2: f64,
    mean_a: f64,
    switched_a: f64,
    (fluctuation_a, fluctuation_tau_s): (f64, f64),
    channel_noise_a: f64,
    pattern: CurrentPattern,
    field_lag_s: f64,
) -> CurrentLoop {
    CurrentLoop {
        name: name.into(),
        position_m,
        normal,
        area_m2,
        mean_a,
        switched_a,
        switches_per_hour: 20.0,
        fluctuation_a,
        fluctuation_tau_s,
        channel_noise_a,
        pattern,
        field_lag_s,
    }
}

/// The 14 current loops of the SGL-like installation (module docs): one
/// row per loop (name, position m, normal, area m², mean A, switched A,
/// fluctuation (A, s), channel noise A, pattern, field lag s).
#[rustfmt::skip]
pub fn sgl_currents() -> Vec<CurrentLoop> {
    use CurrentPattern::*;
    let servo = Servo { bandwidth_hz: 0.3 };
    let slow = (0.5, 30.0);
    vec![
        wire("com_1", [-0.5, 0.0, -0.6], [0.0, 0.0, 1.0], 0.02, 0.5, 3.0, slow, 0.01, Telegraph, 0.0),
        wire("ac_hi", [-2.6, 0.4, 0.0], [0.3, 0.0, 1.0], 0.06, 1.0, 15.0, slow, 0.03, Levels { levels: vec![0.0, 0.5, 1.0], changes_per_hour: 20.0 }, 0.5),
        wire("ac_lo", [-2.7, -0.4, 0.0], [0.0, 0.3, 1.0], 0.03, 0.5, 8.0, slow, 0.02, Levels { levels: vec![0.3, 0.6, 1.0], changes_per_hour: 12.0 }, 0.0),
        wire("tank", [-1.0, -0.8, 0.6], [0.0, 1.0, 0.2], 0.05, 0.2, 6.0, slow, 0.02, Cycle { period_s: 45.0, duty: 0.4 }, 0.0),
        wire("flap", [0.5, -1.2, 0.3], [1.0, 0.2, 0.3], 0.08, 0.0, 12.0, (0.05, 5.0), 0.03, Runs { runs_per_hour: 40.0, run_s: 10.0, ramp_s: 1.5 }, 0.3),
        wire("strb", [0.0, 0.6, -0.2], [0.0, 0.3, 1.0], 0.03, 0.0, 5.0, (0.02, 5.0), 0.015, Strobe { period_s: 1.2, pulse_s: 0.15 }, 0.0),
        wire("srvo_o", [-1.8, -0.3, -0.5], [1.0, 0.0, 0.0], 0.02, 1.0, 2.0, (0.0, 1.0), 0.01, servo.clone(), 0.0),
        wire("srvo_m", [-1.8, 0.0, -0.5], [0.0, 1.0, 0.0], 0.02, 1.0, 2.0, (0.0, 1.0), 0.01, servo.clone(), 0.0),
        wire("srvo_i", [-1.8, 0.3, -0.5], [0.0, 0.0, 1.0], 0.02, 1.0, 2.0, (0.0, 1.0), 0.01, servo, 0.0),
        wire("heat", [1.2, 0.0, 0.2], [0.0, 0.0, 1.0], 0.04, 0.0, 10.0, slow, 0.03, Telegraph, 0.8),
        wire("acpwr", [4.0, 0.0, 0.5], [0.0, 0.0, 1.0], 0.002, 20.0, 0.0, (3.0, 60.0), 0.05, Telegraph, 0.0),
        wire("outpwr", [4.0, 0.5, 0.5], [1.0, 0.0, 0.0], 0.002, 15.0, 0.0, (2.0, 60.0), 0.05, Telegraph, 0.0),
        wire("bat_1", [-4.5, 0.3, 0.3], [0.0, 1.0, 0.0], 0.002, 10.0, 0.0, (1.0, 120.0), 0.05, Telegraph, 0.0),
        wire("bat_2", [-4.5, -0.3, 0.3], [0.0, 1.0, 0.0], 0.002, 10.0, 0.0, (1.0, 120.0), 0.05, Telegraph, 0.0),
    ]
}

/// Pairs of (stinger installation's name, SGL name) renamed one for one.
const RENAMED: [(&str, &str); 10] = [
    ("mag", "mag_1_uc"),
    ("flux_x", "flux_a_x"),
    ("flux_y", "flux_a_y"),
    ("flux_z", "flux_a_z"),
    ("true_interf", "true_interf_1"),
    ("true_external", "true_external_1"),
    ("true_interf_current", "true_interf_current_1"),
    ("true_flux_x", "true_flux_a_x"),
    ("true_flux_y", "true_flux_a_y"),
    ("true_flux_z", "true_flux_a_z"),
];

/// A cabin scalar sensor's column `mag_<k>` (k ≥ 2).
fn cabin_index(name: &str) -> Option<&str> {
    let k = name.strip_prefix("mag_")?;
    (!k.is_empty() && k.bytes().all(|b| b.is_ascii_digit())).then_some(k)
}

/// The SGL installation's name of a stinger-installation column (`mag` →
/// `mag_1_uc`, `mag_3` → `mag_3_uc`, `flux_x` → `flux_a_x`, …), or the
/// name itself when it does not change.
pub fn sgl_name(name: &str) -> String {
    if let Some((_, s)) = RENAMED.iter().find(|(a, _)| *a == name) {
        return (*s).to_string();
    }
    match cabin_index(name) {
        Some(k) => format!("mag_{k}_uc"),
        None => name.to_string(),
    }
}

/// The inverse of [`sgl_name`] for the names it changes (`None` for the
/// others).
pub fn stinger_name(sgl: &str) -> Option<String> {
    if let Some((a, _)) = RENAMED.iter().find(|(_, s)| *s == sgl) {
        return Some((*a).to_string());
    }
    let k = sgl.strip_prefix("mag_")?.strip_suffix("_uc")?;
    cabin_index(&format!("mag_{k}")).map(|k| format!("mag_{k}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_map_both_ways() {
        for (a, s) in [
            ("mag", "mag_1_uc"),
            ("mag_4", "mag_4_uc"),
            ("flux_y", "flux_a_y"),
            ("true_external", "true_external_1"),
            ("true_flux_z", "true_flux_a_z"),
        ] {
            assert_eq!(sgl_name(a), s);
            assert_eq!(stinger_name(s).as_deref(), Some(a));
        }
        for same in ["time", "flux_b_x", "cur_strb", "true_interf_3", "mag_x"] {
            assert_eq!(sgl_name(same), same);
        }
        assert_eq!(stinger_name("flux_b_x"), None);
        assert_eq!(stinger_name("mag_x_uc"), None);
    }

    #[test]
    fn the_preset_is_valid_and_sgl_sized() {
        let aircraft = crate::platform::aircraft::AircraftConfig {
            currents: sgl_currents(),
            ..Default::default()
        };
        assert_eq!(aircraft.currents.len(), 14);
        aircraft.validate("aircraft").unwrap();
        assert_eq!(sgl_scalars().len() + 1, 5);
        assert_eq!(sgl_fluxgates().len() + 1, 4);
    }
}
