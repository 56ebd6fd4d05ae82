//! Wall-clock time of each stage of `calibrate` + `compensate` with the
//! MagNav settings (the peer benchmark's: p3,i6,e9, MagNav convention, no
//! eddy lag, no reference, lines not split) on a flight file.
//!
//! Run: `cargo run --release -p aeromag --example tl_stages -- FLIGHT.csv`
//! (a file from `python tools/bench/peers.py gen N FILE`).
use aeromag::compensate::Compensator;
use aeromag::observer::{Note, Observer};
use aeromag::tolles_lawson::CalibrateSettings;
use aeromag_compensation::tolles_lawson::TermSet;
use std::time::Instant;

/// Prints the time at which each stage ends.
struct Clock(Instant, String);

impl Observer for Clock {
    fn stage(&mut self, name: &str) {
        println!("{:8.3} s  {} done", self.0.elapsed().as_secs_f64(), self.1);
        self.1 = name.to_string();
    }
    fn note(&mut self, n: &Note) {
        println!("          {}", n.message);
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .ok_or("usage: tl_stages FLIGHT.csv")?;
    let mut clock = Clock(Instant::now(), "reading".into());
    let flight = aeromag::Flight::read(&path)?;
    let settings = CalibrateSettings {
        terms: Some(TermSet::parse("p3,i6,e9")?),
        convention: Some("magnav".parse()?),
        eddy_lag: Some("none".parse()?),
        reference: aeromag::flight::ReferenceChannels::None,
        no_split_lines: true,
        ..Default::default()
    };
    clock.stage("preparing the fit");
    let cal = aeromag::tolles_lawson::calibrate(&flight, &settings.options()?, &mut clock)?;
    clock.stage("compensating");
    cal.model.compensate_observed(&flight, &mut clock)?;
    clock.stage("");
    Ok(())
}
