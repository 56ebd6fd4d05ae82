//! `aeromag report`: an HTML report of a compensated flight (library:
//! [`aeromag::score`]).

use crate::args;
use crate::input::InputArgs;
use aeromag::report::Report;
use aeromag::{ModelFile, ReferenceChannels, TlModel};
use std::path::PathBuf;

/// Write a single-file HTML report (plots inline) of a compensated flight:
/// uncompensated and compensated signal, modelled interference, Welch
/// spectra, figure of merit per manoeuvre window, improvement ratio, and —
/// when given the model — the coefficient table with standard deviations.
/// Simulated files (with `true_…` columns) also get residuals versus truth.
///
/// Example:
///   aeromag compensate --model m.json --input cal.csv --out cal_comp.csv
///   aeromag report --input cal_comp.csv --model m.json --out report/
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct Args {
    #[command(flatten)]
    input: InputArgs,
    /// The model file used for the compensation (adds the coefficient table).
    #[arg(long, value_name = "MODEL.json")]
    model: Option<PathBuf>,
    /// Known external-field channels removed before computing FOM and IR
    /// (`auto`: `diurnal` and `igrf` when present; `none`; or a list).
    /// Default: those the model was fitted with, else `auto`.
    #[arg(long, value_parser = args::parsed::<ReferenceChannels>)]
    reference: Option<ReferenceChannels>,
    /// Output folder; the report is DIR/index.html.
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    crate::output::check_folder(&a.out)?;
    let model = a.model.as_deref().map(TlModel::read).transpose()?;
    // Only the columns the report reads (an HDF5 flight of 100 fields).
    let mut extra: Vec<&str> = aeromag::score::SCORED_COLUMNS.to_vec();
    match (&a.reference, &model) {
        (Some(ReferenceChannels::Columns(c)), _) => extra.extend(c.iter().map(String::as_str)),
        (None, Some(m)) => extra.extend(m.reference.iter().map(String::as_str)),
        _ => {}
    }
    let flight = a.input.load_canonical(&extra)?;
    let reference = match (&a.reference, &model) {
        (Some(r), _) => r.resolve(&flight)?,
        (None, Some(m)) => m.reference.clone(),
        (None, None) => ReferenceChannels::Auto.resolve(&flight)?,
    };
    let lever = model.as_ref().and_then(|m| m.lever_arm.as_ref());
    let fig = aeromag::score::score(&flight, &reference, lever)?;
    let mut r = Report::new(format!("aeromag report — {}", flight.file_label()));
    fig.section("Compensation", &flight, model.as_ref())?
        .append_to(&mut r);
    let path = a.out.join("index.html");
    r.write_html(&path)?;
    aeromag::io::atomic::write_file(
        &a.out.join("figures.json"),
        serde_json::to_string_pretty(&fig)?,
    )
    .map_err(|e| aeromag::Error::write(a.out.join("figures.json"), e))?;
    println!("report written to {}", path.display());
    Ok(())
}
