//! `aeromag observability`: what a calibration flight determines.

use crate::commands::calibrate::{EddyLag, FitOptions, fit_model_kalman};
use crate::exit::bad_input;
use crate::flight::TlColumns;
use crate::input::InputArgs;
use aeromag_compensation::kalman::KalmanConfig;
use aeromag_compensation::observability::observability;
use aeromag_compensation::tolles_lawson::TermSet;

/// Observability and estimability of the interference coefficients on a
/// calibration flight (thesis sections 10 and 12).
///
/// Runs the Kalman filter of `calibrate --method kalman` (the external field
/// is a random process along the track, so it is marginalised, not filtered
/// away) and prints: the rank and condition number of the flight's
/// information about the coefficients (scaled by their prior), the
/// combinations of coefficients the flight cannot separate, in words, and
/// the estimability measure μ = sqrt(P_post/P_prior) of every coefficient
/// (near 0: determined by this flight; near 1: not; it depends on the prior,
/// σ = 1000 per coefficient here), and — easier to judge — each term's
/// effect uncertainty in nT: its standard deviation times the size of its
/// design column over a full calibration (1 for permanent terms, |B|/50000
/// for induced, |B|·(0.1 rad/s)/50000 for eddy terms: a 6°/s manoeuvre). A term whose effect is
/// uncertain by 1 nT or more is reported as not determined.
///
/// Use it to check a calibration flight, or a simulated pattern before
/// flying it (`aeromag simulate calibration --config pattern.toml`).
///
/// Example: `aeromag observability --input cal.csv --terms p3,i5,e8`
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct Args {
    #[command(flatten)]
    input: InputArgs,
    /// Term groups: p3, i6 or i5, e9 or e8, bias.
    #[arg(long, default_value = "p3,i5,e8")]
    terms: String,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let terms = TermSet::parse(&a.terms).map_err(|e| bad_input!("--terms: {e}"))?;
    let table = a.input.load()?;
    let cfg = KalmanConfig {
        terms,
        compute_series: false,
        ..KalmanConfig::default()
    };
    let (_, fit, _) = fit_model_kalman(
        &table,
        &cfg,
        &FitOptions {
            eddy_lag: EddyLag::None,
            ..FitOptions::auto()
        },
    )?;
    let o = observability(
        &fit.names,
        &fit.prior_covariance,
        &fit.posterior_covariance,
        1e6,
    )?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&o)?);
        return Ok(());
    }
    let n = o.names.len();
    // Effect uncertainty of each term, nT: its standard deviation times the
    // size its column takes over a full set of headings and manoeuvres —
    // 1 for the permanent terms (e_i spans ±1), |B|/bt_scale for the induced
    // terms, and |B|·0.1 rad/s / bt_scale for the eddy terms (the body-frame
    // field rate of a 6°/s manoeuvre). The column's spread on *this* flight would hide exactly what a
    // poor flight fails to exercise.
    let cols = TlColumns::from_table(&table)?;
    let bt: Vec<f64> = (0..cols.time.len())
        .map(|i| {
            (cols.flux[0][i].powi(2) + cols.flux[1][i].powi(2) + cols.flux[2][i].powi(2)).sqrt()
        })
        .filter(|v| v.is_finite())
        .collect();
    let bt_mean = bt.iter().sum::<f64>() / bt.len().max(1) as f64;
    let effect: Vec<f64> = o
        .names
        .iter()
        .zip(&fit.std)
        .map(|(name, sd)| {
            let scale = match name.as_bytes().first() {
                Some(b'p') => 1.0,
                Some(b'i') => bt_mean / cfg.bt_scale_nt,
                Some(b'e') => 0.1 * bt_mean / cfg.bt_scale_nt,
                _ => 1.0,
            };
            sd * scale
        })
        .collect();
    println!(
        "{}: {} coefficients ({}), {} rows",
        table.file_label(),
        n,
        cfg.terms,
        fit.rows
    );
    println!(
        "information rank {} of {n}, condition number {:.2e}{}",
        o.rank,
        o.condition,
        if o.rank < n {
            " — some combinations are not observable"
        } else {
            ""
        }
    );
    if o.weak_combinations.is_empty() {
        println!("every combination of coefficients is determined by this flight");
    }
    for w in &o.weak_combinations {
        println!("  {w}");
    }
    println!(
        "\n{:<8} {:>10} {:>12} {:>16}  verdict",
        "term", "μ", "std", "effect σ (nT)"
    );
    let mut undetermined = Vec::new();
    for i in 0..n {
        let verdict = if o.estimability[i] > 0.9 || effect[i] >= 1.0 {
            undetermined.push(o.names[i].clone());
            "NOT determined by this flight"
        } else if effect[i] >= 0.1 {
            "weakly determined"
        } else if effect[i] >= 0.01 {
            "determined"
        } else {
            "well determined"
        };
        println!(
            "{:<8} {:>10.4} {:>12.3e} {:>16.4}  {verdict}",
            o.names[i], o.estimability[i], fit.std[i], effect[i]
        );
    }
    if !undetermined.is_empty() {
        println!(
            "\nthis flight cannot determine: {} — fly all four headings with roll, pitch and yaw manoeuvres, or drop these terms",
            undetermined.join(", ")
        );
    }
    Ok(())
}
