//! Positions off the track: rows whose latitude and longitude jump away
//! from the flight's track faster than anything flies, and back (a GPS
//! dropout written as 0, a corrupted cell, a navigation record of another
//! epoch).
//!
//! Two rows are *consistent* when the great-circle distance between their
//! positions is at most `max(MIN_JUMP_M, MAX_GROUND_SPEED_M_S · |Δt|)`. The
//! rows with a finite time, latitude and longitude are cut into runs at
//! each pair of successive rows that is not consistent. The run of most
//! rows is the track's; from it, forward and then backward, each next run
//! is kept when its first (last) row is consistent with the last (first)
//! row kept, and is off the track otherwise. So one glitch row, a run of
//! them, several different ones in a row, and glitches at the flight's
//! start or end are found, while a long gap in time (a transit, a
//! refuelling) allows any plausible displacement.
//!
//! A glitch of less than [`MIN_JUMP_M`] is not found: it does not change a
//! grid's extent, which is what this guards (a row at latitude 0 in a
//! survey at 56° N made the grid 6 200 km tall and its solve run for
//! minutes).

/// Fastest ground speed counted as flight, m/s: survey aircraft fly at
/// 30–150 m/s, and a jet at Mach 3 flies at about 1000 m/s.
pub const MAX_GROUND_SPEED_M_S: f64 = 1000.0;

/// Shortest jump counted as off the track, m: a step of a few metres in a
/// millisecond (a GPS position held between its epochs and then updated,
/// in a record sampled at 1 kHz) is not a glitch.
pub const MIN_JUMP_M: f64 = 1000.0;

/// Mean Earth radius for the great-circle distance, m.
const EARTH_RADIUS_M: f64 = 6_371_000.0;

/// The rows (ascending, 0-based) whose position is off the track (module
/// docs): `time_s` (s, increasing), `lat_deg` and `lon_deg` (degrees) of
/// every row; rows with a missing value are neither judged nor judge.
pub fn position_glitches(time_s: &[f64], lat_deg: &[f64], lon_deg: &[f64]) -> Vec<usize> {
    off_track(time_s, lat_deg, lon_deg, |a, b, most| {
        within(
            [lat_deg[a].to_radians(), lon_deg[a].to_radians()],
            [lat_deg[b].to_radians(), lon_deg[b].to_radians()],
            most,
        )
    })
}

/// [`position_glitches`] of projected positions: `x_m` and `y_m` (easting
/// and northing, m), the distance between two rows the plane's.
pub fn projected_position_glitches(time_s: &[f64], x_m: &[f64], y_m: &[f64]) -> Vec<usize> {
    off_track(time_s, x_m, y_m, |a, b, most| {
        (x_m[b] - x_m[a]).hypot(y_m[b] - y_m[a]) <= most
    })
}

/// The rows off the track of positions given as two coordinates per row,
/// `close(a, b, most_m)` saying whether rows `a` and `b` are at most
/// `most_m` apart.
fn off_track(
    time_s: &[f64],
    c0: &[f64],
    c1: &[f64],
    close: impl Fn(usize, usize, f64) -> bool,
) -> Vec<usize> {
    let n = time_s.len().min(c0.len()).min(c1.len());
    let valid = |k: usize| time_s[k].is_finite() && c0[k].is_finite() && c1[k].is_finite();
    let consistent = |a: usize, b: usize| {
        let most = MIN_JUMP_M.max(MAX_GROUND_SPEED_M_S * (time_s[b] - time_s[a]).abs());
        close(a, b, most)
    };
    // Runs between jumps, each its first and last valid row and how many
    // valid rows it holds (no per-row memory: 10⁷ rows take none).
    let mut runs: Vec<Run> = Vec::new();
    for k in (0..n).filter(|&k| valid(k)) {
        match runs.last_mut() {
            Some(run) if consistent(run.last, k) => {
                run.last = k;
                run.rows += 1;
            }
            _ => runs.push(Run {
                first: k,
                last: k,
                rows: 1,
            }),
        }
    }
    if runs.len() < 2 {
        return Vec::new();
    }
    let longest = runs.iter().map(|r| r.rows).max().unwrap_or(0);
    let anchor = runs.iter().position(|r| r.rows == longest).unwrap_or(0);
    let mut off = vec![false; runs.len()];
    let mut last = runs[anchor].last;
    for (r, run) in runs.iter().enumerate().skip(anchor + 1) {
        if consistent(last, run.first) {
            last = run.last;
        } else {
            off[r] = true;
        }
    }
    let mut first = runs[anchor].first;
    for (r, run) in runs.iter().enumerate().take(anchor).rev() {
        if consistent(run.last, first) {
            first = run.first;
        } else {
            off[r] = true;
        }
    }
    runs.iter()
        .zip(off)
        .filter(|(_, off)| *off)
        .flat_map(|(run, _)| (run.first..=run.last).filter(|&k| valid(k)))
        .collect()
}

/// Successive valid rows without a jump between them ([`off_track`]).
struct Run {
    first: usize,
    last: usize,
    rows: usize,
}

/// Whether the great-circle distance between `a` and `b` (latitude,
/// longitude; rad) is at most `most_m`: first against a bound that needs
/// no trigonometry (the path along the meridian, then along the parallel,
/// is no shorter than the great circle: `d ≤ R(|Δφ| + |Δλ|)`), then by the
/// haversine formula.
fn within(a: [f64; 2], b: [f64; 2], most_m: f64) -> bool {
    use std::f64::consts::{PI, TAU};
    let dphi = (b[0] - a[0]).abs();
    let dlambda = (b[1] - a[1]).rem_euclid(TAU);
    let dlambda = dlambda.min(TAU - dlambda);
    if EARTH_RADIUS_M * (dphi + dlambda) <= most_m {
        return true;
    }
    let h = (0.5 * dphi).sin().powi(2) + a[0].cos() * b[0].cos() * (0.5 * dlambda).sin().powi(2);
    let d = 2.0 * EARTH_RADIUS_M * h.sqrt().min(1.0).asin();
    debug_assert!(d <= EARTH_RADIUS_M * PI + 1.0);
    d <= most_m
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A line north at 60 m/s, 10 Hz, from 56° N 38° E: `n` rows.
    fn track(n: usize) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let t: Vec<f64> = (0..n).map(|k| 36_000.0 + 0.1 * k as f64).collect();
        let lat = (0..n).map(|k| 56.0 + 6.0 * k as f64 / 111_195.0).collect();
        (t, lat, vec![38.0; n])
    }

    /// The same track in metres (north at 60 m/s) finds the same rows as
    /// in degrees, a dropout written as 0, 0 among them.
    #[test]
    fn projected_positions_find_the_same_rows() {
        let (t, mut lat, mut lon) = track(1000);
        let mut x = vec![412_000.0; 1000];
        let mut y: Vec<f64> = (0..1000).map(|k| 6_200_000.0 + 6.0 * k as f64).collect();
        for k in [0, 500, 501, 999] {
            (lat[k], lon[k], x[k], y[k]) = (0.0, 0.0, 0.0, 0.0);
        }
        y[300] = f64::NAN;
        let found = projected_position_glitches(&t, &x, &y);
        assert_eq!(found, vec![0, 500, 501, 999]);
        assert_eq!(found, position_glitches(&t, &lat, &lon));
    }

    #[test]
    fn a_clean_track_has_none() {
        let (t, lat, lon) = track(1000);
        assert!(position_glitches(&t, &lat, &lon).is_empty());
    }

    #[test]
    fn one_row_at_latitude_zero_is_found() {
        let (t, mut lat, lon) = track(1000);
        lat[700] = 0.0;
        assert_eq!(position_glitches(&t, &lat, &lon), [700]);
    }

    #[test]
    fn a_run_and_two_different_glitches_in_a_row_are_found() {
        let (t, mut lat, mut lon) = track(1000);
        for k in 100..105 {
            (lat[k], lon[k]) = (0.0, 0.0);
        }
        lat[500] = -33.0;
        lon[501] = 150.0;
        assert_eq!(
            position_glitches(&t, &lat, &lon),
            [100, 101, 102, 103, 104, 500, 501]
        );
    }

    #[test]
    fn glitches_at_the_start_and_the_end_are_found() {
        let (t, mut lat, lon) = track(1000);
        lat[0] = 0.0;
        lat[1] = 0.0;
        lat[999] = 89.0;
        assert_eq!(position_glitches(&t, &lat, &lon), [0, 1, 999]);
    }

    #[test]
    fn a_gap_in_time_allows_a_plausible_displacement() {
        // A second block 50 km east after an hour's transit without
        // samples (180 km at 50 m/s would be plausible too).
        let (mut t, mut lat, mut lon) = track(2000);
        for k in 1000..2000 {
            t[k] += 3600.0;
            lon[k] += 50_000.0 / (111_195.0 * 56f64.to_radians().cos());
        }
        assert!(position_glitches(&t, &lat, &lon).is_empty());
        // The same displacement between two successive samples is a jump;
        // the shorter part is off the track.
        for tk in &mut t[1000..] {
            *tk -= 3600.0;
        }
        lat.truncate(1300);
        lon.truncate(1300);
        t.truncate(1300);
        assert_eq!(
            position_glitches(&t, &lat, &lon),
            (1000..1300).collect::<Vec<_>>()
        );
    }

    #[test]
    fn missing_values_are_neither_judged_nor_judge() {
        let (mut t, mut lat, mut lon) = track(100);
        lat[10] = f64::NAN;
        lon[20] = f64::NAN;
        t[30] = f64::NAN;
        lat[40] = 0.0;
        assert_eq!(position_glitches(&t, &lat, &lon), [40]);
    }

    #[test]
    fn the_antimeridian_is_no_jump() {
        let n = 100;
        let t: Vec<f64> = (0..n).map(|k| k as f64).collect();
        let lat = vec![-17.0; n];
        // Eastward at 100 m/s across 180°.
        let step = 100.0 / (111_195.0 * 17f64.to_radians().cos());
        let lon: Vec<f64> = (0..n)
            .map(|k| {
                let l = 179.99 + step * k as f64;
                if l > 180.0 { l - 360.0 } else { l }
            })
            .collect();
        assert!(lon.iter().any(|&l| l < 0.0));
        assert!(position_glitches(&t, &lat, &lon).is_empty());
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]
        /// Rows moved far off a clean track (anywhere on Earth at least
        /// 100 km away), alone or in runs, are exactly those found.
        #[test]
        fn rows_moved_far_off_a_clean_track_are_exactly_those_found(
            moved in proptest::collection::btree_set(0usize..600, 1..30),
            places in proptest::collection::vec((-89.0f64..89.0, -180.0f64..180.0), 30),
        ) {
            let (t, mut lat, mut lon) = track(600);
            let mut want = Vec::new();
            for (&k, &(la, lo)) in moved.iter().zip(places.iter().cycle()) {
                // Keep away from the track (56–56.04° N, 38° E).
                let la = if (la - 56.0).abs() < 2.0 && (lo - 38.0).abs() < 4.0 { la - 10.0 } else { la };
                (lat[k], lon[k]) = (la, lo);
                want.push(k);
            }
            prop_assert_eq!(position_glitches(&t, &lat, &lon), want);
        }
    }
}
