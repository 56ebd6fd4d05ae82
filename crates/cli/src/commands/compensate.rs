//! `aeromag compensate`: apply a model file to flight data.

use crate::flight::TlColumns;
use crate::flight::add_compensation;
use crate::input::InputArgs;
use aeromag_compensation::model_file::TlModel;
use aeromag_compensation::tolles_lawson::design::interference;
use aeromag_io::FlightTable;
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

/// Read and check a model file.
pub fn load_model(path: &std::path::Path) -> anyhow::Result<TlModel> {
    crate::flight::load_model_file(path, TlModel::from_json)
}

/// Modelled interference for every row (NaN where an input is missing) and
/// the number of rows that could not be compensated.
pub fn model_interference(model: &TlModel, cols: &TlColumns) -> (Vec<f64>, usize) {
    let n = cols.time.len();
    let mut out = vec![f64::NAN; n];
    // Derivatives must not cross gaps or missing rows; line changes are fine.
    let (segs, short) = cols.segments(false, 1);
    debug_assert!(short.is_empty());
    let coef = model.coef();
    for r in segs {
        let f = [
            &cols.flux[0][r.clone()],
            &cols.flux[1][r.clone()],
            &cols.flux[2][r.clone()],
        ];
        let v = interference(
            &model.terms,
            model.convention,
            model.bt_scale_nt,
            &coef,
            &cols.time[r.clone()],
            f,
        );
        out[r].copy_from_slice(&v);
    }
    let missing = out.iter().filter(|v| !v.is_finite()).count();
    (out, missing)
}

/// Add `mag_interf`, `mag_comp`, `comp_flag` to a table; returns the number
/// of rows that could not be compensated.
pub fn compensate_table(model: &TlModel, table: &mut FlightTable) -> anyhow::Result<usize> {
    let cols = TlColumns::from_table(table)?;
    let (interf, _) = model_interference(model, &cols);
    add_compensation(table, "mag_interf", "comp_flag", interf)
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let model = load_model(&a.model)?;
    let mut table = a.input.load()?;
    let missing = compensate_table(&model, &mut table)?;
    let detail = format!("{} terms, method {}", model.terms, model.method);
    crate::flight::write_compensated(
        &table,
        &a.out,
        &a.model,
        &detail,
        missing,
        "comp_flag",
        "missing values",
    )
}
