//! Simulated flights with known truth, in memory (the simulator is
//! [`aeromag_sim`]; `aeromag simulate` writes the same to a folder).

use crate::error::Result;
use crate::flight::Flight;
pub use aeromag_sim::ScenarioKind;

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
    let sim = aeromag_sim::simulate(kind, config_toml, seed)?;
    Flight::from_table(sim.to_flight_table()?)
}
