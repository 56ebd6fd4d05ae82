//! `aeromag microlevel` on extreme flags: refused quickly and named
//! shortly, or printed shortly when taken.

mod common;
use common::*;

/// A small survey: 6 lines 3 km long, 500 m apart, 2 ties, 2 Hz.
fn small_survey(dir: &std::path::Path) -> std::path::PathBuf {
    let config = dir.join("small.toml");
    std::fs::write(
        &config,
        "[flight]\nsample_rate_hz = 2.0\n[pattern]\nline_count = 6\nline_length_m = 3000.0\ntie_count = 2\ntie_spacing_m = 1500.0\n",
    )
    .unwrap();
    simulate_with(dir, "survey", "1", Some(&config))
}

/// `aeromag microlevel` of the `mag` column of `input` into `out`, with
/// `extra` flags.
fn microlevel_mag(
    input: &std::path::Path,
    out: &std::path::Path,
    extra: &[&str],
) -> std::process::Output {
    let mut a = vec![
        "microlevel",
        "-i",
        input.to_str().unwrap(),
        "--column",
        "mag",
        "--out",
        out.to_str().unwrap(),
    ];
    a.extend(extra);
    aeromag(&a)
}

/// `--cell 1` on a survey 500 m between lines ran for more than a minute
/// (minimum curvature on 10⁷ nodes); `--cutoff 1e308` was refused by the
/// filter as "got inf"; `--along-line 1e308` was printed with 309 digits.
#[test]
fn extreme_cell_cutoff_and_along_line() {
    let d = tempfile::tempdir().unwrap();
    let input = small_survey(d.path());
    let out = d.path().join("ml.csv");
    let run = |extra: &[&str]| microlevel_mag(&input, &out, extra);
    let t0 = std::time::Instant::now();
    let o = run(&["--cell", "1"]);
    assert_code(&o, 2);
    let e = stderr(&o);
    assert!(
        e.contains("cell 1 m is finer") && e.contains("at least 10.0 m"),
        "{e}"
    );
    assert!(t0.elapsed().as_secs() < 20, "{:?}", t0.elapsed());
    let o = run(&["--cutoff", "1e308"]);
    assert_code(&o, 2);
    let e = stderr(&o);
    assert!(
        e.contains("cut-off 1e308 line spacings") && !e.contains("inf"),
        "{e}"
    );
    let o = run(&["--along-line", "1e308"]);
    assert_code(&o, 0);
    let s = stdout(&o);
    assert!(
        s.contains("over 1e308 m") && s.lines().all(|l| l.len() < 200),
        "{s}"
    );
}

/// `--cutoff 1e-300` (or 1) gave a correction of zero with exit 0: the
/// high-pass then passes none of the stripes between lines. The working
/// grid's minimum curvature has `grid`'s limits (`--max-sweeps`,
/// `--convergence`), which its warning named while microlevel had none,
/// and its convergence is printed.
#[test]
fn short_cutoff_refused_and_gridding_limits_taken() {
    let d = tempfile::tempdir().unwrap();
    let input = small_survey(d.path());
    let out = d.path().join("ml.csv");
    let run = |extra: &[&str]| microlevel_mag(&input, &out, extra);
    for cutoff in ["1e-300", "1", "1.99"] {
        let o = run(&["--cutoff", cutoff]);
        assert_code(&o, 2);
        let e = stderr(&o);
        assert!(
            e.contains(&format!("cut-off {cutoff} line spacings is below 2")),
            "{e}"
        );
        assert!(!out.exists());
    }
    let o = run(&["--max-sweeps", "10"]);
    assert_code(&o, 0);
    let (s, e) = (stdout(&o), stderr(&o));
    // Each of the final grid's two relaxations stops at 10 sweeps.
    assert!(
        s.contains("20 sweeps on the final grid, NOT converged"),
        "{s}"
    );
    assert!(
        e.contains("--max-sweeps") && e.contains("--convergence"),
        "{e}"
    );
    let o = run(&["--max-sweeps", "5000", "--cutoff", "2"]);
    assert_code(&o, 0);
    let (s, e) = (stdout(&o), stderr(&o));
    assert!(s.contains("sweeps on the final grid, converged"), "{s}");
    assert!(!e.contains("--max-sweeps"), "{e}");
    let o = run(&["--max-sweeps", "0"]);
    assert_code(&o, 2);
    assert!(stderr(&o).contains("max sweeps"), "{}", stderr(&o));
}
