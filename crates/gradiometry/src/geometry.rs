//! Gradiometer geometry: four sensors at known offsets `δr_i` (m) from the
//! system's measuring centre, in the system (body) frame (seed `004_…`,
//! eq. 5 and eq. 20; spec `gradiometry.md`, "Measuring systems").
//!
//! A *tensor* gradiometer carries four vector sensors, a *scalar* (the
//! seed's "vector") gradiometer four scalar sensors; both use the same
//! layouts. Every layout is centred (`Σ δr_i = 0`) so the measuring centre is
//! the sensors' centroid; `baseline_m` is the distance between neighbouring
//! sensors:
//!
//! - [`Layout::Tetrahedron`]: regular tetrahedron with edge `baseline_m`
//!   (vertices along `(±1, ±1, ±1)` with an even number of minus signs);
//! - [`Layout::Cross`]: a base sensor and three arms of length `baseline_m`
//!   along the body x, y and z axes (orthogonal cross), re-centred;
//! - [`Layout::Planar`]: a horizontal square with side `baseline_m` (all
//!   sensors in the body x–y plane; the vertical gradient is then seen only
//!   through the exact, non-linear differences).

use crate::error::{GradiometryError, Result, in_range};
use nalgebra::{Matrix3, Vector3};

/// The arrangement of the four sensors (`"tetrahedron"`, `"cross"`,
/// `"planar"` in scenario files).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Layout {
    /// Regular tetrahedron, edge = baseline.
    Tetrahedron,
    /// Base sensor plus arms along x, y, z of length = baseline.
    Cross,
    /// Horizontal square, side = baseline.
    Planar,
}

/// Baseline range of a gradiometer, m: 1 mm (sensor heads cannot be closer)
/// to 100 m (beyond that the sensors no longer see one object's gradient,
/// and a dipole source would be inside the array).
pub const BASELINE_RANGE_M: (f64, f64) = (1e-3, 100.0);

/// Four sensor offsets (m) from the measuring centre, body frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Geometry {
    offsets_m: [Vector3<f64>; 4],
}

impl Geometry {
    /// A standard `layout` with neighbour distance `baseline_m` (m).
    ///
    /// `baseline_m` must be within [`BASELINE_RANGE_M`].
    pub fn new(layout: Layout, baseline_m: f64) -> Result<Self> {
        let b = in_range(
            "baseline_m",
            baseline_m,
            BASELINE_RANGE_M.0,
            BASELINE_RANGE_M.1,
        )?;
        let raw = match layout {
            Layout::Tetrahedron => {
                // Edge of (±1,±1,±1)-tetrahedron is 2√2.
                let s = b / (2.0 * std::f64::consts::SQRT_2);
                [
                    Vector3::new(1.0, 1.0, 1.0) * s,
                    Vector3::new(1.0, -1.0, -1.0) * s,
                    Vector3::new(-1.0, 1.0, -1.0) * s,
                    Vector3::new(-1.0, -1.0, 1.0) * s,
                ]
            }
            Layout::Cross => [
                Vector3::new(b, 0.0, 0.0),
                Vector3::new(0.0, b, 0.0),
                Vector3::new(0.0, 0.0, b),
                Vector3::zeros(),
            ],
            Layout::Planar => {
                let h = 0.5 * b;
                [
                    Vector3::new(h, h, 0.0),
                    Vector3::new(h, -h, 0.0),
                    Vector3::new(-h, h, 0.0),
                    Vector3::new(-h, -h, 0.0),
                ]
            }
        };
        Self::from_offsets(raw)
    }

    /// Arbitrary offsets (m), re-centred on their centroid. Errors when they
    /// are not finite or two sensors coincide (closer than 1 mm).
    pub fn from_offsets(offsets_m: [Vector3<f64>; 4]) -> Result<Self> {
        if offsets_m.iter().any(|v| !v.iter().all(|c| c.is_finite())) {
            return Err(GradiometryError::NotFinite { name: "offsets_m" });
        }
        for i in 0..4 {
            for j in i + 1..4 {
                if (offsets_m[i] - offsets_m[j]).norm() < 1e-3 {
                    return Err(GradiometryError::DegenerateGeometry(format!(
                        "sensors {i} and {j} coincide"
                    )));
                }
            }
        }
        let c = offsets_m.iter().sum::<Vector3<f64>>() / 4.0;
        Ok(Self {
            offsets_m: offsets_m.map(|v| v - c),
        })
    }

    /// The offsets `δr_i` (m), centroid at zero.
    pub fn offsets_m(&self) -> &[Vector3<f64>; 4] {
        &self.offsets_m
    }

    /// Rank of the spread matrix `Σ δr_i δr_iᵀ` (3 for a solid layout, 2 for
    /// a planar one).
    pub fn rank(&self) -> usize {
        let s: Matrix3<f64> = self.offsets_m.iter().map(|v| v * v.transpose()).sum();
        s.rank(1e-9 * s.norm())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layouts_have_the_requested_baseline_and_are_centred() {
        for (l, rank) in [
            (Layout::Tetrahedron, 3),
            (Layout::Cross, 3),
            (Layout::Planar, 2),
        ] {
            let g = Geometry::new(l, 0.7).unwrap();
            let o = g.offsets_m();
            assert!(o.iter().sum::<Vector3<f64>>().norm() < 1e-15);
            let dmin = (0..4)
                .flat_map(|i| (i + 1..4).map(move |j| (i, j)))
                .map(|(i, j)| (o[i] - o[j]).norm())
                .fold(f64::INFINITY, f64::min);
            assert!((dmin - 0.7).abs() < 1e-12, "{l:?}: {dmin}");
            assert_eq!(g.rank(), rank);
        }
    }

    #[test]
    fn bad_input_is_an_error() {
        assert!(Geometry::new(Layout::Cross, 0.0).is_err());
        assert!(Geometry::new(Layout::Cross, f64::NAN).is_err());
        let z = Vector3::zeros();
        assert!(Geometry::from_offsets([z, z, Vector3::x(), Vector3::y()]).is_err());
    }
}
