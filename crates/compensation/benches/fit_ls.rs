//! Band-pass least-squares fit on long flights (issue: 10⁷ samples in a few
//! seconds with bounded memory). Run: `cargo bench -p aeromag-compensation --bench fit_ls`.
//! Set AEROMAG_BENCH_N to change the length (default 10⁶ samples at 10 Hz).

use aeromag_compensation::tolles_lawson::fit_ls::{LsConfig, Segment, fit_band_pass_ls};
use aeromag_compensation::tolles_lawson::lag_select::{
    DEFAULT_ALPHA, DEFAULT_LAG_GRID_S, DEFAULT_SELECTION_BLOCK, DEFAULT_SELECTION_ROWS,
    select_eddy_lags, within_budget,
};
use criterion::{Criterion, criterion_group, criterion_main};

/// A long synthetic flight: the Earth's field seen from an aircraft that
/// rolls, pitches and yaws with incommensurate periods, plus a scalar
/// reading with an attitude-dependent offset.
fn flight(n: usize) -> (Vec<f64>, [Vec<f64>; 3], Vec<f64>) {
    let (mut t, mut x, mut y, mut z, mut m) = (vec![], vec![], vec![], vec![], vec![]);
    for i in 0..n {
        let s = i as f64 * 0.1;
        let (r, p, h) = (
            0.17 * (1.2 * s).sin(),
            0.08 * (1.45 * s).sin(),
            0.001 * s + 0.08 * (1.1 * s).sin(),
        );
        let (bn, be, bd) = (17_000.0, 1_500.0, 48_000.0);
        let (ch, sh) = (h.cos(), h.sin());
        let (xn, ye) = (ch * bn + sh * be, -sh * bn + ch * be);
        let bx = xn * p.cos() - bd * p.sin();
        let bz0 = xn * p.sin() + bd * p.cos();
        let by = ye * r.cos() + bz0 * r.sin();
        let bz = -ye * r.sin() + bz0 * r.cos();
        t.push(s);
        x.push(bx);
        y.push(by);
        z.push(bz);
        m.push(
            (bx * bx + by * by + bz * bz).sqrt() + 0.001 * bx - 0.0005 * bz
                + 1e-3 * (s * 0.01).sin(),
        );
    }
    (t, [x, y, z], m)
}

fn bench(c: &mut Criterion) {
    let n: usize = std::env::var("AEROMAG_BENCH_N")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1_000_000);
    let (t, f, m) = flight(n);
    let seg = Segment {
        time: &t,
        flux: [&f[0], &f[1], &f[2]],
        mag: &m,
        channels: Default::default(),
        direction: None,
    };
    let cfg = LsConfig::default();
    let mut g = c.benchmark_group("fit_band_pass_ls");
    g.sample_size(10);
    g.bench_function(format!("p3,i5,e8 n={n}"), |b| {
        b.iter(|| fit_band_pass_ls(std::slice::from_ref(&seg), &cfg).unwrap())
    });
    // `calibrate --eddy-lag auto`: the lag search on the row budget, then
    // the final fit with the lags on every row.
    g.bench_function(format!("auto eddy lags n={n}"), |b| {
        b.iter(|| {
            let sample = within_budget(
                std::slice::from_ref(&seg),
                DEFAULT_SELECTION_ROWS,
                DEFAULT_SELECTION_BLOCK,
            );
            let sel =
                select_eddy_lags(&sample, &cfg, &DEFAULT_LAG_GRID_S, 2, DEFAULT_ALPHA).unwrap();
            let terms = cfg.design.terms.with_eddy_lags(&sel.taus_s).unwrap();
            fit_band_pass_ls(
                std::slice::from_ref(&seg),
                &LsConfig {
                    design: cfg.design.with_terms(terms),
                    ..cfg.clone()
                },
            )
            .unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
