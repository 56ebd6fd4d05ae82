//! Levelling on the simulator's `survey` scenario (spec `compensation.md`,
//! "Survey altitude"; seed `000_…` §9).
//!
//! The survey is compensated with the *true* aircraft interference
//! (`mag − true_interf`: this isolates levelling from the quality of a
//! Tolles-Lawson fit) and reduced by the IGRF at the recorded position.
//! Crossovers are computed at the scalar sensor's positions (lever arm from
//! the simulator's defaults). The truth `k` is `−lag_s` of the scalar sensor
//! (the simulator records `true_lag ≈ −τ d|B|/dt`).
//!
//! What remains at the crossovers after the base-station diurnal correction:
//! the lag term (levellable through `k`), the heading error (a level per line
//! direction), and — not levellable — the anomaly difference between the
//! altitudes of the two passes (turbulence: ±7 m RMS), the IGRF evaluated at
//! the recorded rather than the true position, and noise. (The lag of the
//! interference itself is levellable too: the regressor is the derivative
//! of the uncompensated `mag`, [`SurveyTracks::sensed`].) The altitude term (on by default) models the anomaly
//! difference from the vertical gradient of the two profiles, so the model
//! residual goes below that floor. On the default survey (20 lines × 5
//! ties, 100 crossovers) the tests check that levelling reduces the
//! crossover RMS ≥ 3× below the floor and recovers `k` within 10 % and
//! within 3σ (σ ≈ 4 %), that a larger block (576 crossovers) does so too,
//! and that the classic levelling error — a diurnal variation left
//! uncorrected — is reduced far more than 5×.

use aeromag_compensation::levelling::{
    Crossover, CrossoverSide, LevellingConfig, RowFlag, SurveyLevelling, SurveyTracks, TrackConfig,
    level_survey, sensor_positions,
};
use aeromag_sim::{ScenarioKind, Simulation, simulate};

fn col<'a>(sim: &'a Simulation, name: &str) -> &'a [f64] {
    sim.column(name)
        .unwrap_or_else(|| panic!("simulator column `{name}` missing"))
}

/// Positions `[lat, lon, alt]` of the scalar sensor (the simulator's lever arm).
fn sensor_track(sim: &Simulation) -> [Vec<f64>; 3] {
    let lever = aeromag_sim::scenario::survey_defaults().scalar.position_m;
    let c = |name| col(sim, name);
    sensor_positions(
        c("lat"),
        c("lon"),
        c("alt"),
        c("roll"),
        c("pitch"),
        c("yaw"),
        lever,
    )
    .expect("sensor positions")
}

/// Simulate, compensate with the true interference, optionally correct the
/// diurnal variation with the base station, and level.
fn run(
    toml: Option<&str>,
    seed: u64,
    diurnal: bool,
    cfg: &LevellingConfig,
) -> (Simulation, Vec<f64>, SurveyLevelling) {
    let sim = simulate(ScenarioKind::Survey, toml, Some(seed)).expect("survey simulation");
    let n = sim.n_rows();
    let (mag, interf, base, igrf) = (
        col(&sim, "mag"),
        col(&sim, "true_interf"),
        col(&sim, "diurnal"),
        col(&sim, "igrf"),
    );
    let value: Vec<f64> = (0..n)
        .map(|i| mag[i] - interf[i] - igrf[i] - if diurnal { base[i] } else { 0.0 })
        .collect();
    let [lat, lon, alt] = sensor_track(&sim);
    let tracks = SurveyTracks {
        time: col(&sim, "time"),
        lat: &lat,
        lon: &lon,
        alt: &alt,
        line: col(&sim, "line"),
        value: &value,
        sensed: Some(mag),
    };
    let r = level_survey(&tracks, &TrackConfig::default(), cfg).expect("levelling");
    let f = &r.fit;
    eprintln!(
        "{} crossovers (skipped: gap {}, missing {}, shallow {}); k = {:+.4} ± {:.4} s; RMS {:.4} → {:.4} nT ({:.1}×); σ̂ {:.4} nT; κ {:.1e}",
        r.crossovers.crossovers.len(),
        r.crossovers.skipped_gap,
        r.crossovers.skipped_missing,
        r.crossovers.skipped_shallow,
        f.k_s,
        f.k_std_s,
        f.rms_before_nt,
        f.rms_after_nt,
        f.rms_before_nt / f.rms_after_nt,
        f.sigma_nt,
        f.condition
    );
    assert_eq!(r.levelled.value_nt.len(), n, "every row is kept");
    (sim, value, r)
}

fn true_k() -> f64 {
    -aeromag_sim::scenario::survey_defaults().scalar.lag_s
}

/// A truth column interpolated at one side of a crossover (consecutive rows:
/// the simulator's positions are never missing).
fn at(x: &[f64], s: &CrossoverSide) -> f64 {
    x[s.row] + s.fraction * (x[s.row + 1] - x[s.row])
}

/// RMS over the crossovers of what levelling cannot remove: the difference
/// minus its lag and heading-error parts (truth columns).
fn floor_rms(sim: &Simulation, xs: &[Crossover]) -> f64 {
    let (lag, head) = (col(sim, "true_lag"), col(sim, "true_heading_error"));
    let s2: f64 = xs
        .iter()
        .map(|x| {
            let e = x.difference_nt()
                - (at(lag, &x.a) - at(lag, &x.b))
                - (at(head, &x.a) - at(head, &x.b));
            e * e
        })
        .sum();
    (s2 / xs.len() as f64).sqrt()
}

/// RMS about its mean of `v − true_anomaly` over the levelled rows.
fn rms_vs_anomaly(sim: &Simulation, r: &SurveyLevelling, v: &[f64]) -> f64 {
    let anom = col(sim, "true_anomaly");
    let rows: Vec<usize> = (0..v.len())
        .filter(|&i| r.levelled.flag[i] == RowFlag::Levelled)
        .collect();
    let m = rows.iter().map(|&i| v[i] - anom[i]).sum::<f64>() / rows.len() as f64;
    (rows
        .iter()
        .map(|&i| (v[i] - anom[i] - m).powi(2))
        .sum::<f64>()
        / rows.len() as f64)
        .sqrt()
}

#[test]
fn default_survey_goes_below_the_floor_and_recovers_k_within_ten_percent() {
    let (sim, value, r) = run(None, 7, true, &LevellingConfig::default());
    let f = &r.fit;
    assert_eq!(r.crossovers.crossovers.len(), 100, "20 lines × 5 ties");
    let floor = floor_rms(&sim, &r.crossovers.crossovers);
    let (before, after) = (
        rms_vs_anomaly(&sim, &r, &value),
        rms_vs_anomaly(&sim, &r, &r.levelled.value_nt),
    );
    eprintln!("floor {floor:.4} nT; vs true anomaly {before:.4} → {after:.4} nT");
    assert!(
        (f.k_s - true_k()).abs() <= 3.0 * f.k_std_s,
        "k = {} ± {}",
        f.k_s,
        f.k_std_s
    );
    assert!(f.k_std_s < 0.1 * true_k().abs(), "σ_k {}", f.k_std_s);
    assert!(
        (f.k_s - true_k()).abs() <= 0.1 * true_k().abs(),
        "k = {}",
        f.k_s
    );
    // Everything levellable is removed and the altitude term takes out
    // part of the height differences: what is left is below the floor.
    assert!(
        f.rms_after_nt <= floor,
        "{} > floor {floor}",
        f.rms_after_nt
    );
    assert!(f.rms_before_nt > 3.0 * f.rms_after_nt);
    // And the levelled data are closer to the true anomaly.
    assert!(after < 0.75 * before, "{before} → {after}");
}

#[test]
fn larger_block_recovers_k_within_ten_percent() {
    // 24 lines × 24 ties, 400 m apart both ways (the default 10 km lines).
    let toml = "[pattern]\nline_count = 24\ntie_count = 24\ntie_spacing_m = 400.0\n";
    let (sim, _, r) = run(Some(toml), 7, true, &LevellingConfig::default());
    let f = &r.fit;
    assert!(
        r.crossovers.crossovers.len() >= 570,
        "{}",
        r.crossovers.crossovers.len()
    );
    let k = true_k();
    assert!(
        (f.k_s - k).abs() <= 0.1 * k.abs(),
        "k = {} ± {}, truth {k}",
        f.k_s,
        f.k_std_s
    );
    assert!(
        (f.k_s - k).abs() <= 3.0 * f.k_std_s,
        "k = {} ± {}",
        f.k_s,
        f.k_std_s
    );
    assert!(f.rms_after_nt <= floor_rms(&sim, &r.crossovers.crossovers));
}

#[test]
fn uncorrected_diurnal_is_levelled_out() {
    // No base-station correction: the lines carry the diurnal drift (20 nT/h
    // RMS) as offsets and slopes; levelling with a drift per line removes it.
    let cfg = LevellingConfig {
        drift: true,
        ..LevellingConfig::default()
    };
    let (sim, value, r) = run(None, 7, false, &cfg);
    let f = &r.fit;
    assert!(
        f.rms_before_nt >= 5.0 * f.rms_after_nt,
        "{} → {}",
        f.rms_before_nt,
        f.rms_after_nt
    );
    // Offsets alone leave much more (the diurnal changes along a line).
    let off = level_survey_offsets_only(&sim, &value);
    assert!(
        off > 2.0 * f.rms_after_nt,
        "offsets only {off}, with drift {}",
        f.rms_after_nt
    );
}

/// Plain tie-line levelling (k = 0, offsets only) of `value`: the RMS after.
fn level_survey_offsets_only(sim: &Simulation, value: &[f64]) -> f64 {
    let [lat, lon, alt] = sensor_track(sim);
    let tracks = SurveyTracks {
        time: col(sim, "time"),
        lat: &lat,
        lon: &lon,
        alt: &alt,
        line: col(sim, "line"),
        value,
        sensed: None,
    };
    let cfg = LevellingConfig {
        estimate_k: false,
        ..LevellingConfig::default()
    };
    let r = level_survey(&tracks, &TrackConfig::default(), &cfg).unwrap();
    eprintln!(
        "offsets only: RMS {:.4} → {:.4} nT",
        r.fit.rms_before_nt, r.fit.rms_after_nt
    );
    r.fit.rms_after_nt
}
