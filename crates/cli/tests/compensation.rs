//! `aeromag calibrate` + `compensate` + `report` + `demo` end to end.

mod common;
use common::*;

fn simulate(dir: &std::path::Path, scenario: &str, seed: &str) -> std::path::PathBuf {
    let out = dir.join(scenario);
    assert_code(
        &aeromag(&[
            "simulate",
            scenario,
            "--seed",
            seed,
            "--out",
            out.to_str().unwrap(),
        ]),
        0,
    );
    out.join(format!("{}.csv", scenario.replace('-', "_")))
}

#[test]
fn calibrate_compensate_report_keep_every_row() {
    let d = tempfile::tempdir().unwrap();
    let cal = simulate(d.path(), "calibration", "5");
    let model = d.path().join("m.json");
    let o = aeromag(&[
        "calibrate",
        "--input",
        cal.to_str().unwrap(),
        "--model",
        model.to_str().unwrap(),
    ]);
    assert_code(&o, 0);
    assert!(!stderr(&o).contains("poorly determined"), "{}", stderr(&o));
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    assert_eq!(m["format"], "aeromag-model/1");
    // The simulated airframe's eddy currents lag (τ 0.15–0.6 s): `auto`
    // adds one or two lagged groups of nine columns to the 16 classical ones.
    let lags = m["terms"]["eddy_lags_s"].as_array().map_or(0, |a| a.len());
    assert!((1..=2).contains(&lags), "{}", m["terms"]);
    assert_eq!(m["coefficients"].as_array().unwrap().len(), 16 + 9 * lags);
    assert!(
        stderr(&o).contains("chosen (likelihood-ratio test)"),
        "{}",
        stderr(&o)
    );
    // The model file records the search: every candidate with Λ and its threshold.
    let sel = &m["fit"]["eddy_lag_selection"];
    let cands = sel["candidates"]
        .as_array()
        .expect("lag selection recorded");
    assert!(
        cands.len() >= 7
            && cands
                .iter()
                .all(|c| c["lr_statistic"].is_number() && c["threshold"].is_number()),
        "{sel}"
    );
    assert_eq!(sel["taus_s"], m["terms"]["eddy_lags_s"]);
    let classical = d.path().join("m16.json");
    let o16 = aeromag(&[
        "calibrate",
        "--input",
        cal.to_str().unwrap(),
        "--model",
        classical.to_str().unwrap(),
        "--eddy-lag",
        "none",
    ]);
    assert_code(&o16, 0);
    let m16: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&classical).unwrap()).unwrap();
    assert_eq!(m16["coefficients"].as_array().unwrap().len(), 16);
    // MagNav's convention keeps MagNav's model unless lags are asked for.
    let mn = d.path().join("mn.json");
    assert_code(
        &aeromag(&[
            "calibrate",
            "--input",
            cal.to_str().unwrap(),
            "--model",
            mn.to_str().unwrap(),
            "--convention",
            "magnav",
        ]),
        0,
    );
    let mn: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&mn).unwrap()).unwrap();
    assert_eq!(mn["coefficients"].as_array().unwrap().len(), 16);
    let rms = |m: &serde_json::Value| m["fit"]["residual_rms_nt"].as_f64().unwrap();
    assert!(
        rms(&m) < 0.8 * rms(&m16),
        "lagged {} vs classical {}",
        rms(&m),
        rms(&m16)
    );

    // Blank out some flux values: those rows stay, flagged.
    let text = std::fs::read_to_string(&cal).unwrap();
    let mut lines: Vec<String> = text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(String::from)
        .collect();
    let header: Vec<&str> = lines[0].split(',').collect();
    let fx = header.iter().position(|h| *h == "flux_x").unwrap();
    let n_in = lines.len() - 1;
    for row in [100usize, 101, 2000] {
        let mut cells: Vec<String> = lines[row + 1].split(',').map(String::from).collect();
        cells[fx] = String::new();
        lines[row + 1] = cells.join(",");
    }
    let holed = d.path().join("holed.csv");
    std::fs::write(&holed, lines.join("\n")).unwrap();
    let out = d.path().join("comp.csv");
    let o = compensate(&model, &holed, &out);
    assert_code(&o, 0);
    assert!(stderr(&o).contains("3 of"), "{}", stderr(&o));
    let comp = std::fs::read_to_string(&out).unwrap();
    let rows: Vec<&str> = comp.lines().filter(|l| !l.starts_with('#')).collect();
    assert_eq!(rows.len() - 1, n_in, "one output row per input row");
    let h: Vec<&str> = rows[0].split(',').collect();
    let flag = h.iter().position(|c| *c == "comp_flag").unwrap();
    let flagged: Vec<usize> = (1..rows.len())
        .filter(|&i| {
            rows[i]
                .split(',')
                .nth(flag)
                .and_then(|v| v.parse::<f64>().ok())
                == Some(1.0)
        })
        .map(|i| i - 1)
        .collect();
    assert_eq!(flagged, vec![100, 101, 2000]);

    let rep = d.path().join("rep");
    let o = aeromag(&[
        "report",
        "--input",
        out.to_str().unwrap(),
        "--model",
        model.to_str().unwrap(),
        "--out",
        rep.to_str().unwrap(),
    ]);
    assert_code(&o, 0);
    let html = std::fs::read_to_string(rep.join("index.html")).unwrap();
    for k in [
        "<svg",
        "Figure of merit",
        "coefficient",
        "Power spectral density",
    ] {
        assert!(html.contains(k), "{k} missing in the report");
    }
}

#[test]
fn a_single_heading_without_manoeuvres_is_reported() {
    let d = tempfile::tempdir().unwrap();
    let cal = simulate(d.path(), "calibration", "6");
    // Keep only straight flight on the first leg (no manoeuvres).
    let text = std::fs::read_to_string(&cal).unwrap();
    let mut it = text.lines().filter(|l| !l.starts_with('#'));
    let header = it.next().unwrap();
    let h: Vec<&str> = header.split(',').collect();
    let (li, mi) = (
        h.iter().position(|c| *c == "line").unwrap(),
        h.iter().position(|c| *c == "manoeuvre").unwrap(),
    );
    let kept: Vec<&str> = it
        .filter(|l| {
            let c: Vec<&str> = l.split(',').collect();
            c[li].parse::<f64>().ok() == Some(1.0) && c[mi].parse::<f64>().ok() == Some(0.0)
        })
        .collect();
    assert!(kept.len() > 300);
    let one = d.path().join("one.csv");
    std::fs::write(&one, format!("{header}\n{}", kept.join("\n"))).unwrap();
    let model = d.path().join("m.json");
    let o = aeromag(&[
        "calibrate",
        "--input",
        one.to_str().unwrap(),
        "--model",
        model.to_str().unwrap(),
    ]);
    let e = stderr(&o);
    assert!(!e.contains("panicked"), "{e}");
    // Either a warning naming the undetermined terms, or a clear refusal.
    assert!(
        e.contains("poorly determined terms") || o.status.code() == Some(2),
        "{e}"
    );
    if o.status.code() == Some(0) {
        assert!(e.contains("e_") || e.contains("i_"), "{e}");
    }
}

#[test]
fn model_and_argument_errors_exit_2() {
    let d = tempfile::tempdir().unwrap();
    let cal = simulate(d.path(), "calibration-truncated", "7");
    let p = cal.to_str().unwrap();
    let model = d.path().join("m.json");
    let m = model.to_str().unwrap();
    for args in [
        vec![
            "calibrate",
            "--input",
            p,
            "--model",
            m,
            "--terms",
            "p3,i6,i5",
        ],
        vec!["calibrate", "--input", p, "--model", m, "--band", "0.9,0.1"],
        vec![
            "calibrate",
            "--input",
            p,
            "--model",
            m,
            "--convention",
            "fancy",
        ],
        vec!["calibrate", "--input", p, "--model", m, "--lambda", "-1"],
        vec![
            "calibrate",
            "--input",
            p,
            "--model",
            m,
            "--eddy-lag",
            "0,0.5",
        ],
        vec![
            "calibrate",
            "--input",
            p,
            "--model",
            m,
            "--eddy-lag",
            "fast",
        ],
        vec![
            "calibrate",
            "--input",
            p,
            "--model",
            m,
            "--terms",
            "p3,i5",
            "--eddy-lag",
            "0.3",
        ],
        vec![
            "calibrate",
            "--input",
            p,
            "--model",
            m,
            "--lever-arm",
            "1,2",
        ],
        vec![
            "calibrate",
            "--input",
            p,
            "--model",
            m,
            "--lever-arm",
            "-9.5,0,-0.6",
            "--date",
            "2025-13-01",
        ],
        vec![
            "calibrate",
            "--input",
            p,
            "--model",
            m,
            "--method",
            "kalman",
            "--kalman-noise",
            "1e-15,4e-4",
        ],
        vec![
            "calibrate",
            "--input",
            p,
            "--model",
            m,
            "--method",
            "kalman",
            "--kalman-noise",
            "1e-15,1e-15,0",
        ],
        vec!["calibrate", "--input", p, "--model", m, "--series", "s.csv"],
        vec![
            "calibrate",
            "--input",
            p,
            "--model",
            m,
            "--field-order",
            "3",
        ],
        vec![
            "calibrate",
            "--input",
            p,
            "--model",
            m,
            "--method",
            "kalman",
            "--field-order",
            "7",
        ],
        vec![
            "calibrate",
            "--input",
            p,
            "--model",
            m,
            "--method",
            "kalman",
            "--tune",
            "--no-tune",
        ],
    ] {
        let o = aeromag(&args);
        assert_code(&o, 2);
    }
    assert_code(&aeromag(&["calibrate", "--input", p, "--model", m]), 0);
    let o = aeromag(&[
        "calibrate",
        "--input",
        p,
        "--model",
        m,
        "--method",
        "kalman",
        "--kalman-noise",
        "2e-15,1e-15,3e-4",
    ]);
    assert_code(&o, 0);
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("q1 = 2.000e-15"),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    // By default the Kalman method tunes its noise intensities, and --series
    // writes the smoothed field and innovations on every input row.
    let series = d.path().join("series.csv");
    let o = aeromag(&[
        "calibrate",
        "--input",
        p,
        "--model",
        m,
        "--method",
        "kalman",
        "--series",
        series.to_str().unwrap(),
    ]);
    assert_code(&o, 0);
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("tuned by maximum likelihood"),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    let out = std::fs::read_to_string(&series).unwrap();
    let data = |t: &str| {
        t.lines()
            .filter(|l| !l.starts_with('#'))
            .map(String::from)
            .collect::<Vec<_>>()
    };
    let (rows_in, rows_out) = (data(&std::fs::read_to_string(&cal).unwrap()), data(&out));
    assert_eq!(
        rows_in.len(),
        rows_out.len(),
        "one output row per input row"
    );
    let header: Vec<&str> = rows_out[0].split(',').collect();
    let col = |n: &str| {
        header
            .iter()
            .position(|h| *h == n)
            .unwrap_or_else(|| panic!("no column {n}"))
    };
    let (field, innov, sd) = (
        col("kalman_field"),
        col("kalman_innovation"),
        col("kalman_innovation_std"),
    );
    let num = |r: &str, c: usize| r.split(',').nth(c).and_then(|v| v.parse::<f64>().ok());
    let mut within = 0;
    let mut n = 0;
    for r in rows_out.iter().skip(100) {
        if let (Some(f), Some(v), Some(s)) = (num(r, field), num(r, innov), num(r, sd)) {
            assert!(f.is_finite() && s > 0.0);
            n += 1;
            within += usize::from(v.abs() <= s);
        }
    }
    // A noise model that fits keeps about 68 % of the innovations within ±σ.
    assert!(
        n > 1000 && (0.55..0.85).contains(&(within as f64 / n as f64)),
        "{within} of {n} within ±σ"
    );
    // A model file that is not one.
    let junk = d.path().join("junk.json");
    std::fs::write(&junk, "{\"format\":\"other\"}").unwrap();
    let o = compensate(&junk, std::path::Path::new(p), &d.path().join("o.csv"));
    assert_code(&o, 2);
    assert!(stderr(&o).contains("junk.json"));
    // Data without the vector magnetometer: the message names what is missing.
    let text = std::fs::read_to_string(&cal).unwrap();
    let stripped = text.replace("flux_x", "fx");
    let nofx = d.path().join("nofx.csv");
    std::fs::write(&nofx, stripped).unwrap();
    let o = compensate(std::path::Path::new(m), &nofx, &d.path().join("o.csv"));
    assert_code(&o, 2);
    assert!(stderr(&o).contains("flux_x"), "{}", stderr(&o));
}

/// The keys of each calibration area over geology in the demo's summary.
const GEOLOGY_KEYS: [&str; 7] = [
    "residual_rms_ls_nt",
    "residual_rms_kalman_nt",
    "interference_rms_ls_nt",
    "interference_rms_kalman_nt",
    "noise_floor_nt",
    "calibration_altitude_m",
    "expected_gradient_nt_per_100m",
];

#[test]
fn demo_meets_the_compensation_figures() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("demo");
    let o = aeromag(&["demo", "--out", out.to_str().unwrap()]);
    assert_code(&o, 0);
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let c = &s["compensation"];
    let g = |k: &str| {
        c[k].as_f64()
            .unwrap_or_else(|| panic!("summary key compensation.{k}"))
    };
    let (res, floor) = (g("residual_rms_ls_nt"), g("noise_floor_nt"));
    assert!(
        res <= 2.0 * floor,
        "residual {res} nT > 2 × noise floor {floor} nT"
    );
    assert!(g("ir") >= 20.0, "IR {}", g("ir"));
    assert!(g("fom_after_nt") < g("fom_before_nt") / 20.0);
    assert!(
        g("fom_after_nt") <= 0.5,
        "FOM after {} nT",
        g("fom_after_nt")
    );
    assert!(out.join("index.html").exists() && out.join("model_ls.json").exists());
    // The spec's figure (compensation.md, "Acceptance"): over the gradient
    // area (the box at 300 m, 8.8 nT/100 m expected there) the Kalman
    // method's survey residual is at most half of LS's; in the quiet box it
    // is not worse. Seed 1 measured: gradient area 0.0446 / 0.0138 nT,
    // quiet 0.0113 / 0.0113 nT. The interference model alone: quiet 1.6 /
    // 1.3, gradient area 42.8 / 8.4, mild area (1000 m, 1.0 nT/100 m) 4.3 /
    // 1.9, ×10⁻³ nT.
    let num = |grp: &str, k: &str| s[grp][k].as_f64().unwrap_or(f64::NAN);
    assert!(
        num("compensation_gradient", "residual_rms_kalman_nt")
            <= 0.5 * num("compensation_gradient", "residual_rms_ls_nt"),
        "{}",
        s["compensation_gradient"]
    );
    assert!(
        num("compensation", "residual_rms_kalman_nt") <= num("compensation", "residual_rms_ls_nt"),
        "{}",
        s["compensation"]
    );
    for grp in ["compensation_gradient", "compensation_gradient_mild"] {
        assert!(
            num(grp, "interference_rms_kalman_nt") < num(grp, "interference_rms_ls_nt"),
            "{grp}: {}",
            s[grp]
        );
    }
    assert!(
        num("compensation", "interference_rms_kalman_nt")
            <= num("compensation", "interference_rms_ls_nt"),
        "{}",
        s["compensation"]
    );
    // Every key of data-formats.md that this version computes is present and numeric.
    for (group, keys) in [
        ("compensation", &["residual_rms_kalman_nt"][..]),
        ("compensation_gradient", &GEOLOGY_KEYS[..]),
        ("compensation_gradient_mild", &GEOLOGY_KEYS[..]),
        (
            "rotor",
            &[
                "rotor_rms_nt",
                "residual_model_nt",
                "residual_best_filter_nt",
            ][..],
        ),
        (
            "em",
            &[
                "range_err_rel",
                "angle_err_deg",
                "polarization_ratio_before",
                "polarization_ratio_after",
            ][..],
        ),
        (
            "gradiometry",
            &[
                "efficiency_tensor",
                "efficiency_scalar",
                "convergence_fraction",
            ][..],
        ),
        ("pod", &["rate_train", "rate_test"][..]),
    ] {
        for k in keys {
            assert!(s[group][k].as_f64().is_some(), "summary key {group}.{k}");
        }
    }
    // Levelling of the compensated survey (seed 1's survey: k = −0.0972 ±
    // 0.0042 s measured, truth −0.1): k within 10 % and 3σ, and the classic
    // case (no base station) reduced more than 5×.
    let l = |k: &str| {
        s["levelling"][k]
            .as_f64()
            .unwrap_or_else(|| panic!("summary key levelling.{k}"))
    };
    assert_eq!(l("crossovers"), 100.0);
    let (k, sk, kt) = (l("k_s"), l("k_std_s"), l("k_true_s"));
    assert!(
        (k - kt).abs() <= 0.1 * kt.abs() && (k - kt).abs() <= 3.0 * sk,
        "k = {k} ± {sk}, truth {kt}"
    );
    assert!(
        l("rms_before_no_base_station_nt") >= 5.0 * l("rms_after_no_base_station_nt"),
        "{}",
        s["levelling"]
    );
}

#[test]
fn observability_tells_a_full_box_from_a_single_heading() {
    let d = tempfile::tempdir().unwrap();
    let cal = simulate(d.path(), "calibration", "8");
    let o = aeromag(&["observability", "--input", cal.to_str().unwrap()]);
    assert_code(&o, 0);
    let s = stdout(&o);
    assert!(
        s.contains("rank 16 of 16") && !s.contains("cannot determine"),
        "{s}"
    );
    // One straight leg: the permanent and induced terms are not determined.
    let text = std::fs::read_to_string(&cal).unwrap();
    let mut it = text.lines().filter(|l| !l.starts_with('#'));
    let header = it.next().unwrap();
    let h: Vec<&str> = header.split(',').collect();
    let (li, mi) = (
        h.iter().position(|c| *c == "line").unwrap(),
        h.iter().position(|c| *c == "manoeuvre").unwrap(),
    );
    let kept: Vec<&str> = it
        .filter(|l| {
            let c: Vec<&str> = l.split(',').collect();
            c[li].parse::<f64>().ok() == Some(1.0) && c[mi].parse::<f64>().ok() == Some(0.0)
        })
        .collect();
    let one = d.path().join("one.csv");
    std::fs::write(&one, format!("{header}\n{}", kept.join("\n"))).unwrap();
    let o = aeromag(&["observability", "--input", one.to_str().unwrap()]);
    assert_code(&o, 0);
    let s = stdout(&o);
    assert!(
        s.contains("this flight cannot determine:") && s.contains("p_x") && s.contains("i_xx"),
        "{s}"
    );
    let j = aeromag(&["observability", "--input", one.to_str().unwrap(), "--json"]);
    let v: serde_json::Value = serde_json::from_str(&stdout(&j)).unwrap();
    assert_eq!(v["estimability"].as_array().unwrap().len(), 16);
}

/// Errors of a compensated simulated survey, nT, each the RMS over the
/// survey/tie lines with each line's mean removed (pooled), for scoring
/// only: `[0]` the interference model alone, `true_interf − mag_interf`;
/// `[1]` the survey residual of the spec (`compensation.md`, Metrics),
/// `mag_comp − true_external − true_lag`, which holds the scalar sensor's
/// noise (0.011 nT).
fn survey_errors(path: &std::path::Path) -> [f64; 2] {
    let text = std::fs::read_to_string(path).unwrap();
    let mut rows = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = rows.next().unwrap().split(',').collect();
    let col = |n: &str| {
        header
            .iter()
            .position(|h| *h == n)
            .unwrap_or_else(|| panic!("no column {n}"))
    };
    let idx = [
        col("true_interf"),
        col("mag_interf"),
        col("mag_comp"),
        col("true_external"),
        col("true_lag"),
        col("line"),
    ];
    let mut by_line: std::collections::BTreeMap<i64, [Vec<f64>; 2]> = Default::default();
    for r in rows {
        let v: Vec<&str> = r.split(',').collect();
        let Ok(x) = idx
            .iter()
            .map(|&i| v[i].parse::<f64>())
            .collect::<Result<Vec<f64>, _>>()
        else {
            continue;
        };
        if x[5] > 0.0 {
            let e = by_line.entry(x[5] as i64).or_default();
            e[0].push(x[0] - x[1]);
            e[1].push(x[2] - x[3] - x[4]);
        }
    }
    let mut out = [0.0; 2];
    for (j, o) in out.iter_mut().enumerate() {
        let (mut ss, mut n) = (0.0, 0usize);
        for e in by_line.values() {
            let e = &e[j];
            let mean = e.iter().sum::<f64>() / e.len() as f64;
            ss += e.iter().map(|x| (x - mean).powi(2)).sum::<f64>();
            n += e.len();
        }
        *o = (ss / n as f64).sqrt();
    }
    out
}

/// Over realistic geology at 600 m the Kalman method (as `calibrate`
/// runs it: two-pass lag choice, tuned noise, the default field model of
/// order 6) leaves at most half the interference-model error of band-pass
/// LS on an independent survey, and less than with the thesis' order-3
/// field model (`--field-order 3`). Measured on the demo surveys, seeds
/// 1–5 (×10⁻³ nT, LS / Kalman order 6): 13.4/3.1, 17.8/2.6, 8.7/2.1,
/// 13.7/2.4, 14.9/6.2 (the module docs of `kalman::tuning` have the other
/// altitudes and stronger geology).
#[test]
fn kalman_halves_the_least_squares_error_over_geology_at_600_m() {
    let err = calibrate_and_compare(
        "[pattern]\naltitude_m = 600.0\n[anomaly]\narea = \"realistic\"\n",
        "4",
        "",
        "5",
        "-9.5,0,-0.6",
        &[None, Some("3")],
    );
    let e: Vec<f64> = err.iter().map(|e| e[0]).collect();
    eprintln!(
        "interference error LS {:.4} nT, Kalman (order 6) {:.4} nT, order 3 {:.4} nT",
        e[0], e[1], e[2]
    );
    assert!(e[1] <= 0.5 * e[0], "{err:?}");
    assert!(e[1] < e[2], "{err:?}");
}

/// Over strong geology (10 nT/100 m at 100 m above ground, the top of the
/// survey range; ≈ 8 nT/100 m at the calibration height of 300 m) the
/// band-pass LS model leaves several times the sensor noise on the survey,
/// and the Kalman method halves the survey residual of the spec itself
/// (compensated − true external field, noise included), not only the
/// interference-model error. This needs the cleaned altitude of the
/// vertical-gradient term and the multi-start noise tuning: with the raw
/// GNSS altitude (0.2 m white noise) and Nelder–Mead from the defaults,
/// the Kalman error at 600 m over this geology was 2× the LS error (module
/// docs of `aeromag_compensation::kalman::altitude`).
#[test]
fn kalman_halves_the_survey_residual_over_strong_geology() {
    let err = calibrate_and_compare(
        "[pattern]\naltitude_m = 300.0\n[anomaly]\narea = \"realistic\"\ngradient_rms_nt_per_100m = 10.0\n",
        "6",
        "",
        "7",
        "-9.5,0,-0.6",
        &[None],
    );
    eprintln!(
        "strong geology, LS interference {:.4} residual {:.4} nT; Kalman {:.4} / {:.4} nT",
        err[0][0], err[0][1], err[1][0], err[1][1]
    );
    assert!(err[1][1] <= 0.5 * err[0][1], "{err:?}");
    assert!(err[1][0] <= 0.5 * err[0][0], "{err:?}");
}

/// A different aircraft, not the one the defaults were tuned on: one engine
/// in the nose, a 7 m stinger, other eddy-current circuits (a wing with
/// τ = 0.4 s, between the lags the lag test offers), calibrated at 300 m
/// over realistic geology. Measured (calibration seeds 1–3, surveys 41–43,
/// ×10⁻³ nT, LS / Kalman): 300 m 23.7/6.0, 26.3/8.9, 22.1/5.6; 600 m
/// 10.7/5.9, 16.6/5.8, 8.6/4.5 (before the cleaned altitude and the grid
/// search of the noise tuning: 6.6, 9.3, 12.0; 6.9, 6.2, 4.4). In the
/// quiet box at 3 km both methods gave 5.1–5.5 (not re-measured): what the
/// Tolles-Lawson model itself leaves for this aircraft. On the full survey
/// residual (sensor noise included) the ratio Kalman / LS is 0.49–0.51 at
/// 300 m (the preset geology, 2.6 nT/100 m at the box) and 0.62–0.85 at
/// 600 m.
#[test]
fn kalman_halves_the_least_squares_error_for_another_aircraft_at_300_m() {
    let err = calibrate_and_compare(
        &format!(
            "[pattern]\naltitude_m = 300.0\n[anomaly]\narea = \"realistic\"\n{OTHER_AIRCRAFT}"
        ),
        "1",
        OTHER_AIRCRAFT,
        "41",
        "-7,0,-0.4",
        &[None],
    );
    eprintln!(
        "other aircraft, interference error LS {:.4} nT, Kalman {:.4} nT",
        err[0][0], err[1][0]
    );
    assert!(err[1][0] <= 0.5 * err[0][0], "{err:?}");
}

/// A single-engine aircraft with a short stinger (scenario TOML sections).
const OTHER_AIRCRAFT: &str = r#"
[aircraft]
currents = []

[[aircraft.parts]]
name = "single engine"
position_m = [2.5, 0.0, 0.3]
permanent_am2 = [120.0, -25.0, 60.0]
susceptibility_volume_m3 = [[0.6, 0.05, -0.08], [0.03, 0.3, 0.1], [-0.05, 0.06, 0.45]]

[[aircraft.parts]]
name = "gear"
position_m = [0.0, 0.0, 1.0]
permanent_am2 = [-15.0, 6.0, 30.0]
susceptibility_volume_m3 = [[0.15, 0.02, 0.0], [-0.01, 0.09, 0.02], [0.01, 0.0, 0.12]]

[[aircraft.parts]]
name = "tail cone"
position_m = [-5.0, 0.0, -0.5]
permanent_am2 = [2.0, -0.5, 4.0]
susceptibility_volume_m3 = [[0.02, 0.002, 0.0], [0.001, 0.01, 0.0], [0.001, 0.0, 0.015]]

[[aircraft.eddy]]
name = "wing"
position_m = [0.5, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
area_m2 = 9.0
resistance_ohm = 0.00015
tau_s = 0.4

[[aircraft.eddy]]
name = "tail skin"
position_m = [-5.2, 0.0, -0.4]
normal = [1.0, 0.0, 0.0]
area_m2 = 0.8
resistance_ohm = 0.0003
tau_s = 0.2

[[aircraft.eddy]]
name = "stabiliser"
position_m = [-5.5, 0.0, -1.0]
normal = [0.0, 1.0, 0.0]
area_m2 = 0.7
resistance_ohm = 0.0003
tau_s = 0.35

[scalar]
position_m = [-7.0, 0.0, -0.4]
noise_density_nt_per_rthz = 0.005
axis = [1.0, 0.0, 1.0]
heading_error_1_nt = 0.05
heading_error_2_nt = 0.02
lag_s = 0.0

[fluxgate]
position_m = [-5.8, 0.0, -0.3]
noise_density_nt_per_rthz = 0.05
bias_nt = [-20.0, 5.0, 9.0]
scale_error = [-0.001, 0.0012, 0.0005]
non_orthogonality_deg = [-0.04, 0.06, 0.02]
misalignment_deg = [-0.2, 0.4, 0.1]
"#;

/// Simulate a calibration (`cal_toml`, seed `cal_seed`) and a survey
/// (`survey_toml`, empty for the defaults; seed `survey_seed`), calibrate
/// with band-pass LS and then with the Kalman method for each field order
/// of `kalman_orders` (`None`: the default), compensate the survey with
/// each model, and return the survey errors of each ([`survey_errors`]: the
/// interference model's, the survey residual), LS first, nT.
fn calibrate_and_compare(
    cal_toml: &str,
    cal_seed: &str,
    survey_toml: &str,
    survey_seed: &str,
    lever_arm: &str,
    kalman_orders: &[Option<&str>],
) -> Vec<[f64; 2]> {
    let d = tempfile::tempdir().unwrap();
    let run_simulation = |scenario: &str, toml: &str, seed: &str| {
        let cfg = d.path().join(format!("{scenario}.toml"));
        std::fs::write(&cfg, toml).unwrap();
        let dir = d.path().join(scenario);
        assert_code(
            &aeromag(&[
                "simulate",
                scenario,
                "--config",
                cfg.to_str().unwrap(),
                "--seed",
                seed,
                "--out",
                dir.to_str().unwrap(),
            ]),
            0,
        );
        dir.join(format!("{scenario}.csv"))
    };
    let cal = run_simulation("calibration", cal_toml, cal_seed);
    let survey = run_simulation("survey", survey_toml, survey_seed);
    let runs = std::iter::once(("ls", None)).chain(kalman_orders.iter().map(|o| ("kalman", *o)));
    let mut err = Vec::new();
    for (k, (method, order)) in runs.enumerate() {
        let model = d.path().join(format!("m{k}.json"));
        let out = d.path().join(format!("c{k}.csv"));
        let mut args = vec![
            "calibrate",
            "--input",
            cal.to_str().unwrap(),
            "--model",
            model.to_str().unwrap(),
            "--method",
            method,
            "--lever-arm",
            lever_arm,
        ];
        if let Some(order) = order {
            args.extend(["--field-order", order]);
        }
        assert_code(&aeromag(&args), 0);
        assert_code(&compensate(&model, &survey, &out), 0);
        err.push(survey_errors(&out));
    }
    err
}
