//! The calibration ("compensation", FOM) flight: a box at high altitude, one
//! leg per heading, with roll, pitch and yaw manoeuvres on each leg.
//!
//! Seed `000_…` §4 (fig. 1) and §12 (fig. 2): the calibration flight is
//! flown on four headings at an altitude well above the survey
//! ("калибровочная высота", here 3000 m by default) so that the anomaly is
//! smooth; on each heading the aircraft performs roll (±10°), pitch (±5°)
//! and yaw (±5°) oscillations with periods of 4–6 s (spec `simulator.md`,
//! `compensation.md` "Calibration-flight planning").
//!
//! Each leg is flown as: `lead_in_s` of steady flight, then every manoeuvre
//! of the leg (`cycles` whole periods each) separated by `gap_s` of steady
//! flight, then `tail_s`; consecutive legs are joined by rate-one turns to
//! the next heading. The `line` column holds the leg number (1, 2, …; 0 in
//! turns) and `manoeuvre` the manoeuvre code (1 roll, 2 pitch, 3 yaw).
//!
//! ## The truncated pattern
//!
//! The thesis shows (fig. 2b, not reproduced in the text of the seed) a
//! "truncated" calibration flight that saves up to a quarter of the flight
//! time with nearly the same estimability of the coefficients. It keeps the
//! four headings (four courses are needed for observability, §4), so our
//! reading of it reduces the manoeuvres: 3 cycles instead of 4, shorter
//! steady segments, and yaw manoeuvres only on the first and third legs
//! (north and south). Its flight time is ≈ 73 % of the full pattern's
//! (test `truncated_pattern_saves_about_a_quarter`).

use serde::{Deserialize, Serialize};

use super::config::{FlightConfig, Pattern};
use crate::error::{Result, invalid, require_non_negative, require_positive};
use crate::trajectory::{
    FlightPlan, KinematicsConfig, ManoeuvreBlock, ManoeuvreKind, Segment, SegmentEnd, StartState,
    TrackLine,
};

/// One leg of the calibration pattern.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LegConfig {
    /// Heading of the leg, deg clockwise from north.
    pub heading_deg: f64,
    /// Manoeuvres flown on this leg, in order (`"roll"`, `"pitch"`, `"yaw"`).
    pub manoeuvres: Vec<ManoeuvreKind>,
}

/// The calibration pattern.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CalibrationPattern {
    /// Altitude of the box (WGS84 ellipsoidal), m. Default 3000.
    pub altitude_m: f64,
    /// The legs. Default: headings 0, 90, 180, 270 with roll, pitch and yaw
    /// each (full); truncated: yaw only on the 0° and 180° legs.
    pub legs: Vec<LegConfig>,
    /// Whole cycles per manoeuvre. Default 4 (full), 3 (truncated).
    pub cycles: u32,
    /// Steady flight at the start of each leg, s. Default 30 (full), 20
    /// (truncated).
    pub lead_in_s: f64,
    /// Steady flight between manoeuvres, s. Default 10.
    pub gap_s: f64,
    /// Steady flight at the end of each leg, s. Default 20 (full), 15
    /// (truncated).
    pub tail_s: f64,
    /// Roll amplitude, deg. Default 10.
    pub roll_amplitude_deg: f64,
    /// Roll period, s. Default 6.
    pub roll_period_s: f64,
    /// Pitch amplitude, deg. Default 5.
    pub pitch_amplitude_deg: f64,
    /// Pitch period, s. Default 4.
    pub pitch_period_s: f64,
    /// Yaw amplitude, deg. Default 5.
    pub yaw_amplitude_deg: f64,
    /// Yaw period, s. Default 5.
    pub yaw_period_s: f64,
}

impl Default for CalibrationPattern {
    fn default() -> Self {
        Self::full()
    }
}

fn leg(h: f64, m: &[ManoeuvreKind]) -> LegConfig {
    LegConfig {
        heading_deg: h,
        manoeuvres: m.to_vec(),
    }
}

impl CalibrationPattern {
    /// The full four-heading box.
    pub fn full() -> Self {
        use ManoeuvreKind::*;
        let all = [Roll, Pitch, Yaw];
        Self {
            altitude_m: 3000.0,
            legs: vec![
                leg(0.0, &all),
                leg(90.0, &all),
                leg(180.0, &all),
                leg(270.0, &all),
            ],
            cycles: 4,
            lead_in_s: 30.0,
            gap_s: 10.0,
            tail_s: 20.0,
            roll_amplitude_deg: 10.0,
            roll_period_s: 6.0,
            pitch_amplitude_deg: 5.0,
            pitch_period_s: 4.0,
            yaw_amplitude_deg: 5.0,
            yaw_period_s: 5.0,
        }
    }

    /// The truncated pattern (module docs).
    pub fn truncated() -> Self {
        use ManoeuvreKind::*;
        Self {
            legs: vec![
                leg(0.0, &[Roll, Pitch, Yaw]),
                leg(90.0, &[Roll, Pitch]),
                leg(180.0, &[Roll, Pitch, Yaw]),
                leg(270.0, &[Roll, Pitch]),
            ],
            cycles: 3,
            lead_in_s: 20.0,
            tail_s: 15.0,
            ..Self::full()
        }
    }

    fn block(&self, kind: ManoeuvreKind, start_s: f64) -> ManoeuvreBlock {
        let (a, p) = match kind {
            ManoeuvreKind::Roll => (self.roll_amplitude_deg, self.roll_period_s),
            ManoeuvreKind::Pitch => (self.pitch_amplitude_deg, self.pitch_period_s),
            ManoeuvreKind::Yaw => (self.yaw_amplitude_deg, self.yaw_period_s),
        };
        ManoeuvreBlock {
            kind,
            start_s,
            period_s: p,
            cycles: self.cycles,
            amplitude_rad: a.to_radians(),
        }
    }

    /// Manoeuvre blocks and duration (s) of a leg.
    fn leg_schedule(&self, l: &LegConfig) -> (Vec<ManoeuvreBlock>, f64) {
        let mut t = self.lead_in_s;
        let mut blocks = Vec::new();
        for (i, &m) in l.manoeuvres.iter().enumerate() {
            if i > 0 {
                t += self.gap_s;
            }
            let b = self.block(m, t);
            t += b.duration_s();
            blocks.push(b);
        }
        (blocks, t + self.tail_s)
    }
}

impl Pattern for CalibrationPattern {
    fn validate(&self, flight: &FlightConfig, _kin: &KinematicsConfig) -> Result<()> {
        if !(self.altitude_m.is_finite() && self.altitude_m > flight.terrain_alt_m + 50.0) {
            return Err(invalid(
                "pattern.altitude_m",
                "must be at least 50 m above flight.terrain_alt_m",
            ));
        }
        if self.legs.is_empty() {
            return Err(invalid("pattern.legs", "at least one leg is needed"));
        }
        for (i, l) in self.legs.iter().enumerate() {
            if !l.heading_deg.is_finite() {
                return Err(invalid(
                    format!("pattern.legs[{i}].heading_deg"),
                    "must be finite",
                ));
            }
        }
        if self.cycles == 0 {
            return Err(invalid("pattern.cycles", "must be ≥ 1"));
        }
        for (n, v) in [
            ("lead_in_s", self.lead_in_s),
            ("gap_s", self.gap_s),
            ("tail_s", self.tail_s),
        ] {
            require_non_negative(&format!("pattern.{n}"), v)?;
        }
        for (n, v) in [
            ("roll_period_s", self.roll_period_s),
            ("pitch_period_s", self.pitch_period_s),
            ("yaw_period_s", self.yaw_period_s),
        ] {
            require_positive(&format!("pattern.{n}"), v)?;
        }
        for (n, v, max) in [
            ("roll_amplitude_deg", self.roll_amplitude_deg, 45.0),
            ("pitch_amplitude_deg", self.pitch_amplitude_deg, 15.0),
            ("yaw_amplitude_deg", self.yaw_amplitude_deg, 15.0),
        ] {
            if !(v.is_finite() && (0.0..=max).contains(&v)) {
                return Err(invalid(
                    format!("pattern.{n}"),
                    format!("must be in [0, {max}] deg"),
                ));
            }
        }
        if self.legs.iter().all(|l| self.leg_schedule(l).1 <= 0.0) {
            return Err(invalid("pattern", "the legs have zero duration"));
        }
        Ok(())
    }

    fn plan(&self, _flight: &FlightConfig, _kin: &KinematicsConfig) -> Result<FlightPlan> {
        let first = self.legs[0].heading_deg.to_radians();
        let mut segments = Vec::new();
        for (i, l) in self.legs.iter().enumerate() {
            let h = l.heading_deg.to_radians();
            if i > 0 {
                segments.push(Segment::Turn {
                    heading_rad: h,
                    altitude_m: self.altitude_m,
                });
            }
            let (manoeuvres, duration) = self.leg_schedule(l);
            segments.push(Segment::Track {
                line: TrackLine::FromStart { heading_rad: h },
                altitude_m: self.altitude_m,
                end: SegmentEnd::Duration(duration),
                label: (i + 1) as f64,
                label_along: None,
                manoeuvres,
            });
        }
        Ok(FlightPlan {
            start: StartState {
                north_m: 0.0,
                east_m: 0.0,
                alt_m: self.altitude_m,
                heading_rad: first,
            },
            segments,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn duration(p: &CalibrationPattern) -> f64 {
        let kin = KinematicsConfig {
            speed_m_s: 90.0,
            ..Default::default()
        };
        let legs: f64 = p.legs.iter().map(|l| p.leg_schedule(l).1).sum();
        // three 90° turns at 3°/s with 4 s of ramps
        let turns = (p.legs.len() - 1) as f64 * (90.0 / kin.turn_rate_deg_s + kin.turn_ramp_s);
        legs + turns
    }

    #[test]
    fn truncated_pattern_saves_about_a_quarter() {
        let full = duration(&CalibrationPattern::full());
        let trunc = duration(&CalibrationPattern::truncated());
        let ratio = trunc / full;
        assert!(
            (0.68..0.80).contains(&ratio),
            "truncated/full = {ratio} ({trunc} s / {full} s)"
        );
    }

    #[test]
    fn leg_schedule_places_blocks_in_order() {
        let p = CalibrationPattern::full();
        let (b, d) = p.leg_schedule(&p.legs[0]);
        assert_eq!(b.len(), 3);
        assert_eq!(b[0].start_s, 30.0);
        assert_eq!(b[1].start_s, 30.0 + 24.0 + 10.0);
        assert_eq!(b[2].start_s, 30.0 + 24.0 + 10.0 + 16.0 + 10.0);
        assert_eq!(d, 30.0 + 24.0 + 10.0 + 16.0 + 10.0 + 20.0 + 20.0);
    }
}
