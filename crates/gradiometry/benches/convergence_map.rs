//! Full 40×40×40 convergence map of the seed's fig. 2 case on 2 threads
//! (spec target: ≥ 64 000 starts in < 2 s on 2 cores).

use aeromag_gradiometry::convergence::{ConvergenceCase, Initialisation, convergence_map};
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;

fn bench_map(c: &mut Criterion) {
    let case = ConvergenceCase::seed_fig2(40);
    let mut g = c.benchmark_group("convergence_map_40cubed");
    g.sample_size(10);
    g.bench_function("plain_iekf_2_threads", |b| {
        b.iter(|| {
            convergence_map(black_box(&case), Initialisation::None, 2).map(|m| m.outcomes.len())
        })
    });
    g.bench_function("multistart_2_threads", |b| {
        b.iter(|| {
            convergence_map(black_box(&case), Initialisation::MultiStart, 2)
                .map(|m| m.outcomes.len())
        })
    });
    g.finish();
}

criterion_group!(benches, bench_map);
criterion_main!(benches);
