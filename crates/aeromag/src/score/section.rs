//! The report section of a scored flight.

use super::{Figures, SensorSeries};
use crate::error::Result;
use crate::flight::{Flight, GAP_FACTOR};
use aeromag_compensation::model_file::TlModel;
use aeromag_compensation::tolles_lawson::segments::median_step;
use aeromag_core::spectrum::{WelchConfig, welch};
use aeromag_report::{LinePlot, ReportSection, Series, Table};

fn f3(v: Option<f64>) -> String {
    v.map_or("—".into(), |x| format!("{x:.3}"))
}

/// A FOM or IR cell: the value, or why there is none.
fn fom_cell(v: Option<f64>, windows: usize) -> String {
    match v {
        Some(_) => f3(v),
        None if windows == 0 => "— (no manoeuvre windows found)".into(),
        None => "— (windows too short or not finite)".into(),
    }
}

/// `(t, y)` with a NaN point inserted at every time gap (a step longer
/// than [`GAP_FACTOR`] × the median step), so that a line plot breaks
/// there instead of drawing a straight line across the gap.
fn gapped(t: &[f64], y: &[f64], step: f64) -> (Vec<f64>, Vec<f64>) {
    let mut tt = Vec::with_capacity(t.len());
    let mut yy = Vec::with_capacity(y.len());
    for i in 0..t.len().min(y.len()) {
        if i > 0 && t[i] - t[i - 1] > GAP_FACTOR * step {
            tt.push(0.5 * (t[i] + t[i - 1]));
            yy.push(f64::NAN);
        }
        tt.push(t[i]);
        yy.push(y[i]);
    }
    (tt, yy)
}

impl Figures {
    /// The report section of a compensated flight `t` scored with these
    /// figures: the figures, the signal before and after, the modelled
    /// interference (against the truth where simulated), the residual versus
    /// truth, Welch spectra, the FOM per manoeuvre window, the residual per
    /// line, and the model's coefficients when given.
    pub fn section(
        &self,
        title: &str,
        t: &Flight,
        model: Option<&TlModel>,
    ) -> Result<ReportSection> {
        let sensor = crate::flight::SensorColumns::default();
        let mut r = self.sensor_section(title, t, &SensorSeries::of(t)?, model, &sensor)?;
        levelling_part(&mut r, t)?;
        Ok(r)
    }

    /// [`Figures::section`] of the sensor series `s` of `t` (without the
    /// levelling part, which is the flight's); `model` is applied at
    /// `sensor`'s columns to say whether the first-order projection is
    /// enough there.
    pub fn sensor_section(
        &self,
        title: &str,
        t: &Flight,
        s: &SensorSeries,
        model: Option<&TlModel>,
        sensor: &crate::flight::SensorColumns,
    ) -> Result<ReportSection> {
        let fig = self;
        let time = t.require("time")?;
        let (mag, comp) = (s.mag, s.comp);
        let t0 = time.first().copied().unwrap_or(0.0);
        let tt: Vec<f64> = time.iter().map(|v| v - t0).collect();
        let step = median_step(time);
        // A series over the time axis, broken at the time gaps.
        let series = |name: &str, y: Vec<f64>| {
            let (x, y) = gapped(&tt, &y, step);
            Series::line(name, x, y)
        };
        let mut r = ReportSection::new(title);
        let mut kv = vec![
            ("rows".to_string(), t.n_rows().to_string()),
            (
                "FOM before (nT)".into(),
                fom_cell(fig.fom_before_nt, fig.fom_windows),
            ),
            (
                "FOM after (nT)".into(),
                fom_cell(fig.fom_after_nt, fig.fom_windows),
            ),
            ("manoeuvre windows".into(), fig.fom_windows.to_string()),
            (
                "improvement ratio".into(),
                fom_cell(fig.ir, fig.fom_windows),
            ),
        ];
        if let Some(v) = fig.residual_rms_nt {
            kv.push(("residual vs truth, RMS (nT)".into(), format!("{v:.4}")));
        }
        if let Some(v) = fig.noise_floor_nt {
            kv.push(("scalar sensor noise floor (nT)".into(), format!("{v:.4}")));
        }
        let second = match model {
            Some(m) => crate::tolles_lawson::second_order_range_nt(m, t, sensor)?,
            None => None,
        };
        if let Some(v) = second {
            kv.push((
                "second-order term of the projection, peak to peak (nT)".into(),
                format!("{v:.3}"),
            ));
        }
        r.key_values(kv);
        if let Some(v) = second.filter(|v| *v > crate::tolles_lawson::SECOND_ORDER_NOTE_NT) {
            r.paragraph(format!(
                "The first-order projection of the Tolles-Lawson model leaves out up to {v:.2} nT \
                 on this flight (the second-order term |ΔB⊥|²/2|B| of an interference above about 1 % \
                 of the field): calibrate with --magnitude exact, which fits |B + ΔB| − |B|."
            ));
        }

        let mean = |x: &[f64]| {
            let v: Vec<f64> = x.iter().copied().filter(|v| v.is_finite()).collect();
            v.iter().sum::<f64>() / v.len().max(1) as f64
        };
        let (mm, cm) = (mean(mag), mean(comp));
        let svg = LinePlot::new(
            "Uncompensated and compensated field (means removed)",
            "time since start (s)",
            "field (nT)",
        )
        .with_series(series(
            "uncompensated",
            mag.iter().map(|v| v - mm).collect(),
        ))
        .with_series(series("compensated", comp.iter().map(|v| v - cm).collect()))
        .to_svg()?;
        r.figure(svg, "Scalar magnetometer before and after compensation.");

        if let Some(model_interf) = s.interf {
            let mi = mean(model_interf);
            let truth = s.truth.interf;
            let (title, caption) = if truth.is_some() {
                (
                    "Aircraft interference: model and truth (means removed)",
                    "Modelled interference against the simulator's truth.",
                )
            } else {
                (
                    "Aircraft interference: model (mean removed)",
                    "Modelled interference (the file has no truth to compare with).",
                )
            };
            let mut p =
                LinePlot::new(title, "time since start (s)", "interference (nT)").with_series(
                    series("model", model_interf.iter().map(|v| v - mi).collect()),
                );
            if let Some(ti) = truth {
                let m = mean(ti);
                p = p.with_series(series(
                    "truth (simulation)",
                    ti.iter().map(|v| v - m).collect(),
                ));
            }
            r.figure(p.to_svg()?, caption);
        }

        if let Some(ext) = s.truth.external {
            let lag = s.truth.lag;
            let res: Vec<f64> = (0..comp.len())
                .map(|i| comp[i] - ext[i] - lag.map_or(0.0, |l| l[i]))
                .collect();
            let rm = mean(&res);
            let svg = LinePlot::new(
                "Residual versus truth",
                "time since start (s)",
                "compensated − truth (nT)",
            )
            .with_series(series("residual", res.iter().map(|v| v - rm).collect()))
            .to_svg()?;
            r.figure(svg, "Compensated field minus the true external field (sensor lag term removed), mean removed.");
        }

        // Welch spectra over the longest finite run of each signal.
        let fs = 1.0 / step;
        let longest = |x: &[f64]| -> Vec<f64> {
            let mut best = (0, 0);
            let mut start = 0;
            for i in 0..=x.len() {
                if i == x.len() || !x[i].is_finite() {
                    if i - start > best.1 - best.0 {
                        best = (start, i);
                    }
                    start = i + 1;
                }
            }
            x[best.0..best.1].to_vec()
        };
        let nperseg = 1024usize.min(comp.len() / 4).max(16);
        let mut sp = LinePlot::new(
            "Power spectral density (Welch)",
            "frequency (Hz)",
            "PSD (nT²/Hz)",
        )
        .log_log();
        for (name, x) in [("uncompensated", mag), ("compensated", comp)] {
            let seg = longest(x);
            if seg.len() >= nperseg {
                let psd = welch(&seg, &WelchConfig::new(fs, nperseg))?;
                sp = sp.with_series(Series::line(name, psd.freqs_hz, psd.values));
            }
        }
        if !sp.series.is_empty() {
            r.figure(
                sp.to_svg()?,
                "Welch spectra (Hann window, 50 % overlap) of the longest uninterrupted stretch.",
            );
        }

        if let (Some(before), Some(after)) = (&fig.fom_before, &fig.fom_after) {
            let rows = before
                .windows
                .iter()
                .zip(&after.windows)
                .map(|(b, a)| {
                    vec![
                        format!("{:.0}", b.maneuver.heading_deg),
                        b.maneuver.axis.name().to_string(),
                        format!("{:.1}", tt[b.maneuver.start]),
                        format!("{:.1}", tt[b.maneuver.end - 1]),
                        format!("{:.3}", b.peak_to_peak_nt),
                        format!("{:.3}", a.peak_to_peak_nt),
                    ]
                })
                .collect();
            r.table(Table::new(
                [
                    "heading (°)",
                    "manoeuvre",
                    "start (s)",
                    "end (s)",
                    "p-p before (nT)",
                    "p-p after (nT)",
                ]
                .map(String::from)
                .to_vec(),
                rows,
                "Figure of merit: detrended peak-to-peak amplitude per manoeuvre window.",
            ));
        }
        if !fig.lines.is_empty() {
            let rows = fig
                .lines
                .iter()
                .map(|l| {
                    vec![
                        format!("{}", l.line),
                        l.samples.to_string(),
                        format!("{:.3}", l.mean_nt),
                        format!("{:.4}", l.rms_nt),
                    ]
                })
                .collect();
            r.table(Table::new(
                ["line", "samples", "mean offset (nT)", "RMS about mean (nT)"]
                    .map(String::from)
                    .to_vec(),
                rows,
                "Residual versus truth per line (simulation).",
            ));
        }
        if let Some(m) = model {
            let rows = m
                .coefficients
                .iter()
                .map(|c| {
                    vec![
                        c.name.clone(),
                        format!("{:.6}", c.value),
                        format!("{:.2e}", c.std),
                    ]
                })
                .collect();
            r.table(Table::new(
                ["term", "coefficient", "standard deviation"]
                    .map(String::from)
                    .to_vec(),
                rows,
                format!(
                    "Model coefficients ({}, method {}, convention {:?}).",
                    m.design.terms, m.method, m.design.convention
                ),
            ));
            if !m.fit.warnings.is_empty() {
                r.paragraph(format!("Fit warnings: {}", m.fit.warnings.join(" | ")));
            }
        }
        Ok(r)
    }
}

/// A series over the time axis of `t` (seconds since its start), broken at
/// the time gaps.
pub(super) fn time_series(t: &Flight, name: &str, y: Vec<f64>) -> Result<Series> {
    let time = t.require("time")?;
    let t0 = time.first().copied().unwrap_or(0.0);
    let tt: Vec<f64> = time.iter().map(|v| v - t0).collect();
    let (x, y) = gapped(&tt, &y, median_step(time));
    Ok(Series::line(name, x, y))
}

/// The levelling columns of a file written by `aeromag level`
/// (`<value>_level` and `level_flag`), when present: the rows by flag, the
/// correction (levelled − value) along the flight and per line.
fn levelling_part(r: &mut ReportSection, t: &Flight) -> Result<()> {
    let Some(flag) = t.column(crate::level::LEVEL_FLAG) else {
        return Ok(());
    };
    let Some((value, levelled)) = t.column_names().iter().find_map(|n| {
        let base = n.strip_suffix("_level")?;
        Some((t.column(base)?, t.column(n)?))
    }) else {
        return Ok(());
    };
    let count = |f: f64| flag.iter().filter(|&&x| x == f).count().to_string();
    r.key_values(vec![
        ("rows levelled".into(), count(0.0)),
        ("rows on a line without crossovers".into(), count(1.0)),
        ("rows not on a line".into(), count(2.0)),
        ("rows with a missing value".into(), count(3.0)),
    ]);
    let correction: Vec<f64> = levelled.iter().zip(value).map(|(l, v)| l - v).collect();
    let svg = LinePlot::new(
        "Levelling correction",
        "time since start (s)",
        "levelled − value (nT)",
    )
    .with_series(time_series(t, "correction", correction.clone())?)
    .to_svg()?;
    r.figure(
        svg,
        "The correction levelling applied (line level, drift and the k·d|B0|/dt term).",
    );
    if let Ok(labels) = crate::flight::LineLabels::of(t, &[]) {
        let rows = labels
            .labels
            .iter()
            .enumerate()
            .map(|(k, label)| {
                let id = (k + 1) as f64;
                let c: Vec<f64> = (0..correction.len())
                    .filter(|&i| labels.ids[i] == id && correction[i].is_finite())
                    .map(|i| correction[i])
                    .collect();
                let mean = c.iter().sum::<f64>() / c.len().max(1) as f64;
                let spread =
                    c.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / c.len().max(1) as f64;
                vec![
                    label.clone(),
                    c.len().to_string(),
                    if c.is_empty() {
                        "—".into()
                    } else {
                        format!("{mean:.3}")
                    },
                    if c.is_empty() {
                        "—".into()
                    } else {
                        format!("{:.3}", spread.sqrt())
                    },
                ]
            })
            .collect();
        r.table(Table::new(
            [
                "line",
                "levelled samples",
                "mean correction (nT)",
                "std along the line (nT)",
            ]
            .map(String::from)
            .to_vec(),
            rows,
            "Levelling correction per line.",
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_break_at_time_gaps() {
        let t = [0.0, 0.1, 0.2, 10.0, 10.1];
        let y = [1.0, 2.0, 3.0, 4.0, 5.0];
        let (tt, yy) = gapped(&t, &y, 0.1);
        assert_eq!(tt.len(), 6);
        assert!(yy[3].is_nan() && tt[3] > 0.2 && tt[3] < 10.0);
        assert_eq!(&yy[..3], &[1.0, 2.0, 3.0]);
        assert_eq!(&yy[4..], &[4.0, 5.0]);
        // a regular record is left alone
        assert_eq!(gapped(&t[..3], &y[..3], 0.1).1, y[..3].to_vec());
    }

    #[test]
    fn missing_fom_says_why() {
        assert_eq!(fom_cell(Some(1.23456), 3), "1.235");
        assert!(fom_cell(None, 0).contains("no manoeuvre windows"));
        assert!(fom_cell(None, 2).contains("too short"));
    }
}
