//! The same bytes whatever the number of threads (`AEROMAG_THREADS`).
//!
//! The reader's pieces, the fit's blocks and the eddy-lag search, the
//! Kalman tuning's runs, the writer's chunks, the levelling, gridding and
//! micro-levelling loops and the EM detection's channels and windows are
//! shared out differently with 1, 2, 3 and 7 threads; every file written
//! and every line printed must be the same.

mod common;
use common::*;
use std::path::Path;
use std::process::{Command, Output};

/// `aeromag ARGS` in `dir` with `AEROMAG_THREADS=threads`.
fn with_threads(dir: &Path, threads: &str, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_aeromag"))
        .current_dir(dir)
        .env("AEROMAG_THREADS", threads)
        .args(args)
        .output()
        .expect("spawn aeromag")
}

/// A calibration box sampled at 100 Hz: one segment of about 60 000 rows
/// with `--no-split-lines`, two of the fit's blocks.
fn calibration_at_100_hz(dir: &Path) -> std::path::PathBuf {
    let o = aeromag(&["simulate", "calibration", "--print-config"]);
    assert_code(&o, 0);
    let config = stdout(&o).replace("sample_rate_hz = 10.0", "sample_rate_hz = 100.0");
    assert!(config.contains("sample_rate_hz = 100.0"), "{config}");
    let path = dir.join("c100.toml");
    std::fs::write(&path, config).unwrap();
    let sub = dir.join("c100");
    std::fs::create_dir_all(&sub).unwrap();
    simulate_with(&sub, "calibration", "3", Some(&path))
}

#[test]
fn every_output_is_the_same_with_1_2_3_and_7_threads() {
    let d = tempfile::tempdir().unwrap();
    let cal100 = calibration_at_100_hz(d.path());
    let cal10 = simulate(d.path(), "calibration", "4");
    let survey = simulate(d.path(), "survey", "2");
    let em = d.path().join("em");
    assert_code(
        &aeromag(&["em", "simulate", "--out", em.to_str().unwrap()]),
        0,
    );
    let raw = em.join("em.raw");
    let (cal100, cal10, survey, raw) = (
        cal100.to_str().unwrap(),
        cal10.to_str().unwrap(),
        survey.to_str().unwrap(),
        raw.to_str().unwrap(),
    );
    let steps: [&[&str]; 7] = [
        &[
            "calibrate",
            "--input",
            cal100,
            "--model",
            "m.json",
            "--no-split-lines",
            "--compensated",
            "c.csv",
        ],
        &[
            "calibrate",
            "--input",
            cal10,
            "--model",
            "k.json",
            "--method",
            "kalman",
        ],
        &[
            "compensate",
            "--model",
            "m.json",
            "--input",
            survey,
            "--out",
            "s.csv",
        ],
        &["level", "--input", "s.csv", "--out", "lev.csv"],
        &["grid", "--input", "lev.csv", "--out", "g.asc"],
        &["microlevel", "--input", "lev.csv", "--out", "ml.csv"],
        &["em", "detect", "--input", raw, "--out", "det.csv"],
    ];
    let files = [
        "m.json", "c.csv", "k.json", "s.csv", "lev.csv", "g.asc", "ml.csv", "det.csv",
    ];
    // What each run printed and wrote, per number of threads.
    let run = |threads: &str| -> Vec<(String, Vec<u8>)> {
        let dir = d.path().join(format!("threads-{threads}"));
        std::fs::create_dir_all(&dir).unwrap();
        let mut seen = Vec::new();
        for args in steps {
            let o = with_threads(&dir, threads, args);
            assert_code(&o, 0);
            seen.push((format!("{} stdout", args[0]), o.stdout));
            seen.push((format!("{} stderr", args[0]), o.stderr));
        }
        for f in files {
            seen.push((f.to_string(), std::fs::read(dir.join(f)).unwrap()));
        }
        seen
    };
    let one = run("1");
    // The flight is long enough for two of the fit's blocks of 2¹⁵ rows
    // (and many reading pieces).
    let rows = one.iter().find(|(w, _)| w == "c.csv").unwrap().1.iter();
    assert!(rows.filter(|&&b| b == b'\n').count() > 1 << 15);
    for threads in ["2", "3", "7"] {
        for ((what, a), (_, b)) in one.iter().zip(run(threads)) {
            assert!(
                *a == b,
                "{what} differs with {threads} threads from one thread"
            );
        }
    }
    // A number of threads the program refuses is bad input.
    let o = with_threads(d.path(), "0", &["inspect", "--input", cal10]);
    assert_code(&o, 2);
    assert!(stderr(&o).contains("AEROMAG_THREADS"), "{}", stderr(&o));
}
