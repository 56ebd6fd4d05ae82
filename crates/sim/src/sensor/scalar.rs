//! Scalar (total-field) magnetometer: an optically pumped caesium sensor in
//! the tail stinger.
//!
//! The reading at sample `k` is built in this order:
//!
//! ```text
//! x_k   = |B_ext + ΔB|_k + h(cos θ_k)                  exact modulus + heading error
//! y     = lag(x)   (τ dy/dt + y = x, exact for x linear between samples)
//! mag_k = y_k + n_k,          n_k ~ N(0, σ²),  σ = ρ √(f_s/2)
//! h(c)  = h₁ c + h₂ (2c² − 1),   c = cos θ = a·(B_ext + ΔB)/|B_ext + ΔB|
//! ```
//!
//! `a` is the sensor's optical axis in body axes; `h₁ cos θ + h₂ cos 2θ` is
//! the first two harmonics of the heading error of a split-beam caesium
//! sensor. The lag's exact contribution `y − x` is recorded as the truth
//! column `true_lag`: to first order it is `−τ dx/dt`, the `k·d|B0|/dt` term
//! that levelling recovers on survey data (spec `compensation.md`, "Survey
//! altitude"; seed `000_…` §9).
//!
//! Defaults: noise density 0.005 nT/√Hz (σ = 0.011 nT at 10 Hz, a Cs
//! sensor with its counter in a quiet installation); heading error
//! `h₁ = 0.05` nT, `h₂ = 0.02` nT about the axis `(1, 0, 1)/√2` (45° forward
//! and down); lag 0 s (calibration) and 0.1 s (survey).

use nalgebra::Vector3;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::error::{Result, invalid, require_finite, require_non_negative};
use crate::numerics::lag::lag_linear;
use crate::random::normal;

/// Parameters of the scalar magnetometer.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ScalarSensorConfig {
    /// Position in the body frame (tail stinger), m. Default (−9.5, 0, −0.6).
    pub position_m: [f64; 3],
    /// White-noise density, nT/√Hz. Default 0.005 (0.011 nT RMS at 10 Hz).
    pub noise_density_nt_per_rthz: f64,
    /// Optical axis in the body frame (normalised on use). Default (1, 0, 1).
    pub axis: [f64; 3],
    /// First heading-error harmonic `h₁`, nT. Default 0.05.
    pub heading_error_1_nt: f64,
    /// Second heading-error harmonic `h₂`, nT. Default 0.02.
    pub heading_error_2_nt: f64,
    /// Time constant of the output lag, s (0: none). Default 0 (calibration),
    /// 0.1 (survey).
    pub lag_s: f64,
}

impl Default for ScalarSensorConfig {
    fn default() -> Self {
        Self {
            position_m: [-9.5, 0.0, -0.6],
            noise_density_nt_per_rthz: 0.005,
            axis: [1.0, 0.0, 1.0],
            heading_error_1_nt: 0.05,
            heading_error_2_nt: 0.02,
            lag_s: 0.0,
        }
    }
}

/// The scalar readings and their truth decomposition (all nT).
#[derive(Debug, Clone, PartialEq)]
pub struct ScalarReadings {
    /// Recorded `mag`.
    pub mag: Vec<f64>,
    /// Heading error `h`.
    pub heading_error: Vec<f64>,
    /// Lag contribution `y − x`.
    pub lag: Vec<f64>,
    /// Noise `n`.
    pub noise: Vec<f64>,
}

impl ScalarSensorConfig {
    /// Check the values.
    pub fn validate(&self, p: &str) -> Result<()> {
        for (i, x) in self.position_m.iter().enumerate() {
            require_finite(&format!("{p}.position_m[{i}]"), *x)?;
        }
        require_non_negative(
            &format!("{p}.noise_density_nt_per_rthz"),
            self.noise_density_nt_per_rthz,
        )?;
        require_finite(&format!("{p}.heading_error_1_nt"), self.heading_error_1_nt)?;
        require_finite(&format!("{p}.heading_error_2_nt"), self.heading_error_2_nt)?;
        require_non_negative(&format!("{p}.lag_s"), self.lag_s)?;
        let a = Vector3::from(self.axis);
        if !(a.norm().is_finite() && a.norm() > 0.0) {
            return Err(invalid(
                format!("{p}.axis"),
                "must be a non-zero finite vector",
            ));
        }
        Ok(())
    }

    /// Readings for the total field at the sensor `b_total_nt` (body axes,
    /// nT) sampled at `dt_s`.
    pub fn measure(
        &self,
        b_total_nt: &[Vector3<f64>],
        dt_s: f64,
        rng: &mut ChaCha8Rng,
    ) -> ScalarReadings {
        let axis = Vector3::from(self.axis).normalize();
        let sigma = super::white_rms(self.noise_density_nt_per_rthz, 1.0 / dt_s);
        let mut x = Vec::with_capacity(b_total_nt.len());
        let mut heading_error = Vec::with_capacity(b_total_nt.len());
        for b in b_total_nt {
            let f = b.norm();
            let c = axis.dot(b) / f;
            let h = self.heading_error_1_nt * c + self.heading_error_2_nt * (2.0 * c * c - 1.0);
            heading_error.push(h);
            x.push(f + h);
        }
        let y = lag_linear(&x, dt_s, self.lag_s);
        let lag: Vec<f64> = y.iter().zip(&x).map(|(a, b)| a - b).collect();
        let noise: Vec<f64> = (0..y.len()).map(|_| sigma * normal(rng)).collect();
        let mag = y.iter().zip(&noise).map(|(a, n)| a + n).collect();
        ScalarReadings {
            mag,
            heading_error,
            lag,
            noise,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::{Stream, rng_for};

    #[test]
    fn decomposition_noise_level_and_lag() {
        let cfg = ScalarSensorConfig {
            lag_s: 0.2,
            ..Default::default()
        };
        let dt = 0.1;
        // Field modulus ramping at 2 nT/s.
        let b: Vec<Vector3<f64>> = (0..20_000)
            .map(|k| Vector3::new(0.0, 0.0, 50_000.0 + 2.0 * k as f64 * dt))
            .collect();
        let r = cfg.measure(&b, dt, &mut rng_for(1, Stream::ScalarNoise));
        for (k, bk) in b.iter().enumerate() {
            let recomposed = bk.norm() + r.heading_error[k] + r.lag[k] + r.noise[k];
            assert!((r.mag[k] - recomposed).abs() < 1e-9);
        }
        // On a steady ramp the lag is exactly −τ·rate.
        assert!(r.lag.iter().all(|l| (l + 0.2 * 2.0).abs() < 1e-9));
        // Field along +z, axis (1,0,1)/√2: cos θ = 1/√2, h = 0.05/√2 + 0.
        assert!((r.heading_error[0] - 0.05 / 2f64.sqrt()).abs() < 1e-12);
        let rms = (r.noise.iter().map(|n| n * n).sum::<f64>() / r.noise.len() as f64).sqrt();
        assert!((rms / (0.005 * 5f64.sqrt()) - 1.0).abs() < 0.03, "{rms}");
    }
}
