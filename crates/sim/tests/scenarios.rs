//! Whole-scenario tests: physics that could fail, identities between the
//! columns, determinism, configuration errors and output files.

use std::collections::BTreeMap;

use aeromag_sim::{ScenarioKind, SimError, Simulation, default_config_toml, simulate};

fn col<'a>(s: &'a Simulation, name: &str) -> &'a [f64] {
    s.column(name).unwrap_or_else(|| panic!("no column {name}"))
}

/// Peak-to-peak of `v` after removing its least-squares linear trend.
fn detrended_p2p(v: &[f64]) -> f64 {
    let n = v.len() as f64;
    let xm = (n - 1.0) / 2.0;
    let ym = v.iter().sum::<f64>() / n;
    let sxy: f64 = v
        .iter()
        .enumerate()
        .map(|(i, y)| (i as f64 - xm) * (y - ym))
        .sum();
    let sxx: f64 = (0..v.len()).map(|i| (i as f64 - xm).powi(2)).sum();
    let b = sxy / sxx;
    let r: Vec<f64> = v
        .iter()
        .enumerate()
        .map(|(i, y)| y - ym - b * (i as f64 - xm))
        .collect();
    r.iter().copied().fold(f64::NEG_INFINITY, f64::max)
        - r.iter().copied().fold(f64::INFINITY, f64::min)
}

fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

/// Values of `name` where `line == leg` and `manoeuvre == code`.
fn window(s: &Simulation, name: &str, leg: f64, code: f64) -> Vec<f64> {
    let (l, m, v) = (col(s, "line"), col(s, "manoeuvre"), col(s, name));
    (0..v.len())
        .filter(|&k| l[k] == leg && m[k] == code)
        .map(|k| v[k])
        .collect()
}

#[test]
fn calibration_interference_changes_with_heading_and_manoeuvres() {
    let s = simulate(ScenarioKind::Calibration, None, Some(3)).unwrap();
    let noise = rms(col(&s, "true_mag_noise"));
    assert!((0.009..0.013).contains(&noise), "scalar noise {noise}");
    let mut steady_means = Vec::new();
    let mut fom = 0.0;
    for leg in 1..=4 {
        let leg = leg as f64;
        for code in [1.0, 2.0, 3.0] {
            let w = window(&s, "true_interf", leg, code);
            assert!(
                w.len() > 100,
                "leg {leg} manoeuvre {code}: {} samples",
                w.len()
            );
            let p2p = detrended_p2p(&w);
            let eddy = detrended_p2p(&window(&s, "true_interf_eddy", leg, code));
            println!(
                "leg {leg} manoeuvre {code}: interference p-p {p2p:.2} nT, eddy p-p {eddy:.3} nT"
            );
            // A manoeuvre moves the interference far above the sensor noise
            // (yaw least: at 72° inclination a ±5° flat yaw tilts the field
            // in body axes by only ±1.5°).
            assert!(
                p2p > 20.0 * noise,
                "leg {leg} manoeuvre {code}: p-p {p2p} nT"
            );
            fom += p2p;
        }
        let st = window(&s, "true_interf", leg, 0.0);
        steady_means.push(st.iter().sum::<f64>() / st.len() as f64);
    }
    println!(
        "steady-flight interference by heading: {steady_means:?}; uncompensated FOM {fom:.1} nT"
    );
    // The figure of merit of the uncompensated aircraft (sum of the 12
    // peak-to-peaks) is that of a real installation: tens of nT.
    assert!((10.0..100.0).contains(&fom), "FOM {fom}");
    let spread = steady_means
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max)
        - steady_means.iter().copied().fold(f64::INFINITY, f64::min);
    assert!(
        spread > 1.0,
        "the interference should depend on heading: {steady_means:?}"
    );
    // Tens of nT in total at the stinger, several hundred at the fluxgate.
    let vec_mag = (0..s.n_rows())
        .map(|k| {
            ["x", "y", "z"]
                .iter()
                .map(|a| col(&s, &format!("true_interf_{a}"))[k].powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .sum::<f64>()
        / s.n_rows() as f64;
    let ti = col(&s, "true_interf");
    let range = ti.iter().copied().fold(f64::NEG_INFINITY, f64::max)
        - ti.iter().copied().fold(f64::INFINITY, f64::min);
    println!("|ΔB| at the stinger {vec_mag:.1} nT, scalar interference range {range:.1} nT");
    assert!(
        (15.0..60.0).contains(&vec_mag),
        "interference vector {vec_mag} nT"
    );
    assert!(range > 10.0, "scalar interference range {range} nT");
    let flux_interf = (0..s.n_rows())
        .map(|k| {
            let d = |a: &str| {
                col(&s, &format!("true_flux_{a}"))[k] - col(&s, &format!("true_ext_{a}"))[k]
            };
            (d("x").powi(2) + d("y").powi(2) + d("z").powi(2)).sqrt()
        })
        .sum::<f64>()
        / s.n_rows() as f64;
    println!("|ΔB| at the fluxgate {flux_interf:.0} nT");
    assert!(
        flux_interf > 100.0,
        "interference at the fluxgate {flux_interf} nT"
    );
    // The eddy part is small and moves during manoeuvres, not in steady flight.
    let (l, m, e) = (
        col(&s, "line"),
        col(&s, "manoeuvre"),
        col(&s, "true_interf_eddy"),
    );
    let pick = |f: &dyn Fn(usize) -> bool| {
        (0..s.n_rows())
            .filter(|&k| f(k))
            .map(|k| e[k])
            .collect::<Vec<f64>>()
    };
    let eddy_man = rms(&pick(&|k| m[k] != 0.0));
    let eddy_steady = rms(&pick(&|k| l[k] != 0.0 && m[k] == 0.0));
    println!("eddy RMS: manoeuvres {eddy_man:.3} nT, steady flight {eddy_steady:.3} nT");
    assert!(
        eddy_man > 3.0 * eddy_steady && eddy_man < 1.0,
        "eddy rms: manoeuvres {eddy_man}, steady {eddy_steady}"
    );
}

#[test]
fn columns_add_up_exactly() {
    for kind in [ScenarioKind::Calibration, ScenarioKind::Survey] {
        let cfg = "[pattern]\nline_count = 3\nline_length_m = 3000.0\ntie_count = 1\n";
        let s = simulate(
            kind,
            if kind == ScenarioKind::Survey {
                Some(cfg)
            } else {
                None
            },
            Some(5),
        )
        .unwrap();
        let (mag, ext, int) = (
            col(&s, "mag"),
            col(&s, "true_external"),
            col(&s, "true_interf"),
        );
        let (he, lag, noise) = (
            col(&s, "true_heading_error"),
            col(&s, "true_lag"),
            col(&s, "true_mag_noise"),
        );
        let (ig, an, di) = (
            col(&s, "true_igrf"),
            col(&s, "true_anomaly"),
            col(&s, "true_diurnal"),
        );
        for k in 0..s.n_rows() {
            assert!(
                (mag[k] - (ext[k] + int[k] + he[k] + lag[k] + noise[k])).abs() < 1e-9,
                "{kind} row {k}"
            );
            assert!(
                (ext[k] - (ig[k] + an[k] + di[k])).abs() < 1e-9,
                "{kind} row {k}"
            );
            // exact modulus: |B_ext + ΔB| from the vector truth
            let v = |p: &str| {
                (0..3)
                    .map(|i| col(&s, &format!("{p}_{}", ["x", "y", "z"][i]))[k])
                    .collect::<Vec<f64>>()
            };
            let (e, d) = (v("true_ext"), v("true_interf"));
            let tot =
                ((e[0] + d[0]).powi(2) + (e[1] + d[1]).powi(2) + (e[2] + d[2]).powi(2)).sqrt();
            assert!((tot - (ext[k] + int[k])).abs() < 1e-8, "{kind} row {k}");
            let en = (e[0].powi(2) + e[1].powi(2) + e[2].powi(2)).sqrt();
            assert!((en - ext[k]).abs() < 1e-8);
        }
        // The first-order projections add up to the exact interference up to
        // the second-order term |ΔB_⊥|²/(2|B|) (< 0.05 nT here).
        let parts = [
            "true_interf_perm",
            "true_interf_induced",
            "true_interf_eddy",
            "true_interf_current",
        ];
        let worst = (0..s.n_rows())
            .map(|k| (int[k] - parts.iter().map(|p| col(&s, p)[k]).sum::<f64>()).abs())
            .fold(0.0, f64::max);
        assert!(
            worst < 0.05 && worst > 0.0,
            "{kind}: first-order vs exact {worst}"
        );
    }
}

#[test]
fn survey_lines_gradients_lag_and_altitude() {
    let s = simulate(ScenarioKind::Survey, None, Some(2)).unwrap();
    let line = col(&s, "line");
    let mut counts: BTreeMap<i64, usize> = BTreeMap::new();
    for &l in line {
        if l != 0.0 {
            *counts.entry(l as i64).or_default() += 1;
        }
    }
    let expect: Vec<i64> = (1001..=1020).chain(2001..=2005).collect();
    assert_eq!(counts.keys().copied().collect::<Vec<_>>(), expect);
    // Every survey line is covered over ≥ 97 % of its 10 km at 70 m/s, 10 Hz.
    for l in 1001..=1020 {
        let covered = counts[&l] as f64 * 7.0;
        assert!(
            covered > 9700.0 && covered < 10_100.0,
            "line {l} covers {covered} m"
        );
    }
    // Altitude wanders around 100 m above the 150 m terrain.
    let alt: Vec<f64> = (0..s.n_rows())
        .filter(|&k| line[k] != 0.0)
        .map(|k| col(&s, "true_alt")[k])
        .collect();
    let m = alt.iter().sum::<f64>() / alt.len() as f64;
    let sd = rms(&alt.iter().map(|a| a - m).collect::<Vec<_>>());
    assert!(
        (m - 250.0).abs() < 3.0 && (1.0..15.0).contains(&sd),
        "altitude {m} ± {sd}"
    );
    // Along-line gradient of the anomaly (total field, random grid + dipoles).
    let an = col(&s, "true_anomaly");
    let mut g2 = Vec::new();
    for k in 1..s.n_rows() {
        if line[k] != 0.0 && line[k] == line[k - 1] {
            g2.push(2.0 * ((an[k] - an[k - 1]) / 7.0).powi(2)); // 7 m per sample; |∇h|² ≈ 2 (d/ds)²
        }
    }
    let grad = 100.0 * (g2.iter().sum::<f64>() / g2.len() as f64).sqrt();
    println!("survey anomaly gradient {grad:.2} nT/100 m");
    assert!(
        (1.0..10.0).contains(&grad),
        "survey gradient {grad} nT/100 m"
    );
    // The lag term is −τ d|B|/dt to first order (τ = 0.1 s).
    let x: Vec<f64> = (0..s.n_rows())
        .map(|k| {
            col(&s, "true_external")[k]
                + col(&s, "true_interf")[k]
                + col(&s, "true_heading_error")[k]
        })
        .collect();
    let lag = col(&s, "true_lag");
    let (mut num, mut den) = (0.0, 0.0);
    let mut worst: f64 = 0.0;
    for k in 1..s.n_rows() - 1 {
        let rate = (x[k + 1] - x[k - 1]) / 0.2;
        num += lag[k] * rate;
        den += rate * rate;
        worst = worst.max((lag[k] + 0.1 * rate).abs());
    }
    let k_fit = num / den;
    println!(
        "lag: fitted k = {k_fit:.4} s (τ = 0.1 s), worst first-order residual {worst:.4} nT, rms lag {:.3} nT",
        rms(lag)
    );
    assert!((k_fit + 0.1).abs() < 0.005, "fitted k {k_fit}");
    assert!(
        rms(lag) > 0.05,
        "lag term should matter on a survey: {}",
        rms(lag)
    );
}

#[test]
fn calibration_anomaly_is_much_smoother_than_the_survey_anomaly() {
    let along_gradient = |s: &Simulation, step_m: f64| {
        let (l, an) = (col(s, "line"), col(s, "true_anomaly"));
        let v: Vec<f64> = (1..s.n_rows())
            .filter(|&k| l[k] != 0.0 && l[k] == l[k - 1])
            .map(|k| ((an[k] - an[k - 1]) / step_m).powi(2))
            .collect();
        100.0 * (2.0 * v.iter().sum::<f64>() / v.len() as f64).sqrt()
    };
    let quiet = simulate(ScenarioKind::Calibration, None, Some(4)).unwrap();
    let realistic = simulate(
        ScenarioKind::Calibration,
        Some("[anomaly]\narea = \"realistic\"\n"),
        Some(4),
    )
    .unwrap();
    let gq = along_gradient(&quiet, 9.0);
    let gr = along_gradient(&realistic, 9.0);
    println!(
        "calibration gradients: quiet {gq:.3}, realistic {gr:.3} nT/100 m (includes manoeuvre height changes)"
    );
    assert!(
        gr < 1.0,
        "realistic calibration area at 3000 m: {gr} nT/100 m"
    );
    assert!(gq < 0.2 * gr, "quiet {gq} vs realistic {gr}");
    assert!(
        realistic
            .scenario_toml
            .contains("gradient_rms_nt_per_100m = 3.0")
    );
}

#[test]
fn same_seed_is_bit_identical_and_seeds_differ() {
    let a = simulate(ScenarioKind::CalibrationTruncated, None, Some(11)).unwrap();
    let b = simulate(ScenarioKind::CalibrationTruncated, None, Some(11)).unwrap();
    let c = simulate(ScenarioKind::CalibrationTruncated, None, Some(12)).unwrap();
    assert_eq!(a.column_names(), b.column_names());
    for (x, y) in a.columns.iter().zip(&b.columns) {
        assert!(
            x.values
                .iter()
                .zip(&y.values)
                .all(|(p, q)| p.to_bits() == q.to_bits()),
            "column {}",
            x.name
        );
    }
    assert_eq!(a.truth_json, b.truth_json);
    assert_eq!(a.scenario_toml, b.scenario_toml);
    assert_ne!(col(&a, "mag"), col(&c, "mag"));
    // The filled-in scenario file reproduces the run exactly.
    let again = simulate(
        ScenarioKind::CalibrationTruncated,
        Some(&a.scenario_toml),
        None,
    )
    .unwrap();
    for (x, y) in a.columns.iter().zip(&again.columns) {
        assert!(
            x.values
                .iter()
                .zip(&y.values)
                .all(|(p, q)| p.to_bits() == q.to_bits()),
            "column {}",
            x.name
        );
    }
}

#[test]
fn truncated_flight_is_about_a_quarter_shorter() {
    let full = simulate(ScenarioKind::Calibration, None, Some(1))
        .unwrap()
        .n_rows() as f64;
    let trunc = simulate(ScenarioKind::CalibrationTruncated, None, Some(1))
        .unwrap()
        .n_rows() as f64;
    let r = trunc / full;
    println!("truncated / full flight time: {r:.3}");
    assert!((0.70..0.80).contains(&r), "{r}");
}

#[test]
fn configuration_errors_are_clear() {
    let typo = simulate(
        ScenarioKind::Calibration,
        Some("[pattern]\naltitud_m = 2000.0\n"),
        None,
    );
    match typo {
        Err(SimError::ConfigParse { line, message }) => {
            assert!(
                message.contains("altitud_m") && message.contains("line 2"),
                "{message}"
            );
            assert_eq!(line, Some(2));
        }
        other => panic!("expected a parse error, got {other:?}"),
    }
    let wrong_type = simulate(ScenarioKind::Survey, Some("seed = \"seven\"\n"), None);
    assert!(
        matches!(wrong_type, Err(SimError::ConfigParse { line: Some(1), .. })),
        "{wrong_type:?}"
    );
    let bad_value = simulate(ScenarioKind::Survey, Some("[scalar]\nlag_s = -1.0\n"), None);
    match bad_value {
        Err(SimError::InvalidConfig { field, .. }) => assert_eq!(field, "scalar.lag_s"),
        other => panic!("expected an invalid value, got {other:?}"),
    }
    let bad_date = simulate(
        ScenarioKind::Calibration,
        Some("[flight]\ndate = \"2040-01-01\"\n"),
        None,
    );
    assert!(matches!(bad_date, Err(SimError::Core(_))), "{bad_date:?}");
    // A start time beyond a day (1e300 s was passed on as a date of 300
    // digits, naming no key) or before midnight.
    for start in ["1e300", "86400.5", "-1.0"] {
        let text = format!("[flight]\nstart_time_utc_s = {start}\n");
        match simulate(ScenarioKind::Calibration, Some(&text), None) {
            Err(SimError::InvalidConfig { field, .. }) => {
                assert_eq!(field, "flight.start_time_utc_s")
            }
            other => panic!("{start}: expected an invalid value, got {other:?}"),
        }
    }
    let bad_toml = simulate(ScenarioKind::Calibration, Some("[pattern\n"), None);
    assert!(matches!(
        bad_toml,
        Err(SimError::ConfigParse { line: Some(1), .. })
    ));
    let huge_seed = simulate(ScenarioKind::Calibration, None, Some(u64::MAX));
    assert!(matches!(huge_seed, Err(SimError::InvalidConfig { .. })));
    // TOML's nan and inf are refused naming the key, in every scenario
    // (they went through to NaN columns written as data).
    for (kind, text, key) in [
        (
            ScenarioKind::Calibration,
            "[anomaly]\nsource_depth_m = nan\n",
            "anomaly.source_depth_m",
        ),
        (
            ScenarioKind::Survey,
            "[[aircraft.parts]]\nname = \"x\"\nposition_m = [1.0, -inf, 0.0]\n",
            "aircraft.parts[0].position_m[1]",
        ),
        (
            ScenarioKind::Helicopter,
            "[rotor]\nroot_m = inf\n",
            "rotor.root_m",
        ),
        (ScenarioKind::Pod, "swing_amp_deg = -nan\n", "swing_amp_deg"),
    ] {
        match simulate(kind, Some(text), None) {
            Err(SimError::InvalidConfig { field, reason }) => {
                assert_eq!(field, key);
                assert!(reason.contains("not a finite number"), "{reason}");
            }
            other => panic!("{text}: expected an invalid value, got {other:?}"),
        }
    }
    // Finite values too large for the simulator: an overflow naming the
    // first non-finite column and sample, bad input (they were written).
    for (text, column) in [
        ("field_nt = 1e308\n", "mag"),
        ("speed_m_s = 1e308\n", "lat"),
    ] {
        match simulate(ScenarioKind::Pod, Some(text), None) {
            Err(e @ SimError::Overflow { .. }) => {
                assert!(e.is_bad_input());
                assert!(e.to_string().contains(&format!("`{column}`")), "{e}");
            }
            other => panic!("{text}: expected an overflow, got {other:?}"),
        }
    }
    // A pod flight whose samples would not fit in memory (10⁸ Hz asked for
    // 576 GB) or that outlasts a day.
    for (text, key) in [
        ("sample_rate_hz = 1e8\n", "pod.sample_rate_hz"),
        ("manoeuvre_s = 1e6\n", "pod.manoeuvre_s"),
        (
            "sample_rate_hz = 10000.0\nmanoeuvre_s = 1000.0\n",
            "pod.manoeuvre_s",
        ),
    ] {
        match simulate(ScenarioKind::Pod, Some(text), None) {
            Err(SimError::InvalidConfig { field, .. }) => assert_eq!(field, key, "{text}"),
            other => panic!("{text}: expected an invalid value, got {other:?}"),
        }
    }
    // A turn longer than a flight: an error, not an allocation of 1.7 TB.
    let e = simulate(
        ScenarioKind::Calibration,
        Some("[kinematics]\nturn_ramp_s = 2147483648.0\n"),
        None,
    )
    .unwrap_err();
    assert!(
        e.is_bad_input() && e.to_string().contains("longer than a flight"),
        "{e}"
    );
}

#[test]
fn partial_configuration_keeps_the_scenario_defaults() {
    let s = simulate(
        ScenarioKind::Survey,
        Some("seed = 9\n[pattern]\nline_count = 2\nline_length_m = 2000.0\ntie_count = 0\n"),
        None,
    )
    .unwrap();
    assert_eq!(s.seed, 9);
    // survey defaults survive: lag 0.1 s, realistic area, two dipoles, 70 m/s
    assert!(s.scenario_toml.contains("lag_s = 0.1"));
    assert!(s.scenario_toml.contains("area = \"realistic\""));
    assert_eq!(s.scenario_toml.matches("[[anomaly.dipoles]]").count(), 2);
    assert!(s.scenario_toml.contains("speed_m_s = 70.0"));
    let v = col(&s, "true_vn")
        .iter()
        .zip(col(&s, "true_ve"))
        .map(|(a, b)| (a * a + b * b).sqrt())
        .fold(0.0, f64::max);
    assert!((v - 70.0).abs() < 0.01);
    // the seed argument overrides the file
    let t = simulate(
        ScenarioKind::Survey,
        Some("seed = 9\n[pattern]\nline_count = 2\nline_length_m = 2000.0\ntie_count = 0\n"),
        Some(10),
    )
    .unwrap();
    assert_eq!(t.seed, 10);
    assert!(t.scenario_toml.contains("seed = 10"));
}

#[test]
fn fluxgate_records_its_documented_errors() {
    let s = simulate(
        ScenarioKind::Calibration,
        Some("[fluxgate]\nnoise_density_nt_per_rthz = 0.0\n"),
        Some(6),
    )
    .unwrap();
    let truth: serde_json::Value = serde_json::from_str(&s.truth_json).unwrap();
    let m = &truth["sensors"]["fluxgate"]["matrix"];
    let bias = [12.0, -8.0, 5.0];
    for k in (0..s.n_rows()).step_by(97) {
        let t: Vec<f64> = ["x", "y", "z"]
            .iter()
            .map(|a| col(&s, &format!("true_flux_{a}"))[k])
            .collect();
        for (i, a) in ["x", "y", "z"].iter().enumerate() {
            let expect: f64 = (0..3)
                .map(|j| m[i][j].as_f64().unwrap() * t[j])
                .sum::<f64>()
                + bias[i];
            assert!((col(&s, &format!("flux_{a}"))[k] - expect).abs() < 1e-7);
        }
    }
}

#[test]
fn onboard_current_appears_in_its_channel_and_in_the_interference() {
    let cfg = "[[aircraft.currents]]\nname = \"deicer\"\nposition_m = [-6.0, 0.0, -0.5]\nnormal = [0.0, 0.0, 1.0]\narea_m2 = 0.2\nmean_a = 10.0\nswitched_a = 30.0\nswitches_per_hour = 60.0\n";
    let s = simulate(ScenarioKind::Calibration, Some(cfg), Some(7)).unwrap();
    let rec = col(&s, "cur_deicer");
    let tru = col(&s, "true_cur_deicer");
    let part = col(&s, "true_interf_current");
    assert!(rms(part) > 0.1, "current interference {}", rms(part));
    // the interference follows the current: correlation close to 1 in magnitude
    let mc = tru.iter().sum::<f64>() / tru.len() as f64;
    let mp = part.iter().sum::<f64>() / part.len() as f64;
    let cov: f64 = tru.iter().zip(part).map(|(a, b)| (a - mc) * (b - mp)).sum();
    let va: f64 = tru.iter().map(|a| (a - mc).powi(2)).sum();
    let vb: f64 = part.iter().map(|b| (b - mp).powi(2)).sum();
    let corr = cov / (va * vb).sqrt();
    assert!(corr.abs() > 0.9, "correlation {corr}");
    assert!(rms(&rec.iter().zip(tru).map(|(a, b)| a - b).collect::<Vec<_>>()) < 0.05);
}

/// A scenario whose flight the readers would refuse is refused before a
/// file is written: a scalar sensor lag of 10⁹ s wrote `mag` of 5.4·10⁸ nT
/// that `calibrate` then refused as picotesla.
#[test]
fn a_flight_the_readers_would_refuse_is_not_written() {
    let s = simulate(
        ScenarioKind::Calibration,
        Some("[pattern]\ncycles = 1\n[scalar]\nlag_s = 1e9\n"),
        Some(1),
    )
    .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let e = s.write_to_dir(dir.path()).unwrap_err();
    assert!(matches!(e, SimError::Unreadable { .. }), "{e}");
    assert!(e.is_bad_input());
    let text = e.to_string();
    assert!(
        text.contains("'calibration.csv': column 'mag'") && text.contains("far above"),
        "{text}"
    );
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    // A real sensor's lag is written.
    let s = simulate(
        ScenarioKind::Calibration,
        Some("[pattern]\ncycles = 1\n[scalar]\nlag_s = 0.2\n"),
        Some(1),
    )
    .unwrap();
    s.write_to_dir(dir.path()).unwrap();
}

#[test]
fn files_are_written_and_documented() {
    let s = simulate(ScenarioKind::Calibration, None, Some(8)).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let files = s.write_to_dir(dir.path()).unwrap();
    let csv = std::fs::read_to_string(&files.csv).unwrap();
    let mut lines = csv.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header, s.column_names());
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), s.n_rows());
    // values round-trip exactly
    let first: Vec<f64> = rows[123].split(',').map(|v| v.parse().unwrap()).collect();
    for (c, v) in s.columns.iter().zip(&first) {
        assert_eq!(c.values[123].to_bits(), v.to_bits(), "{}", c.name);
    }
    assert_eq!(
        std::fs::read_to_string(&files.scenario).unwrap(),
        s.scenario_toml
    );
    // aeromag-io reads the file back bit for bit, and its time check passes.
    let table = aeromag_io::read_csv(&files.csv, &aeromag_io::ReadOptions::default()).unwrap();
    assert_eq!(table.n_rows(), s.n_rows());
    for c in &s.columns {
        let back = table.column(&c.name).unwrap();
        assert!(
            back.iter()
                .zip(&c.values)
                .all(|(a, b)| a.to_bits() == b.to_bits()),
            "{}",
            c.name
        );
    }
    aeromag_io::check_time(&table).unwrap();
    let truth: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&files.truth).unwrap()).unwrap();
    assert_eq!(truth["columns"].as_array().unwrap().len(), s.columns.len());
    // Every column is documented in the crate docs.
    let lib = include_str!("../src/lib.rs");
    for c in &s.columns {
        assert!(
            lib.contains(&format!("`{}`", c.name)),
            "column {} is not in the crate docs",
            c.name
        );
        assert!(
            !c.description.is_empty() && !c.unit.is_empty(),
            "{}",
            c.name
        );
    }
    // The default scenario files parse back.
    for kind in ScenarioKind::ALL {
        let text = default_config_toml(kind).unwrap();
        assert!(text.starts_with("# aeromag-sim scenario"));
        let _: toml::Table = toml::from_str(&text).unwrap();
        // The fixed-wing files show the installation key the default
        // leaves out, just before `seed`.
        let fixed_wing = !matches!(kind, ScenarioKind::Helicopter | ScenarioKind::Pod);
        assert_eq!(
            text.contains("\n# installation = \"stinger\" (the default"),
            fixed_wing,
            "{kind:?}"
        );
        if fixed_wing {
            let i = text.find("# installation").unwrap();
            assert!(text[i..].lines().nth(2).unwrap().starts_with("seed = "));
        }
    }
    assert_eq!(
        "calibration-truncated".parse::<ScenarioKind>().unwrap(),
        ScenarioKind::CalibrationTruncated
    );
    assert_eq!(
        "helicopter".parse::<ScenarioKind>().unwrap(),
        ScenarioKind::Helicopter
    );
    assert!("no-such-scenario".parse::<ScenarioKind>().is_err());
}
