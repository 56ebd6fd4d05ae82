//! EM positioning of a towed bird on files, as a survey crew chains the
//! steps: simulate the raw ADC record, detect, calibrate from the known
//! points, locate every epoch.
//!
//! ```sh
//! cargo run --release -p aeromag --example em_chain -- OUT_DIR
//! ```

use aeromag::em::files::{load_table, read_system};
use aeromag::em::{
    DetectOptions, HalfSpace, calibrate, command_default, detect, known_points, locate,
    simulate_to_dir,
};
use aeromag::{Error, Silent};

fn main() -> Result<(), Error> {
    let out = std::env::args().nth(1).unwrap_or_else(|| "em-out".into());
    let files = simulate_to_dir(&command_default(), 8, out.as_ref())?;
    let detected = detect(&files.raw, &DetectOptions::default(), &mut Silent)?;
    let known = known_points(&load_table(&files.known)?, &detected.epochs)?;
    let system = read_system(&files.system)?;
    let half_space = HalfSpace::default();
    let cal = calibrate(&detected.epochs, &known, &system, &half_space)?;
    println!(
        "polarisation ratio {:.2e} → {:.2e} after calibration",
        cal.polarization_ratio_before, cal.polarization_ratio_after
    );
    let poses = locate(&detected.epochs, &cal.file, &half_space, &mut Silent)?;
    for p in poses.poses.iter().take(5) {
        if let Some(l) = p.located {
            println!(
                "t = {:.3} s: range {:.3} m, attitude {:?} deg",
                p.time_s, l.range_m, l.attitude_deg
            );
        }
    }
    println!(
        "{} of {} epochs located",
        poses.poses.len() - poses.failed(),
        poses.poses.len()
    );
    Ok(())
}
