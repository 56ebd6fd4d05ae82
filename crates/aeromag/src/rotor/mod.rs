//! Helicopter main-rotor interference on flights (spec `helicopter.md`
//! part A, seed `000_…` ch. 3; algorithms in
//! [`aeromag_compensation::rotor`]).
//!
//! - [`fit_rotor`]: the physical per-blade model (magnetisation along and
//!   across the blade, eddy currents; the dipole integral along each blade)
//!   with the slowly varying coning and tip-path-plane tilt, fitted on a
//!   flight → [`RotorFitResult`] with the [`RotorModelFile`];
//! - [`RotorModelFile`] as a [`Compensator`](crate::Compensator): the phase
//!   from its channel, or estimated and aligned with the model; the slow
//!   angles tracked with the parameters fixed; output `rotor_interf`,
//!   `mag_comp`, `rotor_flag`;
//! - a tail rotor geared to the main rotor ([`TailRotor`], with a phase
//!   channel) is fitted jointly with it when the options name one;
//! - the rotor geometry is the user's ([`RotorGeometry`]) or a named
//!   [`RotorPreset`]: nothing defaults silently to the simulator's
//!   helicopter.

mod apply;
mod columns;
mod fit;

pub use aeromag_compensation::rotor::model_file::{
    PhaseSource, ROTOR_KIND, RotorModelFile, TailModel,
};
pub use aeromag_compensation::rotor::{FlapAngles, RotorGeometry, TailRotor};
pub use apply::ROTOR_OUTPUT;
pub use columns::{MAX_STEP_DEVIATION, PHASE_GLITCH_DEG, SPIKE_SIGMAS};
pub use fit::{
    MIN_EXPLAINED_VARIANCE, PhaseChoice, RotorChoices, RotorFitResult, RotorOptions, fit_rotor,
};

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::str::FromStr;

/// Shortest record processed between gaps, s.
pub const MIN_SEGMENT_S: f64 = 10.0;

/// Named rotor installations whose geometry is known.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum RotorPreset {
    /// The helicopter of aeromag's simulator (`aeromag simulate
    /// helicopter`): hub (0, 0, −2.6) m, nose-boom sensor (5, 0, 0.6) m,
    /// blades magnetised from 0.8 to 7.5 m, 4 blades, nominal coning 4° and
    /// longitudinal tilt −1.5°.
    AeromagSimHelicopter,
}

impl RotorPreset {
    /// Every preset.
    pub const ALL: [RotorPreset; 1] = [RotorPreset::AeromagSimHelicopter];

    /// Its name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            RotorPreset::AeromagSimHelicopter => "aeromag-sim-helicopter",
        }
    }

    /// Rotor and sensor geometry.
    pub fn geometry(self) -> RotorGeometry {
        match self {
            RotorPreset::AeromagSimHelicopter => {
                aeromag_compensation::rotor::study::scenario_geometry()
            }
        }
    }

    /// Its tail rotor seen from the sensor of [`Self::geometry`]: the
    /// defaults of the simulator's `[tail_rotor]` table (hub (−12.7, −1.0,
    /// −2.4) m, blades 0.3–1.95 m, 3 blades, turning about −y with azimuth 0
    /// up, geared 4.37:1, cone 1°).
    pub fn tail_rotor(self) -> TailRotor {
        match self {
            RotorPreset::AeromagSimHelicopter => {
                aeromag_compensation::rotor::study::scenario_tail_rotor(self.geometry().sensor_m)
            }
        }
    }

    /// Nominal cone angles (the start of the slowly varying estimate).
    pub fn nominal_angles(self) -> FlapAngles {
        match self {
            RotorPreset::AeromagSimHelicopter => {
                aeromag_compensation::rotor::study::nominal_angles()
            }
        }
    }
}

impl std::fmt::Display for RotorPreset {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for RotorPreset {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        RotorPreset::ALL
            .into_iter()
            .find(|p| p.name() == s.trim())
            .ok_or_else(|| {
                Error::bad_input(format!(
                    "rotor preset `{s}`: known presets are {}",
                    RotorPreset::ALL.map(|p| p.name()).join(", ")
                ))
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_have_names_and_valid_geometry() {
        for p in RotorPreset::ALL {
            assert_eq!(p.name().parse::<RotorPreset>().unwrap(), p);
            p.geometry().validate().unwrap();
            p.tail_rotor().validate().unwrap();
        }
        assert!("nosuch".parse::<RotorPreset>().unwrap_err().is_bad_input());
    }
}
