//! Model-file readers: Tolles-Lawson, rotor and pod model files
//! (`from_json(text, origin)`), the EM calibration file and calibration,
//! and the EM system description. A model that parses is applied to a small
//! simulated flight (helicopter / pod rows, committed beside the targets).
#![no_main]

use std::sync::OnceLock;

use aeromag::compensate::Compensator;
use aeromag::{Flight, ModelFile};
use aeromag_compensation::model_file::TlModel;
use aeromag_compensation::pod::model_file::PodModelFile;
use aeromag_compensation::rotor::model_file::RotorModelFile;
use aeromag_em::calibration::Calibration;
use aeromag_em::calibration::file::CalibrationFile;
use aeromag_em::detection::EmSystem;
use libfuzzer_sys::fuzz_target;

fn flights() -> &'static (Flight, Flight) {
    static F: OnceLock<(Flight, Flight)> = OnceLock::new();
    F.get_or_init(|| {
        let read = |name: &str, bytes: &[u8]| {
            Flight::read(aeromag_fuzz::scratch(name, bytes)).expect("fixture flight")
        };
        (
            read("heli.csv", include_bytes!("../fixtures/helicopter.csv")),
            read("pod.csv", include_bytes!("../fixtures/pod.csv")),
        )
    })
}

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let (heli, pod) = flights();
    if let Ok(m) = TlModel::parse(text, "fuzz.json") {
        let _ = m.interference(heli);
        let _ = m.json();
    }
    if let Ok(m) = RotorModelFile::parse(text, "fuzz.json") {
        let _ = m.interference(heli);
        let _ = m.json();
    }
    if let Ok(m) = PodModelFile::parse(text, "fuzz.json") {
        let _ = m.interference(pod);
        let _ = m.json();
    }
    if let Ok(c) = CalibrationFile::from_json(text) {
        let _ = c.to_json();
    }
    if let Ok(c) = Calibration::from_json(text) {
        let _ = c.to_json();
    }
    if let Ok(s) = serde_json::from_str::<EmSystem>(text) {
        let _ = s.validate();
    }
});
