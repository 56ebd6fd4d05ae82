//! CSV of detected field vectors with the truth pose in `true_` columns
//! (issue 6 item 1: "CSV for the detected vectors"; column conventions of
//! spec `simulator.md`: units in the names, truth prefixed `true_`).
//!
//! Columns: `time_s`, then for each frequency `i` = 1..3 and axis
//! `c` ∈ {x, y, z}: `h{i}_{c}_re_t`, `h{i}_{c}_im_t` (T), then
//! `xi{i}_{c}_re`, `xi{i}_{c}_im` (pilot-measured sensitivity), and with a
//! scenario `true_x_m, true_y_m, true_z_m, true_range_m, true_roll_deg,
//! true_pitch_deg, true_yaw_deg` (receiver attitude relative to the
//! transmitter frame, [`crate::positioning::Pose::attitude`]). Numbers use
//! Rust's shortest round-trip formatting.

use super::EmScenario;
use crate::detection::FieldEpoch;
use std::fmt::Write;

const AXES: [&str; 3] = ["x", "y", "z"];

/// The CSV text (header plus one row per epoch).
pub fn detected_csv(epochs: &[FieldEpoch], truth: Option<&EmScenario>) -> String {
    let mut s = String::from("time_s");
    for i in 1..=3 {
        for a in AXES {
            let _ = write!(s, ",h{i}_{a}_re_t,h{i}_{a}_im_t");
        }
    }
    for i in 1..=3 {
        for a in AXES {
            let _ = write!(s, ",xi{i}_{a}_re,xi{i}_{a}_im");
        }
    }
    if truth.is_some() {
        s.push_str(
            ",true_x_m,true_y_m,true_z_m,true_range_m,true_roll_deg,true_pitch_deg,true_yaw_deg",
        );
    }
    s.push('\n');
    for e in epochs {
        let _ = write!(s, "{}", e.time_s);
        for v in e.h.iter().flatten().chain(e.xi.iter().flatten()) {
            let _ = write!(s, ",{},{}", v.re, v.im);
        }
        if let Some(sc) = truth {
            let p = sc.pose_at(e.time_s);
            let a = p.attitude();
            let _ = write!(
                s,
                ",{},{},{},{},{},{},{}",
                p.position_m[0],
                p.position_m[1],
                p.position_m[2],
                p.range_m(),
                a.roll.to_degrees(),
                a.pitch.to_degrees(),
                a.yaw.to_degrees()
            );
        }
        s.push('\n');
    }
    s
}
