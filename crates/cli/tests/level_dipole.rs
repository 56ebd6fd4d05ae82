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

/// A small simulated survey (six lines, two ties) rewritten by `edit`,
/// which gets the header's names and each row's cells (comments dropped).
fn edited_survey(
    dir: &std::path::Path,
    name: &str,
    edit: impl Fn(&mut Vec<String>, bool),
) -> std::path::PathBuf {
    let config = dir.join("small.toml");
    std::fs::write(
        &config,
        "[pattern]\nline_count = 6\nline_length_m = 3000.0\ntie_count = 2\ntie_spacing_m = 1500.0\n",
    )
    .unwrap();
    let input = simulate_with(dir, "survey", "4", Some(&config));
    let text = std::fs::read_to_string(&input).unwrap();
    let mut out = String::new();
    let mut header = true;
    for line in text.lines().filter(|l| !l.starts_with('#')) {
        let mut cells: Vec<String> = line.split(',').map(str::to_string).collect();
        edit(&mut cells, header);
        header = false;
        out.push_str(&cells.join(","));
        out.push('\n');
    }
    let path = dir.join(name);
    std::fs::write(&path, out).unwrap();
    path
}

fn level_default(
    input: &std::path::Path,
    out: &std::path::Path,
    extra: &[&str],
) -> std::process::Output {
    run_on("level", input, out, extra)
}

/// The default column is the compensated one whatever the header's case
/// (an upper-cased `MAG_COMP` was passed over for the raw `mag`), and
/// `grid` then takes its levelled form; the column is printed first.
#[test]
fn level_and_grid_default_to_the_compensated_column_in_any_case() {
    let d = tempfile::tempdir().unwrap();
    // MAG_COMP: the reading less 10 nT, so that it is told from MAG.
    let input = edited_survey(d.path(), "upper.csv", |cells, header| {
        let mag = cells[10].clone();
        if header {
            cells.iter_mut().for_each(|c| *c = c.to_uppercase());
            cells.push("MAG_COMP".into());
        } else {
            cells.push(format!("{}", mag.parse::<f64>().unwrap() - 10.0));
        }
    });
    assert!(
        std::fs::read_to_string(&input)
            .unwrap()
            .starts_with("TIME,LAT")
    );
    let lev = d.path().join("lev.csv");
    let o = level_default(&input, &lev, &[]);
    assert_code(&o, 0);
    let (s, e) = (stdout(&o), stderr(&o));
    assert!(s.starts_with("levelling MAG_COMP\n"), "{s}");
    assert!(s.contains("(column MAG_COMP_level)"), "{s}");
    assert!(!e.contains("uncompensated-default"), "{e}");
    // The reference channels are there but not subtracted: a note says so
    // and names `--reference auto`; not when `none` is chosen.
    assert!(
        e.contains("note: the file has the reference channels diurnal and igrf")
            && e.contains("--reference auto"),
        "{e}"
    );
    let lev2 = d.path().join("lev2.csv");
    let o = level_default(&input, &lev2, &["--reference", "none"]);
    assert_code(&o, 0);
    assert!(!stderr(&o).contains("reference channels"), "{}", stderr(&o));
    let g = run_on("grid", &lev, &d.path().join("g.tif"), &[]);
    assert_code(&g, 0);
    assert!(
        stdout(&g).starts_with("gridded MAG_COMP_level "),
        "{}",
        stdout(&g)
    );
    assert!(
        !stderr(&g).contains("uncompensated-default"),
        "{}",
        stderr(&g)
    );
}

/// After a multi-sensor `compensate` (`mag_1_uc` mapped onto `mag`,
/// `mag_<k>_comp` per sensor) the first sensor's compensated reading is
/// levelled, not the raw `mag`; a file with the raw reading only is
/// levelled with the warning [uncompensated-default].
#[test]
fn level_prefers_the_multi_sensor_compensated_reading_and_warns_of_the_raw_one() {
    let d = tempfile::tempdir().unwrap();
    let input = edited_survey(d.path(), "sgl.csv", |cells, header| {
        if header {
            cells[10] = "mag_1_uc".into();
            cells.extend(["mag_1_comp".into(), "mag_2_comp".into()]);
        } else {
            let mag: f64 = cells[10].parse().unwrap();
            cells.extend([format!("{}", mag - 10.0), format!("{}", mag - 20.0)]);
        }
    });
    let lev = d.path().join("lev.csv");
    let o = level_default(&input, &lev, &[]);
    assert_code(&o, 0);
    assert!(
        stdout(&o).starts_with("levelling mag_1_comp\n"),
        "{}",
        stdout(&o)
    );
    assert!(!stderr(&o).contains("uncompensated"), "{}", stderr(&o));
    let g = run_on("grid", &lev, &d.path().join("g.tif"), &[]);
    assert_code(&g, 0);
    assert!(
        stdout(&g).starts_with("gridded mag_1_comp_level "),
        "{}",
        stdout(&g)
    );

    let d = tempfile::tempdir().unwrap();
    let raw = edited_survey(d.path(), "raw.csv", |_, _| {});
    let o = level_default(
        &raw,
        &d.path().join("raw_lev.csv"),
        &["--reference", "auto"],
    );
    assert_code(&o, 0);
    let e = stderr(&o);
    assert!(
        e.contains("warning: the column taken is `mag`, the uncompensated reading")
            && e.contains("--value")
            && e.contains("[uncompensated-default]"),
        "{e}"
    );
    assert!(
        stdout(&o).starts_with("levelling mag − diurnal − igrf\n"),
        "{}",
        stdout(&o)
    );
}
