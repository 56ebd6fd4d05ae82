//! FIR-weighted synchronous detection (seed `001_…` part II, eq. 2; spec
//! `em-positioning.md`, "Signal chain" item 1).
//!
//! For a block of `N` samples `u[n]` starting at absolute sample index `n₀`,
//! at each frequency `ω = 2π f`:
//!
//! ```text
//! U = (2/Σf) Σ_n f[n] u[n] e^{iω (n₀+n)/f_s}
//! ```
//!
//! so that `u(t) = a cos ωt + b sin ωt` gives `U = a + ib` (i.e.
//! `u = Re(U e^{−iωt})`); the seed's `U_c + iU_s` with the `1/l` scaling
//! replaced by the window sum. Blocks do not overlap: the output rate is
//! `f_s/N` (6.25 Hz for the default 16 000 samples at 100 kHz; the seed uses
//! 6.6 Hz).
//!
//! ## Frequency response
//!
//! For a unit input `cos(ω't + θ)` the output is
//! `A(ω−ω') e^{−iθ} + A(ω+ω') e^{iθ}` with `A(Δ) = Σ f[n] e^{iΔn/f_s}/Σf`;
//! [`SyncDetector::frequency_response`] returns the worst case over `θ`,
//! `|A(ω−ω')| + |A(ω+ω')|`.
//!
//! ## Implementation
//!
//! `f[n] e^{iωn/f_s}·2/Σf` is tabulated once per frequency (f32); a block is
//! two dot products per frequency and channel, accumulated in 32 f32 lanes
//! (AVX2 when available, same arithmetic otherwise) and flushed into f64
//! every 1024 samples, followed by the phase factor `e^{iω n₀/f_s}` (f64) of
//! the block start. Three channels share each kernel load.

use super::Complex64;
use super::impulse::{self, Spike};
use crate::{EmError, Result};
use aeromag_core::filter::{Symmetry, Window};
use std::f64::consts::TAU;

/// Configuration of the synchronous detector.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DetectorConfig {
    /// ADC sampling rate, Hz.
    pub sample_rate_hz: f64,
    /// Window (block) length `N`, samples.
    pub window_len: usize,
    /// Weighting window `f` (periodic variant is used).
    pub window: Window,
    /// Detection frequencies, Hz (working and pilot).
    pub frequencies_hz: Vec<f64>,
}

impl DetectorConfig {
    /// The three-frequency plan of the EM system: for each working
    /// frequency `f_i`, the detectors `f_i`, `f_i − δ`, `f_i + δ` (the layout
    /// [`super::FieldChain`] expects), Blackman–Harris weighting.
    ///
    /// Default of the seed-like system: `f_s` = 100 kHz, `N` = 16 000
    /// (6.25 Hz bins and output rate), `f_i` = 1025, 2075, 3125 Hz,
    /// `δ` = 25 Hz (4 bins): every working, pilot and odd 400 Hz harmonic
    /// frequency is on a bin ≥ 4 bins from every detector, so cross-talk is
    /// exactly zero.
    pub fn three_frequency_plan(
        sample_rate_hz: f64,
        window_len: usize,
        working_hz: [f64; 3],
        pilot_offset_hz: f64,
    ) -> Self {
        let frequencies_hz = working_hz
            .iter()
            .flat_map(|&f| [f, f - pilot_offset_hz, f + pilot_offset_hz])
            .collect();
        Self {
            sample_rate_hz,
            window_len,
            window: Window::BlackmanHarris,
            frequencies_hz,
        }
    }

    /// Bin width `f_s/N`, Hz: frequencies on multiples of it are exact zeros
    /// of the other detectors' responses (≥ 4 bins apart for 4-term windows).
    pub fn bin_hz(&self) -> f64 {
        self.sample_rate_hz / self.window_len as f64
    }
}

/// One detected block: amplitudes for every frequency and channel.
#[derive(Debug, Clone, PartialEq)]
pub struct Epoch {
    /// Absolute index of the block's first sample.
    pub start_index: u64,
    /// Time of the block centre, s from sample 0.
    pub centre_time_s: f64,
    /// `values[k * channels + c]`: frequency `k`, channel `c`, in input units.
    pub values: Vec<Complex64>,
    /// Impulsive spikes repaired before detection ([`impulse`]), channel
    /// by channel, each in frame order.
    pub spikes: Vec<Spike>,
}

/// FIR-weighted synchronous detector with precomputed kernels.
#[derive(Debug, Clone)]
pub struct SyncDetector {
    config: DetectorConfig,
    weights: Vec<f64>,
    kernels_re: Vec<Vec<f32>>,
    kernels_im: Vec<Vec<f32>>,
    avx2: bool,
    /// Sub-block length of the impulse test ([`impulse::sub_block_len`]).
    spike_sub_len: usize,
}

const LANES: usize = 32;
const FLUSH: usize = 1024;

/// `(Σ u·re, Σ u·im)` with f32 lanes flushed into f64 every [`FLUSH`]
/// samples. Separate multiply and add (no FMA), so every code path gives
/// bit-identical results.
#[inline(always)]
fn dot2_body(u: &[f32], re: &[f32], im: &[f32]) -> (f64, f64) {
    let mut sr = 0.0f64;
    let mut si = 0.0f64;
    for ((uc, rc), ic) in u.chunks(FLUSH).zip(re.chunks(FLUSH)).zip(im.chunks(FLUSH)) {
        let mut ar = [0.0f32; LANES];
        let mut ai = [0.0f32; LANES];
        let nl = uc.len() / LANES * LANES;
        for ((ul, rl), il) in uc[..nl]
            .chunks_exact(LANES)
            .zip(rc[..nl].chunks_exact(LANES))
            .zip(ic[..nl].chunks_exact(LANES))
        {
            for j in 0..LANES {
                ar[j] += ul[j] * rl[j];
                ai[j] += ul[j] * il[j];
            }
        }
        for j in nl..uc.len() {
            ar[j - nl] += uc[j] * rc[j];
            ai[j - nl] += uc[j] * ic[j];
        }
        sr += ar.iter().map(|&v| f64::from(v)).sum::<f64>();
        si += ai.iter().map(|&v| f64::from(v)).sum::<f64>();
    }
    (sr, si)
}

/// [`dot2_body`] compiled for AVX2 (8-wide f32 vectors).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn dot2_avx2(u: &[f32], re: &[f32], im: &[f32]) -> (f64, f64) {
    dot2_body(u, re, im)
}

/// Lanes per quarter of a tile: one AVX2 register of f32.
const QUARTER: usize = LANES / 4;

/// Whole tiles of [`LANES`] samples (three channels, the kernel's real
/// and imaginary parts, every slice the same length, a multiple of
/// `LANES`): the sums of lanes `Q..Q + QUARTER` of each tile, each lane in
/// sample order, written to those lanes of `ar` and `ai` (per channel).
///
/// `Q` is a constant and every tile a `LANES`-long chunk, so the loop
/// carries no bounds checks: 20 instructions a step where indexing the
/// slices took 30 (a single-thread detection was not measurably faster
/// for it, the arithmetic sets the pace).
#[inline(always)]
fn quarter_sums<const Q: usize>(
    (u, re, im): ([&[f32]; 3], &[f32], &[f32]),
    ar: &mut [[f32; LANES]; 3],
    ai: &mut [[f32; LANES]; 3],
) {
    let mut sr = [[0.0f32; QUARTER]; 3];
    let mut si = [[0.0f32; QUARTER]; 3];
    let tiles = re
        .chunks_exact(LANES)
        .zip(im.chunks_exact(LANES))
        .zip(u[0].chunks_exact(LANES))
        .zip(u[1].chunks_exact(LANES))
        .zip(u[2].chunks_exact(LANES));
    for ((((r, i), u0), u1), u2) in tiles {
        let rl = &r[Q..Q + QUARTER];
        let il = &i[Q..Q + QUARTER];
        for (c, uc) in [u0, u1, u2].into_iter().enumerate() {
            let ul = &uc[Q..Q + QUARTER];
            for j in 0..QUARTER {
                sr[c][j] += ul[j] * rl[j];
                si[c][j] += ul[j] * il[j];
            }
        }
    }
    for c in 0..3 {
        ar[c][Q..Q + QUARTER].copy_from_slice(&sr[c]);
        ai[c][Q..Q + QUARTER].copy_from_slice(&si[c]);
    }
}

/// Three channels against one kernel: `[(Σ u_c·re, Σ u_c·im); 3]`, the
/// kernel loaded once for all three (same arithmetic as [`dot2_body`] per
/// channel, so results are bit-identical to it).
///
/// The 32 lanes of a tile are summed a quarter (8 lanes, one AVX2
/// register) at a time: each lane still adds its products in sample
/// order, so the bits are those of all 32 at once, but the six sums of a
/// quarter (three channels, real and imaginary) stay in registers, where
/// all 24 vectors of sums did not fit and were written to the stack and
/// read back on every step (`perf annotate`: half the samples of the
/// function on such a reload).
#[inline(always)]
fn dot2x3_body(u: [&[f32]; 3], re: &[f32], im: &[f32]) -> [(f64, f64); 3] {
    let mut out = [(0.0f64, 0.0f64); 3];
    let n = re.len();
    let mut start = 0;
    while start < n {
        let end = (start + FLUSH).min(n);
        let mut ar = [[0.0f32; LANES]; 3];
        let mut ai = [[0.0f32; LANES]; 3];
        let nl = start + (end - start) / LANES * LANES;
        let tiles = (
            [&u[0][start..nl], &u[1][start..nl], &u[2][start..nl]],
            &re[start..nl],
            &im[start..nl],
        );
        quarter_sums::<0>(tiles, &mut ar, &mut ai);
        quarter_sums::<QUARTER>(tiles, &mut ar, &mut ai);
        quarter_sums::<{ 2 * QUARTER }>(tiles, &mut ar, &mut ai);
        quarter_sums::<{ 3 * QUARTER }>(tiles, &mut ar, &mut ai);
        for j in nl..end {
            for c in 0..3 {
                ar[c][j - nl] += u[c][j] * re[j];
                ai[c][j - nl] += u[c][j] * im[j];
            }
        }
        for c in 0..3 {
            out[c].0 += ar[c].iter().map(|&v| f64::from(v)).sum::<f64>();
            out[c].1 += ai[c].iter().map(|&v| f64::from(v)).sum::<f64>();
        }
        start = end;
    }
    out
}

/// [`dot2x3_body`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn dot2x3_avx2(u: [&[f32]; 3], re: &[f32], im: &[f32]) -> [(f64, f64); 3] {
    dot2x3_body(u, re, im)
}

/// Dispatch of [`dot2x3_body`] (see [`dot2`]).
fn dot2x3(u: [&[f32]; 3], re: &[f32], im: &[f32], avx2: bool) -> [(f64, f64); 3] {
    #[cfg(target_arch = "x86_64")]
    if avx2 {
        // SAFETY: `avx2` is true only if the CPU reported AVX2 (see `SyncDetector::new`).
        return unsafe { dot2x3_avx2(u, re, im) };
    }
    let _ = avx2;
    dot2x3_body(u, re, im)
}

/// Dispatch to the AVX2 build of the dot product when the CPU has it.
fn dot2(u: &[f32], re: &[f32], im: &[f32], avx2: bool) -> (f64, f64) {
    #[cfg(target_arch = "x86_64")]
    if avx2 {
        // SAFETY: `avx2` is true only if `is_x86_feature_detected!("avx2")`
        // returned true when the detector was built (see `SyncDetector::new`).
        return unsafe { dot2_avx2(u, re, im) };
    }
    let _ = avx2;
    dot2_body(u, re, im)
}

/// Time of the centre of a block of `window_len` samples whose first sample
/// has absolute index `first_index`, at `sample_rate_hz`:
/// `(n₀ + (N − 1)/2)/f_s`, s (the [`Epoch::centre_time_s`] of every block).
pub fn block_centre_time_s(first_index: u64, window_len: usize, sample_rate_hz: f64) -> f64 {
    (first_index as f64 + (window_len as f64 - 1.0) / 2.0) / sample_rate_hz
}

/// `e^{iω n₀/f_s}`: phase of the reference at the block start.
fn block_phase(f_hz: f64, fs: f64, start_index: u64) -> Complex64 {
    let cycles = (f_hz / fs) * start_index as f64;
    let ph = TAU * cycles.fract();
    Complex64::new(ph.cos(), ph.sin())
}

impl SyncDetector {
    /// Build the detector.
    ///
    /// Errors ([`EmError::InvalidArgument`]): non-positive rate, window shorter
    /// than 8 samples, no frequencies, or a frequency outside `(0, f_s/2)`.
    pub fn new(config: DetectorConfig) -> Result<Self> {
        let fs = config.sample_rate_hz;
        if !crate::positive_finite(fs) {
            return Err(EmError::InvalidArgument {
                reason: format!("sample rate {fs} Hz"),
            });
        }
        if config.window_len < 8 {
            return Err(EmError::InvalidArgument {
                reason: "window shorter than 8 samples".into(),
            });
        }
        if config.frequencies_hz.is_empty() {
            return Err(EmError::InvalidArgument {
                reason: "no detection frequencies".into(),
            });
        }
        if let Some(f) = config
            .frequencies_hz
            .iter()
            .find(|&&f| !(f > 0.0 && f < fs / 2.0))
        {
            return Err(EmError::InvalidArgument {
                reason: format!("frequency {f} Hz outside (0, fs/2)"),
            });
        }
        // On the bin grid (f = k f_s/N, the frequency plan's rule) the
        // phase 2π f n/f_s is 2π ((k n) mod N)/N: one table of N phasors
        // serves every frequency (N sines and cosines instead of N per
        // frequency; the phase is also exact, without the integer part
        // that f n/f_s carries).
        let len = config.window_len;
        let bins_of = |f: f64| f * len as f64 / fs;
        let on_grid = |bins: f64| (bins - bins.round()).abs() <= 1e-9 * bins.max(1.0);
        let any_on_grid = config.frequencies_hz.iter().any(|&f| on_grid(bins_of(f)));
        let weights = config.window.samples(len, Symmetry::Periodic)?;
        let unit: Vec<(f64, f64)> = if any_on_grid {
            (0..len)
                .map(|m| (TAU * (m as f64 / len as f64)).sin_cos())
                .collect()
        } else {
            Vec::new()
        };
        let sum: f64 = weights.iter().sum();
        if !crate::positive_finite(sum) {
            return Err(EmError::InvalidArgument {
                reason: "window sums to zero".into(),
            });
        }
        let scaled: Vec<f64> = weights.iter().map(|w| 2.0 * w / sum).collect();
        // One kernel per frequency, the frequencies shared out over the
        // cores; each kernel is the same bits wherever it is made.
        let kernel = |f: f64| -> (Vec<f32>, Vec<f32>) {
            let bins = bins_of(f);
            let grid = on_grid(bins);
            // k n mod N, stepped (k < N) rather than divided for every n.
            let k = bins.round() as usize % len;
            let mut phase = 0usize;
            scaled
                .iter()
                .enumerate()
                .map(|(n, s)| {
                    let (sin, cos) = if grid {
                        let sc = unit[phase];
                        phase += k;
                        if phase >= len {
                            phase -= len;
                        }
                        sc
                    } else {
                        (TAU * (f * n as f64 / fs).fract()).sin_cos()
                    };
                    ((s * cos) as f32, (s * sin) as f32)
                })
                .unzip()
        };
        let freqs = &config.frequencies_hz;
        let threads = aeromag_core::parallel::threads();
        let (kernels_re, kernels_im): (Vec<Vec<f32>>, Vec<Vec<f32>>) =
            aeromag_core::parallel::parallel_map(freqs.len(), threads, |i| kernel(freqs[i]))
                .into_iter()
                .unzip();
        #[cfg(target_arch = "x86_64")]
        let avx2 = std::arch::is_x86_feature_detected!("avx2");
        #[cfg(not(target_arch = "x86_64"))]
        let avx2 = false;
        let lowest = config
            .frequencies_hz
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        let spike_sub_len = impulse::sub_block_len(len, fs, lowest);
        Ok(Self {
            config,
            weights,
            kernels_re,
            kernels_im,
            avx2,
            spike_sub_len,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &DetectorConfig {
        &self.config
    }

    /// `A(Δf) = Σ f[n] e^{i2πΔf n/f_s} / Σ f[n]` (dimensionless), `Δf` in Hz.
    fn window_transform(&self, delta_hz: f64) -> Complex64 {
        let fs = self.config.sample_rate_hz;
        let mut acc = Complex64::new(0.0, 0.0);
        let mut sum = 0.0;
        for (n, &w) in self.weights.iter().enumerate() {
            let ph = TAU * (delta_hz * n as f64 / fs).fract();
            acc += Complex64::new(w * ph.cos(), w * ph.sin());
            sum += w;
        }
        acc / sum
    }

    /// Worst-case output amplitude of detector `k` for a unit-amplitude
    /// sinusoid of frequency `f_hz` (any phase):
    /// `|A(f_k − f)| + |A(f_k + f)|` (dimensionless; ≈ 1 at `f = f_k`).
    ///
    /// Errors if `k` is out of range.
    pub fn frequency_response(&self, k: usize, f_hz: f64) -> Result<f64> {
        let fk = *self
            .config
            .frequencies_hz
            .get(k)
            .ok_or_else(|| EmError::InvalidArgument {
                reason: format!("detector index {k}"),
            })?;
        Ok(self.window_transform(fk - f_hz).norm() + self.window_transform(fk + f_hz).norm())
    }

    /// Cross-talk matrix `C[k][j]` = response of detector `k` to a unit
    /// sinusoid at detector `j`'s frequency (diagonal ≈ 1); the frequency plan
    /// is clean when every off-diagonal entry is below the noise.
    pub fn cross_talk(&self) -> Vec<Vec<f64>> {
        let f = &self.config.frequencies_hz;
        (0..f.len())
            .map(|k| {
                f.iter()
                    .map(|&fj| self.frequency_response(k, fj).unwrap_or(f64::NAN))
                    .collect()
            })
            .collect()
    }

    /// The response of detector `k` on `points` frequencies evenly spaced
    /// over `[f_lo_hz, f_hi_hz]`: pairs `(f Hz, response)` for plotting (the
    /// seed's fig. 1).
    ///
    /// Errors for a bad index, fewer than 2 points or an empty interval.
    pub fn response_curve(
        &self,
        k: usize,
        f_lo_hz: f64,
        f_hi_hz: f64,
        points: usize,
    ) -> Result<Vec<(f64, f64)>> {
        if points < 2 || f_hi_hz.partial_cmp(&f_lo_hz) != Some(std::cmp::Ordering::Greater) {
            return Err(EmError::InvalidArgument {
                reason: "need ≥ 2 points over a non-empty interval".into(),
            });
        }
        (0..points)
            .map(|j| {
                let f = f_lo_hz + (f_hi_hz - f_lo_hz) * j as f64 / (points - 1) as f64;
                self.frequency_response(k, f).map(|g| (f, g))
            })
            .collect()
    }

    /// Detect one block of one channel (`samples.len() == N`) whose first
    /// sample has absolute index `start_index`; one value per frequency.
    ///
    /// The samples are taken as they are: impulsive spikes are repaired by
    /// [`Self::detect_interleaved`], which owns a copy of each block.
    ///
    /// Errors if the block length differs from the window length.
    pub fn detect_block(&self, samples: &[f32], start_index: u64) -> Result<Vec<Complex64>> {
        if samples.len() != self.config.window_len {
            return Err(EmError::InvalidArgument {
                reason: format!(
                    "block of {} samples, window is {}",
                    samples.len(),
                    self.config.window_len
                ),
            });
        }
        let fs = self.config.sample_rate_hz;
        Ok(self
            .config
            .frequencies_hz
            .iter()
            .zip(self.kernels_re.iter().zip(&self.kernels_im))
            .map(|(&f, (re, im))| {
                let (sr, si) = dot2(samples, re, im, self.avx2);
                Complex64::new(sr, si) * block_phase(f, fs, start_index)
            })
            .collect())
    }

    /// Detect every complete block of channel-interleaved samples
    /// (`data[i * channels + c]`), the first sample having absolute index
    /// `start_index`. A trailing partial block is ignored. Impulsive
    /// samples of each channel are repaired first and reported in the
    /// epoch ([`impulse`]).
    ///
    /// The blocks are independent: they are shared out over the available
    /// cores in contiguous runs, and the epochs come back in order, each
    /// the same bits whatever the thread count.
    ///
    /// Errors for `channels == 0`.
    pub fn detect_interleaved(
        &self,
        data: &[f32],
        channels: usize,
        start_index: u64,
    ) -> Result<Vec<Epoch>> {
        if channels == 0 {
            return Err(EmError::InvalidArgument {
                reason: "zero channels".into(),
            });
        }
        let block = self.config.window_len * channels;
        let blocks = data.len() / block;
        let threads = aeromag_core::parallel::threads().min(blocks);
        if threads <= 1 {
            return self.detect_run(data, channels, start_index);
        }
        let per = blocks.div_ceil(threads);
        let runs = aeromag_core::parallel::parallel_map(blocks.div_ceil(per), threads, |t| {
            let part = &data[t * per * block..((t + 1) * per).min(blocks) * block];
            let first = start_index + (t * per * self.config.window_len) as u64;
            self.detect_run(part, channels, first)
        });
        let mut out = Vec::with_capacity(blocks);
        for run in runs {
            out.extend(run?);
        }
        Ok(out)
    }

    /// [`Self::detect_interleaved`] on one thread.
    fn detect_run(&self, data: &[f32], channels: usize, start_index: u64) -> Result<Vec<Epoch>> {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is true only if the CPU reported AVX2 (see `SyncDetector::new`).
            return unsafe { self.detect_run_avx2(data, channels, start_index) };
        }
        self.detect_run_body(data, channels, start_index)
    }

    /// [`Self::detect_run_body`] compiled for AVX2: the three-channel
    /// deinterleave in 8-wide shuffles (a tenth of a detection's time in
    /// single loads and inserts before). The arithmetic is the same,
    /// without fused multiply–adds, so the epochs are the same bits.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn detect_run_avx2(
        &self,
        data: &[f32],
        channels: usize,
        start_index: u64,
    ) -> Result<Vec<Epoch>> {
        self.detect_run_body(data, channels, start_index)
    }

    /// [`Self::detect_run`] for any target.
    #[inline(always)]
    fn detect_run_body(
        &self,
        data: &[f32],
        channels: usize,
        start_index: u64,
    ) -> Result<Vec<Epoch>> {
        let n = self.config.window_len;
        let nf = self.config.frequencies_hz.len();
        let fs = self.config.sample_rate_hz;
        let mut buf = vec![vec![0.0f32; n]; channels];
        let mut sums = vec![(0.0f64, 0.0f64); nf * channels];
        let mut out = Vec::with_capacity(data.len() / (n * channels));
        for (b, block) in data.chunks_exact(n * channels).enumerate() {
            if let [b0, b1, b2] = &mut buf[..] {
                // Three channels, the usual record: without the general
                // loop's index checks and per-channel lookups (a quarter
                // of a detection's time went there).
                for (((f, x0), x1), x2) in block.chunks_exact(3).zip(b0).zip(b1).zip(b2) {
                    (*x0, *x1, *x2) = (f[0], f[1], f[2]);
                }
            } else {
                for (i, frame) in block.chunks_exact(channels).enumerate() {
                    for (c, &v) in frame.iter().enumerate() {
                        buf[c][i] = v;
                    }
                }
            }
            let first = start_index + (b * n) as u64;
            let mut spikes = Vec::new();
            for (c, ch) in buf.iter_mut().enumerate() {
                impulse::repair(ch, self.spike_sub_len, first, c, &mut spikes);
            }
            sums.iter_mut().for_each(|s| *s = (0.0, 0.0));
            // Tile over samples so that one tile of every kernel and channel
            // stays in L1 while all frequency × channel products are formed.
            for off in (0..n).step_by(FLUSH) {
                let end = (off + FLUSH).min(n);
                for k in 0..nf {
                    let re = &self.kernels_re[k][off..end];
                    let im = &self.kernels_im[k][off..end];
                    if channels == 3 {
                        let u = [&buf[0][off..end], &buf[1][off..end], &buf[2][off..end]];
                        for (c, (sr, si)) in dot2x3(u, re, im, self.avx2).into_iter().enumerate() {
                            let acc = &mut sums[k * 3 + c];
                            acc.0 += sr;
                            acc.1 += si;
                        }
                    } else {
                        for (c, ch) in buf.iter().enumerate() {
                            let (sr, si) = dot2(&ch[off..end], re, im, self.avx2);
                            let acc = &mut sums[k * channels + c];
                            acc.0 += sr;
                            acc.1 += si;
                        }
                    }
                }
            }
            let mut values = Vec::with_capacity(nf * channels);
            for (k, &f) in self.config.frequencies_hz.iter().enumerate() {
                let rot = block_phase(f, fs, first);
                values.extend(
                    sums[k * channels..(k + 1) * channels]
                        .iter()
                        .map(|&(sr, si)| Complex64::new(sr, si) * rot),
                );
            }
            let centre = block_centre_time_s(first, n, fs);
            out.push(Epoch {
                start_index: first,
                centre_time_s: centre,
                values,
                spikes,
            });
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Default plan: 100 kHz, N = 16 000 (6.25 Hz bins), working 1025/2075/3125 Hz,
    /// pilots ±25 Hz (4 bins).
    fn plan() -> DetectorConfig {
        DetectorConfig::three_frequency_plan(100_000.0, 16_000, [1025.0, 2075.0, 3125.0], 25.0)
    }

    fn tone(fs: f64, n: usize, start: u64, f: f64, a: f64, b: f64) -> Vec<f32> {
        (0..n)
            .map(|i| {
                let t = (start + i as u64) as f64 / fs;
                (a * (TAU * f * t).cos() + b * (TAU * f * t).sin()) as f32
            })
            .collect()
    }

    #[test]
    fn recovers_amplitude_and_phase_at_any_block() {
        let d = SyncDetector::new(plan()).unwrap();
        for start in [0u64, 16_000, 123_457] {
            let u = tone(1e5, 16_000, start, 2075.0, 0.7, -0.3);
            let v = d.detect_block(&u, start).unwrap();
            assert!(
                (v[3] - Complex64::new(0.7, -0.3)).norm() < 1e-6,
                "{start}: {}",
                v[3]
            );
        }
    }

    #[test]
    fn cross_talk_of_plan_frequencies_and_power_harmonics_is_below_noise() {
        let cfg = plan();
        let d = SyncDetector::new(cfg.clone()).unwrap();
        let ct = d.cross_talk();
        for (k, row) in ct.iter().enumerate() {
            for (j, &v) in row.iter().enumerate() {
                assert!(
                    if j == k {
                        (v - 1.0).abs() < 1e-6
                    } else {
                        v < 1e-10
                    },
                    "C[{k}][{j}] = {v}"
                );
            }
        }
        let mut others: Vec<f64> = cfg.frequencies_hz.clone();
        others.extend((1..=12).map(|h| 400.0 * h as f64));
        for k in 0..cfg.frequencies_hz.len() {
            let own = d.frequency_response(k, cfg.frequencies_hz[k]).unwrap();
            assert!((own - 1.0).abs() < 1e-6, "own response {own}");
            for &f in others.iter().filter(|&&f| f != cfg.frequencies_hz[k]) {
                let g = d.frequency_response(k, f).unwrap();
                // Exact zeros up to rounding (f64 DTFT of 16 000 samples).
                assert!(g < 1e-10, "detector {k} at {f} Hz: {g}");
            }
        }
        // Between bins the Blackman–Harris sidelobes are below −90 dB far away...
        let far = d.frequency_response(0, 1025.0 + 103.1).unwrap();
        assert!(far < 3.2e-5, "{far}");
        // ...and a rectangular window leaks orders of magnitude more there.
        let rect = SyncDetector::new(DetectorConfig {
            window: Window::Rectangular,
            ..cfg
        })
        .unwrap();
        assert!(rect.frequency_response(0, 1025.0 + 103.1).unwrap() > 100.0 * far);
        // The curve has its maximum at the detector frequency and ≥ 4 exact nulls nearby.
        let curve = d.response_curve(0, 975.0, 1075.0, 401).unwrap();
        let peak = curve
            .iter()
            .cloned()
            .fold((0.0, 0.0), |a, b| if b.1 > a.1 { b } else { a });
        assert_eq!(peak.0, 1025.0);
        assert!(curve.iter().filter(|p| p.1 < 1e-10).count() >= 4);
        assert!(d.response_curve(0, 1.0, 1.0, 10).is_err());
    }

    #[test]
    fn measured_cross_talk_matches_response_bound() {
        let d = SyncDetector::new(plan()).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for _ in 0..10 {
            let f = rng.random_range(900.0..1150.0);
            let th: f64 = rng.random_range(0.0..TAU);
            let u = tone(1e5, 16_000, 0, f, th.cos(), th.sin());
            let v = d.detect_block(&u, 0).unwrap()[0].norm();
            let bound = d.frequency_response(0, f).unwrap();
            assert!(v <= bound * (1.0 + 1e-6) + 2e-7, "f {f}: {v} > {bound}");
        }
    }

    #[test]
    fn interleaved_matches_per_channel_and_rejects_bad_input() {
        let d = SyncDetector::new(plan()).unwrap();
        let chans: Vec<Vec<f32>> = (0..3)
            .map(|c| tone(1e5, 32_000, 0, 3125.0, 0.1 * (c + 1) as f64, 0.05))
            .collect();
        let data: Vec<f32> = (0..32_000)
            .flat_map(|i| chans.iter().map(move |ch| ch[i]))
            .collect();
        let ep = d.detect_interleaved(&data, 3, 0).unwrap();
        assert_eq!(ep.len(), 2);
        for c in 0..3 {
            let v = ep[1].values[6 * 3 + c];
            assert!((v - Complex64::new(0.1 * (c + 1) as f64, 0.05)).norm() < 1e-6);
        }
        assert!(d.detect_block(&[0.0; 10], 0).is_err());
        assert!(d.detect_interleaved(&data, 0, 0).is_err());
        assert!(
            SyncDetector::new(DetectorConfig {
                frequencies_hz: vec![60_000.0],
                ..plan()
            })
            .is_err()
        );
        assert!(
            SyncDetector::new(DetectorConfig {
                window_len: 2,
                ..plan()
            })
            .is_err()
        );
    }

    /// Three channels against one kernel give, in the plain build and in
    /// the AVX2 build where the processor has it, the bits of each channel
    /// alone (lengths with partial lanes and partial flush tiles).
    #[test]
    fn dot_products_are_the_same_bits_in_every_build() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        #[cfg(target_arch = "x86_64")]
        let builds = [false, std::arch::is_x86_feature_detected!("avx2")];
        #[cfg(not(target_arch = "x86_64"))]
        let builds = [false];
        for n in [1usize, 31, 32, 33, 1000, 1024, 2049, 16_000] {
            let mut v = || -> Vec<f32> { (0..n).map(|_| rng.random_range(-1.0f32..1.0)).collect() };
            let (u0, u1, u2, re, im) = (v(), v(), v(), v(), v());
            let u = [u0.as_slice(), u1.as_slice(), u2.as_slice()];
            let bits = |x: [(f64, f64); 3]| x.map(|(a, b)| (a.to_bits(), b.to_bits()));
            let alone = bits(std::array::from_fn(|c| dot2_body(u[c], &re, &im)));
            for avx2 in builds {
                assert_eq!(
                    bits(dot2x3(u, &re, &im, avx2)),
                    alone,
                    "avx2 {avx2}, n = {n}"
                );
                let each = std::array::from_fn(|c| dot2(u[c], &re, &im, avx2));
                assert_eq!(bits(each), alone, "avx2 {avx2} alone, n = {n}");
            }
        }
    }

    /// A detection run compiled for AVX2 gives the epochs of the plain
    /// build bit for bit: three channels (the vectorised deinterleave) and
    /// two (the general loop), with spikes to repair, a partial last block
    /// and a block start off zero.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn detection_runs_are_the_same_bits_in_every_build() {
        let d = SyncDetector::new(DetectorConfig {
            window_len: 4000,
            ..plan()
        })
        .unwrap();
        if !d.avx2 {
            return;
        }
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for channels in [3usize, 2] {
            let frames = 3 * 4000 + 123;
            let mut data: Vec<f32> = (0..frames * channels)
                .map(|i| {
                    let t = (i / channels) as f64 / 1e5;
                    ((TAU * 2075.0 * t).sin() + 0.3 * (TAU * 3125.0 * t).cos()) as f32
                        + rng.random_range(-0.01f32..0.01)
                })
                .collect();
            for k in [17usize, 5000, 9001] {
                data[k * channels + channels - 1] = 40.0;
            }
            let plain = d.detect_run_body(&data, channels, 7).unwrap();
            // SAFETY: `d.avx2` says the processor has AVX2.
            let avx2 = unsafe { d.detect_run_avx2(&data, channels, 7) }.unwrap();
            assert_eq!(plain.len(), 3);
            assert_eq!(plain.iter().map(|e| e.spikes.len()).sum::<usize>(), 3);
            let bits = |e: &[Epoch]| -> Vec<(u64, u64)> {
                e.iter()
                    .flat_map(|e| e.values.iter().map(|v| (v.re.to_bits(), v.im.to_bits())))
                    .collect()
            };
            assert_eq!(bits(&avx2), bits(&plain), "{channels} channels");
            assert_eq!(avx2, plain);
        }
    }

    /// Frequency response against SciPy (`tools/reference/em_detector_response.py`).
    #[test]
    fn frequency_response_matches_scipy_reference() {
        let v: serde_json::Value =
            serde_json::from_str(include_str!("../../tests/data/detector_response.json")).unwrap();
        let d = SyncDetector::new(DetectorConfig {
            sample_rate_hz: v["fs_hz"].as_f64().unwrap(),
            window_len: v["n"].as_u64().unwrap() as usize,
            window: Window::BlackmanHarris,
            frequencies_hz: vec![v["fk_hz"].as_f64().unwrap()],
        })
        .unwrap();
        let rows = v["rows"].as_array().unwrap();
        assert!(rows.len() >= 10);
        for row in rows {
            let f = row["f_hz"].as_f64().unwrap();
            let want = row["response"].as_f64().unwrap();
            let got = d.frequency_response(0, f).unwrap();
            assert!(
                (got - want).abs() < 1e-12 + 1e-9 * want,
                "{f} Hz: {got} vs {want}"
            );
        }
    }
}
