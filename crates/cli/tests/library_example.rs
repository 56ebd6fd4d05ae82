//! The library example `calibrate_kalman` reproduces `aeromag calibrate
//! --method kalman` + `aeromag compensate` byte for byte.

mod common;
use common::*;

#[path = "../../aeromag/examples/calibrate_kalman.rs"]
mod example;

#[test]
fn the_library_example_writes_the_same_files_as_the_command() {
    let d = tempfile::tempdir().unwrap();
    let p = |n: &str| d.path().join(n);
    let s = |p: &std::path::Path| p.to_str().unwrap().to_string();
    for (scenario, seed) in [("calibration-truncated", "3"), ("survey", "4")] {
        let o = aeromag(&[
            "simulate",
            scenario,
            "--seed",
            seed,
            "--out",
            &s(&p(scenario)),
        ]);
        assert_code(&o, 0);
    }
    let cal = p("calibration-truncated").join("calibration_truncated.csv");
    let survey = p("survey").join("survey.csv");
    let o = aeromag(&[
        "calibrate",
        "--input",
        &s(&cal),
        "--model",
        &s(&p("cli.json")),
        "--method",
        "kalman",
    ]);
    assert_code(&o, 0);
    assert_code(&compensate(&p("cli.json"), &survey, &p("cli.csv")), 0);
    example::calibrate_and_compensate(&cal, &survey, &p("lib.json"), &p("lib.csv")).unwrap();
    let bytes = |n: &str| std::fs::read(p(n)).unwrap();
    assert!(bytes("cli.json") == bytes("lib.json"), "model files differ");
    assert!(
        bytes("cli.csv") == bytes("lib.csv"),
        "compensated tables differ"
    );
}
