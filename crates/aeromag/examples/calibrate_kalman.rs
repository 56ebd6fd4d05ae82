//! `aeromag calibrate --method kalman` followed by `aeromag compensate`,
//! written against the library: the same model file and the same
//! compensated table as the command, byte for byte.
//!
//! ```sh
//! aeromag simulate calibration --out cal/ && aeromag simulate survey --out sur/
//! cargo run --release -p aeromag --example calibrate_kalman -- \
//!     cal/calibration.csv sur/survey.csv model.json survey_comp.csv
//! ```

use aeromag::prelude::*;
use std::path::Path;

/// Fit the Kalman method on `cal`, write the model to `model`, compensate
/// `survey` with it and write the result to `out`.
pub fn calibrate_and_compensate(
    cal: &Path,
    survey: &Path,
    model: &Path,
    out: &Path,
) -> aeromag::Result<()> {
    // Read and check the calibration flight (MagNav names are recognised).
    let flight = Flight::read(cal)?;
    // The Kalman method with its defaults: lags chosen after a first pass
    // has removed the field, noise intensities tuned by maximum likelihood.
    let fit = calibrate(&flight, &CalibrateOptions::kalman(), &mut Silent)?;
    for note in &fit.notes {
        eprintln!("{note}");
    }
    fit.model.write(model)?;
    // The model applies itself to another flight.
    let survey = Flight::read(survey)?;
    let compensated = fit.model.compensate(&survey)?;
    eprintln!(
        "{} of {} rows compensated",
        survey.n_rows() - compensated.missing,
        survey.n_rows()
    );
    aeromag::io::write_csv(&compensated.into_table(survey)?, out)?;
    Ok(())
}

#[allow(dead_code)]
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [cal, survey, model, out] = args.as_slice() else {
        eprintln!("usage: calibrate_kalman CAL.csv SURVEY.csv MODEL.json OUT.csv");
        std::process::exit(2);
    };
    if let Err(e) =
        calibrate_and_compensate(cal.as_ref(), survey.as_ref(), model.as_ref(), out.as_ref())
    {
        eprintln!("error: {e}");
        std::process::exit(if e.is_bad_input() { 2 } else { 1 });
    }
}
