//! Three-stage calibration and its run-time application (seed `001_…`
//! part II, eqs. 5–6; spec `em-positioning.md`, "Calibration in three
//! stages").
//!
//! 1. [`linear_polarisation`]: detection phases and the imaginary couplings
//!    that make the field linearly polarised (no external information).
//! 2. [`transmitter_geometry`]: symmetric real transmitter distortion `S`,
//!    effective moments `M' = (I + S) M`, from known ranges and directions.
//! 3. [`attitude`]: small rotation `Q` from a point of known attitude.
//!
//! At run time ([`Calibration::locate`]) the stages are applied in the same
//! order: stage 1 gives the real field matrix, positioning uses `M'`, and
//! the rotation is corrected to `Q R'`. [`three_stage`] fits all three in
//! order; [`file`](mod@file) is the versioned JSON file of the command line.

pub mod attitude;
pub mod file;
pub mod linear_polarisation;
pub mod three_stage;
pub mod transmitter_geometry;

pub use attitude::fit_attitude_correction;
pub use file::{CALIBRATION_FORMAT, CALIBRATION_VERSION, CalibrationFile, FitCounts};
pub use linear_polarisation::{PolarisationCalibration, uncalibrated};
pub use three_stage::KnownPoints;
pub use transmitter_geometry::fit_transmitter_geometry;

use crate::detection::Complex64;
use crate::positioning::{Hemisphere, PolishOptions, Pose, closed_form, polish};
use crate::{EmError, Result};
use nalgebra::Matrix3;

/// The calibration file: all three stages.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Calibration {
    /// Stage 1: linear-polarisation reduction.
    pub polarisation: PolarisationCalibration,
    /// Stage 2: symmetric transmitter distortion `S` (dimensionless).
    pub transmitter_s: Matrix3<f64>,
    /// Stage 3: attitude correction `Q` (rotation).
    pub attitude_q: Matrix3<f64>,
}

impl Default for Calibration {
    /// The identity calibration (no correction).
    fn default() -> Self {
        Self {
            polarisation: PolarisationCalibration::default(),
            transmitter_s: Matrix3::zeros(),
            attitude_q: Matrix3::identity(),
        }
    }
}

/// Largest plausible transmitter distortion `|S|` (Frobenius norm,
/// dimensionless). Stage 2 corrects a transmitter whose effective moments
/// differ from the nominal ones by a few per cent: the simulated scenario
/// (`transmitter_distortion` 0.05, seeds 1–10, starts 0/150/300/450 s,
/// 40 records) fits `|S|` from 0.030 to 0.060. The bound is 8× that.
/// KNOWN positions in km, cm or ft, or moments ×1000, gave 1.7 to
/// 2.8·10¹⁰; swapped channel names 1.14.
pub const MAX_TRANSMITTER_S: f64 = 0.5;

/// Largest plausible attitude correction `Q`, deg (rotation angle). Stage
/// 3 corrects a small mounting error: on the same 40 simulated records
/// the fitted `Q` turns by 0.003° to 0.051°; the bound is 100× that and
/// above any mounting error of a bird (a few degrees). Swapped x/y
/// channels gave 113.8° and 153°, moments of the wrong sign 175°, KNOWN
/// attitudes in radians 10.7°.
pub const MAX_ATTITUDE_Q_DEG: f64 = 5.0;

/// One located epoch.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Located {
    /// Calibrated pose.
    pub pose: Pose,
    /// Polarisation ratio per frequency after stage 1 (dimensionless).
    pub polarisation_ratio: [f64; 3],
    /// RMS relative residual of the LM polish (dimensionless).
    pub rms_residual: f64,
}

impl Calibration {
    /// Serialise to JSON.
    pub fn to_json(&self) -> Result<String> {
        serde_json::to_string_pretty(self).map_err(|e| EmError::InvalidData {
            reason: e.to_string(),
        })
    }

    /// Read from JSON.
    pub fn from_json(s: &str) -> Result<Self> {
        serde_json::from_str(s).map_err(|e| EmError::InvalidData {
            reason: e.to_string(),
        })
    }

    /// The corrections beyond [`MAX_TRANSMITTER_S`] and
    /// [`MAX_ATTITUDE_Q_DEG`], described with their likely causes, or
    /// `None` when both are within the bounds (or not finite: `None` too,
    /// the finiteness is checked elsewhere).
    pub fn implausible(&self) -> Option<String> {
        let mut out = Vec::new();
        // The norm scaled by the largest entry: |S| of 1e300 entries stays finite.
        let big = self.transmitter_s.amax();
        let s = if big > 0.0 {
            big * (self.transmitter_s / big).norm()
        } else {
            big
        };
        if s > MAX_TRANSMITTER_S {
            let g = (Matrix3::identity() + self.transmitter_s)
                .determinant()
                .abs()
                .cbrt();
            let scale = if g.is_finite() {
                format!(
                    " (it scales the moments by about {})",
                    aeromag_core::error::figure(g)
                )
            } else {
                String::new()
            };
            out.push(format!(
                "transmitter distortion |S| = {} exceeds {MAX_TRANSMITTER_S}{scale}: KNOWN positions not in metres (km, cm, ft?), moments in the wrong unit (×1000?), or swapped channels",
                aeromag_core::error::figure(s),
            ));
        }
        let q = crate::positioning::rotation_angle_between(&self.attitude_q, &Matrix3::identity())
            .to_degrees();
        if q > MAX_ATTITUDE_Q_DEG {
            out.push(format!(
                "attitude correction Q turns by {q:.1}°, beyond the {MAX_ATTITUDE_Q_DEG}° of a mounting error: swapped or mislabelled receiver channels, KNOWN attitudes in radians or another convention, or moments of the wrong sign"
            ));
        }
        (!out.is_empty()).then(|| out.join("; "))
    }

    /// Effective moments `M' = (I + S) M` (A·m²).
    pub fn effective_moments(&self, moments: &Matrix3<f64>) -> Matrix3<f64> {
        (Matrix3::identity() + self.transmitter_s) * moments
    }

    /// Apply stages 1–3 to one epoch of three complex vectors (one per
    /// frequency, receiver axes, pilot-corrected) and locate the receiver:
    /// closed form, LM polish, then `R ← Q R`.
    pub fn locate(
        &self,
        epoch: &[[Complex64; 3]; 3],
        moments: &Matrix3<f64>,
        hemisphere: &mut Hemisphere,
    ) -> Result<Located> {
        let (h, ratios) = self.polarisation.apply(epoch);
        let m = self.effective_moments(moments);
        let cf = closed_form(&h, &m, hemisphere)?;
        let p = polish(&h, &m, &cf.pose, &PolishOptions::default())?;
        let pose = Pose {
            position_m: p.pose.position_m,
            rotation: self.attitude_q * p.pose.rotation,
        };
        Ok(Located {
            pose,
            polarisation_ratio: ratios,
            rms_residual: p.rms_residual,
        })
    }
}

#[cfg(test)]
mod tests;
