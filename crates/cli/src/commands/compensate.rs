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
/// With --causal the model is applied as an on-board compensator applies
/// it (what `aeromag stream` gives, value for value): the eddy terms take
/// backward differences, so no row depends on a later one, and runs break
/// at time steps over 1.5 × the calibration's sample interval.
///
/// Examples:
///   aeromag compensate --model model.json --input survey.csv --out survey_comp.csv
///   aeromag compensate --causal --model model.json --input survey.csv --out causal.csv
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct Args {
    /// Model file written by `aeromag calibrate`.
    #[arg(long, value_name = "MODEL.json")]
    model: PathBuf,
    #[command(flatten)]
    input: InputArgs,
    #[arg(long, value_name = "OUT.csv", help = crate::output::TABLE_OUT_HELP)]
    out: PathBuf,
    /// Apply the model causally (backward differences; see above).
    #[arg(long)]
    causal: bool,
    /// With --causal: the sample rate whose interval × 1.5 breaks a run
    /// (default: the calibration's, recorded in the model file).
    #[arg(long, value_name = "HZ", requires = "causal")]
    sample_rate: Option<f64>,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    crate::output::check_files([a.out.as_path()], &[a.input.path(), a.model.as_path()])?;
    crate::output::check_tables([a.out.as_path()])?;
    if aeromag::model_file::kind_of(&a.model)? == aeromag::compensation::model_file::TL_SENSORS_KIND
    {
        return run_sensors(&a);
    }
    let model = TlModel::read(&a.model)?;
    let flight = a.input.load()?;
    let (out, how) = if a.causal {
        let causal = aeromag::online::CausalTl::new(&model, a.sample_rate)?;
        (causal.compensate(&flight)?, ", causal")
    } else {
        (model.compensate(&flight)?, "")
    };
    let detail = crate::output::model_detail(&model, how);
    crate::output::write_compensated(flight, out, &a.out, &a.model, &detail)
}

/// A multi-sensor model: every sensor's columns.
fn run_sensors(a: &Args) -> anyhow::Result<()> {
    use aeromag::CompensateSensors;
    let model = aeromag::SensorsModel::read(&a.model)?;
    let flight = a.input.load()?;
    let out = if a.causal {
        aeromag::online::CausalSensors::new(&model, a.sample_rate)?.compensate(&flight)?
    } else {
        model.compensate(&flight)?
    };
    crate::output::write_compensated_sensors(flight, out, &a.out, &a.model, model.sensors.len())
}
