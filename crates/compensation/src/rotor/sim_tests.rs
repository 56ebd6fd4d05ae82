//! The rotor model and the baselines on the `helicopter` scenario of
//! `aeromag-sim` (spec `helicopter.md` part A, "What to show").
//!
//! The comparison itself (metrics, methods) is [`super::study::evaluate`];
//! edges of 3 s (300 samples) are excluded.

use aeromag_sim::{ScenarioKind, Simulation, simulate};
use nalgebra::Vector3;

use super::*;
use crate::rotor::study::{StudyInput, evaluate, scenario_geometry, std_mid};

struct Case {
    sim: Simulation,
    fs: f64,
    geom: RotorGeometry,
    b: Vec<Vector3<f64>>,
    edge: usize,
}

fn case(seed: u64, cfg: Option<&str>) -> Case {
    let sim = simulate(ScenarioKind::Helicopter, cfg, Some(seed)).unwrap();
    let c = |n: &str| sim.column(n).unwrap().to_vec();
    let (x, y, z) = (c("flux_x"), c("flux_y"), c("flux_z"));
    let b = (0..x.len())
        .map(|k| Vector3::new(x[k], y[k], z[k]))
        .collect();
    let geom = scenario_geometry();
    Case {
        sim,
        fs: 100.0,
        geom,
        b,
        edge: 300,
    }
}

fn diff(a: &[f64], b: &[f64]) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| x - y).collect()
}

#[test]
fn model_beats_the_filters() {
    let cs = case(11, None);
    let col = |n: &str| cs.sim.column(n).unwrap();
    let st = evaluate(
        &cs.geom,
        &StudyInput {
            mag_nt: col("mag"),
            b_body_nt: &cs.b,
            rotor_phase_deg: col("rotor_phase"),
            true_rotor_nt: col("true_rotor"),
            true_anomaly_nt: col("true_anomaly"),
            fs_hz: cs.fs,
            edge: cs.edge,
            tail: None,
        },
    )
    .unwrap();
    let r_rms = st.rotor_rms_nt;
    // The estimated coning against the true one.
    let true_cone: Vec<f64> = col("true_coning").iter().map(|d| d.to_radians()).collect();
    eprintln!(
        "coning: true variation {:.4} deg RMS, estimation error {:.4} deg RMS",
        std_mid(&true_cone, cs.edge).to_degrees(),
        std_mid(&diff(&st.coning_rad, &true_cone), cs.edge).to_degrees()
    );
    eprintln!(
        "rotor interference RMS {r_rms:.3} nT, anomaly RMS {:.3} nT",
        st.anomaly_rms_nt
    );
    for m in &st.methods {
        eprintln!(
            "{:44} residual {:.4} nT ({:.2} %), removes anomaly {:.2} %, 0.5 s bumps {:.2} %, 0.1 s bumps {:.2} %",
            m.name,
            m.residual_nt,
            100.0 * m.residual_nt / r_rms,
            100.0 * m.removed_anomaly,
            100.0 * m.removed_bumps_05,
            100.0 * m.removed_bumps_01
        );
    }
    let (model_res, best_filter) = (st.residual_model_nt, st.residual_best_filter_nt);
    assert_eq!(st.methods.iter().filter(|m| m.is_filter).count(), 4);
    assert!(
        model_res <= 0.10 * r_rms,
        "model leaves {model_res} of {r_rms}"
    );
    assert!(
        best_filter >= 3.0 * model_res,
        "best filter {best_filter} vs model {model_res}"
    );
    let m = &st.methods[1];
    assert!(
        m.removed_anomaly <= 0.05 && m.removed_bumps_05 <= 0.05 && m.removed_bumps_01 <= 0.05,
        "model removes {m:?} of the signal"
    );
}

#[test]
fn works_without_a_phase_channel() {
    let cs = case(
        12,
        Some(
            "[rotor]\nphase_channel = false\n[pattern]\nlegs = [{ heading_deg = 30.0, manoeuvres = [\"roll\", \"pitch\", \"yaw\"] }, { heading_deg = 120.0, manoeuvres = [\"roll\", \"pitch\", \"yaw\"] }, { heading_deg = 210.0, manoeuvres = [\"roll\", \"pitch\", \"yaw\"] }, { heading_deg = 300.0, manoeuvres = [\"roll\", \"pitch\", \"yaw\"] }]\n",
        ),
    );
    assert!(cs.sim.column("rotor_phase").is_none());
    let (fs, edge) = (cs.fs, cs.edge);
    let mag = cs.sim.column("mag").unwrap();
    let rot = cs.sim.column("true_rotor").unwrap();
    let truth = cs.sim.column("true_rotor_phase").unwrap();
    let est = estimate_phase(mag, fs, 4, 4.5, 5.2).unwrap();
    // true mean frequency over the same central 80 % of the record
    let (a, b) = (mag.len() / 10, mag.len() - 1 - mag.len() / 10);
    let true_mean = (truth[b] - truth[a]) / 360.0 * fs / (b - a) as f64;
    assert!(
        (est.rotor_hz - true_mean).abs() < 1e-4,
        "{} vs {true_mean}",
        est.rotor_hz
    );
    let omega = rotor_speed(&est.phase_rad, fs, 1.0).unwrap();
    let nominal = [crate::rotor::study::nominal_angles()];
    let input = RotorInput {
        b_body_nt: &cs.b,
        phase_rad: &est.phase_rad,
        omega_rad_s: &omega,
        angles: &nominal,
    };
    let opts = RotorFitOptions::default();
    let c = refine_phase_offset(&cs.geom, BladeTerms::Full, &input, mag, fs, &opts).unwrap();
    let phase: Vec<f64> = est.phase_rad.iter().map(|p| p + c).collect();
    // The refined phase equals the true one modulo 2π/N (blade labels).
    let q = std::f64::consts::TAU / 4.0;
    let errs: Vec<f64> = (edge..mag.len() - edge)
        .map(|k| {
            let d = (phase[k] - truth[k].to_radians()).rem_euclid(q);
            d.min(q - d)
        })
        .collect();
    let max_err = errs.iter().copied().fold(0.0, f64::max);
    let input = RotorInput {
        phase_rad: &phase,
        ..input
    };
    let so = SlowAngleOptions {
        estimate_phase: true,
        estimate_tilt: false,
        iterations: 6,
        window_s: 2.0,
        joint: true,
    };
    let slow = fit_slow_angles(&cs.geom, BladeTerms::Full, &input, mag, fs, &opts, &so).unwrap();
    let inp_s = RotorInput {
        angles: &slow.angles,
        phase_rad: &slow.phase_rad,
        ..input
    };
    let errs: Vec<f64> = (edge..mag.len() - edge)
        .map(|k| {
            let d = (slow.phase_rad[k] - truth[k].to_radians()).rem_euclid(q);
            d.min(q - d)
        })
        .collect();
    let max_err_refined = errs.iter().copied().fold(0.0, f64::max);
    let pred = slow.fit.predict(&cs.geom, &inp_s).unwrap();
    let res = std_mid(&diff(rot, &pred), edge);
    let r_rms = std_mid(rot, edge);
    eprintln!(
        "no phase channel: f_r {:.4} Hz (true mean {true_mean:.4}), phase error ≤ {:.3} deg tracked, ≤ {:.3} deg refined, residual {res:.4} of {r_rms:.3} nT ({:.2} %)",
        est.rotor_hz,
        max_err.to_degrees(),
        max_err_refined.to_degrees(),
        100.0 * res / r_rms
    );
    assert!(max_err_refined < max_err);
    assert!(res <= 0.10 * r_rms);
}

/// A model fitted on one flight (phase channel) applied to another flight
/// whose phase is estimated from its scalar data: parameters fixed, phase
/// aligned over a revolution, slowly varying angles and phase tracked.
#[test]
fn a_fitted_model_applies_to_another_flight() {
    let a = case(11, None);
    let b = case(12, None);
    let (fs, edge) = (a.fs, a.edge);
    let nominal = [crate::rotor::study::nominal_angles()];
    let opts = RotorFitOptions::default();
    let pa = unwrap_deg(a.sim.column("rotor_phase").unwrap());
    let wa = rotor_speed(&pa, fs, 1.0).unwrap();
    let ia = RotorInput {
        b_body_nt: &a.b,
        phase_rad: &pa,
        omega_rad_s: &wa,
        angles: &nominal,
    };
    let mag_a = a.sim.column("mag").unwrap();
    let so = SlowAngleOptions::default();
    let model = fit_slow_angles(&a.geom, BladeTerms::Full, &ia, mag_a, fs, &opts, &so)
        .unwrap()
        .fit;
    let mag_b = b.sim.column("mag").unwrap();
    let est = estimate_phase(mag_b, fs, 4, 4.5, 5.2).unwrap();
    let wb = rotor_speed(&est.phase_rad, fs, 1.0).unwrap();
    let ib = RotorInput {
        b_body_nt: &b.b,
        phase_rad: &est.phase_rad,
        omega_rad_s: &wb,
        angles: &nominal,
    };
    let c = align_phase_offset(&b.geom, &model, &ib, mag_b, fs, &opts).unwrap();
    let phase: Vec<f64> = est.phase_rad.iter().map(|p| p + c).collect();
    let ib = RotorInput {
        phase_rad: &phase,
        ..ib
    };
    let track = SlowAngleOptions {
        estimate_phase: true,
        iterations: 6,
        ..so
    };
    let t = track_slow_angles(&b.geom, &model, &ib, mag_b, fs, &opts, &track).unwrap();
    assert_eq!(t.fit.params, model.params);
    let inp = RotorInput {
        angles: &t.angles,
        phase_rad: &t.phase_rad,
        ..ib
    };
    let pred = model.predict(&b.geom, &inp).unwrap();
    let rot = b.sim.column("true_rotor").unwrap();
    let share = std_mid(&diff(rot, &pred), edge) / std_mid(rot, edge);
    eprintln!(
        "model of flight 11 on flight 12, phase from the data: {:.2} %",
        100.0 * share
    );
    assert!(share <= 0.10, "{share}");
}
