//! Peak-memory check of the CSV reader (run by hand, see the crate report).
//!
//! ```text
//! cargo run --release -p aeromag-io --example peak_mem -- gen  /tmp/big.csv 10000000
//! /usr/bin/time -v target/release/examples/peak_mem read /tmp/big.csv
//! ```
//!
//! `gen` streams a ROWS × 20 CSV (time at 10 Hz, positions, attitude, field
//! values, a few missing cells) without building a table; `read` reads it
//! with `read_table` and prints the f64 data size to compare with the
//! "Maximum resident set size" reported by `/usr/bin/time -v`.

#[path = "../benches/support/synthetic.rs"]
mod synthetic;

use std::path::Path;

use aeromag_io::{ReadOptions, read_table};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    match args.get(1).map(String::as_str) {
        Some("gen") if args.len() == 4 => {
            let rows: usize = args[3].parse().expect("ROWS must be an integer");
            synthetic::write_synthetic_csv(Path::new(&args[2]), rows).expect("write failed");
        }
        Some("read") if args.len() == 3 => {
            let path = Path::new(&args[2]);
            let start = std::time::Instant::now();
            match read_table(path, &ReadOptions::default()) {
                Ok(t) => {
                    let secs = start.elapsed().as_secs_f64();
                    let data = t.n_rows() * t.columns().len() * 8;
                    let sum: f64 = t
                        .columns()
                        .iter()
                        .filter_map(|c| c.values())
                        .map(|v| v[v.len() / 2])
                        .sum();
                    println!(
                        "rows {} columns {} file {:.1} MB f64 data {:.1} MB read {:.2} s checksum {sum}",
                        t.n_rows(),
                        t.columns().len(),
                        std::fs::metadata(path).map(|m| m.len()).unwrap_or(0) as f64 / 1e6,
                        data as f64 / 1e6,
                        secs
                    );
                }
                Err(e) => {
                    eprintln!("error: {e}");
                    std::process::exit(2);
                }
            }
        }
        _ => {
            eprintln!("usage: peak_mem gen PATH ROWS | peak_mem read PATH");
            std::process::exit(2);
        }
    }
}
