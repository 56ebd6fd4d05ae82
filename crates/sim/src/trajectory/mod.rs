//! Fixed-wing trajectories: a kinematic aircraft that follows a flight plan
//! of straight tracks and turns, with manoeuvres and turbulence.
//!
//! The true state of the navigation reference point (the body origin,
//! nominally the centre of gravity and GNSS/INS reference) is produced on a
//! uniform time grid `t_k = k Δt` by [`flight::fly`]. The kinematics are
//! consistent by construction (spec `simulator.md`, "Scenarios"):
//!
//! ```text
//! χ̇  = g tan φ / V                      coordinated turn: track rate from bank
//! v  = V (cos γ cos χ, cos γ sin χ, −sin γ)           NED velocity, m/s
//! p_{k+1} = p_k + Δt (v_k + v_{k+1})/2                positions integrate velocities
//! χ_{k+1} = χ_k + Δt g tan φ_k / V                    track integrates turn rate
//! roll φ,   pitch θ = γ + α₀ + δθ,   yaw ψ = χ + β      attitude
//! ```
//!
//! `V` is the constant true airspeed (no wind: ground speed = airspeed), `γ`
//! the flight-path angle (altitude hold + pitch manoeuvre + turbulence),
//! `α₀` the trim angle of attack, `δθ` an attitude-only pitch disturbance and
//! `β` a flat-yaw (sideslip) offset from yaw manoeuvres and turbulence.
//!
//! * [`guidance`] — L1 lateral guidance (line capture and tracking) and the
//!   altitude hold.
//! * [`manoeuvre`] — the roll, pitch and yaw manoeuvre blocks of a
//!   calibration leg.
//! * [`turbulence`] — smooth coloured noise in bank, pitch, yaw and
//!   flight-path angle.
//! * [`flight`] — the integrator and the flight-plan segments.

pub mod flight;
pub mod guidance;
pub mod manoeuvre;
pub mod turbulence;

pub use flight::{FlightPlan, KinematicsConfig, Segment, SegmentEnd, StartState, TrackLine, fly};
pub use guidance::RefLine;
pub use manoeuvre::{ManoeuvreBlock, ManoeuvreKind};
pub use turbulence::TurbulenceConfig;

/// True kinematic state history of the navigation reference point.
#[derive(Debug, Clone, Default)]
pub struct Trajectory {
    /// Sample interval, s.
    pub dt_s: f64,
    /// Time since the start of the flight, s.
    pub t_s: Vec<f64>,
    /// North offset from the scenario origin, m.
    pub north_m: Vec<f64>,
    /// East offset from the scenario origin, m.
    pub east_m: Vec<f64>,
    /// Altitude (WGS84 ellipsoidal height), m.
    pub alt_m: Vec<f64>,
    /// Velocity north, m/s.
    pub vn: Vec<f64>,
    /// Velocity east, m/s.
    pub ve: Vec<f64>,
    /// Velocity down, m/s.
    pub vd: Vec<f64>,
    /// Roll φ, rad.
    pub roll: Vec<f64>,
    /// Pitch θ, rad.
    pub pitch: Vec<f64>,
    /// Yaw ψ, rad, wrapped to (−π, π].
    pub yaw: Vec<f64>,
    /// Line label (0 in turns and transits).
    pub line: Vec<f64>,
    /// Manoeuvre code: 0 none, 1 roll, 2 pitch, 3 yaw.
    pub manoeuvre: Vec<f64>,
}

impl Trajectory {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t_s.len()
    }

    /// True when there are no samples.
    pub fn is_empty(&self) -> bool {
        self.t_s.is_empty()
    }

    /// Attitude of sample `k`.
    pub fn attitude(&self, k: usize) -> aeromag_core::frames::Attitude {
        aeromag_core::frames::Attitude::new(self.roll[k], self.pitch[k], self.yaw[k])
    }
}
