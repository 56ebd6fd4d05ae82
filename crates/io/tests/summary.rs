//! summarize on a file: sampling, gaps, lines, missing values, ranges, JSON.

mod common;

use aeromag_io::{ColumnKind, summarize};
use common::Fixtures;

#[test]
fn summary_of_a_small_survey() {
    let fx = Fixtures::new();
    let text = "\
time,line,mag,flux_x,flux_y,flux_z,id
0.0,1010,53000,3,4,0,a
0.1,1010,,3,4,0,a
0.2,1010,53002,3,4,12,a
0.7,2010,53003,3,4,0,b
0.8,2010,NaN,3,4,0,b
0.9,1010,53001,3,4,0,c
";
    let t = fx.read("s.csv", text).unwrap();
    let s = summarize(&t);
    assert_eq!(s.rows, 6);
    let time = s.time.as_ref().unwrap();
    assert!((time.sample_interval_s - 0.1).abs() < 1e-12);
    assert!((time.duration_s - 0.9).abs() < 1e-12);
    assert_eq!(time.gaps, 1);
    assert_eq!(time.largest_gap_row, Some(3));
    assert!((time.largest_gap_s.unwrap() - 0.5).abs() < 1e-12);
    let lines = s.lines.as_ref().unwrap();
    let got: Vec<_> = lines.iter().map(|l| (l.line.as_str(), l.samples)).collect();
    assert_eq!(got, vec![("1010", 4), ("2010", 2)]);
    let mag = s.columns.iter().find(|c| c.name == "mag").unwrap();
    assert_eq!(
        (mag.missing_total, mag.missing.blank, mag.missing.nan),
        (2, 1, 1)
    );
    assert_eq!((mag.min, mag.max), (Some(53000.0), Some(53003.0)));
    assert!((mag.mean.unwrap() - 53001.5).abs() < 1e-9);
    assert_eq!(
        s.columns.iter().find(|c| c.name == "id").unwrap().kind,
        ColumnKind::Text
    );
    let r = s.mag_range_nt.unwrap();
    assert_eq!((r.min, r.max), (53000.0, 53003.0));
    let f = s.flux_magnitude_range_nt.unwrap();
    assert_eq!((f.min, f.max), (5.0, 13.0));

    let json = serde_json::to_value(&s).unwrap();
    assert_eq!(json["rows"], 6);
    assert_eq!(json["time"]["gaps"], 1);
    assert_eq!(json["lines"][1]["line"], "2010");
    assert_eq!(json["columns"][2]["missing"]["blank"], 1);
}

#[test]
fn summary_without_time_or_lines() {
    let fx = Fixtures::new();
    let t = fx.read("n.csv", "mag\n1\n").unwrap();
    let s = summarize(&t);
    assert!(s.time.is_none() && s.lines.is_none() && s.flux_magnitude_range_nt.is_none());
    assert!(serde_json::to_string(&s).unwrap().contains("\"time\":null"));
}
