//! Motion models `MotionMT` (tensor, state `(r, M)`) and `MotionMV` (scalar,
//! state `M`) of seed `004_…` (eqs. 17–18, 29; spec `gradiometry.md`).
//!
//! With `r` the object's position relative to the measuring system and `M`
//! its moment, both in the system's frame, the object's and the system's
//! linear velocities `V_o`, `V_m` (m/s) and angular rates `ω_o`, `ω_m`
//! (rad/s), all in the system frame, over a step `Δt` (s):
//!
//! ```text
//! r_{j+1} = r_j + (V_o − V_m − ω_m × r_j) Δt + q_r
//! M_{j+1} = M_j + (ω_o − ω_m) × M_j Δt + q_M
//! F = [[I − [ω_m×]Δt, 0], [0, I + [(ω_o − ω_m)×]Δt]],
//! ```
//!
//! so the transition is affine: `x_{j+1} = F x_j + u` with
//! `u = ((V_o − V_m) Δt, 0)`. The process noise square root `S_Q` is
//! diagonal: `σ_r √Δt` for the position (characteristic relative speed
//! uncertainty as a random walk, m/√s) and
//! `(σ_M + κ |ω_o| |M|) √Δt` for the moment, the term in `|ω_o|` standing
//! for the induced part that changes with the object's orientation.

use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

/// Known relative motion over one step (system frame, SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Motion {
    /// Object velocity, m/s.
    pub v_object: Vector3<f64>,
    /// System velocity, m/s.
    pub v_system: Vector3<f64>,
    /// Object angular rate, rad/s.
    pub w_object: Vector3<f64>,
    /// System angular rate, rad/s.
    pub w_system: Vector3<f64>,
    /// Step, s.
    pub dt_s: f64,
}

/// Random-walk intensities of the model noise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionNoise {
    /// Position random walk, m/√s.
    pub position_m_per_sqrt_s: f64,
    /// Moment random walk, A·m²/√s.
    pub moment_am2_per_sqrt_s: f64,
    /// Induced-moment coefficient `κ` (per rad): moment noise grows by
    /// `κ |ω_o| |M|` (A·m²/√s).
    pub induced_per_rad: f64,
}

/// Skew matrix `[a×]` with `[a×] b = a × b` (eq. 18).
pub fn skew(a: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
}

/// `MotionMT`: `(F, u, S_Q)` of the 6-state model (module docs); `moment`
/// is the current moment estimate (for the induced term), A·m².
pub fn motion_mt(
    m: &Motion,
    noise: &MotionNoise,
    moment: &Vector3<f64>,
) -> (SMatrix<f64, 6, 6>, SVector<f64, 6>, SVector<f64, 6>) {
    let mut f = SMatrix::<f64, 6, 6>::identity();
    f.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&(Matrix3::identity() - skew(&m.w_system) * m.dt_s));
    let (fm, _, qm) = motion_mv(m, noise, moment);
    f.fixed_view_mut::<3, 3>(3, 3).copy_from(&fm);
    let mut u = SVector::<f64, 6>::zeros();
    u.fixed_rows_mut::<3>(0)
        .copy_from(&((m.v_object - m.v_system) * m.dt_s));
    let qr = noise.position_m_per_sqrt_s * m.dt_s.max(0.0).sqrt();
    let mut q = SVector::<f64, 6>::repeat(qr);
    q.fixed_rows_mut::<3>(3).copy_from(&qm);
    (f, u, q)
}

/// `MotionMV`: `(F, u = 0, S_Q)` of the 3-state (moment) model.
pub fn motion_mv(
    m: &Motion,
    noise: &MotionNoise,
    moment: &Vector3<f64>,
) -> (Matrix3<f64>, Vector3<f64>, Vector3<f64>) {
    let f = Matrix3::identity() + skew(&(m.w_object - m.w_system)) * m.dt_s;
    let qm = (noise.moment_am2_per_sqrt_s
        + noise.induced_per_rad * m.w_object.norm() * moment.norm())
        * m.dt_s.max(0.0).sqrt();
    (f, Vector3::zeros(), Vector3::repeat(qm))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_of_the_system_turns_the_relative_position() {
        // System yawing at 0.1 rad/s: a fixed object appears to rotate backwards.
        let m = Motion {
            v_object: Vector3::zeros(),
            v_system: Vector3::new(1.0, 0.0, 0.0),
            w_object: Vector3::zeros(),
            w_system: Vector3::new(0.0, 0.0, 0.1),
            dt_s: 0.01,
        };
        let noise = MotionNoise {
            position_m_per_sqrt_s: 0.0,
            moment_am2_per_sqrt_s: 0.0,
            induced_per_rad: 2.0,
        };
        let (f, u, q) = motion_mt(&m, &noise, &Vector3::new(10.0, 0.0, 0.0));
        let mut x = SVector::<f64, 6>::zeros();
        x[0] = 10.0;
        let x1 = f * x + u;
        // r' = r − V_m dt − ω×r dt = (10 − 0.01, −0.01, 0)
        assert!((x1[0] - 9.99).abs() < 1e-12 && (x1[1] + 0.01).abs() < 1e-12);
        assert_eq!(q[0], 0.0);
        let w = Motion {
            w_object: Vector3::new(0.0, 0.0, 0.5),
            ..m
        };
        let (_, _, q2) = motion_mt(&w, &noise, &Vector3::new(10.0, 0.0, 0.0));
        assert!((q2[3] - 2.0 * 0.5 * 10.0 * 0.1).abs() < 1e-12);
    }
}
