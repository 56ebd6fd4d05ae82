//! Resolution of the `±r` ambiguity (seed `001_…` part I; spec
//! `em-positioning.md`: "resolve the hemisphere from a prior half-space (a
//! towed bird is behind and below) and continuity").
//!
//! `Ω(r) = Ω(−r)`, so the data fix the direction only up to sign. The sign
//! is chosen so that `e · n > 0` for the configured half-space normal `n`;
//! when `|e · n|` falls below `margin` (the direction is nearly in the
//! dividing plane) the sign closest to the previous epoch's direction wins.

use nalgebra::Vector3;

/// Half-space prior plus continuity memory for the sign of the direction.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Hemisphere {
    /// Normal of the half-space the receiver is assumed in (transmitter frame).
    pub normal: Vector3<f64>,
    /// Below this `|e·n|/|n|` the previous direction decides (dimensionless).
    pub margin: f64,
    /// Direction of the previous epoch (unit), if any.
    pub previous: Option<Vector3<f64>>,
    /// Whether the last [`Hemisphere::resolve`] was decided by continuity
    /// (direction within `margin` of the dividing plane) rather than by the
    /// half-space: a quality flag of the epoch.
    #[serde(default)]
    pub by_continuity: bool,
}

impl Hemisphere {
    /// A prior half-space `e · normal > 0` with a continuity margin of 0.2
    /// (≈ 11.5° from the dividing plane).
    /// The normal is kept scaled by its largest component (a zero or
    /// non-finite normal is kept as given and decides nothing), so that its
    /// length can neither overflow nor underflow.
    pub fn new(normal: Vector3<f64>) -> Self {
        let m = normal.amax();
        let normal = if m > 0.0 && m.is_finite() {
            normal / m
        } else {
            normal
        };
        Self {
            normal,
            margin: 0.2,
            previous: None,
            by_continuity: false,
        }
    }

    /// `e·n/|n|` of a unit direction `e`: its side of the dividing plane
    /// (0 for a zero or non-finite normal, which decides nothing).
    pub fn side(&self, e: &Vector3<f64>) -> f64 {
        let n = self.normal.norm();
        if n > 0.0 {
            e.dot(&self.normal) / n
        } else {
            0.0
        }
    }

    /// Whether the half-space alone decides the sign of `e` (unit):
    /// `|e·n|/|n| ≥ margin`. The same for `e` and `−e`.
    pub fn decisive(&self, e: &Vector3<f64>) -> bool {
        self.side(e).abs() >= self.margin
    }

    /// Orient `e` (unit) and remember it for the next epoch.
    pub fn resolve(&mut self, e: &Vector3<f64>) -> Vector3<f64> {
        let s = self.side(e);
        let flip = match self.previous {
            Some(p) if s.abs() < self.margin => {
                self.by_continuity = true;
                e.dot(&p) < 0.0
            }
            _ => {
                self.by_continuity = false;
                s < 0.0
            }
        };
        let out = if flip { -e } else { *e };
        self.previous = Some(out);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_space_then_continuity() {
        // Bird behind (−x) and below (+z, NED-like): normal (−1, 0, 1).
        let mut h = Hemisphere::new(Vector3::new(-1.0, 0.0, 1.0));
        let e = Vector3::new(-0.8, 0.0, 0.6).normalize();
        assert!(h.resolve(&(-e)).dot(&e) > 0.99);
        // Nearly in the dividing plane: continuity wins over the weak prior.
        let e2 = Vector3::new(0.68, 0.1, 0.72).normalize(); // e·n ≈ +0.03
        let mut h2 = Hemisphere::new(Vector3::new(-1.0, 0.0, 1.0));
        h2.previous = Some(-e2);
        assert!(h2.resolve(&e2).dot(&e2) < 0.0);
        assert!(h2.by_continuity);
        assert!(h2.resolve(&e).dot(&e) > 0.99 && !h2.by_continuity);
    }

    /// `|n|` of (−1e160, 0, 1e160) overflowed (of ±1e-200 underflowed), so
    /// `e·n/|n|` was 0 and the half-space decided nothing: the direction
    /// kept the eigenvector's arbitrary sign.
    #[test]
    fn extreme_normals_keep_their_direction() {
        let e = Vector3::new(-0.8, 0.0, 0.6).normalize();
        for s in [1e160, 1e-200, 1e300, 5e-324, 1.0] {
            let mut h = Hemisphere::new(Vector3::new(-s, 0.0, s));
            assert!(h.resolve(&(-e)).dot(&e) > 0.99, "scale {s}");
            assert!(!h.by_continuity, "scale {s}");
            let mut h = Hemisphere::new(Vector3::new(s, 0.0, -s));
            assert!(h.resolve(&e).dot(&e) < -0.99, "scale {s}");
        }
    }
}
