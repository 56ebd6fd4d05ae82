//! Guidance laws of the kinematic aircraft: L1 lateral guidance and an
//! altitude hold.
//!
//! **L1 guidance** (Park, Deyst & How 2004, *AIAA GNC* 2004-4900): a
//! reference point `R` is taken on the desired line at distance `L1` ahead
//! of the aircraft (the foot of the perpendicular when the line is farther
//! than `L1`); with `η` the angle from the ground velocity to `R − p`
//! (positive to the right), the commanded lateral acceleration is
//!
//! ```text
//! a = 2 V² sin η / L1        (|η| ≥ 90°: a = ±a_max toward R)
//! φ_cmd = atan(a / g),  |φ_cmd| ≤ φ_max
//! ```
//!
//! Near the line this is a second-order loop with `ω_n = √2 V/L1` and damping
//! `1/√2`; far from it the aircraft turns at the bank limit, so the same law
//! captures a new line after the end of the previous one (survey turns).
//!
//! **Altitude hold**: the flight-path angle follows the altitude error with
//! time constant `τ_h`: `sin γ = clamp((h_ref − h)/(V τ_h), ±sin γ_max)`.

/// Gravity, m/s².
pub const G_M_S2: f64 = 9.806_65;

/// A straight reference line in the local north/east plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RefLine {
    /// North coordinate of the line origin (along-track 0), m.
    pub north_m: f64,
    /// East coordinate of the line origin, m.
    pub east_m: f64,
    /// Direction of flight along the line, rad clockwise from north.
    pub heading_rad: f64,
}

impl RefLine {
    /// Along-track and cross-track (positive right of the direction of flight)
    /// coordinates of a point, m.
    pub fn along_cross(&self, north_m: f64, east_m: f64) -> (f64, f64) {
        let (s, c) = self.heading_rad.sin_cos();
        let dn = north_m - self.north_m;
        let de = east_m - self.east_m;
        (dn * c + de * s, -dn * s + de * c)
    }

    /// The point at along-track coordinate `s`, m.
    pub fn point(&self, along_m: f64) -> (f64, f64) {
        let (s, c) = self.heading_rad.sin_cos();
        (self.north_m + along_m * c, self.east_m + along_m * s)
    }
}

/// L1 bank command (rad) for an aircraft at `(north, east)` flying with track
/// angle `chi` at speed `speed` toward `line`.
pub fn l1_bank(
    line: &RefLine,
    north_m: f64,
    east_m: f64,
    chi: f64,
    speed: f64,
    l1_m: f64,
    max_bank: f64,
) -> f64 {
    let (along, cross) = line.along_cross(north_m, east_m);
    let ahead = if cross.abs() < l1_m {
        (l1_m * l1_m - cross * cross).sqrt()
    } else {
        0.0
    };
    let (rn, re) = line.point(along + ahead);
    let (dn, de) = (rn - north_m, re - east_m);
    let (vn, ve) = (chi.cos(), chi.sin());
    let eta = (vn * de - ve * dn).atan2(vn * dn + ve * de);
    let a_max = G_M_S2 * max_bank.tan();
    let a = if eta.abs() >= std::f64::consts::FRAC_PI_2 {
        a_max * eta.signum()
    } else {
        2.0 * speed * speed * eta.sin() / l1_m
    };
    (a / G_M_S2).atan().clamp(-max_bank, max_bank)
}

/// Flight-path angle (rad) of the altitude hold.
pub fn altitude_hold(alt_m: f64, target_m: f64, speed: f64, tau_s: f64, max_gamma: f64) -> f64 {
    let s = ((target_m - alt_m) / (speed * tau_s)).clamp(-max_gamma.sin(), max_gamma.sin());
    s.asin()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn along_cross_signs() {
        let l = RefLine {
            north_m: 0.0,
            east_m: 0.0,
            heading_rad: 0.0,
        };
        assert_eq!(l.along_cross(10.0, 3.0), (10.0, 3.0));
        let l = RefLine {
            north_m: 0.0,
            east_m: 0.0,
            heading_rad: std::f64::consts::FRAC_PI_2,
        };
        let (a, c) = l.along_cross(-2.0, 5.0);
        assert!((a - 5.0).abs() < 1e-12 && (c - 2.0).abs() < 1e-12);
    }

    #[test]
    fn l1_turns_toward_the_line() {
        let l = RefLine {
            north_m: 0.0,
            east_m: 0.0,
            heading_rad: 0.0,
        };
        // Left of the line (negative cross), flying north: turn right.
        assert!(l1_bank(&l, 0.0, -100.0, 0.0, 70.0, 800.0, 0.44) > 0.0);
        // Right of the line: turn left.
        assert!(l1_bank(&l, 0.0, 100.0, 0.0, 70.0, 800.0, 0.44) < 0.0);
        // On the line, on course: wings level.
        assert!(l1_bank(&l, 0.0, 0.0, 0.0, 70.0, 800.0, 0.44).abs() < 1e-12);
        // Flying south with the line 2 km to the east (on the left): bank
        // limit, left turn.
        let b = l1_bank(&l, 0.0, -2000.0, std::f64::consts::PI, 70.0, 800.0, 0.44);
        assert!((b + 0.44).abs() < 1e-12, "{b}");
    }

    proptest::proptest! {
        /// `point` and `along_cross` are inverse: a point at along-track `s`
        /// moved by `c` to the right has coordinates `(s, c)`.
        #[test]
        fn along_cross_round_trip(n0 in -1e4f64..1e4, e0 in -1e4f64..1e4, h in -7.0f64..7.0, s in -2e4f64..2e4, c in -5e3f64..5e3) {
            let l = RefLine { north_m: n0, east_m: e0, heading_rad: h };
            let (pn, pe) = l.point(s);
            let (pn, pe) = (pn - c * h.sin(), pe + c * h.cos());
            let (a, x) = l.along_cross(pn, pe);
            proptest::prop_assert!((a - s).abs() < 1e-8 && (x - c).abs() < 1e-8);
        }
    }
}
