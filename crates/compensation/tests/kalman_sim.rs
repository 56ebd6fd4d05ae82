//! Method 2 (Kalman) against Method 1 (band-pass least squares) on the
//! simulator: calibrate on the calibration box (seed 7), compensate an
//! independent survey flight (seed 11), compare with the truth.
//!
//! Two survey figures, per survey/tie line with the line mean removed,
//! pooled: `residual` = RMS of `mag − interference − true_external` (what a
//! user gets; it also holds the sensor noise, 0.011 nT, and the heading
//! error), `interf` = RMS of `true_interf − interference` (the error of the
//! interference model alone). The survey is simulated without the scalar
//! sensor's 0.1 s lag: its `k·d|B0|/dt` term (0.16 nT RMS) belongs to the
//! levelling, not to the calibration, and would hide the difference.
//!
//! Spec acceptance (`compensation.md`): the Kalman residual at most half the
//! least-squares one when the calibration area has realistic anomaly
//! gradients, not worse in a quiet one. Measured here with the library
//! defaults (field order 6, fixed noise; interference error, Kalman / LS,
//! seeds 7–9): quiet 0.0143–0.0200 / 0.0185–0.0207 nT (0.77–0.97), the box
//! at 3 km over the realistic area the same to 10⁻⁴ nT; with the
//! base-station diurnal subtracted 0.0141–0.0144 / 0.0161–0.0163
//! (0.87–0.89). "Not worse" holds. "Half" is not to be had at 3 km: the
//! band-pass loses almost nothing to geology there (the anomaly has 2·10⁻⁴
//! nT RMS in 0.1–0.9 Hz in the quiet area, ten times that in the realistic
//! one), and the information the Kalman method adds — the low-frequency
//! part of the interference in turns and heading changes — is shared with
//! the field model, which must be flexible enough for the main field along
//! a curved path. With the external field known exactly, an unfiltered fit
//! reaches 0.0075 nT (the floor of the Tolles-Lawson model here) and the
//! Kalman fit with a rigid field model too (measured with the thesis' order
//! 3); with `q₁` at the value the true field needs, 0.014 nT. A calibration
//! area whose gradients reach the box is the demo's gradient area (the box
//! at 300 m, 8.8 nT/100 m there), where the spec's "half" is checked
//! (`crates/cli/tests/compensation.rs`, `demo_meets_the_compensation_figures`).
//!
//! These figures are for the classical 16 terms with the box at 3 km, fixed
//! noise intensities, and no lagged eddy terms. The CLI pipeline (lagged
//! eddy terms `l9`, lags chosen after a first Kalman pass has removed the
//! field, noise tuned by maximum likelihood, sensor altitude from the lever
//! arm, altitude cleaned of GNSS noise) is compared in
//! `crates/cli/tests/compensation.rs` (the `kalman_halves_…` tests), and
//! over seeds 1–5, altitudes 300 m–3 km and geology of 3, 10 and 30 nT/100 m
//! in the module docs of `kalman::tuning`: the Kalman method's
//! interference-model error is below LS in all 40 geology cases and at most
//! half of it in 37; in the quiet box it is below LS on all five seeds.

use aeromag_compensation::kalman::{
    KalmanConfig, KalmanFit, KalmanSegment, fit_kalman, ground_speed_from_velocity,
};
use aeromag_compensation::metrics::{LineLabel, residual_by_line};
use aeromag_compensation::tolles_lawson::Design;
use aeromag_compensation::tolles_lawson::TermSet;
use aeromag_compensation::tolles_lawson::fit_ls::{LsConfig, LsFit, Segment, fit_band_pass_ls};
use aeromag_compensation::tolles_lawson::segments::split_segments;
use aeromag_sim::{ScenarioKind, Simulation, simulate};
use std::ops::Range;

fn col<'a>(s: &'a Simulation, name: &str) -> &'a [f64] {
    s.column(name)
        .unwrap_or_else(|| panic!("simulator column {name}"))
}

struct Flight<'a> {
    sim: &'a Simulation,
    speed: Vec<f64>,
    /// The reading used (mag, or mag minus reference channels).
    mag: Vec<f64>,
}

impl<'a> Flight<'a> {
    fn new(sim: &'a Simulation) -> Self {
        Self {
            speed: ground_speed_from_velocity(col(sim, "vn"), col(sim, "ve")),
            mag: col(sim, "mag").to_vec(),
            sim,
        }
    }
    fn minus_diurnal(sim: &'a Simulation) -> Self {
        let mut f = Self::new(sim);
        f.mag = col(sim, "mag")
            .iter()
            .zip(col(sim, "diurnal"))
            .map(|(a, b)| a - b)
            .collect();
        f
    }
    fn usable(&self) -> Vec<bool> {
        vec![true; self.sim.n_rows()]
    }
    fn segment(&self, r: Range<usize>) -> Segment<'_> {
        let s = self.sim;
        Segment {
            time: &col(s, "time")[r.clone()],
            flux: [
                &col(s, "flux_x")[r.clone()],
                &col(s, "flux_y")[r.clone()],
                &col(s, "flux_z")[r.clone()],
            ],
            mag: &self.mag[r],
            channels: Default::default(),
            direction: None,
        }
    }
    fn kalman_segment(&self, r: Range<usize>) -> KalmanSegment<'_> {
        KalmanSegment {
            data: self.segment(r.clone()),
            alt_m: &col(self.sim, "alt")[r.clone()],
            speed_m_s: &self.speed[r],
        }
    }
    /// Legs split at line changes (the least-squares practice).
    fn legs(&self) -> Vec<Range<usize>> {
        split_segments(
            col(self.sim, "time"),
            Some(col(self.sim, "line")),
            &self.usable(),
            1.5,
            1,
        )
        .0
    }
    /// Contiguous stretches (split only at time gaps).
    fn contiguous(&self) -> Vec<Range<usize>> {
        split_segments(col(self.sim, "time"), None, &self.usable(), 1.5, 1).0
    }
}

fn ls_fit(cal: &Flight) -> LsFit {
    let legs = cal.legs();
    let segs: Vec<Segment> = legs.iter().map(|r| cal.segment(r.clone())).collect();
    fit_band_pass_ls(&segs, &LsConfig::default()).expect("LS fit")
}

fn kalman_fit(cal: &Flight, cfg: &KalmanConfig) -> KalmanFit {
    let runs = cal.contiguous();
    let segs: Vec<KalmanSegment> = runs.iter().map(|r| cal.kalman_segment(r.clone())).collect();
    fit_kalman(&segs, cfg).expect("Kalman fit")
}

/// Survey residuals of a coefficient set: (RMS of `mag − interference −
/// true_external`, RMS of `true_interf − interference`), per survey/tie line
/// with the line mean removed, pooled.
fn survey_error(survey: &Flight, coef: &[f64]) -> (f64, f64) {
    let s = survey.sim;
    let line = col(s, "line");
    let terms = TermSet::observable16();
    let n = s.n_rows();
    let mut model = vec![f64::NAN; n];
    let legs: Vec<Range<usize>> = survey
        .legs()
        .into_iter()
        .filter(|r| line[r.start] != 0.0)
        .collect();
    for r in &legs {
        let seg = survey.segment(r.clone());
        let a = Design::new(terms.clone()).interference(coef, seg.time, seg.flux);
        model[r.clone()].copy_from_slice(&a);
    }
    let mag = col(s, "mag");
    let comp: Vec<f64> = (0..n).map(|i| mag[i] - model[i]).collect();
    let of = |i: usize| LineLabel::Number(line[i]);
    let (_, total) = residual_by_line(&comp, col(s, "true_external"), &of, &legs);
    let (_, interf) = residual_by_line(col(s, "true_interf"), &model, &of, &legs);
    (total, interf)
}

const REALISTIC: &str = "[anomaly]\narea = \"realistic\"\n";
const SURVEY_NO_LAG: &str = "[scalar]\nlag_s = 0.0\n";

/// (LS residual, LS interf, Kalman residual, Kalman interf) for a
/// calibration scenario file; `base_station` subtracts the `diurnal` channel.
fn compare(cal_toml: Option<&str>, base_station: bool, seed: u64) -> [f64; 4] {
    let survey_sim = simulate(ScenarioKind::Survey, Some(SURVEY_NO_LAG), Some(11)).unwrap();
    let survey = Flight::new(&survey_sim);
    let cal_sim = simulate(ScenarioKind::Calibration, cal_toml, Some(seed)).unwrap();
    let cal = if base_station {
        Flight::minus_diurnal(&cal_sim)
    } else {
        Flight::new(&cal_sim)
    };
    let ls = ls_fit(&cal);
    let kf = kalman_fit(&cal, &KalmanConfig::default());
    let (a, b) = survey_error(&survey, &ls.coef);
    let (c, d) = survey_error(&survey, &kf.coef);
    println!(
        "calibration {:?} base station {base_station} seed {seed}: LS residual {a:.4} interf {b:.4}; Kalman residual {c:.4} interf {d:.4} (ratio {:.2}); NIV {:.2}",
        cal_toml.unwrap_or("default (quiet)"),
        d / b,
        kf.normalized_innovation_variance
    );
    [a, b, c, d]
}

/// Assert that the Kalman method's survey residual and interference error
/// (`[ls_res, ls_int, kf_res, kf_int]` of [`compare`]) are below LS
/// (`strict`) or not above it.
fn kalman_ahead([ls_res, ls_int, kf_res, kf_int]: [f64; 4], strict: bool) {
    let ok = |k: f64, l: f64| if strict { k < l } else { k <= l };
    assert!(
        ok(kf_res, ls_res),
        "survey residual: Kalman {kf_res} nT, LS {ls_res} nT"
    );
    assert!(
        ok(kf_int, ls_int),
        "interference error: Kalman {kf_int} nT, LS {ls_int} nT"
    );
}

#[test]
fn kalman_is_not_worse_than_least_squares_in_a_quiet_area() {
    kalman_ahead(compare(None, false, 7), false);
}

#[test]
fn kalman_is_better_than_least_squares_in_a_realistic_area() {
    kalman_ahead(compare(Some(REALISTIC), false, 7), true);
}

#[test]
fn kalman_is_better_than_least_squares_with_the_base_station_subtracted() {
    kalman_ahead(compare(Some(REALISTIC), true, 8), true);
}

/// The comparison over seeds, areas and references (prints a table; run
/// with `--ignored --nocapture`).
#[test]
#[ignore = "report, not a check"]
fn comparison_table() {
    for seed in [7u64, 8, 9] {
        for toml in [None, Some(REALISTIC)] {
            for base in [false, true] {
                compare(toml, base, seed);
            }
        }
    }
}
