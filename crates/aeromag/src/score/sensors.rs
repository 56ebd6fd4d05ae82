//! Scoring a flight compensated with a multi-sensor model
//! ([`SensorsModel`], `aeromag calibrate --mag A,B,…`): per sensor the
//! figures of [`score`](super::score) (before and after), the share of the
//! modelled interference each term group explains, and the recorded
//! currents against what compensation left (`aeromag report --model
//! sensors.json`).
//!
//! The compensated flight carries `<name>_comp` and `<name>_interf` per
//! sensor (as `aeromag compensate` writes them). For simulated data the
//! truth of sensor `mag_k` is `true_external_k` and `true_interf_k`; the
//! first sensor's lag and noise are the simulator's `true_lag` and
//! `true_mag_noise`.

use super::{Figures, SensorSeries, SensorTruth, score_series};
use crate::error::Result;
use crate::flight::{Flight, SensorColumns, reduced, reference_sum};
use crate::studies::fixed;
use crate::tolles_lawson::InterferenceParts;
use aeromag_compensation::metrics::band_pass_segments;
use aeromag_compensation::model_file::{SensorModel, SensorsModel};
use aeromag_compensation::tolles_lawson::segments::median_step;
use aeromag_core::filter::BandPass;
use aeromag_report::{LinePlot, ReportSection, Table};
use serde::Serialize;
use std::ops::Range;

/// RMS of each term group's part of a model's interference
/// ([`InterferenceParts`]) and the share of the total each explains, over
/// the scored rows.
///
/// The share of group `g` is `cov(part_g, total) / var(total)`: the parts
/// of a first-order model sum to its interference (the `bias` term aside,
/// which is constant), so the shares sum to 1; a group can have a negative
/// share when it cancels part of another. With the exact magnitude the
/// parts are each group alone and the shares sum to about 1.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct GroupRms {
    /// Permanent magnetization, nT.
    pub permanent_nt: f64,
    /// Induced magnetization, nT.
    pub induced_nt: f64,
    /// Eddy currents, nT.
    pub eddy_nt: f64,
    /// The currents' terms (the extra regressors), nT.
    pub currents_nt: f64,
    /// The whole modelled interference (about its mean), nT.
    pub total_nt: f64,
    /// Shares of the total: permanent, induced, eddy, currents.
    pub shares: [f64; 4],
}

impl GroupRms {
    /// The figures of `parts` (total: `interference`) on the rows `rows`.
    pub fn of(parts: &InterferenceParts, interference: &[f64], rows: &[usize]) -> Self {
        let pick = |x: &[f64]| -> Vec<f64> { rows.iter().map(|&i| x[i]).collect() };
        let total = pick(interference);
        let groups = [
            &parts.permanent,
            &parts.induced,
            &parts.eddy,
            &parts.currents,
        ]
        .map(|p| pick(p));
        let var = covariance(&total, &total);
        let shares = groups.each_ref().map(|g| {
            if var > 0.0 {
                covariance(g, &total) / var
            } else {
                f64::NAN
            }
        });
        let [p, i, e, c] = groups.each_ref().map(|g| covariance(g, g).sqrt());
        Self {
            permanent_nt: p,
            induced_nt: i,
            eddy_nt: e,
            currents_nt: c,
            total_nt: var.sqrt(),
            shares,
        }
    }
}

/// A channel against a residual.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChannelCorrelation {
    /// The channel.
    pub channel: String,
    /// Pearson correlation with the residual.
    pub correlation: f64,
    /// The residual's RMS the channel explains linearly, |r| × RMS, nT.
    pub explained_nt: f64,
}

/// Covariance of `a` and `b` (same length, finite) about their means.
fn covariance(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().max(1) as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - ma) * (y - mb))
        .sum::<f64>()
        / n
}

/// The correlation of each channel with `residual` over the rows where
/// both are finite, strongest (largest |r|) first; a constant channel has
/// r = 0.
pub fn channel_correlations<C: AsRef<[f64]>>(
    residual: &[f64],
    channels: &[(String, C)],
) -> Vec<ChannelCorrelation> {
    let mut out: Vec<ChannelCorrelation> = channels
        .iter()
        .map(|(name, ch)| {
            let (a, b): (Vec<f64>, Vec<f64>) = residual
                .iter()
                .zip(ch.as_ref())
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .map(|(x, y)| (*x, *y))
                .unzip();
            let (saa, sbb) = (covariance(&a, &a), covariance(&b, &b));
            let r = if saa > 0.0 && sbb > 0.0 {
                covariance(&a, &b) / (saa * sbb).sqrt()
            } else {
                0.0
            };
            ChannelCorrelation {
                channel: name.clone(),
                correlation: r,
                explained_nt: r.abs() * saa.sqrt(),
            }
        })
        .collect();
    // Stable: equal strengths keep the channels' order.
    out.sort_by(|x, y| y.correlation.abs().total_cmp(&x.correlation.abs()));
    out
}

/// One sensor of a multi-sensor model, scored.
#[derive(Debug, Clone, Serialize)]
pub struct SensorScore {
    /// The sensor's name (`mag_3`).
    pub sensor: String,
    /// Its scalar column (`mag_3_uc`).
    pub column: String,
    /// The reference sensor it was fitted against, if any.
    pub reference_sensor: Option<String>,
    /// FOM, IR and (simulation) the residual versus truth.
    pub figures: Figures,
    /// The modelled interference by term group.
    pub groups: GroupRms,
    /// Every current channel (the model's extra regressors and the flight's
    /// `cur_*` columns) against the compensated reading in the compensation
    /// band, strongest first.
    pub currents: Vec<ChannelCorrelation>,
    /// The model's extra regressors (kept by the channel test).
    pub in_model: Vec<String>,
    /// The channels the test dropped.
    pub dropped: Vec<String>,
    /// Peak to peak of the second-order term the first-order projection
    /// leaves out, nT (`None` for an exact-magnitude model).
    pub second_order_nt: Option<f64>,
    /// The compensated reading in the compensation band (reference
    /// channels removed; NaN off the scored rows), nT.
    #[serde(skip)]
    pub left_nt: Vec<f64>,
    /// The strongest current channel in the same band, scaled by its
    /// least-squares slope onto `left_nt`, nT.
    #[serde(skip)]
    pub strongest_nt: Option<Vec<f64>>,
}

/// The figures of a flight compensated with a multi-sensor model.
#[derive(Debug, Clone, Serialize)]
pub struct SensorsFigures {
    /// One per sensor of the model, in its order.
    pub sensors: Vec<SensorScore>,
}

/// The truth of the sensor `name` (`mag_k`): module docs.
fn truth_of<'a>(t: &'a Flight, name: &str) -> SensorTruth<'a> {
    let k = name
        .strip_prefix("mag_")
        .filter(|k| k.parse::<u32>().is_ok());
    match k {
        Some(k) => SensorTruth {
            external: t.column(&format!("true_external_{k}")),
            interf: t.column(&format!("true_interf_{k}")),
            lag: (k == "1").then(|| t.column("true_lag")).flatten(),
            noise: (k == "1").then(|| t.column("true_mag_noise")).flatten(),
        },
        None => SensorTruth::default(),
    }
}

/// The current channels of `t` for `model`: its extra regressors, then
/// the other `cur_*` columns, each once.
fn current_channels<'a>(t: &'a Flight, model: &SensorModel) -> Vec<(String, &'a [f64])> {
    let mut names = extra_channels(model);
    for n in t.column_names() {
        if n.to_ascii_lowercase().starts_with("cur_") && !names.iter().any(|m| m == n) {
            names.push(n.to_string());
        }
    }
    names
        .into_iter()
        .filter_map(|n| t.column(&n).map(|c| (n, c)))
        .collect()
}

/// Score every sensor of `model` on the compensated flight `t` (module
/// docs), with the known external-field channels `reference` removed
/// first as in [`score`](super::score). Reads `<name>_comp` and
/// `<name>_interf`, the sensors' columns and the current channels; truth
/// only to score.
///
/// ```
/// use aeromag::prelude::*;
/// use aeromag::score::score_sensors;
/// use aeromag::simulate::{ScenarioKind, simulate_flight};
/// use aeromag::{CompensateSensors, SensorColumns, SensorSet, calibrate_sensors};
/// let sgl = "installation = \"sgl\"\n[pattern]\ncycles = 1\n";
/// let cal = simulate_flight(ScenarioKind::Calibration, Some(sgl), Some(1))?;
/// let set = SensorSet {
///     sensors: vec![SensorColumns::find(&cal, "mag_1_uc", Some("flux_a"))?,
///                   SensorColumns::find(&cal, "mag_4_uc", Some("flux_a"))?],
///     reference: None,
/// };
/// let opts = CalibrateOptions::default();
/// let model = calibrate_sensors(&cal, &set, &opts, &mut Silent)?.model;
/// let mut table = cal.table().clone();
/// model.compensate(&cal)?.add_to(&mut table)?;
/// let flight = Flight::from_table(table)?;
/// let fig = score_sensors(&flight, &model, &[])?;
/// assert_eq!(fig.sensors[1].sensor, "mag_4");
/// assert!(fig.sensors[1].figures.ir.unwrap() > 1.0);
/// # Ok::<(), aeromag::Error>(())
/// ```
pub fn score_sensors(
    t: &Flight,
    model: &SensorsModel,
    reference: &[String],
) -> Result<SensorsFigures> {
    let time = t.require("time")?;
    let bpf = BandPass::compensation_default(1.0 / median_step(time))?;
    let ref_sum = reference_sum(t, reference, None)?;
    let mut sensors = Vec::new();
    for s in &model.sensors {
        let series = series_of(t, s)?;
        let figures = score_series(t, &series, reference, None)?;
        let segs = scored_segments(t, &series)?;
        let rows: Vec<usize> = segs.iter().flat_map(|r| r.clone()).collect();
        let cols = columns_of(s);
        let parts = InterferenceParts::of(&s.model, t, &cols)?;
        let second_order_nt = crate::tolles_lawson::second_order_range_nt(&s.model, t, &cols)?;
        let groups = GroupRms::of(&parts, series.interf.unwrap_or_default(), &rows);
        // What compensation left in the band of the aircraft's interference.
        let left = band_pass_segments(&reduced(series.comp, &ref_sum), &segs, &bpf)?;
        // Each current in the same band, whole and on the scored rows.
        let banded: Vec<(String, Vec<f64>)> = current_channels(t, s)
            .into_iter()
            .map(|(n, c)| Ok((n, band_pass_segments(c, &segs, &bpf)?)))
            .collect::<Result<_>>()?;
        let on_rows = |x: &[f64]| -> Vec<f64> { rows.iter().map(|&i| x[i]).collect() };
        let scored: Vec<(String, Vec<f64>)> = banded
            .iter()
            .map(|(n, c)| (n.clone(), on_rows(c)))
            .collect();
        let currents = channel_correlations(&on_rows(&left), &scored);
        let strongest_nt = currents.first().and_then(|c| {
            let k = scored.iter().position(|(n, _)| *n == c.channel)?;
            let sd = covariance(&scored[k].1, &scored[k].1).sqrt();
            let slope = c.explained_nt / sd * c.correlation.signum();
            (sd > 0.0).then(|| banded[k].1.iter().map(|v| v * slope).collect())
        });
        let selection = s.model.fit.extra_channel_selection.as_ref();
        sensors.push(SensorScore {
            sensor: s.name.clone(),
            column: s.mag.clone(),
            reference_sensor: s.reference_sensor.clone(),
            figures,
            groups,
            currents,
            in_model: extra_channels(s),
            dropped: selection.map_or_else(Vec::new, |sel| {
                sel.tests
                    .iter()
                    .filter(|c| !c.kept)
                    .map(|c| c.channel.clone())
                    .collect()
            }),
            second_order_nt,
            left_nt: left,
            strongest_nt,
        });
    }
    Ok(SensorsFigures { sensors })
}

/// The channels of the extra regressors of the sensor `s`'s model.
fn extra_channels(s: &SensorModel) -> Vec<String> {
    s.model
        .design
        .terms
        .extras()
        .iter()
        .map(|e| e.channel.clone())
        .collect()
}

/// The columns of the sensor `s`.
fn columns_of(s: &SensorModel) -> SensorColumns {
    SensorColumns {
        mag: s.mag.clone(),
        flux: s.flux.clone(),
    }
}

/// The scored series of the sensor `s` of the compensated flight `t`.
fn series_of<'a>(t: &'a Flight, s: &SensorModel) -> Result<SensorSeries<'a>> {
    let (comp, interf) = (format!("{}_comp", s.name), format!("{}_interf", s.name));
    SensorSeries {
        mag: t.require(&s.mag)?,
        comp: t.require(&comp)?,
        interf: Some(t.require(&interf)?),
        truth: truth_of(t, &s.name),
    }
    .checked(t, [&s.mag, &comp, &interf])
}

impl SensorsFigures {
    /// The report sections: an overview of every sensor (before and after,
    /// shares of the term groups, the strongest current), then per sensor
    /// the section of [`Figures::sensor_section`] with the model's
    /// coefficients, its currents against the residual (table and plot).
    pub fn sections(&self, t: &Flight, model: &SensorsModel) -> Result<Vec<ReportSection>> {
        let mut overview = ReportSection::new("Several sensors: overview");
        let pct = |x: f64| fixed(Some(100.0 * x), 0);
        let rows = self
            .sensors
            .iter()
            .map(|s| {
                let f = &s.figures;
                let g = &s.groups;
                vec![
                    format!("{} ({})", s.sensor, s.column),
                    s.reference_sensor.clone().unwrap_or_else(|| "—".into()),
                    fixed(f.fom_before_nt, 2),
                    fixed(f.fom_after_nt, 3),
                    fixed(f.ir, 1),
                    fixed(f.residual_rms_nt, 3),
                    fixed(Some(g.total_nt), 2),
                    format!(
                        "{} / {} / {} / {}",
                        pct(g.shares[0]),
                        pct(g.shares[1]),
                        pct(g.shares[2]),
                        pct(g.shares[3])
                    ),
                    s.currents.first().map_or("—".into(), |c| {
                        format!(
                            "{} (r = {:.2}, {:.3} nT)",
                            c.channel, c.correlation, c.explained_nt
                        )
                    }),
                    format!("{} kept, {} dropped", s.in_model.len(), s.dropped.len()),
                    match s.second_order_nt {
                        None => "exact magnitude".into(),
                        Some(v) if v > crate::tolles_lawson::SECOND_ORDER_NOTE_NT => {
                            format!("{v:.2} nT: use --magnitude exact")
                        }
                        Some(v) => format!("{v:.3} nT"),
                    },
                ]
            })
            .collect();
        overview.table(Table::new(
            [
                "sensor",
                "reference sensor",
                "FOM before (nT)",
                "FOM after (nT)",
                "IR",
                "residual vs truth (nT)",
                "modelled interference RMS (nT)",
                "shares % (perm. / ind. / eddy / currents)",
                "current most correlated with what is left",
                "current channels",
                "second-order term (p-p)",
            ]
            .map(String::from)
            .to_vec(),
            rows,
            "Each sensor before and after. Shares: cov(part, total)/var(total) of the modelled \
             interference on the scored rows (they sum to 100 % for the first-order model; a negative \
             share cancels part of another group). What is left: the compensated reading in the \
             compensation band (0.1–0.9 Hz). Second-order term: what the first-order projection leaves \
             out, |ΔB⊥|²/2|B| peak to peak; above 0.1 nT the exact magnitude is worth fitting.",
        ));
        let mut out = vec![overview];
        for (s, m) in self.sensors.iter().zip(&model.sensors) {
            let series = series_of(t, m)?;
            let mut sec = s.figures.sensor_section(
                &format!("Sensor {} ({})", s.sensor, s.column),
                t,
                &series,
                Some(&m.model),
                &columns_of(m),
            )?;
            let status = |c: &str| {
                if s.in_model.iter().any(|n| n == c) {
                    "in the model"
                } else if s.dropped.iter().any(|n| n == c) {
                    "dropped by the test"
                } else {
                    "not asked for"
                }
            };
            let rows = s
                .currents
                .iter()
                .map(|c| {
                    vec![
                        c.channel.clone(),
                        format!("{:+.3}", c.correlation),
                        format!("{:.4}", c.explained_nt),
                        status(&c.channel).to_string(),
                    ]
                })
                .collect();
            sec.table(Table::new(
                ["current", "r with what is left", "explains (nT)", "status"]
                    .map(String::from)
                    .to_vec(),
                rows,
                "The recorded currents against the compensated reading in the compensation band: a \
                 channel that still explains a part of it is missing from the model (or needs its lag).",
            ));
            if let (Some(best), Some(c)) = (&s.strongest_nt, s.currents.first()) {
                let svg = LinePlot::new(
                    "What is left and the strongest current",
                    "time since start (s)",
                    "nT",
                )
                .with_series(super::section::time_series(
                    t,
                    "compensated, 0.1–0.9 Hz",
                    s.left_nt.clone(),
                )?)
                .with_series(super::section::time_series(
                    t,
                    &format!("{} × slope", c.channel),
                    best.clone(),
                )?)
                .to_svg()?;
                sec.figure(
                    svg,
                    format!(
                        "The compensated reading in the compensation band and {} scaled by its \
                         least-squares slope (r = {:.2}).",
                        c.channel, c.correlation
                    ),
                );
            }
            out.push(sec);
        }
        Ok(out)
    }
}

/// The segments a sensor is scored on: finite readings, split at lines and
/// gaps, on survey lines (`line` ≠ 0) when the flight has them.
fn scored_segments(t: &Flight, s: &SensorSeries) -> Result<Vec<Range<usize>>> {
    let segs = super::segments(t, s.mag, s.comp)?;
    Ok(match t.line_numbers() {
        Some(l) => segs.into_iter().filter(|r| l[r.start] != 0.0).collect(),
        None => segs,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn correlations_rank_channels_and_explain_the_residual() {
        let n = 400;
        let a: Vec<f64> = (0..n).map(|i| (i as f64 * 0.1).sin()).collect();
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).cos()).collect();
        let flat = vec![2.0; n];
        // residual = 3·a + 0.5·b
        let resid: Vec<f64> = (0..n).map(|i| 3.0 * a[i] + 0.5 * b[i]).collect();
        let chans = vec![
            ("flat".to_string(), &flat[..]),
            ("b".to_string(), &b[..]),
            ("a".to_string(), &a[..]),
        ];
        let c = channel_correlations(&resid, &chans);
        let names: Vec<&str> = c.iter().map(|x| x.channel.as_str()).collect();
        assert_eq!(names, ["a", "b", "flat"]);
        assert!(c[0].correlation > 0.95, "{c:?}");
        assert_eq!(c[2].correlation, 0.0);
        // |r|·RMS: the part of the residual a explains, about 3·RMS(a)
        let rms_a = (covariance(&a, &a)).sqrt();
        assert!((c[0].explained_nt - 3.0 * rms_a).abs() < 0.05 * 3.0 * rms_a);
    }

    #[test]
    fn shares_of_parts_that_sum_to_the_total_sum_to_one() {
        let n = 300;
        let f = |w: f64, a: f64| -> Vec<f64> { (0..n).map(|i| a * (i as f64 * w).sin()).collect() };
        let parts = InterferenceParts {
            permanent: f(0.05, 10.0),
            induced: f(0.11, 4.0),
            eddy: f(0.7, 1.0),
            currents: f(0.23, -2.0),
        };
        let total: Vec<f64> = (0..n)
            .map(|i| {
                parts.permanent[i] + parts.induced[i] + parts.eddy[i] + parts.currents[i] + 7.0
            })
            .collect();
        let rows: Vec<usize> = (0..n).collect();
        let g = GroupRms::of(&parts, &total, &rows);
        assert!((g.shares.iter().sum::<f64>() - 1.0).abs() < 1e-12, "{g:?}");
        assert!(g.shares[0] > g.shares[1] && g.shares[1] > g.shares[2]);
        assert!((g.permanent_nt - 10.0 / 2f64.sqrt()).abs() < 0.5);
    }
}
