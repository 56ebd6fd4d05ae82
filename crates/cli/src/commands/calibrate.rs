//! `aeromag calibrate`: fit a Tolles-Lawson model on a calibration flight.

use crate::exit::bad_input;
use crate::flight::{parse_band, reference_columns, reference_sum, TlColumns};
use crate::input::InputArgs;
use aeromag_compensation::model_file::{Coefficient, FitStats, TlModel, MODEL_FORMAT};
use aeromag_compensation::tolles_lawson::fit_ls::{fit_band_pass_ls, LsConfig, Segment};
use aeromag_compensation::tolles_lawson::{Convention, TermSet};
use aeromag_compensation::kalman::{
    fit_kalman, ground_speed_from_positions, ground_speed_from_velocity, KalmanConfig, KalmanFit, KalmanSegment,
};
use aeromag_io::FlightTable;
use std::path::PathBuf;

/// Fit the aircraft's magnetic interference model (Tolles-Lawson / Leliak)
/// on a calibration flight and save it as a model file (JSON).
///
/// Method `ls`: band-pass least squares (Butterworth order 4, zero-phase,
/// default 0.1–0.9 Hz, 20 samples trimmed at each end of each leg), the
/// industry and MagNav.jl baseline. The flight is split into legs at changes
/// of the `line` column, at time gaps and at missing values; each leg is
/// filtered on its own. Terms not determined by the flight (one heading,
/// missing manoeuvres) are named in a warning.
///
/// Example:
///   aeromag calibrate --input cal.csv --model model.json
///   aeromag calibrate --input cal.csv --model m.json --terms p3,i6,e9 --convention magnav --lambda 0.01
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct Args {
    #[command(flatten)]
    input: InputArgs,
    /// Where to write the model file (JSON).
    #[arg(long, value_name = "MODEL.json")]
    model: PathBuf,
    /// Fitting method: `ls` (band-pass least squares) or `kalman` (Kalman
    /// filter and smoother with a stochastic model of the external field;
    /// needs `alt` and ground speed from `vn`,`ve` or positions).
    #[arg(long, default_value = "ls")]
    method: String,
    /// With --method kalman: tune the noise intensities q1, q2, r by maximum
    /// likelihood of the innovations (otherwise the documented defaults).
    #[arg(long)]
    tune: bool,
    /// Term groups: p3, i6 or i5, e9 or e8, bias (comma-separated).
    #[arg(long, default_value = "p3,i5,e8")]
    terms: String,
    /// Derivative convention of the eddy terms: physical (nT/s) or magnav
    /// (MagNav.jl create_TL_A: per-sample central difference).
    #[arg(long, default_value = "physical")]
    convention: String,
    /// Ridge parameter λ ≥ 0.
    #[arg(long, default_value_t = 0.0)]
    lambda: f64,
    /// Pass band LO,HI in Hz, or `none` to fit unfiltered data.
    #[arg(long, default_value = "0.1,0.9")]
    band: String,
    /// Samples trimmed at each end of each filtered leg.
    #[arg(long, default_value_t = 20)]
    trim: usize,
    /// Scale of the induced and eddy columns, nT.
    #[arg(long, default_value_t = 50_000.0)]
    bt_scale: f64,
    /// Treat the whole file as one leg (ignore the `line` column).
    #[arg(long)]
    no_split_lines: bool,
    /// Known external-field channels subtracted from `mag` before the fit:
    /// `auto` (the `diurnal` and `igrf` columns when present), `none`
    /// (MagNav.jl's way), or a comma-separated list of columns.
    #[arg(long, default_value = "auto")]
    reference: String,
}

/// Build the LS configuration from the command-line flags.
fn config(a: &Args) -> anyhow::Result<LsConfig> {
    let terms = TermSet::parse(&a.terms).map_err(|e| bad_input!("--terms: {e}"))?;
    let convention: Convention = a.convention.parse().map_err(|e| bad_input!("--convention: {e}"))?;
    let band_hz = if a.band.trim().eq_ignore_ascii_case("none") { None } else { Some(parse_band(&a.band)?) };
    if !(a.lambda >= 0.0 && a.lambda.is_finite()) {
        return Err(bad_input!("--lambda {} must be ≥ 0", a.lambda));
    }
    if !(a.bt_scale > 0.0 && a.bt_scale.is_finite()) {
        return Err(bad_input!("--bt-scale {} must be > 0", a.bt_scale));
    }
    Ok(LsConfig { terms, convention, bt_scale_nt: a.bt_scale, band_hz, trim: a.trim, lambda: a.lambda, ..LsConfig::default() })
}

/// Fit a model on a loaded calibration table; warnings go to stderr.
pub fn fit_model(table: &FlightTable, cfg: &LsConfig, split_lines: bool, reference: &str) -> anyhow::Result<TlModel> {
    let cols = TlColumns::from_table(table)?;
    let ref_cols = reference_columns(table, reference)?;
    let ref_sum = reference_sum(table, &ref_cols)?;
    let y: Vec<f64> = cols.mag.iter().zip(&ref_sum).map(|(m, r)| m - r).collect();
    let cols = TlColumns { mag: &y, ..cols };
    let (segs, _) = cols.segments(split_lines, 1);
    let left_out = cols.usable().iter().filter(|u| !**u).count();
    if left_out > 0 {
        eprintln!("warning: {} of {} rows have missing values and are not used by the fit", left_out, table.n_rows());
    }
    let segments: Vec<Segment> = segs
        .iter()
        .map(|r| Segment {
            time: &cols.time[r.clone()],
            flux: [&cols.flux[0][r.clone()], &cols.flux[1][r.clone()], &cols.flux[2][r.clone()]],
            mag: &cols.mag[r.clone()],
        })
        .collect();
    let spinner = crate::progress::spinner("fitting");
    let fit = fit_band_pass_ls(&segments, cfg).map_err(|e| bad_input!("{}: {e}", table.file_label()))?;
    spinner.finish_and_clear();
    for w in &fit.warnings {
        eprintln!("warning: {w}");
    }
    Ok(TlModel {
        format: MODEL_FORMAT.into(),
        kind: "tolles-lawson".into(),
        method: "ls".into(),
        terms: cfg.terms.clone(),
        convention: cfg.convention,
        bt_scale_nt: cfg.bt_scale_nt,
        band_hz: cfg.band_hz,
        filter_order: cfg.filter_order,
        trim: cfg.trim,
        lambda: cfg.lambda,
        coefficients: fit
            .names
            .iter()
            .zip(fit.coef.iter().zip(&fit.std))
            .map(|(n, (v, s))| Coefficient { name: n.clone(), value: *v, std: *s })
            .collect(),
        fit: FitStats {
            rows: fit.rows,
            segments: fit.segments_used,
            condition: fit.condition,
            residual_rms_nt: fit.residual_rms_nt,
            warnings: fit.warnings.clone(),
        },
        columns: ["time", "flux_x", "flux_y", "flux_z", "mag"]
            .iter()
            .map(|c| c.to_string())
            .chain(ref_cols.iter().cloned())
            .map(|c| {
                let file = table.resolve(&c).unwrap_or(&c).to_string();
                (c, file)
            })
            .collect(),
        reference: ref_cols,
        software_version: env!("CARGO_PKG_VERSION").into(),
    })
}

/// Ground speed (m/s) from `vn`, `ve` when present, else from the positions.
fn ground_speed(table: &FlightTable) -> anyhow::Result<Vec<f64>> {
    Ok(match (table.column("vn"), table.column("ve")) {
        (Some(vn), Some(ve)) => ground_speed_from_velocity(vn, ve),
        _ => ground_speed_from_positions(table.require("time")?, table.require("lat")?, table.require("lon")?),
    })
}

/// Fit a model with the Kalman method on a loaded calibration table.
pub fn fit_model_kalman(
    table: &FlightTable,
    cfg: &KalmanConfig,
    split_lines: bool,
    reference: &str,
) -> anyhow::Result<(TlModel, KalmanFit)> {
    let cols = TlColumns::from_table(table)?;
    let ref_cols = reference_columns(table, reference)?;
    let ref_sum = reference_sum(table, &ref_cols)?;
    let y: Vec<f64> = cols.mag.iter().zip(&ref_sum).map(|(m, r)| m - r).collect();
    let alt = table.require("alt")?;
    let speed = ground_speed(table)?;
    let cols = TlColumns { mag: &y, ..cols };
    let (segs, _) = cols.segments(split_lines, 1);
    let segments: Vec<KalmanSegment> = segs
        .iter()
        .map(|r| KalmanSegment {
            data: Segment {
                time: &cols.time[r.clone()],
                flux: [&cols.flux[0][r.clone()], &cols.flux[1][r.clone()], &cols.flux[2][r.clone()]],
                mag: &cols.mag[r.clone()],
            },
            alt_m: &alt[r.clone()],
            speed_m_s: &speed[r.clone()],
        })
        .collect();
    let spinner = crate::progress::spinner("Kalman filter and smoother");
    let fit = fit_kalman(&segments, cfg).map_err(|e| bad_input!("{}: {e}", table.file_label()))?;
    spinner.finish_and_clear();
    for w in &fit.warnings {
        eprintln!("warning: {w}");
    }
    let mut model = fit.to_model(cfg);
    model.reference = ref_cols.clone();
    model.columns = ["time", "flux_x", "flux_y", "flux_z", "mag", "alt"]
        .iter()
        .map(|c| c.to_string())
        .chain(ref_cols)
        .map(|c| {
            let file = table.resolve(&c).unwrap_or(&c).to_string();
            (c, file)
        })
        .collect();
    Ok((model, fit))
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let table = a.input.load()?;
    let model = match a.method.as_str() {
        "ls" => fit_model(&table, &config(&a)?, !a.no_split_lines, &a.reference)?,
        "kalman" => {
            let ls = config(&a)?;
            let mut cfg = KalmanConfig { terms: ls.terms, convention: ls.convention, bt_scale_nt: ls.bt_scale_nt, ..KalmanConfig::default() };
            cfg.tuning.enabled = a.tune;
            let (model, fit) = fit_model_kalman(&table, &cfg, !a.no_split_lines, &a.reference)?;
            println!(
                "noise intensities: q1 = {:.3e} nT²/m⁵, q2 = {:.3e} nT²/m⁵, r = {:.3e} nT² ({})",
                fit.noise.q1_nt2_per_m5,
                fit.noise.q2_nt2_per_m5,
                fit.noise.r_nt2,
                if fit.tuning.is_some() { "tuned by maximum likelihood" } else { "defaults" }
            );
            model
        }
        m => return Err(bad_input!("--method {m}: use `ls` or `kalman`")),
    };
    let cfg_terms = model.terms.clone();
    std::fs::write(&a.model, model.to_json()?)
        .map_err(|e| anyhow::anyhow!("cannot write model file '{}': {e}", a.model.display()))?;
    println!(
        "fitted {} terms ({}, method {}) on {} rows in {} legs: residual {:.4} nT RMS, condition {:.2e}",
        model.coefficients.len(),
        cfg_terms,
        model.method,
        model.fit.rows,
        model.fit.segments,
        model.fit.residual_rms_nt,
        model.fit.condition
    );
    println!("{:<8} {:>14} {:>12}", "term", "coefficient", "std");
    for c in &model.coefficients {
        println!("{:<8} {:>14.6} {:>12.3e}", c.name, c.value, c.std);
    }
    println!("model written to {}", a.model.display());
    Ok(())
}
