//! The fixed-wing simulation pipeline shared by the calibration and survey
//! scenarios.
//!
//! 1. Fly the pattern ([`crate::trajectory::fly`]): true position, velocity,
//!    attitude of the navigation reference point.
//! 2. Sensor positions: `p_s = p + C_nb r_s` for the scalar sensor and the
//!    fluxgate (lever arms in body axes).
//! 3. External field at each sensor: IGRF-14 + anomaly (grid continued to
//!    the flight's altitude range + dipoles) + diurnal along the main field;
//!    rotated into body axes with `C_bn`. (The main field and the diurnal
//!    variation are evaluated once, at the scalar sensor: across the 2 m
//!    between the sensors they differ by < 0.02 nT. The anomaly is
//!    evaluated at each sensor.)
//! 4. Aircraft interference at each sensor (parts, eddy currents driven by
//!    the body-frame field history, on-board currents).
//! 5. Sensor models: scalar (exact modulus, heading error, lag, noise),
//!    fluxgate, GNSS/INS, base station.
//! 6. Columns, filled-in scenario file and truth metadata.
//!
//! ## Extra sensors
//!
//! A survey aircraft may carry more magnetometers than the stinger pair:
//! SGL's fixed-wing installation has five scalar sensors (one in the tail
//! stinger, four in the cabin) and four fluxgates. The optional lists
//! `extra_scalars` and `extra_fluxgates` of the scenario file
//! ([`super::config::FixedWingConfig`]) add them; both are empty by default,
//! and then nothing below changes the output. Each extra sensor gets
//!
//! * the external field at its own lever arm: the anomaly evaluated at the
//!   sensor, the main field and the diurnal variation as at the main scalar
//!   sensor (step 3);
//! * the aircraft's field at its position ([`InterferenceAt`], the parts
//!   induced by the external field at the sensor, the same eddy and
//!   on-board currents);
//! * its own sensor model and random stream
//!   ([`Stream::ExtraScalarNoise`]`(k)`, [`Stream::ExtraFluxgateNoise`]`(j)`),
//!   so adding sensors changes no existing column, main sensors included
//!   (the anomaly grid is sized on the main sensors' tracks; extra lever
//!   arms are limited to 50 m, well inside its margin).
//!
//! Columns: extra scalar `k` = 2, 3, … → `mag_k` (recorded, nT),
//! `true_interf_k` (`|B_ext + ΔB| − |B_ext|` at the sensor, nT) and
//! `true_external_k` (`|B_ext|` at the sensor, nT); extra fluxgate
//! `j` = b, c, d, … → `flux_j_x/y/z` (recorded, body axes, nT) and
//! `true_flux_j_x/y/z` (true total field there, before sensor errors). The
//! truth JSON lists them under `sensors.extra_scalars` and
//! `sensors.extra_fluxgates` with their configuration (position), their
//! interference coefficients and statistics.
//!
//! An example in the spirit of the SGL installation (stinger sensor at the
//! default `(−9.5, 0, −0.6)` m; four cabin sensors and three more
//! fluxgates between x = −2 and +2 m, a metre or two from the engines and
//! the landing gear, so their interference is several times the stinger's):
//!
//! ```toml
//! [[extra_scalars]]
//! position_m = [-2.0, 0.0, -0.3]
//! [[extra_scalars]]
//! position_m = [-1.0, -0.4, -0.3]
//! [[extra_scalars]]
//! position_m = [0.5, 0.4, -0.3]
//! [[extra_scalars]]
//! position_m = [1.5, 0.0, -0.4]
//! [[extra_fluxgates]]
//! position_m = [-2.0, 0.3, -0.3]
//! [[extra_fluxgates]]
//! position_m = [0.0, -0.3, -0.3]
//! [[extra_fluxgates]]
//! position_m = [1.5, 0.3, -0.4]
//! ```
//!
//! Unset fields of each table take the sensor type's defaults (for a scalar
//! sensor lag 0 s, whatever the scenario's main sensor uses).

use aeromag_core::NT_PER_T;
use aeromag_core::frames::Geodetic;
use aeromag_core::time::Date;
use nalgebra::Vector3;
use serde_json::json;

use super::ScenarioKind;
use super::config::{FixedWingConfig, Pattern, extra_fluxgate_letter};
use super::installation::{Installation, sgl_name};
use crate::environment::anomaly::{AnomalyField, Extent};
use crate::environment::main_field::{MainField, decimal_year};
use crate::error::{Result, SimError, invalid};
use crate::output::{Column, Simulation, describe};
use crate::platform::aircraft::{InterferenceAt, eddy_currents, nt};
use crate::platform::currents;
use crate::random::{Stream, rng_for};
use crate::sensor::white_rms;
use crate::trajectory::{Trajectory, fly};

/// Positions (local north, east, altitude) of a body-fixed point along the
/// trajectory.
fn lever_arm_positions(tr: &Trajectory, r_b: [f64; 3]) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let r = Vector3::from(r_b);
    let n = tr.len();
    let (mut pn, mut pe, mut pa) = (
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
    );
    for k in 0..n {
        let d = tr.attitude(k).c_nb() * r;
        pn.push(tr.north_m[k] + d.x);
        pe.push(tr.east_m[k] + d.y);
        pa.push(tr.alt_m[k] - d.z);
    }
    (pn, pe, pa)
}

/// Geodetic position of a local point `(north, east, alt)` relative to the
/// origin `(lat0, lon0)`; the radii of curvature are taken at the point's
/// altitude, so local metres are metres at flight height.
fn geodetic(lat0: f64, lon0: f64, north: f64, east: f64, alt: f64) -> Geodetic {
    Geodetic::new(lat0, lon0, alt).offset_by(north, east, alt)
}

fn stats(v: &[f64]) -> serde_json::Value {
    let n = v.len().max(1) as f64;
    let mean = v.iter().sum::<f64>() / n;
    let rms_dev = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n).sqrt();
    let min = v.iter().copied().fold(f64::INFINITY, f64::min);
    let max = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    json!({ "mean": mean, "std": rms_dev, "min": min, "max": max })
}

/// Run a fixed-wing scenario with a validated configuration.
pub fn run<P: Pattern>(cfg: &FixedWingConfig<P>, kind: ScenarioKind) -> Result<Simulation> {
    cfg.validate()?;
    let seed = cfg.seed;
    let fl = &cfg.flight;
    let dt = 1.0 / fl.sample_rate_hz;
    let date = Date::parse(&fl.date).map_err(|e| invalid("flight.date", e.to_string()))?;

    // 1. Trajectory.
    let plan = cfg.pattern.plan(fl, &cfg.kinematics)?;
    let tr = fly(
        &plan,
        &cfg.kinematics,
        &cfg.turbulence,
        dt,
        rng_for(seed, Stream::Turbulence),
    )?;
    let n = tr.len();
    if n < 2 {
        return Err(SimError::Trajectory(
            "the flight has fewer than two samples".into(),
        ));
    }
    let duration = tr.t_s[n - 1];

    // 2. Sensor positions.
    let (sn, se, sa) = lever_arm_positions(&tr, cfg.scalar.position_m);
    let (fn_, fe, fa) = lever_arm_positions(&tr, cfg.fluxgate.position_m);
    let xs_pos: Vec<_> = cfg
        .extra_scalars
        .iter()
        .map(|s| lever_arm_positions(&tr, s.position_m))
        .collect();
    let xf_pos: Vec<_> = cfg
        .extra_fluxgates
        .iter()
        .map(|f| lever_arm_positions(&tr, f.position_m))
        .collect();

    // 3. External field.
    let extent = Extent::of_points(&sn, &se, &sa).union(&Extent::of_points(&fn_, &fe, &fa));
    let anomaly = AnomalyField::build(
        &cfg.anomaly,
        fl.terrain_alt_m,
        &extent,
        &mut rng_for(seed, Stream::Anomaly),
    )?;
    let centre = geodetic(
        fl.origin_lat_deg,
        fl.origin_lon_deg,
        0.5 * (extent.north_min + extent.north_max),
        0.5 * (extent.east_min + extent.east_max),
        0.5 * (extent.alt_min + extent.alt_max),
    );
    let main = MainField::new(&date, fl.start_time_utc_s, duration, &centre)?;
    let diurnal = cfg
        .diurnal
        .generate(n, dt, &mut rng_for(seed, Stream::Diurnal))?;

    let mut b_s = Vec::with_capacity(n); // external, body, scalar sensor, nT
    let mut b_f = Vec::with_capacity(n); // external, body, fluxgate, nT
    let mut true_igrf = Vec::with_capacity(n);
    let mut true_anomaly = Vec::with_capacity(n);
    let mut true_diurnal = Vec::with_capacity(n);
    let mut true_external = Vec::with_capacity(n);
    // External fields at the extra sensors, body axes, nT.
    let mut xs_b: Vec<Vec<Vector3<f64>>> = xs_pos.iter().map(|_| Vec::with_capacity(n)).collect();
    let mut xf_b: Vec<Vec<Vector3<f64>>> = xf_pos.iter().map(|_| Vec::with_capacity(n)).collect();
    for k in 0..n {
        let pos = geodetic(fl.origin_lat_deg, fl.origin_lon_deg, sn[k], se[k], sa[k]);
        let bm = main.field_nt(&pos, tr.t_s[k]);
        let e_main = bm / bm.norm();
        let ba_s = anomaly.field_nt(sn[k], se[k], sa[k]);
        let ba_f = anomaly.field_nt(fn_[k], fe[k], fa[k]);
        let bd = e_main * diurnal[k];
        let ext_s = bm + ba_s + bd;
        let ext_f = bm + ba_f + bd;
        let c_bn = tr.attitude(k).c_bn();
        b_s.push(c_bn * ext_s);
        b_f.push(c_bn * ext_f);
        for (out, (pn, pe, pa)) in xs_b.iter_mut().zip(&xs_pos) {
            out.push(c_bn * (bm + anomaly.field_nt(pn[k], pe[k], pa[k]) + bd));
        }
        for (out, (pn, pe, pa)) in xf_b.iter_mut().zip(&xf_pos) {
            out.push(c_bn * (bm + anomaly.field_nt(pn[k], pe[k], pa[k]) + bd));
        }
        let f_main = bm.norm();
        let f_ma = (bm + ba_s).norm();
        let f_ext = ext_s.norm();
        true_igrf.push(f_main);
        true_anomaly.push(f_ma - f_main);
        true_diurnal.push(f_ext - f_ma);
        true_external.push(f_ext);
    }

    // 4. Aircraft interference.
    let ac = &cfg.aircraft;
    let eddy = eddy_currents(ac, &b_s, dt)?;
    let mut cur_rng = rng_for(seed, Stream::Currents);
    let cur: Vec<currents::CurrentSeries> = ac
        .currents
        .iter()
        .map(|c| currents::generate(c, n, dt, &mut cur_rng))
        .collect();
    let at_s = InterferenceAt::new(ac, cfg.scalar.position_m)?;
    let at_f = InterferenceAt::new(ac, cfg.fluxgate.position_m)?;
    let mut total_s = Vec::with_capacity(n);
    let mut total_f = Vec::with_capacity(n);
    let mut interf_vec = Vec::with_capacity(n);
    let mut parts: [Vec<f64>; 4] = std::array::from_fn(|_| Vec::with_capacity(n));
    let mut true_interf = Vec::with_capacity(n);
    let (mut i_e, mut i_c) = (vec![0.0; eddy.len()], vec![0.0; cur.len()]);
    for k in 0..n {
        for (slot, series) in i_e.iter_mut().zip(&eddy) {
            *slot = series[k];
        }
        for (slot, series) in i_c.iter_mut().zip(&cur) {
            *slot = series.field_a()[k];
        }
        let bt_s = b_s[k] / NT_PER_T;
        let hours = tr.t_s[k] / 3600.0;
        let c_s = at_s.contributions(hours, &bt_s, &i_e, &i_c);
        let c_f = at_f.contributions(hours, &(b_f[k] / NT_PER_T), &i_e, &i_c);
        let d_s = nt(c_s.total());
        let tot = b_s[k] + d_s;
        let e = b_s[k] / b_s[k].norm();
        for (slot, c) in parts
            .iter_mut()
            .zip([c_s.permanent, c_s.induced, c_s.eddy, c_s.current])
        {
            slot.push(e.dot(&nt(c)));
        }
        true_interf.push(tot.norm() - b_s[k].norm());
        total_s.push(tot);
        interf_vec.push(d_s);
        total_f.push(b_f[k] + nt(c_f.total()));
    }
    // The extra sensors: the same parts and currents at their positions.
    // (The third item: the currents' part of the interference, projected
    // on the external field's direction.)
    type Extra = (InterferenceAt, Vec<Vector3<f64>>, Vec<f64>);
    let extra_total = |pos: [f64; 3], ext: &[Vector3<f64>]| -> Result<Extra> {
        let at = InterferenceAt::new(ac, pos)?;
        let (mut i_e, mut i_c) = (vec![0.0; eddy.len()], vec![0.0; cur.len()]);
        let mut total = Vec::with_capacity(n);
        let mut current = Vec::with_capacity(n);
        for (k, b) in ext.iter().enumerate() {
            for (slot, series) in i_e.iter_mut().zip(&eddy) {
                *slot = series[k];
            }
            for (slot, series) in i_c.iter_mut().zip(&cur) {
                *slot = series.field_a()[k];
            }
            let c = at.contributions(tr.t_s[k] / 3600.0, &(b / NT_PER_T), &i_e, &i_c);
            current.push(b.dot(&nt(c.current)) / b.norm());
            total.push(b + nt(c.total()));
        }
        Ok((at, total, current))
    };
    let xs_total = cfg
        .extra_scalars
        .iter()
        .zip(&xs_b)
        .map(|(s, b)| extra_total(s.position_m, b))
        .collect::<Result<Vec<_>>>()?;
    let xf_total = cfg
        .extra_fluxgates
        .iter()
        .zip(&xf_b)
        .map(|(f, b)| extra_total(f.position_m, b))
        .collect::<Result<Vec<_>>>()?;

    // 5. Sensors.
    let scalar = cfg
        .scalar
        .measure(&total_s, dt, &mut rng_for(seed, Stream::ScalarNoise));
    let flux = cfg
        .fluxgate
        .measure(&total_f, dt, &mut rng_for(seed, Stream::FluxgateNoise));
    let xs_read: Vec<_> = cfg
        .extra_scalars
        .iter()
        .zip(&xs_total)
        .enumerate()
        .map(|(i, (s, (_, tot, _)))| {
            s.measure(
                tot,
                dt,
                &mut rng_for(seed, Stream::ExtraScalarNoise(i as u32 + 2)),
            )
        })
        .collect();
    let xf_read: Vec<_> = cfg
        .extra_fluxgates
        .iter()
        .zip(&xf_total)
        .enumerate()
        .map(|(j, (f, (_, tot, _)))| {
            f.measure(
                tot,
                dt,
                &mut rng_for(seed, Stream::ExtraFluxgateNoise(j as u32 + 1)),
            )
        })
        .collect();
    let nav = cfg.nav.measure(&tr, &mut rng_for(seed, Stream::Navigation));
    let base = cfg
        .base_station
        .measure(&diurnal, &mut rng_for(seed, Stream::BaseStation));

    // 6. Columns.
    let mut cols: Vec<(String, Vec<f64>)> = Vec::new();
    let mut push = |name: &str, v: Vec<f64>| cols.push((name.to_string(), v));
    let deg = |v: &[f64]| v.iter().map(|x| x.to_degrees()).collect::<Vec<f64>>();
    let comp = |v: &[Vector3<f64>], i: usize| v.iter().map(|b| b[i]).collect::<Vec<f64>>();

    let mut lat = Vec::with_capacity(n);
    let mut lon = Vec::with_capacity(n);
    let mut igrf = Vec::with_capacity(n);
    let mut t_lat = Vec::with_capacity(n);
    let mut t_lon = Vec::with_capacity(n);
    for k in 0..n {
        let g = geodetic(
            fl.origin_lat_deg,
            fl.origin_lon_deg,
            nav.north_m[k],
            nav.east_m[k],
            nav.alt_m[k],
        );
        lat.push(g.lat_deg);
        lon.push(g.lon_deg);
        igrf.push(main.field_nt(&g, tr.t_s[k]).norm());
        let t = geodetic(
            fl.origin_lat_deg,
            fl.origin_lon_deg,
            tr.north_m[k],
            tr.east_m[k],
            tr.alt_m[k],
        );
        t_lat.push(t.lat_deg);
        t_lon.push(t.lon_deg);
    }
    push(
        "time",
        tr.t_s.iter().map(|t| fl.start_time_utc_s + t).collect(),
    );
    push("lat", lat);
    push("lon", lon);
    push("alt", nav.alt_m.clone());
    push("vn", nav.vn.clone());
    push("ve", nav.ve.clone());
    push("vd", nav.vd.clone());
    push("roll", deg(&nav.roll));
    push("pitch", deg(&nav.pitch));
    push("yaw", deg(&nav.yaw));
    push("mag", scalar.mag.clone());
    push("flux_x", comp(&flux, 0));
    push("flux_y", comp(&flux, 1));
    push("flux_z", comp(&flux, 2));
    for (i, r) in xs_read.iter().enumerate() {
        push(&format!("mag_{}", i + 2), r.mag.clone());
    }
    for (j, r) in xf_read.iter().enumerate() {
        let l = extra_fluxgate_letter(j);
        for (i, a) in ["x", "y", "z"].iter().enumerate() {
            push(&format!("flux_{l}_{a}"), comp(r, i));
        }
    }
    push("line", tr.line.clone());
    push("manoeuvre", tr.manoeuvre.clone());
    push("diurnal", base);
    push("igrf", igrf);
    for (c, s) in ac.currents.iter().zip(&cur) {
        push(&format!("cur_{}", c.name), s.recorded_a.clone());
    }
    push("true_lat", t_lat);
    push("true_lon", t_lon);
    push("true_alt", tr.alt_m.clone());
    push("true_sensor_alt", sa.clone());
    push("true_vn", tr.vn.clone());
    push("true_ve", tr.ve.clone());
    push("true_vd", tr.vd.clone());
    push("true_roll", deg(&tr.roll));
    push("true_pitch", deg(&tr.pitch));
    push("true_yaw", deg(&tr.yaw));
    push("true_external", true_external);
    push("true_interf", true_interf);
    push("true_igrf", true_igrf);
    push("true_anomaly", true_anomaly);
    push("true_diurnal", true_diurnal);
    push("true_heading_error", scalar.heading_error.clone());
    push("true_lag", scalar.lag.clone());
    push("true_mag_noise", scalar.noise.clone());
    let [p_perm, p_ind, p_eddy, p_cur] = parts;
    push("true_interf_perm", p_perm);
    push("true_interf_induced", p_ind);
    push("true_interf_eddy", p_eddy);
    push("true_interf_current", p_cur);
    for (i, a) in ["x", "y", "z"].iter().enumerate() {
        push(&format!("true_ext_{a}"), comp(&b_s, i));
    }
    for (i, a) in ["x", "y", "z"].iter().enumerate() {
        push(&format!("true_interf_{a}"), comp(&interf_vec, i));
    }
    for (i, a) in ["x", "y", "z"].iter().enumerate() {
        push(&format!("true_flux_{a}"), comp(&total_f, i));
    }
    let sgl = cfg.installation == Installation::Sgl;
    for (i, ((_, tot, current), ext)) in xs_total.iter().zip(&xs_b).enumerate() {
        push(
            &format!("true_interf_{}", i + 2),
            tot.iter()
                .zip(ext)
                .map(|(t, b)| t.norm() - b.norm())
                .collect(),
        );
        push(
            &format!("true_external_{}", i + 2),
            ext.iter().map(|b| b.norm()).collect(),
        );
        if sgl {
            push(&format!("true_interf_current_{}", i + 2), current.clone());
        }
    }
    for (j, (_, tot, _)) in xf_total.iter().enumerate() {
        let l = extra_fluxgate_letter(j);
        for (i, a) in ["x", "y", "z"].iter().enumerate() {
            push(&format!("true_flux_{l}_{a}"), comp(tot, i));
        }
    }
    for (c, s) in ac.currents.iter().zip(&cur) {
        push(&format!("true_cur_{}", c.name), s.true_a.clone());
    }
    // The installation's names (the SGL layout's under `sgl`).
    let name_of = |name: &str| {
        if sgl {
            sgl_name(name)
        } else {
            name.to_string()
        }
    };
    let columns = cols
        .into_iter()
        .map(|(name, values)| {
            let name = name_of(&name);
            let (unit, description) = describe(&name).unwrap_or(("-", String::new()));
            Column {
                name,
                unit,
                description,
                values,
            }
        })
        .collect::<Vec<_>>();

    // Truth metadata.
    let m3 = |m: &nalgebra::Matrix3<f64>| -> Vec<[f64; 3]> {
        (0..3).map(|r| [m[(r, 0)], m[(r, 1)], m[(r, 2)]]).collect()
    };
    let v3 = |v: Vector3<f64>| [v.x, v.y, v.z];
    let sensor_json = |at: &InterferenceAt| {
        json!({
            "permanent_field_nt": v3(nt(at.permanent_t)),
            "induced_matrix": m3(&at.induced),
            "eddy_field_nt_per_a": at.eddy_per_a.iter().map(|f| v3(nt(*f))).collect::<Vec<_>>(),
            "current_field_nt_per_a": at.current_per_a.iter().map(|f| v3(nt(*f))).collect::<Vec<_>>(),
        })
    };
    let col_of = |name: &str| {
        columns
            .iter()
            .find(|c| c.name == name)
            .map(|c| c.values.as_slice())
            .unwrap_or(&[])
    };
    let interf_at_flux: Vec<f64> = total_f
        .iter()
        .zip(&b_f)
        .map(|(t, b)| (t - b).norm())
        .collect();
    let rate = fl.sample_rate_hz;
    let g = anomaly.geometry();
    let truth = json!({
        "format": "aeromag-sim-truth/1",
        "software": format!("aeromag-sim {}", env!("CARGO_PKG_VERSION")),
        "scenario": kind.name(),
        "seed": seed,
        "samples": n,
        "duration_s": duration,
        "sample_rate_hz": rate,
        "conventions": {
            "altitude": "WGS84 ellipsoidal height",
            "navigation_frame": "NED (x north, y east, z down)",
            "body_frame": "x forward, y right wing, z down; Euler Z-Y-X (yaw, pitch, roll)",
            "local_frame": "north/east metres from the origin, at the point's altitude",
            "positions": "lat/lon/alt are the navigation reference point (body origin); sensors at lever arms",
        },
        "origin": { "lat_deg": fl.origin_lat_deg, "lon_deg": fl.origin_lon_deg },
        "terrain_alt_m": fl.terrain_alt_m,
        "main_field": {
            "model": "IGRF-14",
            "decimal_year_at_start": decimal_year(&date, fl.start_time_utc_s),
            "secular_variation_nt_per_hour": v3(main.rate_nt_per_s() * 3600.0),
        },
        "anomaly": {
            "config": &cfg.anomaly,
            "grid": g,
            "spectral_amplitude_nt2_m2": anomaly.spectral_amplitude(),
            "expected_gradient_nt_per_100m_at_reference_height": cfg.anomaly.expected_gradient_nt_per_100m(cfg.anomaly.reference_height_m),
            "expected_gradient_nt_per_100m_at_flight_height": cfg.anomaly.expected_gradient_nt_per_100m(0.5 * (extent.alt_min + extent.alt_max) - fl.terrain_alt_m),
            "expected_rms_nt_at_flight_height": cfg.anomaly.expected_rms_nt(0.5 * (extent.alt_min + extent.alt_max) - fl.terrain_alt_m),
            "true_anomaly_stats_nt": stats(col_of("true_anomaly")),
        },
        "diurnal": { "config": &cfg.diurnal, "true_diurnal_stats_nt": stats(col_of("true_diurnal")) },
        "aircraft": {
            "config": ac,
            "at_scalar_sensor": sensor_json(&at_s),
            "at_fluxgate": sensor_json(&at_f),
            "eddy_time_constants_s": ac.eddy.iter().map(|l| l.tau_s).collect::<Vec<_>>(),
            "true_interf_stats_nt": stats(col_of(&name_of("true_interf"))),
            "true_interf_eddy_stats_nt": stats(col_of("true_interf_eddy")),
            "true_interf_current_stats_nt": stats(col_of(&name_of("true_interf_current"))),
            "interference_magnitude_at_fluxgate_stats_nt": stats(&interf_at_flux),
        },
        "sensors": {
            "scalar": { "config": &cfg.scalar, "noise_rms_nt": white_rms(cfg.scalar.noise_density_nt_per_rthz, rate) },
            "fluxgate": {
                "config": &cfg.fluxgate,
                "matrix": m3(&cfg.fluxgate.matrix()),
                "noise_rms_nt": white_rms(cfg.fluxgate.noise_density_nt_per_rthz, rate),
            },
            "nav": &cfg.nav,
            "base_station": &cfg.base_station,
        },
        "kinematics": &cfg.kinematics,
        "turbulence": &cfg.turbulence,
        "columns": columns.iter().map(|c| json!({ "name": c.name, "unit": c.unit, "description": c.description })).collect::<Vec<_>>(),
    });
    // Extra sensors (only when configured, so that the default file is
    // unchanged).
    let mut truth = truth;
    if !cfg.extra_scalars.is_empty() {
        truth["sensors"]["extra_scalars"] = cfg
            .extra_scalars
            .iter()
            .zip(&xs_total)
            .enumerate()
            .map(|(i, (s, (at, _, current)))| {
                json!({
                    "column": name_of(&format!("mag_{}", i + 2)),
                    "position_m": s.position_m,
                    "config": s,
                    "noise_rms_nt": white_rms(s.noise_density_nt_per_rthz, rate),
                    "interference": sensor_json(at),
                    "true_interf_stats_nt": stats(col_of(&format!("true_interf_{}", i + 2))),
                    "true_interf_current_stats_nt": stats(current),
                })
            })
            .collect();
    }
    if !cfg.extra_fluxgates.is_empty() {
        truth["sensors"]["extra_fluxgates"] = cfg
            .extra_fluxgates
            .iter()
            .zip(&xf_total)
            .zip(&xf_b)
            .enumerate()
            .map(|(j, ((f, (at, tot, _)), ext))| {
                let mag: Vec<f64> = tot.iter().zip(ext).map(|(t, b)| (t - b).norm()).collect();
                json!({
                    "columns": format!("flux_{}_x/y/z", extra_fluxgate_letter(j)),
                    "position_m": f.position_m,
                    "config": f,
                    "matrix": m3(&f.matrix()),
                    "noise_rms_nt": white_rms(f.noise_density_nt_per_rthz, rate),
                    "interference": sensor_json(at),
                    "interference_magnitude_stats_nt": stats(&mag),
                })
            })
            .collect();
    }
    if sgl {
        truth["installation"] = json!("sgl");
    }
    let truth_json = serde_json::to_string_pretty(&truth).map_err(|e| SimError::Serialize {
        what: "truth metadata",
        reason: e.to_string(),
    })?;
    Ok(Simulation {
        kind,
        seed,
        columns,
        scenario_toml: cfg.to_toml(kind)?,
        truth_json,
    })
}
