//! `aeromag compensate`: apply a model file to flight data (library:
//! [`aeromag::Compensator`] for [`aeromag::TlModel`]).

use crate::input::InputArgs;
use aeromag::{Compensator, ModelFile, TlModel};
use std::path::PathBuf;

/// Remove the aircraft's magnetic interference from flight data with a model
/// fitted by `aeromag calibrate`.
///
/// Writes every input column plus `mag_interf` (modelled interference, nT),
/// `mag_comp` (compensated field, nT) and `comp_flag` (0 compensated,
/// 1 not compensated because an input value is missing). Every input row is
/// written, in order.
///
/// Example:
///   aeromag compensate --model model.json --input survey.csv --out survey_comp.csv
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct Args {
    /// Model file written by `aeromag calibrate`.
    #[arg(long, value_name = "MODEL.json")]
    model: PathBuf,
    #[command(flatten)]
    input: InputArgs,
    /// Output CSV file.
    #[arg(long, value_name = "OUT.csv")]
    out: PathBuf,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    crate::output::check_files([a.out.as_path()])?;
    let model = TlModel::read(&a.model)?;
    let flight = a.input.load()?;
    let out = model.compensate(&flight)?;
    let detail = format!("{} terms, method {}", model.design.terms, model.method);
    crate::output::write_compensated(flight, out, &a.out, &a.model, &detail)
}
