//! check_time / check_units on files: errors name file, rows, lines, columns.

mod common;

use aeromag_io::{FlightTable, IoError, WarningKind, check_time, check_units, convert_tesla_to_nt};
use common::{Fixtures, assert_mentions};

#[test]
fn increasing_time_passes() {
    let fx = Fixtures::new();
    let t = fx.read("ok.csv", "time,mag\n0,1\n0.1,2\n0.2,3\n").unwrap();
    check_time(&t).unwrap();
}

#[test]
fn repeated_time_names_both_rows_and_lines() {
    let fx = Fixtures::new();
    let t = fx
        .read("rep.csv", "# c\ntime,mag\n0,1\n0.1,2\n# gap\n0.1,3\n")
        .unwrap();
    let e = check_time(&t).unwrap_err();
    assert!(
        matches!(
            e,
            IoError::NotIncreasing {
                row_a: 1,
                row_b: 2,
                line_a: Some(4),
                line_b: Some(6),
                ..
            }
        ),
        "{e:?}"
    );
    assert_mentions(
        &e.to_string(),
        &[
            "rep.csv",
            "'time'",
            "data row 3 (line 6) has 0.1",
            "data row 2 (line 4) has 0.1",
        ],
    );
}

#[test]
fn step_back_is_an_error() {
    let fx = Fixtures::new();
    let t = fx.read("back.csv", "time\n5\n6\n5.5\n").unwrap();
    let e = check_time(&t).unwrap_err();
    assert!(
        matches!(
            e,
            IoError::NotIncreasing {
                row_a: 1,
                row_b: 2,
                ..
            }
        ),
        "{e:?}"
    );
    assert_mentions(&e.to_string(), &["5.5", "6", "line 4", "line 3"]);
}

#[test]
fn missing_time_is_an_error() {
    let fx = Fixtures::new();
    let t = fx.read("nan.csv", "time,mag\n0,1\n,2\n").unwrap();
    let e = check_time(&t).unwrap_err();
    assert!(
        matches!(
            e,
            IoError::MissingValue {
                row: 1,
                line: Some(3),
                ..
            }
        ),
        "{e:?}"
    );
    assert_mentions(
        &e.to_string(),
        &["nan.csv", "'time'", "data row 2", "line 3"],
    );
    let t = fx.read("notime.csv", "mag\n1\n").unwrap();
    assert!(matches!(check_time(&t), Err(IoError::MissingColumn { .. })));
}

fn table(cols: &[(&str, Vec<f64>)]) -> FlightTable {
    let mut t = FlightTable::new();
    for (n, v) in cols {
        t.add_column(n, v.clone()).unwrap();
    }
    t
}

#[test]
fn tesla_gauss_and_picotesla_are_errors() {
    let cases = [
        (5.2e-5, "looks like tesla"),
        (0.52, "looks like gauss"),
        (5.2e7, "picotesla"),
        (0.003, "far below"),
    ];
    for (v, what) in cases {
        let t = table(&[("mag", vec![v, v * 1.01, f64::NAN])]);
        let e = check_units(&t).unwrap_err();
        assert!(matches!(e, IoError::Units { .. }), "{v}: {e:?}");
        assert_mentions(&e.to_string(), &["'mag'", what]);
    }
    let t = table(&[("igrf", vec![5.2e-5; 3])]);
    assert_mentions(
        &check_units(&t).unwrap_err().to_string(),
        &["'igrf'", "multiply by 1e9)"],
    );
}

/// A total field in microtesla (53.1 for 53 100 nT) was a warning only,
/// and `calibrate` fitted it with exit 0; an anomaly of that median, with
/// values of both signs or spread beyond a factor 2, is still a warning.
#[test]
fn microtesla_is_an_error_an_anomaly_a_warning() {
    let ut = table(&[("mag", vec![53.06, 53.1, 53.62, f64::NAN])]);
    let e = check_units(&ut).unwrap_err();
    assert!(matches!(e, IoError::Units { .. }), "{e:?}");
    assert_mentions(&e.to_string(), &["'mag'", "microtesla", "multiply by 1000"]);
    let igrf = table(&[("igrf", vec![48.0, 48.1])]);
    assert_mentions(
        &check_units(&igrf).unwrap_err().to_string(),
        &["'igrf'", "microtesla"],
    );
    let flux = table(&[
        ("flux_x", vec![14.0, 14.1]),
        ("flux_y", vec![3.7, 3.6]),
        ("flux_z", vec![51.1, 51.2]),
    ]);
    assert_mentions(
        &check_units(&flux).unwrap_err().to_string(),
        &["flux_x/flux_y/flux_z", "microtesla"],
    );
    for anomaly in [vec![53.0, -20.0, 60.0], vec![53.0, 20.0, 160.0]] {
        let t = table(&[("mag", anomaly)]);
        let w = check_units(&t).unwrap();
        assert_eq!(w.len(), 1, "{w:?}");
        assert_eq!(w[0].kind, WarningKind::FieldRange);
    }
}

#[test]
fn flux_components_and_diurnal_in_tesla() {
    let t = table(&[
        ("flux_x", vec![1e-5, -2e-5]),
        ("flux_y", vec![0.0, 3e-6]),
        ("flux_z", vec![4e-5, 4e-5]),
    ]);
    let e = check_units(&t).unwrap_err();
    assert_mentions(&e.to_string(), &["'flux_x'", "tesla"]);
    let t = table(&[("diurnal", vec![1e-9, -2e-9])]);
    assert_mentions(
        &check_units(&t).unwrap_err().to_string(),
        &["'diurnal'", "tesla"],
    );
    // Small diurnal values in nT and an all-zero column are fine.
    let t = table(&[
        ("diurnal", vec![0.3, -0.2, 0.0]),
        ("flux_z", vec![0.0, 0.0, 0.0]),
    ]);
    assert!(check_units(&t).unwrap().is_empty());
}

#[test]
fn earth_field_in_nt_passes_and_odd_magnitudes_warn() {
    let t = table(&[
        ("mag", vec![53_000.0, 53_010.0]),
        ("flux_x", vec![20_000.0, 20_100.0]),
        ("flux_y", vec![-3_000.0, 2_000.0]),
        ("flux_z", vec![48_000.0, 48_100.0]),
        ("diurnal", vec![3.0, -4.0]),
    ]);
    assert!(check_units(&t).unwrap().is_empty());
    let t = table(&[("mag", vec![120.0, -80.0, 30.0])]);
    let w = check_units(&t).unwrap();
    assert_eq!(w.len(), 1);
    assert_eq!(w[0].column.as_deref(), Some("mag"));
    assert!(
        w[0].message.contains("outside Earth's total field"),
        "{}",
        w[0]
    );
}

#[test]
fn field_range_and_vector_against_scalar_are_named_warnings() {
    // 80 000 nT is outside Earth's 15 000–75 000 nT.
    let w = check_units(&table(&[("mag", vec![80_000.0, 80_100.0])])).unwrap();
    assert_eq!(w.len(), 1);
    assert_eq!(w[0].kind, WarningKind::FieldRange);
    assert!(w[0].to_string().ends_with("[field-range]"), "{}", w[0]);
    // A vector magnitude 9 % from the scalar passes (real fluxgates differ
    // by up to 9.5 %), 14 % is warned about, naming both sensors.
    let field = |scale: f64| {
        table(&[
            ("mag", vec![50_000.0, 50_000.0, 50_000.0]),
            ("flux_x", vec![30_000.0 * scale; 3]),
            ("flux_y", vec![0.0; 3]),
            ("flux_z", vec![40_000.0 * scale; 3]),
        ])
    };
    assert!(check_units(&field(1.09)).unwrap().is_empty());
    let w = check_units(&field(1.14)).unwrap();
    assert_eq!(w.len(), 1, "{w:?}");
    assert_eq!(w[0].kind, WarningKind::VectorVsScalar);
    assert!(
        w[0].message.contains("+14.0 %") && w[0].message.contains("(mag)"),
        "{}",
        w[0]
    );
    assert!(check_units(&field(0.85)).unwrap().len() == 1);
}

/// One reading beyond any magnetic field in nT (a corrupted cell, a
/// numeric dummy) is bad input naming its column, row and line, once the
/// column's units pass; a file in picotesla is still reported as such.
#[test]
fn a_reading_beyond_any_field_names_its_row() {
    let fx = Fixtures::new();
    let t = fx
        .read(
            "flux.csv",
            "time,mag,flux_x,flux_y,flux_z\n0,53000,20000,1000,45000\n0.1,53001,20001,1e300,45001\n0.2,53002,20002,1002,45002\n",
        )
        .unwrap();
    let e = check_units(&t).unwrap_err();
    assert!(matches!(e, IoError::Units { .. }), "{e:?}");
    assert_mentions(
        &e.to_string(),
        &[
            "flux.csv",
            "'flux_y'",
            "1e300",
            "data row 2 (line 3)",
            "empty",
        ],
    );
    for (name, dummy) in [("mag", -1e32), ("igrf", 2e6), ("diurnal", -1.5e6)] {
        let mut v = vec![53_000.0; 9];
        v[6] = dummy;
        let e = check_units(&table(&[(name, v)])).unwrap_err();
        assert_mentions(&e.to_string(), &[&format!("'{name}'"), "data row 7"]);
    }
    // At the limit (a total field's limit: a negative one is no reading,
    // below), and a picotesla file's median first.
    let t = table(&[("mag", vec![53_000.0, 1e6, 53_000.0])]);
    assert!(check_units(&t).is_ok());
    let t = table(&[("diurnal", vec![3.0, -1e6, 4.0])]);
    assert!(check_units(&t).is_ok());
    let t = table(&[("mag", vec![5.3e7, 5.3e7, 5.3e7])]);
    assert_mentions(&check_units(&t).unwrap_err().to_string(), &["picotesla"]);
}

/// A dropout value (0, −99999) or a negated reading in a total-field
/// `mag` was compensated as a reading (0 gave `mag_comp` 20.5 nT, flagged
/// compensated) and went into fits: bad input naming the first row. An
/// anomaly column (its median outside Earth's field, warned about) is not
/// tested.
#[test]
fn a_total_field_below_any_reading_names_its_first_row() {
    let fx = Fixtures::new();
    let t = fx
        .read(
            "drop.csv",
            "time,mag\n0,53000\n0.1,53001\n0.2,0\n0.3,53002\n0.4,-99999\n",
        )
        .unwrap();
    let e = check_units(&t).unwrap_err();
    assert!(matches!(e, IoError::Units { .. }), "{e:?}");
    assert_mentions(
        &e.to_string(),
        &[
            "drop.csv",
            "'mag'",
            "0 nT at data row 3 (line 4)",
            "at least 1000 nT",
            "median is 53001 nT",
            "dropout",
            "empty",
        ],
    );
    let e = check_units(&table(&[("mag", vec![-53_000.0; 5])])).unwrap_err();
    assert_mentions(&e.to_string(), &["-53000 nT at data row 1", "negated"]);
    // 999.99 is below, 1000 is a reading (of a total field whose median
    // is Earth's); an anomaly column holds small and negative values.
    let mut v = vec![53_000.0; 9];
    v[4] = 999.99;
    assert_mentions(
        &check_units(&table(&[("mag", v.clone())]))
            .unwrap_err()
            .to_string(),
        &["999.99 nT at data row 5"],
    );
    v[4] = 1000.0;
    assert!(check_units(&table(&[("mag", v)])).is_ok());
    let anomaly = table(&[("mag", vec![-120.0, 0.0, 35.5, 12.0, 800.0])]);
    let w = check_units(&anomaly).unwrap();
    assert!(
        w.len() == 1 && w[0].kind == WarningKind::FieldRange,
        "{w:?}"
    );
}

#[test]
fn position_checks() {
    let fx = Fixtures::new();
    let t = fx
        .read("swap.csv", "time,lat,lon\n0,45,-75\n1,-100.5,45\n")
        .unwrap();
    let e = check_units(&t).unwrap_err();
    assert!(matches!(e, IoError::Units { .. }), "{e:?}");
    assert_mentions(
        &e.to_string(),
        &["swap.csv", "'lat'", "-100.5", "data row 2", "line 3"],
    );
    let t = table(&[("lat", vec![0.0, 1.0]), ("lon", vec![5e5, 6e5])]);
    assert_mentions(
        &check_units(&t).unwrap_err().to_string(),
        &["'lon'", "500000"],
    );
    let t = table(&[("lat", vec![0.78, 0.79]), ("lon", vec![-1.3, -1.31])]);
    let w = check_units(&t).unwrap();
    assert!(w.len() == 1 && w[0].message.contains("radians"), "{w:?}");
    let t = table(&[("lat", vec![45.0, 45.1]), ("lon", vec![-75.0, -75.1])]);
    assert!(check_units(&t).unwrap().is_empty());
}

#[test]
fn attitude_checks() {
    // Degrees through a 270° turn: no warning.
    let n = 200;
    let yaw_deg: Vec<f64> = (0..n).map(|i| i as f64 * 270.0 / n as f64).collect();
    let roll_deg: Vec<f64> = (0..n).map(|i| 25.0 * (i as f64 * 0.05).sin()).collect();
    let pitch_deg = vec![2.0; n];
    let t = table(&[
        ("roll", roll_deg.clone()),
        ("pitch", pitch_deg.clone()),
        ("yaw", yaw_deg.clone()),
    ]);
    assert!(check_units(&t).unwrap().is_empty());
    // The same flight in radians: warning.
    let rad = |v: &Vec<f64>| v.iter().map(|x| x.to_radians()).collect::<Vec<_>>();
    let t = table(&[
        ("roll", rad(&roll_deg)),
        ("pitch", rad(&pitch_deg)),
        ("yaw", rad(&yaw_deg)),
    ]);
    let w = check_units(&t).unwrap();
    assert!(w.len() == 1 && w[0].message.contains("radians"), "{w:?}");
    // Impossible degrees: errors.
    let t = table(&[("pitch", vec![0.0, 95.0])]);
    assert_mentions(
        &check_units(&t).unwrap_err().to_string(),
        &["'pitch'", "95", "data row 2"],
    );
    let t = table(&[("roll", vec![-190.0])]);
    assert!(check_units(&t).is_err());
    let t = table(&[("yaw", vec![0.0, 400.0])]);
    let w = check_units(&t).unwrap();
    assert!(w.len() == 1 && w[0].row == Some(1), "{w:?}");
}

#[test]
fn altitude_warning_and_tesla_conversion() {
    let t = table(&[("alt", vec![30_000.0, 31_000.0])]);
    assert_eq!(check_units(&t).unwrap().len(), 1);
    let mut t = table(&[
        ("mag", vec![5.3e-5, 5.31e-5]),
        ("time", vec![0.0, 1.0]),
        ("igrf", vec![5.2e-5, 5.2e-5]),
    ]);
    assert!(check_units(&t).is_err());
    let converted = convert_tesla_to_nt(&mut t);
    assert_eq!(converted, vec!["mag", "igrf"]);
    assert!((t.column("mag").unwrap()[0] - 53_000.0).abs() < 1e-6);
    assert_eq!(t.column("time").unwrap(), &[0.0, 1.0]);
    check_units(&t).unwrap();
}

/// A huge value is named in exponent form, not as hundreds of digits.
#[test]
fn huge_values_are_named_shortly() {
    let t = table(&[("lat", vec![45.0, 1e300]), ("lon", vec![-75.0, -75.0])]);
    let e = check_units(&t).unwrap_err().to_string();
    assert!(
        e.contains("latitude 1e300 at data row 2") && e.len() < 200,
        "{e}"
    );
    let t = table(&[("yaw", vec![10.0, -1e300])]);
    let w = check_units(&t).unwrap();
    assert!(w[0].message.contains("yaw -1e300 is outside"), "{w:?}");
    let t = table(&[("roll", vec![0.0, 181.5])]);
    let e = check_units(&t).unwrap_err().to_string();
    assert!(e.contains("roll 181.5 at data row 2"), "{e}");
}

/// `inf` in a cell is a number to the cell parser, but the range rules
/// test finite values only: an infinite latitude, field, height or line
/// number passed every check (fuzzing: `level` wrote `inf` into
/// `mag_level` and the crossover table, exit 0). Now bad input naming the
/// column and row.
#[test]
fn an_infinite_value_names_its_column_and_row() {
    let fx = Fixtures::new();
    let t = fx
        .read(
            "inf.csv",
            "time,lat,lon,mag\n0,56,38,53000\n0.5,inf,38,53001\n1,56,38,53002\n",
        )
        .unwrap();
    let e = check_units(&t).unwrap_err();
    assert!(
        matches!(e, IoError::Units { .. }) && e.is_bad_input(),
        "{e:?}"
    );
    assert_mentions(&e.to_string(), &["inf.csv", "'lat'", "data row 2 (line 3)"]);
    for name in ["mag", "alt", "line", "flux_y", "yaw", "time"] {
        let mut v = vec![100.0; 5];
        v[3] = if name == "alt" {
            f64::NEG_INFINITY
        } else {
            f64::INFINITY
        };
        if name == "mag" {
            v = v.iter().map(|x| x * 530.0).collect();
        }
        let e = check_units(&table(&[(name, v)])).unwrap_err();
        assert_mentions(&e.to_string(), &[&format!("'{name}'"), "data row 4"]);
    }
    // A column outside the list keeps its infinities.
    assert!(check_units(&table(&[("other", vec![0.0, f64::INFINITY])])).is_ok());
}

/// A height beyond any aircraft's (a corrupted cell) is bad input naming
/// its row: one 1e308 m made levelling fail with a "singular system".
#[test]
fn a_height_beyond_any_flight_names_its_row() {
    let t = table(&[("alt", vec![250.0, 1e308, 251.0])]);
    let e = check_units(&t).unwrap_err().to_string();
    assert!(
        e.contains("'alt'") && e.contains("height 1e308 m at data row 2"),
        "{e}"
    );
    let t = table(&[("alt", vec![250.0, -aeromag_io::MAX_ALT_M, 251.0])]);
    assert!(check_units(&t).is_ok());
}

/// A time of 1e308 in the "not increasing" error is shown in exponent
/// form (it was printed with all 309 digits).
#[test]
fn a_huge_time_in_the_increasing_check_is_named_shortly() {
    let t = table(&[("time", vec![0.0, 1e308, 2.0])]);
    let e = check_time(&t).unwrap_err().to_string();
    assert!(
        e.contains("has 2 after data row 2 has 1e308") && e.len() < 200,
        "{e}"
    );
}

/// A survey's time in minutes (or hours) moves it faster than any
/// aircraft: a named warning on the time column; in seconds, none.
#[test]
fn time_in_minutes_is_a_named_warning() {
    // 60 m/s due north at 10 Hz: 5.4e-5° of latitude a sample.
    let n = 500;
    let flight = |time_scale: f64| {
        table(&[
            (
                "time",
                (0..n).map(|k| k as f64 * 0.1 * time_scale).collect(),
            ),
            (
                "lat",
                (0..n).map(|k| 56.0 + k as f64 * 6.0 / 111_195.0).collect(),
            ),
            ("lon", vec![38.0; n]),
        ])
    };
    assert!(check_units(&flight(1.0)).unwrap().is_empty());
    let w = check_units(&flight(1.0 / 60.0)).unwrap();
    assert_eq!(w.len(), 1, "{w:?}");
    assert_eq!(w[0].kind, WarningKind::TimeUnit);
    assert_eq!(w[0].column.as_deref(), Some("time"));
    assert!(
        w[0].message.contains("3600 m/s") && w[0].to_string().ends_with("[time-unit]"),
        "{}",
        w[0]
    );
    // A stationary record (a base station) and a slow one are no warning.
    let still = table(&[
        ("time", (0..n).map(|k| k as f64).collect()),
        ("lat", vec![56.0; n]),
        ("lon", vec![38.0; n]),
    ]);
    assert!(check_units(&still).unwrap().is_empty());
    // Time in milliseconds: 6 m a row, a row every 100 "s" (0.06 m/s).
    let w = check_units(&flight(1000.0)).unwrap();
    assert_eq!(w.len(), 1, "{w:?}");
    assert_eq!(w[0].kind, WarningKind::TimeUnit);
    assert!(w[0].message.contains("milliseconds"), "{}", w[0]);
    // A boat at 2 m/s logging every 10 s (20 m a row) is no warning.
    let boat = table(&[
        ("time", (0..n).map(|k| k as f64 * 10.0).collect()),
        (
            "lat",
            (0..n).map(|k| 56.0 + k as f64 * 20.0 / 111_195.0).collect(),
        ),
        ("lon", vec![38.0; n]),
    ]);
    assert!(check_units(&boat).unwrap().is_empty());
}

/// Found by fuzzing: two rows 1e-9 s apart in a 10 Hz flight were taken,
/// and `compensate` wrote an interference of −177 747 nT as compensated.
#[test]
fn a_time_step_far_below_the_median_is_refused_naming_the_rows() {
    let table = |t: Vec<f64>| {
        let mut tb = FlightTable::new();
        tb.add_column("time", t).unwrap();
        tb
    };
    let mut t: Vec<f64> = (0..100).map(|k| k as f64 * 0.1).collect();
    // Jitter of a few per cent and a gap pass.
    t[50] += 0.004;
    for v in &mut t[80..] {
        *v += 3.0;
    }
    check_time(&table(t.clone())).unwrap();
    for dt in [1e-9, 1e-6, 5e-4] {
        let mut g = t.clone();
        g[10] = g[9] + dt;
        let e = check_time(&table(g)).unwrap_err();
        let msg = e.to_string();
        assert!(
            e.is_bad_input() && msg.contains("data row 11") && msg.contains("median step (0.1"),
            "{msg}"
        );
    }
}
