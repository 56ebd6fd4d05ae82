//! Synchronous detection of a raw EM record, read in place or streamed in
//! chunks.

use super::files::RawSource;
use crate::error::{Error, InFile, Result};
use crate::observer::{Note, Notes, Observer};
use aeromag_core::filter::Window;
use aeromag_em::detection::{
    EmSystem, FieldEpoch, SPIKE_THRESHOLD, Spike, block_centre_time_s, major_axis,
};
use aeromag_em::study::{STUDY_WINDOW_LEN, rms};
use std::path::Path;

/// How a raw record is detected.
#[derive(Debug, Clone, PartialEq)]
pub struct DetectOptions {
    /// Detector block length N, samples (output rate f_s/N; default
    /// [`STUDY_WINDOW_LEN`]).
    pub window_len: usize,
    /// Weighting window: 4-term Blackman–Harris (default) or Nuttall, whose
    /// zeros fall on every bin ≥ 4 away.
    pub window: Window,
    /// Divide out the pilot-measured channel sensitivity (default true;
    /// `false` shows the channel drift).
    pub pilot: bool,
    /// Instrument constants instead of the raw header's.
    pub system: Option<EmSystem>,
}

impl Default for DetectOptions {
    fn default() -> Self {
        Self {
            window_len: STUDY_WINDOW_LEN,
            window: Window::BlackmanHarris,
            pilot: true,
            system: None,
        }
    }
}

/// What [`detect`] found.
#[derive(Debug, Clone)]
pub struct Detection {
    /// One complex field vector set per block.
    pub epochs: Vec<FieldEpoch>,
    /// Sample rate of the record, Hz.
    pub sample_rate_hz: f64,
    /// Detector block length, samples.
    pub window_len: usize,
    /// RMS polarisation ratio (minor/major axis) before calibration.
    pub polarization_ratio_rms: f64,
    /// Impulsive spikes repaired before detection (epoch order; frames are
    /// absolute sample indices); counted in a warning.
    pub spikes: Vec<Spike>,
    /// Warnings about the frequency plan and repaired spikes.
    pub notes: Vec<Note>,
}

/// Detect the complex field vectors of a raw EM record (seed 001 eq. 2):
/// for each non-overlapping block of N samples and each channel, the
/// FIR-weighted complex amplitude at the three working frequencies and at
/// the six pilot tones f ± δ; the pilots give the channel sensitivity ξ
/// (eq. 4), which is divided out together with the bench cross-coupling χ
/// and the coil transfer −iωg, leaving the complex field of each dipole in
/// receiver axes. With a 4-term window every tone on the bin grid f_s/N at
/// least 4 bins from a detector is rejected exactly; a plan off the grid is
/// a warning. Samples far outside their block's robust spread (impulsive
/// spikes: sferics, ADC glitches) are repaired by interpolation before
/// detection and counted in a warning naming the file, frame, epoch time
/// and channel ([`aeromag_em::detection::impulse`]). An epoch in which a
/// channel is flat (pilot sensitivity below [`FLAT_CHANNEL_RATIO`] of the
/// others': a dead or saturated channel) is left out, with a warning
/// naming the file, frames, epoch time and channel.
///
/// ```
/// use aeromag::em::files::{load_table, read_system};
/// use aeromag::em::{DetectOptions, HalfSpace, calibrate, command_default, detect, known_points, locate, simulate_to_dir};
/// use aeromag::Silent;
/// let dir = std::env::temp_dir().join(format!("aeromag-doc-em-{}", std::process::id()));
/// // Simulate a record with 8 known positions, then the file chain.
/// let files = simulate_to_dir(&command_default(), 8, &dir)?;
/// let detected = detect(&files.raw, &DetectOptions::default(), &mut Silent)?;
/// let known = known_points(&load_table(&files.known)?, &detected.epochs)?;
/// let cal = calibrate(&detected.epochs, &known, &read_system(&files.system)?, &HalfSpace::default())?;
/// let poses = locate(&detected.epochs, &cal.file, &HalfSpace::default(), &mut Silent)?;
/// assert_eq!(poses.failed(), 0);
/// assert!(cal.polarization_ratio_after < cal.polarization_ratio_before);
/// # std::fs::remove_dir_all(&dir).ok();
/// # Ok::<(), aeromag::Error>(())
/// ```
pub fn detect(path: &Path, opts: &DetectOptions, observer: &mut dyn Observer) -> Result<Detection> {
    let mut notes = Notes::new(observer);
    let file = path.display().to_string();
    let mut source = RawSource::open(path)?;
    let header = source.header().clone();
    let system = opts.system.clone().unwrap_or(header.system.clone());
    // The tones are where the transmitter put them when the record was
    // made: a system given in place of the header's (for its bench
    // constants) must agree on them. Swapped frequencies assigned the
    // fields to the wrong dipoles (every epoch mirrored, exit 0).
    if opts.system.is_some() {
        let h = &header.system;
        let same = |a: f64, b: f64| (a - b).abs() <= 1e-9 * a.abs().max(b.abs());
        let agree = (0..3).all(|i| same(system.frequencies_hz[i], h.frequencies_hz[i]))
            && same(system.pilot_offset_hz, h.pilot_offset_hz);
        if !agree {
            return Err(Error::bad_file(
                file.clone(),
                format!(
                    "the system given has frequencies {:?} Hz and pilot offset {} Hz, but the record was made at {:?} Hz and {} Hz (its header's system): a system of another record, or frequencies swapped or in kHz",
                    system.frequencies_hz,
                    system.pilot_offset_hz,
                    h.frequencies_hz,
                    h.pilot_offset_hz
                ),
            ));
        }
    }
    let fs = header.sample_rate_hz;
    let n = opts.window_len;
    if n < 8 || header.frames < n as u64 {
        return Err(Error::bad_input(format!(
            "window length {n}: need 8 ≤ N ≤ the record's {} frames ('{file}')",
            header.frames
        )));
    }
    let bin = fs / n as f64;
    let off_grid = |f: f64| ((f / bin) - (f / bin).round()).abs() > 1e-6;
    let pilot_bins = system.pilot_offset_hz / bin;
    if system.frequencies_hz.iter().any(|&f| off_grid(f)) || off_grid(system.pilot_offset_hz) {
        notes.warn(format!(
            "frequencies {:?} Hz / pilot offset {} Hz are not multiples of the bin f_s/N = {bin} Hz: cross-talk is not exactly zero",
            system.frequencies_hz, system.pilot_offset_hz
        ));
    }
    // Less than one bin apart, a pilot and its working tone fall in the
    // same bin of an N-sample block: no window separates them (N = 1600
    // gave ranges of 5·10¹⁰ m). From 1 to 4 bins they are inside the
    // window's main lobe and leak (N = 4000 and 12000: position errors of
    // 50 m and 10 m, which locate's residual test fails).
    let min_n = (4.0 * fs / system.pilot_offset_hz).ceil();
    if pilot_bins < 1.0 - 1e-9 {
        return Err(Error::bad_input(format!(
            "window length {n} ({} s of '{file}'): the pilot offset {} Hz is {pilot_bins:.2} bins f_s/N, so the pilots fall in their working tones' bins and cannot be resolved; use N ≥ {min_n} (4 bins)",
            aeromag_core::error::figure(n as f64 / fs),
            system.pilot_offset_hz
        )));
    }
    if pilot_bins < 4.0 - 1e-9 {
        notes.warn(format!(
            "window length N = {n} samples: pilot offset {} Hz is {pilot_bins:.2} bins (< 4): the pilots leak into the working detector; use N ≥ {min_n}",
            system.pilot_offset_hz
        ));
    }
    system.check_tone_plan(fs, n).in_file(&file)?;
    // The detector (its window and nine kernels, 1–2 ms) is built while
    // the mapped record is checked finite (the check brings its pages in):
    // each on its own threads, neither waiting for the other.
    let (chain, checked) = std::thread::scope(|s| {
        let checking = s.spawn(|| source.check_in_advance(path));
        let chain = system.chain(fs, n, opts.window, opts.pilot);
        (chain, checking.join())
    });
    let chain = chain.in_file(&file)?;
    checked.unwrap_or_else(|panic| std::panic::resume_unwind(panic))?;
    notes.stage("detecting");
    notes.check_cancelled()?;
    // Streamed: whole detector blocks of about 2¹⁸ frames (3 MB) per
    // chunk, the default 10.24 s record in four. Mapped: in one piece.
    let chunk = n * (1usize << 18).div_ceil(n);
    let mut epochs = Vec::new();
    let mut spikes = Vec::new();
    source.for_each_chunk(path, chunk, |first, samples| {
        let (got, found) = chain
            .process_with_spikes(samples, first)
            .map_err(|e| silent_channel(&file, first, n, samples, e))?;
        epochs.extend(got);
        spikes.extend(found);
        Ok(())
    })?;
    if let Some(s) = spikes.first() {
        // Frames of the file (as in the non-finite sample's message); the
        // epoch time is that of the detected CSV's `time_s`.
        let block_of = |s: &Spike| (s.frame - header.start_index) / n as u64;
        let mut blocks: Vec<u64> = spikes.iter().map(block_of).collect();
        blocks.dedup();
        let largest = spikes.iter().map(|s| s.statistic).fold(0.0, f64::max);
        notes.warn(format!(
            "'{file}': {} impulsive spike(s) in {} epoch(s) repaired by interpolation before detection (samples more than {SPIKE_THRESHOLD} robust spreads from their block's centre; largest {largest:.1}): the first at frame {} (epoch at {} s), channel {}, {} V",
            spikes.len(),
            blocks.len(),
            s.frame - header.start_index,
            block_centre_time_s(header.start_index + block_of(s) * n as u64, n, fs),
            s.channel,
            s.value
        ));
    }
    // Epochs with a flat channel (its pilots not in the signal) left out.
    let flat: Vec<(usize, usize, f64, f64)> = epochs
        .iter()
        .enumerate()
        .filter_map(|(k, e)| flat_channel(&e.xi).map(|(c, x, o)| (k, c, x, o)))
        .collect();
    if let Some(&(k, c, x, o)) = flat.first() {
        let a = k as u64 * n as u64;
        notes.warn(format!(
            "'{file}': a flat channel (no signal at the tones while the others carry it) in {} epoch(s), left out of the detected epochs: the first in frames {a} … {} (epoch at {} s), channel {c}, pilot-measured sensitivity |ξ| {} against {} on the other channels (a dead or saturated channel)",
            flat.len(),
            a + n as u64 - 1,
            epochs[k].time_s,
            aeromag_core::error::figure(x),
            aeromag_core::error::figure(o)
        ));
        let mut k = 0;
        epochs.retain(|_| {
            k += 1;
            !flat.iter().any(|f| f.0 == k - 1)
        });
    }
    let ratios: Vec<f64> = epochs
        .iter()
        .flat_map(|e| e.h.iter().map(|h| major_axis(h).ratio))
        .collect();
    Ok(Detection {
        epochs,
        sample_rate_hz: fs,
        window_len: n,
        polarization_ratio_rms: rms(&ratios),
        spikes,
        notes: notes.into_notes(),
    })
}

/// Below this fraction of the largest channel's pilot-measured
/// sensitivity |ξ| in an epoch, a channel is flat: it carries no signal at
/// the tones. Measured on the default flight: every channel of every epoch
/// 0.950–0.999 (gain drift 5 %); channel 1 held at 1 mV (or 1000 V) for a
/// block gave 1.2·10⁻¹² there, just above the pilot's "not detected"
/// (10⁻¹²), and calibration from it reached 2× instead of 1669×.
pub const FLAT_CHANNEL_RATIO: f64 = 1e-3;

/// The flat channel of an epoch whose sensitivities are `xi[i][c]`
/// (frequency `i`, channel `c`), with its largest |ξ| and the epoch's
/// largest: a channel whose |ξ| at every frequency is below
/// [`FLAT_CHANNEL_RATIO`] of the epoch's largest.
fn flat_channel(xi: &[[aeromag_em::detection::Complex64; 3]; 3]) -> Option<(usize, f64, f64)> {
    let of = |c: usize| (0..3).map(|i| xi[i][c].norm()).fold(0.0, f64::max);
    let largest = (0..3).map(of).fold(0.0, f64::max);
    (0..3)
        .find(|&c| of(c) < FLAT_CHANNEL_RATIO * largest)
        .map(|c| (c, of(c), largest))
}

/// The error of detecting a chunk of `samples` (interleaved, 3 channels,
/// absolute first frame `first`, detector blocks of `n` frames) in `file`:
/// when a channel is 0 in every sample of the chunk or of a block, the
/// record carries no signal there, which is what the pilot's "not
/// detected" meant (an all-zero record gave "invalid data: pilot not
/// detected on channel 0" without the file).
fn silent_channel(
    file: &str,
    first: u64,
    n: usize,
    samples: &[f32],
    e: aeromag_em::EmError,
) -> Error {
    let frames = samples.len() / 3;
    let silent = |a: usize, b: usize, c: usize| (a..b).all(|k| samples[3 * k + c] == 0.0);
    if let Some(c) = (0..3).find(|&c| silent(0, frames, c)) {
        return Error::bad_file(
            file,
            format!(
                "channel {c} is 0 in every sample of frames {first} … {}: the record carries no signal ({e})",
                first + frames as u64 - 1
            ),
        );
    }
    for a in (0..frames).step_by(n.max(1)) {
        let b = (a + n).min(frames);
        if let Some(c) = (0..3).find(|&c| silent(a, b, c)) {
            return Error::bad_file(
                file,
                format!(
                    "channel {c} is 0 in every sample of frames {} … {}: no signal in that detector block ({e})",
                    first + a as u64,
                    first + b as u64 - 1
                ),
            );
        }
    }
    Err::<(), _>(e).in_file(file).unwrap_err()
}
