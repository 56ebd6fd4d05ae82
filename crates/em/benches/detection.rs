//! Criterion benchmark of the detection chain (spec `em-positioning.md`:
//! "the detector chain runs at ≥ 1000× real time for three channels at
//! 100 kHz sampling on one core").
//!
//! One second of three-channel interleaved f32 data at 100 kHz, detected at
//! three working frequencies and their six pilots (9 detectors × 3
//! channels), 16 000-sample Blackman–Harris windows. Real-time factor =
//! 1 s / measured time.

use aeromag_em::detection::{DetectorConfig, SyncDetector};
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;

fn detection(c: &mut Criterion) {
    let fs = 100_000.0;
    let det = SyncDetector::new(DetectorConfig::three_frequency_plan(
        fs,
        16_000,
        [1025.0, 2075.0, 3125.0],
        25.0,
    ))
    .expect("valid plan");
    // 0.96 s = 6 whole blocks of 16 000 samples per channel.
    let n = 96_000usize;
    let data: Vec<f32> = (0..n * 3)
        .map(|i| {
            let t = (i / 3) as f64 / fs;
            ((std::f64::consts::TAU * 1025.0 * t).sin() + 0.1 * (i % 3) as f64) as f32
        })
        .collect();
    c.bench_function("detect 0.96 s, 3 ch @ 100 kHz, 9 frequencies", |b| {
        b.iter(|| {
            det.detect_interleaved(black_box(&data), 3, 0)
                .expect("detect")
        })
    });
}

criterion_group!(benches, detection);
criterion_main!(benches);
