//! `aeromag simulate`: realistic flight data with known truth.

use crate::exit::bad_input;
use aeromag_sim::{ScenarioKind, default_config_toml};
use std::path::PathBuf;

/// Simulate a flight with the physical simulator and write it to a folder.
///
/// Scenarios: `calibration` (four-heading box at 3000 m with roll, pitch and
/// yaw manoeuvres), `calibration-truncated` (the thesis' shorter pattern),
/// `survey` (lines and tie lines at 100 m above ground), `helicopter` (the box
/// at 40 m/s with a main rotor, 100 Hz, rotor phase channel; a `[tail_rotor]`
/// table in the --config file adds a tail rotor), `pod` (a towed
/// magnetometer pod under a helicopter, seed 002's parameters, 20 Hz, cable
/// inclination and azimuth channels), `gradiometer` (a dipole passing a
/// gradiometer: see `aeromag dipole simulate`), `em` (ADC-level EM
/// positioning record: same as `aeromag em simulate`). The folder gets
/// `<scenario>.csv` (canonical columns plus `true_…` truth columns),
/// `<scenario>.toml` (the scenario with every default filled in: edit it and
/// pass it back with --config) and `<scenario>.truth.json`.
///
/// Examples:
///   aeromag simulate calibration --out cal/
///   aeromag simulate survey --seed 7 --out survey/
///   aeromag simulate calibration --print-config > my.toml
///   aeromag simulate calibration --config my.toml --out cal2/
///   aeromag simulate pod --seed 3 --out pod/
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct Args {
    /// Scenario: calibration, calibration-truncated, survey, helicopter, pod,
    /// gradiometer, em.
    scenario: String,
    /// Scenario file (TOML); fields not given take the scenario's defaults.
    #[arg(long, value_name = "FILE.toml")]
    config: Option<PathBuf>,
    /// Random seed (overrides the scenario file's seed).
    #[arg(long)]
    seed: Option<u64>,
    /// Output folder (created if needed).
    #[arg(long, value_name = "DIR", required_unless_present = "print_config")]
    out: Option<PathBuf>,
    /// Print the scenario's default configuration (TOML) and exit.
    #[arg(long)]
    print_config: bool,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    // Before simulating: an --out that is a file (or /dev/null) failed
    // after the simulation with exit 1.
    // A folder this run creates is removed again if the run writes nothing
    // into it (a refused scenario left an empty folder behind).
    let _created = (!a.print_config)
        .then_some(a.out.as_deref())
        .flatten()
        .map(crate::output::NewFolder::before);
    if let (Some(out), false) = (&a.out, a.print_config) {
        crate::output::check_folder(out)?;
    }
    if a.scenario == "gradiometer" {
        return crate::output::simulate_gradiometer(
            a.config.as_deref(),
            a.seed,
            a.out.as_deref(),
            a.print_config,
        );
    }
    if a.scenario == "em" {
        return crate::output::simulate_em(
            a.config.as_deref(),
            a.seed,
            a.out.as_deref(),
            a.print_config,
            aeromag::em::DEFAULT_KNOWN,
        );
    }
    let kind: ScenarioKind = a.scenario.parse()?;
    if a.print_config {
        print!("{}", default_config_toml(kind)?);
        return Ok(());
    }
    let out = a
        .out
        .as_ref()
        .ok_or_else(|| bad_input!("--out DIR is required"))?;
    // The three files checked before the simulation: a folder in the
    // place of one is bad input (it failed with exit 1).
    let names = aeromag_sim::Simulation::file_names(kind);
    let _checked = crate::output::simulation_folder(
        out,
        names.each_ref().map(|n| n.as_str()),
        a.config.as_deref(),
    )?;
    let spinner = crate::progress::spinner(&format!("simulating {kind}"));
    // The scenario file named with its errors at writing too (a flight the
    // readers would refuse is found there).
    let in_config = |e: aeromag_sim::SimError| match &a.config {
        Some(p) if e.is_bad_input() => {
            anyhow::Error::new(e).context(format!("in '{}'", p.display()))
        }
        _ => anyhow::Error::new(e),
    };
    let sim = aeromag::simulate::simulate_scenario(kind, a.config.as_deref(), a.seed)?;
    spinner.finish_and_clear();
    let files = sim.write_to_dir(out).map_err(in_config)?;
    println!(
        "simulated {kind} (seed {}): {} rows × {} columns",
        sim.seed,
        sim.n_rows(),
        sim.columns.len()
    );
    println!("  data      {}", files.csv.display());
    println!("  scenario  {}", files.scenario.display());
    println!("  truth     {}", files.truth.display());
    Ok(())
}
