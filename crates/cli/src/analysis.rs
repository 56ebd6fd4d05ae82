//! Quality figures of a compensated flight and the report sections that
//! show them. Shared by `aeromag report` and `aeromag demo`.
//!
//! Input is a flight table with `time`, `mag` and `mag_comp` (as written by
//! `aeromag compensate`), optionally `mag_interf`, attitude (`roll`,
//! `pitch`, `yaw`, for the FOM windows), `line`, and — for simulated data —
//! the truth columns `true_external`, `true_interf`, `true_lag`,
//! `true_mag_noise`. Truth is used only to *score* results, never to
//! compute them.

use crate::flight::reference_sum;
use aeromag_compensation::metrics::{
    FomReport, LineResidual, ManeuverDetection, band_pass_segments, detect_maneuvers,
    figure_of_merit, improvement_ratio, residual_by_line,
};
use aeromag_compensation::model_file::TlModel;
use aeromag_compensation::reference_field::LeverArm;
use aeromag_compensation::tolles_lawson::segments::{median_step, split_segments};
use aeromag_core::filter::BandPass;
use aeromag_core::spectrum::{WelchConfig, welch};
use aeromag_io::FlightTable;
use aeromag_report::{LinePlot, Report, Series, Table};
use serde::Serialize;
use std::ops::Range;

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
    #[serde(skip)]
    fom_before: Option<FomReport>,
    #[serde(skip)]
    fom_after: Option<FomReport>,
}

/// Segments of rows where `mag` and `mag_comp` are finite, split at lines and gaps.
fn segments(t: &FlightTable, comp: &[f64]) -> anyhow::Result<Vec<Range<usize>>> {
    let time = t.require("time")?;
    let mag = t.require("mag")?;
    let usable: Vec<bool> = (0..time.len())
        .map(|i| mag[i].is_finite() && comp[i].is_finite())
        .collect();
    Ok(split_segments(time, t.column("line"), &usable, 1.5, 2).0)
}

/// Compute the figures of a compensated table.
///
/// FOM and IR are computed on the readings reduced by the `reference`
/// channels (known external field: base station, IGRF) and band-passed with
/// the default compensation band (0.1–0.9 Hz, order 4) leg by leg, so they
/// measure the aircraft's interference, not the geology or the diurnal
/// variation. The residual versus truth is pooled over survey lines: rows
/// whose `line` label is 0 (turns, in the simulator's convention) are not
/// survey data and are left out. With a lever arm the `igrf` reference is
/// moved to the sensor ([`reference_sum`]).
pub fn figures(
    t: &FlightTable,
    reference: &[String],
    lever: Option<&LeverArm>,
) -> anyhow::Result<Figures> {
    let time = t.require("time")?;
    let ref_sum = reference_sum(t, reference, lever)?;
    let mag: Vec<f64> = t
        .require("mag")?
        .iter()
        .zip(&ref_sum)
        .map(|(a, b)| a - b)
        .collect();
    let comp_raw = t.require("mag_comp")?;
    let comp: Vec<f64> = comp_raw.iter().zip(&ref_sum).map(|(a, b)| a - b).collect();
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

fn f3(v: Option<f64>) -> String {
    v.map_or("—".into(), |x| format!("{x:.3}"))
}

/// Add the sections describing a compensated flight to a report.
pub fn add_to_report(
    r: &mut Report,
    title: &str,
    t: &FlightTable,
    fig: &Figures,
    model: Option<&TlModel>,
) -> anyhow::Result<()> {
    let time = t.require("time")?;
    let mag = t.require("mag")?;
    let comp = t.require("mag_comp")?;
    let t0 = time.first().copied().unwrap_or(0.0);
    let tt: Vec<f64> = time.iter().map(|v| v - t0).collect();
    r.section(title);
    let mut kv = vec![
        ("rows".to_string(), t.n_rows().to_string()),
        ("FOM before (nT)".into(), f3(fig.fom_before_nt)),
        ("FOM after (nT)".into(), f3(fig.fom_after_nt)),
        ("manoeuvre windows".into(), fig.fom_windows.to_string()),
        ("improvement ratio".into(), f3(fig.ir)),
    ];
    if let Some(v) = fig.residual_rms_nt {
        kv.push(("residual vs truth, RMS (nT)".into(), format!("{v:.4}")));
    }
    if let Some(v) = fig.noise_floor_nt {
        kv.push(("scalar sensor noise floor (nT)".into(), format!("{v:.4}")));
    }
    r.key_values(kv);

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
    .with_series(Series::line(
        "uncompensated",
        tt.clone(),
        mag.iter().map(|v| v - mm).collect(),
    ))
    .with_series(Series::line(
        "compensated",
        tt.clone(),
        comp.iter().map(|v| v - cm).collect(),
    ))
    .to_svg()?;
    r.figure(svg, "Scalar magnetometer before and after compensation.");

    if let Some(model_interf) = t.column("mag_interf") {
        let mi = mean(model_interf);
        let mut p = LinePlot::new(
            "Aircraft interference: model and truth (means removed)",
            "time since start (s)",
            "interference (nT)",
        )
        .with_series(Series::line(
            "model",
            tt.clone(),
            model_interf.iter().map(|v| v - mi).collect(),
        ));
        if let Some(ti) = t.column("true_interf") {
            let m = mean(ti);
            p = p.with_series(Series::line(
                "truth (simulation)",
                tt.clone(),
                ti.iter().map(|v| v - m).collect(),
            ));
        }
        r.figure(
            p.to_svg()?,
            "Modelled interference against the simulator's truth where available.",
        );
    }

    if let Some(ext) = t.column("true_external") {
        let lag = t.column("true_lag");
        let res: Vec<f64> = (0..comp.len())
            .map(|i| comp[i] - ext[i] - lag.map_or(0.0, |l| l[i]))
            .collect();
        let rm = mean(&res);
        let svg = LinePlot::new(
            "Residual versus truth",
            "time since start (s)",
            "compensated − truth (nT)",
        )
        .with_series(Series::line(
            "residual",
            tt.clone(),
            res.iter().map(|v| v - rm).collect(),
        ))
        .to_svg()?;
        r.figure(svg, "Compensated field minus the true external field (sensor lag term removed), mean removed.");
    }

    // Welch spectra over the longest finite run of each signal.
    let fs = 1.0 / median_step(time);
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
                m.terms, m.method, m.convention
            ),
        ));
        if !m.fit.warnings.is_empty() {
            r.paragraph(format!("Fit warnings: {}", m.fit.warnings.join(" | ")));
        }
    }
    Ok(())
}
