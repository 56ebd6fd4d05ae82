//! `aeromag rotor study`: the issue-5 figures on the `helicopter` scenario.

mod common;
use common::*;

#[test]
fn rotor_study_meets_the_issue_figures() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("rotor");
    let o = aeromag(&["rotor", "study", "--out", out.to_str().unwrap()]);
    assert_code(&o, 0);
    assert!(
        stdout(&o).contains("synchronous averaging"),
        "{}",
        stdout(&o)
    );
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let v = |k: &str| {
        s["rotor"][k]
            .as_f64()
            .unwrap_or_else(|| panic!("missing rotor.{k}"))
    };
    let (rms, model, filter) = (
        v("rotor_rms_nt"),
        v("residual_model_nt"),
        v("residual_best_filter_nt"),
    );
    eprintln!("rotor {rms:.3} nT, model residual {model:.4} nT, best filter {filter:.4} nT");
    assert!(model <= 0.10 * rms, "model leaves {model} of {rms}");
    assert!(
        filter >= 3.0 * model,
        "best filter {filter} vs model {model}"
    );
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(html.contains("<svg") && html.contains("low-pass"));
}

/// Rows of a CSV written by aeromag: header and the named columns (NaN for
/// empty cells).
fn columns(p: &std::path::Path, names: &[&str]) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(p).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let idx: Vec<usize> = names
        .iter()
        .map(|n| {
            header
                .iter()
                .position(|h| h == n)
                .unwrap_or_else(|| panic!("no column {n}"))
        })
        .collect();
    let mut out = vec![Vec::new(); names.len()];
    for l in lines {
        let f: Vec<&str> = l.split(',').collect();
        for (o, i) in out.iter_mut().zip(&idx) {
            o.push(f[*i].parse().unwrap_or(f64::NAN));
        }
    }
    out
}

/// Standard deviation without 3 s (300 samples) at each end.
fn std_mid(x: &[f64]) -> f64 {
    let s = &x[300..x.len() - 300];
    let m = s.iter().sum::<f64>() / s.len() as f64;
    (s.iter().map(|v| (v - m).powi(2)).sum::<f64>() / s.len() as f64).sqrt()
}

/// Share of the true rotor interference RMS the applied model leaves
/// (scored against `true_rotor`, which the commands never read).
fn residual_share(out: &std::path::Path) -> f64 {
    let c = columns(out, &["true_rotor", "rotor_interf"]);
    let res: Vec<f64> = c[0].iter().zip(&c[1]).map(|(a, b)| a - b).collect();
    std_mid(&res) / std_mid(&c[0])
}

fn simulate_heli(
    d: &std::path::Path,
    name: &str,
    seed: &str,
    config: Option<&str>,
) -> std::path::PathBuf {
    let dir = d.join(name);
    let mut args = vec![
        "simulate",
        "helicopter",
        "--seed",
        seed,
        "--out",
        dir.to_str().unwrap(),
    ];
    let cfg = d.join(format!("{name}.toml"));
    if let Some(text) = config {
        std::fs::write(&cfg, text).unwrap();
        args.extend(["--config", cfg.to_str().unwrap()]);
    }
    assert_code(&aeromag(&args), 0);
    dir.join("helicopter.csv")
}

#[test]
fn rotor_fit_and_apply_leave_under_10_percent_on_an_independent_flight() {
    let d = tempfile::tempdir().unwrap();
    let learn = simulate_heli(d.path(), "a", "11", None);
    let other = simulate_heli(d.path(), "b", "12", None);
    let model = d.path().join("rotor.json");
    let o = aeromag(&[
        "rotor",
        "fit",
        "--input",
        learn.to_str().unwrap(),
        "--model",
        model.to_str().unwrap(),
    ]);
    assert_code(&o, 0);
    assert!(stdout(&o).contains("from `rotor_phase`"), "{}", stdout(&o));
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    assert_eq!(m["format"], "aeromag-model/1");
    assert_eq!(m["kind"], "helicopter-rotor");
    let out = d.path().join("out.csv");
    let o = apply("rotor", &model, &other, &out);
    assert_code(&o, 0);
    let share = residual_share(&out);
    eprintln!(
        "rotor model with phase channel leaves {:.2} % of the rotor RMS on an independent flight",
        100.0 * share
    );
    assert!(share <= 0.10, "{share}");
    // One row per input row; a missing `mag` value is kept and flagged.
    let text = std::fs::read_to_string(&other).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let hdr = lines.iter().position(|l| !l.starts_with('#')).unwrap();
    let mag_i = lines[hdr].split(',').position(|c| c == "mag").unwrap();
    let edit = |row: usize, value: &str| -> String {
        let mut out: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
        let mut f: Vec<String> = out[hdr + row].split(',').map(String::from).collect();
        f[mag_i] = value.into();
        out[hdr + row] = f.join(",");
        out.join("\n") + "\n"
    };
    let gap = d.path().join("gap.csv");
    std::fs::write(&gap, edit(20_000, "")).unwrap();
    let o = apply("rotor", &model, &gap, &out);
    assert_code(&o, 0);
    let c = columns(&out, &["rotor_flag", "mag_comp", "rotor_interf"]);
    assert_eq!(c[0].len(), lines.len() - hdr - 1);
    assert_eq!(c[0][19_999], 1.0);
    assert!(c[1][19_999].is_nan());
    assert_eq!(c[0][0], 0.0);
    assert!(c[2][0].is_finite());
    // A learning flight with a missing value in the middle: the dropout is
    // bridged and the whole record fitted as one.
    let learn_text = std::fs::read_to_string(&learn).unwrap();
    let learn_lines: Vec<&str> = learn_text.lines().collect();
    let lhdr = learn_lines
        .iter()
        .position(|l| !l.starts_with('#'))
        .unwrap();
    let n_learn = learn_lines.len() - lhdr - 1;
    let mut gapped: Vec<String> = learn_lines.iter().map(|l| l.to_string()).collect();
    let mid = lhdr + n_learn / 2;
    let mut f: Vec<String> = gapped[mid].split(',').map(String::from).collect();
    f[mag_i] = String::new();
    gapped[mid] = f.join(",");
    let fit_share = |name: &str, lines: &[String], note: &str| -> (f64, usize) {
        let path = d.path().join(format!("{name}.csv"));
        std::fs::write(&path, lines.join("\n") + "\n").unwrap();
        let model = d.path().join(format!("{name}.json"));
        let o = aeromag(&[
            "rotor",
            "fit",
            "--input",
            path.to_str().unwrap(),
            "--model",
            model.to_str().unwrap(),
        ]);
        assert_code(&o, 0);
        assert!(stderr(&o).contains(note), "{}", stderr(&o));
        let m: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
        let out = d.path().join(format!("{name}_out.csv"));
        assert_code(&apply("rotor", &model, &other, &out), 0);
        (residual_share(&out), m["rows"].as_u64().unwrap() as usize)
    };
    let (share_dropout, rows) = fit_share(
        "dropout",
        &gapped,
        "1 rows with a missing value in a dropout",
    );
    assert_eq!(rows, n_learn);
    assert!(
        (share_dropout - share).abs() < 0.002,
        "{share_dropout} vs {share} without the dropout"
    );
    // A time gap (2000 rows missing): the parameters are refined on both
    // stretches (9.5 % left; the longer stretch alone left 10.9 %).
    let mut cut: Vec<String> = learn_lines.iter().map(|l| l.to_string()).collect();
    cut.drain(mid..mid + 2000);
    let (share_gap, rows) = fit_share("timegap", &cut, "refined on all 2 stretches");
    assert_eq!(rows, n_learn - 2000);
    eprintln!("fitted on two stretches: {:.2} % left", 100.0 * share_gap);
    assert!(share_gap <= 0.10, "{share_gap}");
    // Bad input: a cell that is not a number, a truth column as phase, a
    // model of another kind.
    let bad = d.path().join("bad.csv");
    std::fs::write(&bad, edit(77, "x1")).unwrap();
    let o = apply("rotor", &model, &bad, &out);
    assert_code(&o, 2);
    let e = stderr(&o);
    assert!(
        e.contains("bad.csv") && e.contains("mag") && e.contains("data row 77"),
        "{e}"
    );
    let o = aeromag(&[
        "rotor",
        "fit",
        "--input",
        learn.to_str().unwrap(),
        "--model",
        model.to_str().unwrap(),
        "--phase-column",
        "true_rotor_phase",
    ]);
    assert_code(&o, 2);
    std::fs::write(
        &bad,
        "{\"format\": \"aeromag-model/1\", \"kind\": \"towed-pod\"}",
    )
    .unwrap();
    let o = apply("rotor", &bad, &other, &out);
    assert_code(&o, 2);
}

#[test]
fn rotor_fit_without_a_phase_channel_estimates_the_phase() {
    let d = tempfile::tempdir().unwrap();
    let cfg = "[rotor]\nphase_channel = false\n";
    let learn = simulate_heli(d.path(), "a", "13", Some(cfg));
    let other = simulate_heli(d.path(), "b", "14", Some(cfg));
    let model = d.path().join("rotor.json");
    let o = aeromag(&[
        "rotor",
        "fit",
        "--input",
        learn.to_str().unwrap(),
        "--model",
        model.to_str().unwrap(),
        "--rotor-hz",
        "4.5,5.2",
    ]);
    assert_code(&o, 0);
    assert!(
        stdout(&o).contains("estimated from the data"),
        "{}",
        stdout(&o)
    );
    let out = d.path().join("out.csv");
    let o = apply("rotor", &model, &other, &out);
    assert_code(&o, 0);
    let share = residual_share(&out);
    eprintln!(
        "rotor model, phase estimated from the data, leaves {:.2} % of the rotor RMS on an independent flight",
        100.0 * share
    );
    assert!(share <= 0.10, "{share}");
}
