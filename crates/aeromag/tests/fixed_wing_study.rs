//! The demo's fixed-wing study at full size (seed 1): the compensation,
//! geology, planning and levelling figures of the spec.

use aeromag::Silent;
use aeromag::studies::{FixedWingStudy, MapsStudy, Study, StudyOutcome, StudySize};

#[test]
fn the_fixed_wing_study_meets_the_compensation_figures() {
    let d = tempfile::tempdir().unwrap();
    let out = FixedWingStudy {
        seed: 1,
        out: d.path().to_path_buf(),
    }
    .run(StudySize::Full, &mut Silent)
    .unwrap();
    let s = out.summary();
    let c = &s.compensation;
    let g = |v: Option<f64>, k: &str| v.unwrap_or_else(|| panic!("compensation.{k}"));
    let (res, floor) = (
        g(c.residual_rms_ls_nt, "residual_rms_ls_nt"),
        g(c.noise_floor_nt, "noise_floor_nt"),
    );
    assert!(
        res <= 2.0 * floor,
        "residual {res} nT > 2 × noise floor {floor} nT"
    );
    let (ir, before, after) = (
        g(c.ir, "ir"),
        g(c.fom_before_nt, "fom_before_nt"),
        g(c.fom_after_nt, "fom_after_nt"),
    );
    assert!(ir >= 20.0, "IR {ir}");
    assert!(
        after < before / 20.0 && after <= 0.5,
        "FOM {before} → {after} nT"
    );
    for f in [
        "model_ls.json",
        "model_kalman.json",
        "survey_comp.csv",
        "calibration_comp.csv",
    ] {
        assert!(d.path().join(f).exists(), "{f}");
    }
    // The spec's figure (compensation.md, "Acceptance"): over the gradient
    // area (the box at 300 m, 8.8 nT/100 m expected there) the Kalman
    // method's survey residual is at most half of LS's; in the quiet box it
    // is not worse. Seed 1 measured: gradient area 0.0446 / 0.0138 nT,
    // quiet 0.0113 / 0.0113 nT. The interference model alone: quiet 1.6 /
    // 1.3, gradient area 42.8 / 8.4, mild area (1000 m, 1.0 nT/100 m) 4.3 /
    // 1.9, ×10⁻³ nT.
    let n = |v: Option<f64>| v.unwrap_or(f64::NAN);
    let grad = &s.compensation_gradient;
    assert!(
        n(grad.residual_rms_kalman_nt) <= 0.5 * n(grad.residual_rms_ls_nt),
        "{grad:?}"
    );
    assert!(
        n(c.residual_rms_kalman_nt) <= n(c.residual_rms_ls_nt),
        "{c:?}"
    );
    for area in [&s.compensation_gradient, &s.compensation_gradient_mild] {
        assert!(
            n(area.interference_rms_kalman_nt) < n(area.interference_rms_ls_nt),
            "{area:?}"
        );
        for v in [
            area.noise_floor_nt,
            area.calibration_altitude_m,
            area.expected_gradient_nt_per_100m,
        ] {
            assert!(v.is_some_and(f64::is_finite), "{area:?}");
        }
    }
    assert!(
        n(c.interference_rms_kalman_nt) <= n(c.interference_rms_ls_nt),
        "{c:?}"
    );
    // Planning: the truncated pattern is shorter and leaves every
    // coefficient estimable.
    let p = s.planning.as_ref().expect("planning in a full run");
    assert!(p.duration_truncated_s < p.duration_full_s, "{p:?}");
    assert_eq!(p.estimability_full.len(), 16);
    // Levelling of the compensated survey (seed 1's survey: k = −0.0986 ±
    // 0.0042 s measured, truth −0.1): k within 10 % and 3σ, and the classic
    // case (no base station) reduced more than 5×.
    let l = &s.levelling;
    assert_eq!(l.crossovers, 100);
    assert!(
        (l.k_s - l.k_true_s).abs() <= 0.1 * l.k_true_s.abs()
            && (l.k_s - l.k_true_s).abs() <= 3.0 * l.k_std_s,
        "{l:?}"
    );
    assert!(
        l.rms_before_no_base_station_nt >= 5.0 * l.rms_after_no_base_station_nt,
        "{l:?}"
    );
    // The report sections: summary, planning, calibration, Kalman, survey,
    // levelling.
    let headings: Vec<String> = out
        .sections()
        .unwrap()
        .into_iter()
        .map(|s| s.heading)
        .collect();
    assert_eq!(headings.len(), 6, "{headings:?}");

    // Maps of the same survey (issue 22's figures): the levelled grid
    // against the truth grid within 2× the along-line residual; the
    // derivative map's line-parallel corrugation ≥ 10× lower after
    // compensation.
    let maps = MapsStudy::of(&out, Some(d.path().to_path_buf()))
        .unwrap()
        .run(StudySize::Full, &mut Silent)
        .unwrap();
    let m = maps.summary();
    eprintln!("{m:?}");
    assert!(
        m.grid_rms_vs_truth_nt <= 2.0 * m.along_line_residual_nt,
        "{m:?}"
    );
    assert!(m.corrugation_reduction >= 10.0, "{m:?}");
    assert!(m.stripe_reduction_vs_truth >= 100.0, "{m:?}");
    // Micro-levelling on this survey follows the undersampled geology: it
    // raises the crossover differences of the levelled series (measured
    // 0.50 → 1.07 nT RMS) and the grid's error; the study reports it.
    let (x_before, x_after) = m.microlevel_crossover_rms_nt.expect("crossovers");
    assert!(x_after > 1.5 * x_before, "{m:?}");
    assert!(
        m.microlevelled_grid_rms_vs_truth_nt > m.grid_rms_vs_truth_nt,
        "{m:?}"
    );
    assert_eq!(maps.written().len(), 6);
    for f in maps.written() {
        assert!(f.exists(), "{}", f.display());
    }
    let section = maps.section().unwrap();
    assert_eq!(
        section
            .blocks
            .iter()
            .filter(|b| matches!(b, aeromag::report::Block::Figure { .. }))
            .count(),
        8
    );
}
