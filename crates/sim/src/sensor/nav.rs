//! GNSS/INS navigation errors.
//!
//! Each recorded navigation quantity is the truth plus a time-correlated
//! error (first-order Gauss–Markov, [`crate::random::gauss_markov`]) plus
//! white noise:
//!
//! | quantity | correlated part (σ, τ) | white part | default meaning |
//! |---|---|---|---|
//! | north, east position | 0.5 m, 300 s | 0.1 m | single-frequency GNSS with SBAS |
//! | altitude | 1.0 m, 300 s | 0.2 m | vertical ≈ 2× horizontal |
//! | velocity N, E | — | 0.03 m/s | Doppler velocity |
//! | velocity down | — | 0.05 m/s | |
//! | roll, pitch | 0.03°, 60 s | 0.01° | tactical-grade AHRS/INS |
//! | yaw | 0.1°, 120 s | 0.02° | |
//!
//! The recorded position is converted to latitude/longitude with the local
//! flat-earth relations of [`aeromag_core::frames::Geodetic::offset_by`].
//! Spec `simulator.md`: "GNSS/INS: position, velocity and attitude with
//! realistic noise".

use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::error::{Result, require_non_negative, require_positive};
use crate::random::gauss_markov::gauss_markov;
use crate::trajectory::Trajectory;

/// Navigation error parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct NavConfig {
    /// Correlated horizontal position error, m RMS. Default 0.5.
    pub horizontal_sigma_m: f64,
    /// Its correlation time, s. Default 300.
    pub horizontal_tau_s: f64,
    /// White horizontal position noise, m RMS. Default 0.1.
    pub horizontal_white_m: f64,
    /// Correlated altitude error, m RMS. Default 1.0.
    pub vertical_sigma_m: f64,
    /// Its correlation time, s. Default 300.
    pub vertical_tau_s: f64,
    /// White altitude noise, m RMS. Default 0.2.
    pub vertical_white_m: f64,
    /// White horizontal velocity noise, m/s RMS. Default 0.03.
    pub velocity_white_m_s: f64,
    /// White vertical velocity noise, m/s RMS. Default 0.05.
    pub vertical_velocity_white_m_s: f64,
    /// Correlated roll and pitch error, deg RMS. Default 0.03.
    pub attitude_sigma_deg: f64,
    /// Its correlation time, s. Default 60.
    pub attitude_tau_s: f64,
    /// White roll and pitch noise, deg RMS. Default 0.01.
    pub attitude_white_deg: f64,
    /// Correlated yaw error, deg RMS. Default 0.1.
    pub heading_sigma_deg: f64,
    /// Its correlation time, s. Default 120.
    pub heading_tau_s: f64,
    /// White yaw noise, deg RMS. Default 0.02.
    pub heading_white_deg: f64,
}

impl Default for NavConfig {
    fn default() -> Self {
        Self {
            horizontal_sigma_m: 0.5,
            horizontal_tau_s: 300.0,
            horizontal_white_m: 0.1,
            vertical_sigma_m: 1.0,
            vertical_tau_s: 300.0,
            vertical_white_m: 0.2,
            velocity_white_m_s: 0.03,
            vertical_velocity_white_m_s: 0.05,
            attitude_sigma_deg: 0.03,
            attitude_tau_s: 60.0,
            attitude_white_deg: 0.01,
            heading_sigma_deg: 0.1,
            heading_tau_s: 120.0,
            heading_white_deg: 0.02,
        }
    }
}

/// Recorded navigation (local frame; angles in rad).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct NavReadings {
    /// North offset, m.
    pub north_m: Vec<f64>,
    /// East offset, m.
    pub east_m: Vec<f64>,
    /// Altitude, m.
    pub alt_m: Vec<f64>,
    /// Velocity north, east, down, m/s.
    pub vn: Vec<f64>,
    /// Velocity east, m/s.
    pub ve: Vec<f64>,
    /// Velocity down, m/s.
    pub vd: Vec<f64>,
    /// Roll, rad.
    pub roll: Vec<f64>,
    /// Pitch, rad.
    pub pitch: Vec<f64>,
    /// Yaw, rad (wrapped to (−π, π]).
    pub yaw: Vec<f64>,
}

impl NavConfig {
    /// Check the values.
    pub fn validate(&self, p: &str) -> Result<()> {
        for (n, v) in [
            ("horizontal_sigma_m", self.horizontal_sigma_m),
            ("horizontal_white_m", self.horizontal_white_m),
            ("vertical_sigma_m", self.vertical_sigma_m),
            ("vertical_white_m", self.vertical_white_m),
            ("velocity_white_m_s", self.velocity_white_m_s),
            (
                "vertical_velocity_white_m_s",
                self.vertical_velocity_white_m_s,
            ),
            ("attitude_sigma_deg", self.attitude_sigma_deg),
            ("attitude_white_deg", self.attitude_white_deg),
            ("heading_sigma_deg", self.heading_sigma_deg),
            ("heading_white_deg", self.heading_white_deg),
        ] {
            require_non_negative(&format!("{p}.{n}"), v)?;
        }
        for (n, v) in [
            ("horizontal_tau_s", self.horizontal_tau_s),
            ("vertical_tau_s", self.vertical_tau_s),
            ("attitude_tau_s", self.attitude_tau_s),
            ("heading_tau_s", self.heading_tau_s),
        ] {
            require_positive(&format!("{p}.{n}"), v)?;
        }
        Ok(())
    }

    /// Recorded navigation for the true trajectory.
    pub fn measure(&self, tr: &Trajectory, rng: &mut ChaCha8Rng) -> NavReadings {
        let n = tr.len();
        let dt = tr.dt_s;
        let mut err = |sigma: f64, tau: f64, white: f64| -> Vec<f64> {
            let c = gauss_markov(rng, n, dt, sigma, tau);
            let w = gauss_markov(rng, n, dt, white, 0.0);
            c.iter().zip(&w).map(|(a, b)| a + b).collect()
        };
        let add = |truth: &[f64], e: Vec<f64>| -> Vec<f64> {
            truth.iter().zip(&e).map(|(a, b)| a + b).collect()
        };
        let north_m = add(
            &tr.north_m,
            err(
                self.horizontal_sigma_m,
                self.horizontal_tau_s,
                self.horizontal_white_m,
            ),
        );
        let east_m = add(
            &tr.east_m,
            err(
                self.horizontal_sigma_m,
                self.horizontal_tau_s,
                self.horizontal_white_m,
            ),
        );
        let alt_m = add(
            &tr.alt_m,
            err(
                self.vertical_sigma_m,
                self.vertical_tau_s,
                self.vertical_white_m,
            ),
        );
        let vn = add(&tr.vn, err(0.0, 1.0, self.velocity_white_m_s));
        let ve = add(&tr.ve, err(0.0, 1.0, self.velocity_white_m_s));
        let vd = add(&tr.vd, err(0.0, 1.0, self.vertical_velocity_white_m_s));
        let r = |d: f64| d.to_radians();
        let roll = add(
            &tr.roll,
            err(
                r(self.attitude_sigma_deg),
                self.attitude_tau_s,
                r(self.attitude_white_deg),
            ),
        );
        let pitch = add(
            &tr.pitch,
            err(
                r(self.attitude_sigma_deg),
                self.attitude_tau_s,
                r(self.attitude_white_deg),
            ),
        );
        let yaw = add(
            &tr.yaw,
            err(
                r(self.heading_sigma_deg),
                self.heading_tau_s,
                r(self.heading_white_deg),
            ),
        )
        .into_iter()
        .map(aeromag_core::frames::attitude::wrap_pi)
        .collect();
        NavReadings {
            north_m,
            east_m,
            alt_m,
            vn,
            ve,
            vd,
            roll,
            pitch,
            yaw,
        }
    }
}
