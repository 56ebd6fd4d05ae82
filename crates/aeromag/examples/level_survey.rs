//! Calibrate, compensate and level a survey at its crossovers with the
//! `k·d|B0|/dt` term, on simulated flights, as a survey processor would;
//! prints `k` against the simulator's truth (the scalar sensor's lag) and
//! writes the levelled survey and the crossover table.
//!
//! ```sh
//! cargo run --release -p aeromag --example level_survey -- OUT_DIR
//! ```

use aeromag::level::{LevelOptions, level};
use aeromag::prelude::*;
use aeromag::simulate::{ScenarioKind, simulate_flight};
use std::path::Path;

fn main() -> Result<(), Error> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "level-out".into());
    let out = Path::new(&out);
    std::fs::create_dir_all(out).map_err(|e| Error::write(out, e))?;
    // A calibration box and an independent survey of the same aircraft.
    let cal = simulate_flight(ScenarioKind::Calibration, None, Some(1))?;
    let survey = simulate_flight(ScenarioKind::Survey, None, Some(2))?;
    let model = calibrate(&cal, &CalibrateOptions::default(), &mut Silent)?.model;
    let survey = model.compensate(&survey)?.into_flight(survey)?;
    // Level `mag_comp` with the base station and IGRF removed, at the
    // sensor's position (a stinger 9.5 m behind the navigation point).
    let opts = LevelOptions {
        reference: ReferenceChannels::Auto,
        lever_arm_m: Some([-9.5, 0.0, -0.6]),
        ..LevelOptions::default()
    };
    let lev = level(&survey, &opts, &mut Silent)?;
    let fit = &lev.levelling.fit;
    println!(
        "{} crossovers; k = {:.4} ± {:.4} s (truth −0.1 s: the sensor's 0.1 s lag)",
        lev.levelling.crossovers.crossovers.len(),
        fit.k_s,
        fit.k_std_s
    );
    println!(
        "crossover RMS {:.3} nT before, {:.3} nT after levelling",
        fit.rms_before_nt, fit.rms_after_nt
    );
    let mut table = survey.into_table();
    lev.add_to(&mut table)?;
    aeromag::io::write_csv(&table, &out.join("survey_levelled.csv"))?;
    aeromag::io::write_csv(&lev.crossover_table()?, &out.join("crossovers.csv"))?;
    Ok(())
}
