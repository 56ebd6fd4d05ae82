//! Monte-Carlo efficiency RMS/CRLB of the pass estimator (multi-start,
//! re-linearised passes) on simulated well-posed passes: spec
//! `gradiometry.md` asks for ≤ 1.2 for position and moment, for the
//! stationary and the mobile system, tensor and scalar gradiometers. The
//! computation is the library's `efficiency::monte_carlo`; the bound is
//! computed from the noise-free truth, the estimator starts without it.

use aeromag_gradiometry::efficiency::{Efficiency, efficient_locate, monte_carlo, well_posed};
use aeromag_gradiometry::geometry::Layout;
use aeromag_gradiometry::sim::{Gradiometer, SystemMotion};

const TRIALS: usize = 100;

fn run(motion: SystemMotion, layout: Layout, gradiometer: Gradiometer, seed: u64) -> Efficiency {
    let s = well_posed(motion, layout).unwrap();
    let sigma = match gradiometer {
        Gradiometer::Tensor => s.vector_sensor.noise_nt,
        Gradiometer::Scalar => s.scalar_sensor.noise_nt,
    };
    let e = monte_carlo(
        &s,
        gradiometer,
        &efficient_locate(sigma).unwrap(),
        TRIALS,
        seed,
        2,
    )
    .unwrap();
    eprintln!(
        "{gradiometer:?} {motion:?} {layout:?}: RMS/CRLB position {:?}, moment {:.3}; per parameter {:?}",
        e.position.map(|p| (p * 1000.0).round() / 1000.0),
        e.moment,
        e.per_parameter
            .iter()
            .map(|p| (p * 1000.0).round() / 1000.0)
            .collect::<Vec<_>>()
    );
    assert_eq!(e.trials, TRIALS);
    e
}

/// ≤ 1.2 (the spec) and ≥ 0.8 (RMS well below the bound means a bug), for
/// each block and each parameter.
fn assert_efficient(e: &Efficiency) {
    for eta in e.position.iter().chain([&e.moment]).chain(&e.per_parameter) {
        assert!(
            (0.8..=1.2).contains(eta),
            "efficiency {eta} out of [0.8, 1.2]: {e:?}"
        );
    }
}

#[test]
fn tensor_stationary_system_is_efficient() {
    assert_efficient(&run(
        SystemMotion::Stationary,
        Layout::Tetrahedron,
        Gradiometer::Tensor,
        1000,
    ));
}

#[test]
fn tensor_mobile_system_is_efficient() {
    assert_efficient(&run(
        SystemMotion::Mobile,
        Layout::Tetrahedron,
        Gradiometer::Tensor,
        1000,
    ));
}

#[test]
fn scalar_system_moment_is_efficient() {
    for motion in [SystemMotion::Stationary, SystemMotion::Mobile] {
        let e = run(motion, Layout::Tetrahedron, Gradiometer::Scalar, 2000);
        assert!(e.position.is_none());
        assert_efficient(&e);
    }
}

#[test]
fn tensor_cross_and_planar_layouts_are_efficient() {
    for (motion, layout) in [
        (SystemMotion::Mobile, Layout::Cross),
        (SystemMotion::Stationary, Layout::Planar),
    ] {
        assert_efficient(&run(motion, layout, Gradiometer::Tensor, 1000));
    }
}
