//! Long files, read with the tokenizer running ahead on a second thread:
//! the rows, their line numbers and every error past the first batches
//! (4096 rows each) are those of a plain sequential read.

mod common;

use aeromag_io::IoError;
use common::{Fixtures, assert_mentions, assert_same};

/// `rows` data rows `i,53000+i/8` under a comment and a header, with row
/// `bad` replaced by `bad_text` (data row `r` is on line `r + 3`).
fn csv(rows: usize, bad: Option<(usize, &str)>) -> String {
    let mut text = String::from("# long flight\ntime,mag\n");
    for i in 0..rows {
        match bad {
            Some((r, t)) if r == i => text.push_str(t),
            _ => text.push_str(&format!("{i},{}", 53000.0 + i as f64 / 8.0)),
        }
        text.push('\n');
    }
    text
}

#[test]
fn every_row_in_order_with_its_line() {
    let fx = Fixtures::new();
    let n = 3 * 4096 + 17;
    let t = fx.read("long.csv", csv(n, None)).unwrap();
    let time: Vec<f64> = (0..n).map(|i| i as f64).collect();
    let mag: Vec<f64> = (0..n).map(|i| 53000.0 + i as f64 / 8.0).collect();
    assert_same(t.column("time").unwrap(), &time);
    assert_same(t.column("mag").unwrap(), &mag);
    for r in [0, 4095, 4096, 8191, 8192, n - 1] {
        assert_eq!(t.line_of_row(r), Some(r as u64 + 3), "row {r}");
    }
    // The same rows with CRLF line ends.
    let crlf = fx
        .read("crlf.csv", csv(n, None).replace('\n', "\r\n"))
        .unwrap();
    assert_same(crlf.column("mag").unwrap(), &mag);
}

#[test]
fn a_short_row_after_many_batches_names_its_line() {
    let fx = Fixtures::new();
    let e = fx
        .read("short.csv", csv(20_000, Some((10_000, "1.5"))))
        .unwrap_err();
    assert!(
        matches!(
            e,
            IoError::FieldCount {
                line: 10_003,
                row: 10_000,
                expected: 2,
                found: 1,
                ..
            }
        ),
        "{e:?}"
    );
    assert_mentions(
        &e.to_string(),
        &["short.csv", "line 10003", "data row 10001"],
    );
}

/// A bad cell early in a long file stops the read there (the reader
/// ahead is stopped, not waited for to the end of the file).
#[test]
fn a_bad_cell_stops_the_reader_ahead() {
    let fx = Fixtures::new();
    let e = fx
        .read("cell.csv", csv(200_000, Some((5_000, "5000,abc"))))
        .unwrap_err();
    assert!(
        matches!(
            e,
            IoError::ParseNumber {
                line: 5_003,
                row: 5_000,
                ..
            }
        ),
        "{e:?}"
    );
    assert_mentions(
        &e.to_string(),
        &["cell.csv", "'abc'", "column 'mag'", "line 5003"],
    );
}

#[test]
fn xyz_line_records_across_batches() {
    let fx = Fixtures::new();
    let mut text = String::from("/ time mag\n");
    let mut lines = Vec::new();
    for i in 0..10_000 {
        if i % 1500 == 0 {
            text.push_str(&format!("Line {}\n", 1000 + i / 1500));
        }
        text.push_str(&format!("{i} {}\n", 53000 + i));
        lines.push((1000 + i / 1500) as f64);
    }
    let t = fx.read("long.xyz", text).unwrap();
    assert_same(t.column("line").unwrap(), &lines);
    // Row 9000 follows seven records: line 9000 + 1 (header) + 7 + 1.
    assert_eq!(t.line_of_row(9000), Some(9009));
    assert_eq!(t.column("mag").unwrap()[9999], 62999.0);
}
