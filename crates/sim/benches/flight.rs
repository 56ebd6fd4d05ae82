//! Speed of whole simulations (spec `simulator.md`: "a one-hour 10 Hz flight
//! in well under a second").
//!
//! * `survey_default` — the default survey: ≈ 63 min of flight at 10 Hz
//!   (≈ 37 700 samples), the one-hour flight of the spec.
//! * `calibration_full` — the default calibration box (≈ 10 min).

use aeromag_sim::{ScenarioKind, simulate};
use criterion::{Criterion, criterion_group, criterion_main};

fn bench(c: &mut Criterion) {
    let n = simulate(ScenarioKind::Survey, None, Some(1))
        .map(|s| s.n_rows())
        .unwrap_or(0);
    eprintln!(
        "survey_default: {n} samples = {:.1} min at 10 Hz",
        n as f64 / 600.0
    );
    let mut g = c.benchmark_group("simulate");
    g.sample_size(10);
    g.bench_function("calibration_full", |b| {
        b.iter(|| simulate(ScenarioKind::Calibration, None, Some(1)))
    });
    g.bench_function("survey_default", |b| {
        b.iter(|| simulate(ScenarioKind::Survey, None, Some(1)))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
