//! `aeromag rotor study|fit|apply` as commands: the geometry they require,
//! files, rows kept and flagged, messages and exit codes (the figures are
//! tested in the library).

mod common;
use common::*;

#[test]
fn rotor_study_writes_its_summary_and_report() {
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
    for k in [
        "rotor_rms_nt",
        "residual_model_nt",
        "residual_best_filter_nt",
    ] {
        assert!(s["rotor"][k].is_number(), "rotor.{k}");
    }
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(html.contains("<svg") && html.contains("low-pass"));
}

/// Rows of a CSV written by aeromag: the named columns (NaN for empty cells).
fn columns(p: &std::path::Path, names: &[&str]) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(p).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let idx: Vec<usize> = names
        .iter()
        .map(|n| header.iter().position(|h| h == n).unwrap())
        .collect();
    let mut out = vec![Vec::new(); names.len()];
    for l in lines {
        let f: Vec<&str> = l.split(',').collect();
        for (o, i) in out.iter_mut().zip(&idx) {
            o.push(f[*i].parse().unwrap_or(f64::NAN));
        }
    }
    out
}

#[test]
fn rotor_fit_needs_the_geometry_and_apply_keeps_every_row() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path().join("h");
    assert_code(
        &aeromag(&[
            "simulate",
            "helicopter",
            "--seed",
            "11",
            "--out",
            dir.to_str().unwrap(),
        ]),
        0,
    );
    let heli = dir.join("helicopter.csv");
    let model = d.path().join("rotor.json");
    let fit = |extra: &[&str]| {
        let mut args = vec![
            "rotor",
            "fit",
            "--input",
            heli.to_str().unwrap(),
            "--model",
            model.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        aeromag(&args)
    };
    // No geometry: a usage error naming what to give.
    let o = fit(&[]);
    assert_code(&o, 2);
    assert!(
        stderr(&o).contains("--preset") || stderr(&o).contains("--hub-m"),
        "{}",
        stderr(&o)
    );
    let o = fit(&["--hub-m", "0,0,-2.6", "--sensor-m", "5,0,0.6"]);
    assert_code(&o, 2);
    let o = fit(&["--preset", "nosuch"]);
    assert_code(&o, 2);
    // The simulator's helicopter, by its preset or by its numbers.
    let o = fit(&[
        "--hub-m",
        "0,0,-2.6",
        "--sensor-m",
        "5,0,0.6",
        "--blade-span-m",
        "0.8,7.5",
        "--blades",
        "4",
    ]);
    assert_code(&o, 0);
    let by_numbers = std::fs::read_to_string(&model).unwrap();
    let o = fit(&["--preset", "aeromag-sim-helicopter"]);
    assert_code(&o, 0);
    assert!(stdout(&o).contains("from `rotor_phase`"), "{}", stdout(&o));
    assert!(!stdout(&o).contains("tail rotor"), "{}", stdout(&o));
    assert_eq!(std::fs::read_to_string(&model).unwrap(), by_numbers);
    let m: serde_json::Value = serde_json::from_str(&by_numbers).unwrap();
    assert_eq!(m["format"], "aeromag-model/2");
    assert_eq!(m["kind"], "helicopter-rotor");
    // A truth column as phase is refused, and (taken before) one mapped
    // onto another column or chosen as the vector magnetometer.
    assert_code(
        &fit(&[
            "--preset",
            "aeromag-sim-helicopter",
            "--phase-column",
            "true_rotor_phase",
        ]),
        2,
    );
    for extra in [
        ["--columns", "flux_x=true_flux_x"],
        ["--vector", "true_flux"],
    ] {
        let mut args = vec!["--preset", "aeromag-sim-helicopter"];
        args.extend(extra);
        let o = fit(&args);
        assert_code(&o, 2);
        // Refused on reading, for every command.
        assert!(
            stderr(&o).contains(
                "column 'true_flux_x' cannot be read as `flux_x`: it is simulation truth"
            ),
            "{}",
            stderr(&o)
        );
    }
    // A tail rotor: its values need --tail-rotor (usage error), and without a
    // phase channel it cannot be geared (bad input, exit 2, says why).
    assert_code(
        &fit(&["--preset", "aeromag-sim-helicopter", "--gear-ratio", "4"]),
        2,
    );
    let o = fit(&[
        "--preset",
        "aeromag-sim-helicopter",
        "--tail-rotor",
        "--estimate-phase",
    ]);
    assert_code(&o, 2);
    assert!(stderr(&o).contains("phase channel"), "{}", stderr(&o));
    // The nose-boom sensor does not see the tail rotor: it is left out,
    // with a warning (its slow part had put −8 nT of mean error, 12 nT
    // std, into the compensated reading).
    let o = fit(&["--preset", "aeromag-sim-helicopter", "--tail-rotor"]);
    assert_code(&o, 0);
    assert!(
        stderr(&o).contains(
            "warning: the tail rotor is left out of the model: the sensor does not see it"
        ) && !stdout(&o).contains("tail rotor 21 parameters"),
        "{}\n{}",
        stdout(&o),
        stderr(&o)
    );
    // Apply: one row per input row, a missing `mag` kept and flagged.
    let text = std::fs::read_to_string(&heli).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let hdr = lines.iter().position(|l| !l.starts_with('#')).unwrap();
    let mag_i = lines[hdr].split(',').position(|c| c == "mag").unwrap();
    let edit = |row: usize, value: &str| -> String {
        let mut out: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
        let mut f: Vec<String> = out[hdr + row].split(',').map(String::from).collect();
        f[mag_i] = value.into();
        out[hdr + row] = f.join(",");
        out.join("\n") + "\n"
    };
    let gap = d.path().join("gap.csv");
    std::fs::write(&gap, edit(20_000, "")).unwrap();
    let out = d.path().join("out.csv");
    let o = apply("rotor", &model, &gap, &out);
    assert_code(&o, 0);
    assert!(stderr(&o).contains("rotor_flag = 1"), "{}", stderr(&o));
    let c = columns(&out, &["rotor_flag", "mag_comp", "rotor_interf"]);
    assert_eq!(c[0].len(), lines.len() - hdr - 1);
    assert_eq!(c[0][19_999], 1.0);
    assert!(c[1][19_999].is_nan());
    assert_eq!(c[0][0], 0.0);
    assert!(c[2][0].is_finite());
    // Bad input: a cell that is not a number, a model of another kind.
    let bad = d.path().join("bad.csv");
    std::fs::write(&bad, edit(77, "x1")).unwrap();
    let o = apply("rotor", &model, &bad, &out);
    assert_code(&o, 2);
    let e = stderr(&o);
    assert!(
        e.contains("bad.csv") && e.contains("mag") && e.contains("data row 77"),
        "{e}"
    );
    std::fs::write(
        &bad,
        "{\"format\": \"aeromag-model/2\", \"kind\": \"towed-pod\"}",
    )
    .unwrap();
    assert_code(&apply("rotor", &bad, &heli, &out), 2);
}
