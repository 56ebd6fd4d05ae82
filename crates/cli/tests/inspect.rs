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
