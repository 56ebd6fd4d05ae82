//! Simulated flights with known truth, in memory (the simulator is
//! [`aeromag_sim`]; `aeromag simulate` writes the same to a folder).

use crate::error::{Error, Result};
use crate::flight::Flight;
pub use aeromag_sim::{ScenarioKind, Simulation};
use std::path::Path;

/// Simulate a fixed-wing, helicopter or pod scenario and return the flight:
/// the canonical columns the instruments record and the `true_` columns of
/// the simulator's truth (never read by an estimator). `config_toml` is a
/// scenario file's text (any subset of its fields; the rest take the
/// scenario's defaults: `aeromag simulate SCENARIO --print-config`), `seed`
/// overrides its seed.
///
/// ```
/// use aeromag::simulate::{ScenarioKind, simulate_flight};
/// let survey = simulate_flight(
///     ScenarioKind::Survey,
///     Some("[pattern]\nline_count = 2\nline_length_m = 2000.0\ntie_count = 1\n"),
///     Some(7),
/// )?;
/// assert!(survey.column("mag").is_some() && survey.column("true_external").is_some());
/// # Ok::<(), aeromag::Error>(())
/// ```
pub fn simulate_flight(
    kind: ScenarioKind,
    config_toml: Option<&str>,
    seed: Option<u64>,
) -> Result<Flight> {
    Flight::from_table(aeromag_sim::simulate(kind, config_toml, seed)?.to_flight_table()?)
}

/// Simulate a fixed-wing, helicopter or pod scenario with the scenario file
/// at `config` (`None`: the scenario's defaults; `aeromag simulate
/// --config`): the file is read with [`crate::model_file::read_text_file`]'s
/// bound, and its errors name it (`'my.toml': scenario file: TOML parse
/// error at line 3, column 9 …`, the line also in [`Error::location`]).
pub fn simulate_scenario(
    kind: ScenarioKind,
    config: Option<&Path>,
    seed: Option<u64>,
) -> Result<Simulation> {
    let Some(path) = config else {
        return Ok(aeromag_sim::simulate(kind, None, seed)?);
    };
    let text = crate::model_file::read_text_file(path)?;
    aeromag_sim::simulate(kind, Some(&text), seed).map_err(|e| {
        if e.is_bad_input() {
            Error::in_text(path.display().to_string(), e)
        } else {
            e.into()
        }
    })
}

/// [`simulate_flight`] with the scenario file at `config`
/// ([`simulate_scenario`]).
pub fn simulate_flight_file(
    kind: ScenarioKind,
    config: Option<&Path>,
    seed: Option<u64>,
) -> Result<Flight> {
    Flight::from_table(simulate_scenario(kind, config, seed)?.to_flight_table()?)
}
