//! Closed-form relative positioning in the field of three dipoles (seed
//! `001_…`, part I summarised in spec `em-positioning.md`, "Base algorithm").
//!
//! Measured field matrix (T), columns = the three transmitter dipoles' fields
//! in receiver axes:
//!
//! ```text
//! H = R Ω(r) M,   Ω(r) = μ0/(4π L³) (3 e eᵀ − I),   L = |r|, e = r/L
//! ```
//!
//! 1. [`gram`]: `HᵀH = Mᵀ Ω² M` does not depend on `R`; whitened
//!    `W = M⁻ᵀ HᵀH M⁻¹ = Ω²` has eigenvalues `K², K², 4K²`, `K = μ0/(4π L³)`.
//! 2. [`closed_form`](mod@closed_form): range from the eigenvalues, direction `±e` from the
//!    eigenvector of the largest, `R = H (Ω M)⁻¹` projected onto SO(3)
//!    ([`so3`]); `Ω(r) = Ω(−r)` so the sign of `e` is chosen by
//!    [`hemisphere`].
//! 3. [`polish`](mod@polish): Levenberg–Marquardt on the full model with all nine
//!    measured components.
//! 4. [`error_study`](mod@error_study): Monte-Carlo errors versus range and noise.

pub mod closed_form;
pub mod error_study;
pub mod gram;
pub mod hemisphere;
pub mod polish;
pub mod so3;

pub use closed_form::{ClosedForm, closed_form};
pub use error_study::{ErrorPoint, error_study};
pub use gram::{gram_matrix, whitened_gram};
pub use hemisphere::Hemisphere;
pub use polish::{PolishOptions, Polished, polish};
pub use so3::project_to_so3;

use aeromag_core::field::dipole::dipole_matrix;
use nalgebra::{Matrix3, Vector3};

/// Forward model `H = R Ω(r) M` (T): receiver at `r_m` (m, transmitter frame),
/// rotation `r_rx` (transmitter-frame vectors → receiver axes), moments
/// `moments` (A·m², columns = dipoles).
pub fn field_matrix(
    r_m: &Vector3<f64>,
    r_rx: &Matrix3<f64>,
    moments: &Matrix3<f64>,
) -> Matrix3<f64> {
    r_rx * dipole_matrix(r_m) * moments
}

/// A full positioning solution for one epoch.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Pose {
    /// Receiver position in the transmitter frame, m.
    pub position_m: Vector3<f64>,
    /// Rotation taking transmitter-frame vectors into receiver axes.
    pub rotation: Matrix3<f64>,
}

impl Pose {
    /// Range `|r|`, m.
    pub fn range_m(&self) -> f64 {
        self.position_m.norm()
    }

    /// Receiver attitude relative to the transmitter frame as Z-Y-X Euler
    /// angles: the rotation receiver → transmitter is `Rᵀ`, interpreted as
    /// `C_nb` of [`aeromag_core::frames::Attitude`].
    pub fn attitude(&self) -> aeromag_core::frames::Attitude {
        aeromag_core::frames::Attitude::from_c_nb(&self.rotation.transpose())
    }
}

/// Angle between two unit-or-not vectors, rad (0 if either is zero).
pub fn angle_between(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    let c = a.cross(b).norm();
    let d = a.dot(b);
    if c == 0.0 && d == 0.0 {
        0.0
    } else {
        c.atan2(d)
    }
}

/// Rotation angle of `a bᵀ`, rad: the angle of the rotation that takes `b`
/// onto `a` (both rotation matrices); the attitude error measure.
pub fn rotation_angle_between(a: &Matrix3<f64>, b: &Matrix3<f64>) -> f64 {
    let d = a * b.transpose();
    let c = ((d.trace() - 1.0) / 2.0).clamp(-1.0, 1.0);
    // acos is ill-conditioned near 0; use the skew part for the sine.
    let s = 0.5
        * Vector3::new(
            d[(2, 1)] - d[(1, 2)],
            d[(0, 2)] - d[(2, 0)],
            d[(1, 0)] - d[(0, 1)],
        )
        .norm();
    s.atan2(c)
}
