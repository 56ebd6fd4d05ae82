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
    run_on("grid", input, out, extra)
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
        ("mag.gxf", vec!["--cell", "100"]),
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
    // The same grid as GXF and GeoTIFF (float32 both).
    let (tif, gxf) = (
        aeromag::grid::format::read_grid(&d.path().join("mag.tif")).unwrap(),
        aeromag::grid::format::read_grid(&d.path().join("mag.gxf")).unwrap(),
    );
    assert_eq!((tif.geometry, tif.crs), (gxf.geometry, gxf.crs));
    let bits = |g: &aeromag::grid::Grid| -> Vec<u32> {
        g.values.iter().map(|v| (*v as f32).to_bits()).collect()
    };
    assert_eq!(bits(&tif), bits(&gxf));
    // Oasis montaj's own grid, named with its decoration: the file
    // `mag.grd`, the same float32 values, and a note that its coordinate
    // system is not recorded.
    let o = grid(&input, &d.path().join("mag.grd(GRD)"), &["--cell", "100"]);
    assert_code(&o, 0);
    assert!(stdout(&o).contains("(Geosoft)"), "{}", stdout(&o));
    assert!(
        stderr(&o).contains("does not record its coordinate system (WGS 84 / UTM zone 37N)"),
        "{}",
        stderr(&o)
    );
    let grd = aeromag::grid::format::read_grid(&d.path().join("mag.grd")).unwrap();
    assert_eq!((grd.geometry, grd.crs), (tif.geometry, None));
    assert_eq!(bits(&grd), bits(&tif));
    let o = grid(
        &input,
        &d.path().join("b.tif"),
        &["--method", "bidirectional"],
    );
    assert!(stdout(&o).contains("bi-directional"), "{}", stdout(&o));
}

/// The warning of a solve stopped by the sweep limit names the flags that
/// raise it (it said "raise the sweep limit", which no flag set), and
/// they act: 10 sweeps stop short, a looser limit converges sooner.
#[test]
fn the_sweep_and_convergence_limits_are_flags() {
    let d = tempfile::tempdir().unwrap();
    let input = survey(d.path());
    let sweeps = |o: &std::process::Output| -> usize {
        let s = stdout(o);
        let line = s.lines().find(|l| l.contains("sweeps on the final grid"));
        let words: Vec<&str> = line.expect(&s).split_whitespace().collect();
        let k = words.iter().position(|w| *w == "sweeps").unwrap();
        words[k - 1].parse().unwrap()
    };
    let o = grid(&input, &d.path().join("a.tif"), &["--max-sweeps", "10"]);
    assert_code(&o, 0);
    assert!(stdout(&o).contains("NOT converged"), "{}", stdout(&o));
    assert!(
        stderr(&o).contains("raise the sweep limit (--max-sweeps) or the convergence limit"),
        "{}",
        stderr(&o)
    );
    let o = grid(&input, &d.path().join("b.tif"), &["--max-sweeps", "5000"]);
    assert_code(&o, 0);
    assert!(stdout(&o).contains(", converged"), "{}", stdout(&o));
    let strict = sweeps(&o);
    let o = grid(
        &input,
        &d.path().join("c.tif"),
        &["--max-sweeps", "5000", "--convergence", "1"],
    );
    assert_code(&o, 0);
    assert!(sweeps(&o) < strict, "{} against {strict}", sweeps(&o));
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
        (
            vec!["--max-sweeps", "0"],
            "g.tif",
            "max sweeps = 0 is out of range",
        ),
        (
            vec!["--max-sweeps", "1000000000"],
            "g.tif",
            "max sweeps = 1000000000 is out of range: 1 to 100000",
        ),
        (vec!["--convergence", "0"], "g.tif", "--convergence"),
        (vec!["--convergence", "nan"], "g.tif", "--convergence"),
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
    // Lines a micrometre apart (positions shrunk about the survey): a grid
    // of 2.5e-7 m cells was written, which derive then refused.
    let lat = header.iter().position(|c| *c == "lat").unwrap();
    let lon = header.iter().position(|c| *c == "lon").unwrap();
    let mut tiny = String::new();
    for (k, l) in text.lines().filter(|l| !l.starts_with('#')).enumerate() {
        let mut cells: Vec<String> = l.split(',').map(str::to_string).collect();
        if k > 0 {
            for (c, about) in [(lat, 56.0), (lon, 38.0)] {
                let v: f64 = cells[c].parse().unwrap();
                cells[c] = (about + (v - about) * 1e-9).to_string();
            }
        }
        tiny.push_str(&cells.join(","));
        tiny.push('\n');
    }
    let tiny_path = d.path().join("tiny.csv");
    std::fs::write(&tiny_path, tiny).unwrap();
    let o = grid(&tiny_path, &d.path().join("t.tif"), &[]);
    assert_code(&o, 2);
    assert!(
        stderr(&o).contains("tiny.csv': its lines are")
            && stderr(&o).contains("give the cell size"),
        "{}",
        stderr(&o)
    );
    assert!(!d.path().join("t.tif").exists());
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
    // The grid may be given without --input, but not both ways.
    let fvd2 = d.path().join("fvd2.nc");
    let (gs, f2) = (g.to_str().unwrap(), fvd2.to_str().unwrap());
    let plain = aeromag(&["derive", gs, "--vertical-derivative", "--out", f2]);
    assert_code(&plain, 0);
    assert_eq!(std::fs::read(&fvd).unwrap(), std::fs::read(&fvd2).unwrap());
    let both = aeromag(&["derive", "-i", gs, gs, "--vertical-derivative", "--out", f2]);
    assert_code(&both, 2);
    assert!(
        stderr(&both).contains("cannot be used with"),
        "{}",
        stderr(&both)
    );
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

/// An ESRI ASCII grid `name` in `dir`: `ncols × nrows` at `cell` m, the
/// rows `body` (north first).
fn asc(dir: &Path, name: &str, size: (usize, usize), cell: &str, body: &str) -> String {
    let path = dir.join(name);
    std::fs::write(
        &path,
        format!(
            "ncols {}\nnrows {}\nxllcenter 0\nyllcenter 0\ncellsize {cell}\nNODATA_value -99999\n{body}",
            size.0, size.1
        ),
    )
    .unwrap();
    path.to_str().unwrap().to_string()
}

/// `aeromag derive -i INPUT <product…> --out OUT`.
fn derive(input: &str, product: &[&str], out: &Path) -> std::process::Output {
    let mut a = vec!["derive", "-i", input];
    a.extend(product);
    a.extend(["--out", out.to_str().unwrap()]);
    aeromag(&a)
}

/// Exit code 2, a message naming `what`, of reasonable length, and no
/// output file.
fn assert_refused(o: &std::process::Output, what: &[&str], out: &Path) {
    assert_code(o, 2);
    let e = stderr(o);
    for w in what {
        assert!(e.contains(w), "{w}: {e}");
    }
    assert!(e.len() < 400 && !e.contains("inf "), "{e}");
    assert!(!out.exists(), "{e}");
}

#[test]
fn derive_refuses_values_heights_and_cells_it_cannot_process() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("o.asc");
    let rows = "1 2 3\n4 5 6\n7 8 9\n";
    let ok = asc(d.path(), "ok.asc", (3, 3), "100", rows);
    // Values beyond float32, or infinite: refused naming row and column
    // (they gave inf/-inf nodes and a 300-digit mean with exit code 0).
    let huge = asc(
        d.path(),
        "v.asc",
        (3, 3),
        "100",
        "1e300 2 3\n4 5 6\n7 8 9\n",
    );
    for product in [&["--vertical-derivative"][..], &["--upward", "100"]] {
        let o = derive(&huge, product, &out);
        assert_refused(&o, &["v.asc", "row 1, column 1", "1e300"], &out);
    }
    for (name, value, shown) in [
        ("big.asc", "1e400", "is inf"),
        ("neg.asc", "-1e308", "is -1e308"),
        ("inf.asc", "inf", "is inf"),
        ("max.asc", "1e308", "is 1e308"),
    ] {
        let bad = asc(
            d.path(),
            name,
            (3, 3),
            "100",
            &format!("1 2 3\n4 {value} 6\n7 8 9\n"),
        );
        let o = derive(&ok, &["--minus", &bad], &out);
        assert_refused(&o, &[name, "row 2, column 2", shown], &out);
        let o = derive(&bad, &["--vertical-derivative"], &out);
        assert_refused(&o, &[name, "row 2, column 2", shown], &out);
    }
    // NaN is a blank node (documented): it stays blank.
    let nan = asc(
        d.path(),
        "nan.asc",
        (3, 3),
        "100",
        "1 2 3\n4 nan 6\n7 8 9\n",
    );
    let o = derive(&nan, &["--vertical-derivative"], &out);
    assert_code(&o, 0);
    assert!(stdout(&o).contains("8 not blank"), "{}", stdout(&o));
    let text = std::fs::read_to_string(&out).unwrap();
    assert_eq!(
        text.lines().nth(7).unwrap().split(' ').nth(1),
        Some("-99999")
    );
    std::fs::remove_file(&out).unwrap();
    // Heights: 1e-8 cell to 10 × the extent (3 × 100 m here).
    for h in ["1e308", "5e-324", "0", "3001"] {
        let o = derive(&ok, &["--upward", h], &out);
        assert_refused(
            &o,
            &["continuation height", "between 0.000001 and 3000 m"],
            &out,
        );
    }
    let o = derive(&ok, &["--upward", "3000"], &out);
    assert_code(&o, 0);
    assert!(stdout(&o).contains("continued up 3000 m"), "{}", stdout(&o));
    std::fs::remove_file(&out).unwrap();
    // Cell sizes: 1e-6 to 1e6 m.
    for cell in ["1e-308", "1e308", "-1e308"] {
        let bad = asc(d.path(), "c.asc", (3, 3), cell, rows);
        let o = derive(&bad, &["--vertical-derivative"], &out);
        assert_refused(&o, &["c.asc", "cell size", cell], &out);
    }
}

#[test]
fn derive_refuses_a_header_larger_than_its_file_without_allocating_it() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("o.asc");
    let hd = asc(d.path(), "hd.asc", (15800, 15800), "1", "1 2 3\n");
    let start = std::time::Instant::now();
    let o = derive(&hd, &["--vertical-derivative"], &out);
    assert_refused(&o, &["hd.asc", "declares 15800 × 15800"], &out);
    // It allocated 2 GB and took 2 s.
    assert!(start.elapsed().as_secs_f64() < 1.0, "{:?}", start.elapsed());
}

#[test]
fn derive_on_tiny_and_blank_grids_gives_an_error_or_a_valid_grid() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("o.asc");
    let one = asc(d.path(), "one.asc", (1, 1), "100", "5\n");
    let row = asc(d.path(), "row.asc", (2, 1), "100", "5 6\n");
    let square = asc(d.path(), "sq.asc", (2, 2), "100", "5 6\n7 8\n");
    let blank = asc(
        d.path(),
        "blank.asc",
        (2, 2),
        "100",
        "-99999 -99999\n-99999 -99999\n",
    );
    for grid in [&one, &row] {
        for product in [&["--vertical-derivative"][..], &["--upward", "10"]] {
            let o = derive(grid, product, &out);
            assert_refused(&o, &[grid.as_str(), "too small to filter"], &out);
        }
    }
    for product in [&["--vertical-derivative"][..], &["--upward", "10"]] {
        let o = derive(&blank, product, &out);
        assert_refused(&o, &["blank.asc", "no value"], &out);
        let o = derive(&square, product, &out);
        assert_code(&o, 0);
        assert!(stdout(&o).contains("4 not blank"), "{}", stdout(&o));
        std::fs::remove_file(&out).unwrap();
    }
    // A difference without any value (it wrote a blank grid, "mean NaN").
    let o = derive(&blank, &["--minus", &blank], &out);
    assert_refused(&o, &["blank.asc", "no value"], &out);
    for grid in [&one, &row, &square] {
        let o = derive(grid, &["--minus", grid], &out);
        assert_code(&o, 0);
        assert!(stdout(&o).contains("mean 0.0000"), "{}", stdout(&o));
        std::fs::remove_file(&out).unwrap();
    }
    // Grids of other nodes: said as nodes, not as a Debug dump of the
    // geometry after "cannot grid:" (which no derived product does).
    let o = derive(&square, &["--minus", &row], &out);
    assert_refused(
        &o,
        &[
            "sq.asc minus",
            "the grids' nodes differ: 2 × 2 nodes of 100 m from (0, 0) against 2 × 1 nodes",
        ],
        &out,
    );
    for o in [o, derive(&one, &["--vertical-derivative"], &out)] {
        let e = stderr(&o);
        assert!(
            !e.contains("GridGeometry") && !e.contains("cannot grid"),
            "{e}"
        );
    }
}

/// The grid's format and path are checked before the work: `--out g.png`
/// was refused only after the whole solve (here the input does not even
/// exist, and the format is what is reported).
#[test]
fn an_unknown_grid_format_is_refused_before_the_work() {
    let d = tempfile::tempdir().unwrap();
    let o = grid(&d.path().join("nosuch.csv"), &d.path().join("g.png"), &[]);
    assert_code(&o, 2);
    assert!(stderr(&o).contains("unknown grid format"), "{}", stderr(&o));
    assert_eq!(stdout(&o), "");
}

/// A misspelt `--column` gets a "did you mean" among the file's columns.
#[test]
fn a_misspelt_column_gets_a_suggestion() {
    let d = tempfile::tempdir().unwrap();
    let input = survey(d.path());
    let o = grid(&input, &d.path().join("g.tif"), &["--column", "mga"]);
    assert_code(&o, 2);
    assert!(
        stderr(&o).contains("required column 'mga' is missing (did you mean 'mag'?)"),
        "{}",
        stderr(&o)
    );
}

/// Three nodes with data (a plane) gridded by minimum curvature: the
/// report names the method (it said "bi-directional … (Akima)" when the
/// solve reported no grid level).
#[test]
fn minimum_curvature_without_sweeps_is_labelled_as_such() {
    let d = tempfile::tempdir().unwrap();
    let input = d.path().join("few.csv");
    let mut text = String::from("time,lat,lon,line,mag\n");
    // Three short lines far apart (diagonally): one node each.
    for (k, (lat0, lon)) in [(56.0, 38.0), (56.3, 38.5), (56.6, 39.0)]
        .iter()
        .enumerate()
    {
        for j in 0..3 {
            let t = 1000 * k + 10 * j;
            let lat = lat0 + 0.001 * j as f64;
            text.push_str(&format!("{t},{lat},{lon},{},{}\n", k + 1, 50_000 + 10 * k));
        }
    }
    std::fs::write(&input, text).unwrap();
    let o = grid(
        &input,
        &d.path().join("g.tif"),
        &["--method", "min-curvature"],
    );
    assert_code(&o, 0);
    let s = stdout(&o);
    assert!(
        s.contains("minimum curvature, tension 0.25: 3 nodes hold data"),
        "{s}"
    );
    assert!(!s.contains("bi-directional"), "{s}");
}

/// A survey file with projected positions only (`X`, `Y`, no lat/lon, as
/// a Geosoft XYZ export has them) grids: without a zone, with no
/// coordinate system, said on stdout, warned of (`[no-crs]`) and no
/// `.prj` written; with `--utm-zone`, the same grid file, byte for byte,
/// as its latitudes and longitudes give. `--xy` names other columns; a
/// missing one or a single name is an error (exit 2).
#[test]
fn projected_positions_are_gridded_as_they_are() {
    let d = tempfile::tempdir().unwrap();
    let input = survey(d.path());
    let xy_file = projected_survey(&input, d.path());

    let geodetic = d.path().join("geodetic.asc");
    assert_code(&grid(&input, &geodetic, &[]), 0);
    let plain = d.path().join("plain.asc");
    let o = grid(&xy_file, &plain, &[]);
    assert_code(&o, 0);
    assert!(
        stdout(&o).contains("cell 100 m, no coordinate system"),
        "{}",
        stdout(&o)
    );
    let e = stderr(&o);
    assert!(
        e.contains("[no-crs]") && e.contains("projected columns X (easting) and Y"),
        "{e}"
    );
    assert!(!d.path().join("plain.prj").exists());
    let body = |p: &Path| std::fs::read_to_string(p).unwrap();
    assert_eq!(body(&plain), body(&geodetic));
    for (name, extra) in [
        ("zone.asc", vec!["--utm-zone", "37N"]),
        ("named.asc", vec!["--utm-zone", "37N", "--xy", "e2,n2"]),
    ] {
        let out = d.path().join(name);
        let o = grid(&xy_file, &out, &extra);
        assert_code(&o, 0);
        assert!(
            stdout(&o).contains("UTM zone 37N (EPSG:32637)"),
            "{}",
            stdout(&o)
        );
        assert!(!stderr(&o).contains("[no-crs]"), "{}", stderr(&o));
        assert_eq!(body(&out), body(&geodetic), "{name}");
        assert_eq!(
            body(&out.with_extension("prj")),
            body(&geodetic.with_extension("prj"))
        );
    }
    let o = grid(&xy_file, &d.path().join("m.asc"), &["--xy", "east,N2"]);
    assert_code(&o, 2);
    assert!(stderr(&o).contains("east"), "{}", stderr(&o));
    let o = grid(&xy_file, &d.path().join("m.asc"), &["--xy", "X"]);
    assert_code(&o, 2);
    assert!(stderr(&o).contains("EASTING,NORTHING"), "{}", stderr(&o));
}

/// The survey `input` with UTM zone 37N eastings and northings `X`, `Y`
/// (and copies `E2`, `N2`) in place of lat/lon: `xy.csv` in `dir`.
fn projected_survey(input: &Path, dir: &Path) -> std::path::PathBuf {
    use aeromag::grid::projection::{Utm, UtmZone};
    let table = aeromag::io::read_table(input, &aeromag::io::ReadOptions::default()).unwrap();
    let zone: UtmZone = "37N".parse().unwrap();
    let (lat, lon) = (table.column("lat").unwrap(), table.column("lon").unwrap());
    let (x, y) = Utm::new(zone).forward_all(lat, lon).unwrap();
    let mut xy = aeromag::io::FlightTable::new();
    for name in ["time", "line", "alt", "mag"] {
        xy.add_column(name, table.column(name).unwrap().to_vec())
            .unwrap();
    }
    xy.add_column("X", x.clone()).unwrap();
    xy.add_column("Y", y.clone()).unwrap();
    xy.add_column("E2", x).unwrap();
    xy.add_column("N2", y).unwrap();
    let xy_file = dir.join("xy.csv");
    aeromag::io::write_csv(&xy, &xy_file).unwrap();
    xy_file
}

/// `level` of the same survey with projected positions: their UTM zone is
/// needed (exit 2 naming --utm-zone without it), and with it the levelled
/// column is written.
#[test]
fn projected_positions_are_levelled_given_their_zone() {
    let d = tempfile::tempdir().unwrap();
    let input = survey(d.path());
    let xy_file = projected_survey(&input, d.path());
    let out = d.path().join("lev.csv");
    let o = run_on("level", &xy_file, &out, &[]);
    assert_code(&o, 2);
    assert!(stderr(&o).contains("--utm-zone"), "{}", stderr(&o));
    assert!(!out.exists());
    let o = run_on("level", &xy_file, &out, &["--utm-zone", "37N"]);
    assert_code(&o, 0);
    assert!(
        stderr(&o).contains("projected columns X (easting)"),
        "{}",
        stderr(&o)
    );
    let header = std::fs::read_to_string(&out).unwrap();
    assert!(header.lines().next().unwrap().contains("mag_level"));
}

/// `--map` draws the grid (PNG or SVG by the extension, the same bytes
/// run after run), on `grid` with the flight lines and on `derive`; another
/// extension is refused before the work, nothing written.
#[test]
fn grids_are_drawn_as_maps() {
    let dir = tempfile::tempdir().unwrap();
    let input = survey(dir.path());
    let (tif, png) = (dir.path().join("g.tif"), dir.path().join("g.png"));
    let o = grid(
        &input,
        &tif,
        &["--cell", "100", "--map", png.to_str().unwrap()],
    );
    assert_code(&o, 0);
    assert!(stdout(&o).contains("map: "), "{}", stdout(&o));
    let bytes = std::fs::read(&png).unwrap();
    assert!(bytes.starts_with(b"\x89PNG\r\n\x1a\n"));
    // The picture is 1200 × 900 (IHDR: width, height, big-endian).
    assert_eq!(&bytes[16..24], &[0, 0, 4, 176, 0, 0, 3, 132]);
    assert_code(
        &grid(
            &input,
            &tif,
            &["--cell", "100", "--map", png.to_str().unwrap()],
        ),
        0,
    );
    assert_eq!(std::fs::read(&png).unwrap(), bytes, "deterministic");
    let svg = dir.path().join("d.svg");
    let o = aeromag(&[
        "derive",
        "-i",
        tif.to_str().unwrap(),
        "--vertical-derivative",
        "--out",
        dir.path().join("d.tif").to_str().unwrap(),
        "--map",
        svg.to_str().unwrap(),
    ]);
    assert_code(&o, 0);
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(
        text.contains("<svg") && text.contains("vertical derivative"),
        "{}",
        &text[..200]
    );
    let jpg = dir.path().join("g.jpg");
    let other = dir.path().join("other.tif");
    let o = grid(&input, &other, &["--map", jpg.to_str().unwrap()]);
    assert_code(&o, 2);
    assert!(
        stderr(&o).contains("PNG (.png) or SVG (.svg)"),
        "{}",
        stderr(&o)
    );
    assert!(!other.exists() && !jpg.exists());
}
