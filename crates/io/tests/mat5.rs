//! MATLAB MAT-files (`tools/reference/mat5_flights.py`, files in
//! `tests/data/mat5`, v5 written by `scipy.io.savemat` and by hand, v7.3
//! by `hdf5storage`): the flight's fields read bit-exactly from the top
//! level, one struct, or MagNav.jl's `traj` and `ins_data`; a v7.3 file the
//! same table as the v5 file of its workspace; what is not a field listed;
//! files that hold no flight refused; damaged and hostile files an error
//! naming the file, never a panic.

use std::io::Write;
use std::path::{Path, PathBuf};

use aeromag_io::{Fields, IoError, NotRead, ReadOptions, read_table};
use proptest::prelude::*;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/mat5")
        .join(name)
}

fn read(name: &str) -> aeromag_io::Result<aeromag_io::FlightTable> {
    read_table(&data(name), &ReadOptions::default())
}

fn not_read(t: &aeromag_io::FlightTable) -> Vec<(String, String)> {
    t.not_read()
        .iter()
        .map(|NotRead { name, what }| (name.clone(), what.clone()))
        .collect()
}

fn pairs(p: &[(&str, &str)]) -> Vec<(String, String)> {
    p.iter()
        .map(|(a, b)| (a.to_string(), b.to_string()))
        .collect()
}

/// The values the generator writes, computed the same way.
fn k(n: usize) -> impl Iterator<Item = f64> {
    (0..n).map(|k| k as f64)
}

#[test]
fn a_workspace_of_vectors_reads_its_vectors_and_lists_the_rest() {
    let t = read("top.mat").unwrap();
    assert_eq!(t.n_rows(), 50);
    assert_eq!(t.column_names(), ["tt", "mag_1_uc", "lat", "flag", "ok"]);
    assert_eq!(
        t.column("tt").unwrap(),
        k(50).map(|k| 0.1 * k).collect::<Vec<_>>()
    );
    // n × 1 as 1 × n.
    assert_eq!(
        t.column("mag_1_uc").unwrap(),
        k(50).map(|k| 50_000.0 + 0.125 * k).collect::<Vec<_>>()
    );
    assert_eq!(
        t.column("lat").unwrap(),
        k(50).map(|k| 45.0 + k * 1e-4).collect::<Vec<_>>()
    );
    assert_eq!(
        t.column("flag").unwrap(),
        k(50).map(|k| k % 3.0).collect::<Vec<_>>()
    );
    assert_eq!(
        t.column("ok").unwrap(),
        k(50)
            .map(|k| if k % 2.0 == 0.0 { 1.0 } else { 0.0 })
            .collect::<Vec<_>>()
    );
    // Integer and logical classes are written back as integers, doubles not.
    assert!(t.get("flag").unwrap().integer_text() && t.get("ok").unwrap().integer_text());
    assert!(!t.get("tt").unwrap().integer_text());
    // The canonical names map as for any file.
    assert_eq!(t.resolve("time"), Some("tt"));
    assert_eq!(t.resolve("mag"), Some("mag_1_uc"));
    assert_eq!(
        not_read(&t),
        pairs(&[
            ("extra", "a struct"),
            ("fs", "a scalar, 10"),
            ("note", "text (1 × 11)"),
            ("A", "a 50 × 3 matrix"),
        ])
    );
}

#[test]
fn magnav_traj_and_ins_data_structs_read_as_its_hdf5_names() {
    // Compressed variables; `ins_data`'s fields take back their `ins_`.
    let t = read("magnav.mat").unwrap();
    assert_eq!(
        t.column_names(),
        [
            "ins_tt", "ins_lat", "ins_lon", "ins_roll", "tt", "lat", "lon", "mag_1_uc", "flux_a_x"
        ]
    );
    assert_eq!(
        t.column("ins_lon").unwrap(),
        k(50).map(|k| -75.0 - k * 1e-4).collect::<Vec<_>>()
    );
    assert_eq!(
        t.column("flux_a_x").unwrap(),
        k(50).map(|k| 30_000.0 - 0.25 * k).collect::<Vec<_>>()
    );
    assert_eq!(t.column("ins_roll").unwrap(), vec![0.5; 50]);
    assert_eq!(
        not_read(&t),
        pairs(&[
            ("traj.Cnb", "a 3 × 3 × 50 matrix"),
            ("traj.fileName", "text (1 × 7)")
        ])
    );
}

/// The v7.3 file (HDF5) of a workspace gives the v5 file's table: the same
/// columns with the same bits and integer flags, and the same variables not
/// read (HDF5 keeps them in name order).
#[test]
fn a_v73_file_reads_as_the_v5_file_of_its_workspace() {
    for (v5, v73, left_out) in [
        ("top.mat", "top73.mat", &["ok", "extra"][..]),
        ("magnav.mat", "magnav73.mat", &[][..]),
    ] {
        let (a, b) = (read(v5).unwrap(), read(v73).unwrap());
        assert_eq!(a.n_rows(), b.n_rows());
        let sorted = |mut v: Vec<String>| {
            v.sort();
            v
        };
        let names = |t: &aeromag_io::FlightTable| {
            sorted(t.column_names().into_iter().map(String::from).collect())
        };
        let expected: Vec<String> = names(&a)
            .into_iter()
            .filter(|n| !left_out.contains(&n.as_str()))
            .collect();
        assert_eq!(names(&b), expected, "{v73}");
        for name in &expected {
            let bits = |t: &aeromag_io::FlightTable| -> Vec<u64> {
                t.column(name)
                    .unwrap()
                    .iter()
                    .map(|v| v.to_bits())
                    .collect()
            };
            assert_eq!(bits(&a), bits(&b), "{v73}: {name}");
            let integer = |t: &aeromag_io::FlightTable| t.get(name).unwrap().integer_text();
            assert_eq!(integer(&a), integer(&b), "{v73}: {name}");
        }
        let not_read = |t: &aeromag_io::FlightTable| {
            let mut v: Vec<(String, String)> = not_read(t)
                .into_iter()
                .filter(|(n, _)| !left_out.contains(&n.as_str()))
                .collect();
            v.sort();
            v
        };
        assert_eq!(not_read(&a), not_read(&b), "{v73}");
    }
    // Only the fields asked for are read.
    let opts = ReadOptions {
        fields: Fields::Only(vec!["mag".into(), "ins_roll".into()]),
        ..ReadOptions::default()
    };
    let t = read_table(&data("magnav73.mat"), &opts).unwrap();
    assert_eq!(t.column_names(), ["ins_roll", "mag_1_uc"]);
    assert_eq!(t.unread_columns().len(), 7);
}

#[test]
fn one_struct_gives_the_vectors_of_the_longest_length() {
    // The shape of MagNav's test_data_TL.mat.
    let t = read("one_struct.mat").unwrap();
    assert_eq!(t.n_rows(), 1000);
    assert_eq!(t.column_names(), ["mag_1_uc", "flux_a_x"]);
    assert_eq!(
        not_read(&t),
        pairs(&[
            ("TL_data.fs", "a scalar, 10"),
            ("TL_data.mag_1_uc_f_t", "a vector of 960 values"),
            ("TL_data.TL_a_1", "a vector of 18 values"),
        ])
    );
}

#[test]
fn big_endian_files_and_doubles_stored_as_small_integers_read_exactly() {
    let t = read("big_endian.mat").unwrap();
    assert_eq!(t.column("tt").unwrap(), [0.0, 0.5, 1.0, 1.5, 2.0, 2.5]);
    assert_eq!(
        t.column("mag").unwrap(),
        k(6).map(|k| 50_000.0 + k).collect::<Vec<_>>()
    );
    // A double stored as uint16 is still a double.
    assert!(!t.get("mag").unwrap().integer_text());
    let t = read("small_ints.mat").unwrap();
    assert_eq!(t.column("line").unwrap(), [7.0, 7.0, 8.0]);
    assert_eq!(t.column("mag").unwrap(), [50_000.5, 50_001.5, 50_002.5]);
}

#[test]
fn only_the_fields_asked_for_are_kept() {
    let opts = ReadOptions {
        fields: Fields::Only(vec!["mag".into()]),
        ..ReadOptions::default()
    };
    let t = read_table(&data("magnav.mat"), &opts).unwrap();
    assert_eq!(t.column_names(), ["mag_1_uc"]);
    assert_eq!(t.unread_columns().len(), 8);
}

fn mat_error(name: &str) -> String {
    let e = read(name).unwrap_err();
    assert!(matches!(e, IoError::Mat { .. }), "{e:?}");
    assert!(e.is_bad_input());
    let text = e.to_string();
    assert!(text.contains(name), "{text}");
    text
}

#[test]
fn files_without_a_flight_are_refused_with_what_to_do() {
    let e = mat_error("two_structs.mat");
    assert!(
        e.contains("2 structs (a, b)") && e.contains("-struct"),
        "{e}"
    );
    let e = mat_error("map.mat");
    assert!(e.contains("MagNav.jl map"), "{e}");
}

fn write_temp(dir: &tempfile::TempDir, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.path().join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

/// A read that fails must be an error naming the file, never a panic.
fn error_or_table(path: &Path) {
    if let Err(e) = read_table(path, &ReadOptions::default()) {
        assert!(e.to_string().contains(&path.display().to_string()), "{e}");
    }
}

#[test]
fn every_cut_short_file_is_an_error_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["top.mat", "magnav.mat", "big_endian.mat", "small_ints.mat"] {
        let bytes = std::fs::read(data(name)).unwrap();
        for len in 0..bytes.len() {
            let p = write_temp(&dir, "cut.mat", &bytes[..len]);
            match read_table(&p, &ReadOptions::default()) {
                Err(e) => assert!(e.to_string().contains("cut.mat"), "{name} at {len}: {e}"),
                // Cut after a whole variable: the variables before it.
                Ok(t) => assert!(t.n_rows() > 1, "{name} at {len}"),
            }
        }
    }
}

/// Tag of a little-endian element and its data, padded to 8 bytes.
fn element(kind: u32, data: &[u8]) -> Vec<u8> {
    let mut e = kind.to_le_bytes().to_vec();
    e.extend((data.len() as u32).to_le_bytes());
    e.extend(data);
    e.resize(e.len().next_multiple_of(8), 0);
    e
}

/// A 1 × 1 struct named `name` with the one field `f` holding `inner`.
fn struct_of(name: &str, inner: &[u8]) -> Vec<u8> {
    let mut body = element(6, &[2, 0, 0, 0, 0, 0, 0, 0]);
    body.extend(element(5, &[1, 0, 0, 0, 1, 0, 0, 0]));
    body.extend(element(1, name.as_bytes()));
    body.extend(element(5, &[2, 0, 0, 0]));
    body.extend(element(1, b"f\0"));
    body.extend(inner);
    element(14, &body)
}

fn header() -> Vec<u8> {
    let mut h = b"MATLAB 5.0 MAT-file, test".to_vec();
    h.resize(124, b' ');
    h.extend([0, 1, b'I', b'M']);
    h
}

#[test]
fn hostile_files_are_errors_not_crashes() {
    let dir = tempfile::tempdir().unwrap();
    // Structs nested 100 deep: refused at the depth limit, no stack overflow.
    let mut nested = element(14, &[]);
    for _ in 0..100 {
        nested = struct_of("", &nested);
    }
    let mut bytes = header();
    bytes.extend(struct_of("s", &nested));
    let p = write_temp(&dir, "deep.mat", &bytes);
    let e = read_table(&p, &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("nest deeper than"), "{e}");

    // A compressed variable declaring 4 GB in 30 bytes of zlib.
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    z.write_all(&14u32.to_le_bytes()).unwrap();
    z.write_all(&0xffff_fff0u32.to_le_bytes()).unwrap();
    z.write_all(&[0u8; 64]).unwrap();
    let compressed = z.finish().unwrap();
    let mut bytes = header();
    bytes.extend(15u32.to_le_bytes());
    bytes.extend((compressed.len() as u32).to_le_bytes());
    bytes.extend(&compressed);
    let p = write_temp(&dir, "bomb.mat", &bytes);
    let e = read_table(&p, &ReadOptions::default())
        .unwrap_err()
        .to_string();
    // Refused when the data run out, or before, on a machine with less
    // memory than the size declared.
    assert!(
        e.contains("bomb.mat")
            && (e.contains("ends after 72 of the") || e.contains("this process can take")),
        "{e}"
    );

    // Dimensions that claim 2^62 values.
    let mut body = element(6, &[6, 0, 0, 0, 0, 0, 0, 0]);
    let mut dims = Vec::new();
    for d in [0x7fff_ffffu32, 0x7fff_ffff, 2] {
        dims.extend(d.to_le_bytes());
    }
    body.extend(element(5, &dims));
    body.extend(element(1, b"x"));
    body.extend(element(9, &[0; 16]));
    let mut bytes = header();
    bytes.extend(element(14, &body));
    let p = write_temp(&dir, "dims.mat", &bytes);
    let e = read_table(&p, &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("variable 'x'") && e.contains("holds 2 values"),
        "{e}"
    );
}

/// A double row vector `name` of `values`.
fn vector(name: &str, values: &[f64]) -> Vec<u8> {
    let mut body = element(6, &[6, 0, 0, 0, 0, 0, 0, 0]);
    let mut dims = 1u32.to_le_bytes().to_vec();
    dims.extend((values.len() as u32).to_le_bytes());
    body.extend(element(5, &dims));
    body.extend(element(1, name.as_bytes()));
    let data: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    body.extend(element(9, &data));
    element(14, &body)
}

/// A MATLAB object (`mxOPAQUE`): flags, its name, `MCOS`, its class name,
/// then data (not read).
fn object(name: &str, class: &str) -> Vec<u8> {
    let mut body = element(6, &[17, 0, 0, 0, 0, 0, 0, 0]);
    body.extend(element(1, name.as_bytes()));
    body.extend(element(1, b"MCOS"));
    body.extend(element(1, class.as_bytes()));
    body.extend(element(14, &[]));
    element(14, &body)
}

#[test]
fn matlab_objects_are_listed_and_a_table_alone_says_what_to_save() {
    let dir = tempfile::tempdir().unwrap();
    let mut bytes = header();
    bytes.extend(vector("tt", &[0.0, 0.1, 0.2]));
    bytes.extend(object("when", "datetime"));
    bytes.extend(vector("mag", &[5e4, 5e4, 5e4]));
    let p = write_temp(&dir, "objects.mat", &bytes);
    let t = read_table(&p, &ReadOptions::default()).unwrap();
    assert_eq!(t.column_names(), ["tt", "mag"]);
    assert_eq!(
        not_read(&t),
        pairs(&[("when", "a MATLAB datetime object (1 × 1)")])
    );
    let mut bytes = header();
    bytes.extend(object("T", "table"));
    let p = write_temp(&dir, "table.mat", &bytes);
    let e = read_table(&p, &ReadOptions::default()).unwrap_err();
    assert!(e.is_bad_input());
    let e = e.to_string();
    assert!(
        e.contains("variable 'T': is a MATLAB table")
            && e.contains("table2struct(T, 'ToScalar', true)")
            && e.contains("writetable(T, 'flight.csv')"),
        "{e}"
    );
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    /// Bytes changed anywhere in a file: a table or an error naming it.
    #[test]
    fn damaged_files_give_a_table_or_an_error(
        which in 0usize..5,
        changes in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8),
    ) {
        let name = ["top.mat", "magnav.mat", "one_struct.mat", "top73.mat", "magnav73.mat"][which];
        let mut bytes = std::fs::read(data(name)).unwrap();
        for (at, b) in changes {
            let i = at.index(bytes.len());
            bytes[i] = b;
        }
        let dir = tempfile::tempdir().unwrap();
        error_or_table(&write_temp(&dir, "damaged.mat", &bytes));
    }
}
