//! Atmospheric turbulence as smooth coloured noise in attitude and flight
//! path.
//!
//! Four independent stationary processes with the second-order spectrum
//! `S(f) ∝ 1/(1 + (2π f τ)²)²` (a Dryden-like shape; see
//! [`crate::random::gauss_markov::SmoothNoise`]) and RMS values set here are
//! added to the bank angle, the attitude-only pitch, the sideslip and the
//! flight-path angle. The bank disturbance turns the aircraft through the
//! coordinated-turn relation and the flight-path disturbance moves the
//! altitude, both countered by the guidance loops, so altitude and
//! cross-track wander like a real survey aircraft's (spec `simulator.md`:
//! "turbulence in attitude and altitude").

use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::error::{Result, require_non_negative, require_positive};
use crate::random::gauss_markov::SmoothNoise;

/// Turbulence intensities (RMS values) and correlation time.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TurbulenceConfig {
    /// RMS bank-angle disturbance, deg. Default 1.5 (survey at 100 m above
    /// ground, moderate convective turbulence), 0.3 (calibration at altitude).
    pub roll_deg: f64,
    /// RMS attitude-only pitch disturbance (angle of attack), deg. Default 0.5
    /// (survey), 0.1 (calibration).
    pub pitch_deg: f64,
    /// RMS sideslip (yaw) disturbance, deg. Default 0.5 (survey), 0.1
    /// (calibration).
    pub yaw_deg: f64,
    /// RMS flight-path-angle disturbance, deg (drives altitude wander).
    /// Default 0.6 (survey), 0.1 (calibration).
    pub flight_path_deg: f64,
    /// Correlation time constant of all four processes, s. Default 1.5.
    pub time_constant_s: f64,
}

impl Default for TurbulenceConfig {
    fn default() -> Self {
        Self::survey()
    }
}

impl TurbulenceConfig {
    /// Survey defaults (low level, moderate turbulence).
    pub fn survey() -> Self {
        Self {
            roll_deg: 1.5,
            pitch_deg: 0.5,
            yaw_deg: 0.5,
            flight_path_deg: 0.6,
            time_constant_s: 1.5,
        }
    }

    /// Calibration defaults (smooth air at altitude, light turbulence).
    pub fn calibration() -> Self {
        Self {
            roll_deg: 0.3,
            pitch_deg: 0.1,
            yaw_deg: 0.1,
            flight_path_deg: 0.1,
            time_constant_s: 1.5,
        }
    }

    /// Check the values.
    pub fn validate(&self, prefix: &str) -> Result<()> {
        for (name, v) in [
            ("roll_deg", self.roll_deg),
            ("pitch_deg", self.pitch_deg),
            ("yaw_deg", self.yaw_deg),
            ("flight_path_deg", self.flight_path_deg),
        ] {
            require_non_negative(&format!("{prefix}.{name}"), v)?;
        }
        require_positive(&format!("{prefix}.time_constant_s"), self.time_constant_s)
    }
}

/// The running turbulence generator.
#[derive(Debug, Clone)]
pub struct Turbulence {
    rng: ChaCha8Rng,
    procs: [SmoothNoise; 4],
}

impl Turbulence {
    /// Generator for step `dt_s` drawing from `rng`.
    pub fn new(cfg: &TurbulenceConfig, dt_s: f64, mut rng: ChaCha8Rng) -> Self {
        let tau = cfg.time_constant_s;
        let mk =
            |rng: &mut ChaCha8Rng, deg: f64| SmoothNoise::new(rng, dt_s, deg.to_radians(), tau);
        let procs = [
            mk(&mut rng, cfg.roll_deg),
            mk(&mut rng, cfg.pitch_deg),
            mk(&mut rng, cfg.yaw_deg),
            mk(&mut rng, cfg.flight_path_deg),
        ];
        Self { rng, procs }
    }

    /// Current `(bank, pitch, sideslip, flight path)` disturbances, rad.
    pub fn value(&self) -> [f64; 4] {
        [
            self.procs[0].value(),
            self.procs[1].value(),
            self.procs[2].value(),
            self.procs[3].value(),
        ]
    }

    /// Advance one step.
    pub fn step(&mut self) {
        for p in &mut self.procs {
            p.step(&mut self.rng);
        }
    }
}
