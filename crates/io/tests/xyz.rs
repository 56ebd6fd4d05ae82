//! Geosoft XYZ reader: header rule, Line/Tie records, dummies, errors with line numbers.

mod common;

use aeromag_io::{IoError, ReadOptions, read_table, read_xyz};
use common::{Fixtures, assert_mentions, assert_same};

const NAN: f64 = f64::NAN;

const SURVEY: &str = "\
/ XYZ EXPORT [06/20/2020]
/ DATABASE   [survey.gdb]
/
/   time        lat         lon        mag
//  s           deg         deg        nT
Line 1010
   0.0    45.001    -75.002    53210.4
   0.1    45.002    -75.002          *
/ a comment between rows

tie 2010
   0.2    45.003    -75.003    53211.0
LINE L1020.5
   0.3    45.004    -75.003    53212.5
";

#[test]
fn survey_with_records_dummies_and_units_line() {
    let fx = Fixtures::new();
    let t = fx.read("survey.xyz", SURVEY).unwrap();
    assert_eq!(
        t.column_names(),
        vec!["time", "lat", "lon", "mag", "line", "line_type"]
    );
    assert_same(t.column("time").unwrap(), &[0.0, 0.1, 0.2, 0.3]);
    assert_same(t.column("mag").unwrap(), &[53210.4, NAN, 53211.0, 53212.5]);
    assert_eq!(t.missing("mag").unwrap().dummy, 1);
    assert_same(t.column("line").unwrap(), &[1010.0, 1010.0, 2010.0, 1020.5]);
    assert_same(t.column("line_type").unwrap(), &[0.0, 0.0, 1.0, 0.0]);
    assert_eq!(
        (0..4)
            .map(|r| t.line_of_row(r).unwrap())
            .collect::<Vec<_>>(),
        vec![7, 8, 12, 14]
    );
}

#[test]
fn crlf_bom_comma_header_and_no_trailing_newline() {
    let fx = Fixtures::new();
    let text = "\u{feff}/time,lat,mag\r\n\r\n0 45 1\r\n1 46 2";
    let t = fx.read("c.xyz", text).unwrap();
    assert_eq!(
        t.column_names(),
        vec!["time", "lat", "mag"],
        "no records: no line columns"
    );
    assert_same(t.column("mag").unwrap(), &[1.0, 2.0]);
    assert_eq!(t.line_of_row(1), Some(4));
}

#[test]
fn rows_before_the_first_record_have_missing_line() {
    let fx = Fixtures::new();
    let t = fx.read("r.xyz", "/ time mag\n0 1\nLine 7\n1 2\n").unwrap();
    assert_same(t.column("line").unwrap(), &[NAN, 7.0]);
    assert_same(t.column("line_type").unwrap(), &[NAN, 0.0]);
}

#[test]
fn header_with_line_column_gets_xyz_line() {
    let fx = Fixtures::new();
    let t = fx
        .read("l.xyz", "/ time line mag\nLine 5\n0 99 1\n")
        .unwrap();
    assert_same(t.column("line").unwrap(), &[99.0]);
    assert_same(t.column("xyz_line").unwrap(), &[5.0]);
    assert_same(t.column("line_type").unwrap(), &[0.0]);
}

#[test]
fn last_matching_header_wins_and_text_columns_pass() {
    let fx = Fixtures::new();
    // The first comment has 3 names too, but the later one is the header.
    let text = "/ old header here\n/ time date mag\n0 2020/06/20 1\n1 2020/06/20 2\n";
    let t = fx.read("h.xyz", text).unwrap();
    assert_eq!(t.column_names(), vec!["time", "date", "mag"]);
    assert_eq!(
        t.text_column("date").unwrap(),
        &["2020/06/20", "2020/06/20"]
    );
}

#[test]
fn read_table_dispatches_on_extension_and_content() {
    let fx = Fixtures::new();
    let t = read_table(&fx.file("s.txt", SURVEY), &ReadOptions::default()).unwrap();
    assert!(t.column("line").is_some(), ".txt starting with '/' is XYZ");
    let t = read_table(
        &fx.file("s.dat", "time,mag\n0,1\n"),
        &ReadOptions::default(),
    )
    .unwrap();
    assert_eq!(t.n_rows(), 1);
    let t = read_xyz(&fx.file("s.anything", SURVEY), &ReadOptions::default()).unwrap();
    assert_eq!(t.n_rows(), 4);
}

// ---------------------------------------------------------------- errors

#[test]
fn no_header() {
    let fx = Fixtures::new();
    let e = fx.read("nh.xyz", "/ time mag\n\n0 1 2\n").unwrap_err();
    assert!(matches!(e, IoError::XyzHeader { line: 3, .. }), "{e:?}");
    assert_mentions(
        &e.to_string(),
        &["nh.xyz", "line 3", "3 values", "no column-name header"],
    );
    let e = fx.read("nh2.xyz", "0 1 2\n").unwrap_err();
    assert!(matches!(e, IoError::XyzHeader { line: 1, .. }), "{e:?}");
}

#[test]
fn bad_line_record() {
    let fx = Fixtures::new();
    let e = fx.read("br.xyz", "/ time mag\nLine\n0 1\n").unwrap_err();
    assert!(matches!(e, IoError::XyzHeader { line: 2, .. }), "{e:?}");
    assert_mentions(
        &e.to_string(),
        &["br.xyz", "line 2", "'Line'", "no line number"],
    );
    let e = fx
        .read("br2.xyz", "/ time mag\n0 1\nTie abc\n1 2\n")
        .unwrap_err();
    assert!(matches!(e, IoError::XyzHeader { line: 3, .. }), "{e:?}");
}

#[test]
fn short_and_long_rows() {
    let fx = Fixtures::new();
    let e = fx
        .read("s.xyz", "/ time lat mag\nLine 1\n0 1 2\n1 2\n")
        .unwrap_err();
    assert!(
        matches!(
            e,
            IoError::FieldCount {
                line: 4,
                row: 1,
                expected: 3,
                found: 2,
                header_line: 1,
                ..
            }
        ),
        "{e:?}"
    );
    assert_mentions(
        &e.to_string(),
        &["s.xyz", "line 4", "data row 2", "whitespace"],
    );
    let e = fx.read("l.xyz", "/ time mag\n0 1\n1 2 3\n").unwrap_err();
    assert!(
        matches!(
            e,
            IoError::FieldCount {
                line: 3,
                found: 3,
                ..
            }
        ),
        "{e:?}"
    );
}

#[test]
fn text_in_numeric_column() {
    let fx = Fixtures::new();
    let e = fx
        .read("t.xyz", "/ time mag\nLine 1\n0 1\n1 abc\n")
        .unwrap_err();
    assert!(
        matches!(
            e,
            IoError::ParseNumber {
                line: 4,
                row: 1,
                ..
            }
        ),
        "{e:?}"
    );
    assert_mentions(
        &e.to_string(),
        &[
            "cannot parse 'abc' as a number in column 'mag' at line 4 (data row 2)",
            "t.xyz",
        ],
    );
}

#[test]
fn empty_comments_only_and_no_data() {
    let fx = Fixtures::new();
    let e = fx.read("e.xyz", "").unwrap_err();
    assert!(matches!(e, IoError::Empty { .. }), "{e:?}");
    let e = fx.read("e2.xyz", "\n\n").unwrap_err();
    assert!(matches!(e, IoError::Empty { .. }), "{e:?}");
    let e = fx.read("nd.xyz", "/ time mag\nLine 10\n").unwrap_err();
    assert!(matches!(e, IoError::NoData { header_line: 1, .. }), "{e:?}");
    assert_mentions(&e.to_string(), &["nd.xyz", "no data rows"]);
}

#[test]
fn binary_and_duplicates() {
    let fx = Fixtures::new();
    let e = fx.read("b.xyz", b"/ time mag\n0 \x001\n").unwrap_err();
    assert!(matches!(e, IoError::Binary { line: 2, .. }), "{e:?}");
    let e = fx.read("d.xyz", "/ time mag time\n0 1 2\n").unwrap_err();
    assert!(
        matches!(
            e,
            IoError::DuplicateHeader {
                line: 1,
                first: 1,
                second: 3,
                ..
            }
        ),
        "{e:?}"
    );
}
