//! Levelling on the simulator's `survey` scenario (spec `compensation.md`,
//! "Survey altitude"; seed `000_…` §9).
//!
//! The survey is compensated with the *true* aircraft interference
//! (`mag − true_interf`), corrected for the diurnal variation with the
//! base-station channel and reduced by the IGRF at the recorded position:
//! what is left at the crossovers is the scalar sensor's lag term
//! (`≈ −τ d|B|/dt`, so `k = −τ`), its heading error (a level that depends on
//! the line direction), the field difference between the altitudes of the
//! two passes, and noise. The test checks that the joint fit recovers
//! `k = −lag_s` within 10 % and reduces the RMS crossover difference at
//! least 5×.

use aeromag_compensation::levelling::{LevellingConfig, SurveyTracks, TrackConfig, level_survey};
use aeromag_sim::{ScenarioKind, simulate};

fn col<'a>(sim: &'a aeromag_sim::Simulation, name: &str) -> &'a [f64] {
    sim.column(name).unwrap_or_else(|| panic!("simulator column `{name}` missing"))
}

#[test]
fn survey_levelling_recovers_the_lag_coefficient() {
    let sim = simulate(ScenarioKind::Survey, None, Some(7)).expect("survey simulation");
    let lag_s = aeromag_sim::scenario::survey_defaults().scalar.lag_s;
    assert!(lag_s > 0.0);
    let n = sim.n_rows();
    let (mag, interf, diurnal, igrf) =
        (col(&sim, "mag"), col(&sim, "true_interf"), col(&sim, "diurnal"), col(&sim, "igrf"));
    let value: Vec<f64> = (0..n).map(|i| mag[i] - interf[i] - diurnal[i] - igrf[i]).collect();
    let tracks = SurveyTracks {
        time: col(&sim, "time"),
        lat: col(&sim, "lat"),
        lon: col(&sim, "lon"),
        alt: col(&sim, "alt"),
        line: col(&sim, "line"),
        value: &value,
    };
    let r = level_survey(&tracks, &TrackConfig::default(), &LevellingConfig::default()).expect("levelling");
    let f = &r.fit;
    eprintln!(
        "crossovers {} (skipped gap {}, missing {}, shallow {}); k = {:.5} ± {:.5} s (truth {}); RMS {:.4} → {:.4} nT; σ̂ {:.4} nT, κ {:.2e}",
        r.crossovers.crossovers.len(),
        r.crossovers.skipped_gap,
        r.crossovers.skipped_missing,
        r.crossovers.skipped_shallow,
        f.k_s,
        f.k_std_s,
        -lag_s,
        f.rms_before_nt,
        f.rms_after_nt,
        f.sigma_nt,
        f.condition
    );
    for l in &f.lines {
        eprintln!("  line {}: {} crossovers, offset {:+.4} ± {:.4} nT", l.label, l.crossovers, l.offset_nt, l.offset_std_nt);
    }
    // 12 lines × 3 ties.
    assert_eq!(r.crossovers.crossovers.len(), 36);
    assert!((f.k_s + lag_s).abs() <= 0.1 * lag_s, "k = {} s, truth {}", f.k_s, -lag_s);
    assert!(f.rms_after_nt * 5.0 <= f.rms_before_nt, "{} → {}", f.rms_before_nt, f.rms_after_nt);
    // Every row is kept.
    assert_eq!(r.levelled.value_nt.len(), n);
}
