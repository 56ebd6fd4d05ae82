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
