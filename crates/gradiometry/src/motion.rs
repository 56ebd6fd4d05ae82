//! Motion models `MotionMT` (tensor, state `(r, M)`) and `MotionMV` (scalar,
//! state `M`) of seed `004_…` (eqs. 17–18, 29; spec `gradiometry.md`), and
//! the scalar system's model with a separate induced moment
//! ([`motion_mv_induced`], state `(M_p, M_i)`).
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
//!
//! **Permanent and induced moment** ([`motion_mv_induced`], the scalar
//! system's estimator). Turning the whole moment with the object is wrong
//! for its induced part: an object of susceptibility `K` (A·m²/nT, in its
//! own axes) in the Earth's field `B_e` (nT, navigation frame) carries
//!
//! ```text
//! M_n(t) = C_no(t) M_perm + C_no(t) K C_on(t) B_e
//!        = C_no(t) M_perm + k̄ B_e + C_no(t) (K − k̄ I) C_on(t) B_e,
//! ```
//!
//! the permanent moment turning with the heading, the isotropic part of the
//! induced one (`k̄ = trace K / 3`) fixed with the Earth's field, and an
//! anisotropic residue that changes with the heading. The model keeps the
//! first two, as six states in the system frame: the total moment the
//! sensors see and the induced part, `x = (M, M_i)` (A·m²; the permanent
//! part is `M_p = M − M_i`). With `M_p` turning at `ω_o − ω_m` and `M_i`
//! at `−ω_m` (fixed in the navigation frame):
//!
//! ```text
//! M_j+1   = M_j + (ω_o − ω_m) × M_j Δt − ω_o × M_i,j Δt + q_M
//! M_i,j+1 = M_i,j − ω_m × M_i,j Δt
//! F = [[I + [(ω_o − ω_m)×]Δt, −[ω_o×]Δt], [0, I − [ω_m×]Δt]],   u = 0,
//! σ(q_M) = (σ_M + κ |ω_o| |M|) √Δt,   σ(q_i) = 0,
//! ```
//!
//! the process noise of `MotionMV` on the total only: the anisotropic
//! residue, which changes only when the object turns, and the slow drift
//! of the permanent moment change the moment the sensors see, while the
//! isotropic induced moment is constant. At a constant heading (`ω_o = 0`)
//! `M` moves as in `MotionMV` and `M_i` is not observed: the model is the
//! 3-state one, and `M_i`'s prior keeps the problem well posed; when the
//! object turns, the change of `M` tells the parts apart.

use aeromag_core::frames::Attitude;
use aeromag_core::frames::attitude::wrap_pi;
use nalgebra::{Matrix3, Rotation3, SMatrix, SVector, Vector3};

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

/// Navigation of both bodies at one epoch: what a measuring system knows
/// about the motion (the system's own navigation and the object's track).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NavFix {
    /// System position, local NED, m.
    pub system_position_ned_m: Vector3<f64>,
    /// System attitude.
    pub system_attitude: Attitude,
    /// Object position, local NED, m.
    pub object_position_ned_m: Vector3<f64>,
    /// Object heading, rad.
    pub object_yaw_rad: f64,
}

impl Motion {
    /// The motion over the step `dt_s` (s) from fix `prev` to fix `next`,
    /// in the body frame of `next`'s attitude `C_bn`:
    ///
    /// ```text
    /// V_m = C_bn Δp_m/Δt,  V_o = C_bn Δp_o/Δt,  ω_o = C_bn (0, 0, Δψ_o/Δt),
    /// exp([ω_m×] Δt) = C_nb(prev)ᵀ C_nb(next)  (body rate, rotation vector / Δt)
    /// ```
    ///
    /// Exact for constant velocities and rates. `dt_s ≤ 0` (the first epoch)
    /// gives zero motion with `dt_s = 0`.
    pub fn between(prev: &NavFix, next: &NavFix, dt_s: f64) -> Self {
        if dt_s.is_nan() || dt_s <= 0.0 {
            return Self {
                v_object: Vector3::zeros(),
                v_system: Vector3::zeros(),
                w_object: Vector3::zeros(),
                w_system: Vector3::zeros(),
                dt_s: 0.0,
            };
        }
        let c_bn = next.system_attitude.c_bn();
        let turn = prev.system_attitude.c_nb().transpose() * next.system_attitude.c_nb();
        let yaw_rate = wrap_pi(next.object_yaw_rad - prev.object_yaw_rad) / dt_s;
        Self {
            v_object: c_bn * (next.object_position_ned_m - prev.object_position_ned_m) / dt_s,
            v_system: c_bn * (next.system_position_ned_m - prev.system_position_ned_m) / dt_s,
            w_object: c_bn * Vector3::new(0.0, 0.0, yaw_rate),
            w_system: Rotation3::from_matrix(&turn).scaled_axis() / dt_s,
            dt_s,
        }
    }
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

/// The model with the induced part (module docs): `(F, u = 0, S_Q)` of the
/// 6 states `(M, M_i)`, total and induced moment, system frame, A·m²;
/// `moment` is the characteristic moment `|M|` of the noise's induced term,
/// A·m² (the noise is `MotionMV`'s, on `M` only).
pub fn motion_mv_induced(
    m: &Motion,
    noise: &MotionNoise,
    moment: &Vector3<f64>,
) -> (SMatrix<f64, 6, 6>, SVector<f64, 6>, SVector<f64, 6>) {
    let (fm, _, qm) = motion_mv(m, noise, moment);
    let mut f = SMatrix::<f64, 6, 6>::zeros();
    f.fixed_view_mut::<3, 3>(0, 0).copy_from(&fm);
    f.fixed_view_mut::<3, 3>(0, 3)
        .copy_from(&(-skew(&m.w_object) * m.dt_s));
    f.fixed_view_mut::<3, 3>(3, 3)
        .copy_from(&(Matrix3::identity() - skew(&m.w_system) * m.dt_s));
    let mut q = SVector::<f64, 6>::zeros();
    q.fixed_rows_mut::<3>(0).copy_from(&qm);
    (f, SVector::zeros(), q)
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

    #[test]
    fn the_permanent_moment_turns_with_the_object_and_the_induced_one_does_not() {
        let noise = MotionNoise {
            position_m_per_sqrt_s: 0.0,
            moment_am2_per_sqrt_s: 2.0,
            induced_per_rad: 1.0,
        };
        let m = Motion {
            v_object: Vector3::zeros(),
            v_system: Vector3::zeros(),
            w_object: Vector3::new(0.0, 0.0, 0.1),
            w_system: Vector3::zeros(),
            dt_s: 0.01,
        };
        let scale = Vector3::new(1500.0, 0.0, 0.0);
        let (f, u, q) = motion_mv_induced(&m, &noise, &scale);
        // M_p = (100, 0, 0) turns by ω_o Δt = 1 mrad about down, M_i = (50, 0, 0) stays
        let x = SVector::<f64, 6>::from([150.0, 0.0, 0.0, 50.0, 0.0, 0.0]);
        let x1 = f * x + u;
        assert!((x1[0] - 150.0).abs() < 1e-12 && (x1[1] - 0.1).abs() < 1e-12);
        assert!(x1[3] == 50.0 && x1[4] == 0.0);
        assert_eq!(q.fixed_rows::<3>(0), motion_mv(&m, &noise, &scale).2);
        assert_eq!(q.fixed_rows::<3>(3).norm(), 0.0);
        // a turning system sees both parts turn backwards alike
        let turn = Motion {
            w_object: Vector3::zeros(),
            w_system: Vector3::new(0.0, 0.0, 0.1),
            ..m
        };
        let (f, _, _) = motion_mv_induced(&turn, &noise, &scale);
        let x1 = f * x;
        assert!((x1[1] + 0.15).abs() < 1e-12 && (x1[4] + 0.05).abs() < 1e-12);
    }

    #[test]
    fn motion_between_fixes_recovers_velocities_and_rates() {
        let dt = 0.1;
        let att0 = Attitude::from_degrees(2.0, -3.0, 40.0);
        let w_b = Vector3::new(0.01, -0.02, 0.05); // body rate, rad/s
        let c1 = att0.c_nb() * Rotation3::from_scaled_axis(w_b * dt).into_inner();
        let att1 = Attitude::from_c_nb(&c1);
        let a = NavFix {
            system_position_ned_m: Vector3::new(1.0, 2.0, 3.0),
            system_attitude: att0,
            object_position_ned_m: Vector3::new(10.0, 0.0, 0.0),
            object_yaw_rad: 3.1,
        };
        let b = NavFix {
            system_position_ned_m: a.system_position_ned_m + Vector3::new(0.5, -0.2, 0.0),
            system_attitude: att1,
            object_position_ned_m: a.object_position_ned_m + Vector3::new(0.0, 0.3, 0.1),
            object_yaw_rad: 3.1 + 0.1 - std::f64::consts::TAU, // wraps
        };
        let m = Motion::between(&a, &b, dt);
        assert!((m.w_system - w_b).norm() < 1e-9, "{}", m.w_system);
        let c_bn = att1.c_bn();
        assert!((m.v_system - c_bn * Vector3::new(5.0, -2.0, 0.0)).norm() < 1e-9);
        assert!((m.v_object - c_bn * Vector3::new(0.0, 3.0, 1.0)).norm() < 1e-9);
        assert!((m.w_object - c_bn * Vector3::new(0.0, 0.0, 1.0)).norm() < 1e-9);
        assert_eq!(Motion::between(&a, &b, 0.0).dt_s, 0.0);
    }
}
