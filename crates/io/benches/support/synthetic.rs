//! Synthetic flight CSV shared by the `read_csv` benchmark and the
//! `peak_mem` example (included with `#[path]`).
//!
//! ROWS × 20 columns: time at 10 Hz (s), positions (deg), smooth signals with
//! a hashed perturbation, field values near 53 000 nT, line numbers changing
//! every 60 000 rows, and a missing cell in `aux_2` every 997 rows. Values are
//! written with Ryū (shortest round-trip), as `write_csv` does.

use std::io::{BufWriter, Write};
use std::path::Path;

/// The 20 columns.
pub const NAMES: [&str; 20] = [
    "time",
    "lat",
    "lon",
    "alt",
    "vn",
    "ve",
    "vd",
    "roll",
    "pitch",
    "yaw",
    "mag",
    "flux_x",
    "flux_y",
    "flux_z",
    "line",
    "diurnal",
    "igrf",
    "true_anomaly",
    "aux_1",
    "aux_2",
];

/// Value of row `i`, column `k` (NaN = missing).
pub fn value(i: usize, k: usize) -> f64 {
    let x = i as f64 * 0.1;
    let h = ((i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ (k as u64 * 0x632B_E59B)) >> 40;
    let noise = h as f64 / (1u64 << 24) as f64 - 0.5;
    match NAMES[k] {
        "time" => x,
        "line" => (1000 + i / 60_000) as f64,
        "lat" => 45.0 + x * 1e-6,
        "lon" => -75.0 + (x * 1e-3).sin() * 0.01,
        "mag" | "igrf" => 53_000.0 + 50.0 * (x * 0.01).sin() + noise,
        "aux_2" if i % 997 == 13 => f64::NAN,
        _ => 100.0 * (x * 0.003 * (k as f64 + 1.0)).sin() + noise,
    }
}

/// Streams the synthetic CSV to `path` without building a table.
pub fn write_synthetic_csv(path: &Path, rows: usize) -> std::io::Result<()> {
    let mut out = BufWriter::with_capacity(1 << 20, std::fs::File::create(path)?);
    writeln!(out, "{}", NAMES.join(","))?;
    let mut buf = ryu::Buffer::new();
    for i in 0..rows {
        for k in 0..NAMES.len() {
            if k > 0 {
                out.write_all(b",")?;
            }
            let v = value(i, k);
            if !v.is_nan() {
                out.write_all(buf.format(v).as_bytes())?;
            }
        }
        out.write_all(b"\n")?;
    }
    out.flush()
}
