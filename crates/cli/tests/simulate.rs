//! `aeromag simulate`: files, columns, truth, physics, determinism.

mod common;
use common::*;
use std::collections::BTreeMap;
use std::path::Path;

fn read_csv(p: &Path) -> BTreeMap<String, Vec<f64>> {
    let text = std::fs::read_to_string(p).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    let mut cols: Vec<Vec<f64>> = vec![Vec::new(); header.len()];
    for l in lines {
        for (k, v) in l.split(',').enumerate() {
            cols[k].push(v.parse().unwrap_or(f64::NAN));
        }
    }
    header.into_iter().zip(cols).collect()
}

#[test]
fn calibration_files_columns_and_physics() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("cal");
    let o = aeromag(&[
        "simulate",
        "calibration",
        "--seed",
        "3",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_code(&o, 0);
    for f in [
        "calibration.csv",
        "calibration.toml",
        "calibration.truth.json",
    ] {
        assert!(out.join(f).exists(), "{f}");
    }
    let c = read_csv(&out.join("calibration.csv"));
    for k in [
        "time",
        "lat",
        "lon",
        "alt",
        "roll",
        "pitch",
        "yaw",
        "mag",
        "flux_x",
        "flux_y",
        "flux_z",
        "line",
        "diurnal",
        "igrf",
        "true_external",
        "true_interf",
    ] {
        assert!(c.contains_key(k), "column {k}");
    }
    let n = c["time"].len();
    assert!(n > 3000, "{n} rows");
    // 10 Hz, strictly increasing.
    assert!(
        c["time"]
            .windows(2)
            .all(|w| (w[1] - w[0] - 0.1).abs() < 1e-6)
    );
    // Units: nT magnitudes of the Earth's field.
    assert!(c["mag"].iter().all(|v| (20_000.0..70_000.0).contains(v)));
    // mag = external + interference + small sensor terms.
    let worst = (0..n)
        .map(|i| (c["mag"][i] - c["true_external"][i] - c["true_interf"][i]).abs())
        .fold(0.0, f64::max);
    assert!(
        worst < 0.5,
        "mag − (external + interference) up to {worst} nT"
    );
    // The interference depends on heading like an aircraft's: the per-leg
    // means differ by more than a nanotesla between headings…
    let mut means = Vec::new();
    for leg in 1..=4 {
        let v: Vec<f64> = (0..n)
            .filter(|&i| c["line"][i] == leg as f64)
            .map(|i| c["true_interf"][i])
            .collect();
        assert!(!v.is_empty(), "leg {leg}");
        means.push(v.iter().sum::<f64>() / v.len() as f64);
    }
    let spread = means.iter().cloned().fold(f64::MIN, f64::max)
        - means.iter().cloned().fold(f64::MAX, f64::min);
    assert!(spread > 1.0, "heading dependence {spread} nT: {means:?}");
    // …and swings within the roll manoeuvres far above the sensor noise.
    let roll: Vec<usize> = (0..n)
        .filter(|&i| c["manoeuvre"][i] == 1.0 && c["line"][i] == 1.0)
        .collect();
    let v: Vec<f64> = roll.iter().map(|&i| c["true_interf"][i]).collect();
    let pp =
        v.iter().cloned().fold(f64::MIN, f64::max) - v.iter().cloned().fold(f64::MAX, f64::min);
    assert!(
        pp > 0.5,
        "interference peak-to-peak in roll manoeuvres {pp} nT"
    );
}

#[test]
fn same_seed_same_bytes_other_seed_other_data() {
    let d = tempfile::tempdir().unwrap();
    let run = |seed: &str, sub: &str| {
        let out = d.path().join(sub);
        assert_code(
            &aeromag(&[
                "simulate",
                "calibration-truncated",
                "--seed",
                seed,
                "--out",
                out.to_str().unwrap(),
            ]),
            0,
        );
        std::fs::read(out.join("calibration_truncated.csv")).unwrap()
    };
    let a = run("11", "a");
    let b = run("11", "b");
    let c = run("12", "c");
    assert!(a == b, "same seed must give identical bytes");
    assert!(a != c);
}

#[test]
fn scenario_files_round_trip_and_typos_are_errors() {
    let d = tempfile::tempdir().unwrap();
    let o = aeromag(&["simulate", "survey", "--print-config"]);
    assert_code(&o, 0);
    let toml = stdout(&o);
    let p = d.path().join("s.toml");
    std::fs::write(&p, &toml).unwrap();
    let out = d.path().join("s");
    assert_code(
        &aeromag(&[
            "simulate",
            "survey",
            "--config",
            p.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]),
        0,
    );
    let bad = d.path().join("bad.toml");
    std::fs::write(&bad, "[flight]\nsample_rate_hzz = 10\n").unwrap();
    let o = aeromag(&[
        "simulate",
        "survey",
        "--config",
        bad.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_code(&o, 2);
    assert!(stderr(&o).contains("sample_rate_hzz"), "{}", stderr(&o));
    // A flight the readers would refuse (a sensor lag of 10⁹ s: `mag` of
    // 5.4·10⁸ nT) is bad input naming the scenario file; nothing written.
    let lag = d.path().join("lag.toml");
    std::fs::write(&lag, "[pattern]\ncycles = 1\n[scalar]\nlag_s = 1e9\n").unwrap();
    let lag_out = d.path().join("lag");
    let o = aeromag(&[
        "simulate",
        "calibration",
        "--config",
        lag.to_str().unwrap(),
        "--out",
        lag_out.to_str().unwrap(),
    ]);
    assert_code(&o, 2);
    assert!(
        stderr(&o).contains("lag.toml") && stderr(&o).contains("readers would refuse"),
        "{}",
        stderr(&o)
    );
    // Not even its folder (an empty folder was left behind).
    assert!(!lag_out.exists());
    assert_code(
        &aeromag(&["simulate", "spaceship", "--out", out.to_str().unwrap()]),
        2,
    );
}

/// An --out that is not a folder failed after the simulation with exit 1
/// ("File exists"); a seed of 2⁶⁴ − 1 for `em` wrote an em.toml that
/// --config then refused (the other scenarios refuse it).
#[test]
fn an_out_that_is_no_folder_and_an_unwritable_seed_are_bad_input() {
    let d = tempfile::tempdir().unwrap();
    let file = d.path().join("f.txt");
    std::fs::write(&file, "x").unwrap();
    for scenario in ["pod", "em", "gradiometer"] {
        let o = aeromag(&["simulate", scenario, "--out", file.to_str().unwrap()]);
        assert_code(&o, 2);
        assert!(stderr(&o).contains("f.txt"), "{scenario}: {}", stderr(&o));
    }
    let out = d.path().join("em");
    let o = aeromag(&[
        "simulate",
        "em",
        "--seed",
        "18446744073709551615",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_code(&o, 2);
    assert!(stderr(&o).contains("must be < 2^63"), "{}", stderr(&o));
    assert!(!out.join("em.toml").exists());
}

/// A folder in the place of the truth file: nothing is written (the flight
/// and scenario of the new seed were written beside the old truth), and
/// it is bad input, found before the simulation (exit 2; it was 1).
#[test]
fn a_run_that_cannot_write_every_file_writes_none() {
    let d = tempfile::tempdir().unwrap();
    for scenario in ["pod", "calibration"] {
        let out = d.path().join(scenario);
        let o = aeromag(&["simulate", scenario, "--out", out.to_str().unwrap()]);
        assert_code(&o, 0);
        let truth = out.join(format!("{scenario}.truth.json"));
        std::fs::remove_file(&truth).unwrap();
        std::fs::create_dir(&truth).unwrap();
        let old = tree(&out);
        let o = aeromag(&[
            "simulate",
            scenario,
            "--seed",
            "9",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_code(&o, 2);
        assert!(
            stderr(&o).contains(&format!("{scenario}.truth.json")),
            "{}",
            stderr(&o)
        );
        assert!(tree(&out) == old, "{scenario}: files changed");
    }
}
