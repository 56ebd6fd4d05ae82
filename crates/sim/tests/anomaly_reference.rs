//! The radial moments that set the anomaly amplitude, against SciPy's
//! adaptive quadrature (`tools/reference/sim_anomaly_reference.py` →
//! `tests/data/anomaly_moments.json`).

use aeromag_sim::environment::anomaly::AnomalyConfig;

#[test]
fn radial_moments_match_scipy_quad() {
    let doc: serde_json::Value =
        serde_json::from_str(include_str!("data/anomaly_moments.json")).unwrap();
    let cases = doc["cases"].as_array().unwrap();
    assert_eq!(cases.len(), 60);
    let mut worst: f64 = 0.0;
    for c in cases {
        let cfg = AnomalyConfig {
            spectral_exponent: c["beta"].as_f64().unwrap(),
            regional_wavelength_m: c["lambda_c_m"].as_f64().unwrap(),
            ..AnomalyConfig::default()
        };
        let p = c["p"].as_i64().unwrap() as i32;
        let got = cfg.radial_moment(p, c["height_m"].as_f64().unwrap());
        let want = c["moment"].as_f64().unwrap();
        let rel = (got / want - 1.0).abs();
        worst = worst.max(rel);
        assert!(rel < 1e-11, "{c}: {got} vs {want} (rel {rel:e})");
    }
    println!("worst relative error {worst:e}");
}
