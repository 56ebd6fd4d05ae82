//! Towed-pod compensation on the simulated seed scenario (spec
//! `helicopter.md` part B, seed `002_…` §5): learn on the seed's 8 headings,
//! compensate the independent 8 headings.

use aeromag_compensation::pod::{
    Cable, PodHeading, compensation_rate, compensation_rate_pooled, default_source_points,
    direction_cosines, fit_dipole_array, fit_joint, fit_two_step, pod_offset_ned,
    pod_position_exact, pod_position_seed, predict_dipole_array, predict_dipole_array_raw,
    predict_joint, predict_joint_raw, predict_small_signal, predict_small_signal_raw,
};
use aeromag_core::frames::Attitude;
use aeromag_sim::scenario::pod::{
    LEARNING_HEADINGS_DEG, PodConfig, PodDipole, PodSegment, TEST_HEADINGS_DEG, simulate_pod,
};

#[derive(Clone, Copy, PartialEq)]
enum Trajectory {
    Seed,
    Exact,
}

/// Pod data as a user has it: recorded field, attitude, cable angles and
/// navigation; the pod position from the trajectory model.
fn to_heading(cfg: &PodConfig, s: &PodSegment, traj: Trajectory) -> PodHeading {
    let inc = cfg.inclination_deg.to_radians();
    let dec = cfg.declination_deg.to_radians();
    let cable = Cable {
        length_m: cfg.cable_m,
        attach_m: cfg.attach_m,
        declination_rad: 0.0,
    };
    let (kx, kh) = (cfg.grad_north_nt_per_km / 1e3, cfg.grad_up_nt_per_km / 1e3);
    let n = s.time_s.len();
    let mut h = PodHeading {
        dt_s: 1.0 / cfg.sample_rate_hz,
        total_nt: s.total_nt.clone(),
        ..PodHeading::default()
    };
    for k in 0..n {
        let att = Attitude::new(s.roll[k], s.pitch[k], s.yaw[k]);
        let (ci, ca) = (s.cable_inclination[k], s.cable_azimuth[k]);
        let p = match traj {
            Trajectory::Exact => pod_position_exact(&cable, &att, ci, ca),
            Trajectory::Seed => pod_position_seed(&cable, &att, s.heading_deg.to_radians(), ci, ca),
        };
        let off = pod_offset_ned(&cable, &att, ci, ca);
        h.track_nt
            .push(kx * (s.north_m[k] + off.x) + kh * (s.altitude_m[k] - off.z));
        h.u.push(direction_cosines(inc, dec, &att));
        h.pod_body_m.push([p.x, p.y, p.z]);
    }
    h
}

/// Per-test-heading rates and the pooled rate of the whole test set
/// (`compensation_rate_pooled`) of each solve.
struct Rates {
    two_step: Vec<f64>,
    joint: Vec<f64>,
    dipole: Vec<f64>,
    pooled: [f64; 3],
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

fn min(v: &[f64]) -> f64 {
    v.iter().copied().fold(f64::INFINITY, f64::min)
}

/// Learn on `learn` headings, return the rates on the test headings.
fn run(cfg: &PodConfig, learn: &[f64], traj_two: Trajectory) -> Rates {
    let lc = PodConfig {
        headings_deg: learn.to_vec(),
        ..cfg.clone()
    };
    let tc = PodConfig {
        headings_deg: TEST_HEADINGS_DEG.to_vec(),
        seed: cfg.seed + 1000,
        ..cfg.clone()
    };
    let ls = simulate_pod(&lc).unwrap();
    let ts = simulate_pod(&tc).unwrap();
    let l2: Vec<_> = ls.iter().map(|s| to_heading(&lc, s, traj_two)).collect();
    let lj: Vec<_> = ls
        .iter()
        .map(|s| to_heading(&lc, s, Trajectory::Exact))
        .collect();
    let two = fit_two_step(&l2).unwrap();
    let joint = fit_joint(&lj).unwrap();
    let da = fit_dipole_array(&lj, &default_source_points()).unwrap();
    let mut r = Rates {
        two_step: vec![],
        joint: vec![],
        dipole: vec![],
        pooled: [0.0; 3],
    };
    let (mut hs2, mut hsj, mut preds) = (vec![], vec![], [vec![], vec![], vec![]]);
    for s in &ts {
        let h2 = to_heading(&tc, s, traj_two);
        let hj = to_heading(&tc, s, Trajectory::Exact);
        let p2 = predict_small_signal(&two.theta, &h2).unwrap();
        r.two_step.push(compensation_rate(&h2, &p2).unwrap());
        let pj = predict_joint(&joint, &hj).unwrap();
        r.joint.push(compensation_rate(&hj, &pj).unwrap());
        let pd = predict_dipole_array(&da, &hj).unwrap();
        r.dipole.push(compensation_rate(&hj, &pd).unwrap());
        preds[0].push(p2);
        preds[1].push(pj);
        preds[2].push(pd);
        hs2.push(h2);
        hsj.push(hj);
    }
    r.pooled = [
        compensation_rate_pooled(&hs2, &preds[0]).unwrap(),
        compensation_rate_pooled(&hsj, &preds[1]).unwrap(),
        compensation_rate_pooled(&hsj, &preds[2]).unwrap(),
    ];
    r
}

/// `cfg` with every eddy-current tensor of the dipole array times `f`.
fn eddy_scaled(cfg: &PodConfig, f: f64) -> PodConfig {
    PodConfig {
        dipoles: cfg
            .dipoles
            .iter()
            .map(|d| PodDipole {
                eddy_am2_s_per_nt: d.eddy_am2_s_per_nt.map(|r| r.map(|x| x * f)),
                ..d.clone()
            })
            .collect(),
        ..cfg.clone()
    }
}

/// RMS over the learning headings of the step-1 heading coefficients:
/// `(rms(W3, W4) / rms(W1, W2)` in s, `rms(W5..7) / rms(W1, W2)` in 1/m).
fn coefficient_ratios(cfg: &PodConfig) -> (f64, f64) {
    let segs = simulate_pod(cfg).unwrap();
    let hs: Vec<_> = segs
        .iter()
        .map(|s| to_heading(cfg, s, Trajectory::Seed))
        .collect();
    let ws = fit_two_step(&hs).unwrap().heading_coefficients;
    let r = |i: std::ops::Range<usize>| {
        let v: Vec<f64> = ws.iter().flat_map(|w| w[i.clone()].to_vec()).collect();
        (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
    };
    (r(2..4) / r(0..2), r(4..7) / r(0..2))
}

/// The same two ratios of the seed's Table 1 (its 8 learning headings).
const SEED_TABLE1_EDDY_RATIO_S: f64 = 0.2489;
const SEED_TABLE1_GRADIENT_RATIO_PER_M: f64 = 0.0765;

/// The seed's scenario (default [`PodConfig`], wind-driven swing): the
/// equivalent-dipole-array solve keeps ≥ 97 % on every independent heading,
/// and both improved solves beat the seed's two-step solve on each. The
/// two-step solve's worst heading is far lower (78 %): with a random
/// pendulum, the swing's second-order terms are not carried by its
/// first-order heading coefficients (module docs of `pod`); the guards below
/// on its mean and pooled rates only catch regressions.
#[test]
fn seed_scenario_two_step_and_dipole_array_joint_on_independent_headings() {
    let cfg = PodConfig::default();
    let r = run(&cfg, &LEARNING_HEADINGS_DEG, Trajectory::Seed);
    println!(
        "two-step (seed trajectory) per test heading: {:?}",
        r.two_step
    );
    println!("joint θ (exact trajectory) per test heading: {:?}", r.joint);
    println!("dipole array per test heading: {:?}", r.dipole);
    assert!(min(&r.dipole) >= 0.97, "dipole array {:?}", r.dipole);
    assert!(mean(&r.joint) >= 0.97, "joint {:?}", r.joint);
    assert!(r.dipole.iter().zip(&r.two_step).all(|(d, t)| d > t));
    assert!(r.joint.iter().zip(&r.two_step).all(|(d, t)| d > t));
    assert!(mean(&r.two_step) >= 0.88, "two-step {:?}", r.two_step);
    assert!(r.pooled[0] >= 0.90, "two-step pooled {}", r.pooled[0]);
}

/// The seed's stated simulation conditions ([`PodConfig::seed_002`]: the
/// defaults with the swing a 5° sinusoid). The simulated helicopter has the
/// eddy-to-attitude ratio of the seed's Table 1 (step-1 coefficients
/// `rms(W3, W4)/rms(W1, W2)`, within 15 %). The seed's two-step solve
/// reaches ≥ 90 % on the independent set (pooled over its samples, the
/// spec's rate `1 − std(after)/std(before)` on the test set, and in the
/// mean over its headings); the improved solves keep ≥ 97 % on every
/// independent heading. The two-step solve's worst heading stays below
/// 90 %, and the reason is its first-order heading model, not step 2:
/// fitted on a single learning heading and applied to that same heading
/// (`fit_two_step` on one heading reproduces its 7 coefficients exactly),
/// it already leaves more than 10 % on the worst heading.
#[test]
fn seed_002_conditions_two_step_reaches_90_percent_on_the_independent_set() {
    let seed = PodConfig::seed_002();
    let (eddy, grad) = coefficient_ratios(&seed);
    println!(
        "rms(W3,W4)/rms(W1,W2): seed Table 1 {SEED_TABLE1_EDDY_RATIO_S} s, ours {eddy:.3} s; \
         rms(W5..7)/rms(W1,W2): seed {SEED_TABLE1_GRADIENT_RATIO_PER_M} /m, ours {grad:.4} /m"
    );
    assert!(
        (eddy / SEED_TABLE1_EDDY_RATIO_S - 1.0).abs() < 0.15,
        "{eddy}"
    );
    let r = run(&seed, &LEARNING_HEADINGS_DEG, Trajectory::Seed);
    // In-sample first-order limit: each learning heading alone.
    let segs = simulate_pod(&seed).unwrap();
    let own: Vec<f64> = segs
        .iter()
        .map(|s| {
            let h = to_heading(&seed, s, Trajectory::Seed);
            let one = fit_two_step(std::slice::from_ref(&h)).unwrap();
            compensation_rate(&h, &predict_small_signal(&one.theta, &h).unwrap()).unwrap()
        })
        .collect();
    println!(
        "seed_002: two-step test {:?} pooled {:.4}; own-heading first-order fit {own:?}; \
         joint min {:.4} pooled {:.4}; dipole array min {:.4} pooled {:.4}",
        r.two_step,
        r.pooled[0],
        min(&r.joint),
        r.pooled[1],
        min(&r.dipole),
        r.pooled[2]
    );
    assert!(r.pooled[0] >= 0.90, "two-step pooled {}", r.pooled[0]);
    assert!(mean(&r.two_step) >= 0.90, "two-step {:?}", r.two_step);
    assert!(min(&r.joint) >= 0.97 && min(&r.dipole) >= 0.97);
    assert!(r.pooled[1] >= 0.97 && r.pooled[2] >= 0.97);
    // Why the worst heading stays under 90 %: the first-order per-heading
    // model, fitted on a heading and scored on that same heading, already
    // does (the dropped displacement terms are not small at a 5° swing on a
    // 40 m cable).
    assert!(min(&own) < 0.90, "{own:?}");
}

/// The degradation table of the module docs (`--nocapture` prints it).
#[test]
fn pod_degradation_table() {
    let base = PodConfig::default();
    println!(
        "| case | two-step min / mean / pooled % | joint θ min / mean / pooled % | dipole array min / mean / pooled % |"
    );
    println!("|---|---|---|---|");
    let row = |name: String, cfg: &PodConfig, learn: &[f64]| -> Rates {
        let r = run(cfg, learn, Trajectory::Seed);
        let f = |v: &[f64], p: f64| {
            format!(
                "{:.1} / {:.1} / {:.1}",
                100.0 * min(v),
                100.0 * mean(v),
                100.0 * p
            )
        };
        println!(
            "| {name} | {} | {} | {} |",
            f(&r.two_step, r.pooled[0]),
            f(&r.joint, r.pooled[1]),
            f(&r.dipole, r.pooled[2])
        );
        r
    };
    let mut noise_joint = vec![];
    for noise in [0.002, 0.01, 0.03, 0.1] {
        let cfg = PodConfig {
            sensor_noise_nt: noise,
            ..base.clone()
        };
        noise_joint.push(min(&row(
            format!("sensor noise {noise} nT"),
            &cfg,
            &LEARNING_HEADINGS_DEG,
        )
        .dipole));
    }
    for swing in [2.0, 5.0, 10.0] {
        let cfg = PodConfig {
            swing_amp_deg: swing,
            ..base.clone()
        };
        row(format!("swing {swing}°"), &cfg, &LEARNING_HEADINGS_DEG);
    }
    // Diagnosis of the seed's solve: the same scenario without eddy
    // currents in the helicopter.
    row(
        "no eddy currents".into(),
        &eddy_scaled(&base, 0.0),
        &LEARNING_HEADINGS_DEG,
    );
    let seed = PodConfig::seed_002();
    row(
        "`PodConfig::seed_002()` (sine swing)".into(),
        &seed,
        &LEARNING_HEADINGS_DEG,
    );
    // Robustness: eddy currents 37× stronger (the simulator's default
    // before it took the seed's Table 1 ratio; eddy moments of ≈ 1800 A·m²
    // in a 5° manoeuvre, unphysical for an airframe but a hard case).
    row(
        "`seed_002()`, eddy currents × 37".into(),
        &eddy_scaled(&seed, 37.0),
        &LEARNING_HEADINGS_DEG,
    );
    for n in [4usize, 5, 6, 8] {
        row(
            format!("{n} learning headings"),
            &base,
            &LEARNING_HEADINGS_DEG[..n],
        );
    }
    // More sensor noise cannot help the dipole-array solve.
    assert!(noise_joint[3] < noise_joint[0], "{noise_joint:?}");
}

/// The raw predictions (for compensating a record) are the high-passed ones
/// before the high-pass: `detrend(raw) = high-passed`, and the raw
/// dipole-array prediction follows the true interference including its
/// slow part up to a constant.
#[test]
fn raw_predictions_high_pass_to_the_fitted_ones() {
    use aeromag_compensation::pod::detrend;
    let cfg = PodConfig {
        headings_deg: vec![0.0, 90.0, 200.0],
        ..PodConfig::default()
    };
    let segs = simulate_pod(&cfg).unwrap();
    let hs: Vec<_> = segs
        .iter()
        .map(|s| to_heading(&cfg, s, Trajectory::Exact))
        .collect();
    let joint = fit_joint(&hs).unwrap();
    let theta = fit_two_step(&hs).unwrap().theta;
    let da = fit_dipole_array(&hs, &default_source_points()).unwrap();
    let close = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-9);
    for h in &hs {
        let pairs = [
            (
                predict_small_signal_raw(&theta, h).unwrap(),
                predict_small_signal(&theta, h).unwrap(),
            ),
            (
                predict_joint_raw(&joint, h).unwrap(),
                predict_joint(&joint, h).unwrap(),
            ),
            (
                predict_dipole_array_raw(&da, h).unwrap(),
                predict_dipole_array(&da, h).unwrap(),
            ),
        ];
        for (raw, hp) in &pairs {
            assert!(close(&detrend(raw), hp));
        }
    }
    let s = &segs[2];
    let raw = predict_dipole_array_raw(&da, &hs[2]).unwrap();
    let d: Vec<f64> = raw
        .iter()
        .zip(&s.true_interf_nt)
        .map(|(a, b)| a - b)
        .collect();
    let m = mean(&d);
    let spread = d.iter().map(|x| (x - m).abs()).fold(0.0, f64::max);
    let m_t = mean(&s.true_interf_nt);
    let range = s
        .true_interf_nt
        .iter()
        .map(|x| (x - m_t).abs())
        .fold(0.0, f64::max);
    assert!(spread < 0.05 * range, "{spread} of {range}");
}
