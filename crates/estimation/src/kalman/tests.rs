//! Property tests of the square-root filter and smoother against the
//! conventional (Joseph-form) filter and the textbook RTS smoother on random
//! linear-Gaussian systems.

use super::*;
use nalgebra::{DMatrix, DVector, SymmetricEigen};
use proptest::prelude::*;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

/// A random time-varying linear-Gaussian system with its measurements.
#[derive(Clone)]
struct System {
    x0: Vec<f64>,
    s0: DMatrix<f64>,
    phis: Vec<DMatrix<f64>>,
    gs: Vec<DMatrix<f64>>,
    hs: Vec<Vec<f64>>,
    ys: Vec<f64>,
    rs: Vec<f64>,
    /// Steps without a measurement.
    gaps: Vec<bool>,
}

fn normal(rng: &mut ChaCha8Rng) -> f64 {
    StandardNormal.sample(rng)
}

/// `prior_scale` and `r_scale` stretch the problem towards ill-conditioning.
fn system(seed: u64, n: usize, q: usize, steps: usize, prior_scale: f64, r_scale: f64) -> System {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let a = DMatrix::from_fn(n, n, |_, _| normal(&mut rng));
    let p0 = &a * a.transpose() * prior_scale + DMatrix::identity(n, n) * 0.1;
    let s0 = upper_cholesky(&p0).unwrap();
    let x0 = (0..n).map(|_| normal(&mut rng)).collect();
    let mut sys = System {
        x0,
        s0,
        phis: vec![],
        gs: vec![],
        hs: vec![],
        ys: vec![],
        rs: vec![],
        gaps: vec![],
    };
    for k in 0..steps {
        let phi = DMatrix::identity(n, n) * 0.95
            + DMatrix::from_fn(n, n, |_, _| 0.3 * normal(&mut rng) / (n as f64).sqrt());
        let g = DMatrix::from_fn(n, q, |_, _| 0.3 * normal(&mut rng));
        sys.phis.push(phi);
        sys.gs.push(g);
        sys.hs.push((0..n).map(|_| normal(&mut rng)).collect());
        sys.ys.push(3.0 * normal(&mut rng));
        sys.rs.push(r_scale * rng.random_range(0.05..2.0));
        sys.gaps.push(k % 5 == 3);
    }
    sys
}

/// As [`system`] with `q = n` and upper-triangular `Φ_k` and `G_k` (the
/// structure of chains of integrators), which the time update handles with
/// its cheaper kernel ([`triangularize::triangularize_upper_pair`]).
fn triangular_system(seed: u64, n: usize, steps: usize) -> System {
    let mut sys = system(seed, n, n, steps, 1.0, 1.0);
    for m in sys.phis.iter_mut().chain(sys.gs.iter_mut()) {
        for j in 0..n {
            for i in j + 1..n {
                m[(i, j)] = 0.0;
            }
        }
    }
    sys
}

impl StateSpaceModel for System {
    fn dim(&self) -> usize {
        self.x0.len()
    }
    fn steps(&self) -> usize {
        self.ys.len()
    }
    fn prior(&self, x0: &mut [f64], s0: &mut DMatrix<f64>) {
        x0.copy_from_slice(&self.x0);
        s0.copy_from(&self.s0);
    }
    fn noise_dim(&self) -> usize {
        self.gs[0].ncols()
    }
    fn transition(&self, k: usize, phi: &mut DMatrix<f64>, g: &mut DMatrix<f64>) {
        phi.copy_from(&self.phis[k]);
        g.copy_from(&self.gs[k]);
    }
    fn measurement(&self, k: usize, h: &mut [f64]) -> Option<(f64, f64)> {
        if self.gaps[k] {
            return None;
        }
        h.copy_from_slice(&self.hs[k]);
        Some((self.ys[k], self.rs[k]))
    }
}

/// The conventional filter over the system: per step (predicted, filtered)
/// means and covariances, innovations.
#[allow(clippy::type_complexity)]
fn conventional_run(
    sys: &System,
    ys: &[f64],
    x0: &[f64],
) -> (
    Vec<(DVector<f64>, DMatrix<f64>)>,
    Vec<(DVector<f64>, DMatrix<f64>)>,
    Vec<Innovation>,
) {
    let p0 = &sys.s0 * sys.s0.transpose();
    let mut f = ConventionalKalmanFilter::new(DVector::from_column_slice(x0), p0).unwrap();
    let (mut pred, mut filt, mut inns) = (vec![], vec![], vec![]);
    for k in 0..ys.len() {
        if k > 0 {
            f.predict(&sys.phis[k], &(&sys.gs[k] * sys.gs[k].transpose()));
        }
        pred.push((f.x.clone(), f.p.clone()));
        if !sys.gaps[k] {
            inns.push(f.update(&sys.hs[k], ys[k], sys.rs[k]).unwrap());
        }
        filt.push((f.x.clone(), f.p.clone()));
    }
    (pred, filt, inns)
}

/// The square-root filter over the system: filtered means, factors, innovations.
fn sqrt_run(
    sys: &System,
    ys: &[f64],
    x0: &[f64],
) -> (Vec<DVector<f64>>, Vec<DMatrix<f64>>, Vec<Innovation>) {
    let mut f = SqrtKalmanFilter::new(x0, &sys.s0).unwrap();
    let (mut xs, mut ss, mut inns) = (vec![], vec![], vec![]);
    for k in 0..ys.len() {
        if k > 0 {
            f.predict(&sys.phis[k], &sys.gs[k]).unwrap();
        }
        if !sys.gaps[k] {
            inns.push(f.update(&sys.hs[k], ys[k], sys.rs[k]).unwrap());
        }
        xs.push(f.state().clone());
        ss.push(f.factor().clone());
    }
    (xs, ss, inns)
}

fn scale_of(m: &DMatrix<f64>) -> f64 {
    m.abs().max().max(1.0)
}

fn min_eigenvalue(p: &DMatrix<f64>) -> f64 {
    SymmetricEigen::new(p.clone()).eigenvalues.min()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn square_root_filter_equals_the_joseph_filter(seed in any::<u64>(), n in 1usize..9, q in 0usize..5, steps in 1usize..40, triangular in any::<bool>()) {
        let sys = if triangular { triangular_system(seed, n, steps) } else { system(seed, n, q, steps, 1.0, 1.0) };
        let (_, filt, inn_c) = conventional_run(&sys, &sys.ys, &sys.x0);
        let (xs, ss, inn_s) = sqrt_run(&sys, &sys.ys, &sys.x0);
        for k in 0..steps {
            let p = &ss[k] * ss[k].transpose();
            let tol = 1e-9 * scale_of(&filt[k].1);
            prop_assert!((&p - &filt[k].1).abs().max() <= tol, "P at step {}: {}", k, (&p - &filt[k].1).abs().max());
            let xtol = 1e-9 * filt[k].0.abs().max().max(1.0);
            prop_assert!((&xs[k] - &filt[k].0).abs().max() <= xtol);
        }
        prop_assert_eq!(inn_c.len(), inn_s.len());
        for (a, b) in inn_c.iter().zip(&inn_s) {
            prop_assert!((a.value - b.value).abs() <= 1e-9 * a.value.abs().max(1.0));
            prop_assert!((a.variance - b.variance).abs() <= 1e-9 * a.variance);
        }
    }

    #[test]
    fn the_filter_is_linear_in_the_data_and_prior_mean(seed in any::<u64>(), n in 1usize..7, steps in 1usize..30, a in -3.0f64..3.0, b in -3.0f64..3.0) {
        let sys = system(seed, n, 2, steps, 1.0, 1.0);
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5555);
        let y2: Vec<f64> = (0..steps).map(|_| normal(&mut rng)).collect();
        let x02: Vec<f64> = (0..n).map(|_| normal(&mut rng)).collect();
        let ymix: Vec<f64> = sys.ys.iter().zip(&y2).map(|(u, v)| a * u + b * v).collect();
        let xmix: Vec<f64> = sys.x0.iter().zip(&x02).map(|(u, v)| a * u + b * v).collect();
        let (x1, _, _) = sqrt_run(&sys, &sys.ys, &sys.x0);
        let (x2, _, _) = sqrt_run(&sys, &y2, &x02);
        let (xm, _, _) = sqrt_run(&sys, &ymix, &xmix);
        for k in 0..steps {
            let lin = &x1[k] * a + &x2[k] * b;
            let scale = x1[k].abs().max().max(x2[k].abs().max()).max(1.0) * (a.abs() + b.abs()).max(1.0);
            prop_assert!((&xm[k] - lin).abs().max() <= 1e-10 * scale);
        }
    }

    #[test]
    fn covariance_stays_positive_definite_when_ill_conditioned(seed in any::<u64>(), n in 2usize..9, steps in 5usize..40) {
        // Diffuse prior (variances ~1e8) and precise measurements (r ~ 1e-6):
        // a dynamic range of 1e14 in P.
        let sys = system(seed, n, 1, steps, 1e8, 1e-6);
        let (_, ss, inns) = sqrt_run(&sys, &sys.ys, &sys.x0);
        for s in &ss {
            for i in 0..n {
                prop_assert!(s[(i, i)] > 0.0, "diagonal of S must stay positive");
                for j in 0..i {
                    prop_assert_eq!(s[(i, j)], 0.0);
                }
            }
            let p = s * s.transpose();
            prop_assert_eq!(&p, &p.transpose());
        }
        prop_assert!(inns.iter().all(|i| i.variance > 0.0 && i.variance.is_finite()));
    }

    #[test]
    fn square_root_smoother_equals_the_textbook_one_and_never_exceeds_the_filter(seed in any::<u64>(), n in 1usize..9, q in 1usize..4, steps in 2usize..40, block in 0usize..6, triangular in any::<bool>()) {
        let sys = if triangular { triangular_system(seed, n, steps) } else { system(seed, n, q, steps, 1.0, 1.0) };
        let (pred, filt, inn_c) = conventional_run(&sys, &sys.ys, &sys.x0);
        // Textbook RTS.
        let mut sm = vec![(DVector::zeros(n), DMatrix::zeros(n, n)); steps];
        sm[steps - 1] = filt[steps - 1].clone();
        for k in (0..steps - 1).rev() {
            let (x, p) = rts_step_conventional((&filt[k].0, &filt[k].1), (&pred[k + 1].0, &pred[k + 1].1), &sys.phis[k + 1], (&sm[k + 1].0, &sm[k + 1].1)).unwrap();
            sm[k] = (x, p);
        }
        let opts = SmootherOptions { block_len: block, covariance: true };
        let mut got = vec![(DVector::zeros(n), DMatrix::zeros(n, n)); steps];
        let mut order = vec![];
        let mut n_inn = 0;
        let ll = fixed_interval_smooth(&sys, &opts, |_, _| n_inn += 1, |k, x, s| {
            order.push(k);
            got[k] = (DVector::from_column_slice(x), s.unwrap() * s.unwrap().transpose());
        }).unwrap();
        prop_assert_eq!(order, (0..steps).rev().collect::<Vec<_>>());
        // Means alone, by the modified Bryson–Frazier recursion.
        let mut means = vec![DVector::zeros(n); steps];
        let ll_means = fixed_interval_smooth(&sys, &SmootherOptions { block_len: block, covariance: false }, |_, _| {}, |k, x, s| {
            assert!(s.is_none());
            means[k] = DVector::from_column_slice(x);
        }).unwrap();
        prop_assert_eq!(ll_means, ll);
        for k in 0..steps {
            prop_assert!((&means[k] - &sm[k].0).abs().max() <= 1e-9 * sm[k].0.abs().max().max(1.0), "MBF x_s at {}", k);
        }
        prop_assert_eq!(n_inn, inn_c.len());
        let ll_ref: f64 = inn_c.iter().map(|i| i.log_likelihood()).sum();
        prop_assert!((ll - ll_ref).abs() <= 1e-9 * ll_ref.abs().max(1.0));
        for k in 0..steps {
            let tol = 1e-9 * scale_of(&sm[k].1);
            prop_assert!((&got[k].1 - &sm[k].1).abs().max() <= tol, "P_s at {}", k);
            prop_assert!((&got[k].0 - &sm[k].0).abs().max() <= 1e-9 * sm[k].0.abs().max().max(1.0), "x_s at {}", k);
            // Smoothing never increases uncertainty: P_f − P_s ⪰ 0.
            let diff = &filt[k].1 - &got[k].1;
            prop_assert!(min_eigenvalue(&diff) >= -1e-9 * scale_of(&filt[k].1));
            for i in 0..n {
                prop_assert!(got[k].1[(i, i)] <= filt[k].1[(i, i)] * (1.0 + 1e-9) + 1e-12);
            }
        }
    }
}

#[test]
fn checkpointing_is_bit_identical_whatever_the_block_length() {
    let sys = system(99, 4, 2, 157, 1.0, 1.0);
    let run = |block: usize, cov: bool| {
        let mut out = vec![vec![0.0; 4 + 16]; 157];
        fixed_interval_smooth(
            &sys,
            &SmootherOptions {
                block_len: block,
                covariance: cov,
            },
            |_, _| {},
            |k, x, s| {
                out[k][..4].copy_from_slice(x);
                if let Some(s) = s {
                    out[k][4..].copy_from_slice(s.as_slice());
                }
            },
        )
        .unwrap();
        out
    };
    let reference = run(157, true);
    for block in [1, 2, 7, 64, 0] {
        assert_eq!(run(block, true), reference, "block {block}");
    }
    // Means alone (the MBF recursion): bit-identical whatever the block
    // length too, and equal to the RTS means up to round-off.
    let means = run(157, false);
    for block in [1, 2, 7, 64, 0] {
        assert_eq!(run(block, false), means, "means, block {block}");
    }
    for (m, r) in means.iter().zip(&reference) {
        for i in 0..4 {
            assert!(
                (m[i] - r[i]).abs() <= 1e-12 * r[i].abs().max(1.0),
                "{} vs {}",
                m[i],
                r[i]
            );
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    /// With constant trailing parameters, the joint filter's conditional of
    /// the leading states given the true parameters equals a filter of the
    /// leading states alone on the data corrected by those parameters.
    #[test]
    fn the_leading_conditional_is_the_filter_given_the_parameters(seed in any::<u64>(), k in 1usize..9, m in 1usize..5, steps in 1usize..30, triangular in any::<bool>()) {
        let n = k + m;
        let sys = if triangular { triangular_system(seed, k, steps) } else { system(seed, k, 2, steps, 1.0, 1.0) };
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0xABCD);
        let theta: Vec<f64> = (0..m).map(|_| normal(&mut rng)).collect();
        let hb: Vec<Vec<f64>> = (0..steps).map(|_| (0..m).map(|_| normal(&mut rng)).collect()).collect();
        // Joint filter: prior of the parameters independent, mean 0, std 2.
        let mut s0 = DMatrix::zeros(n, n);
        s0.view_mut((0, 0), (k, k)).copy_from(&sys.s0);
        for j in k..n {
            s0[(j, j)] = 2.0;
        }
        let mut x0 = sys.x0.clone();
        x0.extend(std::iter::repeat_n(0.0, m));
        let mut joint = SqrtKalmanFilter::new(&x0, &s0).unwrap();
        let mut alone = SqrtKalmanFilter::new(&sys.x0, &sys.s0).unwrap();
        for t in 0..steps {
            if t > 0 {
                joint.predict_leading(&sys.phis[t], &sys.gs[t]).unwrap();
                alone.predict(&sys.phis[t], &sys.gs[t]).unwrap();
            }
            if !sys.gaps[t] {
                let mut h = sys.hs[t].clone();
                h.extend_from_slice(&hb[t]);
                joint.update(&h, sys.ys[t], sys.rs[t]).unwrap();
                let corr: f64 = hb[t].iter().zip(&theta).map(|(a, b)| a * b).sum();
                alone.update(&sys.hs[t], sys.ys[t] - corr, sys.rs[t]).unwrap();
            }
            let c = joint.leading_conditional(k).unwrap();
            let mean = c.mean_given(&theta);
            let pa = &c.factor * c.factor.transpose();
            let pb = alone.covariance();
            prop_assert!((&pa - &pb).abs().max() <= 1e-9 * scale_of(&pb));
            for i in 0..k {
                prop_assert!((mean[i] - alone.state()[i]).abs() <= 1e-8 * alone.state().abs().max().max(1.0));
            }
        }
    }
}

/// The smoother re-runs four blocks at a time in SIMD lanes for 5, 6 and 8
/// states: the smoothed means are those of the blocks re-run one at a time
/// with the filter alone, to the bit — dense and two-chain models, steps
/// without a measurement, and a step whose `Φ` is not upper triangular (its
/// batch is re-run block by block). A bad reading is the same error.
#[test]
fn smoothing_in_lanes_is_block_by_block_bit_for_bit() {
    use super::filter_checkpoints;
    use super::fixed_interval::smooth_means_block_by_block;
    fn means<const N: usize>(sys: &System, block: usize, lanes: bool) -> Result<Vec<u64>, String> {
        let (_, cps) = filter_checkpoints(sys, block, |_, _| {}).map_err(|e| e.to_string())?;
        let mut out = vec![0u64; sys.ys.len() * N];
        let keep = |k: usize, x: &[f64], _: Option<&DMatrix<f64>>| {
            for (o, v) in out[k * N..(k + 1) * N].iter_mut().zip(x) {
                *o = v.to_bits();
            }
        };
        if lanes {
            smooth_from_checkpoints(sys, &cps, false, keep)
        } else {
            smooth_means_block_by_block(sys, &cps, keep)
        }
        .map_err(|e| e.to_string())?;
        Ok(out)
    }
    fn check<const N: usize>(seed: u64) {
        let steps = 301;
        for two in [false, true] {
            let mut sys = triangular_system(seed, N, steps);
            if two {
                for m in sys.phis.iter_mut().chain(sys.gs.iter_mut()) {
                    for j in N - 2..N {
                        for i in 0..N - 2 {
                            m[(i, j)] = 0.0;
                        }
                    }
                }
                for h in &mut sys.hs {
                    for (i, v) in h.iter_mut().enumerate() {
                        if i != 0 && i != N - 2 {
                            *v = 0.0;
                        }
                    }
                }
            }
            for block in [1, 7, 40, 301] {
                let reference = means::<N>(&sys, block, false).unwrap();
                assert_eq!(
                    means::<N>(&sys, block, true).unwrap(),
                    reference,
                    "N {N}, two {two}, block {block}"
                );
            }
            // A lower entry in one Φ: that batch block by block.
            let mut lower = sys.clone();
            lower.phis[150][(N - 1, 0)] = 0.01;
            let reference = means::<N>(&lower, 7, false).unwrap();
            assert_eq!(
                means::<N>(&lower, 7, true).unwrap(),
                reference,
                "N {N}, lower Φ"
            );
            // A bad reading after the checkpoints were taken: the same error.
            let (_, cps) = filter_checkpoints(&sys, 7, |_, _| {}).unwrap();
            let mut bad = sys.clone();
            bad.ys[200] = f64::NAN;
            bad.gaps[200] = false;
            let run = |lanes: bool| {
                let keep = |_: usize, _: &[f64], _: Option<&DMatrix<f64>>| {};
                if lanes {
                    smooth_from_checkpoints(&bad, &cps, false, keep)
                } else {
                    smooth_means_block_by_block(&bad, &cps, keep)
                }
                .unwrap_err()
                .to_string()
            };
            assert_eq!(run(true), run(false));
            assert!(run(true).contains("200"), "{}", run(true));
        }
    }
    check::<5>(3);
    check::<6>(4);
    check::<8>(5);
}
