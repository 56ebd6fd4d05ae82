//! The helicopter rotor study (seed 000 ch. 3): the physical rotor model
//! against the filter baselines on the simulated `helicopter` scenario —
//! residual rotor interference and the share of anomaly signal each
//! method removes (`aeromag rotor study`, the demo's `rotor` group).

use super::{PrintedFigure, PrintedSummary, Study, StudyOutcome, StudySize, fixed};
use crate::error::{Error, Result};
use crate::observer::Observer;
use aeromag_compensation::rotor::study::{RotorStudy, StudyInput, evaluate, scenario_geometry};
use aeromag_report::{Block, LinePlot, ReportSection, Series, Table};
use aeromag_sim::{ScenarioKind, simulate};
use nalgebra::Vector3;
use serde::Serialize;

/// The rotor study on the `helicopter` scenario of seed `seed` (the demo
/// uses 11). It has one size.
#[derive(Debug, Clone, Copy)]
pub struct RotorStudyRun {
    /// Seed of the simulated flight.
    pub seed: u64,
}

impl Default for RotorStudyRun {
    fn default() -> Self {
        Self { seed: 11 }
    }
}

/// The study's result with the series its plots need.
#[derive(Debug, Clone)]
pub struct RotorOutcome {
    /// Residuals and removed signal of every method.
    pub study: RotorStudy,
    /// Time, s.
    pub time_s: Vec<f64>,
    /// True rotor interference, nT (scoring and plots only).
    pub true_rotor_nt: Vec<f64>,
    /// Scalar reading, nT.
    pub mag_nt: Vec<f64>,
}

/// The `rotor` group of the demo's `summary.json`.
#[derive(Debug, Clone, Serialize)]
pub struct RotorSummary {
    /// RMS rotor interference at the sensor, nT.
    pub rotor_rms_nt: f64,
    /// What the physical model leaves, nT RMS.
    pub residual_model_nt: f64,
    /// What the best filter leaves, nT RMS.
    pub residual_best_filter_nt: f64,
    /// RMS of the anomaly signal, nT.
    pub anomaly_rms_nt: f64,
    /// Rotor frequency, Hz.
    pub rotor_hz: f64,
}

impl Study for RotorStudyRun {
    type Outcome = RotorOutcome;

    fn run(&self, _size: StudySize, observer: &mut dyn Observer) -> Result<RotorOutcome> {
        observer.stage("rotor study: simulating and fitting");
        run_study(self.seed)
    }
}

impl StudyOutcome for RotorOutcome {
    type Summary = RotorSummary;

    fn summary(&self) -> RotorSummary {
        let s = &self.study;
        RotorSummary {
            rotor_rms_nt: s.rotor_rms_nt,
            residual_model_nt: s.residual_model_nt,
            residual_best_filter_nt: s.residual_best_filter_nt,
            anomaly_rms_nt: s.anomaly_rms_nt,
            rotor_hz: s.rotor_hz,
        }
    }

    fn section(&self) -> Result<ReportSection> {
        section(&self.study, &self.time_s, &self.true_rotor_nt, &self.mag_nt)
    }
}

impl PrintedSummary for RotorSummary {
    fn printed(&self) -> Vec<PrintedFigure> {
        vec![
            PrintedFigure::new("rotor.rotor_rms_nt", fixed(Some(self.rotor_rms_nt), 3)),
            PrintedFigure::new(
                "rotor.residual_model_nt",
                fixed(Some(self.residual_model_nt), 4),
            ),
            PrintedFigure::new(
                "rotor.residual_best_filter_nt",
                fixed(Some(self.residual_best_filter_nt), 4),
            ),
        ]
    }
}

/// Samples excluded at each end (3 s at 100 Hz: filter transients).
const EDGE: usize = 300;

/// Simulate the scenario with `seed` and run the comparison, keeping time
/// (s), the true rotor interference (nT) and the scalar reading (nT) for
/// the plots.
fn run_study(seed: u64) -> Result<RotorOutcome> {
    let sim = simulate(ScenarioKind::Helicopter, None, Some(seed))?;
    let col = |n: &str| {
        sim.column(n).ok_or_else(|| Error::Serialize {
            what: "helicopter scenario",
            reason: format!("no column {n}"),
        })
    };
    let (x, y, z) = (col("flux_x")?, col("flux_y")?, col("flux_z")?);
    let b: Vec<Vector3<f64>> = (0..x.len())
        .map(|k| Vector3::new(x[k], y[k], z[k]))
        .collect();
    let t = col("time")?;
    let fs = if t.len() > 1 {
        (t.len() - 1) as f64 / (t[t.len() - 1] - t[0])
    } else {
        0.0
    };
    let st = evaluate(
        &scenario_geometry(),
        &StudyInput {
            mag_nt: col("mag")?,
            b_body_nt: &b,
            rotor_phase_deg: col("rotor_phase")?,
            true_rotor_nt: col("true_rotor")?,
            true_anomaly_nt: col("true_anomaly")?,
            fs_hz: fs,
            edge: EDGE,
        },
    )?;
    Ok(RotorOutcome {
        study: st,
        time_s: t.to_vec(),
        true_rotor_nt: col("true_rotor")?.to_vec(),
        mag_nt: col("mag")?.to_vec(),
    })
}

/// A fraction as a percentage with two decimals (`–` when not finite).
pub fn pct(x: f64) -> String {
    if x.is_finite() {
        format!("{:.2}", 100.0 * x)
    } else {
        "–".into()
    }
}

/// Waveforms of the scalar reading (high-passed at 2 Hz) before and after
/// the model over a 5 s excerpt, and their Welch spectra (10 s segments).
fn before_after(s: &RotorStudy, t: &[f64], mag: &[f64]) -> Result<Vec<Block>> {
    use aeromag_compensation::rotor::linear::highpass;
    use aeromag_core::spectrum::welch::{WelchConfig, welch};
    let fs = (t.len() - 1) as f64 / (t[t.len() - 1] - t[0]);
    let after: Vec<f64> = mag
        .iter()
        .zip(&s.prediction_nt)
        .map(|(m, p)| m - p)
        .collect();
    let (hb, ha) = (highpass(mag, fs, 2.0)?, highpass(&after, fs, 2.0)?);
    let mid = t.len() / 2;
    let r = mid..(mid + (5.0 * fs) as usize).min(t.len());
    let wave = LinePlot::new(
        "Scalar reading above 2 Hz before and after the rotor model (5 s excerpt)",
        "time (s)",
        "nT",
    )
    .with_series(Series::line(
        "before",
        t[r.clone()].to_vec(),
        hb[r.clone()].to_vec(),
    ))
    .with_series(Series::line(
        "after the model",
        t[r.clone()].to_vec(),
        ha[r].to_vec(),
    ));
    let cfg = WelchConfig::new(fs, ((10.0 * fs) as usize).min(mag.len()));
    let (pb, pa) = (
        welch(&hb[EDGE..hb.len() - EDGE], &cfg)?,
        welch(&ha[EDGE..ha.len() - EDGE], &cfg)?,
    );
    let keep = |f: &[f64], v: &[f64]| -> (Vec<f64>, Vec<f64>) {
        f.iter()
            .zip(v)
            .filter(|(f, _)| **f > 0.0)
            .map(|(f, v)| (*f, *v))
            .unzip()
    };
    let (fb, vb) = keep(&pb.freqs_hz, &pb.values);
    let (fa, va) = keep(&pa.freqs_hz, &pa.values);
    let spec = LinePlot::new(
        "Power spectral density before and after the rotor model",
        "frequency (Hz)",
        "nT²/Hz",
    )
    .with_series(Series::line("before", fb, vb))
    .with_series(Series::line("after the model", fa, va))
    .log_log();
    Ok(vec![
        Block::Figure {
            svg: wave.to_svg()?,
            caption: "Measured scalar field above 2 Hz (rotor interference, anomaly edges, noise) before and after \
                      subtracting the modelled rotor interference."
                .into(),
        },
        Block::Figure {
            svg: spec.to_svg()?,
            caption: format!(
                "Welch spectra (10 s Hann segments) of the high-passed reading: the peaks at f_r = {:.2} Hz, the \
                 blade-passing frequency and their harmonics disappear after the model.",
                s.rotor_hz
            ),
        },
    ])
}

fn section(s: &RotorStudy, t: &[f64], rotor: &[f64], mag: &[f64]) -> Result<ReportSection> {
    let mut sec = ReportSection::new("Helicopter rotor interference (seed 000, ch. 3)");
    sec.blocks.push(Block::Paragraph(format!(
        "Rotor interference {:.3} nT RMS at the sensor (f_r = {:.3} Hz), anomaly {:.3} nT RMS. The physical model \
         leaves {:.4} nT ({:.1} % of the rotor RMS); the best filter leaves {:.4} nT ({:.1}× the model's residual).",
        s.rotor_rms_nt,
        s.rotor_hz,
        s.anomaly_rms_nt,
        s.residual_model_nt,
        100.0 * s.residual_model_nt / s.rotor_rms_nt,
        s.residual_best_filter_nt,
        s.residual_best_filter_nt / s.residual_model_nt
    )));
    let rows = s
        .methods
        .iter()
        .map(|m| {
            vec![
                m.name.clone(),
                format!("{:.4}", m.residual_nt),
                pct(m.residual_nt / s.rotor_rms_nt),
                pct(m.removed_anomaly),
                pct(m.removed_bumps_05),
                pct(m.removed_bumps_01),
            ]
        })
        .collect();
    sec.blocks.push(Block::Table(Table::new(
        [
            "method",
            "residual rotor (nT RMS)",
            "of rotor RMS (%)",
            "anomaly removed (%)",
            "0.5 s bumps removed (%)",
            "0.1 s bumps removed (%)",
        ]
        .map(String::from)
        .to_vec(),
        rows,
        "Residual rotor interference and signal removed by each method (3 s excluded at each end).",
    )));
    // 20 s excerpt from the middle of the record.
    let mid = t.len() / 2;
    let n = ((20.0 / (t[1] - t[0]).max(1e-9)) as usize).min(mid);
    let r = mid - n / 2..mid + n / 2;
    let resid: Vec<f64> = rotor[r.clone()]
        .iter()
        .zip(&s.prediction_nt[r.clone()])
        .map(|(a, b)| a - b)
        .collect();
    let p = LinePlot::new(
        "Rotor interference and model residual (20 s excerpt)",
        "time (s)",
        "nT",
    )
    .with_series(Series::line(
        "true rotor interference",
        t[r.clone()].to_vec(),
        rotor[r.clone()].to_vec(),
    ))
    .with_series(Series::line(
        "residual after the model",
        t[r].to_vec(),
        resid,
    ));
    sec.blocks.push(Block::Figure {
        svg: p.to_svg()?,
        caption: "True rotor interference and what the model leaves.".into(),
    });
    sec.blocks.extend(before_after(s, t, mag)?);
    Ok(sec)
}
