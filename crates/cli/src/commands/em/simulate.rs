//! `aeromag em simulate` (also `aeromag simulate em`): the ADC record of an
//! EM positioning flight plus its truth and the calibration information a
//! crew would have (library: [`aeromag::em::simulate_to_dir`]).

use aeromag::em::DEFAULT_KNOWN;
use std::path::PathBuf;

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

pub fn run(a: SimulateArgs) -> anyhow::Result<()> {
    crate::output::simulate_em(
        a.config.as_deref(),
        a.seed,
        a.out.as_deref(),
        a.print_config,
        a.known_positions,
    )
}
