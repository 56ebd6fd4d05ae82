//! Truth files of a simulated record (spec `data-formats.md`: truth in
//! `true_` columns, never read by the estimators; used by `aeromag em
//! simulate`).
//!
//! - [`truth_csv`]: `time_s, true_x_m, true_y_m, true_z_m, true_range_m,
//!   true_roll_deg, true_pitch_deg, true_yaw_deg` at given times (receiver
//!   position in the transmitter frame; attitude of the receiver axes
//!   relative to the transmitter frame as Z-Y-X Euler angles,
//!   [`crate::positioning::Pose::attitude`]).
//! - [`known_csv`]: the external information a crew has for calibration
//!   stages 2 and 3 (`time_s, x_m, y_m, z_m, roll_deg, pitch_deg, yaw_deg`;
//!   empty cells where a quantity is not known), the format `aeromag em
//!   calibrate --known` reads.

use super::EmScenario;
use std::fmt::Write;

/// Truth CSV at the flight times `times_s` (s).
pub fn truth_csv(sc: &EmScenario, times_s: &[f64]) -> String {
    let mut s = String::from(
        "time_s,true_x_m,true_y_m,true_z_m,true_range_m,true_roll_deg,true_pitch_deg,true_yaw_deg\n",
    );
    for &t in times_s {
        let _ = writeln!(s, "{t},{}", pose_fields(sc, t, true));
    }
    s
}

/// `x,y,z[,range],roll,pitch,yaw` of the truth pose at `t_s`.
fn pose_fields(sc: &EmScenario, t_s: f64, with_range: bool) -> String {
    let p = sc.pose_at(t_s);
    let a = p.attitude();
    let r = &p.position_m;
    let range = if with_range {
        format!(",{}", p.range_m())
    } else {
        String::new()
    };
    format!(
        "{},{},{}{range},{},{},{}",
        r[0],
        r[1],
        r[2],
        a.roll.to_degrees(),
        a.pitch.to_degrees(),
        a.yaw.to_degrees()
    )
}

/// KNOWN CSV: positions at `position_times_s` and, at `attitude_times_s`,
/// the attitude too (rows in time order; a time in both lists gives one row
/// with everything).
pub fn known_csv(sc: &EmScenario, position_times_s: &[f64], attitude_times_s: &[f64]) -> String {
    let mut times: Vec<f64> = position_times_s
        .iter()
        .chain(attitude_times_s)
        .copied()
        .collect();
    times.sort_by(f64::total_cmp);
    times.dedup();
    let mut s = String::from("time_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n");
    for t in times {
        let pos = position_times_s.contains(&t);
        let att = attitude_times_s.contains(&t);
        let f = pose_fields(sc, t, false);
        let v: Vec<&str> = f.split(',').collect();
        let pick = |k: usize, keep: bool| if keep { v[k] } else { "" };
        let _ = writeln!(
            s,
            "{t},{},{},{},{},{},{}",
            pick(0, pos),
            pick(1, pos),
            pick(2, pos),
            pick(3, att),
            pick(4, att),
            pick(5, att)
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::EmSimConfig;

    #[test]
    fn known_rows_leave_unknown_cells_empty() {
        let sc = EmScenario::new(EmSimConfig::default()).unwrap();
        let k = known_csv(&sc, &[0.08, 0.24], &[0.08]);
        let rows: Vec<Vec<&str>> = k.lines().map(|l| l.split(',').collect()).collect();
        assert_eq!(rows.len(), 3);
        assert!(rows.iter().all(|r| r.len() == 7));
        assert!(rows[1].iter().all(|c| !c.is_empty()));
        assert!(rows[2][1..4].iter().all(|c| !c.is_empty()));
        assert!(rows[2][4..].iter().all(|c| c.is_empty()));
        let t = truth_csv(&sc, &[0.24]);
        let tr: Vec<f64> = t
            .lines()
            .nth(1)
            .unwrap()
            .split(',')
            .map(|v| v.parse().unwrap())
            .collect();
        let kr: Vec<f64> = rows[2][..4].iter().map(|v| v.parse().unwrap()).collect();
        assert_eq!(&tr[..4], &kr[..]);
        let p = sc.pose_at(0.24);
        assert!((tr[4] - p.range_m()).abs() < 1e-12);
    }
}
