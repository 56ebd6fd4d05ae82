//! The full-chain flight study of spec `em-positioning.md` ("What to show",
//! issue 6): ADC-level simulation → synchronous detection with pilot
//! correction → three-stage calibration → positioning, over a long flight
//! whose receiver gains and phases drift.
//!
//! [`run_flight_study`] is the one implementation used by the crate's tests,
//! by `aeromag em study` and by `aeromag demo`:
//!
//! 1. one 16 000-sample block (0.16 s at 100 kHz) at each of
//!    `calibration_epochs` times evenly spread over the flight, detected with
//!    pilot correction;
//! 2. [`Calibration::fit`]: stage 1 on all of them (no external
//!    information); stage 2 from the first `known_positions` epochs with
//!    their true positions; stage 3 from the first epoch's true attitude;
//! 3. at `evaluation_epochs` other times, detected with and without pilot
//!    correction: range error `(|r̂| − |r|)/|r|`, direction error
//!    `∠(r̂, r)` (deg), attitude error (rotation angle of `R̂ Rᵀ`, deg) and the
//!    polarisation ratio (minor/major axis of each dipole's field ellipse,
//!    dimensionless; 0 for a perfectly linear field) before calibration,
//!    after it, and after it without pilot correction.
//!
//! Summary figures are RMS over the evaluation epochs (and the three dipoles
//! for the ratios). [`curves`] gives the errors of the same chain versus range
//! and noise level.

pub mod curves;

pub use curves::{CurveConfig, CurvePoint, ErrorCurves, error_curves};

use crate::Result;
use crate::calibration::{Calibration, KnownPoints, uncalibrated};
use crate::detection::{Complex64, FieldChain, FieldEpoch};
use crate::error::EmError;
use crate::positioning::{Hemisphere, angle_between, rotation_angle_between};
use crate::sim::{EmScenario, EmSimConfig, synthesize};
use aeromag_core::filter::Window;
use nalgebra::Vector3;

/// Detector window `N` of the study, samples (0.16 s at 100 kHz; spec
/// `em-positioning.md`, 6.25 Hz output rate).
pub const STUDY_WINDOW_LEN: usize = 16_000;

/// Prior half-space of the study (bird behind and below the aircraft,
/// transmitter frame x forward, z down: `r · (−1, 0, 1) > 0`).
pub fn prior_hemisphere() -> Hemisphere {
    Hemisphere::new(Vector3::new(-1.0, 0.0, 1.0))
}

/// The detection chain of a scenario: the three-frequency plan of
/// [`crate::detection::DetectorConfig::three_frequency_plan`] with window [`STUDY_WINDOW_LEN`],
/// the scenario's coupling `χ`, coil gain and pilot field; pilot correction
/// on or off.
///
/// Errors if the scenario's frequency plan is rejected by the detector.
pub fn field_chain(sc: &EmScenario, use_pilot: bool) -> Result<FieldChain> {
    sc.system().chain(
        sc.config.sample_rate_hz,
        STUDY_WINDOW_LEN,
        Window::BlackmanHarris,
        use_pilot,
    )
}

/// Simulate `config` and detect it: the scenario and its field epochs.
///
/// Errors for an invalid configuration.
pub fn simulate_and_detect(
    config: EmSimConfig,
    use_pilot: bool,
) -> Result<(EmScenario, Vec<FieldEpoch>)> {
    let sc = EmScenario::new(config)?;
    let rec = synthesize(&sc)?;
    let ep = field_chain(&sc, use_pilot)?.process(&rec.samples, rec.header.start_index)?;
    Ok((sc, ep))
}

/// One detector block at each flight time of `times_s` (s): the scenario
/// (identical for every time: same seed) and the epochs in time order.
///
/// Errors if `times_s` is empty or the configuration is invalid.
pub fn epochs_at(
    base: &EmSimConfig,
    times_s: &[f64],
    use_pilot: bool,
) -> Result<(EmScenario, Vec<FieldEpoch>)> {
    let block_s = STUDY_WINDOW_LEN as f64 / base.sample_rate_hz;
    let mut out = Vec::with_capacity(times_s.len());
    let mut scenario = None;
    for &t in times_s {
        let cfg = EmSimConfig {
            start_time_s: t,
            duration_s: block_s,
            ..base.clone()
        };
        let (sc, ep) = simulate_and_detect(cfg, use_pilot)?;
        out.extend(ep);
        scenario = Some(sc);
    }
    let sc = scenario.ok_or_else(|| EmError::InvalidArgument {
        reason: "no epoch times".into(),
    })?;
    Ok((sc, out))
}

/// Root mean square `√(Σ v²/n)` (0 for an empty slice).
pub fn rms(v: &[f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

/// Sizes of the flight study.
#[derive(Debug, Clone, PartialEq)]
pub struct FlightStudyConfig {
    /// Flight length, s (the gain/phase drift period of the scenario is 5 h).
    pub flight_s: f64,
    /// Epochs for stage 1 (polarisation), spread over the flight (≥ 10).
    pub calibration_epochs: usize,
    /// Of those, the first ones with known position for stage 2 (≥ 4).
    pub known_positions: usize,
    /// Evaluation epochs at other times (≥ 1).
    pub evaluation_epochs: usize,
}

impl Default for FlightStudyConfig {
    /// The issue-6 study: 5 h, 120 calibration epochs, 40 known positions,
    /// 40 evaluation epochs.
    fn default() -> Self {
        Self {
            flight_s: 5.0 * 3600.0,
            calibration_epochs: 120,
            known_positions: 40,
            evaluation_epochs: 40,
        }
    }
}

impl FlightStudyConfig {
    /// A smaller study (same flight, 36 / 16 / 12 epochs) for quick demos.
    pub fn quick() -> Self {
        Self {
            calibration_epochs: 36,
            known_positions: 16,
            evaluation_epochs: 12,
            ..Self::default()
        }
    }
}

/// Results of [`run_flight_study`]. Errors and ratios are dimensionless
/// unless the name says `_deg`; the `*_series` vectors have one value per
/// evaluation epoch, aligned with `eval_time_s`.
#[derive(Debug, Clone, PartialEq)]
pub struct FlightStudy {
    /// RMS relative range error `(|r̂| − |r|)/|r|`.
    pub range_err_rel: f64,
    /// RMS direction error `∠(r̂, r)`, deg.
    pub angle_err_deg: f64,
    /// RMS attitude error (rotation angle between estimated and true), deg.
    pub attitude_err_deg: f64,
    /// RMS polarisation ratio before calibration (detection phases removed only).
    pub polarization_ratio_before: f64,
    /// RMS polarisation ratio after the stage-1 calibration, with pilot correction.
    pub polarization_ratio_after: f64,
    /// RMS polarisation ratio after calibration, detected without pilot correction.
    pub ratio_without_pilot: f64,
    /// Evaluation times, s from the start of the flight.
    pub eval_time_s: Vec<f64>,
    /// Relative range error per epoch (signed).
    pub range_err_series: Vec<f64>,
    /// Direction error per epoch, deg.
    pub angle_err_series_deg: Vec<f64>,
    /// Attitude error per epoch, deg.
    pub attitude_err_series_deg: Vec<f64>,
    /// True range per epoch, m.
    pub range_series_m: Vec<f64>,
    /// Polarisation ratio per epoch (RMS over the dipoles), before calibration.
    pub ratio_before_series: Vec<f64>,
    /// The same after calibration.
    pub ratio_after_series: Vec<f64>,
    /// The same after calibration, without pilot correction.
    pub ratio_without_pilot_series: Vec<f64>,
    /// The fitted calibration.
    pub calibration: Calibration,
}

/// Run the full-chain flight study (module docs) on the scenario `base`
/// (its `seed` draws every random element; `start_time_s`/`duration_s` are
/// replaced by the study's block times).
///
/// Errors for invalid sizes (`calibration_epochs < 10`, `known_positions`
/// outside `4..=calibration_epochs`, no evaluation epoch, non-positive
/// flight) or when a calibration stage fails.
pub fn run_flight_study(base: &EmSimConfig, study: &FlightStudyConfig) -> Result<FlightStudy> {
    if study.calibration_epochs < 10
        || study.known_positions < 4
        || study.known_positions > study.calibration_epochs
        || study.evaluation_epochs == 0
        || !crate::positive_finite(study.flight_s)
    {
        return Err(EmError::InvalidArgument {
            reason: format!("flight study sizes {study:?}"),
        });
    }
    let spread = |n: usize, offset: f64| -> Vec<f64> {
        (0..n)
            .map(|k| study.flight_s * (k as f64 + offset) / n as f64)
            .collect()
    };
    let cal_times = spread(study.calibration_epochs, 0.37);
    let eval_times = spread(study.evaluation_epochs, 0.81);
    let (sc, cal_ep) = epochs_at(base, &cal_times, true)?;
    let m = sc.config.moments_am2;
    let data: Vec<[[Complex64; 3]; 3]> = cal_ep.iter().map(|e| e.h).collect();

    // The three stages: stage 1 on every epoch, stage 2 from the first
    // `known_positions` true positions, stage 3 from the first true attitude.
    let known = KnownPoints {
        positions: cal_ep[..study.known_positions]
            .iter()
            .enumerate()
            .map(|(k, e)| (k, sc.pose_at(e.time_s).position_m))
            .collect(),
        attitudes: vec![(0, sc.pose_at(cal_ep[0].time_s).rotation)],
    };
    let cal = Calibration::fit(&data, &known, &m, &prior_hemisphere())?;
    let pol = cal.polarisation;

    // Evaluation, with and without pilot correction.
    let (_, with) = epochs_at(base, &eval_times, true)?;
    let (_, without) = epochs_at(base, &eval_times, false)?;
    let n = with.len();
    let mut out = FlightStudy {
        range_err_rel: 0.0,
        angle_err_deg: 0.0,
        attitude_err_deg: 0.0,
        polarization_ratio_before: 0.0,
        polarization_ratio_after: 0.0,
        ratio_without_pilot: 0.0,
        eval_time_s: Vec::with_capacity(n),
        range_err_series: Vec::with_capacity(n),
        angle_err_series_deg: Vec::with_capacity(n),
        attitude_err_series_deg: Vec::with_capacity(n),
        range_series_m: Vec::with_capacity(n),
        ratio_before_series: Vec::with_capacity(n),
        ratio_after_series: Vec::with_capacity(n),
        ratio_without_pilot_series: Vec::with_capacity(n),
        calibration: cal,
    };
    for (e, e_np) in with.iter().zip(&without) {
        let l = cal.locate(&e.h, &m, &mut prior_hemisphere())?;
        let t = sc.pose_at(e.time_s);
        out.eval_time_s.push(e.time_s);
        out.range_series_m.push(t.range_m());
        out.range_err_series
            .push((l.pose.range_m() - t.range_m()) / t.range_m());
        out.angle_err_series_deg
            .push(angle_between(&l.pose.position_m, &t.position_m).to_degrees());
        out.attitude_err_series_deg
            .push(rotation_angle_between(&l.pose.rotation, &t.rotation).to_degrees());
        out.ratio_before_series
            .push(rms(&uncalibrated(&e.h, &pol.phase_rad).1));
        out.ratio_after_series.push(rms(&l.polarisation_ratio));
        out.ratio_without_pilot_series
            .push(rms(&pol.apply(&e_np.h).1));
    }
    // Equal counts per epoch: the RMS of per-epoch RMS values is the RMS
    // over all epochs and dipoles.
    out.range_err_rel = rms(&out.range_err_series);
    out.angle_err_deg = rms(&out.angle_err_series_deg);
    out.attitude_err_deg = rms(&out.attitude_err_series_deg);
    out.polarization_ratio_before = rms(&out.ratio_before_series);
    out.polarization_ratio_after = rms(&out.ratio_after_series);
    out.ratio_without_pilot = rms(&out.ratio_without_pilot_series);
    Ok(out)
}
