//! Geosoft grids written by Oasis montaj 9.6 (harmonica's test grids, in
//! `tests/data/geosoft/` with their licence) against the values harmonica
//! 0.7.0's `load_oasis_montaj_grid` reads from them.
//!
//! The reference numbers were made (2026-12-01) by
//! `v = harmonica.load_oasis_montaj_grid(f).values` then
//! `np.nansum(v)`, `np.nanmin(v)`, `np.nanmax(v)`, `v[24, 30]`, `v[48, 0]`
//! and `np.isnan(v).sum()` (rows from the south, as aeromag's), on each
//! file; harmonica's own test compares the grids to one expected grid
//! within 10⁻⁸ (0.15 for bytes, 10⁻³ for 16-bit integers).

use std::path::{Path, PathBuf};

use aeromag_grid::Grid;
use aeromag_grid::format::read_grid;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/geosoft")
        .join(name)
}

/// harmonica's figures: sum, min, max, node (24, 30), node (48, 0).
const REFERENCE: [(&str, [f64; 5]); 7] = [
    (
        "om_byte.grd",
        [
            17558.232972421072,
            -0.9217717174144511,
            45.188167465076035,
            4.156415417221066,
            -0.3123892612581898,
        ],
    ),
    (
        "om_short.grd",
        [
            17560.359325059966,
            -0.9925918658295387,
            45.25898761349113,
            4.07571987521133,
            -0.4122807582370527,
        ],
    ),
    (
        "om_long.grd",
        [
            17560.367381130858,
            -0.9928663331114365,
            45.25926208077303,
            4.076022626542681,
            -0.4123728847043644,
        ],
    ),
    (
        "om_float.grd",
        [
            17560.367381218006,
            -0.9928663372993469,
            45.25926208496094,
            4.076022624969482,
            -0.412372887134552,
        ],
    ),
    (
        "om_double.grd",
        [
            17560.367381218006,
            -0.9928663372993469,
            45.25926208496094,
            4.076022624969482,
            -0.412372887134552,
        ],
    ),
    (
        "om_order.grd",
        [
            17560.36738113086,
            -0.9928663331114359,
            45.25926208077303,
            4.0760226265426835,
            -0.4123728847043619,
        ],
    ),
    (
        "om_compress.grd",
        [
            17560.367381218006,
            -0.9928663372993469,
            45.25926208496094,
            4.076022624969482,
            -0.412372887134552,
        ],
    ),
];

fn figures(g: &Grid) -> [f64; 5] {
    let finite = || g.values.iter().filter(|v| !v.is_nan());
    let node = |row: usize, column: usize| g.values[row * g.geometry.nx + column];
    [
        finite().sum(),
        finite().copied().fold(f64::INFINITY, f64::min),
        finite().copied().fold(f64::NEG_INFINITY, f64::max),
        node(24, 30),
        node(48, 0),
    ]
}

/// Every element type, column storage and compression: harmonica's
/// values (to 10⁻¹² relative: the sums add in another order), its
/// geometry (50 × 49 nodes from (1, −24), cell 1) and its 655 blank nodes,
/// the south-western one among them.
#[test]
fn oasis_montaj_grids_read_as_harmonica_reads_them() {
    for (file, expected) in REFERENCE {
        let g = read_grid(&data(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
        let geo = g.geometry;
        assert_eq!(
            (geo.nx, geo.ny, geo.x0, geo.y0, geo.cell),
            (50, 49, 1.0, -24.0, 1.0),
            "{file}"
        );
        assert_eq!(
            g.values.iter().filter(|v| v.is_nan()).count(),
            655,
            "{file}"
        );
        assert!(g.values[0].is_nan(), "{file}");
        for (k, (got, want)) in figures(&g).iter().zip(expected).enumerate() {
            assert!(
                (got - want).abs() <= 1e-12 * want.abs(),
                "{file} figure {k}: {got} against harmonica's {want}"
            );
        }
        assert_eq!((g.name.as_str(), g.crs), (&file[..file.len() - 4], None));
    }
}

/// The types Oasis montaj converted from the float grid hold its values
/// to their precision: bytes within 0.15 (ZMULT 4.92), 16-bit within
/// 10⁻³, 32-bit integers within 10⁻⁸, doubles exactly; the same blanks.
#[test]
fn every_element_type_holds_the_float_grid() {
    let float = read_grid(&data("om_float.grd")).unwrap();
    for (file, tolerance) in [
        ("om_byte.grd", 0.15),
        ("om_short.grd", 1e-3),
        ("om_long.grd", 1e-8),
        ("om_order.grd", 1e-8),
        ("om_double.grd", 0.0),
        ("om_compress.grd", 0.0),
    ] {
        let g = read_grid(&data(file)).unwrap();
        for (k, (a, b)) in float.values.iter().zip(&g.values).enumerate() {
            assert_eq!(a.is_nan(), b.is_nan(), "{file} node {k}");
            if !a.is_nan() {
                assert!((a - b).abs() <= tolerance, "{file} node {k}: {a} vs {b}");
            }
        }
    }
}

/// A rotated grid and a cut-short one are refused, naming the file (the
/// messages are the user's: the rotation, the bytes missing).
#[test]
fn rotated_and_cut_short_grids_are_refused() {
    for (file, needle) in [
        ("om_rotate.grd", "rotated by -30°"),
        ("incomplete_grid.grd", "but 9700 bytes follow it"),
    ] {
        let e = read_grid(&data(file)).unwrap_err();
        assert!(e.is_bad_input(), "{file}: {e}");
        let text = e.to_string();
        assert!(
            text.contains(file) && text.contains(needle),
            "{file}: {text}"
        );
    }
}

/// Every cut-short length of the compressed grid is an error naming the
/// file, never a panic nor a grid.
#[test]
fn every_cut_of_the_compressed_grid_is_an_error() {
    let bytes = std::fs::read(data("om_compress.grd")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cut.grd");
    for len in (0..bytes.len()).step_by(7).chain([bytes.len() - 1]) {
        std::fs::write(&path, &bytes[..len]).unwrap();
        let e = read_grid(&path).unwrap_err();
        assert!(e.to_string().contains("cut.grd"), "{len}: {e}");
    }
}

/// Oasis montaj's float grid read and written again (`name.grd(GRD)`):
/// the same bytes as Oasis montaj wrote, values and header alike, but for
/// the variance's last bits (ZVAR, bytes 176–183: a sum in another order),
/// which stays within 10⁻¹³ relative.
#[test]
fn a_grid_written_as_geosoft_has_oasis_montaj_bytes() {
    let original = std::fs::read(data("om_float.grd")).unwrap();
    let g = read_grid(&data("om_float.grd")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("again.grd");
    let decorated = dir.path().join("again.grd(GRD)");
    aeromag_grid::format::write_grid(&decorated, &g).unwrap();
    let written = std::fs::read(&out).unwrap();
    assert_eq!(written.len(), original.len());
    assert_eq!(written[..176], original[..176]);
    assert_eq!(written[184..], original[184..]);
    let variance = |b: &[u8]| f64::from_le_bytes(b[176..184].try_into().unwrap());
    let (a, b) = (variance(&written), variance(&original));
    assert!((a - b).abs() <= 1e-13 * b, "{a} {b}");
}
