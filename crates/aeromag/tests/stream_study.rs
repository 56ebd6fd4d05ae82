//! Issue 21's figures on simulated flights with truth: the causal path
//! costs at most 5 % of the batch residual; over a 5-hour flight whose
//! aircraft magnetisation creeps, the adaptive Kalman filter's residual at
//! the end stays within 1.5× the start, where the fixed model degrades.

use aeromag::Silent;
use aeromag::studies::{StreamStudy, Study, StudyOutcome, StudySize};

#[test]
fn causal_costs_little_and_the_adaptive_filter_does_not_drift_over_five_hours() {
    let outcome = StreamStudy { seed: 1 }
        .run(StudySize::Quick, &mut Silent)
        .unwrap();
    let s = outcome.summary();
    eprintln!("{s:#?}");
    assert!(s.creep_hours >= 5.0, "{} h", s.creep_hours);
    assert!(s.causal_over_batch <= 1.05, "{}", s.causal_over_batch);
    assert!(
        s.adaptive_end_over_start <= 1.5,
        "adaptive {} → {} nT",
        s.adaptive_start_nt,
        s.adaptive_end_nt
    );
    // The model held fixed degrades: the creep is seen.
    assert!(
        s.fixed_end_over_start >= 3.0,
        "fixed {} → {} nT",
        s.fixed_start_nt,
        s.fixed_end_nt
    );
    // And the adaptive filter ends well below the fixed model.
    assert!(s.adaptive_end_nt < 0.25 * s.fixed_end_nt);
    let sec = outcome.section().unwrap();
    assert!(sec.heading.contains("On board"));
    assert_eq!(sec.blocks.len(), 4);
    permanent_coefficients_follow_the_creep(&outcome);
}

/// The permanent coefficients follow the creep: their change over the
/// flight is the creeping moment's dipole field at the sensor times the
/// hours flown (the simulator's truth, `crates/sim/tests/creep.rs`: 17 nT
/// along x, 3.6 along y), and their standard deviations stay bounded
/// (measured, seed 1: p_x 16.80 against 16.71 nT, σ 0.17; p_y −3.80
/// against −3.61, σ 0.10; p_z 0.64 against −0.05, σ 0.23).
fn permanent_coefficients_follow_the_creep(outcome: &aeromag::studies::StreamOutcome) {
    use aeromag::studies::CREEP_AM2_PER_H;
    use aeromag_core::field::dipole::dipole_matrix;
    use nalgebra::Vector3;
    let snaps = &outcome.kalman().snapshots;
    let (first, last) = (&snaps[0], &snaps[snaps.len() - 1]);
    let hours = (last.time_s - first.time_s) / 3600.0;
    // The stinger sensor and the left engine (the default aircraft).
    let r = Vector3::new(-9.5, 0.0, -0.6) - Vector3::new(1.0, -3.2, 0.2);
    let want = dipole_matrix(&r) * Vector3::from(CREEP_AM2_PER_H) * 1e9 * hours;
    let names = outcome.model().design.column_names();
    for (axis, name) in ["p_x", "p_y", "p_z"].iter().enumerate() {
        let k = names.iter().position(|n| n == name).unwrap();
        let got = last.values[k] - first.values[k];
        eprintln!(
            "{name}: {got:.3} nT, truth {:.3} nT, σ {:.3} → {:.3}",
            want[axis], first.std[k], last.std[k]
        );
        if *name == "p_z" {
            // In level flight the field's z direction cosine is nearly
            // constant, so p_z trades against the field's level: it must
            // stay put (the creep moves it by 0.05 nT), not follow.
            assert!(
                (got - want[axis]).abs() < 1.0,
                "{name}: {got} vs {}",
                want[axis]
            );
        } else {
            // Within three of the filter's own standard deviations: the
            // estimate follows the truth and its σ is honest.
            assert!(
                (got - want[axis]).abs() < 3.0 * last.std[k],
                "{name}: {got} vs {} (σ {})",
                want[axis],
                last.std[k]
            );
        }
        assert!(last.std[k] < 0.1 * want.norm(), "{name}: σ {}", last.std[k]);
    }
}
