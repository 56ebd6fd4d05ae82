//! `aeromag dipole simulate|locate|crlb` as commands: files, reading a pass
//! without its truth columns, the CRLB output against the library, bad
//! input (the accuracy is tested in the library).

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

/// The pass file `text` with the cell of `column` on line `line` (0: the
/// header) set to `value`.
fn edited(text: &str, column: &str, line: usize, value: &str) -> String {
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let col = header.iter().position(|&h| h == column).unwrap();
    text.lines()
        .enumerate()
        .map(|(i, l)| {
            let mut f: Vec<String> = l.split(',').map(String::from).collect();
            if i == line {
                f[col] = value.to_string();
            }
            f.join(",") + "\n"
        })
        .collect()
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
    let o = locate_with(csv, toml, out, &[]);
    assert_code(&o, 0);
    read_columns(out)
}

/// A well-posed pass: mobile system (tilted), no bias, no variations,
/// object heading fixed, IGRF background, deterministic motion model,
/// multi-start and re-linearised passes.
const WELL_POSED: &str = include_str!("../../aeromag/tests/data/well_posed_pass.toml");

fn crlb_json(toml: &Path) -> serde_json::Value {
    let o = aeromag(&["dipole", "crlb", "--config", p(toml), "--json"]);
    assert_code(&o, 0);
    serde_json::from_str(&stdout(&o)).unwrap()
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
    // The pass may be given without --input.
    let o = aeromag(&[
        "dipole",
        "locate",
        p(&bare),
        "--config",
        p(&toml),
        "--out",
        p(&b),
    ]);
    assert_code(&o, 0);
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    assert_eq!(est["time"].len(), truth["time"].len(), "one row per epoch");
    for c in [
        "detected",
        "x_m",
        "sd_mz_am2",
        "mu_x",
        "iterations",
        "converged",
    ] {
        assert!(est.contains_key(c), "{c}");
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

/// A pass whose heading column has another name: the missing-column
/// message's `--columns yaw=NAME` works, and gives the estimates of the
/// file with the canonical name. The default pass: in a pass of 120
/// epochs the object is near during the quiet epochs, and no epoch
/// converges (a failure, exit 1).
#[test]
fn columns_map_the_navigation_names() {
    let d = tempfile::tempdir().unwrap();
    let (csv, toml) = simulate_into(&d.path().join("sim"), None);
    let text = std::fs::read_to_string(&csv).unwrap();
    let (header, rows) = text.split_once('\n').unwrap();
    let renamed = d.path().join("heading.csv");
    let header = header.replace(",yaw,", ",heading,");
    std::fs::write(&renamed, format!("{header}\n{rows}")).unwrap();
    let locate = |input: &Path, out: &Path, extra: &[&str]| {
        let mut args = vec![
            "dipole",
            "locate",
            "--input",
            p(input),
            "--config",
            p(&toml),
            "--out",
            p(out),
        ];
        args.extend_from_slice(extra);
        aeromag(&args)
    };
    let o = locate(&renamed, &d.path().join("no.csv"), &[]);
    assert_code(&o, 2);
    assert!(
        stderr(&o).contains("required column 'yaw' is missing")
            && stderr(&o).contains("--columns yaw=NAME"),
        "{}",
        stderr(&o)
    );
    let (mapped, plain) = (d.path().join("mapped.csv"), d.path().join("plain.csv"));
    assert_code(&locate(&renamed, &mapped, &["--columns", "yaw=heading"]), 0);
    assert_code(&locate(&csv, &plain, &[]), 0);
    assert_eq!(
        std::fs::read(&mapped).unwrap(),
        std::fs::read(&plain).unwrap()
    );
    // A canonical name the command does not read (it was taken and
    // changed nothing) and an unknown one: bad input naming those it maps.
    for map in ["yaw=heading,mag=b1_x", "bogus=lat"] {
        let o = locate(&renamed, &d.path().join("x.csv"), &["--columns", map]);
        assert_code(&o, 2);
        assert!(
            stderr(&o).contains(
                "not a column this command reads; it maps: time, lat, lon, alt, roll, pitch, yaw"
            ) && !stderr(&o).contains("flux_x"),
            "{}",
            stderr(&o)
        );
    }
}

#[test]
fn bad_input_exits_2_naming_file_row_and_column() {
    let d = tempfile::tempdir().unwrap();
    let (csv, toml) = simulate_into(&d.path().join("sim"), Some("[trajectory]\nepochs = 120\n"));
    let text = std::fs::read_to_string(&csv).unwrap();
    let edit = |row: usize, value: &str| edited(&text, "b2_y", row, value);
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
            vec!["text.csv", "b2_y", "abc", "line 10 (data row 9)"],
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

/// `aeromag dipole locate` on `csv` with extra flags: the output.
fn locate_with(csv: &Path, toml: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "dipole",
        "locate",
        "--input",
        p(csv),
        "--config",
        p(toml),
        "--out",
        p(out),
    ];
    args.extend(extra);
    aeromag(&args)
}

fn assert_bad(o: &std::process::Output, needles: &[&str]) {
    assert_code(o, 2);
    let e = stderr(o);
    for n in needles {
        assert!(e.contains(n), "no '{n}' in {e}");
    }
    assert!(e.len() < 600 && !e.contains("panicked"), "{e}");
}

#[test]
fn values_beyond_their_physical_range_name_the_column_key_or_flag() {
    let d = tempfile::tempdir().unwrap();
    let (csv, toml) = simulate_into(&d.path().join("sim"), Some("[trajectory]\nepochs = 120\n"));
    let text = std::fs::read_to_string(&csv).unwrap();
    let edit = |name: &str, line: usize, value: &str| edited(&text, name, line, value);
    let out = d.path().join("est.csv");
    for (column, value) in [
        ("north_m", "1e308"),
        ("obj_north_m", "1e308"),
        ("b1_x", "1e308"),
        ("b1_x", "1e300"),
        ("time", "1e300"),
        ("roll", "1e308"),
    ] {
        let f = d.path().join(format!("{column}.csv"));
        std::fs::write(&f, edit(column, 60, value)).unwrap();
        assert_bad(
            &locate_with(&f, &toml, &out, &[]),
            &[
                &format!("{column}.csv"),
                &format!("column '{column}'"),
                "data row",
            ],
        );
    }
    for (flag, value) in [
        ("--baseline-m", "1e308"),
        ("--noise-nt", "1e-308"),
        ("--passes", "0"),
        ("--passes", "1000000"),
    ] {
        assert_bad(&locate_with(&csv, &toml, &out, &[flag, value]), &[flag]);
    }
    // scenario keys: checked before anything is allocated or simulated
    let cfg = d.path().join("cfg.toml");
    for (text, key) in [
        ("[trajectory]\nepochs = 100000000\n", "trajectory.epochs"),
        ("[trajectory]\ndt_s = 1e-300\n", "trajectory.dt_s"),
        (
            "[estimator]\nmax_iterations = 1000000000\n",
            "max_iterations",
        ),
        ("[estimator]\nmax_iterations = 0\n", "max_iterations"),
        (
            "[environment]\ndecimal_year = 2100.0\n",
            "environment.decimal_year",
        ),
        ("[environment]\nlat_deg = 91.0\n", "environment.lat_deg"),
        (
            "[system]\nattitude_deg = [1e308, 0.0, 0.0]\n",
            "attitude_deg",
        ),
    ] {
        std::fs::write(&cfg, text).unwrap();
        let t = std::time::Instant::now();
        for args in [
            vec!["dipole", "crlb", "--config", p(&cfg)],
            vec![
                "dipole",
                "simulate",
                "--config",
                p(&cfg),
                "--out",
                p(&d.path().join("x")),
            ],
        ] {
            let o = aeromag(&args);
            assert_bad(&o, &["cfg.toml", key]);
            assert!(!stderr(&o).contains("must be finite"), "{}", stderr(&o));
        }
        assert!(t.elapsed().as_secs() < 10, "{text}");
    }
}

#[test]
fn re_linearised_passes_that_lose_the_object_fail_instead_of_answering_wrongly() {
    let d = tempfile::tempdir().unwrap();
    // The default pass ends 60 m (60 baselines) from the object: the noisy
    // first of several passes loses it and they ended at (8.9, −0.5, −0.5) m
    // with σ 0.04 m instead of the true (59.9, 6, 2) m.
    let (csv, toml) = simulate_into(&d.path().join("sim"), None);
    let out = d.path().join("est.csv");
    let o = locate_with(&csv, &toml, &out, &["--passes", "2"]);
    assert_code(&o, 1);
    assert!(
        stderr(&o).contains("re-linearised passes"),
        "{}",
        stderr(&o)
    );
    let o = locate_with(&csv, &toml, &out, &["--passes", "1"]);
    assert_code(&o, 0);
}

#[test]
fn scalar_gradiometer_says_its_position_sigma_is_not_estimated() {
    let d = tempfile::tempdir().unwrap();
    let (csv, toml) = simulate_into(
        &d.path().join("sim"),
        Some("[system]\ngradiometer = \"scalar\"\n[trajectory]\nepochs = 120\n"),
    );
    let out = d.path().join("est.csv");
    let o = locate_with(&csv, &toml, &out, &[]);
    assert_code(&o, 0);
    let s = stdout(&o);
    assert!(s.contains("σ not estimated") && !s.contains("NaN"), "{s}");
}

#[test]
fn convergence_on_the_smallest_grids_and_threads_zero() {
    let d = tempfile::tempdir().unwrap();
    for g in ["2", "3"] {
        let dir = d.path().join(g);
        let o = aeromag(&["dipole", "convergence", "--grid", g, "--out", p(&dir)]);
        assert_code(&o, 0);
        assert!(dir.join("index.html").exists());
    }
    let o = aeromag(&[
        "dipole",
        "convergence",
        "--grid",
        "4",
        "--threads",
        "0",
        "--out",
        p(&d.path().join("t")),
    ]);
    assert_bad(&o, &["--threads 0"]);
}

/// The plain IEKF locks on a wrong solution on the default pass (180 m off,
/// `converged` 1, σ about a metre): a warning now says its estimates are
/// not to be trusted; the multi-start's are not warned of. Both print the
/// mean normalised innovation and write it per epoch (`nis`). The scenario
/// file as the output, and readings in µT, are refused; a truth column is
/// not read.
#[test]
fn a_wrong_lock_is_warned_of_and_wrong_units_or_paths_are_refused() {
    let d = tempfile::tempdir().unwrap();
    let (csv, toml) = simulate_into(&d.path().join("sim"), None);
    let out = d.path().join("est.csv");
    let good = locate_with(&csv, &toml, &out, &[]);
    assert_code(&good, 0);
    assert!(
        stdout(&good).contains("mean normalised innovation squared per contrast 0.9")
            && !stderr(&good).contains("warning"),
        "{}{}",
        stdout(&good),
        stderr(&good)
    );
    let header = std::fs::read_to_string(&out).unwrap();
    assert!(header.lines().next().unwrap().ends_with(",converged,nis"));
    // The scenario file named as the output: refused, the file kept (it
    // was replaced by the estimates).
    let before = std::fs::read(&toml).unwrap();
    let o = locate_with(&csv, &toml, &toml, &[]);
    assert_code(&o, 2);
    assert!(stderr(&o).contains("is also an input"), "{}", stderr(&o));
    assert_eq!(std::fs::read(&toml).unwrap(), before);
    // Sensor 2's readings in µT: bad input naming its columns (it read as
    // a pass where the object was not detected, exit 0).
    let text = std::fs::read_to_string(&csv).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let micro: String = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            let f: Vec<String> = l
                .split(',')
                .zip(&header)
                .map(|(v, h)| match (i, h.starts_with("b2_")) {
                    (1.., true) => (v.parse::<f64>().unwrap() * 1e-3).to_string(),
                    _ => v.to_string(),
                })
                .collect();
            f.join(",") + "\n"
        })
        .collect();
    let micro_csv = d.path().join("micro.csv");
    std::fs::write(&micro_csv, micro).unwrap();
    let o = locate_with(&micro_csv, &toml, &out, &[]);
    assert_code(&o, 2);
    assert!(
        stderr(&o).contains("sensor 2 (b2_x, b2_y, b2_z) reads a median field of"),
        "{}",
        stderr(&o)
    );
    // A text cell in a truth column, which locate never reads: located
    // (it was parsed, and refused).
    let truth_text = d.path().join("truth_text.csv");
    std::fs::write(&truth_text, edited(&text, "true_x_m", 5, "abc")).unwrap();
    assert_code(&locate_with(&truth_text, &toml, &out, &[]), 0);
    let plain = locate_with(&csv, &toml, &out, &["--plain"]);
    assert_code(&plain, 0);
    assert!(
        stderr(&plain).contains("warning: the filter's normalised innovations squared average")
            && stderr(&plain).contains("not to be trusted"),
        "{}",
        stderr(&plain)
    );
}

/// A pass with 10 s missing at the closest approach: the object is not
/// detected, and a warning names the gap (it said nothing of it).
#[test]
fn a_time_gap_in_the_pass_is_warned_of() {
    let d = tempfile::tempdir().unwrap();
    let (csv, toml) = simulate_into(&d.path().join("sim"), None);
    let text = std::fs::read_to_string(&csv).unwrap();
    let gapped: String = text
        .lines()
        .enumerate()
        .filter(|(i, _)| !(250..350).contains(i))
        .map(|(_, l)| format!("{l}\n"))
        .collect();
    let f = d.path().join("gap.csv");
    std::fs::write(&f, gapped).unwrap();
    let o = locate_with(&f, &toml, &d.path().join("est.csv"), &[]);
    assert_code(&o, 0);
    assert!(
        stderr(&o).contains("1 time gap(s) in the pass")
            && stderr(&o).contains("before data row 250"),
        "{}",
        stderr(&o)
    );
    let o = locate_with(&csv, &toml, &d.path().join("est.csv"), &[]);
    assert!(!stderr(&o).contains("gap"), "{}", stderr(&o));
}

/// `dipole simulate` wrote the CSV, then the scenario: a folder in the
/// place of gradiometer.toml failed with exit 1 after the CSV was
/// replaced. Both are checked first (exit 2, nothing replaced) and
/// written as a set.
#[test]
fn a_folder_in_the_place_of_the_scenario_replaces_nothing() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("g");
    let (csv, toml) = simulate_into(&out, None);
    std::fs::remove_file(&toml).unwrap();
    std::fs::create_dir(&toml).unwrap();
    let before = std::fs::read(&csv).unwrap();
    let o = aeromag(&["dipole", "simulate", "--seed", "7", "--out", p(&out)]);
    assert_code(&o, 2);
    assert!(stderr(&o).contains("gradiometer.toml"), "{}", stderr(&o));
    assert!(
        std::fs::read(&csv).unwrap() == before,
        "the CSV was replaced"
    );
    std::fs::remove_dir(&toml).unwrap();
    assert_code(
        &aeromag(&["dipole", "simulate", "--seed", "7", "--out", p(&out)]),
        0,
    );
    assert!(std::fs::read(&csv).unwrap() != before);
    assert!(std::fs::read_to_string(&toml).unwrap().contains("seed = 7"));
}
