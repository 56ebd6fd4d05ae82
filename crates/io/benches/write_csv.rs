//! Criterion benchmark: the CSV writer on the table `compensate` writes
//! for the 10⁶-row peer flight (`tools/bench/peers.sh`): time at 10 Hz (one
//! decimal), four field columns of three decimals, a line number, two
//! computed columns of full precision and a flag; and `NumberText` alone
//! on a column of three decimals and one of full precision.
//! Run: `cargo bench -p aeromag-io --bench write_csv`.

use std::hint::black_box;

use aeromag_io::{FlightTable, NumberText, write_csv_to};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};

const ROWS: usize = 1_000_000;

/// Row `i`'s field value of column `k`: near 50 000 nT, three decimals.
fn field(i: usize, k: usize) -> f64 {
    let x = i as f64 * 0.1;
    let h = ((i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ (k as u64 * 0x632B_E59B)) >> 40;
    let v =
        13_000.0 * (k as f64 + 1.0) + 300.0 * (x * 0.01 * (k as f64 + 1.0)).sin() + h as f64 / 1e7;
    (v * 1000.0).round() / 1000.0
}

fn table() -> FlightTable {
    let mut t = FlightTable::new();
    t.add_column("time", (0..ROWS).map(|i| i as f64 / 10.0).collect())
        .unwrap();
    for (k, name) in ["flux_x", "flux_y", "flux_z", "mag"].iter().enumerate() {
        t.add_column(name, (0..ROWS).map(|i| field(i, k)).collect())
            .unwrap();
    }
    t.add_integer_column("line", (0..ROWS).map(|i| (1 + i / 60_000) as f64).collect())
        .unwrap();
    let interf: Vec<f64> = (0..ROWS)
        .map(|i| field(i, 5) / 4.7 + 1e-9 * i as f64)
        .collect();
    let comp: Vec<f64> = (0..ROWS).map(|i| field(i, 3) - interf[i]).collect();
    t.add_column("mag_interf", interf).unwrap();
    t.add_column("mag_comp", comp).unwrap();
    t.add_integer_column("comp_flag", vec![0.0; ROWS]).unwrap();
    t
}

fn bench(c: &mut Criterion) {
    let t = table();
    let mut g = c.benchmark_group("write_1e6x9");
    g.sample_size(10);
    g.throughput(Throughput::Elements(ROWS as u64));
    g.bench_function("write_csv_to_sink", |b| {
        b.iter(|| write_csv_to(black_box(&t), std::io::sink()).unwrap())
    });
    g.finish();

    let mut g = c.benchmark_group("number_text_1e6");
    g.throughput(Throughput::Elements(ROWS as u64));
    for name in ["mag", "mag_comp"] {
        let values = t.column(name).unwrap().to_vec();
        g.bench_function(name, |b| {
            b.iter(|| {
                let mut text = NumberText::new();
                let mut bytes = 0;
                for &v in &values {
                    bytes += text.format(black_box(v)).len();
                }
                bytes
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
