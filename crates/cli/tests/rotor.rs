//! `aeromag rotor study`: the issue-5 figures on the `helicopter` scenario.

mod common;
use common::*;

#[test]
fn rotor_study_meets_the_issue_figures() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("rotor");
    let o = aeromag(&["rotor", "study", "--out", out.to_str().unwrap()]);
    assert_code(&o, 0);
    assert!(
        stdout(&o).contains("synchronous averaging"),
        "{}",
        stdout(&o)
    );
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let v = |k: &str| {
        s["rotor"][k]
            .as_f64()
            .unwrap_or_else(|| panic!("missing rotor.{k}"))
    };
    let (rms, model, filter) = (
        v("rotor_rms_nt"),
        v("residual_model_nt"),
        v("residual_best_filter_nt"),
    );
    eprintln!("rotor {rms:.3} nT, model residual {model:.4} nT, best filter {filter:.4} nT");
    assert!(model <= 0.10 * rms, "model leaves {model} of {rms}");
    assert!(
        filter >= 3.0 * model,
        "best filter {filter} vs model {model}"
    );
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(html.contains("<svg") && html.contains("low-pass"));
}
