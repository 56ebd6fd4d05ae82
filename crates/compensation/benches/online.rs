//! The online compensator, sample by sample (issue 21: per-sample latency
//! p99 ≤ 5 µs for the fixed model, ≤ 50 µs for the adaptive Kalman mode).
//!
//! Run: `cargo bench -p aeromag-compensation --bench online`. The
//! criterion group times passes over 10⁵ samples (the mean per sample is
//! the time / 10⁵); then each of 10⁶ pushes is timed on its own and the
//! p50, p99, p99.9 and maximum are printed (`Instant` costs about 20 ns,
//! included).
//!
//! The model: 18 terms with two lagged eddy groups (`p3,i6,e9,l9` at
//! τ = 0.3, 0.7 s), a bias and two extra channels (one lagged): 37
//! columns, first order and exact magnitude, fixed; adaptive (first order)
//! with the Kalman filter (37 coefficients and 8 field states) and RLS.

use aeromag_compensation::kalman::online::{OnlineKalman, OnlineKalmanSettings};
use aeromag_compensation::tolles_lawson::adaptive::{AdaptiveTl, Navigation};
use aeromag_compensation::tolles_lawson::online::{OnlineSample, OnlineTl};
use aeromag_compensation::tolles_lawson::rls::{Rls, RlsSettings};
use aeromag_compensation::tolles_lawson::{Design, ExtraTerm, Magnitude, TermSet};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;
use std::time::Instant;

/// `n` samples at 10 Hz: a turning, oscillating field, a reading and two
/// channels.
fn samples(n: usize) -> Vec<(f64, [f64; 3], f64, [f64; 2])> {
    (0..n)
        .map(|k| {
            let t = k as f64 * 0.1;
            let h = 0.001 * t + 0.2 * (0.9 * t).sin();
            let b = [
                20_000.0 * h.cos(),
                20_000.0 * h.sin(),
                45_000.0 + 50.0 * (0.5 * t).cos(),
            ];
            let strobe = 5.0 * ((k / 7) % 2) as f64;
            let ramp = (k % 50) as f64 * 0.1;
            (t, b, 50_000.0 + (0.01 * t).sin(), [strobe, ramp])
        })
        .collect()
}

fn model(magnitude: Magnitude) -> (Design, Vec<f64>) {
    let terms = TermSet::parse("p3,i6,e9,l9,bias")
        .unwrap()
        .with_eddy_lags(&[0.3, 0.7])
        .unwrap()
        .with_extras(&[ExtraTerm::new("strobe"), ExtraTerm::lagged("ramp", 0.4)])
        .unwrap();
    let n = terms.n_columns();
    let coef = (0..n).map(|k| 10.0 * ((k as f64) * 0.7).sin()).collect();
    (
        Design {
            magnitude,
            ..Design::new(terms)
        },
        coef,
    )
}

type Sample = (f64, [f64; 3], f64, [f64; 2]);

fn sample(s: &Sample) -> OnlineSample<'_> {
    OnlineSample {
        time_s: s.0,
        flux_nt: s.1,
        mag_nt: s.2,
        channels: &s.3,
    }
}

const NAV: Navigation = Navigation {
    speed_m_s: 70.0,
    alt_m: 3000.0,
};

/// Makes a fresh compensator: a closure pushing one sample.
type Make = Box<dyn Fn() -> Box<dyn FnMut(&Sample) -> f64>>;

/// The compensators timed: name and a fresh one pushing a sample.
fn compensators() -> Vec<(&'static str, Make)> {
    let fixed = |magnitude| -> Make {
        let (design, coef) = model(magnitude);
        Box::new(move || {
            let mut o = OnlineTl::new(&design, &coef, 0.15).unwrap();
            Box::new(move |s: &Sample| o.push(&sample(s)).compensated_nt)
        })
    };
    let adaptive = |kalman: bool| -> Make {
        let (design, coef) = model(Magnitude::FirstOrder);
        let std = vec![1.0; coef.len()];
        Box::new(move || {
            let est: Box<dyn aeromag_compensation::tolles_lawson::adaptive::CoefficientEstimator> =
                if kalman {
                    Box::new(
                        OnlineKalman::new(&design, &coef, &std, &OnlineKalmanSettings::default())
                            .unwrap(),
                    )
                } else {
                    Box::new(Rls::new(&coef, &std, RlsSettings::default()).unwrap())
                };
            let mut o = AdaptiveTl::new(&design, 0.15, est).unwrap();
            Box::new(move |s: &Sample| o.push(&sample(s), NAV).compensated_nt)
        })
    };
    vec![
        ("first-order", fixed(Magnitude::FirstOrder)),
        ("exact", fixed(Magnitude::Exact)),
        ("adaptive Kalman", adaptive(true)),
        ("adaptive RLS", adaptive(false)),
    ]
}

fn bench(c: &mut Criterion) {
    let data = samples(100_000);
    let mut g = c.benchmark_group("online");
    g.throughput(Throughput::Elements(data.len() as u64));
    g.sample_size(10);
    for (name, make) in compensators() {
        g.bench_function(format!("push 1e5 samples, {name}"), |b| {
            b.iter(|| {
                let mut push = make();
                let mut acc = 0.0;
                for s in &data {
                    acc += push(s);
                }
                black_box(acc)
            })
        });
    }
    g.finish();
    // Each push timed alone.
    let data = samples(1_000_000);
    for (name, make) in compensators() {
        let mut push = make();
        let mut ns: Vec<u64> = Vec::with_capacity(data.len());
        for s in &data {
            let t0 = Instant::now();
            black_box(push(s));
            ns.push(t0.elapsed().as_nanos() as u64);
        }
        ns.sort_unstable();
        let q = |p: f64| ns[((ns.len() as f64 * p) as usize).min(ns.len() - 1)];
        println!(
            "online push latency, {name}, {} samples: p50 {} ns, p99 {} ns, p99.9 {} ns, max {} ns",
            ns.len(),
            q(0.5),
            q(0.99),
            q(0.999),
            ns[ns.len() - 1]
        );
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
