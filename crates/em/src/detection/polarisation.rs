//! Reduction of a complex field vector to the major axis of its polarisation
//! ellipse (seed `001_…` part II; spec `em-positioning.md`, "Signal chain"
//! item 4).
//!
//! For `h = a + i b` (`a, b` real 3-vectors) the real vector
//! `Re(e^{iφ} h) = a cos φ − b sin φ` traces the ellipse. Its squared length
//! is `S/2 + (D/2) cos 2φ − (a·b) sin 2φ` with `S = |a|² + |b|²`,
//! `D = |a|² − |b|²`, so
//!
//! ```text
//! 2φ* = atan2(−2 a·b, D)           (φ* ∈ (−π/2, π/2], major axis nearest a)
//! |major|² = S/2 + ρ,  |minor|² = S/2 − ρ,  ρ = √(D²/4 + (a·b)²)
//! ratio = |minor|/|major|           (0 for a linearly polarised field)
//! ```
//!
//! The sign of the major axis follows the detection phase: it is the one
//! nearer `Re h`, so the detector reference phase must be within ±90° of the
//! signal phase (set by calibration).

use super::Complex64;
use nalgebra::Vector3;

/// The polarisation ellipse of one complex vector.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PolarisationEllipse {
    /// Major semi-axis `Re(e^{iφ*} h)`, in the units of `h`.
    pub major: Vector3<f64>,
    /// Minor semi-axis `Re(e^{i(φ*+π/2)} h)`, in the units of `h`.
    pub minor: Vector3<f64>,
    /// Rotation `φ*` that makes `h` as real as possible, rad.
    pub phase_rad: f64,
    /// `|minor|/|major|` in [0, 1] (dimensionless quality figure).
    pub ratio: f64,
}

/// Major axis, minor axis and polarisation ratio of `h` (closed form above).
/// A zero vector gives zero axes and ratio 0.
pub fn major_axis(h: &[Complex64; 3]) -> PolarisationEllipse {
    let a = Vector3::new(h[0].re, h[1].re, h[2].re);
    let b = Vector3::new(h[0].im, h[1].im, h[2].im);
    let ab = a.dot(&b);
    let d = a.norm_squared() - b.norm_squared();
    let phi = 0.5 * (-2.0 * ab).atan2(d);
    let (s, c) = phi.sin_cos();
    let major = a * c - b * s;
    let minor = -a * s - b * c;
    let mj = major.norm();
    let ratio = if mj > 0.0 {
        (minor.norm() / mj).min(1.0)
    } else {
        0.0
    };
    PolarisationEllipse {
        major,
        minor,
        phase_rad: phi,
        ratio,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// A linearly polarised vector with any phase returns its real
        /// direction, ratio 0; the major axis is the maximum over φ.
        #[test]
        fn linear_vector_and_maximality(
            x in -1.0..1.0f64, y in -1.0..1.0f64, z in 0.1..1.0f64,
            ph in -1.5..1.5f64, bx in -0.2..0.2f64, by in -0.2..0.2f64,
        ) {
            let v = Vector3::new(x, y, z);
            let e = Complex64::from_polar(1.0, ph);
            let h = [e * v[0], e * v[1], e * v[2]];
            let el = major_axis(&h);
            prop_assert!((el.major - v).norm() < 1e-12);
            prop_assert!(el.ratio < 1e-8);
            // Elliptical: |major| ≥ |Re(e^{iφ} h)| for a grid of φ.
            let g = [h[0] + Complex64::new(0.0, bx), h[1] + Complex64::new(0.0, by), h[2]];
            let el2 = major_axis(&g);
            for k in 0..64 {
                let p = std::f64::consts::PI * k as f64 / 64.0;
                let r = Complex64::from_polar(1.0, p);
                let w = Vector3::new((r * g[0]).re, (r * g[1]).re, (r * g[2]).re);
                prop_assert!(w.norm() <= el2.major.norm() * (1.0 + 1e-12));
            }
            prop_assert!(el2.major.dot(&el2.minor).abs() < 1e-12 * (1.0 + el2.major.norm_squared()));
        }
    }

    #[test]
    fn known_ellipse_ratio() {
        // a = (2,0,0), b = (0,0.5,0): ratio 0.25, major along x.
        let h = [
            Complex64::new(2.0, 0.0),
            Complex64::new(0.0, 0.5),
            Complex64::new(0.0, 0.0),
        ];
        let el = major_axis(&h);
        assert!((el.ratio - 0.25).abs() < 1e-15);
        assert!((el.major - Vector3::new(2.0, 0.0, 0.0)).norm() < 1e-15);
        assert_eq!(major_axis(&[Complex64::new(0.0, 0.0); 3]).ratio, 0.0);
    }
}
