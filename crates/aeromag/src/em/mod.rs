//! Low-frequency EM positioning of a towed bird on files (spec
//! `em-positioning.md`, seed 001; algorithms in [`aeromag_em`]), as a
//! survey crew chains the steps: [`simulate_to_dir`] (raw ADC record,
//! system, KNOWN, truth) → [`detect`] (detected vectors) → [`calibrate`]
//! (the three stages, with [`known_points`]) → [`locate`] (poses). The
//! file readers are in [`files`]. The algorithms' modules are re-exported
//! here (`aeromag::em::detection`, `::calibration`, …).

mod calibrate;
mod detect;
pub mod files;
mod locate;
mod simulate;

pub use aeromag_em::{EmError, calibration, detection, positioning, sim, study};
pub use calibrate::{EmCalibration, KNOWN_RANGE_M, calibrate, check_known_position, known_points};
pub use detect::{DetectOptions, Detection, FLAT_CHANNEL_RATIO, detect};
pub use locate::{Located, MAX_RESIDUAL_REL, Pose, Poses, locate};
pub use simulate::{DEFAULT_KNOWN, SimulatedEm, command_default, parse_config, simulate_to_dir};

use crate::error::{Error, Result};
use nalgebra::Vector3;
use std::str::FromStr;

/// The prior half-space of the bird for the ±r choice: the bird is where
/// `r·n > 0` (transmitter frame). Default: behind and below (x forward,
/// z down), `n = (−1, 0, 1)`.
///
/// ```
/// use aeromag::em::HalfSpace;
/// let h: HalfSpace = "-1,0,1".parse()?;
/// assert_eq!(h, HalfSpace::default());
/// assert!("0,0,0".parse::<HalfSpace>().is_err());
/// # Ok::<(), aeromag::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HalfSpace(Vector3<f64>);

impl HalfSpace {
    /// The half-space of a non-zero, finite normal; only its direction
    /// matters. The normal is kept scaled by its largest component (which
    /// becomes ±1, so `-1,0,1` is kept exactly): its length is then between
    /// 1 and √3 and normalising it can neither overflow nor underflow. The
    /// length of `-1e160,0,1e160` overflowed to ∞ (`-1e-200,0,1e-200`
    /// underflowed to 0), `e·n/|n|` became 0 and every bird came out
    /// mirrored.
    pub fn new(normal: Vector3<f64>) -> Result<Self> {
        if normal == Vector3::zeros() || !normal.iter().all(|v| v.is_finite()) {
            return Err(Error::bad_input(format!(
                "half-space normal {},{},{}: must be finite and not zero",
                normal.x, normal.y, normal.z
            )));
        }
        Ok(Self(normal / normal.amax()))
    }

    /// The normal, scaled so that its largest component is ±1.
    pub fn normal(&self) -> Vector3<f64> {
        self.0
    }
}

impl Default for HalfSpace {
    fn default() -> Self {
        Self(Vector3::new(-1.0, 0.0, 1.0))
    }
}

impl std::fmt::Display for HalfSpace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{},{},{}", self.0.x, self.0.y, self.0.z)
    }
}

impl FromStr for HalfSpace {
    type Err = Error;
    /// `NX,NY,NZ`.
    fn from_str(s: &str) -> Result<Self> {
        let v: Vec<f64> = s
            .split(',')
            .map(|p| p.trim().parse::<f64>())
            .collect::<std::result::Result<_, _>>()
            .map_err(|_| Error::bad_input(format!("half-space '{s}': expected NX,NY,NZ")))?;
        let [x, y, z] = v[..] else {
            return Err(Error::bad_input(format!(
                "half-space '{s}': expected NX,NY,NZ"
            )));
        };
        Self::new(Vector3::new(x, y, z))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `-1e160,0,1e160` is the direction of `-1,0,1`: its length overflowed
    /// (that of `-1e-200,0,1e-200` underflowed) and every bird was mirrored.
    #[test]
    fn half_space_normals_of_any_scale_are_the_same_half_space() {
        for s in [
            "-1e160,0,1e160",
            "-1e-200,0,1e-200",
            "-1e308,0,1e308",
            "-5e-324,0,5e-324",
        ] {
            let h: HalfSpace = s.parse().unwrap();
            assert_eq!(h, HalfSpace::default(), "{s}");
            assert_eq!(h.to_string(), "-1,0,1", "{s}");
        }
        let h: HalfSpace = "2,-3e200,1e-300".parse().unwrap();
        let n = h.normal();
        assert_eq!(n.amax(), 1.0);
        assert!(n.norm().is_finite() && n.y == -1.0, "{n}");
        assert!("0,0,0".parse::<HalfSpace>().is_err());
        assert!("1,inf,0".parse::<HalfSpace>().is_err());
    }
}
