//! write_csv → read_csv preserves every value bit for bit (NaN positions
//! included; NaN payloads are not kept) and text cells exactly.

mod common;

use aeromag_io::{ColumnData, FlightTable, IoError, ReadOptions, read_csv, write_csv};
use common::{Fixtures, assert_same};
use proptest::prelude::*;

/// Any f64 bit pattern: normals, subnormals, ±0, ±inf, NaNs of every payload.
fn any_f64() -> impl Strategy<Value = f64> {
    prop_oneof![
        any::<u64>().prop_map(f64::from_bits),
        Just(f64::NAN),
        Just(-0.0),
        Just(f64::INFINITY),
        Just(f64::MIN_POSITIVE / 4.0),
        (-1e6f64..1e6f64),
    ]
}

/// Text that cannot parse as a number (starts with a letter) but may contain
/// commas, quotes, '#', spaces and line ends.
fn text_cell() -> impl Strategy<Value = String> {
    ("[a-zA-Z]", "[a-z0-9 ,\"#\n\r;.é-]{0,8}").prop_map(|(a, b)| format!("{a}{b}"))
}

fn table_strategy() -> impl Strategy<Value = FlightTable> {
    (1usize..40, 1usize..5, 0usize..2).prop_flat_map(|(rows, n_num, n_text)| {
        (
            proptest::collection::vec(proptest::collection::vec(any_f64(), rows), n_num),
            proptest::collection::vec(proptest::collection::vec(text_cell(), rows), n_text),
        )
            .prop_map(|(nums, texts)| {
                let mut t = FlightTable::new();
                // Canonical, truth and free names: all must survive.
                let names = ["mag", "true_anomaly", "aux", "flux_x"];
                for (k, v) in nums.into_iter().enumerate() {
                    t.add_column(names[k], v).unwrap();
                }
                for (k, v) in texts.into_iter().enumerate() {
                    t.add_text_column(&format!("note{k}"), v).unwrap();
                }
                t
            })
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]
    #[test]
    fn write_then_read_is_lossless(t in table_strategy()) {
        let fx = Fixtures::new();
        let path = fx.path("rt.csv");
        write_csv(&t, &path).unwrap();
        let back = read_csv(&path, &ReadOptions::default()).unwrap();
        prop_assert_eq!(back.n_rows(), t.n_rows());
        prop_assert_eq!(back.column_names(), t.column_names());
        for c in t.columns() {
            match c.data() {
                ColumnData::Numeric { values, .. } => {
                    let got = back.column(c.name()).expect("numeric column read back");
                    assert_same(got, values);
                    let nans = values.iter().filter(|v| v.is_nan()).count();
                    prop_assert_eq!(back.missing(c.name()).unwrap().total(), nans);
                }
                ColumnData::Text(v) => {
                    prop_assert_eq!(back.text_column(c.name()).expect("text column read back"), &v[..]);
                }
            }
        }
    }
}

#[test]
fn zero_row_table_reads_back_as_header_only_error() {
    let fx = Fixtures::new();
    let mut t = FlightTable::new();
    t.add_column("time", vec![]).unwrap();
    let path = fx.path("empty.csv");
    write_csv(&t, &path).unwrap();
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "time\n");
    assert!(matches!(
        read_csv(&path, &ReadOptions::default()),
        Err(IoError::NoData { .. })
    ));
}

#[test]
fn write_error_names_the_file() {
    let fx = Fixtures::new();
    let mut t = FlightTable::new();
    t.add_column("time", vec![1.0]).unwrap();
    let path = fx.path("no/such/dir/out.csv");
    let e = write_csv(&t, &path).unwrap_err();
    assert!(
        matches!(e, IoError::Write { .. }) && !e.is_bad_input(),
        "{e:?}"
    );
    assert!(e.to_string().contains("out.csv"), "{e}");
}

/// A pass-through column keeps the form it was written in: integers stay
/// integers (`1003`, not `1003.0`), other numbers are written exactly
/// (shortest form), and a column changed in memory loses the integer form.
#[test]
fn integers_are_written_back_as_integers() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("in.csv");
    std::fs::write(
        &src,
        "time,line,flt,mixed,big\n0.0,1003.01,1003,7,123456789012345\n0.1,1003.02,1003,7.5,-42\n0.2,L1020,+1004,,9\n",
    )
    .unwrap();
    let mut t = read_csv(&src, &ReadOptions::default()).unwrap();
    let col = |t: &FlightTable, n: &str| {
        t.columns()
            .iter()
            .find(|c| c.name() == n)
            .unwrap()
            .integer_text()
    };
    assert!(col(&t, "flt") && col(&t, "big"));
    assert!(!col(&t, "mixed") && !col(&t, "time"));
    let out = dir.path().join("out.csv");
    write_csv(&t, &out).unwrap();
    assert_eq!(
        std::fs::read_to_string(&out).unwrap(),
        "time,line,flt,mixed,big\n0.0,1003.01,1003,7.0,123456789012345\n0.1,1003.02,1003,7.5,-42\n0.2,L1020,1004,,9\n"
    );
    t.set_column("flt", vec![1.0, 2.0, 3.0]).unwrap();
    assert!(!col(&t, "flt"));
}
