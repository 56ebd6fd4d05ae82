//! `aeromag simulate pod`, `aeromag pod fit` and `aeromag pod apply` end to
//! end (spec `helicopter.md` part B, issue 5): learn on the seed's headings,
//! compensate the independent heading set of another flight, score against
//! the simulator's truth columns (the commands never read them).

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

fn rms(x: &[f64]) -> f64 {
    (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt()
}

/// Seed-style rate per heading (`line`): `1 − RMS(detrend(mag − true_external
/// − pod_interf)) / RMS(detrend(mag))`, and the same pooled over all rows.
fn rates(out: &Path) -> (Vec<f64>, f64) {
    use aeromag_compensation::pod::detrend;
    let (h, rows) = read_csv(out);
    let (mag, ext, pred, line) = (
        column(&h, &rows, "mag"),
        column(&h, &rows, "true_external"),
        column(&h, &rows, "pod_interf"),
        column(&h, &rows, "line"),
    );
    let sum_sq = |x: &[f64]| x.iter().map(|v| v * v).sum::<f64>();
    let (mut r, mut pooled_before, mut pooled_after) = (Vec::new(), 0.0, 0.0);
    let mut start = 0;
    for k in 1..=line.len() {
        if k == line.len() || line[k] != line[start] {
            let before = detrend(&mag[start..k]);
            let after: Vec<f64> = (start..k).map(|j| mag[j] - ext[j] - pred[j]).collect();
            let after = detrend(&after);
            r.push(1.0 - rms(&after) / rms(&before));
            pooled_before += sum_sq(&before);
            pooled_after += sum_sq(&after);
            start = k;
        }
    }
    (r, 1.0 - (pooled_after / pooled_before).sqrt())
}

const SETUP: [&str; 10] = [
    "--cable-length-m",
    "40",
    "--attach-m",
    "0,0,1.2",
    "--inclination-deg",
    "45",
    "--grad-north-nt-per-km",
    "5.91",
    "--grad-up-nt-per-km",
    "-25.91",
];

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

fn fit_apply(d: &Path, learn: &Path, test: &Path, method: &str) -> std::path::PathBuf {
    fit_apply_with(d, learn, test, method, &SETUP)
}

fn fit_apply_with(
    d: &Path,
    learn: &Path,
    test: &Path,
    method: &str,
    setup: &[&str],
) -> std::path::PathBuf {
    let model = d.join(format!("{method}.json"));
    let mut args = vec![
        "pod",
        "fit",
        "--input",
        learn.to_str().unwrap(),
        "--model",
        model.to_str().unwrap(),
        "--method",
        method,
    ];
    args.extend(setup);
    assert_code(&aeromag(&args), 0);
    let out = d.join(format!("{method}.csv"));
    let o = apply("pod", &model, &test, &out);
    assert_code(&o, 0);
    out
}

#[test]
fn seed_solve_reaches_90_percent_on_the_set_dipole_array_and_joint_97_percent_on_every_heading() {
    let d = tempfile::tempdir().unwrap();
    let (learn, test) = simulate_pair(d.path());
    let text = std::fs::read_to_string(&learn).unwrap();
    let header = text.lines().find(|l| !l.starts_with('#')).unwrap();
    assert!(
        header.contains("cable_inclination")
            && header.contains("cable_azimuth")
            && header.contains("true_interf")
    );
    let da = fit_apply(d.path(), &learn, &test, "dipole-array");
    let two = fit_apply(d.path(), &learn, &test, "two-step");
    let joint = fit_apply(d.path(), &learn, &test, "joint");
    let ((rd, pd), (rt, pt), (rj, pj)) = (rates(&da), rates(&two), rates(&joint));
    eprintln!(
        "dipole array per test heading {rd:?} pooled {pd}\ntwo-step per test heading {rt:?} \
         pooled {pt}\njoint per test heading {rj:?} pooled {pj}"
    );
    // The seed's solve: its "above 90 %" on the independent set as a whole.
    assert!(pt >= 0.90, "two-step pooled {pt}");
    assert_eq!(rd.len(), 8);
    assert!(rd.iter().all(|r| *r >= 0.97), "dipole array {rd:?}");
    assert!(rj.iter().all(|r| *r >= 0.97), "joint {rj:?}");
    assert!(rd.iter().zip(&rt).all(|(a, b)| a > b), "{rd:?} vs {rt:?}");
    // One output row per input row, the new columns present.
    let (h, rows) = read_csv(&da);
    let (_, input_rows) = read_csv(&test);
    assert_eq!(rows.len(), input_rows.len());
    for c in ["pod_interf", "mag_comp", "pod_flag"] {
        assert!(h.iter().any(|x| x == c), "{c}");
    }
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
    args.extend(SETUP);
    assert_code(&aeromag(&args), 0);
    // Blank two `mag` cells of the test file: rows kept, flagged.
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
    let (h, rows) = read_csv(&out);
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
        "{\"format\": \"aeromag-model/1\", \"kind\": \"tolles-lawson\"}",
    )
    .unwrap();
    let o = apply("pod", &bad, &test, &out);
    assert_code(&o, 2);
}

/// Another installation and other headings than the seed's: a 30 m cable at
/// 65°, the attachment 1 m forward and 0.3 m right, inclination 60°, the
/// wind-driven (random) swing, tested on headings 15, 105, …, 330°.
#[test]
fn other_geometry_and_headings() {
    let d = tempfile::tempdir().unwrap();
    let toml = "cable_m = 30.0\ncable_inclination_deg = 65.0\nattach_m = [1.0, 0.3, 1.5]\n\
                inclination_deg = 60.0\n";
    let (learn, test) = simulate_pair_with(
        d.path(),
        toml,
        "[15.0, 105.0, 195.0, 285.0, 60.0, 150.0, 240.0, 330.0]",
    );
    let setup = [
        "--cable-length-m",
        "30",
        "--attach-m",
        "1.0,0.3,1.5",
        "--inclination-deg",
        "60",
        "--grad-north-nt-per-km",
        "5.91",
        "--grad-up-nt-per-km",
        "-25.91",
    ];
    let mut all = Vec::new();
    for method in ["dipole-array", "joint", "two-step"] {
        let out = fit_apply_with(d.path(), &learn, &test, method, &setup);
        let (r, pooled) = rates(&out);
        eprintln!("{method}: per heading {r:?} pooled {pooled:.4}");
        all.push((r, pooled));
    }
    let (da, joint, two) = (&all[0], &all[1], &all[2]);
    assert!(da.0.iter().all(|r| *r >= 0.97), "dipole array {:?}", da.0);
    assert!(joint.1 >= 0.97, "joint pooled {}", joint.1);
    assert!(two.1 >= 0.90, "two-step pooled {}", two.1);
}
