//! The trajectory integrator: a kinematic fixed-wing aircraft flying a
//! [`FlightPlan`] of straight tracks and scheduled turns (equations in the
//! [module docs](super)).
//!
//! Each step produces sample `k+1` from sample `k`:
//!
//! 1. `χ_{k+1} = χ_k + Δt g tan φ_k / V` (the turn rate of the bank held over
//!    the step);
//! 2. the active segment gives the bank for `k+1`: on a track the L1 command
//!    from the position at `k`, passed through a first-order lag
//!    (`τ_φ`, the roll response); in a scheduled turn `atan(V r_i/g)` of a
//!    raised-cosine turn-rate profile `r_i` scaled so that `Σ r_i Δt` is
//!    exactly the heading change; plus manoeuvre and turbulence offsets;
//! 3. `γ_{k+1}` is the altitude hold (from the altitude at `k`) plus the
//!    pitch manoeuvre and turbulence; `v_{k+1}` follows from `χ_{k+1}` and
//!    `γ_{k+1}`. While a manoeuvre block is active the pilot flies open loop:
//!    the L1 command is zero and the altitude hold is off, so whole cycles
//!    leave heading and altitude where they were;
//! 4. `p_{k+1} = p_k + Δt (v_k + v_{k+1})/2` (trapezoid: the position is the
//!    exact integral of the piecewise-linear velocity).

use aeromag_core::frames::attitude::wrap_pi;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::Trajectory;
use super::guidance::{G_M_S2, RefLine, altitude_hold, l1_bank};
use super::manoeuvre::{ManoeuvreBlock, offsets};
use super::turbulence::{Turbulence, TurbulenceConfig};
use crate::error::{Result, SimError, invalid, require_non_negative, require_positive};

/// Aircraft performance and autopilot settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct KinematicsConfig {
    /// True airspeed (= ground speed, no wind), m/s. Default 90 (calibration,
    /// at altitude) and 70 (survey), a turboprop survey aircraft.
    pub speed_m_s: f64,
    /// Bank-angle limit of the autopilot, deg. Default 25.
    pub max_bank_deg: f64,
    /// Time constant of the roll response to the bank command, s. Default 1.
    pub bank_time_constant_s: f64,
    /// L1 guidance distance, m. Default 600 (natural period of the track loop
    /// `2π L1/(√2 V)` ≈ 38 s at 70 m/s, damping 0.71).
    pub l1_distance_m: f64,
    /// Time constant of the altitude hold, s. Default 15.
    pub altitude_time_constant_s: f64,
    /// Flight-path-angle limit of the altitude hold, deg. Default 6.
    pub max_flight_path_deg: f64,
    /// Trim angle of attack (pitch minus flight-path angle), deg. Default 2.
    pub angle_of_attack_deg: f64,
    /// Turn rate of scheduled turns (calibration legs), deg/s. Default 3
    /// (rate-one turn).
    pub turn_rate_deg_s: f64,
    /// Duration of the raised-cosine roll-in and roll-out of scheduled turns, s.
    /// Default 4.
    pub turn_ramp_s: f64,
}

impl Default for KinematicsConfig {
    fn default() -> Self {
        Self {
            speed_m_s: 70.0,
            max_bank_deg: 25.0,
            bank_time_constant_s: 1.0,
            l1_distance_m: 600.0,
            altitude_time_constant_s: 15.0,
            max_flight_path_deg: 6.0,
            angle_of_attack_deg: 2.0,
            turn_rate_deg_s: 3.0,
            turn_ramp_s: 4.0,
        }
    }
}

impl KinematicsConfig {
    /// Check the values.
    pub fn validate(&self, p: &str) -> Result<()> {
        require_positive(&format!("{p}.speed_m_s"), self.speed_m_s)?;
        require_positive(
            &format!("{p}.bank_time_constant_s"),
            self.bank_time_constant_s,
        )?;
        require_positive(&format!("{p}.l1_distance_m"), self.l1_distance_m)?;
        require_positive(
            &format!("{p}.altitude_time_constant_s"),
            self.altitude_time_constant_s,
        )?;
        require_positive(&format!("{p}.turn_rate_deg_s"), self.turn_rate_deg_s)?;
        require_non_negative(&format!("{p}.turn_ramp_s"), self.turn_ramp_s)?;
        if !(self.max_bank_deg > 0.0 && self.max_bank_deg < 60.0) {
            return Err(invalid(
                format!("{p}.max_bank_deg"),
                "must be in (0, 60) deg",
            ));
        }
        if !(self.max_flight_path_deg > 0.0 && self.max_flight_path_deg < 30.0) {
            return Err(invalid(
                format!("{p}.max_flight_path_deg"),
                "must be in (0, 30) deg",
            ));
        }
        if !self.angle_of_attack_deg.is_finite() || self.angle_of_attack_deg.abs() >= 15.0 {
            return Err(invalid(
                format!("{p}.angle_of_attack_deg"),
                "must be in (−15, 15) deg",
            ));
        }
        Ok(())
    }

    /// Radius of a turn at the bank limit, m: `V²/(g tan φ_max)`.
    pub fn min_turn_radius_m(&self) -> f64 {
        self.speed_m_s.powi(2) / (G_M_S2 * self.max_bank_deg.to_radians().tan())
    }
}

/// When a segment ends.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SegmentEnd {
    /// After this many seconds.
    Duration(f64),
    /// When the along-track coordinate of the segment's line reaches this
    /// value (m) — after the line has been captured, for a segment with a
    /// labelled along-track range.
    Along(f64),
}

/// The line a track segment follows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TrackLine {
    /// A planned line (survey lines: position errors are corrected).
    Fixed(RefLine),
    /// The line through the position where the segment starts, with this
    /// direction (rad): calibration legs start wherever the turn ended.
    FromStart {
        /// Direction of flight, rad clockwise from north.
        heading_rad: f64,
    },
}

/// One element of a flight plan.
#[derive(Debug, Clone, PartialEq)]
pub enum Segment {
    /// Capture and follow a straight line (L1 guidance), optionally with
    /// manoeuvres.
    Track {
        /// The line.
        line: TrackLine,
        /// Altitude to hold, m.
        altitude_m: f64,
        /// End condition.
        end: SegmentEnd,
        /// Line label written while on the line.
        label: f64,
        /// Label only once captured and within this along-track range (m);
        /// `None` labels the whole segment.
        label_along: Option<(f64, f64)>,
        /// Manoeuvre blocks (times relative to the segment start).
        manoeuvres: Vec<ManoeuvreBlock>,
    },
    /// Scheduled turn to a heading (shortest direction), label 0.
    Turn {
        /// Target track angle, rad.
        heading_rad: f64,
        /// Altitude to hold, m.
        altitude_m: f64,
    },
}

/// Initial state of the aircraft.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StartState {
    /// North offset from the origin, m.
    pub north_m: f64,
    /// East offset, m.
    pub east_m: f64,
    /// Altitude, m.
    pub alt_m: f64,
    /// Track angle, rad.
    pub heading_rad: f64,
}

/// A start state and a list of segments.
#[derive(Debug, Clone, PartialEq)]
pub struct FlightPlan {
    /// The initial state.
    pub start: StartState,
    /// The segments, flown in order.
    pub segments: Vec<Segment>,
}

/// Capture thresholds: cross-track (m) and track-angle error (rad).
const CAPTURE_CROSS_M: f64 = 30.0;
const CAPTURE_ANGLE_RAD: f64 = 0.087;
/// Longest flight accepted, s (a plan that never ends is an error).
pub(crate) const MAX_FLIGHT_S: f64 = 24.0 * 3600.0;
/// Most samples of a simulated flight: its 50-odd columns take 8 GB at
/// this length (a day at 231 Hz; a high sample rate would otherwise run
/// out of memory before the day's limit).
pub const MAX_SAMPLES: usize = 20_000_000;

/// Runtime state of the active segment.
struct Runtime {
    /// The resolved line of a track segment.
    line: RefLine,
    /// Whether the line has been captured.
    captured: bool,
    /// Turn-rate samples of a scheduled turn, rad/s.
    rates: Vec<f64>,
}

/// Commands for one sample.
struct Cmd {
    /// Whether the altitude hold is engaged (not during manoeuvres).
    hold: bool,
    bank_base: f64,
    offsets: [f64; 3],
    code: f64,
    label: f64,
    target_alt: f64,
}

/// Fly `plan` at sample interval `dt_s` (s); turbulence draws from `rng`.
pub fn fly(
    plan: &FlightPlan,
    kin: &KinematicsConfig,
    turb_cfg: &TurbulenceConfig,
    dt_s: f64,
    rng: ChaCha8Rng,
) -> Result<Trajectory> {
    require_positive("sample interval", dt_s)?;
    if plan.segments.is_empty() {
        return Err(SimError::Trajectory(
            "the flight plan has no segments".into(),
        ));
    }
    let v = kin.speed_m_s;
    let max_bank = kin.max_bank_deg.to_radians();
    let max_gamma = kin.max_flight_path_deg.to_radians();
    let aoa = kin.angle_of_attack_deg.to_radians();
    let bank_gain = 1.0 - (-dt_s / kin.bank_time_constant_s).exp();
    let mut turb = Turbulence::new(turb_cfg, dt_s, rng);

    let mut tr = Trajectory {
        dt_s,
        ..Default::default()
    };
    let (mut n, mut e, mut h) = (plan.start.north_m, plan.start.east_m, plan.start.alt_m);
    let mut chi = plan.start.heading_rad;
    let mut bank_g = 0.0; // lagged guidance bank
    let mut seg = 0usize;
    let mut seg_k0 = 0usize;
    let mut active = activate(&plan.segments[0], n, e, chi, kin, dt_s)?;
    let max_samples = ((MAX_FLIGHT_S / dt_s) as usize).min(MAX_SAMPLES);

    // Commands of the active segment for its local sample `i_loc`, position
    // (n, e) and track angle chi; updates the lagged guidance bank.
    let commands = |seg: &Segment,
                    rt: &mut Runtime,
                    i_loc: usize,
                    n: f64,
                    e: f64,
                    chi: f64,
                    bank_g: &mut f64|
     -> Cmd {
        let tl = i_loc as f64 * dt_s;
        match seg {
            Segment::Track {
                altitude_m,
                label,
                label_along,
                manoeuvres,
                ..
            } => {
                let (offsets, code) = offsets(manoeuvres, tl);
                // The pilot flies manoeuvres open loop: no guidance while one is active.
                let cmd = if code == 0.0 {
                    l1_bank(&rt.line, n, e, chi, v, kin.l1_distance_m, max_bank)
                } else {
                    0.0
                };
                *bank_g += bank_gain * (cmd - *bank_g);
                let (along, cross) = rt.line.along_cross(n, e);
                if !rt.captured
                    && cross.abs() < CAPTURE_CROSS_M
                    && wrap_pi(chi - rt.line.heading_rad).abs() < CAPTURE_ANGLE_RAD
                {
                    rt.captured = true;
                }
                let on_line = match label_along {
                    None => true,
                    Some((a0, a1)) => rt.captured && along >= *a0 && along <= *a1,
                };
                Cmd {
                    hold: code == 0.0,
                    bank_base: *bank_g,
                    offsets,
                    code: if on_line { code } else { 0.0 },
                    label: if on_line { *label } else { 0.0 },
                    target_alt: *altitude_m,
                }
            }
            Segment::Turn { altitude_m, .. } => {
                let r = rt.rates.get(i_loc).copied().unwrap_or(0.0);
                *bank_g = (v * r / G_M_S2).atan();
                Cmd {
                    hold: true,
                    bank_base: *bank_g,
                    offsets: [0.0; 3],
                    code: 0.0,
                    label: 0.0,
                    target_alt: *altitude_m,
                }
            }
        }
    };

    // Sample 0.
    let c = commands(&plan.segments[0], &mut active, 0, n, e, chi, &mut bank_g);
    let tb = turb.value();
    let mut bank = c.bank_base + c.offsets[0] + tb[0];
    let hold = |c: &Cmd, h: f64| {
        if c.hold {
            altitude_hold(h, c.target_alt, v, kin.altitude_time_constant_s, max_gamma)
        } else {
            0.0
        }
    };
    let mut gamma = hold(&c, h) + c.offsets[1] + tb[3];
    let mut vel = velocity(v, chi, gamma);
    push(
        &mut tr,
        0.0,
        n,
        e,
        h,
        vel,
        bank,
        gamma + aoa + tb[1],
        chi + c.offsets[2] + tb[2],
        c.label,
        c.code,
    );

    loop {
        let k = tr.len() - 1; // index of the last sample
        // End of the active segment (tested on sample k)?
        let ended = match &plan.segments[seg] {
            Segment::Track {
                end: SegmentEnd::Duration(d),
                ..
            } => ((k + 1 - seg_k0) as f64) * dt_s >= *d - 1e-9,
            Segment::Track {
                end: SegmentEnd::Along(s_end),
                label_along,
                ..
            } => {
                (active.captured || label_along.is_none())
                    && active.line.along_cross(n, e).0 >= *s_end
            }
            Segment::Turn { .. } => k + 1 - seg_k0 >= active.rates.len(),
        };
        if ended {
            seg += 1;
            if seg == plan.segments.len() {
                break;
            }
            seg_k0 = k + 1;
            active = activate(
                &plan.segments[seg],
                n,
                e,
                chi + dt_s * G_M_S2 * bank.tan() / v,
                kin,
                dt_s,
            )?;
        }
        if k + 1 >= max_samples {
            return Err(SimError::Trajectory(if max_samples == MAX_SAMPLES {
                format!(
                    "the flight needs more than {MAX_SAMPLES} samples at {} Hz (segment {} of {} not ended after {:.2} h): lower the sample rate or shorten the pattern",
                    aeromag_core::error::shown(1.0 / dt_s),
                    seg + 1,
                    plan.segments.len(),
                    max_samples as f64 * dt_s / 3600.0
                )
            } else {
                format!(
                    "segment {} did not end within {} h of flight: the plan cannot be flown",
                    seg + 1,
                    MAX_FLIGHT_S / 3600.0
                )
            }));
        }
        // Sample k+1.
        chi += dt_s * G_M_S2 * bank.tan() / v;
        turb.step();
        let tb = turb.value();
        let c = commands(
            &plan.segments[seg],
            &mut active,
            k + 1 - seg_k0,
            n,
            e,
            chi,
            &mut bank_g,
        );
        bank = c.bank_base + c.offsets[0] + tb[0];
        gamma = hold(&c, h) + c.offsets[1] + tb[3];
        let vel1 = velocity(v, chi, gamma);
        n += 0.5 * dt_s * (vel[0] + vel1[0]);
        e += 0.5 * dt_s * (vel[1] + vel1[1]);
        h -= 0.5 * dt_s * (vel[2] + vel1[2]);
        vel = vel1;
        let t = (k + 1) as f64 * dt_s;
        push(
            &mut tr,
            t,
            n,
            e,
            h,
            vel,
            bank,
            gamma + aoa + tb[1],
            chi + c.offsets[2] + tb[2],
            c.label,
            c.code,
        );
    }
    Ok(tr)
}

fn velocity(v: f64, chi: f64, gamma: f64) -> [f64; 3] {
    let (sg, cg) = gamma.sin_cos();
    let (sc, cc) = chi.sin_cos();
    [v * cg * cc, v * cg * sc, -v * sg]
}

#[allow(clippy::too_many_arguments)]
fn push(
    tr: &mut Trajectory,
    t: f64,
    n: f64,
    e: f64,
    h: f64,
    vel: [f64; 3],
    roll: f64,
    pitch: f64,
    yaw: f64,
    line: f64,
    code: f64,
) {
    tr.t_s.push(t);
    tr.north_m.push(n);
    tr.east_m.push(e);
    tr.alt_m.push(h);
    tr.vn.push(vel[0]);
    tr.ve.push(vel[1]);
    tr.vd.push(vel[2]);
    tr.roll.push(roll);
    tr.pitch.push(pitch);
    tr.yaw.push(wrap_pi(yaw));
    tr.line.push(line);
    tr.manoeuvre.push(code);
}

/// Runtime state for a segment entered at position (n, e) with track angle `chi`.
fn activate(
    seg: &Segment,
    n: f64,
    e: f64,
    chi: f64,
    kin: &KinematicsConfig,
    dt_s: f64,
) -> Result<Runtime> {
    Ok(match seg {
        Segment::Track { line, .. } => {
            let line = match line {
                TrackLine::Fixed(l) => *l,
                TrackLine::FromStart { heading_rad } => RefLine {
                    north_m: n,
                    east_m: e,
                    heading_rad: *heading_rad,
                },
            };
            Runtime {
                line,
                captured: false,
                rates: Vec::new(),
            }
        }
        Segment::Turn { heading_rad, .. } => Runtime {
            line: RefLine {
                north_m: n,
                east_m: e,
                heading_rad: *heading_rad,
            },
            captured: false,
            rates: turn_rates(wrap_pi(heading_rad - chi), kin, dt_s)?,
        },
    })
}

/// Turn-rate samples (rad/s) of a scheduled turn by `delta` rad: raised-cosine
/// roll-in and roll-out of `turn_ramp_s`, constant rate in between, scaled so
/// that `Σ r_i Δt = delta` exactly.
/// A turn longer than a whole flight may last ([`MAX_FLIGHT_S`]: a tiny
/// turn rate or a huge ramp) is an error, before its samples are allocated.
fn turn_rates(delta: f64, kin: &KinematicsConfig, dt_s: f64) -> Result<Vec<f64>> {
    let rmax = kin.turn_rate_deg_s.to_radians();
    if delta.abs() < 1e-12 {
        return Ok(Vec::new());
    }
    let total = delta.abs() / rmax + kin.turn_ramp_s;
    if total.is_nan() || total > MAX_FLIGHT_S {
        return Err(SimError::Trajectory(format!(
            "a turn of {:.0}° would last {} s at kinematics.turn_rate_deg_s = {} with kinematics.turn_ramp_s = {}, longer than a flight ({} h)",
            delta.abs().to_degrees(),
            aeromag_core::error::shown(total.round()),
            aeromag_core::error::shown(kin.turn_rate_deg_s),
            aeromag_core::error::shown(kin.turn_ramp_s),
            MAX_FLIGHT_S / 3600.0
        )));
    }
    let n = ((total / dt_s).round() as usize).max(1);
    let t_total = n as f64 * dt_s;
    let ramp = kin.turn_ramp_s.min(0.5 * t_total);
    let shape: Vec<f64> = (0..n)
        .map(|i| {
            let t = (i as f64 + 0.5) * dt_s;
            let edge = t.min(t_total - t);
            if ramp > 0.0 && edge < ramp {
                0.5 * (1.0 - (std::f64::consts::PI * edge / ramp).cos())
            } else {
                1.0
            }
        })
        .collect();
    let sum: f64 = shape.iter().sum::<f64>() * dt_s;
    Ok(shape.iter().map(|s| delta * s / sum).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::{Stream, rng_for};
    use crate::trajectory::{ManoeuvreBlock, ManoeuvreKind};

    fn calm() -> TurbulenceConfig {
        TurbulenceConfig {
            roll_deg: 0.0,
            pitch_deg: 0.0,
            yaw_deg: 0.0,
            flight_path_deg: 0.0,
            time_constant_s: 1.0,
        }
    }

    #[test]
    fn scheduled_turn_reaches_the_heading_exactly_and_positions_integrate_velocities() {
        let kin = KinematicsConfig {
            speed_m_s: 90.0,
            ..Default::default()
        };
        let start = StartState {
            north_m: 0.0,
            east_m: 0.0,
            alt_m: 3000.0,
            heading_rad: 0.0,
        };
        let line = |h: f64| TrackLine::FromStart { heading_rad: h };
        let plan = FlightPlan {
            start,
            segments: vec![
                Segment::Track {
                    line: line(0.0),
                    altitude_m: 3000.0,
                    end: SegmentEnd::Duration(10.0),
                    label: 1.0,
                    label_along: None,
                    manoeuvres: vec![],
                },
                Segment::Turn {
                    heading_rad: std::f64::consts::FRAC_PI_2,
                    altitude_m: 3000.0,
                },
                Segment::Track {
                    line: line(std::f64::consts::FRAC_PI_2),
                    altitude_m: 3000.0,
                    end: SegmentEnd::Duration(5.0),
                    label: 2.0,
                    label_along: None,
                    manoeuvres: vec![],
                },
            ],
        };
        let tr = fly(&plan, &kin, &calm(), 0.1, rng_for(1, Stream::Turbulence)).unwrap();
        let last = tr.len() - 1;
        let first2 = tr.line.iter().position(|&l| l == 2.0).unwrap();
        assert!(
            (tr.yaw[first2] - std::f64::consts::FRAC_PI_2).abs() < 1e-9,
            "yaw {}",
            tr.yaw[first2]
        );
        assert!(
            (tr.yaw[last] - std::f64::consts::FRAC_PI_2).abs() < 1e-3,
            "yaw {}",
            tr.yaw[last]
        );
        assert_eq!(tr.line[0], 1.0);
        assert_eq!(tr.line[last], 2.0);
        // Peak bank of a rate-3 turn at 90 m/s: atan(90·0.05236/g) ≈ 25.7°.
        let max_roll = tr
            .roll
            .iter()
            .fold(0.0f64, |m, r| m.max(r.abs()))
            .to_degrees();
        assert!((max_roll - 25.67).abs() < 0.2, "{max_roll}");
        for k in 0..last {
            let dn = tr.north_m[k + 1] - tr.north_m[k];
            assert!((dn - 0.05 * (tr.vn[k] + tr.vn[k + 1])).abs() < 1e-9);
            // coordinated turn: heading change = Δt g tan φ / V
            let dpsi = wrap_pi(tr.yaw[k + 1] - tr.yaw[k]);
            assert!((dpsi - 0.1 * G_M_S2 * tr.roll[k].tan() / 90.0).abs() < 1e-12);
        }
    }

    #[test]
    fn roll_and_pitch_manoeuvres_return_heading_and_altitude() {
        let kin = KinematicsConfig {
            speed_m_s: 90.0,
            ..Default::default()
        };
        let start = StartState {
            north_m: 0.0,
            east_m: 0.0,
            alt_m: 3000.0,
            heading_rad: 0.0,
        };
        let mk = |kind, start_s, period_s, amp: f64| ManoeuvreBlock {
            kind,
            start_s,
            period_s,
            cycles: 3,
            amplitude_rad: amp.to_radians(),
        };
        let plan = FlightPlan {
            start,
            segments: vec![Segment::Track {
                line: TrackLine::FromStart { heading_rad: 0.0 },
                altitude_m: 3000.0,
                end: SegmentEnd::Duration(60.0),
                label: 1.0,
                label_along: None,
                manoeuvres: vec![
                    mk(ManoeuvreKind::Roll, 5.0, 6.0, 10.0),
                    mk(ManoeuvreKind::Pitch, 30.0, 4.0, 5.0),
                ],
            }],
        };
        let tr = fly(&plan, &kin, &calm(), 0.1, rng_for(1, Stream::Turbulence)).unwrap();
        let roll_max = tr
            .roll
            .iter()
            .fold(0.0f64, |m, r| m.max(r.abs()))
            .to_degrees();
        assert!((roll_max - 10.0).abs() < 0.3, "{roll_max}");
        let alt_dev = tr
            .alt_m
            .iter()
            .fold(0.0f64, |m, a| m.max((a - 3000.0).abs()));
        // γ = A sin ωt starting at 0: h − h₀ = V A (1 − cos ωt)/ω, up to
        // 2 V A T/2π = 2·90·0.0873·4/2π ≈ 10 m above the start.
        assert!(alt_dev > 9.0 && alt_dev < 10.5, "{alt_dev}");
        // Flown open loop, whole cycles return the heading (roll block 5–23 s)
        // and the altitude (pitch block 30–42 s) to their values at the start.
        assert!(
            (tr.yaw[230] - tr.yaw[50]).abs() < 1e-12,
            "heading change {}",
            tr.yaw[230] - tr.yaw[50]
        );
        // (the altitude hold re-engages at the sample after the block, whose
        // half step enters the trapezoid: a sub-millimetre residue)
        assert!(
            (tr.alt_m[420] - tr.alt_m[300]).abs() < 1e-3,
            "altitude change {}",
            tr.alt_m[420] - tr.alt_m[300]
        );
        assert!(tr.manoeuvre.iter().filter(|&&c| c == 1.0).count() == 180);
    }

    #[test]
    fn l1_captures_a_parallel_line_after_a_reversal() {
        let kin = KinematicsConfig::default();
        let start = StartState {
            north_m: 0.0,
            east_m: 0.0,
            alt_m: 250.0,
            heading_rad: 0.0,
        };
        // Line 2.5 km east, flown south from north = 0 to north = −5 km.
        let line = RefLine {
            north_m: 0.0,
            east_m: 2500.0,
            heading_rad: std::f64::consts::PI,
        };
        let plan = FlightPlan {
            start,
            segments: vec![Segment::Track {
                line: TrackLine::Fixed(line),
                altitude_m: 250.0,
                end: SegmentEnd::Along(5000.0),
                label: 7.0,
                label_along: Some((0.0, 5000.0)),
                manoeuvres: vec![],
            }],
        };
        let tr = fly(&plan, &kin, &calm(), 0.1, rng_for(1, Stream::Turbulence)).unwrap();
        let on: Vec<usize> = (0..tr.len()).filter(|&k| tr.line[k] == 7.0).collect();
        assert!(!on.is_empty());
        let worst = on
            .iter()
            .map(|&k| (tr.east_m[k] - 2500.0).abs())
            .fold(0.0, f64::max);
        assert!(
            worst < CAPTURE_CROSS_M + 1.0,
            "worst cross-track on the line {worst}"
        );
        let max_bank = tr.roll.iter().fold(0.0f64, |m, r| m.max(r.abs()));
        assert!(max_bank <= 25f64.to_radians() + 1e-12);
    }

    /// A turn that would outlast a flight (the ramp of 2³¹ s of a mutated
    /// scenario file asked for 1.7 TB) is an error, not an allocation.
    #[test]
    fn a_turn_longer_than_a_flight_is_an_error() {
        for (rate, ramp) in [(3.0, 2_147_483_648.0), (1e-9, 4.0)] {
            let kin = KinematicsConfig {
                turn_rate_deg_s: rate,
                turn_ramp_s: ramp,
                ..Default::default()
            };
            let e = turn_rates(1.0, &kin, 0.1).unwrap_err().to_string();
            assert!(e.contains("longer than a flight (24 h)"), "{e}");
        }
        let kin = KinematicsConfig {
            turn_ramp_s: 3600.0,
            ..Default::default()
        };
        assert!(turn_rates(1.0, &kin, 0.1).is_ok());
    }

    proptest::proptest! {
        /// A scheduled turn changes the heading by exactly the requested
        /// angle and never exceeds the turn rate by more than the
        /// discretisation of the ramps.
        #[test]
        fn turn_profile_is_exact(delta in -3.1f64..3.1, rate in 1.0f64..6.0, ramp in 0.0f64..8.0, fine in proptest::bool::ANY) {
            let dt = if fine { 0.01 } else { 0.1 };
            let kin = KinematicsConfig { turn_rate_deg_s: rate, turn_ramp_s: ramp, ..Default::default() };
            let r = turn_rates(delta, &kin, dt).unwrap();
            let total: f64 = r.iter().sum::<f64>() * dt;
            // Exact up to the rounding of summing r.len() terms (ε per addition),
            // e.g. 13 700 samples of a 3 rad turn at 0.01 s: ~1e-11 rad.
            let rounding = 4.0 * r.len() as f64 * f64::EPSILON * delta.abs() + 1e-15;
            proptest::prop_assert!((total - delta).abs() < rounding, "error {} vs bound {}", (total - delta).abs(), rounding);
            let max = r.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            proptest::prop_assert!(max <= rate.to_radians() * 1.1 + 1e-12, "max {} vs {}", max, rate.to_radians());
            proptest::prop_assert!(r.iter().all(|x| x * delta >= 0.0));
        }
    }
}
