//! `aeromag simulate pod`, `aeromag pod fit` and `aeromag pod apply` as
//! commands: files, rows kept and flagged, messages and exit codes (the
//! compensation rates are tested in the library, crates/aeromag/tests/pod.rs).

mod common;
use common::*;
use std::path::Path;

/// Rows of a CSV written by aeromag: header and values (text).
fn read_csv(p: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(p).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    (
        header,
        lines
            .map(|l| l.split(',').map(String::from).collect())
            .collect(),
    )
}

fn column(h: &[String], rows: &[Vec<String>], name: &str) -> Vec<f64> {
    let i = h
        .iter()
        .position(|c| c == name)
        .unwrap_or_else(|| panic!("no column {name}"));
    rows.iter()
        .map(|r| r[i].parse().unwrap_or(f64::NAN))
        .collect()
}

/// The seed's stated conditions (swing a 5° sinusoid): a learning flight on
/// the seed's headings (sim seed 1) and the independent heading set (1001).
fn simulate_pair(d: &Path) -> (std::path::PathBuf, std::path::PathBuf) {
    simulate_pair_with(
        d,
        "swing_sine = true\n",
        "[30.0, 120.0, 210.0, 300.0, 70.0, 160.0, 250.0, 340.0]",
    )
}

/// A learning flight (sim seed 1) and a test flight on `test_headings`
/// (seed 1001), both with the scenario lines `toml`.
fn simulate_pair_with(
    d: &Path,
    toml: &str,
    test_headings: &str,
) -> (std::path::PathBuf, std::path::PathBuf) {
    let learn = d.join("learn");
    let learn_cfg = d.join("learn.toml");
    std::fs::write(&learn_cfg, toml).unwrap();
    assert_code(
        &aeromag(&[
            "simulate",
            "pod",
            "--config",
            learn_cfg.to_str().unwrap(),
            "--out",
            learn.to_str().unwrap(),
        ]),
        0,
    );
    let cfg = d.join("test.toml");
    std::fs::write(&cfg, format!("{toml}headings_deg = {test_headings}\n")).unwrap();
    let test = d.join("test");
    assert_code(
        &aeromag(&[
            "simulate",
            "pod",
            "--seed",
            "1001",
            "--config",
            cfg.to_str().unwrap(),
            "--out",
            test.to_str().unwrap(),
        ]),
        0,
    );
    (learn.join("pod.csv"), test.join("pod.csv"))
}

#[test]
fn missing_values_are_kept_and_flagged_and_bad_input_exits_2() {
    let d = tempfile::tempdir().unwrap();
    let (learn, test) = simulate_pair(d.path());
    let model = d.path().join("m.json");
    let mut args = vec![
        "pod",
        "fit",
        "--input",
        learn.to_str().unwrap(),
        "--model",
        model.to_str().unwrap(),
    ];
    args.extend(POD_SETUP);
    let o = aeromag(&args);
    assert_code(&o, 0);
    assert!(stdout(&o).contains("learning heading"), "{}", stdout(&o));
    // A source point at 1e300 m ran the fit until killed (the SVD never
    // returned on NaN); a declination of 1e300° was taken.
    for (extra, needle) in [
        (["--source-points", "1e300,0,0"], "source point"),
        (["--declination-deg", "1e300"], "declination"),
    ] {
        let mut bad_args = args.clone();
        bad_args.extend(extra);
        let o = aeromag(&bad_args);
        assert_code(&o, 2);
        assert!(stderr(&o).contains(needle), "{}", stderr(&o));
    }
    // Blank a `mag` cell of the test file: rows kept, flagged.
    let text = std::fs::read_to_string(&test).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let hdr = lines.iter().position(|l| !l.starts_with('#')).unwrap();
    let cols: Vec<&str> = lines[hdr].split(',').collect();
    let edit = |row: usize, col: &str, value: &str| -> String {
        let ci = cols.iter().position(|c| *c == col).unwrap();
        let mut out: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
        let mut f: Vec<String> = out[hdr + row].split(',').map(String::from).collect();
        f[ci] = value.into();
        out[hdr + row] = f.join(",");
        out.join("\n") + "\n"
    };
    let gap = d.path().join("gap.csv");
    std::fs::write(&gap, edit(500, "mag", "")).unwrap();
    let out = d.path().join("out.csv");
    let o = apply("pod", &model, &gap, &out);
    assert_code(&o, 0);
    assert!(stdout(&o).contains("all headings pooled"), "{}", stdout(&o));
    assert!(stderr(&o).contains("pod_flag = 1"), "{}", stderr(&o));
    let (h, rows) = read_csv(&out);
    for c in ["pod_interf", "mag_comp", "pod_flag"] {
        assert!(h.iter().any(|x| x == c), "{c}");
    }
    assert_eq!(rows.len(), lines.len() - hdr - 1);
    let flag = column(&h, &rows, "pod_flag");
    assert_eq!(flag[499], 1.0);
    assert_eq!(flag[0], 0.0);
    assert!(column(&h, &rows, "mag_comp")[499].is_nan());
    // A cell that is not a number: exit 2 naming file, row and column.
    let bad = d.path().join("bad.csv");
    std::fs::write(&bad, edit(7, "cable_azimuth", "north")).unwrap();
    let o = apply("pod", &model, &bad, &out);
    assert_code(&o, 2);
    let e = stderr(&o);
    assert!(
        e.contains("bad.csv") && e.contains("cable_azimuth") && e.contains("data row 7"),
        "{e}"
    );
    // A cable inclination outside (0, 90)°: exit 2 naming file, row and column.
    std::fs::write(&bad, edit(12, "cable_inclination", "95")).unwrap();
    let o = apply("pod", &model, &bad, &out);
    assert_code(&o, 2);
    let e = stderr(&o);
    assert!(
        e.contains("bad.csv") && e.contains("cable_inclination") && e.contains("data row 12"),
        "{e}"
    );
    // A model file of another kind.
    std::fs::write(
        &bad,
        "{\"format\": \"aeromag-model/2\", \"kind\": \"tolles-lawson\"}",
    )
    .unwrap();
    let o = apply("pod", &bad, &test, &out);
    assert_code(&o, 2);
}
