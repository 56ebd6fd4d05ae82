//! The readers' limits on hostile files (issue 18, point 6): a line longer
//! than `MAX_LINE_BYTES`, a quoted field that never closes, a header of more
//! than `MAX_COLUMNS` columns are clear errors naming the file and the line,
//! read in bounded memory; a header at the limit is read (in linear time).
//! Peak memory on 1 GB lines and 10^6 columns: `scripts/hostile_inputs.sh`.

mod common;

use aeromag_io::{IoError, MAX_COLUMNS, MAX_LINE_BYTES, ReadOptions, read_xyz};
use common::Fixtures;

fn too_large(e: IoError, line: u64) -> String {
    let s = e.to_string();
    assert!(e.is_bad_input(), "{s}");
    match e {
        IoError::TooLarge { line: l, .. } if line > 0 => assert_eq!(l, line, "{s}"),
        IoError::TooLarge { .. } => {}
        other => panic!("expected TooLarge, got {other:?}"),
    }
    s
}

fn long(len: u64, byte: u8) -> Vec<u8> {
    vec![byte; len as usize]
}

#[test]
fn csv_line_over_the_limit_is_an_error() {
    let fx = Fixtures::new();
    let mut f = b"time,mag\n0,".to_vec();
    f.extend(long(MAX_LINE_BYTES + 1, b'1'));
    f.extend(b"\n1,2\n");
    let s = too_large(fx.read("long.csv", &f).unwrap_err(), 2);
    assert!(s.contains("long.csv") && s.contains("16 MiB"), "{s}");
    // A line of separators only (millions of empty fields).
    let mut f = b"time,mag\n".to_vec();
    f.extend(long(MAX_LINE_BYTES + 1, b','));
    too_large(fx.read("commas.csv", &f).unwrap_err(), 2);
    // The header line itself.
    let mut f = b"# comment\n".to_vec();
    f.extend(long(MAX_LINE_BYTES + 1, b'a'));
    f.extend(b"\n1\n");
    too_large(fx.read("header.csv", &f).unwrap_err(), 2);
}

#[test]
fn csv_unclosed_quote_is_bounded() {
    let fx = Fixtures::new();
    let mut f = b"time,note\n0,\"".to_vec();
    for _ in 0..(MAX_LINE_BYTES / 8 + 1) {
        f.extend(b"1234567\n");
    }
    // (The line of a record whose quote never closes is not reliable.)
    too_large(fx.read("quote.csv", &f).unwrap_err(), 0);
}

#[test]
fn csv_line_at_the_limit_is_read() {
    let fx = Fixtures::new();
    // A text cell just under the limit (the line is "0,<cell>").
    let mut f = b"time,note\n0,".to_vec();
    f.extend(long(MAX_LINE_BYTES - 2, b'x'));
    f.extend(b"\r\n1,y\r\n");
    let t = fx.read("atlimit.csv", &f).unwrap();
    assert_eq!(t.n_rows(), 2);
}

#[test]
fn xyz_line_over_the_limit_is_an_error() {
    let fx = Fixtures::new();
    let mut f = b"/ time mag\nLine 10\n0 1\n".to_vec();
    f.extend(long(MAX_LINE_BYTES + 1, b'1'));
    let p = fx.file("long.xyz", &f);
    let s = too_large(read_xyz(&p, &ReadOptions::default()).unwrap_err(), 4);
    assert!(s.contains("long.xyz"), "{s}");
    // A comment line.
    let mut f = b"/ ".to_vec();
    f.extend(long(MAX_LINE_BYTES, b'a'));
    f.extend(b"\n/ time mag\n0 1\n");
    let p = fx.file("comment.xyz", &f);
    too_large(read_xyz(&p, &ReadOptions::default()).unwrap_err(), 1);
    // A whitespace table.
    let mut f = b"time mag\n".to_vec();
    f.extend(long(MAX_LINE_BYTES + 1, b' '));
    too_large(fx.read("long.txt", &f).unwrap_err(), 2);
}

fn header(n: usize, sep: &str) -> String {
    (0..n)
        .map(|i| format!("c{i}"))
        .collect::<Vec<_>>()
        .join(sep)
}

#[test]
fn more_columns_than_the_limit_is_an_error() {
    let fx = Fixtures::new();
    let n = 1_000_000;
    let ones = vec!["1"; n];
    let csv = format!("{}\n{}\n", header(n, ","), ones.join(","));
    let s = too_large(fx.read("wide.csv", &csv).unwrap_err(), 1);
    assert!(s.contains("1000000 columns") && s.contains("100000"), "{s}");
    let xyz = format!("/ {}\n{}\n", header(n, " "), ones.join(" "));
    too_large(fx.read("wide.xyz", &xyz).unwrap_err(), 2);
    let txt = format!("{}\n{}\n", header(n, " "), ones.join(" "));
    too_large(fx.read("wide.txt", &txt).unwrap_err(), 1);
}

#[test]
fn a_header_at_the_column_limit_is_read() {
    // Also the duplicate-name check: linear (it was quadratic: 5·10^9
    // comparisons for 10^5 columns).
    let fx = Fixtures::new();
    let start = std::time::Instant::now();
    let row = vec!["1"; MAX_COLUMNS].join(",");
    let t = fx
        .read(
            "limit.csv",
            format!("{}\n{row}\n{row}\n", header(MAX_COLUMNS, ",")),
        )
        .unwrap();
    assert_eq!((t.n_rows(), t.columns().len()), (2, MAX_COLUMNS));
    assert!(start.elapsed().as_secs() < 20, "{:?}", start.elapsed());
    let mut h = header(MAX_COLUMNS - 1, ",");
    h.push_str(",c7");
    match fx.read("dup.csv", format!("{h}\n{row}\n")).unwrap_err() {
        IoError::DuplicateHeader { first, second, .. } => {
            assert_eq!((first, second), (8, MAX_COLUMNS))
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn xyz_header_rule_after_many_comment_lines() {
    // The comment lines are read twice instead of kept: same header rule.
    let fx = Fixtures::new();
    let mut f = String::new();
    for i in 0..10_000 {
        f.push_str(&format!("/ a{i} b c\n"));
    }
    f.push_str("// time mag\n/ x y\n/ 1 2\n  / lead mag\nLine 3\n0 1\n1 2\n");
    let p = fx.file("comments.xyz", &f);
    let t = read_xyz(&p, &ReadOptions::default()).unwrap();
    let names: Vec<&str> = t.columns().iter().map(|c| c.name()).collect();
    assert_eq!(names, ["x", "y", "line", "line_type"]);
}
