//! The survey flight: parallel lines and perpendicular tie lines at a
//! constant clearance above a flat terrain, flown through turbulence.
//!
//! Geometry (spec `simulator.md` "survey"; seed `000_…` §4: survey height
//! ~100 m): `line_count` lines of length `line_length_m`, `line_spacing_m`
//! apart, in direction `line_heading_deg`, starting at the local origin and
//! stepping to the right of the line direction; `tie_count` tie lines
//! perpendicular to them, `tie_spacing_m` apart and centred on the block,
//! extending `tie_overshoot_m` beyond the outer lines.
//!
//! Flying order: the lines are flown alternately in both directions; the
//! next line is the nearest unflown one at least one turn diameter
//! (`2 V²/(g tan φ_max)`) away (for the defaults: 1, 6, 11, 5, 10, 4, 9, 3,
//! 8, 2, 7, 12), or the farthest unflown one when none is that far. The tie
//! lines follow: an unlabelled approach track outside the block brings the
//! aircraft onto the first tie (the nearest one at least a turn diameter
//! plus the run-out away) ahead of its start; the others are reached by
//! reversals. Each line is captured and tracked by the L1 guidance;
//! the aircraft continues `run_out_m` past the end before turning; samples on
//! a line (captured, between its ends) carry the line's label in `line`
//! (lines `first_line_label`, `first_line_label + 1`, … in geometric order;
//! ties `first_tie_label`, …), all other samples 0.

use serde::{Deserialize, Serialize};

use super::config::{FlightConfig, Pattern};
use crate::error::{Result, invalid, require_non_negative, require_positive};
use crate::trajectory::{
    FlightPlan, KinematicsConfig, RefLine, Segment, SegmentEnd, StartState, TrackLine,
};

/// The survey pattern.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SurveyPattern {
    /// Flight height above the terrain, m. Default 100.
    pub clearance_m: f64,
    /// Direction of the survey lines, deg clockwise from north. Default 0.
    pub line_heading_deg: f64,
    /// Length of the survey lines, m. Default 10 000.
    pub line_length_m: f64,
    /// Number of survey lines. Default 20.
    pub line_count: u32,
    /// Distance between survey lines, m. Default 500 (with the default turn
    /// diameter of 2.1 km every line is reached by a clean 180° turn).
    pub line_spacing_m: f64,
    /// Number of tie lines. Default 5 (100 crossovers with the default
    /// lines: the levelling's `k` needs about that many, see
    /// `aeromag_compensation::levelling`).
    pub tie_count: u32,
    /// Distance between tie lines, m. Default 2000 (4× the line spacing).
    pub tie_spacing_m: f64,
    /// Extension of the tie lines beyond the outer survey lines, m. Default 500.
    pub tie_overshoot_m: f64,
    /// Straight flight before the first line, m. Default 1500.
    pub run_in_m: f64,
    /// Straight flight after the end of each line before turning, m.
    /// Default 2500 (room for the L1 loop to settle on the next line after
    /// the turn; with 1500 m some of 20 lines were captured 500–800 m late).
    pub run_out_m: f64,
    /// Label of the first survey line. Default 1001.
    pub first_line_label: u32,
    /// Label of the first tie line. Default 2001.
    pub first_tie_label: u32,
}

impl Default for SurveyPattern {
    fn default() -> Self {
        Self {
            clearance_m: 100.0,
            line_heading_deg: 0.0,
            line_length_m: 10_000.0,
            line_count: 20,
            line_spacing_m: 500.0,
            tie_count: 5,
            tie_spacing_m: 2000.0,
            tie_overshoot_m: 500.0,
            run_in_m: 1500.0,
            run_out_m: 2500.0,
            first_line_label: 1001,
            first_tie_label: 2001,
        }
    }
}

/// Order in which `count` parallel lines `spacing` apart are flown, starting
/// with line 0: the nearest unflown line at least `d_min` away, else the
/// farthest unflown one.
fn flying_order(count: usize, spacing: f64, d_min: f64, first: usize) -> Vec<usize> {
    let mut flown = vec![false; count];
    let mut order = Vec::with_capacity(count);
    let mut cur = first;
    flown[cur] = true;
    order.push(cur);
    while order.len() < count {
        let dist = |j: usize| (j as f64 - cur as f64).abs() * spacing;
        let unflown = (0..count).filter(|&j| !flown[j]);
        let next = unflown
            .clone()
            .filter(|&j| dist(j) >= d_min)
            .min_by(|&a, &b| dist(a).total_cmp(&dist(b)).then(a.cmp(&b)))
            .or_else(|| unflown.max_by(|&a, &b| dist(a).total_cmp(&dist(b)).then(b.cmp(&a))));
        let Some(next) = next else { break };
        flown[next] = true;
        order.push(next);
        cur = next;
    }
    order
}

impl SurveyPattern {
    /// Unit vectors of the line direction `u` and of the cross direction `c`
    /// (to the right of `u`), as (north, east).
    fn axes(&self) -> ((f64, f64), (f64, f64)) {
        let h = self.line_heading_deg.to_radians();
        ((h.cos(), h.sin()), (-h.sin(), h.cos()))
    }

    /// Along-line positions of the tie lines, m.
    fn tie_positions(&self) -> Vec<f64> {
        let n = self.tie_count as usize;
        let mid = 0.5 * self.line_length_m;
        (0..n)
            .map(|k| mid + (k as f64 - 0.5 * (n as f64 - 1.0)) * self.tie_spacing_m)
            .collect()
    }
}

impl Pattern for SurveyPattern {
    fn validate(&self, _flight: &FlightConfig, _kin: &KinematicsConfig) -> Result<()> {
        require_positive("pattern.clearance_m", self.clearance_m)?;
        if !self.line_heading_deg.is_finite() {
            return Err(invalid("pattern.line_heading_deg", "must be finite"));
        }
        require_positive("pattern.line_length_m", self.line_length_m)?;
        if self.line_count == 0 {
            return Err(invalid("pattern.line_count", "must be ≥ 1"));
        }
        require_positive("pattern.line_spacing_m", self.line_spacing_m)?;
        require_positive("pattern.tie_spacing_m", self.tie_spacing_m)?;
        for (n, v) in [
            ("tie_overshoot_m", self.tie_overshoot_m),
            ("run_in_m", self.run_in_m),
            ("run_out_m", self.run_out_m),
        ] {
            require_non_negative(&format!("pattern.{n}"), v)?;
        }
        if let (Some(first), Some(last)) =
            (self.tie_positions().first(), self.tie_positions().last())
            && (*first < 0.0 || *last > self.line_length_m)
        {
            return Err(invalid(
                "pattern.tie_spacing_m",
                format!(
                    "{} tie lines {} m apart do not fit on lines {} m long",
                    self.tie_count, self.tie_spacing_m, self.line_length_m
                ),
            ));
        }
        if self.first_tie_label < self.first_line_label + self.line_count
            && self.first_tie_label + self.tie_count > self.first_line_label
        {
            return Err(invalid(
                "pattern.first_tie_label",
                "tie labels overlap the survey-line labels",
            ));
        }
        Ok(())
    }

    fn plan(&self, flight: &FlightConfig, kin: &KinematicsConfig) -> Result<FlightPlan> {
        let alt = flight.terrain_alt_m + self.clearance_m;
        let h = self.line_heading_deg.to_radians();
        let ((un, ue), (cn, ce)) = self.axes();
        let len = self.line_length_m;
        let d_min = 2.0 * kin.min_turn_radius_m();
        let mut segments = Vec::new();
        let mut at_far_end = false; // the aircraft is at along = L of the last line flown

        let track = |line: RefLine, label: f64, length: f64| Segment::Track {
            line: TrackLine::Fixed(line),
            altitude_m: alt,
            end: SegmentEnd::Along(length + self.run_out_m),
            label,
            label_along: Some((0.0, length)),
            manoeuvres: Vec::new(),
        };

        for j in flying_order(self.line_count as usize, self.line_spacing_m, d_min, 0) {
            let off = j as f64 * self.line_spacing_m;
            let (n0, e0) = (off * cn, off * ce);
            let line = if at_far_end {
                RefLine {
                    north_m: n0 + len * un,
                    east_m: e0 + len * ue,
                    heading_rad: h + std::f64::consts::PI,
                }
            } else {
                RefLine {
                    north_m: n0,
                    east_m: e0,
                    heading_rad: h,
                }
            };
            segments.push(track(line, (self.first_line_label + j as u32) as f64, len));
            at_far_end = !at_far_end;
        }

        // Tie lines. The aircraft is at the end of the last line, on one side
        // of the block. It first flies an unlabelled approach track parallel to
        // the lines, outside the block by the tie overshoot plus a turn
        // diameter (a clean reversal from the last line), and leaves it one
        // turn radius before the first tie, so that a 90° turn puts it on the
        // tie ahead of the tie's start. Later ties are reached by reversals
        // like the lines.
        let ties = self.tie_positions();
        let order_lines = flying_order(self.line_count as usize, self.line_spacing_m, d_min, 0);
        if !ties.is_empty() {
            let last_line = self.line_count as f64 - 1.0;
            let width = last_line * self.line_spacing_m + 2.0 * self.tie_overshoot_m;
            let here_along = if at_far_end { len } else { 0.0 };
            let clearance = d_min + self.run_out_m;
            let dist = |k: usize| (ties[k] - here_along).abs();
            let first = (0..ties.len())
                .filter(|&k| dist(k) >= clearance)
                .min_by(|&a, &b| dist(a).total_cmp(&dist(b)))
                .or_else(|| (0..ties.len()).max_by(|&a, &b| dist(a).total_cmp(&dist(b))))
                .unwrap_or(0);
            let last_j = *order_lines.last().unwrap_or(&0) as f64;
            let mut from_right = last_j > 0.5 * last_line;
            let radius = kin.min_turn_radius_m();
            let aux_cross = if from_right {
                last_line * self.line_spacing_m + self.tie_overshoot_m + 1.1 * d_min
            } else {
                -self.tie_overshoot_m - 1.1 * d_min
            };
            let a0 = ties[first];
            let aux = if at_far_end {
                RefLine {
                    north_m: len * un + aux_cross * cn,
                    east_m: len * ue + aux_cross * ce,
                    heading_rad: h + std::f64::consts::PI,
                }
            } else {
                RefLine {
                    north_m: aux_cross * cn,
                    east_m: aux_cross * ce,
                    heading_rad: h,
                }
            };
            let aux_end = if at_far_end {
                len - a0 - radius
            } else {
                a0 - radius
            };
            segments.push(Segment::Track {
                line: TrackLine::Fixed(aux),
                altitude_m: alt,
                end: SegmentEnd::Along(aux_end),
                label: 0.0,
                label_along: None,
                manoeuvres: Vec::new(),
            });
            for k in flying_order(ties.len(), self.tie_spacing_m, d_min, first) {
                let a = ties[k];
                let line = if from_right {
                    let s = width - self.tie_overshoot_m;
                    RefLine {
                        north_m: a * un + s * cn,
                        east_m: a * ue + s * ce,
                        heading_rad: h - std::f64::consts::FRAC_PI_2,
                    }
                } else {
                    let s = -self.tie_overshoot_m;
                    RefLine {
                        north_m: a * un + s * cn,
                        east_m: a * ue + s * ce,
                        heading_rad: h + std::f64::consts::FRAC_PI_2,
                    }
                };
                segments.push(track(line, (self.first_tie_label + k as u32) as f64, width));
                from_right = !from_right;
            }
        }
        let start = StartState {
            north_m: -self.run_in_m * un,
            east_m: -self.run_in_m * ue,
            alt_m: alt,
            heading_rad: h,
        };
        Ok(FlightPlan { start, segments })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn racetrack_order() {
        // 12 lines 400 m apart, turn diameter 2.2 km: 0, 6, 1, 7, …
        let o = flying_order(12, 400.0, 2200.0, 0);
        assert_eq!(o, vec![0, 6, 1, 7, 2, 8, 3, 9, 4, 10, 5, 11]);
        // The defaults: 500 m apart, turn diameter 2.14 km.
        let o = flying_order(12, 500.0, 2142.0, 0);
        assert_eq!(o, vec![0, 5, 10, 4, 9, 3, 8, 2, 7, 1, 6, 11]);
        let o = flying_order(3, 4000.0, 2200.0, 1);
        assert_eq!(o.len(), 3);
        assert_eq!(o[0], 1);
        let mut s = o.clone();
        s.sort();
        assert_eq!(s, vec![0, 1, 2]);
    }

    #[test]
    fn ties_must_fit() {
        let p = SurveyPattern {
            tie_count: 4,
            tie_spacing_m: 5000.0,
            ..Default::default()
        };
        assert!(
            p.validate(&FlightConfig::default(), &KinematicsConfig::default())
                .is_err()
        );
    }
}
