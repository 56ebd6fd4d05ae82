//! Method 2 (Kalman filter + smoother) on long flights: issue 4 asks for a
//! 10⁶-sample flight in about a second, and for 10⁷ to work.
//!
//! Run: `cargo bench -p aeromag-compensation --bench kalman`. Environment:
//! `AEROMAG_BENCH_N` sets the length (default 10⁶ samples at 10 Hz);
//! `AEROMAG_BENCH_ORDER` the order of the field model (default
//! [`DEFAULT_ORDER`]); `AEROMAG_BENCH_ONCE=1` runs the fit once with each
//! coefficient pass (`Joint`, the default; `Augmented`, the CLI's pass 1;
//! `Split`, the CLI's final fit), without and with the smoother's pass, and
//! prints the times (use with `/usr/bin/time -v` to see the peak memory,
//! e.g. for 10⁷).
//!
//! * `filter+smoother`: pass 1 (joint 24-state filter: the default field
//!   model of order 6 has 8 states, plus 16 coefficients), compensated
//!   series, pass 2 (8-state filter + checkpointed smoother of the means,
//!   modified Bryson–Frazier), no tuning;
//! * `filter only`: pass 1 alone (coefficients and covariances).

use aeromag_compensation::kalman::{
    CoefficientPass, DEFAULT_ORDER, KalmanConfig, KalmanSegment, NoiseModel, TuningConfig, X2Prior,
    fit_kalman,
};
use aeromag_compensation::tolles_lawson::fit_ls::Segment;
use aeromag_compensation::tolles_lawson::terms::derivative;
use aeromag_compensation::tolles_lawson::{Convention, DEFAULT_BT_SCALE_NT, TermSet};
use aeromag_core::frames::Attitude;
use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Vector3;

/// Columns of a synthetic calibration-like flight.
struct Flight {
    time: Vec<f64>,
    flux: [Vec<f64>; 3],
    mag: Vec<f64>,
    alt: Vec<f64>,
    speed: Vec<f64>,
}

/// `n` samples at 10 Hz: 90 m/s, the heading turning by 90° every 5 min,
/// roll/pitch/yaw oscillations, a field with an along-track gradient, a
/// Tolles-Lawson interference and a deterministic pseudo-random noise.
fn flight(n: usize) -> Flight {
    let b_ned = Vector3::new(17_000.0, 1_500.0, 48_000.0);
    let coef = [
        30.0, -12.0, 45.0, 20.0, -5.0, 8.0, 15.0, -3.0, 2.0, -1.5, 0.5, 1.0, -0.7, 0.3, 1.2, -0.4,
    ];
    let mut f = Flight {
        time: vec![],
        flux: [vec![], vec![], vec![]],
        mag: vec![],
        alt: vec![],
        speed: vec![],
    };
    for i in 0..n {
        let s = i as f64 * 0.1;
        let heading = 90.0 * (s / 300.0).floor() + 90.0 * ((s % 300.0 - 270.0).max(0.0) / 30.0);
        let att = Attitude::from_degrees(
            10.0 * (1.05 * s).sin(),
            5.0 * (1.4 * s).sin(),
            heading + 5.0 * (1.25 * s).sin(),
        );
        let b = att.c_bn() * b_ned;
        f.time.push(s);
        for k in 0..3 {
            f.flux[k].push(b[k]);
        }
        f.alt.push(3000.0 + 5.0 * (0.2 * s).sin());
        f.speed.push(90.0);
    }
    let db = [0, 1, 2].map(|k| derivative(&f.flux[k], &f.time, Convention::Physical));
    let terms = TermSet::observable16();
    let mut row = vec![0.0; 16];
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    for i in 0..n {
        terms.row(
            [f.flux[0][i], f.flux[1][i], f.flux[2][i]],
            [db[0][i], db[1][i], db[2][i]],
            &[],
            &[],
            DEFAULT_BT_SCALE_NT,
            &mut row,
        );
        let interf: f64 = row.iter().zip(&coef).map(|(a, c)| a * c).sum();
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        let u = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
        let x = 90.0 * f.time[i];
        f.mag
            .push(b_ned.norm() + interf + 30.0 * (x / 5_000.0).sin() + 0.02 * u);
    }
    f
}

fn config(series: bool) -> KalmanConfig {
    let order = std::env::var("AEROMAG_BENCH_ORDER")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(DEFAULT_ORDER);
    KalmanConfig {
        field_prior: X2Prior {
            order,
            ..X2Prior::default()
        },
        noise: NoiseModel::calibration_default_for(order),
        tuning: TuningConfig {
            enabled: false,
            ..TuningConfig::default()
        },
        compute_series: series,
        ..KalmanConfig::default()
    }
}

fn bench(c: &mut Criterion) {
    let n: usize = std::env::var("AEROMAG_BENCH_N")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1_000_000);
    let f = flight(n);
    let seg = KalmanSegment {
        data: Segment {
            time: &f.time,
            flux: [&f.flux[0], &f.flux[1], &f.flux[2]],
            mag: &f.mag,
            channels: Default::default(),
            direction: None,
        },
        alt_m: &f.alt,
        speed_m_s: &f.speed,
    };
    if std::env::var("AEROMAG_BENCH_ONCE").is_ok() {
        // Each coefficient pass alone, then with the smoother's pass: one
        // segment is one run, so each runs on one core.
        for pass in [
            CoefficientPass::Joint,
            CoefficientPass::Augmented,
            CoefficientPass::Split,
        ] {
            let with = |series: bool| KalmanConfig {
                coefficient_pass: pass,
                ..config(series)
            };
            let t0 = std::time::Instant::now();
            fit_kalman(std::slice::from_ref(&seg), &with(false)).unwrap();
            let t1 = std::time::Instant::now();
            let fit = fit_kalman(std::slice::from_ref(&seg), &with(true)).unwrap();
            let (filter, both) = ((t1 - t0).as_secs_f64(), t1.elapsed().as_secs_f64());
            eprintln!(
                "fit_kalman n={n} {pass:?}: filter only {filter:.2} s; filter+smoother {both:.2} s, \
                 the smoother's pass {:.2} s (residual {:.4} nT, {} runs)",
                both - filter,
                fit.residual_rms_nt,
                fit.runs
            );
        }
        return;
    }
    let mut g = c.benchmark_group("fit_kalman");
    g.sample_size(10);
    g.bench_function(format!("filter+smoother p3,i5,e8 n={n}"), |b| {
        b.iter(|| fit_kalman(std::slice::from_ref(&seg), &config(true)).unwrap())
    });
    g.bench_function(format!("filter only p3,i5,e8 n={n}"), |b| {
        b.iter(|| fit_kalman(std::slice::from_ref(&seg), &config(false)).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
