//! CSV reader: every awkward-but-valid layout and every malformed case of the
//! brief, asserting the error variant and that the message names the file,
//! the line and the column.

mod common;

use aeromag_io::{ColumnMap, IoError, MapOrigin, ReadOptions, read_csv};
use common::{Fixtures, assert_mentions, assert_same};

fn nan() -> f64 {
    f64::NAN
}

// ---------------------------------------------------------------- valid files

#[test]
fn plain_file() {
    let fx = Fixtures::new();
    let t = fx
        .read("a.csv", "time,lat,mag\n0,45.5,53000.25\n0.1,45.6,53001\n")
        .unwrap();
    assert_eq!(t.n_rows(), 2);
    assert_eq!(t.column_names(), vec!["time", "lat", "mag"]);
    assert_same(t.column("mag").unwrap(), &[53000.25, 53001.0]);
    assert_eq!(t.source(), Some(fx.path("a.csv").as_path()));
    assert_eq!(t.line_of_row(0), Some(2));
}

#[test]
fn crlf_bom_and_no_trailing_newline() {
    let fx = Fixtures::new();
    let t = fx
        .read("b.csv", b"\xEF\xBB\xBFtime,mag\r\n0,1\r\n1,2\r\n2,3")
        .unwrap();
    assert_eq!(
        t.column_names(),
        vec!["time", "mag"],
        "BOM must not stick to the first name"
    );
    assert_same(t.column("time").unwrap(), &[0.0, 1.0, 2.0]);
    assert_same(t.column("mag").unwrap(), &[1.0, 2.0, 3.0]);
    assert_eq!(t.line_of_row(2), Some(4));
}

/// Lines ending in `\r` alone (a classic Mac OS file) were read as one
/// header line: "column name '0.0' appears twice", or an XYZ file's "a
/// header but no data rows".
#[test]
fn cr_only_line_ends_are_named() {
    let fx = Fixtures::new();
    for (name, text) in [
        ("mac.csv", "time,mag\r0,53000\r0.1,53001\r"),
        (
            "mac.xyz",
            "/ survey\rTIME MAG LINE\r0 53000 1\r0.1 53001 1\r",
        ),
    ] {
        let e = fx.read(name, text).unwrap_err();
        assert!(matches!(e, IoError::CrLineEnds { line: 1, .. }), "{e:?}");
        assert!(e.is_bad_input());
        assert_mentions(&e.to_string(), &[name, "line 1", "\\r alone"]);
    }
    // A long one is named so too, not "the header has 360019 columns".
    let rows = "0.1,53001\r".repeat(60_000);
    for (name, text) in [
        ("long_mac.csv", format!("time,mag\r{rows}")),
        (
            "long_mac.xyz",
            format!("TIME MAG\r{}", rows.replace(',', " ")),
        ),
    ] {
        let e = fx.read(name, &text).unwrap_err();
        assert!(
            matches!(e, IoError::CrLineEnds { line: 1, .. }),
            "{name}: {e:?}"
        );
    }
    // A CRLF file with a quoted header name still reads.
    let t = fx.read("q.csv", "time,\"mag\"\r\n0,53000\r\n").unwrap();
    assert_eq!(t.column_names(), vec!["time", "mag"]);
}

#[test]
fn comments_anywhere_and_blank_lines_keep_line_numbers() {
    let fx = Fixtures::new();
    let text = "# survey 42\n# units: s, nT\n\ntime,mag\n0,1\n# a comment\n1,2\n\n2,3\n";
    let t = fx.read("c.csv", text).unwrap();
    assert_eq!(t.n_rows(), 3);
    assert_same(t.column("mag").unwrap(), &[1.0, 2.0, 3.0]);
    assert_eq!(
        (0..3)
            .map(|r| t.line_of_row(r).unwrap())
            .collect::<Vec<_>>(),
        vec![5, 7, 9]
    );
}

#[test]
fn missing_cells_are_counted_by_reason() {
    let fx = Fixtures::new();
    let text = "time,mag,diurnal\n0,,NaN\n1,nan,*\n2, * ,3\n3,4, \n";
    let t = fx.read("d.csv", text).unwrap();
    assert_same(t.column("mag").unwrap(), &[nan(), nan(), nan(), 4.0]);
    assert_same(t.column("diurnal").unwrap(), &[nan(), nan(), 3.0, nan()]);
    let m = t.missing("mag").unwrap();
    assert_eq!((m.blank, m.nan, m.dummy, m.total()), (1, 1, 1, 3));
    let d = t.missing("diurnal").unwrap();
    assert_eq!((d.blank, d.nan, d.dummy), (1, 1, 1));
    assert_eq!(t.n_rows(), 4, "rows with missing cells are kept");
}

#[test]
fn number_spellings_and_whitespace() {
    let fx = Fixtures::new();
    let t = fx
        .read("e.csv", "time,mag\n 12 ,+5\n1e-3,-1.5E+2\n\t.5\t,5.\n")
        .unwrap();
    assert_same(t.column("time").unwrap(), &[12.0, 1e-3, 0.5]);
    assert_same(t.column("mag").unwrap(), &[5.0, -150.0, 5.0]);
}

#[test]
fn extra_columns_numeric_and_text() {
    let fx = Fixtures::new();
    // `code` looks numeric for two rows, then has text: it becomes a text
    // column with the original spelling of the first rows ("007", "1.50").
    let text = "time,mag,flight,code,aux\n0,1,F-101,007,9\n1,2,F-101,1.50,8\n2,3,F-102,x12,7\n";
    let t = fx.read("f.csv", text).unwrap();
    assert_eq!(
        t.text_column("flight").unwrap(),
        &["F-101", "F-101", "F-102"]
    );
    assert_eq!(t.text_column("code").unwrap(), &["007", "1.50", "x12"]);
    assert_same(t.column("aux").unwrap(), &[9.0, 8.0, 7.0]);
    assert!(t.column("flight").is_none());
}

#[test]
fn text_column_turning_late_in_a_long_file() {
    // The switch happens after the capacity estimate (row 1024): the second
    // pass must recover all earlier cells.
    let fx = Fixtures::new();
    let mut text = String::from("time,tag\n");
    for i in 0..3000 {
        let tag = if i == 2500 {
            "end".to_string()
        } else {
            format!("{i:04}")
        };
        text.push_str(&format!("{i},{tag}\n"));
    }
    let t = fx.read("g.csv", text).unwrap();
    let tags = t.text_column("tag").unwrap();
    assert_eq!(tags.len(), 3000);
    assert_eq!(tags[7], "0007");
    assert_eq!(tags[2500], "end");
    assert_eq!(tags[2999], "2999");
}

#[test]
fn quoted_fields() {
    let fx = Fixtures::new();
    let t = fx
        .read(
            "h.csv",
            "time,note,mag\n0,\"a, b\",\"12.5\"\n1,\"say \"\"hi\"\"\",13\n",
        )
        .unwrap();
    assert_eq!(t.text_column("note").unwrap(), &["a, b", "say \"hi\""]);
    assert_same(t.column("mag").unwrap(), &[12.5, 13.0]);

    // A quoted field spanning two lines: later rows keep exact line numbers.
    let text = "time,note,mag\r\n0,\"two\r\nlines\",1\r\n1,plain,2\r\n2,x,bad\r\n";
    let e = fx.read("ml.csv", text).unwrap_err();
    assert!(
        matches!(
            e,
            IoError::ParseNumber {
                line: 5,
                row: 2,
                ..
            }
        ),
        "{e:?}"
    );
    let t = fx
        .read("ml2.csv", "time,note,mag\n0,\"two\nlines\",1\n1,plain,2\n")
        .unwrap();
    assert_eq!(t.text_column("note").unwrap(), &["two\nlines", "plain"]);
    assert_eq!((t.line_of_row(0), t.line_of_row(1)), (Some(2), Some(4)));
}

#[test]
fn semicolon_tab_and_whitespace_delimiters_are_detected() {
    let fx = Fixtures::new();
    for (name, text) in [
        ("s.csv", "time;mag\n0;1\n1;2\n"),
        ("t.csv", "time\tmag\n0\t1\n1\t2\n"),
        ("w.csv", "# whitespace table\ntime   mag\n 0  1\n1 2\n"),
    ] {
        let t = fx
            .read(name, text)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_same(t.column("mag").unwrap(), &[1.0, 2.0]);
    }
    let t = fx.read("one.csv", "mag\n1\n2\n").unwrap();
    assert_same(t.column("mag").unwrap(), &[1.0, 2.0]);
}

#[test]
fn empty_header_names_become_unnamed() {
    let fx = Fixtures::new();
    let t = fx.read("u.csv", ",time,mag\n0,0,1\n1,1,2\n").unwrap();
    assert_eq!(t.column_names(), vec!["unnamed_1", "time", "mag"]);
}

#[test]
fn user_column_map_and_magnav_preset() {
    let fx = Fixtures::new();
    let text = "tt,lat,lon,utm_z,ins_roll,ins_pitch,ins_yaw,mag_1_uc,mag_3_uc,flux_a_x,flux_a_y,flux_a_z,line\n\
                0,45,-75,300,1,2,3,53000,53100,10,20,30,1001\n";
    let t = fx.read("m.csv", text).unwrap();
    assert_same(t.require("time").unwrap(), &[0.0]);
    assert_same(t.require("alt").unwrap(), &[300.0]);
    assert_same(t.require("mag").unwrap(), &[53000.0]);
    assert_same(t.require("flux_z").unwrap(), &[30.0]);
    assert!(
        t.mapping()
            .iter()
            .all(|m| m.origin == MapOrigin::MagNavPreset)
    );
    assert_eq!(t.column_names()[0], "tt", "mapping does not rename");

    let opts = ReadOptions {
        columns: ColumnMap::parse("mag=mag_3_uc").unwrap(),
        ..ReadOptions::default()
    };
    let t = fx.read_with("m.csv", text, &opts).unwrap();
    assert_same(t.require("mag").unwrap(), &[53100.0]);
    let m = t.mapping().iter().find(|m| m.canonical == "mag").unwrap();
    assert_eq!(
        (m.file_column.as_str(), m.origin),
        ("mag_3_uc", MapOrigin::User)
    );

    let off = ReadOptions {
        magnav_preset: false,
        ..ReadOptions::default()
    };
    let t = fx.read_with("m.csv", text, &off).unwrap();
    assert!(t.column("mag").is_none() && t.mapping().is_empty());
}

#[test]
fn read_csv_ignores_extension() {
    let fx = Fixtures::new();
    let p = fx.file("data.dat", "time,mag\n0,1\n");
    let t = read_csv(&p, &ReadOptions::default()).unwrap();
    assert_eq!(t.n_rows(), 1);
}

// ---------------------------------------------------------------- errors

#[test]
fn missing_file() {
    let fx = Fixtures::new();
    let p = fx.path("nope.csv");
    let e = aeromag_io::read_table(&p, &ReadOptions::default()).unwrap_err();
    assert!(matches!(e, IoError::Open { .. }), "{e:?}");
    assert_mentions(&e.to_string(), &["nope.csv", "cannot open"]);
    assert!(e.is_bad_input());
}

#[test]
fn directory_is_not_a_table() {
    let fx = Fixtures::new();
    let p = fx.path("");
    let e = read_csv(&p, &ReadOptions::default()).unwrap_err();
    assert!(matches!(e, IoError::Open { .. }), "{e:?}");
}

#[test]
fn empty_file_and_comments_only() {
    let fx = Fixtures::new();
    for (name, text) in [
        ("empty.csv", ""),
        ("comments.csv", "# nothing\n\n# here\n"),
        ("bom.csv", "\u{feff}"),
    ] {
        let e = fx.read(name, text).unwrap_err();
        assert!(matches!(e, IoError::Empty { .. }), "{name}: {e:?}");
        assert_mentions(&e.to_string(), &[name, "empty"]);
    }
}

#[test]
fn header_only() {
    let fx = Fixtures::new();
    for (name, text) in [
        ("h1.csv", "# c\ntime,mag\n"),
        ("h2.csv", "# c\ntime,mag"),
        ("h3.csv", "# c\ntime,mag\n# more\n\n"),
    ] {
        let e = fx.read(name, text).unwrap_err();
        assert!(
            matches!(e, IoError::NoData { header_line: 2, .. }),
            "{name}: {e:?}"
        );
        assert_mentions(&e.to_string(), &[name, "line 2", "no data rows"]);
    }
}

#[test]
fn required_column_missing() {
    let fx = Fixtures::new();
    let t = fx.read("r.csv", "time,lat\n0,1\n").unwrap();
    let e = t.require("mag").unwrap_err();
    assert!(matches!(e, IoError::MissingColumn { .. }), "{e:?}");
    assert_mentions(
        &e.to_string(),
        &["r.csv", "'mag'", "time, lat", "--columns mag="],
    );
}

#[test]
fn text_in_numeric_column_names_line_row_and_column() {
    let fx = Fixtures::new();
    let mut text = String::from("# flight 7\ntime,mag\n");
    for i in 0..20 {
        let mag = if i == 14 {
            "abc".to_string()
        } else {
            format!("{}", 53000 + i)
        };
        text.push_str(&format!("{i},{mag}\n"));
    }
    let e = fx.read("p.csv", &text).unwrap_err();
    assert!(
        matches!(
            e,
            IoError::ParseNumber {
                line: 17,
                row: 14,
                ..
            }
        ),
        "{e:?}"
    );
    assert_mentions(
        &e.to_string(),
        &[
            "cannot parse 'abc' as a number in column 'mag' at line 17 (data row 15)",
            "p.csv",
        ],
    );
}

#[test]
fn text_in_truth_and_mapped_columns() {
    let fx = Fixtures::new();
    let e = fx
        .read("q.csv", "time,true_anomaly\n0,1\n1,oops\n")
        .unwrap_err();
    assert!(
        matches!(
            e,
            IoError::ParseNumber {
                line: 3,
                row: 1,
                ..
            }
        ),
        "{e:?}"
    );
    assert_mentions(
        &e.to_string(),
        &["'oops'", "'true_anomaly'", "line 3", "q.csv"],
    );

    let opts = ReadOptions {
        columns: ColumnMap::parse("mag=sensor").unwrap(),
        ..ReadOptions::default()
    };
    let e = fx
        .read_with("q2.csv", "time,sensor\n0,x\n", &opts)
        .unwrap_err();
    assert_mentions(
        &e.to_string(),
        &[
            "'sensor' (mapped to 'mag')",
            "line 2",
            "data row 1",
            "q2.csv",
        ],
    );
}

#[test]
fn decimal_comma_gets_a_hint() {
    let fx = Fixtures::new();
    let e = fx.read("dc.csv", "time;mag\n0;53000,5\n").unwrap_err();
    assert!(matches!(e, IoError::ParseNumber { .. }), "{e:?}");
    assert_mentions(
        &e.to_string(),
        &["'53000,5'", "decimal comma", "'mag'", "line 2"],
    );
}

#[test]
fn short_and_long_rows_are_errors() {
    let fx = Fixtures::new();
    let e = fx
        .read("short.csv", "time,lat,mag\n0,1,2\n1,2\n2,3,4\n")
        .unwrap_err();
    assert!(
        matches!(
            e,
            IoError::FieldCount {
                line: 3,
                row: 1,
                expected: 3,
                found: 2,
                ..
            }
        ),
        "{e:?}"
    );
    assert_mentions(
        &e.to_string(),
        &[
            "short.csv",
            "line 3",
            "data row 2",
            "2 fields",
            "3 columns",
            "line 1",
        ],
    );

    let e = fx
        .read("long.csv", "time,mag\r\n0,1\r\n1,2,3\r\n")
        .unwrap_err();
    assert!(
        matches!(
            e,
            IoError::FieldCount {
                line: 3,
                expected: 2,
                found: 3,
                ..
            }
        ),
        "{e:?}"
    );

    // A trailing comma on data rows only is a long row too.
    let e = fx.read("trail.csv", "time,mag\n0,1,\n").unwrap_err();
    assert!(
        matches!(
            e,
            IoError::FieldCount {
                line: 2,
                found: 3,
                ..
            }
        ),
        "{e:?}"
    );

    let e = fx.read("ws.txt", "time lat mag\n0 1 2\n1 2\n").unwrap_err();
    assert!(
        matches!(
            e,
            IoError::FieldCount {
                line: 3,
                found: 2,
                ..
            }
        ),
        "{e:?}"
    );
    assert_mentions(&e.to_string(), &["whitespace"]);
}

#[test]
fn binary_garbage() {
    let fx = Fixtures::new();
    // NUL bytes near the start (e.g. a zip or HDF5 file renamed to .csv).
    let e = fx
        .read(
            "bin.csv",
            b"\x89HDF\r\n\x1a\n\x00\x00\x00\x00\x00\x08\x08\x00",
        )
        .unwrap_err();
    assert!(matches!(e, IoError::Binary { line: 3, .. }), "{e:?}");
    assert_mentions(
        &e.to_string(),
        &["bin.csv", "line 3", "NUL", "not a UTF-8 text table"],
    );

    // UTF-16 (as saved by some spreadsheet programs).
    let e = fx
        .read("utf16.csv", b"\xFF\xFEt\x00i\x00m\x00e\x00\n\x00")
        .unwrap_err();
    assert!(matches!(e, IoError::Binary { line: 1, .. }), "{e:?}");
    assert_mentions(
        &e.to_string(),
        &["utf16.csv", "UTF-16", "save the file as UTF-8"],
    );

    // Invalid UTF-8 in the header row.
    let e = fx.read("latin1.csv", b"time,\xb5T\n0,1\n").unwrap_err();
    assert!(matches!(e, IoError::Binary { line: 1, .. }), "{e:?}");

    // Invalid UTF-8 and NUL in cells far beyond the sniffed start.
    let mut big = String::from("time,mag,note\n");
    for i in 0..10_000 {
        big.push_str(&format!("{i},53000.125,ok\n"));
    }
    let mut bytes = big.clone().into_bytes();
    bytes.extend_from_slice(b"10000,5\xff3,ok\n");
    let e = fx.read("late.csv", &bytes).unwrap_err();
    assert!(matches!(e, IoError::Binary { line: 10_002, .. }), "{e:?}");
    assert_mentions(
        &e.to_string(),
        &[
            "late.csv",
            "line 10002",
            "invalid UTF-8",
            "'mag'",
            "data row 10001",
        ],
    );

    let mut bytes = big.into_bytes();
    bytes.extend_from_slice(b"10000,1,o\x00k\n");
    let e = fx.read("late_nul.csv", &bytes).unwrap_err();
    assert!(matches!(e, IoError::Binary { line: 10_002, .. }), "{e:?}");
    assert_mentions(&e.to_string(), &["NUL byte in column 'note'"]);
}

#[test]
fn duplicated_header_names() {
    let fx = Fixtures::new();
    let e = fx
        .read("dup.csv", "# x\ntime,mag,lat,mag\n0,1,2,3\n")
        .unwrap_err();
    assert!(
        matches!(
            e,
            IoError::DuplicateHeader {
                line: 2,
                first: 2,
                second: 4,
                ..
            }
        ),
        "{e:?}"
    );
    assert_mentions(&e.to_string(), &["dup.csv", "line 2", "'mag'", "twice"]);
}

#[test]
fn forced_wrong_delimiter() {
    let fx = Fixtures::new();
    let opts = ReadOptions {
        delimiter: Some(b','),
        ..ReadOptions::default()
    };
    let e = fx
        .read_with("semi.csv", "time;lat;mag\n0;1;2\n", &opts)
        .unwrap_err();
    assert!(
        matches!(e, IoError::WrongDelimiter { line: 1, .. }),
        "{e:?}"
    );
    assert_mentions(
        &e.to_string(),
        &["semi.csv", "wrong delimiter?", "one column 'time;lat;mag'"],
    );
}

#[test]
fn mapped_column_absent() {
    let fx = Fixtures::new();
    let opts = ReadOptions {
        columns: ColumnMap::parse("mag=mag_9_uc").unwrap(),
        ..ReadOptions::default()
    };
    let e = fx
        .read_with("ma.csv", "time,mag_1_uc\n0,1\n", &opts)
        .unwrap_err();
    assert!(matches!(e, IoError::MappedColumnAbsent { .. }), "{e:?}");
    assert_mentions(&e.to_string(), &["ma.csv", "'mag_9_uc'", "time, mag_1_uc"]);
}

#[test]
fn a_damaged_h5_is_an_hdf5_error_naming_the_file() {
    let fx = Fixtures::new();
    let p = fx.file("flight.h5", b"\x89HDF");
    let e = aeromag_io::read_table(&p, &ReadOptions::default()).unwrap_err();
    assert!(matches!(e, IoError::Hdf5 { .. }), "{e:?}");
    assert_mentions(&e.to_string(), &["flight.h5"]);
}

/// A quote left open runs to the end of the file (csv-core reads every
/// line after it as one field): an error naming the row's first line and
/// the quote (it was "2 fields, but the header has 3 columns" on the line
/// before the row's). A quoted field closed on the last line, with a line
/// end in it or not, reads.
#[test]
fn a_quote_left_open_is_named_at_its_row() {
    let d = tempfile::tempdir().unwrap();
    let read = |text: &str| {
        let p = d.path().join("q.csv");
        std::fs::write(&p, text).unwrap();
        aeromag_io::read_table(&p, &ReadOptions::default())
    };
    for text in [
        "time,mag,note\n0,1,a\n0.1,2,b\n0.2,\"3,c\n0.3,4,d\n",
        "time,mag,note\r\n0,1,a\r\n0.1,2,b\r\n0.2,\"3,c\r\n0.3,4,d\r\n",
        "time,mag,note\n0,1,a\n0.1,2,b\n0.2,3,\"c\n",
    ] {
        let e = read(text).unwrap_err();
        assert!(
            matches!(e, IoError::UnclosedQuote { line: 4, .. }) && e.is_bad_input(),
            "{text:?}: {e:?}"
        );
        assert!(e.to_string().contains("line 4: a quote"), "{e}");
    }
    for text in [
        "time,mag,note\n0,1,a\n0.1,2,\"b\nc\"\n",
        "time,mag,note\n0,1,a\n0.1,2,\"b\n\"\n",
        "time,mag,note\n0,1,a\n0.1,\"2\",\"b\nc\"\n",
    ] {
        let t = read(text).unwrap();
        assert_eq!(t.n_rows(), 2, "{text:?}");
    }
}
