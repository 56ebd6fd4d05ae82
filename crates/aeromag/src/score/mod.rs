//! Scoring a compensated flight: figure of merit, improvement ratio and —
//! for simulated data — the residual against the truth; and the report
//! section that shows them (`aeromag report`, the demo).
//!
//! Input is a flight table with `time`, `mag` and `mag_comp` (as written by
//! `aeromag compensate`), optionally `mag_interf`, attitude (`roll`,
//! `pitch`, `yaw`, for the FOM windows), `line`, and — for simulated data —
//! the truth columns `true_external`, `true_interf`, `true_lag`,
//! `true_mag_noise`. Truth is used only to *score* results, never to
//! compute them.

mod section;

use crate::error::Result;
use crate::flight::{Flight, LeverArm, SegmentRule, reduced, reference_sum};
use aeromag_compensation::metrics::{
    FomReport, LineResidual, ManeuverDetection, band_pass_segments, detect_maneuvers,
    figure_of_merit, improvement_ratio, residual_by_line,
};
use aeromag_compensation::tolles_lawson::segments::median_step;
use aeromag_core::filter::BandPass;
use serde::Serialize;
use std::ops::Range;

/// The columns [`score`] and the report section read besides the canonical
/// ones and the reference channels (for a lazy read, as patterns of
/// [`Fields::Only`](aeromag_io::Fields::Only)): the compensated and
/// modelled signal, simulation truth, and the levelling columns of
/// `aeromag level`.
pub const SCORED_COLUMNS: [&str; 5] = [
    "mag_comp",
    "mag_interf",
    "true_*",
    crate::level::LEVEL_FLAG,
    "*_level",
];

/// The figures of one compensated flight.
#[derive(Debug, Clone, Serialize)]
pub struct Figures {
    /// FOM of the uncompensated signal over the detected manoeuvres, nT.
    pub fom_before_nt: Option<f64>,
    /// FOM of the compensated signal, nT.
    pub fom_after_nt: Option<f64>,
    /// Manoeuvre windows found.
    pub fom_windows: usize,
    /// Improvement ratio.
    pub ir: Option<f64>,
    /// Pooled per-line RMS of compensated − (true external + true lag), nT
    /// (simulation only).
    pub residual_rms_nt: Option<f64>,
    /// Pooled per-line RMS of `true_interf − mag_interf`, nT: the error of the
    /// interference model alone, the spec's "coefficient error versus truth,
    /// in nT of effect" (simulation only; needs `mag_interf`).
    pub interference_rms_nt: Option<f64>,
    /// Scalar sensor noise floor, RMS of `true_mag_noise`, nT (simulation only).
    pub noise_floor_nt: Option<f64>,
    /// Per-line residuals (simulation only).
    pub lines: Vec<LineResidual>,
    /// The FOM windows of the uncompensated signal.
    #[serde(skip)]
    pub fom_before: Option<FomReport>,
    /// The FOM windows of the compensated signal.
    #[serde(skip)]
    pub fom_after: Option<FomReport>,
}

/// Segments of rows where `mag` and `mag_comp` are finite, split at lines
/// and gaps, of at least 2 rows.
fn segments(t: &Flight, comp: &[f64]) -> Result<Vec<Range<usize>>> {
    let time = t.require("time")?;
    let mag = t.require("mag")?;
    let usable: Vec<bool> = (0..time.len())
        .map(|i| mag[i].is_finite() && comp[i].is_finite())
        .collect();
    Ok(SegmentRule::default()
        .min_len(2)
        .split(time, t.column("line"), &usable)
        .kept)
}

/// The figures of a compensated flight (columns `time`, `mag`, `mag_comp`;
/// optionally `mag_interf`, the attitude, `line` and the truth columns).
///
/// FOM and IR are computed on the readings reduced by the `reference`
/// channels (known external field: base station, IGRF) and band-passed with
/// the default compensation band (0.1–0.9 Hz, order 4) leg by leg, so they
/// measure the aircraft's interference, not the geology or the diurnal
/// variation. The residual versus truth is pooled over survey lines: rows
/// whose `line` label is 0 (turns, in the simulator's convention) are not
/// survey data and are left out. With a lever arm the `igrf` reference is
/// moved to the sensor ([`reference_sum`]).
///
/// Truth columns are read only to score, never to compute a result.
///
/// ```
/// use aeromag::prelude::*;
/// use aeromag::score::score;
/// use aeromag::simulate::{ScenarioKind, simulate_flight};
/// let cal = simulate_flight(ScenarioKind::Calibration, None, Some(1))?;
/// let model = calibrate(&cal, &CalibrateOptions::default(), &mut Silent)?.model;
/// let flight = model.compensate(&cal)?.into_flight(cal)?;
/// let figures = score(&flight, &[], None)?;
/// assert!(figures.ir.unwrap() > 1.0); // the compensation helps
/// println!("FOM {:?} → {:?} nT", figures.fom_before_nt, figures.fom_after_nt);
/// # Ok::<(), aeromag::Error>(())
/// ```
pub fn score(t: &Flight, reference: &[String], lever: Option<&LeverArm>) -> Result<Figures> {
    let time = t.require("time")?;
    let ref_sum = reference_sum(t, reference, lever)?;
    let mag = reduced(t.require("mag")?, &ref_sum);
    let comp_raw = t.require("mag_comp")?;
    let comp = reduced(comp_raw, &ref_sum);
    let segs = segments(t, &comp)?;
    let fs = 1.0 / median_step(time);
    let bpf = BandPass::compensation_default(fs)?;
    let ir = improvement_ratio(&mag, &comp, &segs, &bpf)?;
    let (mut fom_before, mut fom_after) = (None, None);
    let mut fom_windows = 0;
    if let (Some(r), Some(p), Some(y)) = (t.column("roll"), t.column("pitch"), t.column("yaw")) {
        let windows = detect_maneuvers(time, r, p, y, &ManeuverDetection::default());
        if !windows.is_empty() {
            fom_windows = windows.len();
            fom_before = Some(figure_of_merit(
                time,
                &band_pass_segments(&mag, &segs, &bpf)?,
                &windows,
            ));
            fom_after = Some(figure_of_merit(
                time,
                &band_pass_segments(&comp, &segs, &bpf)?,
                &windows,
            ));
        }
    }
    let (mut residual_rms_nt, mut lines, mut noise_floor_nt) = (None, Vec::new(), None);
    let on_line: Vec<Range<usize>> = match t.column("line") {
        Some(l) => segs.iter().filter(|r| l[r.start] != 0.0).cloned().collect(),
        None => segs.clone(),
    };
    let interference_rms_nt = match (t.column("true_interf"), t.column("mag_interf")) {
        (Some(truth), Some(model)) => {
            let (_, pooled) = residual_by_line(model, truth, t.column("line"), &on_line);
            pooled.is_finite().then_some(pooled)
        }
        _ => None,
    };
    if let Some(ext) = t.column("true_external") {
        // The sensor lag is not aircraft interference: levelling handles it.
        let truth: Vec<f64> = match t.column("true_lag") {
            Some(lag) => ext.iter().zip(lag).map(|(e, l)| e + l).collect(),
            None => ext.to_vec(),
        };
        let (l, pooled) = residual_by_line(comp_raw, &truth, t.column("line"), &on_line);
        residual_rms_nt = pooled.is_finite().then_some(pooled);
        lines = l;
    }
    if let Some(noise) = t.column("true_mag_noise") {
        let v: Vec<f64> = noise.iter().copied().filter(|v| v.is_finite()).collect();
        noise_floor_nt =
            Some((v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64).sqrt());
    }
    Ok(Figures {
        fom_before_nt: fom_before.as_ref().map(|f: &FomReport| f.fom_nt),
        fom_after_nt: fom_after.as_ref().map(|f: &FomReport| f.fom_nt),
        fom_windows,
        ir,
        residual_rms_nt,
        interference_rms_nt,
        noise_floor_nt,
        lines,
        fom_before,
        fom_after,
    })
}
