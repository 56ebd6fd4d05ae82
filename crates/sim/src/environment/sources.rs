//! Discrete magnetic sources of the crust: point dipoles (and uniformly
//! magnetised spheres, whose external field is exactly that of a dipole at
//! the centre with moment `M V`).
//!
//! `B(r) = μ0/(4π|r|³) (3 e eᵀ − I) m` (`aeromag_core::field::dipole`) with
//! `r` from the source to the observer in NED; the source lies `depth_m`
//! below the (flat) terrain, the observer `alt − terrain` above it. Spec
//! `simulator.md` "Fields": "plus discrete sources (dipoles, spheres)".

use aeromag_core::NT_PER_T;
use aeromag_core::field::dipole::dipole_field;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::error::{Result, require_finite, require_positive};

/// A buried dipole (or sphere) in the local frame of the scenario.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DipoleSource {
    /// North offset from the scenario origin, m.
    pub north_m: f64,
    /// East offset from the scenario origin, m.
    pub east_m: f64,
    /// Depth of the centre below the terrain surface, m (> 0).
    pub depth_m: f64,
    /// Magnetic moment, A·m², NED components.
    pub moment_am2: [f64; 3],
}

impl DipoleSource {
    /// Check the values.
    pub fn validate(&self, p: &str) -> Result<()> {
        require_finite(&format!("{p}.north_m"), self.north_m)?;
        require_finite(&format!("{p}.east_m"), self.east_m)?;
        require_positive(&format!("{p}.depth_m"), self.depth_m)?;
        for (i, m) in self.moment_am2.iter().enumerate() {
            require_finite(&format!("{p}.moment_am2[{i}]"), *m)?;
        }
        Ok(())
    }

    /// Field (nT, NED) at `(north, east)` and altitude `alt_m` above a flat
    /// terrain at `terrain_alt_m`.
    pub fn field_nt(
        &self,
        north_m: f64,
        east_m: f64,
        alt_m: f64,
        terrain_alt_m: f64,
    ) -> Vector3<f64> {
        let r = Vector3::new(
            north_m - self.north_m,
            east_m - self.east_m,
            -(alt_m - terrain_alt_m) - self.depth_m,
        );
        dipole_field(&Vector3::from(self.moment_am2), &r) * NT_PER_T
    }
}

/// Default bodies of the survey area: an induced intrusion (moment along a
/// field of inclination ≈ 72°, 2·10⁷ A·m² at 400 m depth, ≈ 30 nT at 100 m
/// above ground) and a shallow remanently magnetised body (3·10⁶ A·m² at
/// 150 m).
pub fn default_survey_sources() -> Vec<DipoleSource> {
    vec![
        DipoleSource {
            north_m: 3500.0,
            east_m: 1500.0,
            depth_m: 400.0,
            moment_am2: [6.0e6, 0.0, 1.9e7],
        },
        DipoleSource {
            north_m: 7000.0,
            east_m: 3000.0,
            depth_m: 150.0,
            moment_am2: [-1.5e6, 1.2e6, 2.3e6],
        },
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn field_above_a_vertical_dipole_points_down_and_decays_as_r_cubed() {
        let s = DipoleSource {
            north_m: 0.0,
            east_m: 0.0,
            depth_m: 100.0,
            moment_am2: [0.0, 0.0, 1e6],
        };
        let b1 = s.field_nt(0.0, 0.0, 100.0, 0.0); // 200 m above
        let b2 = s.field_nt(0.0, 0.0, 300.0, 0.0); // 400 m above
        // Axial field 2·1e-7·m/r³ along +z (down) for a downward moment.
        assert!((b1.z - 2.0 * 1e-7 * 1e6 / 8e6 * 1e9).abs() < 1e-9);
        assert!((b1.z / b2.z - 8.0).abs() < 1e-12);
        assert!(b1.x.abs() < 1e-12 && b1.y.abs() < 1e-12);
    }
}
