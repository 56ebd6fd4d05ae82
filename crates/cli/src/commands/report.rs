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
/// With a multi-sensor model (`calibrate --mag A,B,…`) and the file its
/// `compensate` wrote: an overview of every sensor (before and after, the
/// share of the interference each term group explains, the current most
/// correlated with what is left), then each sensor's section with its
/// currents against the residual.
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

/// The files `report` writes into its folder, as a set.
const REPORT_FILES: [&str; 2] = ["index.html", "figures.json"];

pub fn run(a: Args) -> anyhow::Result<()> {
    crate::output::check_folder_files(&a.out, REPORT_FILES, &[a.input.path()])?;
    if let Some(m) = &a.model
        && aeromag::model_file::kind_of(m)? == aeromag::compensation::model_file::TL_SENSORS_KIND
    {
        return run_sensors(&a, m);
    }
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
    write(&a, r, serde_json::to_string_pretty(&fig)?)
}

/// The report and `figures.json` into the output folder, as a set: an
/// interruption or a failure leaves both old or both new.
fn write(a: &Args, r: Report, figures: String) -> anyhow::Result<()> {
    std::fs::create_dir_all(&a.out).map_err(|e| aeromag::Error::write(&a.out, e))?;
    let [path, fig_path] = REPORT_FILES.map(|n| a.out.join(n));
    aeromag::model_file::write_files(&[
        (&path, r.to_html().as_bytes()),
        (&fig_path, figures.as_bytes()),
    ])?;
    println!("report written to {}", path.display());
    Ok(())
}

/// A multi-sensor model: every sensor (library: [`aeromag::score::score_sensors`]).
fn run_sensors(a: &Args, model_path: &std::path::Path) -> anyhow::Result<()> {
    let model = aeromag::SensorsModel::read(model_path)?;
    let flight = a.input.load()?;
    let reference = match &a.reference {
        Some(r) => r.resolve(&flight)?,
        // The sensors fitted against the field share the reference channels.
        None => match model.sensors.iter().find(|s| s.reference_sensor.is_none()) {
            Some(s) => s.model.reference.clone(),
            None => ReferenceChannels::Auto.resolve(&flight)?,
        },
    };
    let fig = aeromag::score::score_sensors(&flight, &model, &reference)?;
    let mut r = Report::new(format!("aeromag report — {}", flight.file_label()));
    for s in fig.sections(&flight, &model)? {
        s.append_to(&mut r);
    }
    for s in &fig.sensors {
        let f = &s.figures;
        println!(
            "{:<8} IR {:>7}  FOM {} → {} nT  shares {}",
            s.sensor,
            f.ir.map_or("—".into(), |v| format!("{v:.1}")),
            f.fom_before_nt.map_or("—".into(), |v| format!("{v:.2}")),
            f.fom_after_nt.map_or("—".into(), |v| format!("{v:.3}")),
            s.groups
                .shares
                .map(|x| format!("{:.0}%", 100.0 * x))
                .join("/")
        );
    }
    write(a, r, serde_json::to_string_pretty(&fig)?)
}
