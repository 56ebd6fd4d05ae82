//! `aeromag calibrate`: fit a Tolles-Lawson model on a calibration flight.

use crate::exit::bad_input;
use crate::flight::{parse_band, reference_columns, reference_sum, TlColumns};
use crate::input::InputArgs;
use aeromag_compensation::model_file::{Coefficient, FitStats, TlModel, MODEL_FORMAT};
use aeromag_compensation::tolles_lawson::fit_ls::{fit_band_pass_ls, LsConfig, Segment};
use aeromag_compensation::tolles_lawson::{Convention, TermSet};
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
    /// Fitting method: ls (band-pass least squares).
    #[arg(long, default_value = "ls")]
    method: String,
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

pub fn run(a: Args) -> anyhow::Result<()> {
    if a.method != "ls" {
        return Err(bad_input!("--method {}: only `ls` is available in this version", a.method));
    }
    let cfg = config(&a)?;
    let table = a.input.load()?;
    let model = fit_model(&table, &cfg, !a.no_split_lines, &a.reference)?;
    std::fs::write(&a.model, model.to_json()?)
        .map_err(|e| anyhow::anyhow!("cannot write model file '{}': {e}", a.model.display()))?;
    println!(
        "fitted {} terms ({}) on {} rows in {} legs: residual {:.4} nT RMS (band-passed), condition {:.2e}",
        model.coefficients.len(),
        cfg.terms,
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
