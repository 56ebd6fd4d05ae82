//! Pod position from the cable geometry and the aircraft attitude (spec
//! `helicopter.md` part B, seed `002_…` eqs. 7–8).
//!
//! The cable is a straight line of length `L` (m) from the attachment point
//! `r_a = (a, b, c)` (body frame: x forward, y right, z down, m), with
//! inclination `I` below the horizontal and azimuth `θ` from magnetic north,
//! both recorded. Its NED vector is `ℓ_n = L (cos I cos θ', cos I sin θ',
//! sin I)` with `θ' = θ + θ_d` (declination `θ_d`, so that `θ'` is from true
//! north like the attitude's heading).
//!
//! * [`pod_position_exact`]: `p_b = r_a + C_bn(φ, θ_p, ψ) ℓ_n` — the
//!   attachment point is fixed in the body, the cable vector is rotated by
//!   the full attitude (yaw-pitch-roll, `C_bn = R_x(φ) R_y(θ_p) R_z(ψ)`).
//! * [`pod_position_seed`]: the seed's eq. 7 as printed:
//!   `p_b = A (L cos I cos(θ + θ_d − θ₀) + a, L cos I sin(θ + θ_d − θ₀) + b,
//!   L sin I + c)` with `A = A_h A_p A_r` (eq. 8) built from the deviations
//!   `θ_h = ψ − θ₀`, `θ_p`, `φ` from the mean heading `θ₀`; it rotates the
//!   attachment point too and composes the rotations in the order
//!   yaw·pitch·roll on the *body* side, which is exact only when a single
//!   manoeuvre angle is non-zero (the seed's §3.2.1 assumption).

use aeromag_core::frames::Attitude;
use nalgebra::{Matrix3, Vector3};

/// Cable geometry: length and attachment point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cable {
    /// Cable length `L`, m.
    pub length_m: f64,
    /// Attachment point `(a, b, c)` in the body frame, m.
    pub attach_m: [f64; 3],
    /// Declination `θ_d`, rad (0 when headings and azimuths are magnetic).
    pub declination_rad: f64,
}

fn cable_ned(c: &Cable, inclination: f64, azimuth: f64) -> Vector3<f64> {
    let az = azimuth + c.declination_rad;
    Vector3::new(
        inclination.cos() * az.cos(),
        inclination.cos() * az.sin(),
        inclination.sin(),
    ) * c.length_m
}

/// Exact pod position in the body frame, m: `p_b = r_a + C_bn ℓ_n`
/// (inclination and azimuth in rad).
pub fn pod_position_exact(
    c: &Cable,
    att: &Attitude,
    inclination: f64,
    azimuth: f64,
) -> Vector3<f64> {
    Vector3::from(c.attach_m) + att.ned_to_body(&cable_ned(c, inclination, azimuth))
}

/// Pod offset from the aircraft's navigation point in NED, m:
/// `C_nb r_a + ℓ_n` (for the track term: north `x_N` and altitude `h` of
/// the pod are the aircraft's plus this offset's north and minus its down).
pub fn pod_offset_ned(c: &Cable, att: &Attitude, inclination: f64, azimuth: f64) -> Vector3<f64> {
    att.body_to_ned(&Vector3::from(c.attach_m)) + cable_ned(c, inclination, azimuth)
}

/// The seed's pod position (eqs. 7–8), m, for mean heading `heading0` (rad).
pub fn pod_position_seed(
    c: &Cable,
    att: &Attitude,
    heading0: f64,
    inclination: f64,
    azimuth: f64,
) -> Vector3<f64> {
    let (sh, ch) = (att.yaw - heading0).sin_cos();
    let (sp, cp) = att.pitch.sin_cos();
    let (sr, cr) = att.roll.sin_cos();
    let a_h = Matrix3::new(ch, sh, 0.0, -sh, ch, 0.0, 0.0, 0.0, 1.0);
    let a_p = Matrix3::new(cp, 0.0, -sp, 0.0, 1.0, 0.0, sp, 0.0, cp);
    let a_r = Matrix3::new(1.0, 0.0, 0.0, 0.0, cr, sr, 0.0, -sr, cr);
    let level = Attitude::new(0.0, 0.0, heading0).ned_to_body(&cable_ned(c, inclination, azimuth));
    a_h * a_p * a_r * (level + Vector3::from(c.attach_m))
}

/// Direction cosines `u` of the Earth field in the body frame for field
/// inclination `inc` and declination `dec` (rad): `u = C_bn (cos inc cos dec,
/// cos inc sin dec, sin inc)` (seed eq. 1).
pub fn direction_cosines(inc: f64, dec: f64, att: &Attitude) -> [f64; 3] {
    let d = Vector3::new(inc.cos() * dec.cos(), inc.cos() * dec.sin(), inc.sin());
    let u = att.ned_to_body(&d);
    [u.x, u.y, u.z]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seed_and_exact_agree_for_single_manoeuvres_without_attachment_offset() {
        let c = Cable {
            length_m: 40.0,
            attach_m: [0.0, 0.0, 0.0],
            declination_rad: 0.0,
        };
        let h0 = 0.7;
        for att in [
            Attitude::new(0.0, 0.0, h0 + 0.08),
            Attitude::new(0.0, 0.08, h0),
            Attitude::new(0.08, 0.0, h0),
        ] {
            let e = pod_position_exact(&c, &att, 1.2, h0 + 3.0);
            let s = pod_position_seed(&c, &att, h0, 1.2, h0 + 3.0);
            assert!((e - s).norm() < 1e-9, "{e} {s}");
        }
        // With pitch and roll together the seed's composition differs.
        let att = Attitude::new(0.08, 0.08, h0 + 0.08);
        let e = pod_position_exact(&c, &att, 1.2, h0 + 3.0);
        let s = pod_position_seed(&c, &att, h0, 1.2, h0 + 3.0);
        assert!((e - s).norm() > 1e-3);
    }

    #[test]
    fn direction_cosines_are_unit_and_level_north_is_the_field() {
        let u = direction_cosines(0.8, 0.0, &Attitude::new(0.0, 0.0, 0.0));
        assert!((u[0] - 0.8f64.cos()).abs() < 1e-12 && u[1].abs() < 1e-12);
        let u = direction_cosines(0.8, 0.1, &Attitude::new(0.1, -0.2, 2.0));
        assert!((u.iter().map(|x| x * x).sum::<f64>() - 1.0).abs() < 1e-12);
    }
}
