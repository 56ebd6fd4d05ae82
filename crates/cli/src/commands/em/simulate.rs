//! `aeromag em simulate` (also `aeromag simulate em`): the ADC record of an
//! EM positioning flight plus its truth and the calibration information a
//! crew would have.

use crate::exit::bad_input;
use aeromag_em::detection::block_centre_time_s;
use aeromag_em::sim::{EmScenario, EmSimConfig, known_csv, synthesize, truth_csv, write_raw};
use aeromag_em::study::STUDY_WINDOW_LEN;
use std::path::{Path, PathBuf};

/// Simulate an EM positioning flight: raw ADC record, system, KNOWN and truth files.
///
/// The `em` scenario at ADC level: a three-dipole transmitter on the
/// aircraft (1025, 2075, 3125 Hz), a towed bird 30–100 m behind and below
/// that swings and turns, three induction-coil channels (∝ dB/dt) at
/// 100 kHz with the pilot tones (f ± 25 Hz), cross-coupling χ, drifting
/// channel gains/phases, transmitter distortion, coil noise, 400 Hz
/// harmonics and sferics (spec em-positioning.md, seed 001).
///
/// Writes to DIR:
///   em.raw          the ADC record: bytes 0..8 "AEMRAW1\n", bytes 8..12 u32 LE
///                   header length L, L bytes of JSON header (sample_rate_hz,
///                   channels, frames, start_index, system = instrument
///                   constants), then frames × 3 little-endian f32 volts,
///                   interleaved (frame n, channel c at index 3n + c)
///   em.system.json  the instrument constants alone (frequencies, pilot, coil
///                   gain, bench cross-coupling χ, nominal moments) for
///                   `em calibrate --system`
///   em.known.csv    calibration information (format of `em calibrate
///                   --known`): positions at the first N detector epochs,
///                   attitude at the first
///   em.truth.csv    true pose at every 16 000-sample detector epoch
///                   (time_s, true_x_m … true_yaw_deg); never read by the
///                   other commands
///   em.toml         the scenario with every default filled in
///
/// Default: 10.24 s (64 epochs of 0.16 s), about 12 MB, a second or two.
///
/// Examples:
///   aeromag em simulate --out em/
///   aeromag em simulate --print-config > em.toml
///   aeromag em simulate --config em.toml --seed 3 --out em3/
///   aeromag simulate em --out em/        (the same command)
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct SimulateArgs {
    /// Output folder (created if needed).
    #[arg(long, value_name = "DIR", required_unless_present = "print_config")]
    out: Option<PathBuf>,
    /// Scenario file (TOML); keys not given take the defaults.
    #[arg(long, value_name = "FILE.toml")]
    config: Option<PathBuf>,
    /// Random seed (overrides the scenario file's seed).
    #[arg(long)]
    seed: Option<u64>,
    /// Print the default scenario (TOML) and exit.
    #[arg(long)]
    print_config: bool,
    /// Epochs at the start of the record whose position is given in
    /// em.known.csv (calibration stage 2; ≥ 2).
    #[arg(long, value_name = "N", default_value_t = DEFAULT_KNOWN)]
    known_positions: usize,
}

/// Known positions written by default.
pub const DEFAULT_KNOWN: usize = 8;

/// Defaults of the command: the library scenario, 10.24 s long.
fn cli_default() -> EmSimConfig {
    EmSimConfig {
        duration_s: 10.24,
        ..EmSimConfig::default()
    }
}

/// The scenario from the command defaults overlaid with the TOML text
/// (unknown keys are errors).
fn parse_config(text: Option<&str>, file: &str) -> anyhow::Result<EmSimConfig> {
    let toml::Value::Table(mut table) = toml::Value::try_from(cli_default())? else {
        anyhow::bail!("default scenario does not serialise to a TOML table");
    };
    if let Some(text) = text {
        let user: toml::Table = toml::from_str(text).map_err(|e| bad_input!("'{file}': {e}"))?;
        table.extend(user);
    }
    toml::Value::Table(table)
        .try_into()
        .map_err(|e| bad_input!("'{file}': {e}"))
}

pub fn run(a: SimulateArgs) -> anyhow::Result<()> {
    simulate_em(
        a.config.as_deref(),
        a.seed,
        a.out.as_deref(),
        a.print_config,
        a.known_positions,
    )
}

/// The command; `aeromag simulate em` calls it with the default number of
/// known positions.
pub fn simulate_em(
    config: Option<&Path>,
    seed: Option<u64>,
    out: Option<&Path>,
    print_config: bool,
    known_positions: usize,
) -> anyhow::Result<()> {
    if print_config {
        print!("{}", toml::to_string(&cli_default())?);
        return Ok(());
    }
    let text = match config {
        Some(p) => Some(
            std::fs::read_to_string(p)
                .map_err(|e| bad_input!("cannot read scenario file '{}': {e}", p.display()))?,
        ),
        None => None,
    };
    let file = config.map_or_else(|| "defaults".to_string(), |p| p.display().to_string());
    let mut cfg = parse_config(text.as_deref(), &file)?;
    if let Some(s) = seed {
        cfg.seed = s;
    }
    let out = out.ok_or_else(|| bad_input!("--out DIR is required"))?;
    let sc = EmScenario::new(cfg.clone()).map_err(|e| bad_input!("'{file}': {e}"))?;
    let fs = cfg.sample_rate_hz;
    let frames = (cfg.duration_s * fs).round();
    if frames > 2e9 {
        return Err(bad_input!(
            "'{file}': {frames} frames is more than this command writes (2e9)"
        ));
    }
    let spinner = crate::progress::spinner("simulating em");
    let rec = synthesize(&sc)?;
    spinner.finish_and_clear();
    let start = rec.header.start_index;
    let blocks = rec.header.frames as usize / STUDY_WINDOW_LEN;
    let times: Vec<f64> = (0..blocks)
        .map(|b| block_centre_time_s(start + (b * STUDY_WINDOW_LEN) as u64, STUDY_WINDOW_LEN, fs))
        .collect();
    if known_positions < 2 || known_positions > times.len() {
        return Err(bad_input!(
            "--known-positions {known_positions}: need 2 ..= {} (the record has {} epochs of {STUDY_WINDOW_LEN} samples)",
            times.len().max(2),
            times.len()
        ));
    }
    std::fs::create_dir_all(out)?;
    let path = |n: &str| out.join(n);
    let raw = path("em.raw");
    let mut w = std::io::BufWriter::new(std::fs::File::create(&raw)?);
    write_raw(&mut w, &rec.header, &rec.samples)?;
    std::io::Write::flush(&mut w)?;
    std::fs::write(
        path("em.system.json"),
        serde_json::to_string_pretty(&rec.header.system)?,
    )?;
    std::fs::write(
        path("em.known.csv"),
        known_csv(&sc, &times[..known_positions], &times[..1]),
    )?;
    std::fs::write(path("em.truth.csv"), truth_csv(&sc, &times))?;
    std::fs::write(path("em.toml"), toml::to_string(&cfg)?)?;
    println!(
        "simulated em (seed {}): {} frames × 3 channels at {} Hz ({} s, {} epochs of {STUDY_WINDOW_LEN} samples)",
        cfg.seed,
        rec.header.frames,
        fs,
        cfg.duration_s,
        times.len()
    );
    for (what, n) in [
        ("raw", "em.raw"),
        ("system", "em.system.json"),
        ("known", "em.known.csv"),
        ("truth", "em.truth.csv"),
        ("scenario", "em.toml"),
    ] {
        println!("  {what:<9} {}", path(n).display());
    }
    Ok(())
}
