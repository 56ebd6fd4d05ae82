//! The field smoother of the Kalman method (`kalman::field_smoother`): the
//! 8-state filter of the default field order re-run from its checkpoints
//! and the modified Bryson–Frazier recursion back, over 10⁵ samples in
//! runs of 900 (the legs of a calibration flight at 10 Hz), one thread —
//! what pass 1 and the final fit of `calibrate --method kalman` do on
//! every sample.
//!
//! Run: `cargo bench -p aeromag-compensation --bench smoother`. The record
//! is synthetic (deterministic readings, altitude and speed); the time
//! depends on the sizes, not on the values.

use aeromag_compensation::kalman::anomaly_model::AnomalyTransition;
use aeromag_compensation::kalman::field_smoother::{FieldModel, smooth_field};
use aeromag_compensation::kalman::{DEFAULT_ORDER, NoiseModel, X2Prior};
use aeromag_estimation::kalman::{default_block_len, filter_checkpoints};
use criterion::{Criterion, criterion_group, criterion_main};

fn bench(c: &mut Criterion) {
    let (n, run) = (100_000, 900);
    // Deterministic values that do not repeat along a run.
    let wiggle = |k: usize, f: f64| (f * k as f64).sin() + 0.3 * (2.7 * f * k as f64).cos();
    let time: Vec<f64> = (0..n).map(|k| 0.1 * k as f64).collect();
    let speed: Vec<f64> = (0..n).map(|k| 90.0 + 5.0 * wiggle(k, 0.37)).collect();
    let alt: Vec<f64> = (0..n).map(|k| 600.0 + 10.0 * wiggle(k, 0.011)).collect();
    let compensated: Vec<f64> = (0..n).map(|k| 50_000.0 + 20.0 * wiggle(k, 0.05)).collect();
    let noise = NoiseModel::calibration_default_for(DEFAULT_ORDER);
    let prior = X2Prior::default();
    let models: Vec<FieldModel> = (0..n / run)
        .map(|r| FieldModel {
            time: &time,
            speed_m_s: &speed,
            alt_m: &alt,
            compensated_nt: &compensated,
            offset: r * run,
            len: run,
            y_ref_nt: 50_000.0,
            z0_m: 600.0,
            noise,
            prior,
            transition: AnomalyTransition::new(&noise, prior.order),
        })
        .collect();
    let checkpoints: Vec<_> = models
        .iter()
        .map(|m| {
            filter_checkpoints(m, default_block_len(run), |_, _| {})
                .unwrap()
                .1
        })
        .collect();
    let mut external = vec![0.0; n];
    let mut g = c.benchmark_group("field smoother");
    g.sample_size(20);
    g.bench_function(format!("n={n} runs of {run}"), |b| {
        b.iter(|| {
            for (m, cps) in models.iter().zip(&checkpoints) {
                smooth_field(m, cps, &mut external).unwrap();
            }
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
