//! One likelihood evaluation of the noise tuning (`kalman::tuning`): the
//! field filter of the default order (8 states) over a decimated
//! calibration of 20 000 samples in short runs, the 34 coefficients of
//! `p3,i5,e8,l9` with two lags integrated out — what `calibrate --method
//! kalman` repeats 100–150 times whatever the flight's length.
//!
//! Run: `cargo bench -p aeromag-compensation --bench tuning`. The subset is
//! synthetic (deterministic pseudo-random rows, runs of 18 samples, steps
//! of 400–500 m as a 50× decimation of a 10 Hz flight gives); the time
//! depends on the sizes, not on the values.

use aeromag_compensation::kalman::tuning::Subset;
use aeromag_compensation::kalman::{DEFAULT_ORDER, NoiseModel, X2Prior};
use criterion::{Criterion, criterion_group, criterion_main};

/// `n` samples of `m` coefficients in runs of `run` samples.
fn subset(n: usize, m: usize, run: usize) -> Subset {
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let mut s = Subset {
        m,
        ..Subset::default()
    };
    for k in 0..n {
        for j in 0..m {
            s.rows.push(100.0 * next() / (1 + j % 5) as f64);
        }
        s.y.push(20.0 * next());
        s.dz.push(5.0 * next());
        s.d.push(450.0 + 100.0 * next());
        s.start.push(k % run == 0);
    }
    s
}

fn bench(c: &mut Criterion) {
    let (n, m) = (20_000, 34);
    let s = subset(n, m, 18);
    let prior = X2Prior::default();
    let noise = NoiseModel::calibration_default_for(DEFAULT_ORDER);
    let (mean, std) = (vec![0.0; m], vec![1e3; m]);
    let mut g = c.benchmark_group("tuning likelihood");
    g.sample_size(20);
    for threads in [1, 2] {
        g.bench_function(format!("n={n} m={m} threads={threads}"), |b| {
            b.iter(|| {
                s.log_likelihood(&mean, &std, &prior, noise, threads)
                    .unwrap()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
