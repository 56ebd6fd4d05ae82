//! `aeromag em detect`: raw ADC record → detected complex field vectors.

use super::files::{next_chunk, open_raw, read_system};
use crate::exit::bad_input;
use aeromag_core::filter::Window;
use aeromag_em::detection::major_axis;
use aeromag_em::sim::detected_csv;
use aeromag_em::study::{STUDY_WINDOW_LEN, rms};
use std::path::PathBuf;

/// Detect the complex field vectors of a raw EM record (pilot-corrected).
///
/// Synchronous detection (seed 001 eq. 2): for each
/// non-overlapping block of N samples and each channel, the FIR-weighted
/// complex amplitude at the three working frequencies and at the six pilot
/// tones f ± δ; the pilots give the channel sensitivity ξ (eq. 4), which is
/// divided out together with the bench cross-coupling χ and the coil
/// transfer −iωg, leaving the complex field of each dipole in receiver axes.
/// Frequencies, pilot offset, coil gain and χ come from the raw header
/// (or --system).
///
/// Frequency plan: with a 4-term window (Blackman–Harris, Nuttall) every
/// tone on the bin grid f_s/N at least 4 bins from a detector is rejected
/// exactly; the command warns when the plan is off the grid.
///
/// Output CSV, one row per block: time_s (block centre), h{i}_{x,y,z}_re_t /
/// _im_t (field of dipole i = 1..3, T), xi{i}_{x,y,z}_re / _im (pilot-measured
/// sensitivity, detected pilot / nominal; 1 with --no-pilot), pol_ratio_{i}
/// (polarisation ratio, minor/major axis, before calibration).
///
/// Example: `aeromag em detect --input em/em.raw --out em/detected.csv`
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct DetectArgs {
    /// Raw record (`aeromag em simulate` writes DIR/em.raw).
    #[arg(long, short = 'i', value_name = "RAW")]
    input: PathBuf,
    /// Detected-vector CSV to write.
    #[arg(long, value_name = "DETECTED.csv")]
    out: PathBuf,
    /// Skip the pilot correction (ξ = 1): shows the channel drift.
    #[arg(long)]
    no_pilot: bool,
    /// Detector block length N, samples (output rate f_s/N).
    #[arg(long, value_name = "N", default_value_t = STUDY_WINDOW_LEN)]
    window_len: usize,
    /// Weighting window: blackman-harris or nuttall (4-term: zeros at ≥ 4 bins).
    #[arg(long, value_name = "NAME", default_value = "blackman-harris")]
    window: String,
    /// Instrument constants (JSON, as em.system.json) instead of the raw
    /// header's.
    #[arg(long, value_name = "FILE.json")]
    system: Option<PathBuf>,
}

fn window(name: &str) -> anyhow::Result<Window> {
    match name {
        "blackman-harris" => Ok(Window::BlackmanHarris),
        "nuttall" => Ok(Window::Nuttall),
        _ => Err(bad_input!(
            "--window '{name}': expected blackman-harris or nuttall"
        )),
    }
}

pub fn run(a: DetectArgs) -> anyhow::Result<()> {
    let win = window(&a.window)?;
    let mut reader = open_raw(&a.input)?;
    let header = reader.header().clone();
    let system = match &a.system {
        Some(p) => read_system(p)?,
        None => header.system.clone(),
    };
    let fs = header.sample_rate_hz;
    let n = a.window_len;
    if n < 8 || header.frames < n as u64 {
        return Err(bad_input!(
            "--window-len {n}: need 8 ≤ N ≤ the record's {} frames ('{}')",
            header.frames,
            a.input.display()
        ));
    }
    let bin = fs / n as f64;
    let off_grid = |f: f64| ((f / bin) - (f / bin).round()).abs() > 1e-6;
    let pilot_bins = system.pilot_offset_hz / bin;
    if system.frequencies_hz.iter().any(|&f| off_grid(f)) || off_grid(system.pilot_offset_hz) {
        eprintln!(
            "warning: frequencies {:?} Hz / pilot offset {} Hz are not multiples of the bin f_s/N = {bin} Hz: cross-talk is not exactly zero",
            system.frequencies_hz, system.pilot_offset_hz
        );
    }
    if pilot_bins < 4.0 - 1e-9 {
        eprintln!(
            "warning: pilot offset {} Hz is {pilot_bins:.2} bins (< 4): the pilots leak into the working detector",
            system.pilot_offset_hz
        );
    }
    let chain = system
        .chain(fs, n, win, !a.no_pilot)
        .map_err(|e| bad_input!("'{}': {e}", a.input.display()))?;
    // Whole detector blocks of about 2¹⁸ frames (3 MB) per chunk: the
    // default 10.24 s record is read in four.
    let chunk = n * (1usize << 18).div_ceil(n);
    let mut samples = Vec::new();
    let mut epochs = Vec::new();
    loop {
        let (first, got) = next_chunk(&mut reader, &a.input, chunk, &mut samples)?;
        if got == 0 {
            break;
        }
        epochs.extend(chain.process(&samples, first)?);
    }
    std::fs::write(&a.out, detected_csv(&epochs))?;
    let ratios: Vec<f64> = epochs
        .iter()
        .flat_map(|e| e.h.iter().map(|h| major_axis(h).ratio))
        .collect();
    println!(
        "detected {} epochs of {n} samples ({:.3} s, {:.2} Hz output) from '{}'{}; polarisation ratio RMS {:.3e} (before calibration)",
        epochs.len(),
        n as f64 / fs,
        bin,
        a.input.display(),
        if a.no_pilot {
            ", no pilot correction"
        } else {
            ""
        },
        rms(&ratios)
    );
    println!("  detected  {}", a.out.display());
    Ok(())
}
