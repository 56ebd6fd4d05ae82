//! Ground speed and along-track distance, the independent variable of the
//! field model ([`super::anomaly_model`]).
//!
//! The step between samples `k−1` and `k` is the trapezoidal path length
//! `d_k = ½ (v_{k−1} + v_k)(t_k − t_{k−1})` (m) with `v` the ground speed
//! (m/s), from the navigation velocity `v = √(v_n² + v_e²)` or, when no
//! velocity is recorded, from the positions by central differences of the
//! local north/east offsets (WGS84 radii of curvature,
//! [`aeromag_core::frames::Geodetic::ned_offset_to`]).

use aeromag_core::frames::Geodetic;

/// Ground speed `√(v_n² + v_e²)`, m/s, from the north and east velocity (m/s).
pub fn ground_speed_from_velocity(vn: &[f64], ve: &[f64]) -> Vec<f64> {
    vn.iter().zip(ve).map(|(n, e)| n.hypot(*e)).collect()
}

/// Ground speed, m/s, from time (s) and WGS84 latitude/longitude (deg):
/// horizontal distance between the neighbours `k−1` and `k+1` over their
/// time difference, one-sided at the ends. Non-finite inputs give NaN at the
/// affected samples; fewer than two samples give NaN.
pub fn ground_speed_from_positions(time: &[f64], lat_deg: &[f64], lon_deg: &[f64]) -> Vec<f64> {
    let n = time.len().min(lat_deg.len()).min(lon_deg.len());
    let speed = |a: usize, b: usize| {
        let pa = Geodetic::new(lat_deg[a], lon_deg[a], 0.0);
        let pb = Geodetic::new(lat_deg[b], lon_deg[b], 0.0);
        let [dn, de, _] = pa.ned_offset_to(&pb);
        let dt = time[b] - time[a];
        if dt > 0.0 {
            dn.hypot(de) / dt
        } else {
            f64::NAN
        }
    };
    (0..n)
        .map(|k| {
            if n < 2 {
                f64::NAN
            } else if k == 0 {
                speed(0, 1)
            } else if k == n - 1 {
                speed(n - 2, n - 1)
            } else {
                speed(k - 1, k + 1)
            }
        })
        .collect()
}

/// Path length between samples `k−1` and `k`, m: `½(v_{k−1} + v_k)(t_k − t_{k−1})`.
pub fn step_length(time: &[f64], speed: &[f64], k: usize) -> f64 {
    0.5 * (speed[k - 1] + speed[k]) * (time[k] - time[k - 1])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn speed_from_positions_matches_the_velocity() {
        // 80 m/s on a heading of 30° at 56° N, 10 Hz.
        let origin = Geodetic::new(56.0, 38.0, 0.0);
        let (v, hdg) = (80.0f64, 30f64.to_radians());
        let t: Vec<f64> = (0..50).map(|k| k as f64 * 0.1).collect();
        let pos: Vec<Geodetic> = t
            .iter()
            .map(|s| origin.offset_by(v * s * hdg.cos(), v * s * hdg.sin(), 0.0))
            .collect();
        let lat: Vec<f64> = pos.iter().map(|p| p.lat_deg).collect();
        let lon: Vec<f64> = pos.iter().map(|p| p.lon_deg).collect();
        let s = ground_speed_from_positions(&t, &lat, &lon);
        assert!(s.iter().all(|x| (x - 80.0).abs() < 0.05), "{:?}", &s[..3]);
        let g = ground_speed_from_velocity(&[v * hdg.cos()], &[v * hdg.sin()]);
        assert!((g[0] - 80.0).abs() < 1e-12);
        assert!((step_length(&t, &s, 1) - 8.0).abs() < 0.01);
        assert!(ground_speed_from_positions(&t[..1], &lat[..1], &lon[..1])[0].is_nan());
    }
}
