//! End-to-end tests of the `em` scenario through detection, pilot
//! correction and positioning.

use super::*;
use crate::detection::{DetectorConfig, FieldChain, FieldEpoch, SyncDetector, major_axis};
use crate::positioning::{
    Hemisphere, PolishOptions, angle_between, closed_form, polish, rotation_angle_between,
};
use aeromag_core::field::dipole::dipole_matrix;
use nalgebra::{Matrix3, Vector3};

fn chain(sc: &EmScenario, use_pilot: bool) -> FieldChain {
    let c = &sc.config;
    let plan = DetectorConfig::three_frequency_plan(
        c.sample_rate_hz,
        16_000,
        c.frequencies_hz,
        c.pilot_offset_hz,
    );
    let det = SyncDetector::new(plan).unwrap();
    FieldChain::new(
        det,
        &sc.chi,
        c.coil_gain_v_per_t_s,
        &c.pilot_field_t,
        use_pilot,
    )
    .unwrap()
}

fn run(config: EmSimConfig, use_pilot: bool) -> (EmScenario, Vec<FieldEpoch>) {
    let sc = EmScenario::new(config).unwrap();
    let rec = synthesize(&sc).unwrap();
    let ep = chain(&sc, use_pilot)
        .process(&rec.samples, rec.header.start_index)
        .unwrap();
    (sc, ep)
}

/// Relative error of the detected complex field against the truth `R Ω M'`.
fn field_error(sc: &EmScenario, e: &FieldEpoch) -> f64 {
    let p = sc.pose_at(e.time_s);
    let rom = (p.rotation * dipole_matrix(&p.position_m))
        .map(|v| crate::detection::Complex64::new(v, 0.0))
        * sc.effective_moments();
    let mut num = 0.0;
    let mut den = 0.0;
    for i in 0..3 {
        for c in 0..3 {
            num += (e.h[i][c] - rom[(c, i)]).norm_sqr();
            den += rom[(c, i)].norm_sqr();
        }
    }
    (num / den).sqrt()
}

#[test]
fn raw_format_round_trip_and_determinism() {
    let cfg = EmSimConfig {
        duration_s: 0.2,
        ..EmSimConfig::default()
    };
    let sc = EmScenario::new(cfg).unwrap();
    let a = synthesize(&sc).unwrap();
    let b = synthesize(&sc).unwrap();
    assert_eq!(
        a.samples, b.samples,
        "seeded synthesis must be bit-identical"
    );
    let mut bytes = Vec::new();
    write_raw(&mut bytes, &a.header, &a.samples).unwrap();
    assert_eq!(
        bytes.len(),
        12 + serde_json::to_vec(&a.header).unwrap().len() + a.samples.len() * 4
    );
    let (h, s) = read_raw(&bytes).unwrap();
    // serde_json's default float parsing may differ in the last ulp of the
    // drawn matrices; the configuration (short decimals) is exact and
    // regenerates the scenario bit for bit.
    assert_eq!(
        (h.frames, h.channels, h.start_index),
        (a.header.frames, 3, 0)
    );
    assert_eq!(h.scenario.config, a.header.scenario.config);
    assert_eq!(
        EmScenario::new(h.scenario.config.clone()).unwrap(),
        a.header.scenario
    );
    assert_eq!(s, a.samples);
    assert!(read_raw(&bytes[..bytes.len() - 1]).is_err());
    assert!(read_raw(b"NOTRAW00\0\0\0\0").is_err());
    assert!(write_raw(Vec::new(), &a.header, &a.samples[1..]).is_err());
    assert!(
        EmScenario::new(EmSimConfig {
            frequencies_hz: [1025.0, 2075.0, 60_000.0],
            ..EmSimConfig::default()
        })
        .is_err()
    );
}

#[test]
fn pilot_correction_removes_the_gain_drift() {
    // 1.25 h into the flight the gains have drifted by several per cent.
    let noisy = EmSimConfig {
        start_time_s: 4500.0,
        ..EmSimConfig::default()
    };
    // Noise-free and static bird: isolates the pilot correction itself.
    let quiet = EmSimConfig {
        coil_noise_v: 0.0,
        power_line_v: 0.0,
        sferic_rate_hz: 0.0,
        swing_amplitude_m: 0.0,
        attitude_amplitude_deg: 0.0,
        rotation_rate_deg_s: 0.0,
        range_period_s: 1e12,
        ..noisy.clone()
    };
    let max_err = |cfg: &EmSimConfig, pilot: bool| {
        let (sc, ep) = run(cfg.clone(), pilot);
        assert_eq!(ep.len(), 16);
        ep.iter().map(|e| field_error(&sc, e)).fold(0.0, f64::max)
    };
    let (quiet_w, quiet_o) = (max_err(&quiet, true), max_err(&quiet, false));
    let (noisy_w, noisy_o) = (max_err(&noisy, true), max_err(&noisy, false));
    eprintln!("max field error, noise-free: with pilot {quiet_w:.2e}, without {quiet_o:.2e}");
    eprintln!("max field error, with noise: with pilot {noisy_w:.2e}, without {noisy_o:.2e}");
    // What remains is f32 ADC rounding: the pilot removes the drift entirely.
    assert!(quiet_w < 2e-6, "{quiet_w}");
    assert!(quiet_o > 1e-2, "{quiet_o}");
    // A moving bird with coil noise, 400 Hz and sferics: the error stays at
    // the level of the noise and of the motion within a 0.16 s block.
    assert!(noisy_w < 1e-3, "{noisy_w}");
}

#[test]
fn end_to_end_positioning_without_transmitter_distortion() {
    let cfg = EmSimConfig {
        transmitter_distortion: 0.0,
        start_time_s: 200.0,
        ..EmSimConfig::default()
    };
    let (sc, ep) = run(cfg, true);
    let m = sc.config.moments_am2;
    let mut worst = [0.0f64; 4];
    let mut hemi = Hemisphere::new(Vector3::new(-1.0, 0.0, 1.0));
    for e in &ep {
        let mut h = Matrix3::zeros();
        let mut ratio = 0.0f64;
        for i in 0..3 {
            let el = major_axis(&e.h[i]);
            h.set_column(i, &el.major);
            ratio = ratio.max(el.ratio);
        }
        let cf = closed_form(&h, &m, &mut hemi).unwrap();
        let p = polish(&h, &m, &cf.pose, &PolishOptions::default())
            .unwrap()
            .pose;
        let t = sc.pose_at(e.time_s);
        worst[0] = worst[0].max(((p.range_m() - t.range_m()) / t.range_m()).abs());
        worst[1] = worst[1].max(angle_between(&p.position_m, &t.position_m).to_degrees());
        worst[2] = worst[2].max(rotation_angle_between(&p.rotation, &t.rotation).to_degrees());
        worst[3] = worst[3].max(ratio);
    }
    eprintln!(
        "worst over {} epochs: range {:.2e} (rel), direction {:.4}°, attitude {:.4}°, polarisation ratio {:.2e}",
        ep.len(),
        worst[0],
        worst[1],
        worst[2],
        worst[3]
    );
    assert!(
        worst[0] < 1e-3 && worst[1] < 0.1 && worst[2] < 0.1,
        "{worst:?}"
    );
    assert!(worst[3] < 1e-3, "{worst:?}");
}

/// One 16 000-sample block at each flight time of `times_s`.
fn epochs_at(
    base: &EmSimConfig,
    times_s: &[f64],
    use_pilot: bool,
) -> (EmScenario, Vec<FieldEpoch>) {
    let mut out = Vec::with_capacity(times_s.len());
    let mut scenario = None;
    for &t in times_s {
        let cfg = EmSimConfig {
            start_time_s: t,
            duration_s: 0.16,
            ..base.clone()
        };
        let (sc, ep) = run(cfg, use_pilot);
        out.extend(ep);
        scenario = Some(sc);
    }
    (scenario.expect("at least one time"), out)
}

fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

#[test]
fn three_stage_calibration_over_a_five_hour_flight() {
    use crate::calibration::{
        Calibration, PolarisationCalibration, fit_attitude_correction, fit_transmitter_geometry,
        uncalibrated,
    };
    let base = EmSimConfig::default();
    let flight = 5.0 * 3600.0;
    let cal_times: Vec<f64> = (0..120)
        .map(|k| flight * (k as f64 + 0.37) / 120.0)
        .collect();
    let eval_times: Vec<f64> = (0..40).map(|k| flight * (k as f64 + 0.81) / 40.0).collect();
    let (sc, cal_ep) = epochs_at(&base, &cal_times, true);
    let m = sc.config.moments_am2;
    let data: Vec<[[crate::detection::Complex64; 3]; 3]> = cal_ep.iter().map(|e| e.h).collect();

    // Stage 1 (no external information).
    let pol = PolarisationCalibration::fit(&data).unwrap();
    // Stage 2 (known positions of 40 epochs).
    let fields: Vec<Matrix3<f64>> = data[..40].iter().map(|e| pol.apply(e).0).collect();
    let pos: Vec<Vector3<f64>> = cal_ep[..40]
        .iter()
        .map(|e| sc.pose_at(e.time_s).position_m)
        .collect();
    let s = fit_transmitter_geometry(&fields, &pos, &m).unwrap();
    // Stage 3 (one known attitude).
    let mut cal = Calibration {
        polarisation: pol,
        transmitter_s: s,
        attitude_q: Matrix3::identity(),
    };
    let mut hemi = Hemisphere::new(Vector3::new(-1.0, 0.0, 1.0));
    let l0 = cal.locate(&data[0], &m, &mut hemi).unwrap();
    cal.attitude_q = fit_attitude_correction(
        &[sc.pose_at(cal_ep[0].time_s).rotation],
        &[l0.pose.rotation],
    )
    .unwrap();

    // Evaluation on other epochs, with and without pilot correction.
    let (_, with) = epochs_at(&base, &eval_times, true);
    let (_, without) = epochs_at(&base, &eval_times, false);
    let mut ratio_before = Vec::new();
    let mut ratio_after = Vec::new();
    let mut ratio_no_pilot = Vec::new();
    let mut err = [Vec::new(), Vec::new(), Vec::new()];
    for (e, e_np) in with.iter().zip(&without) {
        ratio_before.extend(uncalibrated(&e.h, &pol.phase_rad).1);
        let mut hemi = Hemisphere::new(Vector3::new(-1.0, 0.0, 1.0));
        let l = cal.locate(&e.h, &m, &mut hemi).unwrap();
        ratio_after.extend(l.polarisation_ratio);
        ratio_no_pilot.extend(pol.apply(&e_np.h).1);
        let t = sc.pose_at(e.time_s);
        err[0].push((l.pose.range_m() - t.range_m()) / t.range_m());
        err[1].push(angle_between(&l.pose.position_m, &t.position_m).to_degrees());
        err[2].push(rotation_angle_between(&l.pose.rotation, &t.rotation).to_degrees());
    }
    let (rb, ra, rn) = (rms(&ratio_before), rms(&ratio_after), rms(&ratio_no_pilot));
    let e = err.map(|v| rms(&v));
    eprintln!(
        "polarisation ratio RMS: before {rb:.3e}, after {ra:.3e} ({:.0}×), after without pilot {rn:.3e}",
        rb / ra
    );
    eprintln!(
        "RMS errors over 5 h: range {:.3e} (rel), direction {:.4}°, attitude {:.4}°",
        e[0], e[1], e[2]
    );
    // Stable over the flight: the last hour is no worse than the first.
    let n = ratio_after.len();
    let (first, last) = (rms(&ratio_after[..n / 5]), rms(&ratio_after[n - n / 5..]));
    eprintln!("after-calibration ratio RMS first hour {first:.3e}, last hour {last:.3e}");
    assert!(rb / ra >= 100.0, "reduction {}", rb / ra);
    assert!(rn > 10.0 * ra, "without pilot {rn} vs {ra}");
    assert!(last < 3.0 * first && first < 3.0 * last);
    assert!(e[0] <= 1e-3 && e[1] <= 0.1 && e[2] <= 0.1, "{e:?}");
}
