//! `aeromag demo --quick`: its summary (a rounded JSON snapshot), the
//! printed table built from the same figures, and the files it writes.

mod common;
use common::*;

/// `v` with every number rounded to 4 significant digits (the snapshot
/// holds the figures, not their last bits).
fn rounded(v: &serde_json::Value) -> serde_json::Value {
    use serde_json::Value;
    match v {
        Value::Number(n) => match n.as_f64() {
            Some(x) if n.is_f64() && x != 0.0 && x.is_finite() => {
                let digits = 3 - x.abs().log10().floor() as i32;
                let scale = 10f64.powi(digits);
                serde_json::json!((x * scale).round() / scale)
            }
            _ => v.clone(),
        },
        Value::Array(a) => Value::Array(a.iter().map(rounded).collect()),
        Value::Object(o) => Value::Object(o.iter().map(|(k, v)| (k.clone(), rounded(v))).collect()),
        _ => v.clone(),
    }
}

#[test]
fn quick_demo_summary_table_and_files() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("demo");
    let o = aeromag(&["demo", "--quick", "--out", out.to_str().unwrap()]);
    assert_code(&o, 0);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    insta::assert_snapshot!(
        "demo_quick_summary",
        serde_json::to_string_pretty(&rounded(&summary)).unwrap()
    );
    // The printed table: every figure it names is in the summary and none
    // is missing ("—").
    let text = stdout(&o);
    let rows: Vec<&str> = text
        .lines()
        .skip_while(|l| !l.starts_with("figure"))
        .skip(1)
        .take_while(|l| !l.starts_with("results in"))
        .collect();
    assert!(rows.len() >= 25, "{text}");
    for row in rows {
        assert!(!row.contains('—'), "{row}");
        // `group.key` (composite rows name the first of their keys).
        let key = row.split_whitespace().next().unwrap();
        let (group, name) = key.split_once('.').unwrap();
        let found = summary[group]
            .as_object()
            .is_some_and(|g| g.iter().any(|(k, v)| k.starts_with(name) && v.is_number()));
        assert!(found, "{key} not in summary.json");
    }
    for f in [
        "index.html",
        "model_ls.json",
        "model_kalman.json",
        "survey_comp.csv",
        "calibration_comp.csv",
    ] {
        assert!(out.join(f).exists(), "{f}");
    }
}

/// A seed whose survey seed (seed + 1) is no scenario seed is refused at
/// once, before minutes of work (2⁶⁴ − 1 wrapped the survey's to 0).
#[test]
fn a_seed_beyond_the_scenarios_is_refused_at_once() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("demo");
    for seed in ["18446744073709551615", "9223372036854775807"] {
        let start = std::time::Instant::now();
        let o = aeromag(&[
            "demo",
            "--quick",
            "--seed",
            seed,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_code(&o, 2);
        assert!(
            stderr(&o).contains("demo seed") && stderr(&o).contains("too large"),
            "{}",
            stderr(&o)
        );
        assert!(
            start.elapsed().as_secs_f64() < 10.0,
            "{:?}",
            start.elapsed()
        );
        assert!(!out.join("summary.json").exists());
    }
}

/// `demo` into an earlier run's folder replaced its files as the run went
/// (SIGTERM left the new data, models and compensated flights beside the
/// old summary, report and maps; a folder in the place of
/// maps/levelled.tif failed after 40 s with exit 1 and a mix). Now every
/// file is checked before the run (exit 2 at once, naming it, nothing
/// replaced) and the run's files replace the old ones together at the
/// end: an interruption before that leaves every old file and no staging
/// folder.
#[cfg(unix)]
#[test]
fn demo_replaces_an_earlier_run_whole_or_not_at_all() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("demo");
    let run = |seed: &str| aeromag(&["demo", "--quick", "--seed", seed, "--out", s(&out)]);
    assert_code(&run("1"), 0);
    let old = tree(&out);
    let mut expected = vec![
        "summary.json".to_string(),
        "index.html".into(),
        "model_ls.json".into(),
        "model_kalman.json".into(),
        "calibration_comp.csv".into(),
        "survey_comp.csv".into(),
    ];
    for dir in ["data", "data/gradient_area", "data/gradient_area_mild"] {
        for ext in ["csv", "toml", "truth.json"] {
            expected.push(format!("{dir}/calibration_truncated.{ext}"));
        }
    }
    for ext in ["csv", "toml", "truth.json"] {
        expected.push(format!("data/survey.{ext}"));
    }
    for map in [
        "uncompensated",
        "compensated",
        "levelled",
        "microlevelled",
        "truth",
        "levelled_minus_truth",
    ] {
        expected.push(format!("maps/{map}.tif"));
    }
    expected.sort();
    assert_eq!(old.keys().cloned().collect::<Vec<_>>(), expected);

    // A folder in the place of a file (the last map, a model), a file in
    // the place of a subfolder: exit 2 at once, naming it.
    let aside = d.path().join("aside");
    for (name, folder) in [
        ("maps/levelled.tif", true),
        ("model_ls.json", true),
        ("data", false),
    ] {
        let p = out.join(name);
        std::fs::rename(&p, &aside).unwrap();
        if folder {
            std::fs::create_dir(&p).unwrap();
        } else {
            std::fs::write(&p, "x").unwrap();
        }
        let start = std::time::Instant::now();
        let o = run("3");
        assert_code(&o, 2);
        assert!(stderr(&o).contains(name), "{name}: {}", stderr(&o));
        assert!(
            start.elapsed().as_secs_f64() < 10.0,
            "{:?}",
            start.elapsed()
        );
        if folder {
            std::fs::remove_dir(&p).unwrap();
        } else {
            std::fs::remove_file(&p).unwrap();
        }
        std::fs::rename(&aside, &p).unwrap();
        assert!(tree(&out) == old, "{name}: files changed");
    }

    // SIGTERM once the run has written its models (to its staging folder).
    let child = std::process::Command::new(env!("CARGO_BIN_EXE_aeromag"))
        .args(["demo", "--quick", "--seed", "2", "--out", s(&out)])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let staged_models = || {
        std::fs::read_dir(&out).unwrap().flatten().any(|e| {
            e.file_name()
                .to_string_lossy()
                .starts_with(".aeromag-staging")
                && e.path().join("model_ls.json").exists()
        })
    };
    let start = std::time::Instant::now();
    while !staged_models() {
        assert!(start.elapsed().as_secs() < 300, "no staged model");
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    // SAFETY: sending a signal to our own child process.
    unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGTERM) };
    let o = child.wait_with_output().unwrap();
    assert_code(&o, 143);
    assert!(
        tree(&out) == old,
        "files changed or left: {:?}",
        tree(&out).keys()
    );
}

fn s(p: &std::path::Path) -> &str {
    p.to_str().unwrap()
}
