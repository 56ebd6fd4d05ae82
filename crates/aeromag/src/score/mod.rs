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
mod sensors;

pub use sensors::{
    ChannelCorrelation, GroupRms, SensorScore, SensorsFigures, channel_correlations, score_sensors,
};

use crate::error::{Error, Result};
use crate::flight::{Flight, LeverArm, SegmentRule, reduced, reference_sum};
use aeromag_compensation::metrics::{
    FomReport, LineLabel, LineResidual, ManeuverDetection, band_pass_segments, detect_maneuvers,
    figure_of_merit, improvement_ratio, residual_by_line,
};
use aeromag_compensation::tolles_lawson::segments::median_step;
use aeromag_core::error::{fixed, shown};
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

/// The series of one scored sensor (nT per row of the flight): what
/// [`score_series`] and the report section read. [`SensorSeries::of`] takes
/// the single-sensor columns of `aeromag compensate` (`mag`, `mag_comp`,
/// `mag_interf`, `true_…`); [`score_sensors`] builds one per sensor of a
/// multi-sensor model.
#[derive(Debug, Clone, Copy)]
pub struct SensorSeries<'a> {
    /// The uncompensated reading.
    pub mag: &'a [f64],
    /// The compensated reading.
    pub comp: &'a [f64],
    /// The modelled interference, when written.
    pub interf: Option<&'a [f64]>,
    /// Simulation truth, used only to score.
    pub truth: SensorTruth<'a>,
}

/// The simulator's truth of one scalar sensor (every series optional).
#[derive(Debug, Clone, Copy, Default)]
pub struct SensorTruth<'a> {
    /// The external field at the sensor (`true_external`).
    pub external: Option<&'a [f64]>,
    /// The sensor's time-lag term (`true_lag`), not aircraft interference.
    pub lag: Option<&'a [f64]>,
    /// The aircraft interference at the sensor (`true_interf`).
    pub interf: Option<&'a [f64]>,
    /// The sensor's white noise (`true_mag_noise`).
    pub noise: Option<&'a [f64]>,
}

/// A compensated reading of another processing that the file holds under
/// its own name, any case (SGL's `COMPMAG1`, MagNav's `mag_1_c`): named
/// when `mag_comp` is missing.
fn other_compensated(t: &Flight) -> Option<String> {
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    let table = t.table();
    table
        .column_names()
        .into_iter()
        .chain(table.unread_columns())
        .find(|name| {
            let l = name.to_ascii_lowercase();
            l.strip_prefix("compmag").is_some_and(digits)
                || l.strip_prefix("mag_")
                    .and_then(|r| r.strip_suffix("_c"))
                    .is_some_and(digits)
        })
        .map(str::to_string)
}

/// The error of a missing `mag_comp` in a file that holds `name`, a
/// compensated reading of another processing.
fn missing_comp(t: &Flight, name: &str) -> Error {
    Error::BadInput {
        file: Some(t.file_label()),
        line: None,
        row: None,
        column: Some("mag_comp".into()),
        reason: format!(
            "required column 'mag_comp' is missing; the file has '{name}', a reading compensated by another processing: map it to score that compensation (--columns mag_comp={name}), or compensate the flight with `aeromag compensate` (which writes mag_comp)"
        ),
    }
}

impl<'a> SensorSeries<'a> {
    /// The single-sensor columns of a compensated flight: `mag`,
    /// `mag_comp`, and `mag_interf`, `true_external`, `true_lag`,
    /// `true_interf`, `true_mag_noise` when present.
    pub fn of(t: &'a Flight) -> Result<Self> {
        Self {
            mag: t.require("mag")?,
            comp: t.require("mag_comp").map_err(|e| {
                other_compensated(t).map_or(e.into(), |name| missing_comp(t, &name))
            })?,
            interf: t.column("mag_interf"),
            truth: SensorTruth {
                external: t.column("true_external"),
                lag: t.column("true_lag"),
                interf: t.column("true_interf"),
                noise: t.column("true_mag_noise"),
            },
        }
        .checked(t, ["mag", "mag_comp", "mag_interf"])
    }

    /// The series, once its compensated reading and interference (columns
    /// `names`: reading, compensated, interference) are checked to be what
    /// they say, as bad input naming the row and column: within any
    /// magnetic field ([`aeromag_io::MAX_FIELD_NT`]); the compensated
    /// reading a total field like the reading (their median difference
    /// below [`MAX_INTERFERENCE_SHARE`] of the reading's median); and, with
    /// the interference, the reading minus it (to
    /// [`CONSISTENCY_TOLERANCE_NT`] or 10⁻⁹ of the reading). A report of
    /// `1e300` in `mag_comp` gave an improvement ratio of 0.000, one in µT
    /// a residual of −53 046 nT, and `mag_interf` ×1000 or `mag` and
    /// `mag_comp` swapped were scored, all without a word.
    pub(crate) fn checked(self, t: &Flight, names: [&str; 3]) -> Result<Self> {
        let [mag_name, comp_name, interf_name] = names;
        let columns =
            std::iter::once((comp_name, self.comp)).chain(self.interf.map(|v| (interf_name, v)));
        for (name, v) in columns {
            if let Some(row) = v.iter().position(|x| x.abs() > aeromag_io::MAX_FIELD_NT) {
                return Err(t.bad_value(
                    row,
                    name,
                    format!(
                        "{} nT is beyond any magnetic field (at most {} nT in magnitude)",
                        shown(v[row]),
                        shown(aeromag_io::MAX_FIELD_NT)
                    ),
                ));
            }
        }
        // Medians over evenly strided rows where both are finite (NaN
        // elsewhere is left out).
        let n = self.mag.len().min(self.comp.len());
        let both = |f: fn(f64, f64) -> f64| {
            move |i: usize| {
                let (m, c) = (self.mag[i], self.comp[i]);
                if c.is_finite() { f(m, c) } else { f64::NAN }
            }
        };
        let field = aeromag_io::sampled_median(n, both(|m, _| m.abs()));
        let diff = aeromag_io::sampled_median(n, both(|m, c| (m - c).abs()));
        if let (Some(field), Some(diff)) = (field, diff)
            && diff > MAX_INTERFERENCE_SHARE * field
        {
            return Err(t.bad_column(
                comp_name,
                format!(
                    "the compensated reading differs from `{mag_name}` by a median of {} nT, {} % of \
                     the field ({} nT): no aircraft's interference is that large; is it in another \
                     unit (µT, pT?) or another column?",
                    fixed(diff, 1),
                    fixed(100.0 * diff / field, 1),
                    fixed(field, 1)
                ),
            ));
        }
        if let Some(interf) = self.interf {
            let off = |i: usize| {
                let (m, c, f) = (self.mag[i], self.comp[i], interf[i]);
                let tol = CONSISTENCY_TOLERANCE_NT.max(1e-9 * m.abs());
                m.is_finite() && c.is_finite() && f.is_finite() && (m - f - c).abs() > tol
            };
            if let Some(row) =
                (0..self.mag.len().min(self.comp.len()).min(interf.len())).find(|&i| off(i))
            {
                return Err(t.bad_value(
                    row,
                    comp_name,
                    format!(
                        "{} nT is not `{mag_name}` minus `{interf_name}` ({} − {} = {} nT): columns \
                         swapped, another unit, or edited after compensation? (drop `{interf_name}` to \
                         report the compensated reading alone)",
                        shown(self.comp[row]),
                        shown(self.mag[row]),
                        shown(interf[row]),
                        shown(self.mag[row] - interf[row])
                    ),
                ));
            }
        }
        Ok(self)
    }
}

/// The largest median difference between a flight's reading and its
/// compensated reading, as a share of the reading's median, that
/// [`SensorSeries::checked`] takes for aircraft interference: half the
/// field. Fixed-wing interference is tens to thousands of nT against a
/// field of 20 000–65 000 nT; a compensated reading in µT differs by 99.9 %.
pub const MAX_INTERFERENCE_SHARE: f64 = 0.5;

/// How far the compensated reading may differ from the reading minus the
/// interference, nT ([`SensorSeries::checked`]): files written by another
/// tool with three decimals round each by 0.0005 nT.
pub const CONSISTENCY_TOLERANCE_NT: f64 = 0.01;

impl SensorTruth<'_> {
    /// What the compensated reading should be: the external field plus the
    /// sensor's lag term (not aircraft interference: levelling handles it),
    /// when the external field is known.
    pub fn compensated(&self) -> Option<Vec<f64>> {
        let ext = self.external?;
        Some(match self.lag {
            Some(lag) => ext.iter().zip(lag).map(|(e, l)| e + l).collect(),
            None => ext.to_vec(),
        })
    }
}

/// Segments of rows where `mag` and `comp` are finite, split at lines and
/// gaps, of at least 2 rows.
fn segments(t: &Flight, mag: &[f64], comp: &[f64]) -> Result<Vec<Range<usize>>> {
    let time = t.require("time")?;
    let usable: Vec<bool> = (0..time.len())
        .map(|i| mag[i].is_finite() && comp[i].is_finite())
        .collect();
    Ok(SegmentRule::default()
        .min_len(2)
        .split(time, t.line_numbers(), &usable)
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
    score_series(t, &SensorSeries::of(t)?, reference, lever)
}

/// [`score`] of the sensor series `s` of the flight `t` (which gives the
/// time, attitude, lines and reference channels).
pub fn score_series(
    t: &Flight,
    s: &SensorSeries,
    reference: &[String],
    lever: Option<&LeverArm>,
) -> Result<Figures> {
    let time = t.require("time")?;
    let ref_sum = reference_sum(t, reference, lever)?;
    let mag = reduced(s.mag, &ref_sum);
    let comp_raw = s.comp;
    let comp = reduced(comp_raw, &ref_sum);
    let segs = segments(t, &mag, &comp)?;
    let step = median_step(time);
    if step.is_nan() || step <= 0.0 {
        return Err(Error::bad_file(
            t.file_label(),
            format!(
                "{} row(s) with no time step: scoring needs a record sampled in time",
                time.len()
            ),
        ));
    }
    let fs = 1.0 / step;
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
    let on_line: Vec<Range<usize>> = match t.line_numbers() {
        Some(l) => segs.iter().filter(|r| l[r.start] != 0.0).cloned().collect(),
        None => segs.clone(),
    };
    // A line by its first row's label: the number, or the text of a text
    // column (every line was `0` in the table before).
    let numbers = t.column("line");
    let text = t.table().text_column("line");
    let line_of = |i: usize| match (numbers, text) {
        (Some(v), _) => LineLabel::Number(v[i]),
        (None, Some(s)) => LineLabel::Text(s[i].trim().to_string()),
        (None, None) => LineLabel::Number(0.0),
    };
    let interference_rms_nt = match (s.truth.interf, s.interf) {
        (Some(truth), Some(model)) => {
            let (_, pooled) = residual_by_line(model, truth, &line_of, &on_line);
            pooled.is_finite().then_some(pooled)
        }
        _ => None,
    };
    if let Some(truth) = s.truth.compensated() {
        let (l, pooled) = residual_by_line(comp_raw, &truth, &line_of, &on_line);
        residual_rms_nt = pooled.is_finite().then_some(pooled);
        lines = l;
    }
    if let Some(noise) = s.truth.noise {
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

#[cfg(test)]
mod tests {
    use super::*;
    use aeromag_io::FlightTable;

    /// A flight without `mag_comp` whose file holds a compensated reading
    /// of another processing (SGL's COMPMAG1, MagNav's mag_1_c) names it.
    #[test]
    fn a_missing_mag_comp_names_the_compensated_reading_the_file_has() {
        for (other, named) in [
            ("COMPMAG1", true),
            ("mag_3_c", true),
            ("mag_c", false),
            ("compmagx", false),
        ] {
            let mut t = FlightTable::new();
            t.add_column("time", vec![0.0, 0.1, 0.2]).unwrap();
            t.add_column("mag", vec![5e4; 3]).unwrap();
            t.add_column(other, vec![5e4; 3]).unwrap();
            let flight = Flight::from_table(t).unwrap();
            let e = SensorSeries::of(&flight).map(|_| ()).unwrap_err();
            assert!(e.is_bad_input());
            assert_eq!(
                e.to_string().contains(&format!("the file has '{other}'")),
                named,
                "{e}"
            );
            assert!(e.to_string().contains("'mag_comp' is missing"), "{e}");
        }
    }
}
