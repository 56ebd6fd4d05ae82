//! The estimator on realistic simulated passes: per-sensor biases (removed
//! with quiet epochs), natural variations, Earth's field and gradient, an
//! object that yaws so its induced moment changes (not in the model).

use aeromag_gradiometry::convergence::multistart_epoch;
use aeromag_gradiometry::geometry::{Geometry, Layout};
use aeromag_gradiometry::motion::MotionNoise;
use aeromag_gradiometry::pass::{PassStep, run_pass};
use aeromag_gradiometry::sim::{
    Processing, Scenario, SystemMotion, scalar_epochs, simulate, tensor_epochs,
};
use aeromag_gradiometry::sr_iekf::{IekfConfig, SrState};
use nalgebra::{SVector, Vector3};

fn processing() -> Processing {
    Processing {
        quiet_epochs: 50,
        noise: MotionNoise {
            position_m_per_sqrt_s: 0.02,
            moment_am2_per_sqrt_s: 2.0,
            induced_per_rad: 1.0,
        },
        moment_scale_am2: 1500.0,
    }
}

fn scenario(motion: SystemMotion, layout: Layout) -> Scenario {
    let mut s = Scenario::new(motion, Geometry::new(layout, 1.0).unwrap());
    s.epochs = 600; // 120 m pass: the first 5 s are ≥ 50 m away (quiet)
    s
}

fn init_step(s: &SrState<6>) -> PassStep<6> {
    PassStep {
        posterior: *s,
        iterations: 0,
        converged: false,
        estimability: SVector::repeat(1.0),
        nis: f64::NAN,
    }
}

#[test]
fn tensor_filter_tracks_position_and_moment_over_realistic_passes() {
    for (motion, layout) in [
        (SystemMotion::Stationary, Layout::Tetrahedron),
        (SystemMotion::Mobile, Layout::Cross),
        (SystemMotion::Stationary, Layout::Planar),
    ] {
        let s = scenario(motion, layout);
        let sim = simulate(&s).unwrap();
        let epochs = tensor_epochs(&sim, &s.geometry, &processing());
        let cfg = IekfConfig::new(s.vector_sensor.noise_nt).unwrap();
        // Detection: the first epoch whose contrasts exceed 30 σ √9; start
        // there with the multi-start initialisation (no knowledge of the truth).
        let j0 = epochs
            .iter()
            .position(|e| e.z.norm() > 30.0 * 3.0 * cfg.sigma_nt)
            .unwrap();
        let init = multistart_epoch(&epochs[j0].model, &epochs[j0].z, &cfg, 20.0, 3000.0).unwrap();
        let mut out = vec![init_step(&init.posterior); j0 + 1];
        out.extend(run_pass(&init.posterior, &epochs[j0 + 1..], &cfg).unwrap());
        eprintln!(
            "detected at epoch {j0}, range {:.1} m",
            sim[j0].true_position_m.norm()
        );
        // Closest approach and 2 s after it.
        for j in [300, 320] {
            let e = &sim[j];
            let est = out[j].posterior.x;
            let dr = (est.fixed_rows::<3>(0) - e.true_position_m).norm();
            let dm = (est.fixed_rows::<3>(3) - e.true_moment_am2).norm() / e.true_moment_am2.norm();
            let mu = out[j].estimability;
            eprintln!(
                "{motion:?} {layout:?} epoch {j}: |dr| {dr:.3} m, |dM|/|M| {dm:.4}, μ {:?}",
                mu.as_slice()
            );
            assert!(dr < 0.1, "position error {dr}");
            assert!(dm < 0.05, "moment error {dm}");
            assert!(mu.iter().all(|&m| m < 0.1), "estimability {mu:?}");
        }
    }
}

#[test]
fn scalar_filter_recovers_the_moment_over_a_realistic_pass() {
    for motion in [SystemMotion::Stationary, SystemMotion::Mobile] {
        let s = scenario(motion, Layout::Tetrahedron);
        let sim = simulate(&s).unwrap();
        let pos: Vec<_> = sim.iter().map(|e| e.true_position_m).collect();
        let epochs = scalar_epochs(&sim, &s.geometry, &pos, &processing()).unwrap();
        let prior = SrState::diagonal(Vector3::zeros(), &Vector3::repeat(3000.0));
        let out = run_pass(
            &prior,
            &epochs,
            &IekfConfig::new(s.scalar_sensor.noise_nt).unwrap(),
        )
        .unwrap();
        for j in [300, 320] {
            let e = &sim[j];
            let dm = (out[j].posterior.x - e.true_moment_am2).norm() / e.true_moment_am2.norm();
            eprintln!(
                "scalar {motion:?} epoch {j}: |dM|/|M| {dm:.4}, μ {:?}",
                out[j].estimability.as_slice()
            );
            assert!(dm < 0.05, "moment error {dm}");
        }
    }
}
