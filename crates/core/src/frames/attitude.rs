//! Attitude: Z-Y-X (yaw, pitch, roll) Euler angles and the direction cosine
//! matrix `C_nb` that rotates body vectors into the NED navigation frame.
//!
//! `C_nb = R_z(ψ) · R_y(θ) · R_x(φ)` with the active rotations
//!
//! ```text
//!        | cψ −sψ 0 |          |  cθ 0 sθ |          | 1  0   0  |
//! R_z =  | sψ  cψ 0 |   R_y =  |  0  1 0  |   R_x =  | 0  cφ −sφ |
//!        | 0   0  1 |          | −sθ 0 cθ |          | 0  sφ  cφ |
//! ```
//!
//! A level aircraft flying east (ψ = 90°) has its nose (body x) along NED y.
//! Positive pitch raises the nose (body x gets a negative NED z component,
//! i.e. points up); positive roll lowers the right wing.

use nalgebra::{Matrix3, Vector3};

/// Aircraft attitude as Z-Y-X Euler angles in **radians**.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Attitude {
    /// Roll φ, rad, positive right wing down.
    pub roll: f64,
    /// Pitch θ, rad, positive nose up.
    pub pitch: f64,
    /// Yaw (heading) ψ, rad, clockwise from north.
    pub yaw: f64,
}

impl Attitude {
    /// Attitude from angles in radians.
    pub fn new(roll: f64, pitch: f64, yaw: f64) -> Self {
        Self { roll, pitch, yaw }
    }

    /// Attitude from angles in degrees.
    pub fn from_degrees(roll_deg: f64, pitch_deg: f64, yaw_deg: f64) -> Self {
        Self::new(
            roll_deg.to_radians(),
            pitch_deg.to_radians(),
            yaw_deg.to_radians(),
        )
    }

    /// `C_nb`: rotates body-frame vectors into NED, `v_n = C_nb v_b`.
    pub fn c_nb(&self) -> Matrix3<f64> {
        let (sf, cf) = self.roll.sin_cos();
        let (st, ct) = self.pitch.sin_cos();
        let (sp, cp) = self.yaw.sin_cos();
        Matrix3::new(
            cp * ct,
            cp * st * sf - sp * cf,
            cp * st * cf + sp * sf,
            sp * ct,
            sp * st * sf + cp * cf,
            sp * st * cf - cp * sf,
            -st,
            ct * sf,
            ct * cf,
        )
    }

    /// `C_bn = C_nbᵀ`: rotates NED vectors into the body frame.
    pub fn c_bn(&self) -> Matrix3<f64> {
        self.c_nb().transpose()
    }

    /// Euler angles of a rotation matrix `C_nb` (inverse of [`Attitude::c_nb`]).
    ///
    /// Pitch is returned in [−π/2, π/2], roll and yaw in (−π, π]. At gimbal
    /// lock (|θ| = π/2) roll is set to zero and the whole rotation about the
    /// vertical is assigned to yaw.
    pub fn from_c_nb(c: &Matrix3<f64>) -> Self {
        let st = (-c[(2, 0)]).clamp(-1.0, 1.0);
        let pitch = st.asin();
        if (1.0 - st.abs()) < 1e-12 {
            // Gimbal lock: only yaw − sign(θ)·roll is defined.
            let yaw = (-c[(0, 1)]).atan2(c[(1, 1)]);
            return Self::new(0.0, pitch, yaw);
        }
        let roll = c[(2, 1)].atan2(c[(2, 2)]);
        let yaw = c[(1, 0)].atan2(c[(0, 0)]);
        Self::new(roll, pitch, yaw)
    }

    /// Rotate a body vector into NED.
    pub fn body_to_ned(&self, v_b: &Vector3<f64>) -> Vector3<f64> {
        self.c_nb() * v_b
    }

    /// Rotate a NED vector into the body frame.
    pub fn ned_to_body(&self, v_n: &Vector3<f64>) -> Vector3<f64> {
        self.c_bn() * v_n
    }
}

/// Wrap an angle in radians to (−π, π].
pub fn wrap_pi(a: f64) -> f64 {
    let two_pi = std::f64::consts::TAU;
    let mut w = a.rem_euclid(two_pi);
    if w > std::f64::consts::PI {
        w -= two_pi;
    }
    w
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    #[test]
    fn heading_east_points_nose_east() {
        let a = Attitude::from_degrees(0.0, 0.0, 90.0);
        let nose = a.body_to_ned(&Vector3::x());
        assert_relative_eq!(nose, Vector3::y(), epsilon = 1e-15);
    }

    #[test]
    fn pitch_up_raises_nose_and_roll_lowers_right_wing() {
        let a = Attitude::from_degrees(0.0, 10.0, 0.0);
        assert!(a.body_to_ned(&Vector3::x()).z < 0.0);
        let r = Attitude::from_degrees(10.0, 0.0, 0.0);
        assert!(r.body_to_ned(&Vector3::y()).z > 0.0);
    }

    #[test]
    fn gimbal_lock_is_finite() {
        let a = Attitude::from_degrees(20.0, 90.0, 30.0);
        let b = Attitude::from_c_nb(&a.c_nb());
        assert_relative_eq!(a.c_nb(), b.c_nb(), epsilon = 1e-9);
    }

    proptest! {
        #[test]
        fn c_nb_is_a_proper_rotation(r in -3.1f64..3.1, p in -1.5f64..1.5, y in -3.1f64..3.1) {
            let c = Attitude::new(r, p, y).c_nb();
            let i = c * c.transpose();
            prop_assert!((i - Matrix3::identity()).norm() < 1e-13);
            prop_assert!((c.determinant() - 1.0).abs() < 1e-13);
        }

        #[test]
        fn euler_round_trip(r in -3.1f64..3.1, p in -1.55f64..1.55, y in -3.1f64..3.1) {
            let a = Attitude::new(r, p, y);
            let b = Attitude::from_c_nb(&a.c_nb());
            prop_assert!((wrap_pi(a.roll - b.roll)).abs() < 1e-9);
            prop_assert!((a.pitch - b.pitch).abs() < 1e-9);
            prop_assert!((wrap_pi(a.yaw - b.yaw)).abs() < 1e-9);
        }

        #[test]
        fn rotation_preserves_norm(r in -3.1f64..3.1, p in -1.5f64..1.5, y in -3.1f64..3.1,
                                   x in -1e5f64..1e5, yv in -1e5f64..1e5, z in -1e5f64..1e5) {
            let a = Attitude::new(r, p, y);
            let v = Vector3::new(x, yv, z);
            let w = a.ned_to_body(&a.body_to_ned(&v));
            prop_assert!((w - v).norm() <= 1e-9 * (1.0 + v.norm()));
            prop_assert!((a.body_to_ned(&v).norm() - v.norm()).abs() <= 1e-9 * (1.0 + v.norm()));
        }
    }
}
