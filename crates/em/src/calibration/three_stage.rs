//! The three calibration stages fitted in order from one set of detected
//! epochs plus the external information each stage needs (seed `001_…`
//! part II; spec `em-positioning.md`, "Calibration in three stages"):
//!
//! 1. [`PolarisationCalibration::fit`] on every epoch (no external
//!    information);
//! 2. [`fit_transmitter_geometry`] on the stage-1 fields of the epochs
//!    whose position is known (range and direction, not attitude);
//! 3. the epochs whose attitude is known are located with stages 1–2 and
//!    `Q = proj_SO(3)(Σ R Rᵀ')` ([`fit_attitude_correction`]); one point
//!    suffices.

use super::{
    Calibration, PolarisationCalibration, fit_attitude_correction, fit_transmitter_geometry,
};
use crate::detection::Complex64;
use crate::positioning::Hemisphere;
use crate::{EmError, Result};
use nalgebra::{Matrix3, Vector3};

/// External information for stages 2 and 3: indices into the epoch slice
/// with the known position (m, transmitter frame) or the known rotation
/// (transmitter-frame vectors → receiver axes).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct KnownPoints {
    /// `(epoch index, position r, m)`: stage 2 (≥ 2 points).
    pub positions: Vec<(usize, Vector3<f64>)>,
    /// `(epoch index, rotation R)`: stage 3 (≥ 1 point).
    pub attitudes: Vec<(usize, Matrix3<f64>)>,
}

impl Calibration {
    /// Fit the three stages in order (module docs) from `epochs[e][i]`
    /// (complex field of dipole `i`, receiver axes, pilot-corrected, T),
    /// the nominal `moments` (A·m²) and the prior half-space `hemisphere`
    /// used to locate the attitude points.
    ///
    /// Errors: an index outside `epochs`, fewer than 2 known positions or
    /// no known attitude, or a failing stage (too few or too uniform epochs).
    pub fn fit(
        epochs: &[[[Complex64; 3]; 3]],
        known: &KnownPoints,
        moments: &Matrix3<f64>,
        hemisphere: &Hemisphere,
    ) -> Result<Self> {
        let get = |k: usize| {
            epochs.get(k).ok_or_else(|| EmError::InvalidArgument {
                reason: format!("known point refers to epoch {k} of {}", epochs.len()),
            })
        };
        if known.attitudes.is_empty() {
            return Err(EmError::InvalidArgument {
                reason: "stage 3 needs at least one point of known attitude".into(),
            });
        }
        let polarisation = PolarisationCalibration::fit(epochs)?;
        let mut fields = Vec::with_capacity(known.positions.len());
        let mut positions = Vec::with_capacity(known.positions.len());
        for (k, r) in &known.positions {
            fields.push(polarisation.apply(get(*k)?).0);
            positions.push(*r);
        }
        let transmitter_s = fit_transmitter_geometry(&fields, &positions, moments)?;
        let mut cal = Calibration {
            polarisation,
            transmitter_s,
            attitude_q: Matrix3::identity(),
        };
        let mut truth = Vec::with_capacity(known.attitudes.len());
        let mut computed = Vec::with_capacity(known.attitudes.len());
        for (k, r) in &known.attitudes {
            let mut hemi = Hemisphere {
                previous: None,
                ..*hemisphere
            };
            computed.push(cal.locate(get(*k)?, moments, &mut hemi)?.pose.rotation);
            truth.push(*r);
        }
        cal.attitude_q = fit_attitude_correction(&truth, &computed)?;
        Ok(cal)
    }
}
