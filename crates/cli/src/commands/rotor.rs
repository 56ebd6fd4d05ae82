//! `aeromag rotor`: helicopter main-rotor interference (spec `helicopter.md`
//! part A, seed 000 ch. 3; library `aeromag_compensation::rotor`).

use crate::report_section::{Block, ReportSection};
use aeromag_compensation::rotor::study::{RotorStudy, StudyInput, evaluate, scenario_geometry};
use aeromag_report::{LinePlot, Report, Series, Table};
use aeromag_sim::{ScenarioKind, simulate};
use nalgebra::Vector3;
use serde_json::json;
use std::path::PathBuf;

/// Helicopter main-rotor interference: physical blade model against filters.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    command: Sub,
}

#[derive(Debug, clap::Subcommand)]
enum Sub {
    Study(StudyArgs),
    Fit(FitArgs),
    Apply(ApplyArgs),
}

/// Simulates the `helicopter` scenario (4 headings with manoeuvres, 290 rpm,
/// 4 blades, nose-boom sensor, rotor phase channel), fits the physical rotor
/// model (magnetic masses and eddy currents of each blade, slowly varying
/// cone) and the filter baselines (low-pass, notches, synchronous averaging),
/// and compares the residual rotor interference and the share of anomaly
/// signal each removes. Prints the table; writes DIR/summary.json and
/// DIR/index.html.
///
/// Example: `aeromag rotor study --out rotor-study`
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
struct StudyArgs {
    /// Output folder.
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// Seed of the simulated flight.
    #[arg(long, default_value_t = 11)]
    seed: u64,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    match a.command {
        Sub::Study(s) => study(s),
        Sub::Fit(f) => super::rotor_fit::fit(f),
        Sub::Apply(x) => super::rotor_fit::apply(x),
    }
}

pub use super::rotor_fit::{ApplyArgs, FitArgs};

/// Samples excluded at each end (3 s at 100 Hz: filter transients).
const EDGE: usize = 300;

/// The study, time (s), true rotor interference (nT), scalar reading (nT).
type StudyRun = (RotorStudy, Vec<f64>, Vec<f64>, Vec<f64>);

/// Simulate the scenario with `seed` and run the comparison; also returns
/// time (s), the true rotor interference (nT) and the scalar reading (nT)
/// for the plots.
fn run_study(seed: u64) -> anyhow::Result<StudyRun> {
    let sim = simulate(ScenarioKind::Helicopter, None, Some(seed))?;
    let col = |n: &str| {
        sim.column(n)
            .ok_or_else(|| anyhow::anyhow!("helicopter scenario has no column {n}"))
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
    Ok((
        st,
        t.to_vec(),
        col("true_rotor")?.to_vec(),
        col("mag")?.to_vec(),
    ))
}

/// The `rotor.*` keys of `aeromag demo`'s summary (data-formats.md).
fn summary_json(s: &RotorStudy) -> serde_json::Value {
    json!({
        "rotor_rms_nt": s.rotor_rms_nt,
        "residual_model_nt": s.residual_model_nt,
        "residual_best_filter_nt": s.residual_best_filter_nt,
        "anomaly_rms_nt": s.anomaly_rms_nt,
        "rotor_hz": s.rotor_hz,
    })
}

fn pct(x: f64) -> String {
    if x.is_finite() {
        format!("{:.2}", 100.0 * x)
    } else {
        "–".into()
    }
}

/// Waveforms of the scalar reading (high-passed at 2 Hz) before and after
/// the model over a 5 s excerpt, and their Welch spectra (10 s segments).
fn before_after(s: &RotorStudy, t: &[f64], mag: &[f64]) -> anyhow::Result<Vec<Block>> {
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

fn section(s: &RotorStudy, t: &[f64], rotor: &[f64], mag: &[f64]) -> anyhow::Result<ReportSection> {
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

/// The study for `aeromag demo` (seed 11): the `rotor.*` summary object
/// (`rotor_rms_nt`, `residual_model_nt`, `residual_best_filter_nt`,
/// `anomaly_rms_nt`, `rotor_hz`) and the report section. `quick` is
/// accepted for symmetry with [`super::em::demo_em`]; the study has one size.
pub fn demo_rotor(quick: bool) -> anyhow::Result<(serde_json::Value, Option<ReportSection>)> {
    let _ = quick;
    let (s, t, rotor, mag) = run_study(11)?;
    Ok((summary_json(&s), Some(section(&s, &t, &rotor, &mag)?)))
}

fn study(a: StudyArgs) -> anyhow::Result<()> {
    let bar = crate::progress::bar(1, "rotor study");
    bar.set_message("simulating and fitting");
    let (s, t, rotor, mag) = run_study(a.seed)?;
    bar.inc(1);
    bar.finish_and_clear();
    println!(
        "rotor interference RMS {:.3} nT, anomaly RMS {:.3} nT, f_r {:.3} Hz",
        s.rotor_rms_nt, s.anomaly_rms_nt, s.rotor_hz
    );
    for m in &s.methods {
        println!(
            "{:44} residual {:.4} nT ({:>6} %), removes anomaly {:>5} %, 0.5 s bumps {:>5} %, 0.1 s bumps {:>5} %",
            m.name,
            m.residual_nt,
            pct(m.residual_nt / s.rotor_rms_nt),
            pct(m.removed_anomaly),
            pct(m.removed_bumps_05),
            pct(m.removed_bumps_01)
        );
    }
    std::fs::create_dir_all(&a.out)?;
    std::fs::write(
        a.out.join("summary.json"),
        serde_json::to_string_pretty(&json!({ "rotor": summary_json(&s) }))?,
    )?;
    let mut r = Report::new("aeromag — helicopter rotor interference study");
    section(&s, &t, &rotor, &mag)?.append_to(&mut r);
    let path = a.out.join("index.html");
    r.write_html(&path)?;
    println!("report written to {}", path.display());
    Ok(())
}
