//! `aeromag inspect` on good and malformed files: every malformed file gives
//! exit code 2 and a message naming the file, the line and the column.

mod common;
use common::*;
use std::path::PathBuf;

fn write(dir: &tempfile::TempDir, name: &str, content: &[u8]) -> PathBuf {
    let p = dir.path().join(name);
    std::fs::write(&p, content).unwrap();
    p
}

const GOOD: &str = "time,lat,lon,alt,mag,flux_x,flux_y,flux_z,line\n\
0.0,45.0,10.0,3000,52000.1,17000,1500,48000,1\n\
0.1,45.0,10.0,3000,52000.2,17001,1500,48000,1\n\
0.2,45.0,10.0,3000,52000.3,17002,1500,48000,1\n\
0.3,45.0,10.0,3000,52000.4,17003,1500,48000,2\n";

#[test]
fn summarises_a_good_file() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "good.csv", GOOD.as_bytes());
    let o = aeromag(&["inspect", "--input", p.to_str().unwrap()]);
    assert_code(&o, 0);
    let s = stdout(&o);
    assert!(s.contains("rows     4"), "{s}");
    assert!(s.contains("rate 10"), "{s}");
    assert!(s.contains("lines    2"), "{s}");
    let j = aeromag(&["inspect", "--input", p.to_str().unwrap(), "--json"]);
    assert_code(&j, 0);
    let v: serde_json::Value = serde_json::from_str(&stdout(&j)).unwrap();
    assert_eq!(v["rows"], 4);
    assert_eq!(v["position_glitch_rows"], serde_json::json!([]));
    assert!(!s.contains("off the track"), "{s}");
}

/// The flight file may be given as the command's argument, as `--input`
/// gives it (`aeromag inspect flight.xyz`), but not both ways at once nor
/// not at all.
#[test]
fn the_file_may_be_given_without_input() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "good.csv", GOOD.as_bytes());
    let file = p.to_str().unwrap();
    let with_input = aeromag(&["inspect", "--input", file]);
    let plain = aeromag(&["inspect", file]);
    assert_code(&plain, 0);
    assert_eq!(stdout(&plain), stdout(&with_input));
    let one_line = aeromag(&["inspect", file, "--lines", "1"]);
    assert_code(&one_line, 0);
    assert!(
        stdout(&one_line).contains("rows     3"),
        "{}",
        stdout(&one_line)
    );
    let both = aeromag(&["inspect", "--input", file, file]);
    assert_code(&both, 2);
    assert!(
        stderr(&both).contains("cannot be used with"),
        "{}",
        stderr(&both)
    );
    let neither = aeromag(&["inspect"]);
    assert_code(&neither, 2);
    assert!(
        stderr(&neither).contains("<--input <FILE>|FILE>"),
        "{}",
        stderr(&neither)
    );
    // Every command reading a flight takes it so.
    let out = d.path().join("m.json");
    let cal = aeromag(&["calibrate", file, "--model", out.to_str().unwrap()]);
    assert!(!stderr(&cal).contains("required"), "{}", stderr(&cal));
}

/// A file of one row has a time but no sampling (it said the file had
/// no `time` column); a file without one still says so.
#[test]
fn one_row_has_a_time_but_no_sampling() {
    let d = tempfile::tempdir().unwrap();
    let one: String = GOOD.lines().take(2).map(|l| format!("{l}\n")).collect();
    let p = write(&d, "one.csv", one.as_bytes());
    let o = aeromag(&["inspect", "--input", p.to_str().unwrap()]);
    assert_code(&o, 0);
    let s = stdout(&o);
    assert!(
        s.contains("time     0.000 s (one time only: no sampling interval)"),
        "{s}"
    );
    let p = write(&d, "untimed.csv", b"mag\n52000.1\n");
    let s = stdout(&aeromag(&["inspect", "--input", p.to_str().unwrap()]));
    assert!(s.contains("no `time` column"), "{s}");
}

/// A row whose latitude reads 0 among rows at 45° N is named as off the
/// track, in the text and in the JSON.
#[test]
fn a_position_off_the_track_is_named() {
    let d = tempfile::tempdir().unwrap();
    let glitch = GOOD.replacen("0.2,45.0,", "0.2,0,", 1);
    let p = write(&d, "glitch.csv", glitch.as_bytes());
    let o = aeromag(&["inspect", "--input", p.to_str().unwrap()]);
    assert_code(&o, 0);
    let s = stdout(&o);
    assert!(
        s.contains("position 1 row off the track") && s.contains("data row 3 [position-glitch]"),
        "{s}"
    );
    let j = aeromag(&["inspect", "--input", p.to_str().unwrap(), "--json"]);
    let v: serde_json::Value = serde_json::from_str(&stdout(&j)).unwrap();
    assert_eq!(v["position_glitch_rows"], serde_json::json!([2]));
}

#[test]
fn awkward_but_valid_files_are_read() {
    let d = tempfile::tempdir().unwrap();
    let crlf = GOOD.replace('\n', "\r\n");
    let mut bom = vec![0xEF, 0xBB, 0xBF];
    bom.extend_from_slice(GOOD.as_bytes());
    let commented = format!("# flight 7\n# units nT\n{GOOD}");
    let no_newline = GOOD.trim_end().to_string();
    let extra = GOOD
        .replace("line\n", "line,pilot\n")
        .replace(",1\n", ",1,ann\n")
        .replace(",2\n", ",2,bob\n");
    let nan = GOOD.replace("52000.2", "NaN").replace("17002", "");
    for (name, content) in [
        ("crlf.csv", crlf.into_bytes()),
        ("bom.csv", bom),
        ("comments.csv", commented.into_bytes()),
        ("nonl.csv", no_newline.into_bytes()),
        ("extra.csv", extra.into_bytes()),
        ("nan.csv", nan.into_bytes()),
    ] {
        let p = write(&d, name, &content);
        let o = aeromag(&["inspect", "--input", p.to_str().unwrap(), "--json"]);
        assert_code(&o, 0);
        let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
        assert_eq!(v["rows"], 4, "{name}");
    }
}

#[test]
fn malformed_files_exit_2_naming_file_line_and_column() {
    let d = tempfile::tempdir().unwrap();
    let cases: Vec<(&str, Vec<u8>, Vec<&str>)> = vec![
        ("empty.csv", vec![], vec!["empty.csv"]),
        (
            "header_only.csv",
            b"time,mag\n".to_vec(),
            vec!["header_only.csv"],
        ),
        (
            "truncated.csv",
            GOOD.replace("52000.3,17002,1500,48000,1", "52000.3,17002")
                .into_bytes(),
            vec!["truncated.csv", "line 4"],
        ),
        (
            "text.csv",
            GOOD.replace("52000.2", "abc").into_bytes(),
            vec!["text.csv", "line 3", "mag", "abc"],
        ),
        (
            "backwards.csv",
            GOOD.replace("0.2,45", "0.05,45").into_bytes(),
            vec!["backwards.csv", "time"],
        ),
        (
            "duplicate.csv",
            GOOD.replace("0.2,45", "0.1,45").into_bytes(),
            vec!["duplicate.csv", "time"],
        ),
        (
            "tesla.csv",
            GOOD.replace("52000.", "0.000052").into_bytes(),
            vec!["tesla.csv", "mag", "tesla"],
        ),
        (
            "binary.csv",
            vec![0x00, 0xff, 0xfe, 0x10, 0x00, 0x80, 0x81],
            vec!["binary.csv"],
        ),
        (
            "semicolon.csv",
            GOOD.replace(',', ";")
                .replace("52000.1", "52000,1")
                .into_bytes(),
            vec!["semicolon.csv"],
        ),
    ];
    for (name, content, needles) in cases {
        let p = write(&d, name, &content);
        let o = aeromag(&["inspect", "--input", p.to_str().unwrap()]);
        assert_code(&o, 2);
        let e = stderr(&o);
        assert!(!e.contains("panicked"), "{name}: {e}");
        for n in needles {
            assert!(e.contains(n), "{name}: `{n}` not in: {e}");
        }
    }
    let o = aeromag(&[
        "inspect",
        "--input",
        d.path().join("absent.csv").to_str().unwrap(),
    ]);
    assert_code(&o, 2);
    assert!(stderr(&o).contains("absent.csv"));
}

#[test]
fn malformed_xyz_exits_2() {
    let d = tempfile::tempdir().unwrap();
    let good = "/ Geosoft XYZ\n/ time mag flux_x flux_y flux_z\nLine 1010\n0.0 52000.0 17000 1500 48000\n0.1 * 17000 1500 48000\nTie 2010\n0.2 52000.2 17000 1500 48000\n";
    let p = write(&d, "good.xyz", good.as_bytes());
    let o = aeromag(&["inspect", "--input", p.to_str().unwrap(), "--json"]);
    assert_code(&o, 0);
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(v["rows"], 3);
    let bad = good.replace("0.1 * 17000", "0.1 x 17000");
    let p = write(&d, "bad.xyz", bad.as_bytes());
    let o = aeromag(&["inspect", "--input", p.to_str().unwrap()]);
    assert_code(&o, 2);
    assert!(
        stderr(&o).contains("bad.xyz") && stderr(&o).contains("line 5"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn column_mapping_of_magnav_names() {
    let d = tempfile::tempdir().unwrap();
    let magnav = GOOD.replace("time,", "tt,").replace(
        ",mag,flux_x,flux_y,flux_z,",
        ",mag_1_uc,flux_a_x,flux_a_y,flux_a_z,",
    );
    let p = write(&d, "magnav.csv", magnav.as_bytes());
    let o = aeromag(&["inspect", "--input", p.to_str().unwrap()]);
    assert_code(&o, 0);
    assert!(stdout(&o).contains("mag=mag_1_uc"), "{}", stdout(&o));
    let renamed = GOOD.replace(",mag,", ",scalar,");
    let p = write(&d, "renamed.csv", renamed.as_bytes());
    let o = aeromag(&[
        "inspect",
        "--input",
        p.to_str().unwrap(),
        "--columns",
        "mag=scalar",
    ]);
    assert_code(&o, 0);
    let o = aeromag(&[
        "inspect",
        "--input",
        p.to_str().unwrap(),
        "--columns",
        "mag=nothere",
    ]);
    assert_code(&o, 2);
    assert!(stderr(&o).contains("nothere"));
}

/// A file of our own in the layout of the SGL surveys' Geosoft XYZ export
/// (spec `data-formats.md`, "Real survey files"; the values are made up):
/// `/` header, upper-case names, `*` dummies, labels such as 1003.01, INS
/// position in radians and velocity west/up.
const SGL_XYZ: &str = "/\n/\n\
/   LINE   FLT    TIME       UTM-Z   LAT          LONG        PITCH  ROLL  AZIMUTH DIURNAL  IGRFMAG1  UNCOMPMAG1 UNCOMPMAG2 FLUXA_X  FLUXA_Y  FLUXA_Z  FLUXB_X  FLUXB_Y  FLUXB_Z  INS_LAT    INS_LON     INS_VEL_N INS_VEL_W INS_VEL_V CUR_STRB  V_BAT1\n\
 1003.01  1003  49820.00  190.0  45.3147665  -75.6633086  9.22   6.18  130.74  -5.009  -183.066  53620.756  51721.735  -5460.8  46219.7  -21467.0  40991.1  31304.5  11463.4  0.7909039  -1.3205527  -29.36  -33.31  2.92  2.507  25.757\n\
 1003.01  1003  49820.10  190.3  45.3147401  -75.6632662  9.18   6.16  130.83  -5.008  -183.522  53620.219  51726.489  -5467.9  46224.1  -21452.8  40995.3  31300.6  11449.8  0.7909034  -1.3205520  -29.43  -33.25  2.92  2.508  25.759\n\
 1003.02  1003  50713.00  384.3  44.8750983  -76.0921488  6.27  -0.70  125.58  -4.551   -87.226  53580.163  51262.653  -12787.6 46804.1  -17682.7  45836.5  24991.9  7956.7   0.7832354  -1.3280286  -43.70  -56.49  2.15  2.507  25.795\n\
 1003.02  1003  50713.10  384.5  44.8750590  -76.0920775  6.31  -0.70  125.63  -4.551   -86.141  53581.140  51269.450  *        46792.3  -17734.8  45820.8  25006.8  8008.1   0.7832347  -1.3280273  -43.65  -56.48  2.23  2.507  25.793\n";

#[test]
fn contractor_xyz_names_are_recognised_with_their_units() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "flt1003.xyz", SGL_XYZ.as_bytes());
    let o = aeromag(&["inspect", "--input", p.to_str().unwrap()]);
    assert_code(&o, 0);
    let s = stdout(&o);
    for mapped in [
        "time=TIME [s]",
        "lat=LAT [deg]",
        "lon=LONG [deg]",
        "yaw=AZIMUTH [deg]",
        "mag=UNCOMPMAG1 [nT]",
        "line=LINE [—]",
        "flux_x=FLUXA_X [nT]",
    ] {
        assert!(s.contains(mapped), "{mapped} in\n{s}");
    }
    assert!(
        s.contains("1003.01 (2 samples), 1003.02 (2 samples)"),
        "{s}"
    );
    // The JSON gives every recognised column its unit; radians stay radians
    // and are not mapped onto lat/lon.
    let j = aeromag(&["inspect", "--input", p.to_str().unwrap(), "--json"]);
    assert_code(&j, 0);
    let v: serde_json::Value = serde_json::from_str(&stdout(&j)).unwrap();
    let col = |name: &str| {
        v["columns"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["name"] == name)
            .cloned()
            .unwrap_or_else(|| panic!("{name}"))
    };
    for (name, unit) in [
        ("UNCOMPMAG2", "nT"),
        ("FLUXB_Z", "nT"),
        ("INS_LAT", "rad"),
        ("INS_VEL_W", "m/s"),
        ("CUR_STRB", "A"),
        ("V_BAT1", "V"),
        ("IGRFMAG1", "nT"),
    ] {
        assert_eq!(col(name)["unit"], unit, "{name}");
    }
    assert!(col("INS_LAT")["canonical"].is_null());
    assert!(col("IGRFMAG1")["canonical"].is_null());
    assert_eq!(col("FLUXA_X")["missing_total"], 1);
}

/// A contractor's XYZ export with several sensors (our own numbers, SGL
/// names): `--mag`/`--vector` choose the sensors by their SGL names,
/// `--lines`/`--time-range` the rows, radians and west velocities are
/// derived, and every mistake exits 2 naming the option.
#[test]
fn sensors_and_segments_of_a_whole_flight() {
    let dir = tempfile::tempdir().unwrap();
    let mut text = String::from(
        "/ XYZ EXPORT\n/ LINE TIME LAT LONG INS_LAT INS_LON INS_VEL_W UNCOMPMAG1 UNCOMPMAG2 FLUXA_X FLUXA_Y FLUXA_Z FLUXB_X FLUXB_Y FLUXB_Z\n",
    );
    for i in 0..9 {
        let line = ["1002.01", "1002.02", "1003.01"][i / 3];
        let t = 100.0 + i as f64 * 0.1;
        text.push_str(&format!(
            "{line} {t:.1} 45.0 -75.0 0.785398 -1.308997 -60.0 5300{i}.0 5310{i}.0 30000 1000 42000 31000 900 41000\n"
        ));
    }
    let f = write(&dir, "flight.xyz", text.as_bytes());
    let f = f.to_str().unwrap();
    let o = aeromag(&[
        "inspect",
        "-i",
        f,
        "--mag",
        "mag_2_uc",
        "--vector",
        "flux_b",
        "--lines",
        "1002.02,1003.01",
        "--time-range",
        "100.35,101",
    ]);
    assert_code(&o, 0);
    let s = stdout(&o);
    assert!(s.contains("rows     5"), "{s}");
    assert!(
        s.contains("mag=UNCOMPMAG2 [nT]") && s.contains("flux_x=FLUXB_X [nT]"),
        "{s}"
    );
    assert!(
        s.contains("lines    2: 1002.02 (2 samples), 1003.01 (3 samples)"),
        "{s}"
    );
    assert!(s.contains("derived  ve=INS_VEL_W (× −1) [m/s]"), "{s}");
    for (args, needle) in [
        (vec!["--mag", "mag_4_uc"], "--mag mag_4_uc: no such column"),
        (vec!["--vector", "flux_c"], "--vector flux_c"),
        (
            vec!["--lines", "1004.01"],
            "labels present: 1002.01, 1002.02, 1003.01",
        ),
        (
            vec!["--time-range", "5,1"],
            "--time-range: start 5 is after end 1",
        ),
        (
            vec!["--time-range", "0,50"],
            "the file's time runs from 100 to 100.8 s",
        ),
    ] {
        let mut a = vec!["inspect", "-i", f];
        a.extend(args);
        let o = aeromag(&a);
        assert_code(&o, 2);
        assert!(stderr(&o).contains(needle), "{}", stderr(&o));
    }
}

/// Values near f64's limit are summarised shortly: a line labelled 1e308
/// was printed with 309 digits (lines), a last time of 1e308 s likewise
/// (time, duration, gaps) and is now refused as no time in seconds (a time
/// from −1e308 to 1e308 s gave an infinite duration with exit 0), an `inf`
/// cell passed as a value.
#[test]
fn huge_times_and_labels_are_printed_shortly_and_inf_is_bad_input() {
    let d = tempfile::tempdir().unwrap();
    let huge = GOOD.replacen(
        "52000.4,17003,1500,48000,2",
        "52000.4,17003,1500,48000,1e308",
        1,
    );
    let p = write(&d, "huge.csv", huge.as_bytes());
    let o = aeromag(&["inspect", "--input", p.to_str().unwrap()]);
    assert_code(&o, 0);
    let s = stdout(&o);
    assert!(s.contains("1e308 (1 samples)"), "{s}");
    assert!(
        s.lines().all(|l| l.len() < 200) && !s.contains("inf"),
        "{s}"
    );
    for (from, to, needle) in [
        (
            "0.3,45.0",
            "1e308,45.0",
            "time 1e308 s at data row 4 (line 5)",
        ),
        (
            "0.0,45.0",
            "-1e308,45.0",
            "time -1e308 s at data row 1 (line 2)",
        ),
    ] {
        let huge = GOOD.replacen(from, to, 1);
        let p = write(&d, "huge_time.csv", huge.as_bytes());
        let o = aeromag(&["inspect", "--input", p.to_str().unwrap()]);
        assert_code(&o, 2);
        let e = stderr(&o);
        assert!(e.contains("huge_time.csv") && e.contains(needle), "{e}");
        assert!(e.len() < 400, "{e}");
    }
    let inf = GOOD.replacen("0.2,45.0,10.0,3000", "0.2,45.0,10.0,inf", 1);
    let p = write(&d, "inf.csv", inf.as_bytes());
    let o = aeromag(&["inspect", "--input", p.to_str().unwrap()]);
    assert_code(&o, 2);
    let e = stderr(&o);
    assert!(
        e.contains("inf.csv") && e.contains("'alt'") && e.contains("data row 3 (line 4)"),
        "{e}"
    );
}

/// A grid file is summarised as a grid (it was read as a flight table:
/// "NUL byte; this is not a UTF-8 text table" for a GeoTIFF); a flight
/// command given one says it is a grid.
#[test]
fn a_grid_file_is_inspected_as_a_grid_and_refused_as_a_flight() {
    let d = tempfile::tempdir().unwrap();
    let asc = write(
        &d,
        "g.asc",
        b"ncols 3\nnrows 3\nxllcenter 500000\nyllcenter 6000000\ncellsize 50\nNODATA_value -99999\n\
          1 2 3\n4 -99999 6\n7 8 9\n",
    );
    let tif = d.path().join("g.tif");
    let o = aeromag(&[
        "derive",
        asc.to_str().unwrap(),
        "--upward",
        "1",
        "--out",
        tif.to_str().unwrap(),
    ]);
    assert_code(&o, 0);
    let o = aeromag(&["inspect", asc.to_str().unwrap()]);
    assert_code(&o, 0);
    let s = stdout(&o);
    assert!(s.contains("grid     3 × 3 nodes, cell 50 m"), "{s}");
    assert!(
        s.contains("extent   x 500000 … 500100 m, y 6000000 … 6000100 m"),
        "{s}"
    );
    assert!(s.contains("8 set, 1 blank; mean 5.0000"), "{s}");
    let o = aeromag(&["inspect", tif.to_str().unwrap(), "--json"]);
    assert_code(&o, 0);
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!((v["nx"].as_u64(), v["blank"].as_u64()), (Some(3), Some(1)));
    let model = d.path().join("m.json");
    let o = aeromag(&[
        "calibrate",
        tif.to_str().unwrap(),
        "--model",
        model.to_str().unwrap(),
    ]);
    assert_code(&o, 2);
    assert!(
        stderr(&o).contains("a grid file (TIFF), not a flight table"),
        "{}",
        stderr(&o)
    );
}

/// A MATLAB v5 MAT-file (aeromag-io's test files): the fields read, what
/// is not a field printed and in the JSON; a file of several structs exits
/// 2 naming them.
#[test]
fn a_matlab_v5_file_lists_what_is_not_a_field() {
    let mat5 = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../io/tests/data/mat5");
    let p = mat5.join("magnav.mat");
    let o = aeromag(&["inspect", p.to_str().unwrap()]);
    assert_code(&o, 0);
    let s = stdout(&o);
    assert!(s.contains("rows     50"), "{s}");
    assert!(
        s.contains("not read traj.Cnb: a 3 × 3 × 50 matrix, traj.fileName: text (1 × 7)"),
        "{s}"
    );
    assert!(s.contains("mag=mag_1_uc"), "{s}");
    let j = aeromag(&["inspect", p.to_str().unwrap(), "--json"]);
    assert_code(&j, 0);
    let v: serde_json::Value = serde_json::from_str(&stdout(&j)).unwrap();
    assert_eq!(v["not_read"][0]["name"], "traj.Cnb");
    assert_eq!(v["columns"][1]["name"], "ins_lat");
    // Other formats leave the key out.
    let d = tempfile::tempdir().unwrap();
    let good = write(&d, "good.csv", GOOD.as_bytes());
    let j = aeromag(&["inspect", good.to_str().unwrap(), "--json"]);
    let v: serde_json::Value = serde_json::from_str(&stdout(&j)).unwrap();
    assert!(v.get("not_read").is_none(), "{v}");
    let o = aeromag(&["inspect", mat5.join("two_structs.mat").to_str().unwrap()]);
    assert_code(&o, 2);
    assert!(
        stderr(&o).contains("two_structs.mat': holds 2 structs (a, b)"),
        "{}",
        stderr(&o)
    );
}

/// An Oasis montaj (Geosoft) grid, harmonica's compressed test grid:
/// summarised as a grid, taken by `derive`, refused as a flight naming its
/// kind; a rotated one exits 2 saying so.
#[test]
fn a_geosoft_grid_is_inspected_and_derived() {
    let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../grid/tests/data/geosoft");
    let grd = data.join("om_compress.grd");
    let o = aeromag(&["inspect", grd.to_str().unwrap()]);
    assert_code(&o, 0);
    let s = stdout(&o);
    assert!(s.contains("grid     50 × 49 nodes, cell 1 m"), "{s}");
    assert!(s.contains("1795 set, 655 blank"), "{s}");
    let d = tempfile::tempdir().unwrap();
    let tif = d.path().join("up.tif");
    let o = aeromag(&[
        "derive",
        grd.to_str().unwrap(),
        "--upward",
        "1",
        "--out",
        tif.to_str().unwrap(),
    ]);
    assert_code(&o, 0);
    let model = d.path().join("m.json");
    let o = aeromag(&[
        "calibrate",
        grd.to_str().unwrap(),
        "--model",
        model.to_str().unwrap(),
    ]);
    assert_code(&o, 2);
    assert!(
        stderr(&o).contains("a grid file (Geosoft), not a flight table"),
        "{}",
        stderr(&o)
    );
    let o = aeromag(&["inspect", data.join("om_rotate.grd").to_str().unwrap()]);
    assert_code(&o, 2);
    let e = stderr(&o);
    assert!(
        e.contains("om_rotate.grd") && e.contains("rotated by -30°"),
        "{e}"
    );
}
