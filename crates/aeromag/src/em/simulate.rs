//! An EM positioning flight simulated to a folder: the raw ADC record, the
//! instrument constants, the calibration information a crew would have, and
//! the truth.

use super::calibrate::check_known_position;
use super::files::{MAX_FRAME_INDEX, check_raw_header};
use crate::error::{Error, Result};
use aeromag_em::detection::block_centre_time_s;
use aeromag_em::sim::{
    EmScenario, EmSimConfig, RawHeader, known_csv, synthesize, truth_csv, write_raw,
};
use aeromag_em::study::STUDY_WINDOW_LEN;
use aeromag_io::atomic::FileSet;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Known positions written by default (calibration stage 2 needs ≥ 2).
pub const DEFAULT_KNOWN: usize = 8;

/// The scenario of `aeromag em simulate` without a file: the library's,
/// 10.24 s long (64 epochs of 0.16 s).
pub fn command_default() -> EmSimConfig {
    EmSimConfig {
        duration_s: 10.24,
        ..EmSimConfig::default()
    }
}

/// The scenario from [`command_default`] overlaid with a scenario file's
/// TOML text (unknown keys are errors; `origin` names the file).
pub fn parse_config(text: Option<&str>, origin: &str) -> Result<EmSimConfig> {
    let bad = |e: &dyn std::fmt::Display| Error::bad_file(origin, e.to_string());
    let toml::Value::Table(mut table) =
        toml::Value::try_from(command_default()).map_err(|e| Error::Serialize {
            what: "EM scenario",
            reason: e.to_string(),
        })?
    else {
        return Err(Error::Serialize {
            what: "EM scenario",
            reason: "not a TOML table".into(),
        });
    };
    if let Some(text) = text {
        let user: toml::Table = toml::from_str(text).map_err(|e| Error::toml(origin, text, &e))?;
        aeromag_sim::scenario::config::check_finite_numbers(&user)
            .map_err(|e| Error::in_text(origin, e))?;
        table.extend(user);
    }
    toml::Value::Table(table).try_into().map_err(|e| bad(&e))
}

/// Most frames [`simulate_to_dir`] builds (in memory, three `f32` channels
/// a frame: 3 GB; 41 minutes at 100 kHz). 10⁸ Hz for the default 10.24 s
/// asked for 12 GB and aborted.
pub const MAX_FRAMES: u64 = 250_000_000;

/// The files [`simulate_to_dir`] writes.
#[derive(Debug, Clone)]
pub struct SimulatedEm {
    /// `em.raw`: the ADC record (header with the instrument constants,
    /// interleaved little-endian f32 volts).
    pub raw: PathBuf,
    /// `em.system.json`: the instrument constants alone.
    pub system: PathBuf,
    /// `em.known.csv`: positions at the first epochs, attitude at the first.
    pub known: PathBuf,
    /// `em.truth.csv`: the true pose at every detector epoch (never read by
    /// the other steps).
    pub truth: PathBuf,
    /// `em.toml`: the scenario with every default filled in.
    pub scenario: PathBuf,
    /// Frames written.
    pub frames: u64,
    /// Detector epochs of [`STUDY_WINDOW_LEN`] samples in the record.
    pub epochs: usize,
}

/// Simulate `cfg` and write its files to `out` (created if needed), with
/// `known_positions` known positions (2 ..= the record's epochs).
pub fn simulate_to_dir(
    cfg: &EmSimConfig,
    known_positions: usize,
    out: &Path,
) -> Result<SimulatedEm> {
    // The scenario file written beside the record must read back: TOML
    // integers are signed 64-bit (a seed of 2⁶⁴ − 1 was simulated and its
    // em.toml then refused by --config).
    if cfg.seed > i64::MAX as u64 {
        return Err(Error::bad_input(format!(
            "seed {} must be < 2^63 (TOML integers are signed 64-bit)",
            cfg.seed
        )));
    }
    let sc = EmScenario::new(cfg.clone())?;
    let fs = cfg.sample_rate_hz;
    let frames = (cfg.duration_s * fs).round();
    if frames > MAX_FRAMES as f64 {
        return Err(Error::bad_input(format!(
            "duration_s × sample_rate_hz = {} frames, more than {MAX_FRAMES:e} (the record is built in memory, 12 bytes a frame): shorten duration_s or lower sample_rate_hz",
            aeromag_core::error::shown(frames)
        )));
    }
    // What `em detect` and `em calibrate` check on the files is checked
    // here with their own checks, before anything is built or written: a
    // coil gain or moments of 0, or a frequency given twice, were written
    // to a record that `em detect` then refused (exit 0, then 2).
    let max_start_s = (MAX_FRAME_INDEX as f64 - frames) / fs;
    if !(0.0..=max_start_s).contains(&cfg.start_time_s) {
        return Err(Error::bad_input(format!(
            "field 'start_time_s' is {} s, expected 0 … {} s (the record's frame indices start_time_s × sample_rate_hz … + frames must lie within 0 … 2^53)",
            aeromag_core::error::shown(cfg.start_time_s),
            aeromag_core::error::shown(max_start_s.max(0.0))
        )));
    }
    let header = RawHeader::new(
        fs,
        3,
        frames as u64,
        (cfg.start_time_s * fs).round() as u64,
        sc.system(),
    );
    check_raw_header(&header)
        .map_err(|m| Error::bad_input(format!("em detect would refuse the record: {m}")))?;
    header
        .system
        .check_tone_plan(fs, STUDY_WINDOW_LEN)
        .map_err(|e| Error::bad_input(format!("em detect would refuse the record: {e}")))?;
    let start = header.start_index;
    let blocks = header.frames as usize / STUDY_WINDOW_LEN;
    let times: Vec<f64> = (0..blocks)
        .map(|b| block_centre_time_s(start + (b * STUDY_WINDOW_LEN) as u64, STUDY_WINDOW_LEN, fs))
        .collect();
    if known_positions < 2 || known_positions > times.len() {
        return Err(Error::bad_input(format!(
            "{known_positions} known positions: need 2 ..= {} (the record has {} epochs of {STUDY_WINDOW_LEN} samples)",
            times.len().max(2),
            times.len()
        )));
    }
    for &t in &times[..known_positions] {
        let p = sc.pose_at(t).position_m;
        check_known_position([p.x, p.y, p.z]).map_err(|m| {
            Error::bad_input(format!(
                "em calibrate would refuse the known position at {t} s (fields 'range_min_m', 'range_max_m', 'mean_direction', 'swing_amplitude_m'): {m}"
            ))
        })?;
    }
    let rec = synthesize(&sc)?;
    // The simulator models nothing as missing: NaN or ∞ is an overflow of
    // the scenario's values (a rotation rate of −10³⁰⁸ °/s).
    if let Some(k) = rec.samples.iter().position(|v| !v.is_finite()) {
        return Err(Error::bad_input(format!(
            "scenario: the values are too large for the simulator: the simulated coil {} is {} at frame {}",
            k % 3 + 1,
            rec.samples[k],
            k / 3 + 1
        )));
    }
    debug_assert_eq!(rec.header, header);
    crate::model_file::create_output_folder(out)?;
    let [raw, system, known, truth, scenario] = SimulatedEm::FILE_NAMES.map(|n| out.join(n));
    let files = SimulatedEm {
        raw,
        system,
        known,
        truth,
        scenario,
        frames: rec.header.frames,
        epochs: times.len(),
    };
    let scenario = toml::to_string(cfg).map_err(|e| Error::Serialize {
        what: "EM scenario",
        reason: e.to_string(),
    })?;
    // The five as a set (each was renamed into place as it was written: a
    // folder in the place of em.truth.csv left a new record beside the old
    // scenario): all checked, written to temporaries (the record streamed
    // to its own), then renamed one right after another.
    let werr = |(path, e): (PathBuf, std::io::Error)| Error::write(path, e);
    let mut set = FileSet::new(
        [
            &files.raw,
            &files.system,
            &files.known,
            &files.truth,
            &files.scenario,
        ]
        .map(|p| p.as_path()),
    )
    .map_err(werr)?;
    let mut failure = None;
    set.write(&files.raw, |w| {
        write_raw(w, &rec.header, &rec.samples).map_err(|e| {
            failure = Some(e);
            std::io::Error::other("write failed")
        })
    })
    .map_err(|e| failure.take().map_or_else(|| werr(e), Error::from))?;
    let system = serde_json::to_string_pretty(&rec.header.system)?;
    let texts = [
        (&files.system, system),
        (
            &files.known,
            known_csv(&sc, &times[..known_positions], &times[..1]),
        ),
        (&files.truth, truth_csv(&sc, &times)),
        (&files.scenario, scenario),
    ];
    for (path, text) in texts {
        set.write(path, |w| w.write_all(text.as_bytes()))
            .map_err(werr)?;
    }
    set.commit().map_err(werr)?;
    Ok(files)
}

impl SimulatedEm {
    /// The names of the five files [`simulate_to_dir`] writes in its
    /// folder: record, system, known positions, truth, scenario.
    pub const FILE_NAMES: [&str; 5] = [
        "em.raw",
        "em.system.json",
        "em.known.csv",
        "em.truth.csv",
        "em.toml",
    ];
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Scenarios whose record `em detect` (or whose KNOWN file `em
    /// calibrate`) refuses were simulated and written (exit 0): they are
    /// bad input naming the field, and nothing is written.
    #[test]
    fn scenarios_detect_or_calibrate_would_refuse_are_bad_input() {
        let dir =
            std::env::temp_dir().join(format!("aeromag-em-sim-refuse-{}", std::process::id()));
        let base = EmSimConfig {
            duration_s: 0.32,
            ..command_default()
        };
        let cases: [(EmSimConfig, &str); 7] = [
            (
                EmSimConfig {
                    coil_gain_v_per_t_s: 0.0,
                    ..base.clone()
                },
                "'coil_gain_v_per_t_s' is 0, expected",
            ),
            (
                EmSimConfig {
                    moments_am2: nalgebra::Matrix3::zeros(),
                    ..base.clone()
                },
                "'moments_am2' is singular",
            ),
            (
                EmSimConfig {
                    frequencies_hz: [1025.0, 1025.0, 3125.0],
                    ..base.clone()
                },
                "'frequencies_hz' holds 1025 Hz twice",
            ),
            (
                EmSimConfig {
                    pilot_offset_hz: 0.0,
                    ..base.clone()
                },
                "'pilot_offset_hz' is 0, expected",
            ),
            (
                EmSimConfig {
                    start_time_s: -100.0,
                    ..base.clone()
                },
                "'start_time_s' is -100 s, expected 0 …",
            ),
            (
                EmSimConfig {
                    start_time_s: 1e15,
                    ..base.clone()
                },
                "'start_time_s' is 1000000000000000 s, expected 0 …",
            ),
            (
                EmSimConfig {
                    range_min_m: 15_000.0,
                    range_max_m: 20_000.0,
                    ..base.clone()
                },
                "expected 1 … 10000 m",
            ),
        ];
        for (cfg, want) in cases {
            let e = simulate_to_dir(&cfg, 2, &dir).unwrap_err();
            assert!(e.is_bad_input(), "{e}");
            assert!(e.to_string().contains(want), "{e}");
            assert!(!dir.exists(), "{want}: wrote {}", dir.display());
        }
    }
}
