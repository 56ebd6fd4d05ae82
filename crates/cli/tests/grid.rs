//! `aeromag grid` as a command: formats, defaults, messages and exit codes
//! (the gridding itself is tested in aeromag-grid, against GMT).

mod common;
use common::*;
use std::path::Path;

/// A small simulated survey: six lines 500 m apart, two ties.
fn survey(dir: &Path) -> std::path::PathBuf {
    let config = dir.join("small.toml");
    std::fs::write(
        &config,
        "[pattern]\nline_count = 6\nline_length_m = 3000.0\ntie_count = 2\ntie_spacing_m = 1500.0\n",
    )
    .unwrap();
    simulate_with(dir, "survey", "5", Some(&config))
}

fn grid(input: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "grid",
        "-i",
        input.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend(extra);
    aeromag(&args)
}

#[test]
fn grids_in_every_format_with_defaults_from_the_lines() {
    let d = tempfile::tempdir().unwrap();
    let input = survey(d.path());
    let asc = d.path().join("mag.asc");
    let o = grid(&input, &asc, &[]);
    assert_code(&o, 0);
    let s = stdout(&o);
    assert!(s.contains("gridded mag"), "{s}");
    assert!(
        s.contains("6 traverse lines") && s.contains("(2 other lines)"),
        "{s}"
    );
    assert!(
        (s.contains("spacing 499.") || s.contains("spacing 500.")) && s.contains("cell 100 m"),
        "{s}"
    );
    assert!(
        s.contains("UTM zone 37N (EPSG:32637)") && s.contains("sweeps on the final grid"),
        "{s}"
    );
    let header = std::fs::read_to_string(&asc).unwrap();
    assert!(header.starts_with("ncols"), "{}", &header[..100]);
    assert!(d.path().join("mag.prj").exists());
    for (name, extra) in [
        ("mag.tif", vec!["--cell", "100"]),
        (
            "mag.nc",
            vec!["--method", "bidirectional", "--utm-zone", "37N"],
        ),
        (
            "t.nc",
            vec![
                "--column",
                "true_anomaly",
                "--tension",
                "0.5",
                "--blanking",
                "300",
            ],
        ),
    ] {
        let out = d.path().join(name);
        let o = grid(&input, &out, &extra);
        assert_code(&o, 0);
        assert!(out.exists(), "{name}");
    }
    let o = grid(
        &input,
        &d.path().join("b.tif"),
        &["--method", "bidirectional"],
    );
    assert!(stdout(&o).contains("bi-directional"), "{}", stdout(&o));
}

#[test]
fn bad_arguments_and_files_exit_with_code_2() {
    let d = tempfile::tempdir().unwrap();
    let input = survey(d.path());
    for (extra, out, needle) in [
        (vec![], "g.png", "png"),
        (vec!["--column", "nope"], "g.tif", "nope"),
        (vec!["--tension", "1.5"], "g.tif", "tension"),
        (vec!["--utm-zone", "61N"], "g.tif", "61"),
        (vec!["--cell", "0"], "g.tif", "cell"),
        (vec!["--tension", "1e300"], "g.tif", "tension = 1e300 is"),
        // The grid library's own errors (the extent is checked before the
        // file is read) are bad input too; they exited 1.
        (
            vec!["--cell", "100", "--extent=1,0,0,1"],
            "g.tif",
            "not a finite area",
        ),
        (
            vec!["--cell", "100", "--extent=0,1e9,0,1e9"],
            "g.tif",
            "10000001 × 10000001 nodes",
        ),
        // Not metres: every position moved off the survey.
        (vec!["--lever-arm=5000,0,0"], "g.tif", "longer than 1000 m"),
        // Beyond the integers: it was "a 0 × 2 grid".
        (
            vec!["--cell", "100", "--extent=-1e300,1e300,0,1"],
            "g.tif",
            "2e298 × 2 nodes at a 100 m cell is more than",
        ),
    ] {
        let o = grid(&input, &d.path().join(out), &extra);
        assert_code(&o, 2);
        assert!(stderr(&o).contains(needle), "{extra:?}: {}", stderr(&o));
        assert!(!d.path().join(out).exists());
    }
    // Without line labels the cell size must be given.
    let text = std::fs::read_to_string(&input).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let keep: Vec<usize> = (0..header.len()).filter(|&k| header[k] != "line").collect();
    let mut csv = String::new();
    for l in std::iter::once(header.join(",").as_str()).chain(lines) {
        let cells: Vec<&str> = l.split(',').collect();
        csv.push_str(&keep.iter().map(|&k| cells[k]).collect::<Vec<_>>().join(","));
        csv.push('\n');
    }
    let nolines = d.path().join("nolines.csv");
    std::fs::write(&nolines, csv).unwrap();
    let o = grid(&nolines, &d.path().join("n.tif"), &[]);
    assert_code(&o, 2);
    assert!(stderr(&o).contains("cell size"), "{}", stderr(&o));
    assert_code(
        &grid(&nolines, &d.path().join("n.tif"), &["--cell", "200"]),
        0,
    );
}

#[test]
fn derived_grids_and_micro_levelling_from_the_command_line() {
    let d = tempfile::tempdir().unwrap();
    let input = survey(d.path());
    let g = d.path().join("mag.tif");
    assert_code(&grid(&input, &g, &["--column", "true_anomaly"]), 0);
    let run = |args: &[&str]| {
        let mut a = vec!["derive", "-i", g.to_str().unwrap()];
        a.extend(args);
        aeromag(&a)
    };
    let fvd = d.path().join("fvd.nc");
    let o = run(&["--vertical-derivative", "--out", fvd.to_str().unwrap()]);
    assert_code(&o, 0);
    assert!(
        stdout(&o).contains("vertical derivative") && stdout(&o).contains("nT/m"),
        "{}",
        stdout(&o)
    );
    let up = d.path().join("up.asc");
    assert_code(&run(&["--upward", "150", "--out", up.to_str().unwrap()]), 0);
    let zero = d.path().join("zero.tif");
    let o = run(&[
        "--minus",
        g.to_str().unwrap(),
        "--out",
        zero.to_str().unwrap(),
    ]);
    assert_code(&o, 0);
    assert!(
        stdout(&o).contains("mean 0.0000, std 0.0000"),
        "{}",
        stdout(&o)
    );
    // Exactly one product; unreadable grids are bad input.
    assert_code(&run(&["--out", zero.to_str().unwrap()]), 2);
    assert_code(
        &run(&[
            "--upward",
            "1",
            "--vertical-derivative",
            "--out",
            zero.to_str().unwrap(),
        ]),
        2,
    );
    std::fs::write(d.path().join("bad.tif"), "not a tiff").unwrap();
    let o = aeromag(&[
        "derive",
        "-i",
        d.path().join("bad.tif").to_str().unwrap(),
        "--vertical-derivative",
        "--out",
        zero.to_str().unwrap(),
    ]);
    assert_code(&o, 2);
    assert!(stderr(&o).contains("bad.tif"), "{}", stderr(&o));

    let out = d.path().join("micro.csv");
    let o = aeromag(&[
        "microlevel",
        "-i",
        input.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_code(&o, 0);
    let s = stdout(&o);
    assert!(
        s.contains("mag → mag_mlev") && s.contains("correction mag_mlev_corr: RMS"),
        "{s}"
    );
    let header = std::fs::read_to_string(&out).unwrap();
    let header = header.lines().find(|l| !l.starts_with('#')).unwrap();
    assert!(header.ends_with("mag_mlev,mag_mlev_corr"), "{header}");
    // Running it again on its own output: the column exists already.
    let again = d.path().join("again.csv");
    assert_code(
        &aeromag(&[
            "microlevel",
            "-i",
            out.to_str().unwrap(),
            "--column",
            "mag",
            "--out",
            again.to_str().unwrap(),
        ]),
        2,
    );
}
