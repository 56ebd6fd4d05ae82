//! `aeromag dipole simulate|locate|crlb` end to end (issue 7): simulated
//! passes located without the truth and scored against it by the test.

mod common;
use aeromag_gradiometry::config::GradiometerConfig;
use aeromag_gradiometry::efficiency::{scalar_pass_crlb, tensor_pass_crlb};
use aeromag_gradiometry::sim::simulate;
use common::*;
use std::collections::HashMap;
use std::path::Path;

const STATE: [&str; 6] = ["x_m", "y_m", "z_m", "mx_am2", "my_am2", "mz_am2"];

/// A CSV file as columns by name (the test's own reader).
fn read_columns(p: &Path) -> HashMap<String, Vec<f64>> {
    let text = std::fs::read_to_string(p).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let names: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    let mut cols: Vec<Vec<f64>> = vec![Vec::new(); names.len()];
    for l in lines {
        for (c, v) in l.split(',').enumerate() {
            cols[c].push(v.parse().unwrap_or(f64::NAN));
        }
    }
    names.into_iter().zip(cols).collect()
}

fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}

/// Simulate with `config` (None = defaults) into `dir`; returns (csv, toml).
fn simulate_into(dir: &Path, config: Option<&str>) -> (std::path::PathBuf, std::path::PathBuf) {
    let mut args = vec!["dipole", "simulate", "--out", p(dir)];
    let cfg = dir.with_extension("in.toml");
    if let Some(text) = config {
        std::fs::write(&cfg, text).unwrap();
        args.extend(["--config", p(&cfg)]);
    }
    assert_code(&aeromag(&args), 0);
    (dir.join("gradiometer.csv"), dir.join("gradiometer.toml"))
}

fn locate(csv: &Path, toml: &Path, out: &Path) -> HashMap<String, Vec<f64>> {
    let o = aeromag(&[
        "dipole",
        "locate",
        "--input",
        p(csv),
        "--config",
        p(toml),
        "--out",
        p(out),
    ]);
    assert_code(&o, 0);
    read_columns(out)
}

/// A well-posed pass: mobile system (tilted), no bias, no variations,
/// object heading fixed, IGRF background, deterministic motion model,
/// multi-start and re-linearised passes.
const WELL_POSED: &str = r#"
[system]
motion = "mobile"
gradiometer = "GRAD"
attitude_deg = [3.0, -2.0, 10.0]
[sensors.vector]
noise_nt = 0.5
bias_sigma_nt = 0.0
[sensors.scalar]
noise_nt = 0.02
bias_sigma_nt = 0.0
[environment]
variation_nt = 0.0
[object]
yaw_rate_rad_s = 0.0
[trajectory]
epochs = 100
[estimator]
quiet_epochs = 0
position_random_walk_m_per_sqrt_s = 0.0
moment_random_walk_am2_per_sqrt_s = 0.0
induced_per_rad = 0.0
detection_factor = 10.0
prior_sigma_moment_am2 = 5000.0
passes = 10
"#;

fn crlb_json(toml: &Path) -> serde_json::Value {
    let o = aeromag(&["dipole", "crlb", "--config", p(toml), "--json"]);
    assert_code(&o, 0);
    serde_json::from_str(&stdout(&o)).unwrap()
}

#[test]
fn well_posed_tensor_and_scalar_passes_are_located_within_a_few_crlb_sigmas() {
    let d = tempfile::tempdir().unwrap();
    for (grad, scored) in [("tensor", &STATE[..]), ("scalar", &STATE[3..])] {
        let (csv, toml) = simulate_into(
            &d.path().join(grad),
            Some(&WELL_POSED.replace("GRAD", grad)),
        );
        let est = locate(&csv, &toml, &d.path().join(format!("{grad}_est.csv")));
        let truth = read_columns(&csv);
        let bound = crlb_json(&toml);
        let last = truth["time"].len() - 1;
        assert_eq!(bound["end"]["epoch"].as_u64(), Some(last as u64));
        assert_eq!(est["detected"][last], 1.0);
        for n in scored {
            let err = est[*n][last] - truth[&format!("true_{n}")][last];
            let crlb = bound["end"]["std"][n].as_f64().unwrap();
            let sd = est[&format!("sd_{n}")][last];
            eprintln!("{grad} {n}: error {err:+.3e}, CRLB σ {crlb:.3e}, filter σ {sd:.3e}");
            assert!(
                err.abs() <= 4.0 * crlb,
                "{grad} {n}: error {err} vs CRLB σ {crlb}"
            );
            // the re-linearised passes reach the bound: their σ is the CRLB's
            assert!(
                (0.9..=1.1).contains(&(sd / crlb)),
                "{grad} {n}: σ {sd} vs CRLB {crlb}"
            );
        }
        if grad == "scalar" {
            // the known position comes from the tracks, not from true_ columns
            for (k, n) in STATE[..3].iter().enumerate() {
                let e = (est[*n][last] - truth[&format!("true_{n}")][last]).abs();
                assert!(e < 1e-9, "scalar known position {k}: {e}");
            }
        }
    }
}

#[test]
fn crlb_output_matches_the_library() {
    let d = tempfile::tempdir().unwrap();
    for grad in ["tensor", "scalar"] {
        let text = WELL_POSED.replace("GRAD", grad);
        let f = d.path().join(format!("{grad}.toml"));
        std::fs::write(&f, &text).unwrap();
        let v = crlb_json(&f);
        let cfg = GradiometerConfig::from_toml(&text).unwrap();
        let sim = simulate(&cfg.scenario().unwrap()).unwrap();
        let g = cfg.geometry().unwrap();
        for key in ["closest_approach", "end"] {
            let j = v[key]["epoch"].as_u64().unwrap() as usize;
            let sd: Vec<f64> = if grad == "tensor" {
                let b = tensor_pass_crlb(&sim[..=j], &g, 0.5).unwrap();
                (0..6).map(|k| b[(k, k)].sqrt()).collect()
            } else {
                let b = scalar_pass_crlb(&sim[..=j], &g, 0.02).unwrap();
                (0..3).map(|k| b[(k, k)].sqrt()).collect()
            };
            let names = if grad == "tensor" {
                &STATE[..]
            } else {
                &STATE[3..]
            };
            for (n, s) in names.iter().zip(&sd) {
                let cli = v[key]["std"][n].as_f64().unwrap();
                assert!(
                    (cli - s).abs() <= 1e-12 * s,
                    "{grad} {key} {n}: {cli} vs {s}"
                );
            }
        }
        let closest = v["closest_approach"]["range_m"].as_f64().unwrap();
        let min = sim
            .iter()
            .map(|e| e.true_position_m.norm())
            .fold(f64::INFINITY, f64::min);
        assert_eq!(closest, min);
    }
    let o = aeromag(&["dipole", "crlb"]);
    assert_code(&o, 0);
    assert!(stdout(&o).contains("closest_approach"), "{}", stdout(&o));
}

#[test]
fn default_pass_is_tracked_without_the_truth_columns() {
    let d = tempfile::tempdir().unwrap();
    let (csv, toml) = simulate_into(&d.path().join("sim"), None);
    let truth = read_columns(&csv);
    // The same file without its true_ columns gives the same estimates.
    let text = std::fs::read_to_string(&csv).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let keep: Vec<usize> = (0..header.len())
        .filter(|&i| !header[i].starts_with("true_"))
        .collect();
    assert_eq!(header.len() - keep.len(), 6);
    let stripped: String = text
        .lines()
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            keep.iter().map(|&i| f[i]).collect::<Vec<_>>().join(",") + "\n"
        })
        .collect();
    let bare = d.path().join("bare.csv");
    std::fs::write(&bare, stripped).unwrap();
    let (a, b) = (d.path().join("a.csv"), d.path().join("b.csv"));
    let est = locate(&csv, &toml, &a);
    locate(&bare, &toml, &b);
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    // Realistic pass (biases, variations, yawing object with induced
    // moment): detected before the closest approach, and there the errors
    // are within 3σ of the filter's own uncertainty, below 0.1 m and 5 %.
    let j0 = est["detected"].iter().position(|&v| v == 1.0).unwrap();
    let range = |j: usize| {
        (0..3)
            .map(|k| truth[&format!("true_{}", STATE[k])][j].powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let closest = (0..est["time"].len())
        .min_by(|&i, &j| range(i).total_cmp(&range(j)))
        .unwrap();
    assert!(
        j0 < closest - 20,
        "detected at {j0}, closest approach {closest}"
    );
    for j in [closest, closest + 20] {
        let mut dr = 0.0;
        let (mut dm, mut m) = (0.0, 0.0);
        for (k, n) in STATE.iter().enumerate() {
            let t = truth[&format!("true_{n}")][j];
            let e = est[*n][j] - t;
            assert!(
                e.abs() <= 3.0 * est[&format!("sd_{n}")][j],
                "epoch {j} {n}: error {e}"
            );
            if k < 3 {
                dr += e * e;
            } else {
                dm += e * e;
                m += t * t;
            }
        }
        assert!(
            dr.sqrt() < 0.1 && (dm / m).sqrt() < 0.05,
            "epoch {j}: {dr} {dm} {m}"
        );
        assert!(est["mu_x"][j] > 0.9 && est["mu_mx"][j] > 0.9);
    }
}

#[test]
fn scenario_file_round_trip_and_simulate_dispatch() {
    let d = tempfile::tempdir().unwrap();
    let o = aeromag(&["simulate", "gradiometer", "--print-config"]);
    assert_code(&o, 0);
    let printed = stdout(&o);
    assert_eq!(
        GradiometerConfig::from_toml(&printed).unwrap(),
        GradiometerConfig::default()
    );
    let a = d.path().join("a");
    assert_code(
        &aeromag(&["simulate", "gradiometer", "--seed", "5", "--out", p(&a)]),
        0,
    );
    let b = d.path().join("b");
    let o = aeromag(&[
        "dipole",
        "simulate",
        "--config",
        p(&a.join("gradiometer.toml")),
        "--out",
        p(&b),
    ]);
    assert_code(&o, 0);
    let bytes = |dir: &Path| std::fs::read(dir.join("gradiometer.csv")).unwrap();
    assert_eq!(
        bytes(&a),
        bytes(&b),
        "the written scenario reproduces the data"
    );
    assert!(
        std::fs::read_to_string(b.join("gradiometer.toml"))
            .unwrap()
            .contains("seed = 5")
    );
}

#[test]
fn bad_input_exits_2_naming_file_row_and_column() {
    let d = tempfile::tempdir().unwrap();
    let (csv, toml) = simulate_into(&d.path().join("sim"), Some("[trajectory]\nepochs = 120\n"));
    let text = std::fs::read_to_string(&csv).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let col = header.iter().position(|&h| h == "b2_y").unwrap();
    let edit = |row: usize, value: &str| -> String {
        text.lines()
            .enumerate()
            .map(|(i, l)| {
                let mut f: Vec<String> = l.split(',').map(String::from).collect();
                if i == row {
                    f[col] = value.to_string();
                }
                f.join(",") + "\n"
            })
            .collect()
    };
    let out = d.path().join("est.csv");
    for (name, content, needles) in [
        (
            "blank.csv",
            edit(7, ""),
            vec!["blank.csv", "b2_y", "data row 7"],
        ),
        (
            "text.csv",
            edit(9, "abc"),
            vec!["text.csv", "b2_y", "abc", "data row 9 (line 10)"],
        ),
    ] {
        let f = d.path().join(name);
        std::fs::write(&f, content).unwrap();
        let o = aeromag(&[
            "dipole",
            "locate",
            "--input",
            p(&f),
            "--config",
            p(&toml),
            "--out",
            p(&out),
        ]);
        assert_code(&o, 2);
        for n in needles {
            assert!(stderr(&o).contains(n), "{name}: no '{n}' in {}", stderr(&o));
        }
    }
    // a missing column
    let o = aeromag(&[
        "dipole",
        "locate",
        "--input",
        p(&csv),
        "--gradiometer",
        "scalar",
        "--out",
        p(&out),
    ]);
    assert_code(&o, 2);
    assert!(stderr(&o).contains("f1"), "{}", stderr(&o));
    // bad scenario files and flags
    let bad = d.path().join("bad.toml");
    std::fs::write(&bad, "[system]\nlayout = \"hexagon\"\n").unwrap();
    for args in [
        vec!["dipole", "crlb", "--config", p(&bad)],
        vec![
            "dipole",
            "simulate",
            "--config",
            p(&bad),
            "--out",
            p(d.path()),
        ],
        vec![
            "dipole",
            "locate",
            "--input",
            p(&csv),
            "--layout",
            "hexagon",
            "--out",
            p(&out),
        ],
        vec![
            "dipole",
            "locate",
            "--input",
            p(&csv),
            "--noise-nt=-1",
            "--out",
            p(&out),
        ],
    ] {
        let o = aeromag(&args);
        assert_code(&o, 2);
        assert!(
            stderr(&o).contains("hexagon") || stderr(&o).contains("noise_nt"),
            "{}",
            stderr(&o)
        );
    }
}
