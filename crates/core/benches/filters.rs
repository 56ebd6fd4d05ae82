//! Filter and spectrum throughput: the compensation band-pass (order 4,
//! 0.1–0.9 Hz at 10 Hz, zero-phase) over 10⁶ samples, and a Welch PSD of
//! the same series.
//!
//! Run: `cargo bench -p aeromag-core --bench filters`.

use aeromag_core::filter::{BandPass, sosfiltfilt_columns_in_place, sosfiltfilt_in_place};
use aeromag_core::spectrum::{WelchConfig, welch};
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;

/// Deterministic test signal (no RNG needed): two tones, a drift and a
/// pseudo-random sawtooth from a multiplicative congruence.
fn signal(n: usize, fs: f64) -> Vec<f64> {
    (0..n)
        .map(|k| {
            let t = k as f64 / fs;
            let saw = ((k as u64 * 2_654_435_761) % 1000) as f64 / 500.0 - 1.0;
            50_000.0 + 0.01 * t + (0.3 * t).sin() + 0.2 * (2.0 * t).sin() + 0.1 * saw
        })
        .collect()
}

fn bench_filters(c: &mut Criterion) {
    let fs = 10.0;
    let n = 1_000_000;
    let x = signal(n, fs);
    let bp = BandPass::compensation_default(fs).expect("valid design");

    let mut g = c.benchmark_group("bandpass_1e6");
    g.sample_size(20);
    g.bench_function("sosfiltfilt_copy", |b| {
        b.iter(|| bp.filter(black_box(&x)).expect("filter"))
    });
    let mut work = x.clone();
    g.bench_function("sosfiltfilt_in_place", |b| {
        b.iter(|| {
            work.copy_from_slice(&x);
            bp.filter_in_place(black_box(&mut work)).expect("filter")
        })
    });
    g.finish();

    // The band-pass of a Tolles-Lawson fit: 20 columns (18 terms, y and a
    // spare) of 10⁵ samples, one at a time against FILTER_LANES at a time.
    let cols: Vec<Vec<f64>> = (0..20)
        .map(|j| signal(100_000, fs + j as f64 * 1e-3))
        .collect();
    let sos = bp.sos();
    let mut work = cols.clone();
    let mut g = c.benchmark_group("bandpass_20_columns_1e5");
    g.sample_size(20);
    g.bench_function("one_at_a_time", |b| {
        b.iter(|| {
            for (w, x) in work.iter_mut().zip(&cols) {
                w.copy_from_slice(x);
                sosfiltfilt_in_place(sos, black_box(w)).expect("filter");
            }
        })
    });
    g.bench_function("in_lanes", |b| {
        b.iter(|| {
            for (w, x) in work.iter_mut().zip(&cols) {
                w.copy_from_slice(x);
            }
            let mut refs: Vec<&mut [f64]> = work.iter_mut().map(|w| w.as_mut_slice()).collect();
            sosfiltfilt_columns_in_place(sos, black_box(&mut refs)).expect("filter")
        })
    });
    g.finish();

    let cfg = WelchConfig::new(fs, 1024);
    let mut g = c.benchmark_group("welch_1e6");
    g.sample_size(20);
    g.bench_function("hann_1024", |b| {
        b.iter(|| welch(black_box(&x), &cfg).expect("welch"))
    });
    g.finish();
}

criterion_group!(benches, bench_filters);
criterion_main!(benches);
