//! Optional extra sensors of the fixed-wing scenarios (`[[extra_scalars]]`,
//! `[[extra_fluxgates]]`): off by default and then invisible; on, they are
//! Earth-field channels with their own (larger, in the cabin) interference,
//! their own noise streams, reproducible, and they leave every other column
//! alone.

use aeromag_sim::output::describe;
use aeromag_sim::{ScenarioKind, SimError, Simulation, simulate};

/// The documented example: the stinger sensor stays the main `mag`; four
/// cabin scalar sensors (`mag_2` … `mag_5`) and three cabin fluxgates
/// (`flux_b`, `flux_c`, `flux_d`) between x = −2 and +2 m.
const SGL_LIKE: &str = r#"
[[extra_scalars]]
position_m = [-2.0, 0.0, -0.3]
[[extra_scalars]]
position_m = [-1.0, -0.4, -0.3]
[[extra_scalars]]
position_m = [0.5, 0.4, -0.3]
[[extra_scalars]]
position_m = [1.5, 0.0, -0.4]
[[extra_fluxgates]]
position_m = [-2.0, 0.3, -0.3]
[[extra_fluxgates]]
position_m = [0.0, -0.3, -0.3]
[[extra_fluxgates]]
position_m = [1.5, 0.3, -0.4]
"#;

fn col<'a>(s: &'a Simulation, name: &str) -> &'a [f64] {
    s.column(name).unwrap_or_else(|| panic!("no column {name}"))
}

fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

fn std(v: &[f64]) -> f64 {
    let m = v.iter().sum::<f64>() / v.len() as f64;
    (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / v.len() as f64).sqrt()
}

fn csv(s: &Simulation) -> Vec<u8> {
    let mut out = Vec::new();
    s.write_csv(&mut out).unwrap();
    out
}

fn bits_equal(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

#[test]
fn no_extra_sensors_means_the_default_output() {
    for kind in [ScenarioKind::Calibration, ScenarioKind::Survey] {
        let base = simulate(kind, None, Some(5)).unwrap();
        assert!(
            !base
                .column_names()
                .iter()
                .any(|c| c.starts_with("mag_") || c.starts_with("flux_b")),
            "{:?}",
            base.column_names()
        );
        assert!(!base.scenario_toml.contains("extra_"));
        assert!(!base.truth_json.contains("extra_"));
        // Empty lists written out are the same run and the same files.
        let empty = simulate(
            kind,
            Some("extra_scalars = []\nextra_fluxgates = []\n"),
            Some(5),
        )
        .unwrap();
        assert_eq!(csv(&base), csv(&empty));
        assert_eq!(base.scenario_toml, empty.scenario_toml);
        assert_eq!(base.truth_json, empty.truth_json);
    }
}

#[test]
fn extra_sensors_are_earth_field_channels_with_their_own_interference() {
    let base = simulate(ScenarioKind::Calibration, None, Some(1)).unwrap();
    let s = simulate(ScenarioKind::Calibration, Some(SGL_LIKE), Some(1)).unwrap();
    let names = s.column_names();
    // Adding sensors changes no existing column (main sensors included).
    for c in &base.columns {
        assert!(bits_equal(&c.values, col(&s, &c.name)), "{}", c.name);
    }
    let expected_new = [
        "mag_2",
        "mag_3",
        "mag_4",
        "mag_5",
        "flux_b_x",
        "flux_b_y",
        "flux_b_z",
        "flux_c_x",
        "flux_c_y",
        "flux_c_z",
        "flux_d_x",
        "flux_d_y",
        "flux_d_z",
        "true_interf_2",
        "true_interf_3",
        "true_interf_4",
        "true_interf_5",
        "true_external_2",
        "true_external_3",
        "true_external_4",
        "true_external_5",
        "true_flux_b_x",
        "true_flux_b_y",
        "true_flux_b_z",
        "true_flux_c_x",
        "true_flux_c_y",
        "true_flux_c_z",
        "true_flux_d_x",
        "true_flux_d_y",
        "true_flux_d_z",
    ];
    assert_eq!(names.len(), base.columns.len() + expected_new.len());
    for name in expected_new {
        assert!(names.contains(&name), "{name} missing");
        let c = s.columns.iter().find(|c| c.name == name).unwrap();
        assert_eq!(c.unit, "nT", "{name}");
        assert!(!c.description.is_empty(), "{name}");
        assert!(c.values.iter().all(|v| v.is_finite()), "{name}");
    }
    // The recorded channels sit right after the main fluxgate.
    let at = |n: &str| names.iter().position(|c| *c == n).unwrap();
    assert_eq!(at("mag_2"), at("flux_z") + 1);
    assert_eq!(at("flux_b_x"), at("mag_5") + 1);

    let main_rms = rms(col(&s, "true_interf"));
    let main_std = std(col(&s, "true_interf"));
    println!("true_interf (stinger): RMS {main_rms:.2} nT, std {main_std:.2} nT");
    for k in 2..=5 {
        let mag = col(&s, &format!("mag_{k}"));
        assert!(
            mag.iter().all(|v| (40_000.0..70_000.0).contains(v)),
            "mag_{k}"
        );
        let ti = col(&s, &format!("true_interf_{k}"));
        let te = col(&s, &format!("true_external_{k}"));
        let (r, sd) = (rms(ti), std(ti));
        println!("true_interf_{k}: RMS {r:.2} nT, std {sd:.2} nT");
        // Cabin sensors: much closer to the engines and the gear.
        assert!(r > 3.0 * main_rms, "true_interf_{k} RMS {r} vs {main_rms}");
        assert!(sd > main_std, "true_interf_{k} std {sd} vs {main_std}");
        // mag_k = |B_ext| + interference + heading error + noise (lag 0).
        let resid: Vec<f64> = (0..mag.len()).map(|i| mag[i] - te[i] - ti[i]).collect();
        assert!(rms(&resid) < 0.1, "mag_{k} residual {}", rms(&resid));
        // The external field differs from the stinger's only by the anomaly
        // across a few metres (and the diurnal/main field are shared).
        let d: Vec<f64> = te
            .iter()
            .zip(col(&s, "true_external"))
            .map(|(a, b)| a - b)
            .collect();
        assert!(
            rms(&d) < 0.5,
            "true_external_{k} − true_external {}",
            rms(&d)
        );
    }
    // The noise streams are independent: the noise of two cabin sensors
    // (mag − truth − heading error, heading error smooth) is uncorrelated.
    let noise = |k: u32| -> Vec<f64> {
        let (m, e, i) = (
            col(&s, &format!("mag_{k}")),
            col(&s, &format!("true_external_{k}")),
            col(&s, &format!("true_interf_{k}")),
        );
        let r: Vec<f64> = (0..m.len()).map(|j| m[j] - e[j] - i[j]).collect();
        r.windows(2).map(|w| w[1] - w[0]).collect()
    };
    let (a, b) = (noise(2), noise(3));
    let corr = a.iter().zip(&b).map(|(x, y)| x * y).sum::<f64>()
        / (a.iter().map(|x| x * x).sum::<f64>() * b.iter().map(|x| x * x).sum::<f64>()).sqrt();
    assert!(corr.abs() < 0.05, "noise correlation {corr}");

    // Extra fluxgates: body-frame vectors whose magnitude is the total field.
    let mag = col(&s, "mag");
    for j in ['b', 'c', 'd'] {
        let (x, y, z) = (
            col(&s, &format!("flux_{j}_x")),
            col(&s, &format!("flux_{j}_y")),
            col(&s, &format!("flux_{j}_z")),
        );
        let (tx, ty, tz) = (
            col(&s, &format!("true_flux_{j}_x")),
            col(&s, &format!("true_flux_{j}_y")),
            col(&s, &format!("true_flux_{j}_z")),
        );
        let mut worst: f64 = 0.0;
        let mut worst_true: f64 = 0.0;
        for i in 0..x.len() {
            let f = (x[i] * x[i] + y[i] * y[i] + z[i] * z[i]).sqrt();
            let t = (tx[i] * tx[i] + ty[i] * ty[i] + tz[i] * tz[i]).sqrt();
            worst = worst.max((f / mag[i] - 1.0).abs());
            worst_true = worst_true.max((f / t - 1.0).abs());
        }
        println!(
            "|flux_{j}| vs mag: max {:.2} %; vs |true_flux_{j}|: max {:.3} %",
            100.0 * worst,
            100.0 * worst_true
        );
        assert!(worst < 0.05, "flux_{j} vs mag {worst}");
        // The fluxgate's own errors (scale 1e-3, bias ~10 nT) only.
        assert!(worst_true < 0.003, "flux_{j} vs truth {worst_true}");
    }

    // Truth metadata: every extra sensor with its position and coefficients.
    let truth: serde_json::Value = serde_json::from_str(&s.truth_json).unwrap();
    let xs = truth["sensors"]["extra_scalars"].as_array().unwrap();
    assert_eq!(xs.len(), 4);
    assert_eq!(xs[1]["column"], "mag_3");
    assert_eq!(xs[1]["position_m"], serde_json::json!([-1.0, -0.4, -0.3]));
    assert!(xs[1]["interference"]["induced_matrix"].is_array());
    assert!(xs[1]["true_interf_stats_nt"]["std"].as_f64().unwrap() > main_std);
    let xf = truth["sensors"]["extra_fluxgates"].as_array().unwrap();
    assert_eq!(xf.len(), 3);
    assert_eq!(xf[2]["columns"], "flux_d_x/y/z");
    assert!(xf[2]["interference"]["permanent_field_nt"].is_array());
    assert_eq!(truth["columns"].as_array().unwrap().len(), s.columns.len());
}

#[test]
fn extra_sensors_are_reproducible_and_their_file_reruns_the_flight() {
    let a = simulate(ScenarioKind::CalibrationTruncated, Some(SGL_LIKE), Some(9)).unwrap();
    let b = simulate(ScenarioKind::CalibrationTruncated, Some(SGL_LIKE), Some(9)).unwrap();
    assert_eq!(csv(&a), csv(&b));
    assert_eq!(a.truth_json, b.truth_json);
    let c = simulate(ScenarioKind::CalibrationTruncated, Some(SGL_LIKE), Some(10)).unwrap();
    assert!(!bits_equal(col(&a, "mag_3"), col(&c, "mag_3")));
    // The filled-in scenario file lists the sensors and reproduces the run.
    assert_eq!(a.scenario_toml.matches("[[extra_scalars]]").count(), 4);
    assert_eq!(a.scenario_toml.matches("[[extra_fluxgates]]").count(), 3);
    let again = simulate(
        ScenarioKind::CalibrationTruncated,
        Some(&a.scenario_toml),
        None,
    )
    .unwrap();
    assert_eq!(csv(&a), csv(&again));
    // Written files: the CSV reads back with every extra column.
    let dir = tempfile::tempdir().unwrap();
    let files = a.write_to_dir(dir.path()).unwrap();
    let table = aeromag_io::read_csv(&files.csv, &aeromag_io::ReadOptions::default()).unwrap();
    for name in ["mag_5", "flux_d_z", "true_interf_2", "true_flux_b_x"] {
        assert!(
            bits_equal(table.column(name).unwrap(), col(&a, name)),
            "{name}"
        );
    }
    // Every extra column pattern is documented in the crate docs.
    let lib = include_str!("../src/lib.rs");
    for pattern in [
        "`mag_<k>`",
        "`flux_<j>_x`",
        "`true_interf_<k>`",
        "`true_external_<k>`",
        "`true_flux_<j>_x`",
    ] {
        assert!(lib.contains(pattern), "{pattern} not in the crate docs");
    }
}

#[test]
fn extra_sensor_settings_are_checked() {
    let bad = |text: &str| simulate(ScenarioKind::Calibration, Some(text), Some(1)).unwrap_err();
    let e = bad("[[extra_scalars]]\nposition_m = [-2.0, 0.0]\n");
    assert!(matches!(e, SimError::ConfigParse { .. }), "{e}");
    let e = bad("[[extra_scalars]]\nposition = [-2.0, 0.0, 0.0]\n");
    assert!(e.to_string().contains("position"), "{e}");
    let e = bad("[[extra_fluxgates]]\nposition_m = [-200.0, 0.0, 0.0]\n");
    assert!(
        e.to_string().contains("extra_fluxgates[0].position_m"),
        "{e}"
    );
    let e =
        bad("[[extra_scalars]]\nposition_m = [-1.0, 0.0, 0.0]\nnoise_density_nt_per_rthz = -1.0\n");
    assert!(e.to_string().contains("extra_scalars[0]"), "{e}");
    let many = "[[extra_fluxgates]]\n".repeat(26);
    let e = bad(&many);
    assert!(e.to_string().contains("extra_fluxgates"), "{e}");
    // The helicopter adds its rotor at the main sensors only.
    let e = simulate(
        ScenarioKind::Helicopter,
        Some("[[extra_scalars]]\nposition_m = [-1.0, 0.0, 0.0]\n"),
        Some(1),
    )
    .unwrap_err();
    assert!(e.to_string().contains("helicopter"), "{e}");
}

#[test]
fn extra_columns_are_described() {
    assert_eq!(describe("mag_2").unwrap().0, "nT");
    assert_eq!(describe("mag_17").unwrap().0, "nT");
    assert!(describe("mag_1").is_none());
    assert!(describe("mag_02").is_none());
    assert!(describe("mag_x").is_none());
    assert_eq!(describe("flux_c_y").unwrap().0, "nT");
    // `flux_a` is the SGL layout's name of the stinger fluxgate.
    assert!(
        describe("flux_a_y")
            .unwrap()
            .1
            .contains("SGL layout: `flux_y`")
    );
    assert!(describe("flux_c_w").is_none());
    assert!(
        describe("true_flux_d_z")
            .unwrap()
            .1
            .contains("extra fluxgate d")
    );
    assert!(describe("true_interf_3").unwrap().1.contains("mag_3"));
    assert!(describe("true_external_4").unwrap().1.contains("mag_4"));
    // The fixed columns keep their entries.
    assert!(
        describe("true_interf_x")
            .unwrap()
            .1
            .contains("scalar sensor")
    );
    assert!(describe("flux_x").unwrap().1.contains("fluxgate x"));
}

/// Peak to peak.
fn ptp(v: &[f64]) -> f64 {
    v.iter().copied().fold(f64::NEG_INFINITY, f64::max)
        - v.iter().copied().fold(f64::INFINITY, f64::min)
}

/// `installation = "sgl"`: the SGL HDF5 names, truth per sensor, the
/// cabin sensors' hundreds of nT of which tens follow the currents, the
/// stinger seeing the currents weakly; every recorded current is its true
/// current plus its own noise; the stinger's column equals what the
/// stinger installation records with the same currents (the names change,
/// not the physics). Prints the per-sensor figures the docs quote.
#[test]
fn the_sgl_installation() {
    let s = simulate(
        ScenarioKind::Calibration,
        Some("installation = \"sgl\"\n"),
        Some(2),
    )
    .unwrap();
    let names = s.column_names();
    for n in [
        "mag_1_uc",
        "mag_5_uc",
        "flux_a_x",
        "flux_d_z",
        "cur_strb",
        "cur_bat_2",
        "true_interf_1",
        "true_external_5",
        "true_interf_current_1",
        "true_interf_current_4",
    ] {
        assert!(names.contains(&n), "no {n}");
        assert!(
            describe(n).is_some_and(|(u, d)| u != "-" && !d.is_empty()),
            "{n}"
        );
    }
    for gone in ["mag", "flux_x", "true_interf", "mag_2", "current_strb"] {
        assert!(!names.contains(&gone), "{gone}");
    }
    assert_eq!(names.iter().filter(|n| n.starts_with("cur_")).count(), 14);
    for k in 1..=5 {
        let (interf, cur) = (
            col(&s, &format!("true_interf_{k}")),
            col(&s, &format!("true_interf_current_{k}")),
        );
        println!(
            "mag_{k}_uc: interference RMS {:.1} nT, peak to peak {:.1} nT; currents' part RMS {:.2} nT, peak to peak {:.2} nT",
            rms(interf),
            ptp(interf),
            std(cur),
            ptp(cur)
        );
        let m = col(&s, &format!("mag_{k}_uc"));
        let ext = col(&s, &format!("true_external_{k}"));
        // The reading is the external field plus the interference, within
        // the sensor's errors (noise, heading error, lag: well under 1 nT).
        let d: Vec<f64> = (0..m.len()).map(|i| m[i] - ext[i] - interf[i]).collect();
        assert!(std(&d) < 0.5, "mag_{k}_uc: {}", std(&d));
        if k == 1 {
            assert!(
                (0.02..1.5).contains(&ptp(cur)),
                "stinger currents {}",
                ptp(cur)
            );
        } else {
            assert!(ptp(cur) > 10.0, "mag_{k}_uc currents {}", ptp(cur));
        }
    }
    assert!(
        (2..=5).any(|k| rms(col(&s, &format!("true_interf_{k}"))) > 300.0),
        "a cabin sensor with hundreds of nT"
    );
    for c in ["strb", "flap", "bat_1"] {
        let rec = col(&s, &format!("cur_{c}"));
        let tru = col(&s, &format!("true_cur_{c}"));
        let noise: Vec<f64> = rec.iter().zip(tru).map(|(a, b)| a - b).collect();
        assert!(
            std(&noise) > 0.005 && std(&noise) < 0.06,
            "{c}: {}",
            std(&noise)
        );
        assert!(std(tru) > 5.0 * std(&noise), "{c} varies");
    }
    let truth: serde_json::Value = serde_json::from_str(&s.truth_json).unwrap();
    assert_eq!(truth["installation"], "sgl");
    assert_eq!(truth["sensors"]["extra_scalars"][3]["column"], "mag_5_uc");
    // The same physics under the stinger installation's names.
    let cfg = s.scenario_toml.replace("installation = \"sgl\"\n", "");
    let plain = simulate(ScenarioKind::Calibration, Some(&cfg), Some(2)).unwrap();
    assert!(bits_equal(col(&plain, "mag"), col(&s, "mag_1_uc")));
    assert!(bits_equal(col(&plain, "mag_3"), col(&s, "mag_3_uc")));
    assert!(bits_equal(col(&plain, "flux_y"), col(&s, "flux_a_y")));
    // A file's own list replaces the preset's; the helicopter refuses it.
    let own = simulate(
        ScenarioKind::CalibrationTruncated,
        Some("installation = \"sgl\"\n[[extra_scalars]]\nposition_m = [0.0, 0.0, -0.5]\n"),
        Some(2),
    )
    .unwrap();
    assert!(own.column("mag_2_uc").is_some() && own.column("mag_3_uc").is_none());
    let e = simulate(
        ScenarioKind::Helicopter,
        Some("installation = \"sgl\"\n"),
        Some(2),
    )
    .unwrap_err();
    assert!(
        matches!(e, SimError::InvalidConfig { .. }) && e.to_string().contains("installation"),
        "{e}"
    );
}
