//! The helicopter models on simulated flights: the rotor model fitted on
//! one flight (the simulator's helicopter, a named preset) and applied to
//! another; the towed-pod model fitted on the seed's learning headings and
//! applied to an independent heading set, with its compensation rates.
//!
//! ```sh
//! cargo run --release -p aeromag --example rotor_pod
//! ```

use aeromag::pod::{PodMethod, PodSetup, apply_pod, fit_pod};
use aeromag::prelude::*;
use aeromag::rotor::{RotorOptions, RotorPreset, fit_rotor};
use aeromag::simulate::{ScenarioKind, simulate_flight};

fn main() -> Result<(), Error> {
    // Rotor: learn on one flight, compensate another.
    let learn = simulate_flight(ScenarioKind::Helicopter, None, Some(11))?;
    let other = simulate_flight(ScenarioKind::Helicopter, None, Some(12))?;
    let opts = RotorOptions::preset(RotorPreset::AeromagSimHelicopter);
    let fit = fit_rotor(&learn, &opts, &mut Silent)?;
    let interf = fit.model.interference(&other)?;
    let truth = other.require("true_rotor")?;
    let rms = |x: &[f64]| (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt();
    let left: Vec<f64> = truth.iter().zip(&interf).map(|(t, m)| t - m).collect();
    println!(
        "rotor model ({} parameters): {:.3} nT of rotor interference, {:.3} nT left (scored against the truth)",
        fit.model.model.params.len(),
        rms(&truth[300..truth.len() - 300]),
        rms(&left[300..left.len() - 300])
    );
    // Towed pod: the seed's installation, learning and test headings.
    let setup = PodSetup {
        cable_length_m: 40.0,
        attach_m: [0.0, 0.0, 1.2],
        inclination_deg: 45.0,
        declination_deg: 0.0,
        grad_north_nt_per_km: 5.91,
        grad_up_nt_per_km: -25.91,
    };
    let pod_learn = simulate_flight(ScenarioKind::Pod, Some("swing_sine = true\n"), None)?;
    let test_headings = "swing_sine = true\nheadings_deg = [30.0, 120.0, 210.0, 300.0]\n";
    let pod_test = simulate_flight(ScenarioKind::Pod, Some(test_headings), Some(1001))?;
    let model = fit_pod(
        &pod_learn,
        &setup,
        PodMethod::DipoleArray,
        None,
        &mut Silent,
    )?
    .model;
    let applied = apply_pod(&model, &pod_test)?;
    for h in &applied.per_heading {
        println!(
            "pod heading {:5.1}°: compensation rate {:.2} %",
            h.heading_deg,
            100.0 * h.rate
        );
    }
    Ok(())
}
