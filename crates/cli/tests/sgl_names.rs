//! SGL files in their two namings (MagNav/HDF5 `mag_1_uc`, `cur_com_1`;
//! Geosoft XYZ export `UNCOMPMAG1`, `CUR_COM1`): models, `--extra` and
//! `--reference-sensor` find a field in either, the main field is derived
//! as MagNav derives it, and INS positions in degrees are told from
//! radians. The XYZ files are written here from a simulated SGL-like
//! flight (no SGL data in the repository).

mod common;
use common::*;
use std::path::{Path, PathBuf};

/// The XYZ export name of a column of the simulated flight (HDF5 layout),
/// `None` for truth columns and those the export lacks.
fn xyz_name(h5: &str) -> Option<String> {
    let fixed = [
        ("time", "TIME"),
        ("lat", "LAT"),
        ("lon", "LONG"),
        ("alt", "UTM-Z"),
        ("roll", "ROLL"),
        ("pitch", "PITCH"),
        ("yaw", "AZIMUTH"),
        ("line", "LINE"),
        ("diurnal", "DIURNAL"),
        ("cur_com_1", "CUR_COM1"),
        ("cur_ac_hi", "CUR_ACHi"),
        ("cur_ac_lo", "CUR_ACLo"),
        ("cur_heat", "CUR_IHTR"),
        ("cur_bat_1", "CUR_BAT1"),
        ("cur_bat_2", "CUR_BAT2"),
    ];
    if let Some((_, x)) = fixed.iter().find(|(h, _)| *h == h5) {
        return Some(x.to_string());
    }
    if let Some(k) = h5.strip_prefix("mag_").and_then(|r| r.strip_suffix("_uc")) {
        return Some(format!("UNCOMPMAG{k}"));
    }
    if let Some((sensor, axis)) = h5.strip_prefix("flux_").and_then(|r| r.split_once('_')) {
        return Some(format!(
            "FLUX{}_{}",
            sensor.to_uppercase(),
            axis.to_uppercase()
        ));
    }
    h5.starts_with("cur_").then(|| h5.to_uppercase())
}

/// The simulated SGL-like calibration flight (CSV, MagNav names) and the
/// same flight as a contractor's XYZ export (upper-case SGL export names,
/// every value as read); with `dc_igrf`, `DCMAG1` and `IGRFMAG1` in place
/// of the `igrf` column (`IGRFMAG1 = DCMAG1 − igrf`, as the contractor's
/// IGRF correction).
fn flights(dir: &Path, dc_igrf: bool) -> (PathBuf, PathBuf) {
    let toml = dir.join("sgl.toml");
    std::fs::write(&toml, "installation = \"sgl\"\n").unwrap();
    let csv = simulate_with(dir, "calibration-truncated", "3", Some(&toml));
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let keep: Vec<(usize, String)> = header
        .iter()
        .enumerate()
        .filter_map(|(i, h)| xyz_name(h).map(|x| (i, x)))
        .collect();
    let at = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (mag1, diurnal, igrf) = (at("mag_1_uc"), at("diurnal"), at("igrf"));
    let mut out = String::from("/ XYZ EXPORT (aeromag simulation)\n/ ");
    let mut names: Vec<String> = keep.iter().map(|(_, x)| x.clone()).collect();
    if dc_igrf {
        names.extend(["DCMAG1".to_string(), "IGRFMAG1".to_string()]);
    }
    out.push_str(&names.join(" "));
    out.push('\n');
    for l in lines {
        let v: Vec<&str> = l.split(',').collect();
        let mut row: Vec<String> = keep.iter().map(|(i, _)| v[*i].to_string()).collect();
        if dc_igrf {
            let f = |i: usize| v[i].parse::<f64>().unwrap();
            let dc = f(mag1) - f(diurnal);
            row.push(format!("{dc:?}"));
            row.push(format!("{:?}", dc - f(igrf)));
        }
        out.push_str(&row.join(" "));
        out.push('\n');
    }
    let xyz = dir.join(if dc_igrf { "sgl_dc.xyz" } else { "sgl.xyz" });
    std::fs::write(&xyz, out).unwrap();
    (csv, xyz)
}

fn run(args: &[&str]) -> String {
    let o = aeromag(args);
    assert_code(&o, 0);
    stdout(&o)
}

/// The values of `column` in a CSV written by `compensate`.
fn column(path: &Path, name: &str) -> Vec<String> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let k = lines
        .next()
        .unwrap()
        .split(',')
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("{name} in {}", path.display()));
    lines
        .map(|l| l.split(',').nth(k).unwrap().to_string())
        .collect()
}

/// Before: a model fitted on MagNav names failed on the XYZ export
/// (`required column 'mag_1_uc' is missing`), and `--extra cur_com_1` and
/// `--reference-sensor mag_1_uc` on the export too; a model fitted with
/// the export's names stored `UNCOMPMAG1` and failed on the MagNav-named
/// file. Now either naming fits the same model, stored under MagNav names,
/// and either applies to either file.
#[test]
fn a_model_fitted_in_either_naming_applies_to_the_other() {
    let d = tempfile::tempdir().unwrap();
    let (csv, xyz) = flights(d.path(), false);
    let (csv, xyz) = (csv.to_str().unwrap(), xyz.to_str().unwrap());
    let m_csv = d.path().join("m_csv.json");
    let m_xyz = d.path().join("m_xyz.json");
    let fit = |input: &str, mags: &str, extra: &str, reference: &str, model: &Path| {
        run(&[
            "calibrate",
            "--input",
            input,
            "--mag",
            mags,
            "--extra",
            extra,
            "--reference-sensor",
            reference,
            "--eddy-lag",
            "none",
            // The export here has no main field (see the next test).
            "--reference",
            "diurnal",
            "--model",
            model.to_str().unwrap(),
        ])
    };
    fit(
        csv,
        "mag_1_uc,mag_4_uc",
        "cur_strb,cur_com_1",
        "mag_1_uc",
        &m_csv,
    );
    let out = fit(
        xyz,
        "UNCOMPMAG1,mag_4_uc",
        "CUR_STRB,cur_com_1",
        "mag_1_uc",
        &m_xyz,
    );
    // The preset's fluxgate is named.
    assert!(
        out.contains("flux_x, flux_y, flux_z = FLUXA_X, FLUXA_Y, FLUXA_Z"),
        "{out}"
    );
    let model = std::fs::read_to_string(&m_xyz).unwrap();
    for stored in [
        "\"mag\": \"mag_1_uc\"",
        "\"mag\": \"mag_4_uc\"",
        "\"reference_sensor\": \"mag_1_uc\"",
        "\"channel\": \"cur_com_1\"",
        "\"channel\": \"cur_strb\"",
    ] {
        assert!(model.contains(stored), "{stored} in {model}");
    }
    assert!(
        !model.contains("UNCOMPMAG") && !model.contains("CUR_"),
        "{model}"
    );
    // Every model on every file; the two models give the same readings.
    let mut outs = Vec::new();
    for (m, input) in [(&m_csv, xyz), (&m_xyz, csv), (&m_csv, csv), (&m_xyz, xyz)] {
        let out = d.path().join(format!("c{}.csv", outs.len()));
        let o = compensate(m, Path::new(input), &out);
        assert_code(&o, 0);
        outs.push(out);
    }
    for c in ["mag_1_comp", "mag_4_comp"] {
        let a = column(&outs[2], c);
        let b: Vec<f64> = column(&outs[1], c)
            .iter()
            .map(|v| v.parse().unwrap())
            .collect();
        for (a, b) in a.iter().zip(&b) {
            let a: f64 = a.parse().unwrap();
            assert!((a - b).abs() < 1e-6, "{c}: {a} vs {b}");
        }
        assert_eq!(column(&outs[0], c), column(&outs[2], c), "{c}");
    }
}

/// Before: a file with `DCMAG1` and `IGRFMAG1` and no `igrf` had the
/// diurnal alone subtracted, without a word. Now `igrf = DCMAG1 −
/// IGRFMAG1` (MagNav's `get_XYZ20`), `calibrate` says what it subtracted,
/// and the fit equals the one on the recorded `igrf`.
#[test]
fn igrf_is_derived_from_the_contractors_corrections() {
    let d = tempfile::tempdir().unwrap();
    let (csv, xyz) = flights(d.path(), true);
    let (csv, xyz) = (csv.to_str().unwrap(), xyz.to_str().unwrap());
    let m = |n: &str| d.path().join(n).to_str().unwrap().to_string();
    let out = run(&[
        "calibrate",
        "-i",
        xyz,
        "--eddy-lag",
        "none",
        "--model",
        &m("x.json"),
    ]);
    assert!(
        out.contains(
            "reference subtracted from the scalar reading: diurnal, igrf (derived from DCMAG1 − IGRFMAG1)"
        ),
        "{out}"
    );
    let own = run(&[
        "calibrate",
        "-i",
        csv,
        "--eddy-lag",
        "none",
        "--model",
        &m("c.json"),
    ]);
    assert!(
        own.contains("reference subtracted from the scalar reading: diurnal, igrf\n"),
        "{own}"
    );
    let coef = |p: &str| -> Vec<f64> {
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap();
        v["coefficients"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c["value"].as_f64().unwrap())
            .collect()
    };
    let (a, b) = (coef(&m("x.json")), coef(&m("c.json")));
    assert_eq!(a.len(), b.len());
    for (a, b) in a.iter().zip(&b) {
        assert!((a - b).abs() <= 1e-6 * (1.0 + b.abs()), "{a} vs {b}");
    }
    let o = aeromag(&["inspect", "-i", xyz]);
    assert_code(&o, 0);
    assert!(
        stdout(&o).contains("igrf=DCMAG1 − IGRFMAG1 [nT]"),
        "{}",
        stdout(&o)
    );
}

/// Before: `ins_lat`/`ins_lon` were radians whatever their values, so a
/// file in degrees (MagNav's XYZ0 layout) was listed in `rad` and, without
/// `lat`/`lon`, refused with "column 'lat': latitude 2243.74". Now values
/// that cannot be radians are taken as degrees with a named warning, an
/// error names the file's field, and radians read exactly as before.
#[test]
fn ins_positions_in_degrees_or_radians() {
    let d = tempfile::tempdir().unwrap();
    let write = |name: &str, lat: f64, lon: f64| {
        let p = d.path().join(name);
        let mut s = String::from("time,ins_lat,ins_lon\n");
        for k in 0..20 {
            let t = k as f64 * 0.1;
            s.push_str(&format!("{t},{:?},{:?}\n", lat + 1e-6 * t, lon));
        }
        std::fs::write(&p, s).unwrap();
        p
    };
    let deg = write("deg.csv", 39.1607, -95.5207);
    let o = aeromag(&["inspect", "-i", deg.to_str().unwrap()]);
    assert_code(&o, 0);
    let (out, err) = (stdout(&o), stderr(&o));
    assert!(
        err.contains("column 'ins_lat': taken as degrees")
            && err.contains("ins_lat = 39.1607")
            && err.contains("[ins-degrees]"),
        "{err}"
    );
    assert!(
        out.contains("lat=ins_lat (deg as recorded) [deg]")
            && out
                .lines()
                .any(|l| l.starts_with("ins_lat") && l.contains(" deg ")),
        "{out}"
    );
    let rad = write(
        "rad.csv",
        39.1607f64.to_radians(),
        (-95.5207f64).to_radians(),
    );
    let o = aeromag(&["inspect", "-i", rad.to_str().unwrap()]);
    assert_code(&o, 0);
    assert!(!stderr(&o).contains("ins-degrees"), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("lat=ins_lat (rad → deg) [deg]")
            && stdout(&o)
                .lines()
                .any(|l| l.starts_with("ins_lat") && l.contains(" rad ")),
        "{}",
        stdout(&o)
    );
    let bad = write("bad.csv", 2243.74, -95.5);
    let o = aeromag(&["inspect", "-i", bad.to_str().unwrap()]);
    assert_code(&o, 2);
    assert!(
        stderr(&o).contains("column 'ins_lat': latitude 2243.74"),
        "{}",
        stderr(&o)
    );
}
