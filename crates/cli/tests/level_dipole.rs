//! `aeromag level` and `aeromag dipole convergence` as commands: arguments,
//! exit codes, files, messages (the figures are tested in the library).

mod common;
use common::*;

#[test]
fn level_keeps_every_row_and_reports_k() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("s");
    assert_code(
        &aeromag(&[
            "simulate",
            "survey",
            "--seed",
            "4",
            "--out",
            out.to_str().unwrap(),
        ]),
        0,
    );
    let input = out.join("survey.csv");
    let lev = d.path().join("lev.csv");
    let o = aeromag(&[
        "level",
        "--input",
        input.to_str().unwrap(),
        "--out",
        lev.to_str().unwrap(),
        "--lever-arm",
        "-9.5,0,-0.6",
        "--drift",
    ]);
    assert_code(&o, 0);
    let s = stdout(&o);
    assert!(
        s.contains("crossovers") && s.contains("k (d|B0|/dt term)"),
        "{s}"
    );
    let rows = |p: &std::path::Path| {
        std::fs::read_to_string(p)
            .unwrap()
            .lines()
            .filter(|l| !l.starts_with('#'))
            .count()
    };
    assert_eq!(rows(&input), rows(&lev), "one output row per input row");
    let header = std::fs::read_to_string(&lev)
        .unwrap()
        .lines()
        .find(|l| !l.starts_with('#'))
        .unwrap()
        .to_string();
    assert!(header.contains("mag_level") && header.contains("level_flag"));
    let bad = aeromag(&[
        "level",
        "--input",
        input.to_str().unwrap(),
        "--out",
        lev.to_str().unwrap(),
        "--lever-arm",
        "1,2",
    ]);
    assert_code(&bad, 2);
    let bad = aeromag(&[
        "level",
        "--input",
        input.to_str().unwrap(),
        "--out",
        lev.to_str().unwrap(),
        "--reference",
        "nosuch",
    ]);
    assert_code(&bad, 2);
}

/// The options of `level`, as the command prints them (what the fit finds
/// is tested in the library): the reduction, the regressor, the altitude
/// term, the robust weights and the crossover table.
#[test]
fn level_options_and_crossover_table() {
    let d = tempfile::tempdir().unwrap();
    let dir = |n: &str| d.path().join(n);
    assert_code(
        &aeromag(&[
            "simulate",
            "survey",
            "--seed",
            "2",
            "--out",
            dir("s").to_str().unwrap(),
        ]),
        0,
    );
    let survey = dir("s").join("survey.csv");
    let lev = dir("lev.csv");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "level",
            "--input",
            survey.to_str().unwrap(),
            "--out",
            lev.to_str().unwrap(),
            "--lever-arm",
            "-9.5,0,-0.6",
            "--reference",
            "auto",
        ];
        args.extend_from_slice(extra);
        let o = aeromag(&args);
        assert_code(&o, 0);
        stdout(&o)
    };
    let xs = dir("x.csv");
    let s = run(&["--crossovers", xs.to_str().unwrap()]);
    for line in [
        "levelling mag − diurnal − igrf",
        "along-track derivative of `mag`",
        "k (d|B0|/dt term) = ",
        "altitude term: vertical-gradient scale c =",
        "robust weighting:",
        "crossover table written to",
    ] {
        assert!(s.contains(line), "{line}\n{s}");
    }
    let table = std::fs::read_to_string(&xs).unwrap();
    let mut lines = table.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    for c in ["line_a", "line_b", "difference_nt", "residual_nt", "weight"] {
        assert!(header.contains(&c), "{header:?}");
    }
    assert_eq!(lines.count(), 100, "20 lines × 5 ties");
    let sp = run(&["--no-robust", "--no-altitude-term", "--rate-of", "mag"]);
    assert!(
        !sp.contains("robust weighting:") && !sp.contains("altitude term:"),
        "{sp}"
    );
    let st = run(&["--tie-only"]);
    assert!(!st.contains("k (d|B0|/dt term)"), "{st}");
}

#[test]
fn dipole_convergence_map_multistart_converges_everywhere() {
    let d = tempfile::tempdir().unwrap();
    let o = aeromag(&[
        "dipole",
        "convergence",
        "--grid",
        "9",
        "--out",
        d.path().to_str().unwrap(),
    ]);
    assert_code(&o, 0);
    let s = stdout(&o);
    assert!(s.lines().any(|l| l.starts_with("multi-start")), "{s}");
    assert!(s.lines().any(|l| l.starts_with("plain IEKF")), "{s}");
    assert!(
        std::fs::read_to_string(d.path().join("index.html"))
            .unwrap()
            .contains("<svg")
    );
    assert_code(
        &aeromag(&[
            "dipole",
            "convergence",
            "--grid",
            "1",
            "--out",
            d.path().to_str().unwrap(),
        ]),
        2,
    );
}
