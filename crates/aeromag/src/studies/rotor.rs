//! The helicopter rotor study (seed 000 ch. 3): the physical rotor model
//! against the filter baselines on the simulated `helicopter` scenario —
//! residual rotor interference and the share of anomaly signal each
//! method removes (`aeromag rotor study`, the demo's `rotor` group).

use super::{PrintedFigure, PrintedSummary, Study, StudyOutcome, StudySize, fixed};
use crate::error::{Error, Result};
use crate::observer::Observer;
use aeromag_compensation::rotor::study::{
    MethodResult, RotorStudy, StudyInput, evaluate, scenario_geometry, scenario_tail_rotor, std_mid,
};
use aeromag_compensation::rotor::{RotorGeometry, TailRotor};
use aeromag_report::{Block, LinePlot, ReportSection, Series, Table};
use aeromag_sim::platform::rotor::RotorConfig;
use aeromag_sim::platform::tail_rotor::TailRotorConfig;
use aeromag_sim::scenario::helicopter::{self, HelicopterConfig, helicopter_defaults};
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
    /// Residuals and removed signal of every method on the default rotor.
    pub study: RotorStudy,
    /// The same on a rotor that satisfies the simplified model's
    /// assumptions ([`RotorConfig::simplified`]).
    pub ideal: RotorStudy,
    /// The default rotor with the tail rotor, seen from a sensor under the
    /// tail boom ([`TAIL_BOOM_SENSOR_M`]), fitted with and without it.
    pub tail: RotorStudy,
    /// RMS of the tail rotor's part at that sensor, nT.
    pub tail_rms_tail_boom_nt: f64,
    /// RMS of the tail rotor's part at the default nose-boom sensor, nT.
    pub tail_rms_nose_nt: f64,
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
    /// The thesis' simplified model (3 per blade, nominal cone): residual
    /// over the rotor RMS on a rotor that satisfies its assumptions.
    pub simplified_fraction_ideal_rotor: f64,
    /// … on the default (richer) rotor.
    pub simplified_fraction_default_rotor: f64,
    /// The best filter's residual over the rotor RMS on the ideal rotor.
    pub best_filter_fraction_ideal_rotor: f64,
    /// The best filter's residual over the rotor RMS on the default rotor.
    pub best_filter_fraction_default_rotor: f64,
    /// With a tail rotor (sensor under the tail boom): residual over the
    /// rotor RMS with the main and the tail rotor modelled.
    pub tail_residual_fraction: f64,
    /// … with the main rotor only.
    pub tail_unmodelled_residual_fraction: f64,
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
            simplified_fraction_ideal_rotor: self.ideal.residual_simplified_nt
                / self.ideal.rotor_rms_nt,
            simplified_fraction_default_rotor: s.residual_simplified_nt / s.rotor_rms_nt,
            best_filter_fraction_ideal_rotor: self.ideal.residual_best_filter_nt
                / self.ideal.rotor_rms_nt,
            best_filter_fraction_default_rotor: s.residual_best_filter_nt / s.rotor_rms_nt,
            tail_residual_fraction: self.tail.residual_with_tail_nt.unwrap_or(f64::NAN)
                / self.tail.rotor_rms_nt,
            tail_unmodelled_residual_fraction: self.tail.residual_model_nt / self.tail.rotor_rms_nt,
        }
    }

    fn section(&self) -> Result<ReportSection> {
        let mut sec = section(&self.study, &self.time_s, &self.true_rotor_nt, &self.mag_nt)?;
        sec.blocks.extend(simplified_and_tail_blocks(self));
        Ok(sec)
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
            PrintedFigure::new(
                "rotor.simplified_fraction_ideal_rotor",
                fixed(Some(self.simplified_fraction_ideal_rotor), 4),
            ),
            PrintedFigure::new(
                "rotor.simplified_fraction_default_rotor",
                fixed(Some(self.simplified_fraction_default_rotor), 4),
            ),
            PrintedFigure::new(
                "rotor.tail_residual_fraction",
                fixed(Some(self.tail_residual_fraction), 4),
            ),
        ]
    }
}

/// Samples excluded at each end (3 s at 100 Hz: filter transients).
const EDGE: usize = 300;

/// The scalar sensor and fluxgate of the tail-rotor case: under the tail
/// boom, 10 m behind the main rotor shaft (body axes, m), 4 m from the tail
/// rotor's hub (at the default nose boom the tail rotor's part is two
/// orders of magnitude below the main rotor's).
pub const TAIL_BOOM_SENSOR_M: [f64; 3] = [-10.0, 0.0, 0.3];

/// One simulated record and its comparison.
struct Case {
    study: RotorStudy,
    time_s: Vec<f64>,
    true_rotor_nt: Vec<f64>,
    mag_nt: Vec<f64>,
    true_tail_rotor_nt: Option<Vec<f64>>,
}

/// Simulate `cfg` and run the comparison with the main rotor geometry
/// `geom` (and `tail`, fitted jointly when given).
fn run_case(
    cfg: &HelicopterConfig,
    geom: &RotorGeometry,
    tail: Option<&TailRotor>,
) -> Result<Case> {
    let sim = helicopter::run(cfg)?;
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
    let study = evaluate(
        geom,
        &StudyInput {
            mag_nt: col("mag")?,
            b_body_nt: &b,
            rotor_phase_deg: col("rotor_phase")?,
            true_rotor_nt: col("true_rotor")?,
            true_anomaly_nt: col("true_anomaly")?,
            fs_hz: fs,
            edge: EDGE,
            tail,
        },
    )?;
    Ok(Case {
        study,
        time_s: t.to_vec(),
        true_rotor_nt: col("true_rotor")?.to_vec(),
        mag_nt: col("mag")?.to_vec(),
        true_tail_rotor_nt: sim.column("true_tail_rotor").map(<[f64]>::to_vec),
    })
}

/// Simulate the scenario with `seed` and run the comparison on the default
/// rotor, keeping time (s), the true rotor interference (nT) and the scalar
/// reading (nT) for the plots; then the same on the ideal rotor and on the
/// rotor with its tail rotor.
fn run_study(seed: u64) -> Result<RotorOutcome> {
    let base = HelicopterConfig::parse_over(helicopter_defaults(), None, Some(seed))?;
    let geom = scenario_geometry();
    let main = run_case(&base, &geom, None)?;
    let ideal = HelicopterConfig {
        rotor: RotorConfig::simplified(),
        ..base.clone()
    };
    let ideal = run_case(&ideal, &geom, None)?;
    let mut with_tail = HelicopterConfig {
        tail_rotor: Some(TailRotorConfig::default()),
        ..base.clone()
    };
    let nose_tail = run_case(&with_tail, &geom, None)?;
    with_tail.base.scalar.position_m = TAIL_BOOM_SENSOR_M;
    with_tail.base.fluxgate.position_m = [
        TAIL_BOOM_SENSOR_M[0] + 0.5,
        TAIL_BOOM_SENSOR_M[1],
        TAIL_BOOM_SENSOR_M[2],
    ];
    let tail_geom = RotorGeometry {
        sensor_m: TAIL_BOOM_SENSOR_M,
        ..geom
    };
    let tail_model = scenario_tail_rotor(TAIL_BOOM_SENSOR_M);
    let tail = run_case(&with_tail, &tail_geom, Some(&tail_model))?;
    let rms = |c: &Case| {
        c.true_tail_rotor_nt
            .as_deref()
            .map_or(f64::NAN, |v| std_mid(v, EDGE))
    };
    Ok(RotorOutcome {
        tail_rms_tail_boom_nt: rms(&tail),
        tail_rms_nose_nt: rms(&nose_tail),
        study: main.study,
        ideal: ideal.study,
        tail: tail.study,
        time_s: main.time_s,
        true_rotor_nt: main.true_rotor_nt,
        mag_nt: main.mag_nt,
    })
}

/// The report's table of the simplified model and of the tail-rotor case.
fn simplified_and_tail_blocks(o: &RotorOutcome) -> Vec<Block> {
    let row = |case: &str, s: &RotorStudy, m: &MethodResult| {
        vec![
            case.to_string(),
            m.name.clone(),
            format!("{:.4}", m.residual_nt),
            pct(m.residual_nt / s.rotor_rms_nt),
        ]
    };
    // Every model, then the best filter, of one case.
    let case_rows = |case: &str, s: &RotorStudy| -> Vec<Vec<String>> {
        s.methods
            .iter()
            .filter(|m| !m.is_filter)
            .chain(s.best_filter())
            .map(|m| row(case, s, m))
            .collect()
    };
    let mut rows = case_rows("default rotor", &o.study);
    rows.extend(case_rows("ideal rotor", &o.ideal));
    let verdict = |s: &RotorStudy| {
        format!(
            "{} the best filter ({:.1} % against {:.1} %)",
            if s.residual_simplified_nt < s.residual_best_filter_nt {
                "beats"
            } else {
                "does not beat"
            },
            100.0 * s.residual_simplified_nt / s.rotor_rms_nt,
            100.0 * s.residual_best_filter_nt / s.rotor_rms_nt
        )
    };
    let t = &o.tail;
    let tail_cfg = TailRotorConfig::default();
    let with = t.residual_with_tail_nt.unwrap_or(f64::NAN);
    let tail_rows = case_rows("tail-boom sensor", t);
    let header = [
        "case",
        "method",
        "residual rotor (nT RMS)",
        "of rotor RMS (%)",
    ]
    .map(String::from)
    .to_vec();
    vec![
        Block::Paragraph(format!(
            "The thesis' simplified model (§16: blades turning uniformly in a fixed plane, hard and soft \
             magnetisation along the blade, eddy currents without lag; 3 parameters per blade) on a rotor that \
             satisfies these assumptions {}; on the default rotor (magnetisation across the spar, lagging eddy \
             currents, coning and tilt that follow the load, ±1 % speed) it {}: its prediction of the slow part \
             of the rotor field is then wrong. The full model (7 per blade) with the slowly varying cone is \
             needed there.",
            verdict(&o.ideal),
            verdict(&o.study)
        )),
        Block::Table(Table::new(
            header.clone(),
            rows,
            "The simplified and the full model and the best filter on the default rotor and on a rotor that \
             satisfies the simplified model's assumptions (same flight, seed and sensor).",
        )),
        Block::Paragraph(format!(
            "Tail rotor ({} blades, geared {}:1 to the main rotor, {:.1} Hz): at the nose-boom sensor its part is \
             {:.4} nT RMS, negligible; at a sensor under the tail boom, 4 m from its hub, it is {:.3} nT of {:.3} nT \
             rotor interference. Modelled jointly with the main rotor (its phase from the main rotor's through the \
             gear ratio, the offset estimated: {:.2}°, simulated {}°), the residual falls from {:.4} nT ({:.1} %) to \
             {:.4} nT ({:.1} %).",
            tail_cfg.blades.len(),
            tail_cfg.gear_ratio,
            tail_cfg.gear_ratio * t.rotor_hz,
            o.tail_rms_nose_nt,
            o.tail_rms_tail_boom_nt,
            t.rotor_rms_nt,
            t.tail_offset_rad.unwrap_or(f64::NAN).to_degrees(),
            tail_cfg.phase_offset_deg,
            t.residual_model_nt,
            100.0 * t.residual_model_nt / t.rotor_rms_nt,
            with,
            100.0 * with / t.rotor_rms_nt
        )),
        Block::Table(Table::new(
            header,
            tail_rows,
            "Main and tail rotor interference at a sensor under the tail boom: the model without and with the tail \
             rotor, and the best filter.",
        )),
    ]
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
