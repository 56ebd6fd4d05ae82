//! A whole simulated flight in the SGL HDF5 layout (calibration box
//! 1002.02, transit gap, survey lines 1003.01… and ties 1003.51…; written by
//! `tools/reference/sgl_flight.py` with h5py, SGL names, INS position in
//! radians and velocity north/west/up) is calibrated on its box with
//! `--lines` and compensated on its survey lines with `--lines`, giving the
//! numbers of the same flight as CSV (canonical names, degrees, NED).
//!
//! Needs python3 with numpy and h5py (`scripts/test.sh` installs them).

mod common;
use common::*;
use std::path::Path;
use std::process::Command;

const SENSORS: &str = "\
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
[[aircraft.currents]]
name = \"strb\"
position_m = [-1.0, 0.0, -0.5]
[[aircraft.currents]]
name = \"flap\"
position_m = [0.5, 2.0, 0.0]
";

fn python_flight(dir: &Path) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    // Four more scalar magnetometers and three more fluxgates in the cabin
    // (mag_2 … mag_5, flux_b … flux_d), as on the SGL aircraft, and two
    // recorded currents.
    let config = dir.join("sensors.toml");
    std::fs::write(&config, SENSORS).unwrap();
    let cal = &simulate_with(dir, "calibration", "1", Some(&config));
    // Six survey lines (1003.01–1003.06) and the five ties: a third of the
    // default survey, every kind of line the test compensates.
    let survey_config = dir.join("survey.toml");
    std::fs::write(
        &survey_config,
        format!("{SENSORS}[pattern]\nline_count = 6\n"),
    )
    .unwrap();
    let survey = &simulate_with(dir, "survey", "2", Some(&survey_config));
    let o = Command::new("python3")
        .arg(root.join("tools/reference/sgl_flight.py"))
        .arg(cal)
        .arg(survey)
        .arg(dir)
        .output()
        .expect("python3");
    assert!(
        o.status.success(),
        "tools/reference/sgl_flight.py failed (needs numpy and h5py: run scripts/test.sh, or pip install numpy h5py):\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// `aeromag compensate` of the rows of `lines` of `input` with `model`
/// into `out`, which must succeed.
fn compensate_lines(input: &Path, lines: &str, model: &Path, out: &Path) {
    let o = aeromag(&[
        "compensate",
        "-i",
        input.to_str().unwrap(),
        "--lines",
        lines,
        "--model",
        model.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_code(&o, 0);
}

/// The column `name` of the two outputs (the CSV and the HDF5 route) is
/// the same row for row (to 1e-6 nT), over more than 1000 survey rows.
fn assert_same_column(outputs: &[std::path::PathBuf], name: &str) {
    let (ca, cb) = (column(&outputs[0], name), column(&outputs[1], name));
    assert_eq!(ca.len(), cb.len());
    assert!(ca.len() > 1000, "{} survey rows", ca.len());
    let worst = ca
        .iter()
        .zip(&cb)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0f64, f64::max);
    assert!(worst < 1e-6, "{name}: largest difference {worst} nT");
}

fn read_json(p: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

fn column(p: &Path, name: &str) -> Vec<f64> {
    let text = std::fs::read_to_string(p).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let k = header
        .iter()
        .position(|h| *h == name)
        .unwrap_or_else(|| panic!("{name}"));
    lines
        .map(|l| {
            l.split(',')
                .nth(k)
                .unwrap()
                .parse::<f64>()
                .unwrap_or(f64::NAN)
        })
        .collect()
}

#[test]
fn whole_flight_in_sgl_hdf5_gives_the_numbers_of_the_csv_route() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    python_flight(d);
    let (csv, h5) = (d.join("whole_flight.csv"), d.join("whole_flight.h5"));
    // Every sensor and current of the HDF5 flight is recognised with its unit.
    let o = aeromag(&["inspect", "-i", h5.to_str().unwrap()]);
    assert_code(&o, 0);
    let s = stdout(&o);
    for field in ["mag_5_uc", "flux_d_z", "cur_strb", "ins_lat", "ins_vw"] {
        assert!(s.lines().any(|l| l.starts_with(field)), "{field} in\n{s}");
    }
    assert!(s.contains("derived  lat=ins_lat (rad → deg) [deg]"), "{s}");
    let survey_lines = "1003.01,1003.02,1003.03,1003.04,1003.05,1003.51,1003.52";
    // `calibrate` on the box (line 1002.02) of `input`, with `more` arguments.
    let calibrate_box = |input: &Path, model: &Path, more: &[&str]| {
        let mut args = vec![
            "calibrate",
            "-i",
            input.to_str().unwrap(),
            "--lines",
            "1002.02",
        ];
        args.extend(["--model", model.to_str().unwrap()]);
        args.extend(more);
        aeromag(&args)
    };
    let mut models = Vec::new();
    let mut outputs = Vec::new();
    for (k, input) in [&csv, &h5].into_iter().enumerate() {
        let model = d.join(format!("model{k}.json"));
        let o = calibrate_box(input, &model, &[]);
        assert_code(&o, 0);
        let out = d.join(format!("comp{k}.csv"));
        compensate_lines(input, survey_lines, &model, &out);
        models.push(read_json(&model));
        outputs.push(out);
    }
    // The same coefficients (the HDF5 latitude went through radians and
    // back: equal to ~1e-15 relative).
    let coef = |m: &serde_json::Value| -> Vec<f64> {
        m["coefficients"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c["value"].as_f64().unwrap())
            .collect()
    };
    let (a, b) = (coef(&models[0]), coef(&models[1]));
    assert!(a.len() >= 16 && a.len() == b.len());
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).abs() <= 1e-9 * x.abs().max(1e-3), "{x} vs {y}");
    }
    // The same compensated survey, row for row.
    assert_same_column(&outputs, "mag_comp");
    // `calibrate --compensated` on the HDF5 box writes every field of the
    // file (not only those the fit reads), as `compensate` does.
    let (m, c1, c2) = (d.join("box.json"), d.join("box1.csv"), d.join("box2.csv"));
    let o = calibrate_box(&h5, &m, &["--compensated", c1.to_str().unwrap()]);
    assert_code(&o, 0);
    compensate_lines(&h5, "1002.02", &m, &c2);
    let box_text = std::fs::read_to_string(&c1).unwrap();
    assert!(box_text.lines().next().unwrap().contains("mag_5_uc"));
    assert_eq!(box_text, std::fs::read_to_string(&c2).unwrap());
    // Every survey row is written, none of the box or the transit.
    let lines = column(&outputs[1], "line");
    assert!(
        lines.iter().all(|&l| l > 1003.0 && l < 1004.0),
        "{:?}",
        &lines[..5]
    );
    // Another sensor pair of the whole flight, chosen by its canonical name
    // in the CSV and by its SGL name in the HDF5 file: the same model.
    let mut chosen = Vec::new();
    for (k, (input, mag)) in [(&csv, "mag_3"), (&h5, "mag_3_uc")].into_iter().enumerate() {
        let model = d.join(format!("model_mag3_{k}.json"));
        let o = aeromag(&[
            "calibrate",
            "-i",
            input.to_str().unwrap(),
            "--lines",
            "1002.02",
            "--mag",
            mag,
            "--vector",
            "flux_c",
            "--model",
            model.to_str().unwrap(),
        ]);
        assert_code(&o, 0);
        chosen.push(coef(&read_json(&model)));
    }
    assert_eq!(chosen[0].len(), chosen[1].len());
    for (x, y) in chosen[0].iter().zip(&chosen[1]) {
        assert!((x - y).abs() <= 1e-9 * x.abs().max(1e-3), "{x} vs {y}");
    }
    assert!(
        chosen[0]
            .iter()
            .zip(&a)
            .any(|(x, y)| (x - y).abs() > 1e-3 * y.abs().max(1.0)),
        "the cabin sensor pair has its own model"
    );
    // Several sensors with current terms in the reference-sensor mode
    // (issue 20), on the whole flight's box: the same models from the CSV
    // (canonical names) and from the HDF5 file (SGL names), the same
    // compensated cabin sensor on the survey lines, and its report.
    let mut sensor_models = Vec::new();
    let mut sensor_outputs = Vec::new();
    for (k, (input, mags, vectors, reference)) in [
        (&csv, "mag,mag_3", "flux,flux_c", "mag"),
        (&h5, "mag_1_uc,mag_3_uc", "flux_a,flux_c", "mag_1_uc"),
    ]
    .into_iter()
    .enumerate()
    {
        let model = d.join(format!("sensors_{k}.json"));
        let input = input.to_str().unwrap();
        let o = aeromag(&[
            "calibrate",
            "-i",
            input,
            "--lines",
            "1002.02",
            "--mag",
            mags,
            "--vector",
            vectors,
            "--extra",
            "cur_strb,cur_flap:lag",
            "--reference-sensor",
            reference,
            "--model",
            model.to_str().unwrap(),
        ]);
        assert_code(&o, 0);
        let out = d.join(format!("sensors_comp{k}.csv"));
        compensate_lines(Path::new(input), survey_lines, &model, &out);
        sensor_models.push(read_json(&model));
        sensor_outputs.push(out);
    }
    for s in 0..2 {
        let c = |m: &serde_json::Value| coef(&m["sensors"][s]["model"]);
        let (x, y) = (c(&sensor_models[0]), c(&sensor_models[1]));
        assert!(
            x.len() > 16 && x.len() == y.len(),
            "{} vs {}",
            x.len(),
            y.len()
        );
        for (x, y) in x.iter().zip(&y) {
            assert!((x - y).abs() <= 1e-9 * x.abs().max(1e-3), "{x} vs {y}");
        }
    }
    assert_eq!(
        sensor_models[1]["sensors"][1]["reference_sensor"],
        "mag_1_uc"
    );
    assert_same_column(&sensor_outputs, "mag_3_comp");
    let rep = d.join("sensors_report");
    let o = aeromag(&[
        "report",
        "-i",
        sensor_outputs[1].to_str().unwrap(),
        "--model",
        d.join("sensors_1.json").to_str().unwrap(),
        "--out",
        rep.to_str().unwrap(),
    ]);
    assert_code(&o, 0);
    let fig = read_json(&rep.join("figures.json"));
    assert_eq!(fig["sensors"][1]["column"], "mag_3_uc");
    assert!(
        fig["sensors"][1]["figures"]["residual_rms_nt"].is_number(),
        "{fig}"
    );
    // Levelled with its decimal labels (ties declared), and reported: the
    // report reads the levelling columns.
    let levelled = d.join("level.csv");
    let o = aeromag(&[
        "level",
        "-i",
        outputs[1].to_str().unwrap(),
        "--ties",
        "1003.51,1003.52",
        "--out",
        levelled.to_str().unwrap(),
    ]);
    assert_code(&o, 0);
    assert!(stdout(&o).contains("1003.51"), "{}", stdout(&o));
    let rep = d.join("report");
    let o = aeromag(&[
        "report",
        "-i",
        levelled.to_str().unwrap(),
        "--out",
        rep.to_str().unwrap(),
    ]);
    assert_code(&o, 0);
    let html = std::fs::read_to_string(rep.join("index.html")).unwrap();
    for k in ["Levelling correction per line", "rows levelled", "1003.52"] {
        assert!(html.contains(k), "{k} missing in the report");
    }
    // The report of an HDF5 copy reads only the fields it needs (the
    // compensated, modelled, truth and levelling columns): the same figures.
    let h5 = h5_copy(&levelled);
    let rep5 = d.join("report5");
    let o = aeromag(&[
        "report",
        "-i",
        h5.to_str().unwrap(),
        "--out",
        rep5.to_str().unwrap(),
    ]);
    assert_code(&o, 0);
    let figures = |r: &Path| read_json(&r.join("figures.json"));
    assert_eq!(figures(&rep), figures(&rep5));
    assert!(
        figures(&rep)["interference_rms_nt"].is_number(),
        "truth was read"
    );
    let html5 = std::fs::read_to_string(rep5.join("index.html")).unwrap();
    assert!(html5.contains("Levelling correction per line"));
}

/// An HDF5 copy of an aeromag CSV file (tools/reference/csv_h5.py: every
/// column a dataset under its own name).
fn h5_copy(csv: &Path) -> std::path::PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let h5 = csv.with_extension("h5");
    let o = Command::new("python3")
        .arg(root.join("tools/reference/csv_h5.py"))
        .arg(csv)
        .arg(&h5)
        .output()
        .expect("python3");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    h5
}

/// The rotor and pod fits read only the fields they need from an HDF5
/// flight (canonical columns and their own: the rotor phase, the cable
/// angles): the same model file as from the CSV.
#[test]
fn rotor_and_pod_fits_read_their_fields_from_hdf5() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let fit = |family: &str, input: &Path, model: &Path, setup: &[&str]| {
        let mut args = vec![
            family,
            "fit",
            "-i",
            input.to_str().unwrap(),
            "--model",
            model.to_str().unwrap(),
        ];
        args.extend_from_slice(setup);
        let o = aeromag(&args);
        assert_code(&o, 0);
        std::fs::read_to_string(model).unwrap()
    };
    let csv = simulate(d, "helicopter", "11");
    let setup = ["--preset", "aeromag-sim-helicopter"];
    let a = fit("rotor", &csv, &d.join("r.json"), &setup);
    let b = fit("rotor", &h5_copy(&csv), &d.join("r5.json"), &setup);
    assert!(a.contains("\"rotor_phase\""), "the phase channel was used");
    assert_eq!(a, b);
    let pod = simulate(d, "pod", "1");
    let a = fit("pod", &pod, &d.join("p.json"), &POD_SETUP);
    let b = fit("pod", &h5_copy(&pod), &d.join("p5.json"), &POD_SETUP);
    assert!(a.contains("cable_inclination"));
    assert_eq!(a, b);
}
