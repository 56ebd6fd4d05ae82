//! The rotor model and the baselines on the `helicopter` scenario of
//! `aeromag-sim` (spec `helicopter.md` part A, "What to show").
//!
//! Metrics (all RMS about the mean, nT, samples within 3 s of the ends
//! excluded):
//! * residual rotor interference: `true_rotor − prediction` for the model
//!   (fitted to the full scalar record: fuselage, anomaly, noise included);
//!   for the linear baselines the part of `true_rotor` they let through;
//! * signal removed: the part of an anomaly signal each method takes away,
//!   by linearity (the method applied to the signal alone with the same
//!   phase, field and angles), relative to the signal's RMS. Two signals:
//!   the scenario's `true_anomaly` (150 m above ground, smooth) and a train
//!   of Gaussian bumps of 0.5 s standard width (a shallow source passed at
//!   40 m/s), which is what low-pass filters hurt.

use aeromag_sim::{ScenarioKind, Simulation, simulate};
use nalgebra::Vector3;

use super::*;
use crate::rotor::lowpass::lowpass;
use crate::rotor::notch::{NotchOptions, notch_harmonics};
use crate::rotor::synchronous::synchronous_template;

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
    let geom = RotorGeometry {
        hub_m: [0.0, 0.0, -2.6],
        sensor_m: [5.0, 0.0, 0.6],
        root_m: 0.8,
        tip_m: 7.5,
        blades: 4,
    };
    Case {
        sim,
        fs: 100.0,
        geom,
        b,
        edge: 300,
    }
}

fn std_mid(x: &[f64], edge: usize) -> f64 {
    let s = &x[edge..x.len() - edge];
    let m = s.iter().sum::<f64>() / s.len() as f64;
    (s.iter().map(|v| (v - m).powi(2)).sum::<f64>() / s.len() as f64).sqrt()
}

fn diff(a: &[f64], b: &[f64]) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| x - y).collect()
}

fn bumps(n: usize, fs: f64, sigma_s: f64) -> Vec<f64> {
    (0..n)
        .map(|k| {
            let t = k as f64 / fs;
            (0..(n as f64 / fs / 25.0) as usize)
                .map(|i| {
                    let t0 = 12.5 + 25.0 * i as f64;
                    let amp = if i % 2 == 0 { 5.0 } else { -3.0 };
                    amp * (-(t - t0).powi(2) / (2.0 * sigma_s * sigma_s)).exp()
                })
                .sum()
        })
        .collect()
}

#[test]
fn model_beats_the_filters() {
    let cs = case(11, None);
    let (fs, edge) = (cs.fs, cs.edge);
    let col = |n: &str| cs.sim.column(n).unwrap().to_vec();
    let mag = col("mag");
    let rot = col("true_rotor");
    let anom = col("true_anomaly");
    let bump = bumps(mag.len(), fs, 0.5);
    let sharp = bumps(mag.len(), fs, 0.1);
    let phase = unwrap_deg(&col("rotor_phase"));
    let omega = rotor_speed(&phase, fs, 1.0).unwrap();
    let f_r = omega.iter().sum::<f64>() / omega.len() as f64 / std::f64::consts::TAU;
    let nominal = [FlapAngles {
        coning_rad: 4f64.to_radians(),
        tilt_lon_rad: (-1.5f64).to_radians(),
        tilt_lat_rad: 0.0,
    }];
    let input = RotorInput {
        b_body_nt: &cs.b,
        phase_rad: &phase,
        omega_rad_s: &omega,
        angles: &nominal,
    };
    let opts = RotorFitOptions::default();
    let r_rms = std_mid(&rot, edge);

    let mut report = Vec::new();
    // Models.
    for terms in [BladeTerms::Simplified, BladeTerms::Full] {
        let f = fit(&cs.geom, terms, &input, &mag, fs, &opts).unwrap();
        let p = f.predict(&cs.geom, &input).unwrap();
        report.push((
            format!("model {terms:?}"),
            std_mid(&diff(&rot, &p), edge),
            f64::NAN,
            f64::NAN,
            f64::NAN,
        ));
    }
    let slow = fit_slow_angles(
        &cs.geom,
        BladeTerms::Full,
        &input,
        &mag,
        fs,
        &opts,
        &SlowAngleOptions::default(),
    )
    .unwrap();
    let inp_s = RotorInput {
        angles: &slow.angles,
        ..input
    };
    let cols = regressors(&cs.geom, BladeTerms::Full, &inp_s).unwrap();
    let pred = slow.fit.predict_columns(&cols).unwrap();
    let model_res = std_mid(&diff(&rot, &pred), edge);
    // The estimated coning follows the true one.
    let true_cone: Vec<f64> = col("true_coning").iter().map(|d| d.to_radians()).collect();
    let est_cone: Vec<f64> = slow.angles.iter().map(|a| a.coning_rad).collect();
    let cone_err = std_mid(&diff(&est_cone, &true_cone), edge);
    let cone_var = std_mid(&true_cone, edge);
    eprintln!(
        "coning: true variation {:.4} deg RMS, estimation error {:.4} deg RMS",
        cone_var.to_degrees(),
        cone_err.to_degrees()
    );
    let removed = |sig: &[f64]| {
        let f = linear::fit_columns(&cols, BladeTerms::Full, sig, fs, &opts).unwrap();
        std_mid(&f.predict_columns(&cols).unwrap(), edge) / std_mid(sig, edge)
    };
    let (m_a, m_b, m_c) = (removed(&anom), removed(&bump), removed(&sharp));
    report.push(("model Full + slow cone".into(), model_res, m_a, m_b, m_c));
    // Baselines.
    let lin = |name: String, f: &dyn Fn(&[f64]) -> Vec<f64>| {
        let res = std_mid(&f(&rot), edge);
        let ra = std_mid(&diff(&anom, &f(&anom)), edge) / std_mid(&anom, edge);
        let rb = std_mid(&diff(&bump, &f(&bump)), edge) / std_mid(&bump, edge);
        let rc = std_mid(&diff(&sharp, &f(&sharp)), edge) / std_mid(&sharp, edge);
        (name, res, ra, rb, rc)
    };
    let bp = 4.0 * f_r;
    report.push(lin(
        format!("low-pass {:.1} Hz (0.8 f_bp)", 0.8 * bp),
        &|x| lowpass(x, fs, 0.8 * bp, 6).unwrap(),
    ));
    report.push(lin(
        format!("low-pass {:.1} Hz (0.8 f_r)", 0.8 * f_r),
        &|x| lowpass(x, fs, 0.8 * f_r, 6).unwrap(),
    ));
    report.push(lin("notches 1..16 f_r".into(), &|x| {
        notch_harmonics(x, fs, f_r, &NotchOptions::default()).unwrap()
    }));
    report.push(lin("synchronous avg 10 s".into(), &|x| {
        diff(
            x,
            &synchronous_template(x, &phase, fs, 64, 10.0, 2.0).unwrap(),
        )
    }));
    eprintln!(
        "rotor interference RMS {r_rms:.3} nT, anomaly RMS {:.3} nT",
        std_mid(&anom, edge)
    );
    for (name, res, a, b, c) in &report {
        eprintln!(
            "{name:32} residual {res:.4} nT ({:.2} %), removes anomaly {:.2} %, 0.5 s bumps {:.2} %, 0.1 s bumps {:.2} %",
            100.0 * res / r_rms,
            100.0 * a,
            100.0 * b,
            100.0 * c
        );
    }
    let best_filter = report[3..]
        .iter()
        .map(|r| r.1)
        .fold(f64::INFINITY, f64::min);
    assert!(
        model_res <= 0.10 * r_rms,
        "model leaves {model_res} of {r_rms}"
    );
    assert!(
        best_filter >= 3.0 * model_res,
        "best filter {best_filter} vs model {model_res}"
    );
    assert!(
        m_a <= 0.05 && m_b <= 0.05 && m_c <= 0.05,
        "model removes {m_a} / {m_b} / {m_c} of the signal"
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
    let nominal = [FlapAngles {
        coning_rad: 4f64.to_radians(),
        tilt_lon_rad: (-1.5f64).to_radians(),
        tilt_lat_rad: 0.0,
    }];
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
