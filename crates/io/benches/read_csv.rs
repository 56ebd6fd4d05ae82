//! Criterion benchmark: read and write a 10^6-row, 20-column flight CSV
//! (~350 MB, see `support/synthetic.rs`), generated once in a temporary directory.
//! Run: `cargo bench -p aeromag-io --bench read_csv`.

#[path = "support/synthetic.rs"]
mod synthetic;

use std::hint::black_box;

use aeromag_io::{ReadOptions, read_csv, write_csv};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};

const ROWS: usize = 1_000_000;

fn bench(c: &mut Criterion) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("flight.csv");
    synthetic::write_synthetic_csv(&path, ROWS).unwrap();
    let bytes = std::fs::metadata(&path).unwrap().len();
    eprintln!(
        "benchmark file: {ROWS} rows x {} columns, {:.1} MB",
        synthetic::NAMES.len(),
        bytes as f64 / 1e6
    );

    let mut g = c.benchmark_group("csv_1e6x20");
    g.sample_size(10);
    g.throughput(Throughput::Bytes(bytes));
    g.bench_function("read_csv", |b| {
        b.iter(|| black_box(read_csv(black_box(&path), &ReadOptions::default()).unwrap()))
    });
    let table = read_csv(&path, &ReadOptions::default()).unwrap();
    let out = dir.path().join("out.csv");
    g.bench_function("write_csv", |b| {
        b.iter(|| write_csv(black_box(&table), &out).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
