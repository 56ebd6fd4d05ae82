//! `aeromag em study`: the issue-6 figures from the full chain
//! (simulation → detection → calibration → positioning over 5 h).

mod common;
use common::*;

#[test]
fn em_study_meets_the_issue_figures() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("em");
    let o = aeromag(&["em", "study", "--out", out.to_str().unwrap()]);
    assert_code(&o, 0);
    assert!(stdout(&o).contains("RMS range error"), "{}", stdout(&o));
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let v = |k: &str| {
        s["em"][k]
            .as_f64()
            .unwrap_or_else(|| panic!("missing em.{k}"))
    };
    let (range, angle, att) = (
        v("range_err_rel"),
        v("angle_err_deg"),
        v("attitude_err_deg"),
    );
    let (before, after, no_pilot) = (
        v("polarization_ratio_before"),
        v("polarization_ratio_after"),
        v("ratio_without_pilot"),
    );
    eprintln!(
        "range {range:.3e}, direction {angle:.4}°, attitude {att:.4}°, ratio {before:.3e} → {after:.3e} (no pilot {no_pilot:.3e})"
    );
    assert!(range <= 1e-3, "range error {range}");
    assert!(angle <= 0.1 && att <= 0.1, "angles {angle} {att}");
    assert!(before >= 100.0 * after, "ratio {before} → {after}");
    assert!(
        no_pilot > 10.0 * after,
        "without pilot {no_pilot} vs {after}"
    );
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(html.contains("frequency response") && html.contains("<svg"));
    assert!(out.join("calibration.json").is_file());
}

#[test]
fn em_study_requires_out() {
    assert_code(&aeromag(&["em", "study"]), 2);
}
