//! The calibration file written by `aeromag em calibrate` and read by
//! `aeromag em locate`: JSON, versioned, self-contained (it carries the
//! nominal moments the stages were fitted with).
//!
//! ```json
//! { "format": "aeromag-em-calibration", "version": 1,
//!   "moments_am2": [9 numbers, column-major],
//!   "calibration": { "polarisation": {...}, "transmitter_s": [...], "attitude_q": [...] },
//!   "fit": { "epochs": 120, "known_positions": 8, "known_attitudes": 1 },
//!   "half_space": [-1.0, 0.0, 1.0] }
//! ```
//!
//! (`half_space`, the prior half-space the stages were fitted with, is
//! absent from files written before it was kept.)
//!
//! The stages are applied in the order they were fitted
//! ([`Calibration::locate`]).

use super::Calibration;
use crate::{EmError, Result};
use aeromag_core::error::shown;
use nalgebra::Matrix3;
use std::f64::consts::PI;

/// Value of the `format` field.
pub const CALIBRATION_FORMAT: &str = "aeromag-em-calibration";
/// Current `version` (readers reject other versions).
pub const CALIBRATION_VERSION: u32 = 1;

/// Largest entry of `QᵀQ − I` of a stored attitude correction `Q`: a
/// rotation written by `calibrate` is orthonormal to rounding (~10⁻¹⁵);
/// 10⁻⁶ leaves room for a hand-edited file with 7 significant digits.
pub const ROTATION_TOLERANCE: f64 = 1e-6;

/// Largest entry of `S − Sᵀ` of a stored transmitter distortion: stage 2
/// writes an exactly symmetric `S`; 10⁻⁶ leaves room for a hand-edited
/// file with 7 significant digits.
pub const SYMMETRY_TOLERANCE: f64 = 1e-6;

/// How many epochs and known points the stages were fitted from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct FitCounts {
    /// Epochs of stage 1.
    pub epochs: usize,
    /// Known positions of stage 2.
    pub known_positions: usize,
    /// Known attitudes of stage 3.
    pub known_attitudes: usize,
}

/// The versioned calibration file.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CalibrationFile {
    /// Always [`CALIBRATION_FORMAT`].
    pub format: String,
    /// Always [`CALIBRATION_VERSION`].
    pub version: u32,
    /// Nominal transmitter moments (columns = dipoles), A·m².
    pub moments_am2: Matrix3<f64>,
    /// The three stages.
    pub calibration: Calibration,
    /// Fit sizes (informational).
    pub fit: FitCounts,
    /// The prior half-space normal (transmitter frame) the calibration was
    /// fitted with, its known positions on that side (`em calibrate
    /// --half-space`); `em locate` warns when it is given another. Absent
    /// in files written before it was kept.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub half_space: Option<[f64; 3]>,
}

impl CalibrationFile {
    /// Wrap a fitted calibration.
    pub fn new(calibration: Calibration, moments_am2: Matrix3<f64>, fit: FitCounts) -> Self {
        Self {
            format: CALIBRATION_FORMAT.into(),
            version: CALIBRATION_VERSION,
            moments_am2,
            calibration,
            fit,
            half_space: None,
        }
    }

    /// The file with the prior half-space normal the calibration was
    /// fitted with ([`CalibrationFile::half_space`]).
    pub fn with_half_space(self, normal: [f64; 3]) -> Self {
        Self {
            half_space: Some(normal),
            ..self
        }
    }

    /// Pretty JSON text.
    pub fn to_json(&self) -> Result<String> {
        serde_json::to_string_pretty(self).map_err(|e| EmError::InvalidData {
            reason: e.to_string(),
        })
    }

    /// Parse and check format, version and finiteness, that
    /// `calibration.attitude_q` is a rotation (orthonormal within
    /// [`ROTATION_TOLERANCE`], determinant +1), that
    /// `calibration.transmitter_s` is symmetric (within
    /// [`SYMMETRY_TOLERANCE`]), the phases within ±π, and that `|S|` and
    /// `Q` are within [`MAX_TRANSMITTER_S`](super::MAX_TRANSMITTER_S) and
    /// [`MAX_ATTITUDE_Q_DEG`](super::MAX_ATTITUDE_Q_DEG) (what `calibrate`
    /// accepts: `S = −I` would make the effective moments singular).
    ///
    /// Errors ([`EmError::InvalidData`]) with serde's line and column for
    /// malformed JSON, or naming the offending field.
    pub fn from_json(s: &str) -> Result<Self> {
        let f: Self = serde_json::from_str(s).map_err(|e| EmError::InvalidData {
            reason: e.to_string(),
        })?;
        if f.format != CALIBRATION_FORMAT {
            return Err(EmError::InvalidData {
                reason: format!(
                    "field 'format' is \"{}\", expected \"{CALIBRATION_FORMAT}\"",
                    f.format
                ),
            });
        }
        if f.version != CALIBRATION_VERSION {
            return Err(EmError::InvalidData {
                reason: format!(
                    "field 'version' is {}, this program reads version {CALIBRATION_VERSION}",
                    f.version
                ),
            });
        }
        let c = &f.calibration;
        let finite = |m: &Matrix3<f64>| m.iter().all(|v| v.is_finite());
        if !(finite(&f.moments_am2)
            && finite(&c.transmitter_s)
            && finite(&c.attitude_q)
            && finite(&c.polarisation.b)
            && c.polarisation.p.iter().all(finite)
            && c.polarisation.phase_rad.iter().all(|v| v.is_finite()))
        {
            return Err(EmError::InvalidData {
                reason: "non-finite number in the calibration".into(),
            });
        }
        if let Some(n) = f.half_space
            && !(n.iter().all(|v| v.is_finite()) && n.iter().any(|&v| v != 0.0))
        {
            return Err(EmError::InvalidData {
                reason: format!(
                    "field 'half_space' is {},{},{}: expected a finite, non-zero normal",
                    shown(n[0]),
                    shown(n[1]),
                    shown(n[2])
                ),
            });
        }
        let q = &c.attitude_q;
        let off = (q.transpose() * q - Matrix3::identity()).amax();
        if off > ROTATION_TOLERANCE || q.determinant() <= 0.0 {
            return Err(EmError::InvalidData {
                reason: format!(
                    "field 'calibration.attitude_q' is not a rotation (QᵀQ differs from I by {}, \
                     det {}; expected orthonormal within {ROTATION_TOLERANCE}, det +1)",
                    shown(off),
                    shown(q.determinant())
                ),
            });
        }
        let st = &c.transmitter_s;
        let asym = (st - st.transpose()).amax();
        if asym > SYMMETRY_TOLERANCE {
            return Err(EmError::InvalidData {
                reason: format!(
                    "field 'calibration.transmitter_s' is not symmetric (S and Sᵀ differ by {}; \
                     stage 2 fits a symmetric S, expected within {SYMMETRY_TOLERANCE})",
                    shown(asym)
                ),
            });
        }
        if let Some(k) = c.polarisation.phase_rad.iter().position(|v| v.abs() > PI) {
            return Err(EmError::InvalidData {
                reason: format!(
                    "field 'calibration.polarisation.phase_rad[{k}]' is {} rad, expected -π…π",
                    shown(c.polarisation.phase_rad[k])
                ),
            });
        }
        if let Some(what) = c.implausible() {
            let field = if what.contains("|S|") {
                "calibration.transmitter_s"
            } else {
                "calibration.attitude_q"
            };
            return Err(EmError::InvalidData {
                reason: format!("field '{field}': {what}"),
            });
        }
        if f.moments_am2.determinant().abs() == 0.0 {
            return Err(EmError::InvalidData {
                reason: "field 'moments_am2' is singular".into(),
            });
        }
        Ok(f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file() -> CalibrationFile {
        CalibrationFile::new(
            Calibration::default(),
            Matrix3::from_diagonal_element(2.0e4),
            FitCounts {
                epochs: 64,
                known_positions: 8,
                known_attitudes: 1,
            },
        )
    }

    #[test]
    fn round_trip_and_rejections() {
        let f = file();
        let text = f.to_json().unwrap();
        assert_eq!(CalibrationFile::from_json(&text).unwrap(), f);
        let err = |t: &str| CalibrationFile::from_json(t).unwrap_err().to_string();
        assert!(err(&text.replace("\"version\": 1", "\"version\": 2")).contains("version"));
        assert!(err(&text.replace("aeromag-em-calibration", "something-else")).contains("format"));
        assert!(err(&text[..text.len() / 2]).contains("line"));
        // The half-space kept since it was added round-trips; a zero one is refused.
        let with_half = f.clone().with_half_space([-1.0, 0.0, 1.0]);
        let half_text = with_half.to_json().unwrap();
        assert!(half_text.contains("\"half_space\""));
        assert_eq!(CalibrationFile::from_json(&half_text).unwrap(), with_half);
        assert!(
            err(&f.clone().with_half_space([0.0; 3]).to_json().unwrap()).contains("half_space")
        );
        let mut singular = f.clone();
        singular.moments_am2 = Matrix3::zeros();
        assert!(err(&singular.to_json().unwrap()).contains("moments_am2"));
        for q in [Matrix3::zeros(), Matrix3::from_diagonal_element(5.0)] {
            let mut bad = f.clone();
            bad.calibration.attitude_q = q;
            let e = err(&bad.to_json().unwrap());
            assert!(
                e.contains("attitude_q") && e.contains("not a rotation"),
                "{e}"
            );
        }
        let mut mirror = f.clone();
        mirror.calibration.attitude_q =
            Matrix3::from_diagonal(&nalgebra::Vector3::new(1.0, 1.0, -1.0));
        assert!(err(&mirror.to_json().unwrap()).contains("attitude_q"));
        // Found by fuzzing (findings/09): all were read and used.
        let with_s = |s: Matrix3<f64>| {
            let mut b = f.clone();
            b.calibration.transmitter_s = s;
            err(&b.to_json().unwrap())
        };
        let mut asym = Matrix3::zeros();
        asym[(0, 1)] = 0.02;
        let e = with_s(asym);
        assert!(
            e.contains("transmitter_s") && e.contains("not symmetric"),
            "{e}"
        );
        for s in [-Matrix3::identity(), Matrix3::from_diagonal_element(1e300)] {
            let e = with_s(s);
            assert!(
                e.contains("'calibration.transmitter_s'") && e.contains("exceeds 0.5"),
                "{e}"
            );
        }
        let mut phase = f.clone();
        phase.calibration.polarisation.phase_rad[1] = 1e300;
        let e = err(&phase.to_json().unwrap());
        assert!(e.contains("phase_rad[1]") && e.contains("1e300"), "{e}");
        let mut turned = f.clone();
        turned.calibration.attitude_q =
            nalgebra::Rotation3::from_euler_angles(0.0, 0.0, 1.0).into_inner();
        let e = err(&turned.to_json().unwrap());
        assert!(
            e.contains("'calibration.attitude_q'") && e.contains("57.3°"),
            "{e}"
        );
        let mut nan = f;
        nan.calibration.attitude_q[(0, 1)] = f64::NAN;
        // serde_json writes NaN as null, which does not parse as a number.
        assert!(CalibrationFile::from_json(&nan.to_json().unwrap()).is_err());
    }
}
