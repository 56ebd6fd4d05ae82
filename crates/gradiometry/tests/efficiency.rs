//! Monte-Carlo efficiency RMS/CRLB of the square-root IEKF on simulated
//! passes (spec `gradiometry.md`: ≤ 1.2 in well-posed cases), and
//! convergence on a realistic pass (biases, variations, induced moment).

use aeromag_core::frames::Attitude;
use aeromag_gradiometry::crlb::{crlb, efficiency};
use aeromag_gradiometry::geometry::{Geometry, Layout};
use aeromag_gradiometry::motion::MotionNoise;
use aeromag_gradiometry::pass::{run_pass, run_pass_relinearised};
use aeromag_gradiometry::sim::{
    Processing, Scenario, SystemMotion, scalar_epochs, simulate, tensor_epochs,
};
use aeromag_gradiometry::sr_iekf::{IekfConfig, SrState};
use nalgebra::{SVector, Vector3};

const TRIALS: u64 = 100;

fn no_noise_model() -> Processing {
    Processing {
        quiet_epochs: 0,
        noise: MotionNoise {
            position_m_per_sqrt_s: 0.0,
            moment_am2_per_sqrt_s: 0.0,
            induced_per_rad: 0.0,
        },
        moment_scale_am2: 0.0,
    }
}

/// Well-posed case: no bias, constant heading, known motion, no natural
/// variations (they shift the direction of the total field, which the
/// scalar model takes from IGRF), a 20 m pass (range ≤ 12 m throughout, so
/// the signal is strong from the first epoch).
fn well_posed(motion: SystemMotion) -> Scenario {
    well_posed_with(motion, Layout::Tetrahedron)
}

fn well_posed_with(motion: SystemMotion, layout: Layout) -> Scenario {
    let g = Geometry::new(layout, 1.0).unwrap();
    let mut s = Scenario::new(motion, g);
    s.epochs = 100;
    s.variation_nt = 0.0;
    s.vector_sensor.bias_sigma_nt = 0.0;
    s.scalar_sensor.bias_sigma_nt = 0.0;
    s.object_yaw_rate_rad_s = 0.0;
    if motion == SystemMotion::Mobile {
        s.system_attitude = Attitude::from_degrees(3.0, -2.0, 10.0);
    }
    s
}

fn state6(r: &Vector3<f64>, m: &Vector3<f64>) -> SVector<f64, 6> {
    SVector::<f64, 6>::from([r.x, r.y, r.z, m.x, m.y, m.z])
}

fn tensor_efficiency(motion: SystemMotion) -> (f64, f64) {
    tensor_efficiency_with(motion, Layout::Tetrahedron)
}

fn tensor_efficiency_with(motion: SystemMotion, layout: Layout) -> (f64, f64) {
    let base = well_posed_with(motion, layout);
    let cfg = IekfConfig::new(base.vector_sensor.noise_nt).unwrap();
    let mut errors = Vec::new();
    let mut bound = None;
    for trial in 0..TRIALS {
        let s = Scenario {
            seed: 1000 + trial,
            ..base.clone()
        };
        let sim = simulate(&s).unwrap();
        let epochs = tensor_epochs(&sim, &s.geometry, &no_noise_model());
        if bound.is_none() {
            let truth: Vec<_> = sim
                .iter()
                .map(|e| state6(&e.true_position_m, &e.true_moment_am2))
                .collect();
            let models: Vec<_> = epochs.iter().map(|e| e.model).collect();
            let trans: Vec<_> = epochs.iter().map(|e| e.transition).collect();
            bound = Some(crlb(&models, &truth, &trans, s.vector_sensor.noise_nt).unwrap());
        }
        let first = &sim[0];
        // Position guess 1.6 m off; the moment from linear least squares at
        // that guess on the first epoch (closed form).
        let r0 = first.true_position_m + Vector3::new(1.0, -1.0, 0.5);
        let m0 = epochs[0]
            .model
            .moment_least_squares(&r0, &epochs[0].z)
            .unwrap();
        let x0 = state6(&r0, &m0);
        let prior = SrState::diagonal(
            x0,
            &SVector::<f64, 6>::from([20.0, 20.0, 20.0, 5000.0, 5000.0, 5000.0]),
        );
        let out = run_pass_relinearised(
            &prior,
            &epochs,
            &cfg,
            10,
            &SVector::<f64, 6>::from([0.3, 0.3, 0.3, 30.0, 30.0, 30.0]),
        )
        .unwrap();
        let last = sim.last().unwrap();
        errors.push(
            out.last().unwrap().posterior.x - state6(&last.true_position_m, &last.true_moment_am2),
        );
    }
    let b = bound.unwrap();
    (
        efficiency(&errors, &b, 0, 3).unwrap(),
        efficiency(&errors, &b, 3, 3).unwrap(),
    )
}

#[test]
fn tensor_stationary_system_is_efficient() {
    let (ep, em) = tensor_efficiency(SystemMotion::Stationary);
    eprintln!("tensor stationary: RMS/CRLB position {ep:.3}, moment {em:.3}");
    assert!(ep <= 1.2 && em <= 1.2);
    assert!(
        ep >= 0.8 && em >= 0.8,
        "RMS well below the bound means a bug"
    );
}

#[test]
fn tensor_mobile_system_is_efficient() {
    let (ep, em) = tensor_efficiency(SystemMotion::Mobile);
    eprintln!("tensor mobile: RMS/CRLB position {ep:.3}, moment {em:.3}");
    assert!(ep <= 1.2 && em <= 1.2);
    assert!(
        ep >= 0.8 && em >= 0.8,
        "RMS well below the bound means a bug"
    );
}

#[test]
fn scalar_system_moment_is_efficient() {
    for motion in [SystemMotion::Stationary, SystemMotion::Mobile] {
        let base = well_posed(motion);
        let cfg = IekfConfig::new(base.scalar_sensor.noise_nt).unwrap();
        let mut errors = Vec::new();
        let mut bound = None;
        for trial in 0..TRIALS {
            let s = Scenario {
                seed: 2000 + trial,
                ..base.clone()
            };
            let sim = simulate(&s).unwrap();
            let pos: Vec<_> = sim.iter().map(|e| e.true_position_m).collect();
            let epochs = scalar_epochs(&sim, &s.geometry, &pos, &no_noise_model()).unwrap();
            if bound.is_none() {
                let truth: Vec<_> = sim.iter().map(|e| e.true_moment_am2).collect();
                let models: Vec<_> = epochs.iter().map(|e| e.model).collect();
                let trans: Vec<_> = epochs.iter().map(|e| e.transition).collect();
                bound = Some(crlb(&models, &truth, &trans, s.scalar_sensor.noise_nt).unwrap());
            }
            let prior = SrState::diagonal(Vector3::zeros(), &Vector3::repeat(5000.0));
            let out = run_pass(&prior, &epochs, &cfg).unwrap();
            errors.push(out.last().unwrap().posterior.x - sim.last().unwrap().true_moment_am2);
        }
        let em = efficiency(&errors, &bound.unwrap(), 0, 3).unwrap();
        eprintln!("scalar {motion:?}: RMS/CRLB moment {em:.3}");
        assert!((0.8..=1.2).contains(&em), "{em}");
    }
}

#[test]
fn tensor_cross_and_planar_layouts_are_efficient() {
    for (motion, layout) in [
        (SystemMotion::Mobile, Layout::Cross),
        (SystemMotion::Stationary, Layout::Planar),
    ] {
        let (ep, em) = tensor_efficiency_with(motion, layout);
        eprintln!("tensor {motion:?} {layout:?}: RMS/CRLB position {ep:.3}, moment {em:.3}");
        assert!(ep <= 1.2 && em <= 1.2);
        assert!(
            ep >= 0.8 && em >= 0.8,
            "RMS well below the bound means a bug"
        );
    }
}
