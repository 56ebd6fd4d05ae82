//! `aeromag igrf` end to end.

mod common;
use common::*;

#[test]
fn json_output_has_the_documented_keys_and_consistent_values() {
    let o = aeromag(&[
        "igrf",
        "--lat",
        "55.75",
        "--lon",
        "37.62",
        "--alt",
        "200",
        "--date",
        "2025-06-01",
        "--json",
    ]);
    assert_code(&o, 0);
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("valid JSON");
    let g = |k: &str| v[k].as_f64().unwrap_or_else(|| panic!("key {k}"));
    let (x, y, z, f) = (g("x"), g("y"), g("z"), g("f"));
    assert!(((x * x + y * y + z * z).sqrt() - f).abs() < 1e-6);
    // Moscow: F ≈ 52 000 nT, inclination ≈ 72°, declination ≈ +12° (2025).
    assert!((50_000.0..54_000.0).contains(&f), "F = {f}");
    assert!((g("inclination") - 72.0).abs() < 2.0);
    assert!((g("declination") - 12.0).abs() < 3.0);
    assert!((g("declination") - y.atan2(x).to_degrees()).abs() < 1e-9);
}

#[test]
fn text_output_names_the_components() {
    let o = aeromag(&[
        "igrf",
        "--lat",
        "-33.9",
        "--lon",
        "18.4",
        "--date",
        "2010-01-01",
    ]);
    assert_code(&o, 0);
    let s = stdout(&o);
    for k in ["X (north)", "Y (east)", "Z (down)", "F", "D", "I"] {
        assert!(s.contains(k), "{k} missing in\n{s}");
    }
}

#[test]
fn bad_arguments_exit_with_code_2() {
    for args in [
        vec!["igrf", "--lat", "95", "--lon", "0", "--date", "2020-01-01"],
        vec!["igrf", "--lat", "10", "--lon", "0", "--date", "2020-02-30"],
        vec!["igrf", "--lat", "10", "--lon", "0", "--date", "1850-01-01"],
        vec!["igrf", "--lat", "10", "--lon", "0", "--date", "tomorrow"],
        vec!["igrf", "--lat", "ten", "--lon", "0", "--date", "2020-01-01"],
        vec!["igrf", "--lon", "0", "--date", "2020-01-01"],
    ] {
        let o = aeromag(&args);
        assert_code(&o, 2);
        assert!(!stderr(&o).contains("panicked"), "{}", stderr(&o));
    }
}

/// Extreme values are refused and named shortly: `--lon 1e308` was taken
/// (exit 0, the longitude printed with 309 digits), `--lat 1e308` and
/// `--alt -1e308` were refused with all their digits.
#[test]
fn extreme_values_are_refused_and_named_shortly() {
    for (flag, value) in [
        ("--lon", "1e308"),
        ("--lon", "-400"),
        ("--lat", "1e308"),
        ("--alt", "-1e308"),
    ] {
        let mut args = vec![
            "igrf",
            "--lat",
            "10",
            "--lon",
            "0",
            "--alt",
            "0",
            "--date",
            "2020-01-01",
        ];
        let k = args.iter().position(|a| *a == flag).unwrap();
        args[k + 1] = value;
        let o = aeromag(&args);
        assert_code(&o, 2);
        let e = stderr(&o);
        assert!(
            e.contains(&format!("{flag} {value}")) && e.len() < 200,
            "{e}"
        );
    }
    let o = aeromag(&[
        "igrf",
        "--lat",
        "10",
        "--lon",
        "-360",
        "--date",
        "2020-01-01",
    ]);
    assert_code(&o, 0);
}
