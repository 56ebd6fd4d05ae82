//! `aeromag report`: an HTML report of a compensated flight.

use crate::analysis::{add_to_report, figures};
use crate::commands::compensate::load_model;
use crate::flight::reference_columns;
use crate::input::InputArgs;
use aeromag_report::Report;
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
    #[arg(long)]
    reference: Option<String>,
    /// Output folder; the report is DIR/index.html.
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let table = a.input.load()?;
    let model = a.model.as_deref().map(load_model).transpose()?;
    let reference = match (&a.reference, &model) {
        (Some(r), _) => reference_columns(&table, r)?,
        (None, Some(m)) => m.reference.clone(),
        (None, None) => reference_columns(&table, "auto")?,
    };
    let fig = figures(
        &table,
        &reference,
        model.as_ref().and_then(|m| m.lever_arm.as_ref()),
    )?;
    let mut r = Report::new(format!("aeromag report — {}", table.file_label()));
    add_to_report(&mut r, "Compensation", &table, &fig, model.as_ref())?;
    let path = a.out.join("index.html");
    r.write_html(&path)?;
    std::fs::write(
        a.out.join("figures.json"),
        serde_json::to_string_pretty(&fig)?,
    )?;
    println!("report written to {}", path.display());
    Ok(())
}
