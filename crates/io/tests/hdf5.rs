//! HDF5 flight files in the MagNav/SGL layout, written by h5py
//! (`tools/reference/sgl_h5.py`, files in `tests/data/hdf5`): every field
//! of every layout read bit-exactly (FNV-1a checksums of the float64
//! values computed by the generator), only the fields asked for read, and
//! files that are not in the layout or not HDF5 at all refused with a
//! message naming the file, never a panic.

use std::path::{Path, PathBuf};

use aeromag_io::{Fields, IoError, ReadOptions, RowSelection, read_table};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/hdf5")
        .join(name)
}

fn expected() -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(data("expected.json")).unwrap()).unwrap()
}

/// FNV-1a 64 over the little-endian bytes of the values.
fn fnv(values: &[f64]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for v in values {
        for b in v.to_le_bytes() {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    format!("{h:016x}")
}

#[test]
fn every_layout_reads_every_field_bit_exactly() {
    let exp = expected();
    let files = exp["files"].as_object().unwrap();
    let mut checked = 0;
    for (file, spec) in files {
        if file == "twod.h5" {
            continue;
        }
        let t = read_table(&data(file), &ReadOptions::default()).unwrap();
        for (path, ds) in spec["datasets"].as_object().unwrap() {
            let name = path.rsplit('/').next().unwrap();
            if ds["len"].as_u64() == Some(0) {
                assert!(t.get(name).is_none(), "{file}: empty '{name}' is skipped");
                continue;
            }
            let c = t.get(name).unwrap_or_else(|| panic!("{file}: {name}"));
            let v = c.values().unwrap();
            assert_eq!(v.len() as u64, ds["len"].as_u64().unwrap(), "{file} {name}");
            assert_eq!(fnv(v), ds["fnv_f64"].as_str().unwrap(), "{file} {name}");
            let integer = !ds["dtype"].as_str().unwrap().contains('f');
            assert_eq!(c.integer_text(), integer, "{file} {name}");
            checked += 1;
        }
        // MagNav names are mapped and radians derived.
        assert_eq!(t.resolve("time"), Some("tt"), "{file}");
        assert_eq!(t.resolve("mag"), Some("mag_1_uc"), "{file}");
        assert!(t.derived().is_empty(), "{file}: lat is in the file");
    }
    assert!(checked >= 90, "{checked} datasets checked");
}

#[test]
fn only_the_fields_asked_for_are_read() {
    for file in ["root_gzip.h5", "group_contig.h5"] {
        let opts = ReadOptions {
            fields: Fields::Only(vec!["time".into(), "mag".into(), "ins_vn".into()]),
            ..ReadOptions::default()
        };
        let t = read_table(&data(file), &opts).unwrap();
        let mut names = t.column_names();
        names.sort();
        assert_eq!(names, ["ins_vn", "mag_1_uc", "tt"], "{file}");
        // The others are listed, and named when a column is missing.
        let unread = t.unread_columns();
        assert!(unread.contains(&"mag_2_uc"), "{file}: {unread:?}");
        assert!(!unread.contains(&"tt"), "{file}: {unread:?}");
        let e = t.require("flux_x").unwrap_err().to_string();
        assert!(e.contains("mag_2_uc"), "{file}: {e}");
        // Patterns: a prefix and a suffix.
        let opts = ReadOptions {
            fields: Fields::Only(vec!["MAG_*".into(), "*_vn".into()]),
            ..ReadOptions::default()
        };
        let t = read_table(&data(file), &opts).unwrap();
        let mut names = t.column_names();
        names.sort();
        assert_eq!(names, ["ins_vn", "mag_1_uc", "mag_2_uc"], "{file}");
        // A row selection brings its `line` and `time`.
        let opts = ReadOptions {
            fields: Fields::Only(vec!["mag_2_uc".into()]),
            rows: RowSelection::parse(Some("1001"), None).unwrap(),
            ..ReadOptions::default()
        };
        let t = read_table(&data(file), &opts).unwrap();
        assert!(t.n_rows() > 0 && t.n_rows() < 250, "{file}: {}", t.n_rows());
        assert!(t.column("line").unwrap().iter().all(|&l| l == 1001.0));
    }
}

#[test]
fn a_file_in_another_layout_is_refused_with_what_was_expected() {
    let e = read_table(&data("twod.h5"), &ReadOptions::default()).unwrap_err();
    assert!(matches!(e, IoError::Hdf5Layout { .. }), "{e:?}");
    let s = e.to_string();
    assert!(
        s.contains("twod.h5") && s.contains("one 1-D dataset per field") && s.contains("[250, 3]"),
        "{s}"
    );
    assert!(e.is_bad_input());
}

#[test]
fn damaged_and_fake_hdf5_files_are_errors_not_panics() {
    let dir = tempfile::tempdir().unwrap();
    let whole = std::fs::read(data("root_gzip.h5")).unwrap();
    let mut cases: Vec<(&str, Vec<u8>)> = vec![
        ("empty.h5", Vec::new()),
        ("text.h5", b"time,mag\n0,1\n".to_vec()),
        ("signature_only.h5", b"\x89HDF\r\n\x1a\n".to_vec()),
        ("half.h5", whole[..whole.len() / 2].to_vec()),
        ("tenth.h5", whole[..whole.len() / 10].to_vec()),
    ];
    // Bytes flipped in the superblock and the first object headers.
    for k in [8usize, 13, 40, 100, 300, 800] {
        let mut b = whole.clone();
        b[k] ^= 0xff;
        cases.push(("flipped.h5", b));
    }
    for (name, bytes) in cases {
        let p = dir.path().join(name);
        std::fs::write(&p, &bytes).unwrap();
        match read_table(&p, &ReadOptions::default()) {
            Ok(t) => assert!(t.n_rows() <= 250, "{name}"),
            Err(e) => {
                assert!(e.to_string().contains(name), "{name}: {e}");
                assert!(e.is_bad_input(), "{name}: {e}");
            }
        }
    }
    // A missing file is an open error, said once.
    let e = read_table(&dir.path().join("absent.h5"), &ReadOptions::default()).unwrap_err();
    assert!(matches!(e, IoError::Open { .. }), "{e:?}");
}

#[test]
fn hdf5_is_recognised_by_content_whatever_the_extension() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("flight.mat");
    std::fs::copy(data("root_contig.h5"), &p).unwrap();
    let t = read_table(&p, &ReadOptions::default()).unwrap();
    assert_eq!(t.n_rows(), 250);
}

/// Dataspaces patched to claim 2⁴⁰ values (8 TiB of f64) in a 60 KB file:
/// refused before anything is allocated (the reader caps allocations by
/// the file's size), never an out-of-memory abort.
#[test]
fn a_header_claiming_a_trillion_values_is_refused_without_allocating() {
    let dir = tempfile::tempdir().unwrap();
    let n = 250u64.to_le_bytes();
    let huge = (1u64 << 40).to_le_bytes();
    for file in ["root_contig.h5", "group_gzip.h5", "root_gzip_latest.h5"] {
        let mut b = std::fs::read(data(file)).unwrap();
        let mut patched = 0;
        // Dataspace messages v1 and v2, with and without max dims.
        let patterns: [(Vec<u8>, usize); 4] = [
            ([&[1u8, 1, 1, 0, 0, 0, 0, 0][..], &n, &n].concat(), 2),
            ([&[1u8, 1, 0, 0, 0, 0, 0, 0][..], &n].concat(), 1),
            ([&[2u8, 1, 1, 1][..], &n, &n].concat(), 2),
            ([&[2u8, 1, 0, 1][..], &n].concat(), 1),
        ];
        for (pat, dims) in &patterns {
            let head = pat.len() - 8 * dims;
            let mut i = 0;
            while let Some(k) = b[i..].windows(pat.len()).position(|w| w == &pat[..]) {
                let at = i + k + head;
                for d in 0..*dims {
                    b[at + 8 * d..at + 8 * d + 8].copy_from_slice(&huge);
                }
                patched += 1;
                i = i + k + 1;
            }
        }
        assert!(patched >= 5, "{file}: {patched} dataspaces patched");
        let p = dir.path().join(format!("huge_{file}"));
        std::fs::write(&p, &b).unwrap();
        let e = read_table(&p, &ReadOptions::default()).unwrap_err();
        assert!(e.to_string().contains("huge_"), "{file}: {e}");
        assert!(e.is_bad_input(), "{e}");
    }
}

/// A `units` attribute that contradicts the layout (a latitude in degrees
/// under the radian field `ins_lat`) is refused, naming file and dataset.
#[test]
fn a_units_attribute_that_contradicts_the_layout_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = std::fs::read(data("root_contig.h5")).unwrap();
    // The variable-length or fixed "rad" of /ins_lat's attribute becomes "deg".
    let at = b
        .windows(3)
        .position(|w| w == b"rad")
        .expect("a 'rad' attribute");
    b[at..at + 3].copy_from_slice(b"deg");
    let p = dir.path().join("deg_as_rad.h5");
    std::fs::write(&p, &b).unwrap();
    let e = read_table(&p, &ReadOptions::default()).unwrap_err();
    let s = e.to_string();
    assert!(
        s.contains("deg_as_rad.h5")
            && s.contains("ins_lat")
            && s.contains("'deg'")
            && s.contains("rad"),
        "{s}"
    );
    assert!(e.is_bad_input());
}

/// Found by the fuzzer (`fuzz/fuzz_targets/hdf5.rs`): a file whose fields
/// claim a huge length, read for fields it does not have, once gave a
/// table of that many rows without data, and a row selection then tried to
/// allocate them. Rows now come from data actually read.
#[test]
fn fuzz_crash_rows_claimed_but_not_read() {
    let p = data("fuzz-crash-rows-claimed.h5");
    let len = std::fs::metadata(&p).unwrap().len() as usize;
    for fields in [Fields::All, Fields::Only(vec!["time".into(), "mag".into()])] {
        let opts = ReadOptions {
            fields,
            rows: RowSelection::parse(Some("1001"), None).unwrap(),
            ..ReadOptions::default()
        };
        match read_table(&p, &opts) {
            Ok(t) => assert!(t.n_rows() <= 8 * len, "{} rows", t.n_rows()),
            Err(e) => assert!(e.to_string().contains("fuzz-crash-rows-claimed.h5"), "{e}"),
        }
    }
}

/// Fields each under the single-read cap but together far beyond memory
/// (4·10⁸ rows claimed by a small file's headers) are refused before any
/// is read: 7 such fields of unwritten chunks aborted `inspect` out of
/// memory (exit 134, 3 GB resident); this file's were read to 3.9 GB
/// resident before the reader gave up on one.
#[test]
fn fields_together_beyond_the_read_cap_are_refused_before_reading() {
    let dir = tempfile::tempdir().unwrap();
    let n = 250u64.to_le_bytes();
    let rows = 400_000_000u64.to_le_bytes();
    let mut b = std::fs::read(data("root_chunked.h5")).unwrap();
    let mut patched = 0;
    for (pat, dims) in [
        ([&[1u8, 1, 1, 0, 0, 0, 0, 0][..], &n, &n].concat(), 2),
        ([&[1u8, 1, 0, 0, 0, 0, 0, 0][..], &n].concat(), 1),
        ([&[2u8, 1, 1, 1][..], &n, &n].concat(), 2),
        ([&[2u8, 1, 0, 1][..], &n].concat(), 1),
    ] {
        let head = pat.len() - 8 * dims;
        let mut i = 0;
        while let Some(k) = b[i..].windows(pat.len()).position(|w| w == &pat[..]) {
            let at = i + k + head;
            for d in 0..dims {
                b[at + 8 * d..at + 8 * d + 8].copy_from_slice(&rows);
            }
            patched += 1;
            i = i + k + 1;
        }
    }
    assert!(patched >= 5, "{patched} dataspaces patched");
    let p = dir.path().join("many_rows.h5");
    std::fs::write(&p, &b).unwrap();
    let e = read_table(&p, &ReadOptions::default()).unwrap_err();
    let m = e.to_string();
    assert!(
        m.contains("many_rows.h5") && m.contains("fields of 400000000 values"),
        "{m}"
    );
    assert!(e.is_bad_input(), "{e}");
}
