//! Three-axis fluxgate magnetometer.
//!
//! The true field at the fluxgate `B_b` (body axes: external field at the
//! fluxgate plus the aircraft's interference there, nT) is recorded as
//!
//! ```text
//! flux = S T C_sb B_b + b + n,     n ~ N(0, σ² I),  σ = ρ √(f_s/2)
//! C_sb = C_bn(φ_m, θ_m, ψ_m)       misalignment: sensor axes rotated from the body by
//!                                  the Z-Y-X Euler angles (φ_m, θ_m, ψ_m)
//! T = | 1        0        0                        |   non-orthogonality: rows are the
//!     | sin εxy  cos εxy  0                        |   sensing directions in an
//!     | sin εxz  sin εyz  √(1 − sin²εxz − sin²εyz) |   orthonormal sensor frame
//! S = diag(1 + s_x, 1 + s_y, 1 + s_z)                scale errors
//! ```
//!
//! Defaults: bias (12, −8, 5) nT, scale errors (1.5, −1.0, 0.8)·10⁻³,
//! non-orthogonality (εxy, εxz, εyz) = (0.05°, −0.08°, 0.03°), misalignment
//! (roll, pitch, yaw) = (0.3°, −0.2°, 0.5°), noise density 0.05 nT/√Hz
//! (σ = 0.11 nT at 10 Hz). Spec `simulator.md` ("Vector fluxgate: noise,
//! bias, scale errors, non-orthogonality, misalignment relative to the body").

use aeromag_core::frames::Attitude;
use nalgebra::{Matrix3, Vector3};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::error::{Result, invalid, require_finite, require_non_negative};
use crate::random::normal;

/// Parameters of the fluxgate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FluxgateConfig {
    /// Position in the body frame (stinger root), m. Default (−8.0, 0, −0.5).
    pub position_m: [f64; 3],
    /// White-noise density, nT/√Hz. Default 0.05.
    pub noise_density_nt_per_rthz: f64,
    /// Bias, nT. Default (12, −8, 5).
    pub bias_nt: [f64; 3],
    /// Scale errors `s` (dimensionless). Default (1.5e-3, −1.0e-3, 0.8e-3).
    pub scale_error: [f64; 3],
    /// Non-orthogonality angles (εxy, εxz, εyz), deg. Default (0.05, −0.08, 0.03).
    pub non_orthogonality_deg: [f64; 3],
    /// Misalignment Euler angles (roll, pitch, yaw) of the sensor axes
    /// relative to the body, deg. Default (0.3, −0.2, 0.5).
    pub misalignment_deg: [f64; 3],
}

impl Default for FluxgateConfig {
    fn default() -> Self {
        Self {
            position_m: [-8.0, 0.0, -0.5],
            noise_density_nt_per_rthz: 0.05,
            bias_nt: [12.0, -8.0, 5.0],
            scale_error: [1.5e-3, -1.0e-3, 0.8e-3],
            non_orthogonality_deg: [0.05, -0.08, 0.03],
            misalignment_deg: [0.3, -0.2, 0.5],
        }
    }
}

impl FluxgateConfig {
    /// Check the values.
    pub fn validate(&self, p: &str) -> Result<()> {
        for (name, v) in [
            ("position_m", &self.position_m),
            ("bias_nt", &self.bias_nt),
            ("scale_error", &self.scale_error),
            ("misalignment_deg", &self.misalignment_deg),
        ] {
            for (i, x) in v.iter().enumerate() {
                require_finite(&format!("{p}.{name}[{i}]"), *x)?;
            }
        }
        require_non_negative(
            &format!("{p}.noise_density_nt_per_rthz"),
            self.noise_density_nt_per_rthz,
        )?;
        if self.scale_error.iter().any(|s| *s <= -1.0) {
            return Err(invalid(format!("{p}.scale_error"), "each must be > −1"));
        }
        let e = self.non_orthogonality_deg.map(|d| d.to_radians().sin());
        if !(e.iter().all(|x| x.abs() < 0.5) && e[1] * e[1] + e[2] * e[2] < 1.0) {
            return Err(invalid(
                format!("{p}.non_orthogonality_deg"),
                "angles must be small (|ε| < 30°)",
            ));
        }
        Ok(())
    }

    /// The matrix `S T C_sb` mapping the body field to the readings (before
    /// bias and noise).
    pub fn matrix(&self) -> Matrix3<f64> {
        let [a, b, c] = self.misalignment_deg;
        let c_sb = Attitude::from_degrees(a, b, c).c_bn();
        let [exy, exz, eyz] = self.non_orthogonality_deg.map(|d| d.to_radians().sin());
        let t = Matrix3::new(
            1.0,
            0.0,
            0.0,
            exy,
            (1.0 - exy * exy).sqrt(),
            0.0,
            exz,
            eyz,
            (1.0 - exz * exz - eyz * eyz).sqrt(),
        );
        let s = Matrix3::from_diagonal(&Vector3::from(self.scale_error).add_scalar(1.0));
        s * t * c_sb
    }

    /// Readings (nT) for the true body fields at the fluxgate (nT).
    pub fn measure(
        &self,
        b_body_nt: &[Vector3<f64>],
        dt_s: f64,
        rng: &mut ChaCha8Rng,
    ) -> Vec<Vector3<f64>> {
        let m = self.matrix();
        let bias = Vector3::from(self.bias_nt);
        let sigma = super::white_rms(self.noise_density_nt_per_rthz, 1.0 / dt_s);
        b_body_nt
            .iter()
            .map(|b| {
                let n = Vector3::new(normal(rng), normal(rng), normal(rng)) * sigma;
                m * b + bias + n
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::{Stream, rng_for};

    #[test]
    fn errors_are_applied_as_documented() {
        let cfg = FluxgateConfig {
            noise_density_nt_per_rthz: 0.0,
            ..Default::default()
        };
        let m = cfg.matrix();
        // A perfect sensor is the identity.
        let ideal = FluxgateConfig {
            bias_nt: [0.0; 3],
            scale_error: [0.0; 3],
            non_orthogonality_deg: [0.0; 3],
            misalignment_deg: [0.0; 3],
            noise_density_nt_per_rthz: 0.0,
            ..Default::default()
        };
        assert!((ideal.matrix() - Matrix3::identity()).norm() < 1e-15);
        let b = Vector3::new(15_000.0, -2_000.0, 48_000.0);
        let r = cfg.measure(&[b], 0.1, &mut rng_for(1, Stream::FluxgateNoise))[0];
        assert!((r - (m * b + Vector3::new(12.0, -8.0, 5.0))).norm() < 1e-9);
        // Only a scale error on x: reading x = (1 + s) B_x.
        let sx = FluxgateConfig {
            scale_error: [2e-3, 0.0, 0.0],
            ..ideal.clone()
        };
        let r = sx.measure(&[b], 0.1, &mut rng_for(1, Stream::FluxgateNoise))[0];
        assert!((r.x - 1.002 * b.x).abs() < 1e-9 && (r.y - b.y).abs() < 1e-9);
        // Only εxy: the y axis leans toward x, reading y = sin ε B_x + cos ε B_y.
        let no = FluxgateConfig {
            non_orthogonality_deg: [0.1, 0.0, 0.0],
            ..ideal.clone()
        };
        let e = 0.1f64.to_radians();
        let r = no.measure(&[b], 0.1, &mut rng_for(1, Stream::FluxgateNoise))[0];
        assert!((r.y - (e.sin() * b.x + e.cos() * b.y)).abs() < 1e-9);
        // Only a yaw misalignment ψ: the sensor x axis is rotated by ψ toward body y.
        let mis = FluxgateConfig {
            misalignment_deg: [0.0, 0.0, 1.0],
            ..ideal.clone()
        };
        let p = 1f64.to_radians();
        let r = mis.measure(&[b], 0.1, &mut rng_for(1, Stream::FluxgateNoise))[0];
        assert!((r.x - (p.cos() * b.x + p.sin() * b.y)).abs() < 1e-9);
        // Noise level.
        let noisy = FluxgateConfig { ..ideal };
        let noisy = FluxgateConfig {
            noise_density_nt_per_rthz: 0.05,
            ..noisy
        };
        let v = noisy.measure(
            &vec![b; 20_000],
            0.1,
            &mut rng_for(2, Stream::FluxgateNoise),
        );
        let rms =
            (v.iter().map(|r| (r - b).norm_squared()).sum::<f64>() / (3.0 * v.len() as f64)).sqrt();
        assert!((rms / (0.05 * 5f64.sqrt()) - 1.0).abs() < 0.02, "{rms}");
    }

    proptest::proptest! {
        /// Misalignment alone is a proper rotation; scale errors alone are
        /// diagonal; the non-orthogonal axes are unit vectors.
        #[test]
        fn matrix_structure(r in -2.0f64..2.0, p in -2.0f64..2.0, y in -2.0f64..2.0,
                            e1 in -1.0f64..1.0, e2 in -1.0f64..1.0, e3 in -1.0f64..1.0) {
            let ideal = FluxgateConfig { bias_nt: [0.0; 3], scale_error: [0.0; 3], non_orthogonality_deg: [0.0; 3],
                misalignment_deg: [0.0; 3], ..Default::default() };
            let m = FluxgateConfig { misalignment_deg: [r, p, y], ..ideal.clone() }.matrix();
            proptest::prop_assert!((m * m.transpose() - Matrix3::identity()).norm() < 1e-14);
            proptest::prop_assert!((m.determinant() - 1.0).abs() < 1e-14);
            let t = FluxgateConfig { non_orthogonality_deg: [e1, e2, e3], ..ideal }.matrix();
            for i in 0..3 {
                proptest::prop_assert!((t.row(i).norm() - 1.0).abs() < 1e-14);
            }
            proptest::prop_assert!(t[(0, 1)] == 0.0 && t[(0, 2)] == 0.0 && t[(1, 2)] == 0.0);
        }
    }
}
