//! `aeromag calibrate`, `compensate`, `report` and `observability` as
//! commands: arguments, exit codes, files written, messages. What the fits
//! find is tested through the library (crates/aeromag/tests).

mod common;
use common::*;

#[test]
fn calibrate_compensate_report_keep_every_row() {
    let d = tempfile::tempdir().unwrap();
    let cal = simulate(d.path(), "calibration", "5");
    let model = d.path().join("m.json");
    let o = aeromag(&[
        "calibrate",
        "--input",
        cal.to_str().unwrap(),
        "--model",
        model.to_str().unwrap(),
    ]);
    assert_code(&o, 0);
    assert!(!stderr(&o).contains("poorly determined"), "{}", stderr(&o));
    // The interference by part, per manoeuvre of the simulated box.
    let out = stdout(&o);
    assert!(out.contains("interference by part"), "{out}");
    for group in ["roll ", "pitch ", "yaw ", "manoeuvres ", "between "] {
        assert!(out.lines().any(|l| l.starts_with(group)), "{group}: {out}");
    }
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    assert_eq!(m["format"], "aeromag-model/2");
    assert_eq!(m["method"], "ls");
    assert_eq!(m["trim"], 20);
    assert!(!m["coefficients"].as_array().unwrap().is_empty());
    // The fit's notes reach the user on stderr (which lags, and why, is
    // tested in crates/aeromag/tests/tolles_lawson.rs).
    assert!(
        stderr(&o).contains("chosen (likelihood-ratio test)"),
        "{}",
        stderr(&o)
    );
    // Blank out some flux values: those rows stay, flagged.
    let text = std::fs::read_to_string(&cal).unwrap();
    let mut lines: Vec<String> = text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(String::from)
        .collect();
    let header: Vec<&str> = lines[0].split(',').collect();
    let fx = header.iter().position(|h| *h == "flux_x").unwrap();
    let n_in = lines.len() - 1;
    for row in [100usize, 101, 2000] {
        let mut cells: Vec<String> = lines[row + 1].split(',').map(String::from).collect();
        cells[fx] = String::new();
        lines[row + 1] = cells.join(",");
    }
    let holed = d.path().join("holed.csv");
    std::fs::write(&holed, lines.join("\n")).unwrap();
    let out = d.path().join("comp.csv");
    let o = compensate(&model, &holed, &out);
    assert_code(&o, 0);
    assert!(stderr(&o).contains("3 of"), "{}", stderr(&o));
    let comp = std::fs::read_to_string(&out).unwrap();
    let rows: Vec<&str> = comp.lines().filter(|l| !l.starts_with('#')).collect();
    assert_eq!(rows.len() - 1, n_in, "one output row per input row");
    let h: Vec<&str> = rows[0].split(',').collect();
    let flag = h.iter().position(|c| *c == "comp_flag").unwrap();
    let flagged: Vec<usize> = (1..rows.len())
        .filter(|&i| {
            rows[i]
                .split(',')
                .nth(flag)
                .and_then(|v| v.parse::<f64>().ok())
                == Some(1.0)
        })
        .map(|i| i - 1)
        .collect();
    assert_eq!(flagged, vec![100, 101, 2000]);

    let rep = d.path().join("rep");
    let o = aeromag(&[
        "report",
        "--input",
        out.to_str().unwrap(),
        "--model",
        model.to_str().unwrap(),
        "--out",
        rep.to_str().unwrap(),
    ]);
    assert_code(&o, 0);
    let html = std::fs::read_to_string(rep.join("index.html")).unwrap();
    for k in [
        "<svg",
        "Figure of merit",
        "coefficient",
        "Power spectral density",
    ] {
        assert!(html.contains(k), "{k} missing in the report");
    }
    assert!(rep.join("figures.json").exists());
    // A folder in the place of figures.json: the report is not replaced
    // either (index.html was written first, then figures.json failed).
    let html_before = std::fs::read(rep.join("index.html")).unwrap();
    std::fs::remove_file(rep.join("figures.json")).unwrap();
    std::fs::create_dir(rep.join("figures.json")).unwrap();
    let o = aeromag(&[
        "report",
        "--input",
        out.to_str().unwrap(),
        "--out",
        rep.to_str().unwrap(),
    ]);
    assert_code(&o, 2);
    assert!(stderr(&o).contains("figures.json"), "{}", stderr(&o));
    assert_eq!(std::fs::read(rep.join("index.html")).unwrap(), html_before);
    // One row selected: no time step to score by (was "invalid argument
    // `fs_hz`", naming neither the file nor the flag).
    let t0 = rows[1].split(',').next().unwrap();
    let one = d.path().join("rep1");
    let o = aeromag(&[
        "report",
        "--input",
        out.to_str().unwrap(),
        "--out",
        one.to_str().unwrap(),
        "--time-range",
        &format!("{t0},{t0}"),
    ]);
    assert_code(&o, 2);
    assert!(
        stderr(&o).contains("comp.csv") && stderr(&o).contains("no time step"),
        "{}",
        stderr(&o)
    );
    // `observability` prints the verdicts, or JSON.
    let o = aeromag(&["observability", "--input", cal.to_str().unwrap()]);
    assert_code(&o, 0);
    assert!(stdout(&o).contains("rank 16 of 16"), "{}", stdout(&o));
    let j = aeromag(&["observability", "--input", cal.to_str().unwrap(), "--json"]);
    assert_code(&j, 0);
    let v: serde_json::Value = serde_json::from_str(&stdout(&j)).unwrap();
    assert_eq!(v["estimability"].as_array().unwrap().len(), 16);
}

/// `calibrate --compensated` writes the model `calibrate` writes and the
/// flight `compensate` writes with it, from one reading of the flight;
/// the same file for both outputs is bad input.
#[test]
fn calibrate_writes_the_compensated_flight_as_compensate_does() {
    let d = tempfile::tempdir().unwrap();
    let cal = simulate(d.path(), "calibration-truncated", "4");
    let path = |name: &str| d.path().join(name);
    let (m1, c1, m2, c2) = (
        path("m1.json"),
        path("c1.csv"),
        path("m2.json"),
        path("c2.csv"),
    );
    // `calibrate` with the model file `m` and, if given, `--compensated c`.
    let calibrate = |m: &std::path::Path, c: Option<&std::path::Path>| {
        let mut args = vec!["calibrate", "--input", cal.to_str().unwrap()];
        args.extend(["--model", m.to_str().unwrap()]);
        if let Some(c) = c {
            args.extend(["--compensated", c.to_str().unwrap()]);
        }
        aeromag(&args)
    };
    let o = calibrate(&m1, Some(&c1));
    assert_code(&o, 0);
    let out = stdout(&o);
    let last = out.lines().last().unwrap();
    assert!(
        last.starts_with("compensated ") && last.ends_with(&format!("written to {}", c1.display())),
        "{out}"
    );
    assert_code(&calibrate(&m2, None), 0);
    assert_code(&compensate(&m2, &cal, &c2), 0);
    let read = |p: &std::path::Path| std::fs::read(p).unwrap();
    assert_eq!(read(&m1), read(&m2), "the model files");
    assert_eq!(read(&c1), read(&c2), "the compensated flights");
    let o = calibrate(&m1, Some(&m1));
    assert_code(&o, 2);
    assert!(stderr(&o).contains("name the same file"), "{}", stderr(&o));
}

#[test]
fn model_and_argument_errors_exit_2() {
    let d = tempfile::tempdir().unwrap();
    let cal = simulate(d.path(), "calibration-truncated", "7");
    let p = cal.to_str().unwrap();
    let model = d.path().join("m.json");
    let m = model.to_str().unwrap();
    for args in [
        vec![
            "calibrate",
            "--input",
            p,
            "--model",
            m,
            "--terms",
            "p3,i6,i5",
        ],
        vec!["calibrate", "--input", p, "--model", m, "--band", "0.9,0.1"],
        vec![
            "calibrate",
            "--input",
            p,
            "--model",
            m,
            "--convention",
            "fancy",
        ],
        vec!["calibrate", "--input", p, "--model", m, "--lambda", "-1"],
        vec![
            "calibrate",
            "--input",
            p,
            "--model",
            m,
            "--eddy-lag",
            "0,0.5",
        ],
        vec![
            "calibrate",
            "--input",
            p,
            "--model",
            m,
            "--eddy-lag",
            "fast",
        ],
        vec![
            "calibrate",
            "--input",
            p,
            "--model",
            m,
            "--terms",
            "p3,i5",
            "--eddy-lag",
            "0.3",
        ],
        vec![
            "calibrate",
            "--input",
            p,
            "--model",
            m,
            "--lever-arm",
            "1,2",
        ],
        vec![
            "calibrate",
            "--input",
            p,
            "--model",
            m,
            "--lever-arm",
            "-9.5,0,-0.6",
            "--date",
            "2025-13-01",
        ],
        vec![
            "calibrate",
            "--input",
            p,
            "--model",
            m,
            "--method",
            "kalman",
            "--kalman-noise",
            "1e-15,4e-4",
        ],
        vec![
            "calibrate",
            "--input",
            p,
            "--model",
            m,
            "--method",
            "kalman",
            "--kalman-noise",
            "1e-15,1e-15,0",
        ],
        // Empty values (an unset shell variable) were taken as `none`.
        vec!["calibrate", "--input", p, "--model", m, "--eddy-lag="],
        vec!["calibrate", "--input", p, "--model", m, "--reference="],
        vec!["calibrate", "--input", p, "--model", m, "--reference=,"],
        vec!["calibrate", "--input", p, "--model", m, "--series", "s.csv"],
        vec![
            "calibrate",
            "--input",
            p,
            "--model",
            m,
            "--field-order",
            "3",
        ],
        vec![
            "calibrate",
            "--input",
            p,
            "--model",
            m,
            "--method",
            "kalman",
            "--field-order",
            "7",
        ],
        vec![
            "calibrate",
            "--input",
            p,
            "--model",
            m,
            "--method",
            "kalman",
            "--tune",
            "--no-tune",
        ],
    ] {
        let o = aeromag(&args);
        assert_code(&o, 2);
    }
    assert_code(&aeromag(&["calibrate", "--input", p, "--model", m]), 0);
    let o = aeromag(&[
        "calibrate",
        "--input",
        p,
        "--model",
        m,
        "--method",
        "kalman",
        "--kalman-noise",
        "2e-15,1e-15,3e-4",
    ]);
    assert_code(&o, 0);
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("q1 = 2.000e-15"),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    // By default the Kalman method tunes its noise intensities, and --series
    // writes the smoothed field and innovations on every input row.
    let series = d.path().join("series.csv");
    let o = aeromag(&[
        "calibrate",
        "--input",
        p,
        "--model",
        m,
        "--method",
        "kalman",
        "--series",
        series.to_str().unwrap(),
    ]);
    assert_code(&o, 0);
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("tuned by maximum likelihood"),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    let out = std::fs::read_to_string(&series).unwrap();
    let data = |t: &str| {
        t.lines()
            .filter(|l| !l.starts_with('#'))
            .map(String::from)
            .collect::<Vec<_>>()
    };
    let (rows_in, rows_out) = (data(&std::fs::read_to_string(&cal).unwrap()), data(&out));
    assert_eq!(
        rows_in.len(),
        rows_out.len(),
        "one output row per input row"
    );
    let header: Vec<&str> = rows_out[0].split(',').collect();
    let col = |n: &str| {
        header
            .iter()
            .position(|h| *h == n)
            .unwrap_or_else(|| panic!("no column {n}"))
    };
    let (field, innov, sd) = (
        col("kalman_field"),
        col("kalman_innovation"),
        col("kalman_innovation_std"),
    );
    let num = |r: &str, c: usize| r.split(',').nth(c).and_then(|v| v.parse::<f64>().ok());
    // The series are on the rows the fit used (what they hold is tested in
    // the library).
    let with_series = rows_out
        .iter()
        .skip(1)
        .filter(|r| num(r, field).is_some() && num(r, innov).is_some() && num(r, sd).is_some())
        .count();
    assert!(with_series > 1000, "{with_series} rows with series");
    // A model file that is not one.
    let junk = d.path().join("junk.json");
    std::fs::write(&junk, "{\"format\":\"other\"}").unwrap();
    let o = compensate(&junk, std::path::Path::new(p), &d.path().join("o.csv"));
    assert_code(&o, 2);
    assert!(stderr(&o).contains("junk.json"));
    // A model with a corrupted coefficient: exit 2 naming the first row
    // whose interference is beyond any field, and no output file.
    let model_text = std::fs::read_to_string(&model).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&model_text).unwrap();
    v["coefficients"][0]["value"] = 1e300.into();
    let corrupt = d.path().join("corrupt.json");
    std::fs::write(&corrupt, v.to_string()).unwrap();
    let out = d.path().join("c.csv");
    let o = compensate(&corrupt, std::path::Path::new(p), &out);
    assert_code(&o, 2);
    assert!(
        stderr(&o).contains("line") && stderr(&o).contains("beyond any magnetic field"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists());
    // Data without the vector magnetometer: the message names what is missing.
    let text = std::fs::read_to_string(&cal).unwrap();
    let stripped = text.replace("flux_x", "fx");
    let nofx = d.path().join("nofx.csv");
    std::fs::write(&nofx, stripped).unwrap();
    let o = compensate(std::path::Path::new(m), &nofx, &d.path().join("o.csv"));
    assert_code(&o, 2);
    assert!(stderr(&o).contains("flux_x"), "{}", stderr(&o));
}

/// A fit the flight cannot determine and an output that cannot be written
/// are failures, not bad input: exit code 1.
#[test]
fn failures_that_are_not_bad_input_exit_1() {
    let d = tempfile::tempdir().unwrap();
    // A noise-free turning flight in a constant field: without a band-pass
    // the induced diagonal i_xx + i_yy + i_zz = |B|/bt_scale equals the
    // bias column times a constant, so the normal equations are singular.
    let mut rows = vec!["time,flux_x,flux_y,flux_z,mag".to_string()];
    for k in 0..3000 {
        let t = k as f64 * 0.1;
        let (a, b) = (0.4 * (1.9 * t).sin(), 0.3 * (1.3 * t + 1.0).sin());
        let f = [a.cos() * b.cos(), a.sin() * b.cos(), b.sin()].map(|c| 50_000.0 * c);
        rows.push(format!(
            "{t},{},{},{},{}",
            f[0],
            f[1],
            f[2],
            50_000.0 + 3.0 * f[0] / 50_000.0
        ));
    }
    let exact = d.path().join("exact.csv");
    std::fs::write(&exact, rows.join("\n") + "\n").unwrap();
    let model = d.path().join("m.json");
    let (e, m) = (exact.to_str().unwrap(), model.to_str().unwrap());
    let common = ["--eddy-lag", "none", "--reference", "none"];
    let mut args = vec![
        "calibrate",
        "--input",
        e,
        "--model",
        m,
        "--band",
        "none",
        "--terms",
        "p3,i6,bias",
    ];
    args.extend(common);
    let o = aeromag(&args);
    assert_code(&o, 1);
    assert!(
        stderr(&o).contains("exact.csv") && stderr(&o).contains("singular"),
        "{}",
        stderr(&o)
    );
    assert!(!model.exists(), "no model file after a failed fit");
    // The same flight with a fit it determines, to a folder that does not
    // exist yet: it is created before the work (issue 18).
    let nowhere = d.path().join("no/such/folder/m.json");
    let mut args = vec![
        "calibrate",
        "--input",
        e,
        "--model",
        nowhere.to_str().unwrap(),
        "--terms",
        "p3",
    ];
    args.extend(common);
    let o = aeromag(&args);
    assert_code(&o, 0);
    assert!(nowhere.exists());
    let mut args = vec!["calibrate", "--input", e, "--model", m, "--terms", "p3"];
    args.extend(common);
    assert_code(&aeromag(&args), 0);
}

/// Several sensors, current terms and the reference-sensor mode on the
/// command line (issue 20): one multi-sensor model file, every sensor's
/// columns from `compensate`, and bad input exiting 2 with the name.
#[test]
fn several_sensors_with_current_terms() {
    let d = tempfile::tempdir().unwrap();
    let toml = d.path().join("sgl.toml");
    std::fs::write(&toml, "installation = \"sgl\"\n").unwrap();
    let cal = simulate_with(d.path(), "calibration-truncated", "3", Some(&toml));
    let (cal, m) = (cal.to_str().unwrap(), d.path().join("m.json"));
    let o = aeromag(&[
        "calibrate",
        "--input",
        cal,
        "--mag",
        "mag_1_uc,mag_4_uc",
        "--vector",
        "flux_a,flux_d",
        "--extra",
        "cur_strb,cur_flap:lag",
        "--model",
        m.to_str().unwrap(),
        "--compensated",
        d.path().join("c_cal.csv").to_str().unwrap(),
    ]);
    assert_code(&o, 0);
    let out = stdout(&o);
    assert!(
        out.contains("mag_4      mag_4_uc") && out.contains("flux_d_x,flux_d_y,flux_d_z"),
        "{out}"
    );
    assert!(out.contains("2 sensor models written"), "{out}");
    assert!(out.contains("compensated 2 sensors on"), "{out}");
    let model = std::fs::read_to_string(&m).unwrap();
    assert!(
        model.contains("\"kind\": \"tolles-lawson-sensors\"")
            && model.contains("cur_flap:lag:e_x") == model.contains("\"lag_s\""),
        "{model}"
    );
    let comp = d.path().join("c.csv");
    let o = aeromag(&[
        "compensate",
        "--input",
        cal,
        "--model",
        m.to_str().unwrap(),
        "--out",
        comp.to_str().unwrap(),
    ]);
    assert_code(&o, 0);
    // `stream` takes one sensor: it said the model was not written by
    // `aeromag calibrate`.
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_aeromag"))
        .args(["stream", "--model", m.to_str().unwrap()])
        .stdin(std::process::Stdio::null())
        .output()
        .unwrap();
    assert_code(&o, 2);
    assert!(
        stderr(&o).contains("stream compensates one sensor"),
        "{}",
        stderr(&o)
    );
    // `calibrate --compensated` wrote the same file from its one reading.
    assert_eq!(
        std::fs::read(&comp).unwrap(),
        std::fs::read(d.path().join("c_cal.csv")).unwrap()
    );
    let header = std::fs::read_to_string(&comp).unwrap();
    let header = header
        .lines()
        .find(|l| !l.starts_with('#'))
        .unwrap()
        .to_string();
    for c in [
        "mag_1_interf",
        "mag_1_comp",
        "mag_4_interf",
        "mag_4_comp",
        "mag_4_grad",
    ] {
        assert!(header.split(',').any(|h| h == c), "{c} in {header}");
    }
    // The report of a multi-sensor model: every sensor, its term groups'
    // shares and its currents against what is left.
    let rep = d.path().join("rep");
    let report = |input: &str| {
        aeromag(&[
            "report",
            "--input",
            input,
            "--model",
            m.to_str().unwrap(),
            "--out",
            rep.to_str().unwrap(),
        ])
    };
    let o = report(comp.to_str().unwrap());
    assert_code(&o, 0);
    assert!(
        stdout(&o).contains("mag_4 ") && stdout(&o).contains("shares"),
        "{}",
        stdout(&o)
    );
    let fig: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(rep.join("figures.json")).unwrap()).unwrap();
    let sensors = fig["sensors"].as_array().unwrap();
    assert_eq!(sensors.len(), 2);
    for s in sensors {
        // First-order models: the shares of the groups sum to one.
        let shares: f64 = s["groups"]["shares"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .sum();
        assert!((shares - 1.0).abs() < 1e-9, "{s}");
        let currents: Vec<&str> = s["currents"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c["channel"].as_str().unwrap())
            .collect();
        assert!(
            currents.contains(&"cur_strb") && currents.contains(&"cur_flap"),
            "{currents:?}"
        );
        assert!(s["figures"]["ir"].as_f64().unwrap() > 1.0, "{s}");
    }
    assert_eq!(sensors[1]["column"], "mag_4_uc");
    // A cabin sensor's first-order model: the report says the projection
    // leaves out more than the threshold and recommends the exact
    // magnitude; the stinger's does not need it.
    let second = |k: usize| sensors[k]["second_order_nt"].as_f64().unwrap();
    assert!(second(0) < 0.1 && second(1) > 0.1, "{sensors:?}");
    let html = std::fs::read_to_string(rep.join("index.html")).unwrap();
    for needle in [
        "Several sensors: overview",
        "Sensor mag_4 (mag_4_uc)",
        "r with what is left",
        "calibrate with --magnitude exact",
    ] {
        assert!(html.contains(needle), "{needle}");
    }
    // Without the compensated columns: bad input naming the column.
    std::fs::remove_dir_all(&rep).unwrap();
    let o = report(cal);
    assert_code(&o, 2);
    assert!(stderr(&o).contains("mag_1_comp"), "{}", stderr(&o));
    // Reference-sensor mode against the compensated stinger column.
    let o = aeromag(&[
        "calibrate",
        "--input",
        comp.to_str().unwrap(),
        "--mag",
        "mag_4_uc",
        "--vector",
        "flux_a",
        "--reference-sensor",
        "mag_1_comp",
        "--model",
        d.path().join("r.json").to_str().unwrap(),
    ]);
    assert_code(&o, 0);
    assert!(stdout(&o).contains("mag_1_comp"), "{}", stdout(&o));
    // Bad input: a channel the file lacks, a bad suffix, a sensor it lacks,
    // a vector list of the wrong length.
    for (args, needle) in [
        (vec!["--mag", "mag_4_uc", "--extra", "cur_nope"], "cur_nope"),
        (vec!["--extra", "cur_strb:lagg"], "lagg"),
        (vec!["--mag", "mag_1_uc,mag_9_uc"], "mag_9_uc"),
        (
            vec![
                "--mag",
                "mag_1_uc,mag_4_uc,mag_5_uc",
                "--vector",
                "flux_a,flux_b",
            ],
            "--vector",
        ),
        (vec!["--magnitude", "exactly"], "magnitude"),
    ] {
        let x = d.path().join("x.json");
        let mut a = vec!["calibrate", "--input", cal, "--model", x.to_str().unwrap()];
        a.extend(args);
        let o = aeromag(&a);
        assert_code(&o, 2);
        assert!(stderr(&o).contains(needle), "{needle}: {}", stderr(&o));
    }
}

/// A compensated reading of another processing (SGL's `COMPMAG1`) is
/// scored by mapping it (`--columns mag_comp=COMPMAG1`): the figures of the
/// same values named `mag_comp`. Without the map the error names it.
#[test]
fn a_contractors_compensated_column_is_scored_when_mapped() {
    let d = tempfile::tempdir().unwrap();
    let cal = simulate(d.path(), "calibration", "4");
    let model = d.path().join("m.json");
    let ours = d.path().join("ours.csv");
    assert_code(
        &aeromag(&[
            "calibrate",
            cal.to_str().unwrap(),
            "--model",
            model.to_str().unwrap(),
        ]),
        0,
    );
    assert_code(&compensate(&model, &cal, &ours), 0);
    // The same file as a contractor's: mag_comp named COMPMAG1, no model columns.
    let text = std::fs::read_to_string(&ours).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let keep: Vec<usize> = (0..header.len())
        .filter(|&i| !matches!(header[i], "mag_interf" | "comp_flag"))
        .collect();
    let row = |cells: Vec<&str>| keep.iter().map(|&i| cells[i]).collect::<Vec<_>>().join(",");
    let renamed: Vec<&str> = header
        .iter()
        .map(|&h| if h == "mag_comp" { "COMPMAG1" } else { h })
        .collect();
    let mut theirs_text = row(renamed) + "\n";
    for l in lines {
        theirs_text += &(row(l.split(',').collect()) + "\n");
    }
    let theirs = d.path().join("theirs.csv");
    std::fs::write(&theirs, theirs_text).unwrap();
    let figures = |input: &std::path::Path, extra: &[&str], dir: &str| {
        let out = d.path().join(dir);
        let mut args = vec![
            "report",
            input.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend(extra);
        let o = aeromag(&args);
        assert_code(&o, 0);
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("figures.json")).unwrap())
                .unwrap();
        (
            v["fom_before_nt"].clone(),
            v["fom_after_nt"].clone(),
            v["ir"].clone(),
        )
    };
    let mapped = figures(&theirs, &["--columns", "mag_comp=COMPMAG1"], "r1");
    assert!(mapped.2.as_f64().unwrap() > 1.0, "{mapped:?}");
    assert_eq!(mapped, figures(&ours, &[], "r2"));
    let o = aeromag(&[
        "report",
        theirs.to_str().unwrap(),
        "--out",
        d.path().join("r3").to_str().unwrap(),
    ]);
    assert_code(&o, 2);
    assert!(
        stderr(&o).contains("--columns mag_comp=COMPMAG1"),
        "{}",
        stderr(&o)
    );
    // Compensating that file again: the map is what clashes with the new
    // mag_comp, and the message says so; without it COMPMAG1 stays as it is.
    let again = d.path().join("again.csv");
    let mut args = vec!["compensate", theirs.to_str().unwrap()];
    args.extend(["--model", model.to_str().unwrap()]);
    args.extend(["--out", again.to_str().unwrap()]);
    let o = aeromag(&[&args[..], &["--columns", "mag_comp=COMPMAG1"]].concat());
    assert_code(&o, 2);
    assert!(
        stderr(&o).contains("the column map reads its column 'COMPMAG1' as `mag_comp`")
            && stderr(&o).contains("leave `mag_comp` out of the map"),
        "{}",
        stderr(&o)
    );
    assert!(!again.exists());
    assert_code(&aeromag(&args), 0);
    let header = std::fs::read_to_string(&again).unwrap();
    let header: Vec<&str> = header.lines().next().unwrap().split(',').collect();
    assert!(
        header.contains(&"COMPMAG1") && header.contains(&"mag_comp"),
        "{header:?}"
    );
}
