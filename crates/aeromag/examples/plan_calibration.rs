//! Calibration-flight planning (thesis fig. 2): simulate the full
//! four-heading box and the truncated pattern before flying them, and
//! compare what each determines — the estimability μ of every coefficient
//! and the effect uncertainty in nT.
//!
//! ```sh
//! cargo run --release -p aeromag --example plan_calibration
//! ```

use aeromag::compensation::tolles_lawson::TermSet;
use aeromag::simulate::{ScenarioKind, simulate_flight};
use aeromag::{Error, Silent, observability};

fn main() -> Result<(), Error> {
    let terms = TermSet::observable16();
    for kind in [
        ScenarioKind::Calibration,
        ScenarioKind::CalibrationTruncated,
    ] {
        let flight = simulate_flight(kind, None, Some(1))?;
        let time = flight.require("time")?;
        let minutes = (time[time.len() - 1] - time[0]) / 60.0;
        let o = observability(&flight, &terms, None, &mut Silent)?;
        let worst = o
            .coefficients
            .iter()
            .max_by(|a, b| a.effect_std_nt.total_cmp(&b.effect_std_nt))
            .expect("coefficients");
        println!(
            "{kind}: {minutes:.0} min, information rank {} of {}, worst term {} (μ {:.2e}, effect σ {:.4} nT, {})",
            o.observability.rank,
            o.coefficients.len(),
            worst.name,
            worst.mu,
            worst.effect_std_nt,
            worst.verdict.words()
        );
    }
    Ok(())
}
