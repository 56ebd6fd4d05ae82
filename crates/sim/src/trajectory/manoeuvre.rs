//! Calibration manoeuvres: sinusoidal roll, pitch and yaw oscillations.
//!
//! A block of `n` whole cycles of period `T` and amplitude `A` starting at
//! local time `t₀` adds `A sin(2π (t − t₀)/T)` for `t₀ ≤ t < t₀ + nT` to
//! the bank angle (roll), the flight-path angle (pitch: the nose and the path
//! go up and down together, the altitude oscillates by `±V A T/2π`) or the
//! sideslip (yaw: a flat rudder yaw, the track stays). Whole cycles of an odd
//! function leave the heading (roll) and the altitude (pitch) unchanged at the
//! end of the block. Spec `simulator.md`: "roll ±10°, pitch ±5°, yaw ±5°
//! manoeuvres with periods of 4–6 s"; seed `000_…` §4 (the calibration flight
//! on four headings).

use serde::{Deserialize, Serialize};

/// Which attitude angle a manoeuvre excites.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ManoeuvreKind {
    /// Bank oscillation (code 1 in the `manoeuvre` column).
    Roll,
    /// Pitch (flight-path) oscillation (code 2).
    Pitch,
    /// Flat yaw (sideslip) oscillation (code 3).
    Yaw,
}

impl ManoeuvreKind {
    /// Code written to the `manoeuvre` column.
    pub fn code(self) -> f64 {
        match self {
            Self::Roll => 1.0,
            Self::Pitch => 2.0,
            Self::Yaw => 3.0,
        }
    }
}

/// One block of whole sinusoidal cycles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ManoeuvreBlock {
    /// The excited angle.
    pub kind: ManoeuvreKind,
    /// Start, s after the start of the segment.
    pub start_s: f64,
    /// Period, s.
    pub period_s: f64,
    /// Number of whole cycles.
    pub cycles: u32,
    /// Amplitude, rad.
    pub amplitude_rad: f64,
}

impl ManoeuvreBlock {
    /// Duration `n T`, s.
    pub fn duration_s(&self) -> f64 {
        self.period_s * self.cycles as f64
    }

    /// The offset (rad) at segment-local time `t_s`, or `None` outside the block.
    pub fn offset(&self, t_s: f64) -> Option<f64> {
        let tau = t_s - self.start_s;
        // A small tolerance keeps a sample that falls on the end (rounding) out.
        if tau >= -1e-9 && tau < self.duration_s() - 1e-9 {
            Some(self.amplitude_rad * (std::f64::consts::TAU * tau / self.period_s).sin())
        } else {
            None
        }
    }
}

/// Offsets of all blocks at local time `t_s`: `(bank, flight path, sideslip)`
/// in rad and the manoeuvre code (0 when none is active).
pub fn offsets(blocks: &[ManoeuvreBlock], t_s: f64) -> ([f64; 3], f64) {
    let mut out = [0.0; 3];
    let mut code = 0.0;
    for b in blocks {
        if let Some(v) = b.offset(t_s) {
            let i = match b.kind {
                ManoeuvreKind::Roll => 0,
                ManoeuvreKind::Pitch => 1,
                ManoeuvreKind::Yaw => 2,
            };
            out[i] += v;
            code = b.kind.code();
        }
    }
    (out, code)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn whole_cycles_sum_to_zero_and_stay_in_amplitude() {
        let b = ManoeuvreBlock {
            kind: ManoeuvreKind::Pitch,
            start_s: 2.0,
            period_s: 4.0,
            cycles: 3,
            amplitude_rad: 0.1,
        };
        let dt = 0.1;
        let vals: Vec<f64> = (0..200).filter_map(|k| b.offset(k as f64 * dt)).collect();
        assert_eq!(vals.len(), 120);
        assert!(vals.iter().sum::<f64>().abs() < 1e-12);
        assert!(vals.iter().all(|v| v.abs() <= 0.1));
        let (o, code) = offsets(&[b], 3.0);
        assert_eq!(code, 2.0);
        assert!((o[1] - 0.1).abs() < 1e-12 && o[0] == 0.0 && o[2] == 0.0);
    }
}
