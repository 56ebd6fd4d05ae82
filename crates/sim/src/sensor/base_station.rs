//! The base-station magnetometer: a ground total-field sensor that records
//! the diurnal variation for correction.
//!
//! `diurnal_k = d(t_k) + n_k`, `n_k ~ N(0, σ²)` white (default σ = 0.01 nT,
//! a caesium or Overhauser base sensor averaged to the flight's sample rate).
//! The base is assumed close enough that the diurnal variation is the same
//! as at the aircraft (no spatial gradient of the external variation) and is
//! reported relative to its value at take-off, the usual convention of the
//! correction channel (spec `data-formats.md`: `diurnal`, nT).

use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::error::{Result, require_non_negative};
use crate::random::normal;

/// Base-station parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BaseStationConfig {
    /// White noise of the recorded channel, nT RMS. Default 0.01.
    pub noise_nt: f64,
}

impl Default for BaseStationConfig {
    fn default() -> Self {
        Self { noise_nt: 0.01 }
    }
}

impl BaseStationConfig {
    /// Check the values.
    pub fn validate(&self, p: &str) -> Result<()> {
        require_non_negative(&format!("{p}.noise_nt"), self.noise_nt)
    }

    /// The recorded channel for the true diurnal variation `d` (nT).
    pub fn measure(&self, d: &[f64], rng: &mut ChaCha8Rng) -> Vec<f64> {
        d.iter().map(|x| x + self.noise_nt * normal(rng)).collect()
    }
}
