//! A gradiometer pass: simulate it, write it as a table, read it back
//! without its truth columns, locate the object with the square-root IEKF,
//! and compare the final uncertainty with the Cramér–Rao bound.
//!
//! The default estimator lets position and moment random-walk (the object
//! may move), so its σ settles well above the bound of a static object;
//! with the random walks at zero and re-linearised passes it reaches the
//! bound (`crates/aeromag/tests/gradiometry.rs` asserts that).
//!
//! ```sh
//! cargo run --release -p aeromag --example gradiometer_pass
//! ```

use aeromag::gradiometry::config::GradiometerConfig;
use aeromag::gradiometry::sim::simulate;
use aeromag::gradiometry::{STATE_NAMES, crlb, locate_pass, pass_table, read_pass};
use aeromag::{Error, Flight, FlightTable};

fn main() -> Result<(), Error> {
    let cfg = GradiometerConfig::default();
    let sim = simulate(&cfg.scenario()?)?;
    // The file a survey would record: the pass without the truth.
    let table = pass_table(&cfg, &sim)?;
    let mut recorded = FlightTable::new();
    for c in table
        .columns()
        .iter()
        .filter(|c| !c.name().starts_with("true_"))
    {
        recorded.add_column(c.name(), c.values().unwrap_or_default().to_vec())?;
    }
    let pass = read_pass(&Flight::from_table(recorded)?, &cfg)?;
    let track = locate_pass(&cfg, &pass.epochs, &pass.positions_m)?;
    let bound = crlb(&cfg)?;
    let last = track.x.len() - 1;
    println!("end of the pass (random-walk process noise in the filter, none in the bound):");
    for (k, name) in STATE_NAMES.iter().enumerate() {
        println!(
            "{name:>7}: estimate {:10.3}, filter σ {:.3e}, CRLB σ {:.3e}",
            track.x[last][k], track.sd[last][k], bound.end.std[k]
        );
    }
    Ok(())
}
