//! Towed-pod compensation on the simulated seed scenario (spec
//! `helicopter.md` part B, seed `002_…` §5): learn on the seed's 8 headings,
//! compensate the independent 8 headings.

use aeromag_compensation::pod::{
    Cable, PodHeading, compensation_rate, default_source_points, direction_cosines,
    fit_dipole_array, fit_joint, fit_two_step, pod_offset_ned, pod_position_exact,
    pod_position_seed, predict_dipole_array, predict_dipole_array_raw, predict_joint,
    predict_joint_raw, predict_small_signal, predict_small_signal_raw,
};
use aeromag_core::frames::Attitude;
use aeromag_sim::scenario::pod::{
    LEARNING_HEADINGS_DEG, PodConfig, PodSegment, TEST_HEADINGS_DEG, simulate_pod,
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

struct Rates {
    two_step: Vec<f64>,
    joint: Vec<f64>,
    dipole: Vec<f64>,
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
    };
    for s in &ts {
        let h2 = to_heading(&tc, s, traj_two);
        let hj = to_heading(&tc, s, Trajectory::Exact);
        let p2 = predict_small_signal(&two.theta, &h2).unwrap();
        r.two_step.push(compensation_rate(&h2, &p2).unwrap());
        let pj = predict_joint(&joint, &hj).unwrap();
        r.joint.push(compensation_rate(&hj, &pj).unwrap());
        let pd = predict_dipole_array(&da, &hj).unwrap();
        r.dipole.push(compensation_rate(&hj, &pd).unwrap());
    }
    r
}

/// The seed's scenario (default [`PodConfig`]): the equivalent-dipole-array
/// solve and the joint solve with the eddy-current gradient keep ≥ 97 % on
/// every independent heading and beat the seed's two-step solve on each.
/// The two-step solve does **not** reach the seed's 90 % on every heading
/// here (83.6 % worst, 89.4 % mean, see the module docs of `pod`): its
/// first-order heading coefficients cannot carry the gradient of the
/// eddy-current field (the product of the pod displacement and the field
/// rate), which is large in this scenario, nor the second-order terms in
/// `v` and in the displacement (without eddy currents its worst heading is
/// 77 %, degradation table); the guard below (mean ≥ 85 %) only catches
/// regressions.
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
    assert!(min(&r.joint) >= 0.97, "joint {:?}", r.joint);
    assert!(r.dipole.iter().zip(&r.two_step).all(|(d, t)| d > t));
    assert!(r.joint.iter().zip(&r.two_step).all(|(d, t)| d > t));
    assert!(mean(&r.two_step) >= 0.85, "two-step {:?}", r.two_step);
}

/// The degradation table of the module docs (`--nocapture` prints it).
#[test]
fn pod_degradation_table() {
    let base = PodConfig::default();
    println!("| case | two-step min / mean % | joint θ min / mean % | dipole array min / mean % |");
    println!("|---|---|---|---|");
    let row = |name: String, cfg: &PodConfig, learn: &[f64]| -> Rates {
        let r = run(cfg, learn, Trajectory::Seed);
        let f = |v: &[f64]| format!("{:.1} / {:.1}", 100.0 * min(v), 100.0 * mean(v));
        println!(
            "| {name} | {} | {} | {} |",
            f(&r.two_step),
            f(&r.joint),
            f(&r.dipole)
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
    let no_eddy = PodConfig {
        dipoles: base
            .dipoles
            .iter()
            .map(|d| aeromag_sim::scenario::pod::PodDipole {
                eddy_am2_s_per_nt: [[0.0; 3]; 3],
                ..d.clone()
            })
            .collect(),
        ..base.clone()
    };
    row("no eddy currents".into(), &no_eddy, &LEARNING_HEADINGS_DEG);
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
