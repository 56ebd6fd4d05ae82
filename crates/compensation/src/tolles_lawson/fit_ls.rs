//! Method 1: band-pass least squares (the industry and MagNav.jl baseline).
//!
//! Spec `compensation.md`, "Method 1"; seed `000_…` chapter 1 (the classical
//! approach the thesis improves on).
//!
//! For every contiguous segment (leg) of the calibration flight:
//! 1. build the design matrix `A` from the vector magnetometer
//!    ([`super::design::Design::columns`]);
//! 2. band-pass every non-constant column of `A` and the scalar reading `y`
//!    with a zero-phase Butterworth filter (order 4, 0.1–0.9 Hz by default),
//!    so that the slowly varying external field (main field, geology,
//!    diurnal) is suppressed while the manoeuvre-induced interference stays;
//!    a column is constant when its standard deviation is ≤ ε (MagNav's rule);
//! 3. drop `trim` samples at each end (filter transients);
//! 4. accumulate the normal equations.
//!
//! Then solve the ridge problem `(AᵀA + λI) c = Aᵀy` with equilibration
//! ([`aeromag_estimation::least_squares::NormalEquations`]). Memory is
//! `O(segment length × columns)` for the filtering and `O(columns²)` for the
//! fit, whatever the number of segments.
//!
//! The compensated signal is `mag − A_unfiltered c`.
//!
//! **Uncertainties.** The filtered residuals are correlated: only a fraction
//! `2 (f_hi − f_lo) / f_s` of the samples is independent. Standard
//! deviations use that effective number of rows.
//!
//! **Diagnostics.** Coefficients whose variance inflation factor exceeds
//! [`LsConfig::max_vif`] are reported by name as poorly determined (the
//! flight does not separate them from the other terms: typically one heading
//! or missing manoeuvres), and near-null combinations are spelled out.

use super::design::{Channels, Design, DesignBlock, Magnitude, TotalField};
use super::eddy_lag::FirstOrderLag;
use super::segments::median_step;
use crate::error::{CompError, Result};
use aeromag_core::filter::sos::Sos;
use aeromag_core::filter::{Band, FILTER_LANES, butter, sosfiltfilt_columns_propagating_with};
use aeromag_core::parallel::for_each_weighted_mut;
use aeromag_core::simd::all_finite;
use aeromag_estimation::least_squares::{BlockProducts, LsSolution, NormalEquations};
use serde::{Deserialize, Serialize};

/// Settings of the band-pass least-squares fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LsConfig {
    /// Terms (default `p3,i5,e8`: the 16 observable parameters), derivative
    /// convention and scale of the induced and eddy columns (default
    /// 50 000 nT).
    #[serde(flatten)]
    pub design: Design,
    /// Pass band in Hz (default 0.1–0.9 Hz); `None` fits unfiltered data.
    pub band_hz: Option<(f64, f64)>,
    /// Butterworth order (default 4).
    pub filter_order: usize,
    /// Samples dropped at each end of each filtered segment (default 20).
    pub trim: usize,
    /// Ridge parameter λ ≥ 0 (default 0), in the units of `AᵀA`.
    pub lambda: f64,
    /// Variance inflation factor above which a term is reported as poorly
    /// determined (default 1e4: its standard deviation is inflated 100×).
    pub max_vif: f64,
    /// Longest stretch filtered at once, samples (default 2¹⁵); longer
    /// segments are filtered in overlapping blocks with bounded memory and
    /// the same result (see `for_each_filtered_block`). The default keeps
    /// a block's columns (about 25 series of 8 bytes a row: 6 MB) near the
    /// cores' caches and its buffers reused from block to block; 2¹⁷ made
    /// the fit of a 10⁷-row flight 10–20 % slower, 2¹³ spent too much on the
    /// overlaps.
    pub block_len: usize,
}

impl Default for LsConfig {
    fn default() -> Self {
        Self {
            design: Design::default(),
            band_hz: Some((0.1, 0.9)),
            filter_order: 4,
            trim: 20,
            lambda: 0.0,
            max_vif: 1e4,
            block_len: 1 << 15,
        }
    }
}

/// One contiguous segment of calibration data (equal-length slices).
#[derive(Debug, Clone, Copy)]
pub struct Segment<'a> {
    /// Time, s, strictly increasing.
    pub time: &'a [f64],
    /// Vector magnetometer, body frame, nT.
    pub flux: [&'a [f64]; 3],
    /// Scalar magnetometer, nT.
    pub mag: &'a [f64],
    /// The channels of the design's extra regressors
    /// ([`super::TermSet::extras`]), [`Channels::NONE`] without them.
    pub channels: Channels<'a>,
    /// The vector whose direction cosines the columns use (x, y, z), when
    /// not `flux`: the total field of a Gauss–Newton step of the
    /// exact-magnitude model ([`super::design::Magnitude`]). `None` for
    /// data.
    pub direction: Option<[&'a [f64]; 3]>,
}

impl<'a> Segment<'a> {
    /// How the messages name the `k`-th segment (from 0) of a fit: counted
    /// from 1, with its time span, which finds it in the file (a single
    /// segment was "segment 0"): `segment 3 (time 49820–50117.5 s)`.
    pub fn name(&self, k: usize) -> String {
        let shown = aeromag_core::error::shown;
        match (self.time.first(), self.time.last()) {
            (Some(&t0), Some(&t1)) => {
                format!("segment {} (time {}–{} s)", k + 1, shown(t0), shown(t1))
            }
            _ => format!("segment {} (empty)", k + 1),
        }
    }

    /// A segment without extra regressor channels.
    pub fn new(time: &'a [f64], flux: [&'a [f64]; 3], mag: &'a [f64]) -> Self {
        Self {
            time,
            flux,
            mag,
            channels: Channels::NONE,
            direction: None,
        }
    }

    /// The rows `r` of this segment (panics if `r` is out of its range,
    /// like slicing).
    pub fn slice(&self, r: std::ops::Range<usize>) -> Segment<'a> {
        Segment {
            time: &self.time[r.clone()],
            flux: [
                &self.flux[0][r.clone()],
                &self.flux[1][r.clone()],
                &self.flux[2][r.clone()],
            ],
            mag: &self.mag[r.clone()],
            channels: self.channels.slice(r.clone()),
            direction: self
                .direction
                .map(|d| [&d[0][r.clone()], &d[1][r.clone()], &d[2][r]]),
        }
    }
}

/// Result of a fit.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct LsFit {
    /// Column names.
    pub names: Vec<String>,
    /// Coefficients.
    pub coef: Vec<f64>,
    /// Standard deviations of the coefficients.
    pub std: Vec<f64>,
    /// Variance inflation factor of each coefficient.
    pub vif: Vec<f64>,
    /// Scaled condition number of the normal equations.
    pub condition: f64,
    /// RMS of the filtered fit residual, nT.
    pub residual_rms_nt: f64,
    /// Rows used (after trimming).
    pub rows: usize,
    /// Effective degrees of freedom of the residual: the rows times the
    /// fraction of independent samples of the band-passed signal,
    /// `min(1, 2 (f_hi − f_lo)/f_s)`.
    pub effective_dof: f64,
    /// Segments used.
    pub segments_used: usize,
    /// Warnings for the user (ill-conditioning, poorly determined terms,
    /// segments too short to filter).
    pub warnings: Vec<String>,
    /// Notes for the user: how the fit went where nothing is wrong (the
    /// exact magnitude's Gauss–Newton steps).
    pub notes: Vec<String>,
}

/// Relative accuracy to which block-wise filtering reproduces whole-segment
/// filtering (the overlap is the filter's settling length for this decay).
const BLOCK_TOLERANCE: f64 = 1e-15;

/// Design the segment's columns, zero-phase filter every non-constant column
/// and `y`, drop `trim` samples at each end, and hand the result to `sink`
/// in blocks of at most `cfg.block_len` rows (`dt_s`: the segment's median
/// sampling interval, s).
///
/// A segment longer than `block_len` is processed in overlapping blocks:
/// each block is extended on both sides by the filter's settling length `P`
/// (impulse response below [`BLOCK_TOLERANCE`]), filtered on its own, and only
/// its core is kept. Inside the core the result equals whole-segment
/// filtering to that tolerance (the transients of the block's artificial
/// ends have decayed), so memory is `O(block_len × columns)` whatever the
/// segment's length.
///
/// The blocks are independent, so they are designed, filtered and passed
/// through `map` on `threads` threads, one block per thread (a single
/// block spreads its columns over the threads instead); `reduce` receives
/// the mapped blocks in order on the calling thread. Each block is the same
/// bits whatever the thread count. A column with a non-finite value is
/// non-finite throughout after the filter ([`filter_columns`]): `map` must
/// not let that pass unseen ([`BlockProducts::of`] is an error for it).
fn for_each_filtered_block<T: Send>(
    seg: &Segment,
    dt_s: f64,
    cfg: &LsConfig,
    sos: Option<&Sos>,
    threads: usize,
    map: impl Fn(&[&[f64]], &[f64]) -> Result<T> + Sync,
    mut reduce: impl FnMut(T) -> Result<()>,
) -> Result<()> {
    let plan = block_plan(seg.time.len(), dt_s, cfg, sos)?;
    let threads = threads.max(1);
    if plan.len() == 1 || threads == 1 {
        let mut work = BlockWork::default();
        for blk in &plan {
            work.compute(seg, cfg, sos, blk, threads)?;
            reduce(work.map(blk, &map)?)?;
        }
        return Ok(());
    }
    let mut works: Vec<BlockWork> = (0..threads).map(|_| BlockWork::default()).collect();
    for chunk in plan.chunks(threads) {
        // One block per thread, each with its work buffers, kept for the
        // next chunk.
        let mut jobs: Vec<(&mut BlockWork, &BlockPlan, Option<Result<T>>)> = works
            .iter_mut()
            .zip(chunk)
            .map(|(w, blk)| (w, blk, None))
            .collect();
        for_each_weighted_mut(
            &mut jobs,
            threads,
            |_| 1,
            |(w, blk, out)| {
                *out = Some(
                    w.compute(seg, cfg, sos, blk, 1)
                        .and_then(|()| w.map(blk, &map)),
                );
            },
        );
        for (_, _, m) in jobs {
            reduce(m.expect("every block is mapped")?)?;
        }
    }
    Ok(())
}

/// One block of [`for_each_filtered_block`]: rows `a..b` of the segment are
/// designed and filtered, rows `core` (within `a..b`) are kept.
struct BlockPlan {
    a: usize,
    b: usize,
    core: std::ops::Range<usize>,
}

/// The blocks of a segment of `n` rows (see [`for_each_filtered_block`]).
fn block_plan(n: usize, dt_s: f64, cfg: &LsConfig, sos: Option<&Sos>) -> Result<Vec<BlockPlan>> {
    let (keep_lo, keep_hi) = if sos.is_some() {
        (cfg.trim, n - cfg.trim)
    } else {
        (0, n)
    };
    let filter_overlap = match sos {
        Some(s) => s
            .settling_samples(BLOCK_TOLERANCE)
            .ok_or_else(|| CompError::Failed {
                reason: "unstable band-pass filter".into(),
            })?,
        None => 1, // the central-difference derivative needs one neighbour
    };
    // The lagged eddy columns start at rest at each block's first sample:
    // their start-up transient must also have decayed inside the core.
    let terms = &cfg.design.terms;
    let lag_overlap = terms
        .eddy_lags_s()
        .iter()
        .copied()
        .chain(terms.extra_lags_s())
        .map(|tau| FirstOrderLag::settling_samples(tau, dt_s, BLOCK_TOLERANCE))
        .max()
        .unwrap_or(0);
    let overlap = filter_overlap + lag_overlap;
    let block = cfg.block_len.max(1);
    let mut plan = Vec::new();
    let mut start = keep_lo;
    while start < keep_hi {
        let end = (start + block).min(keep_hi);
        let (a, b) = if keep_lo == 0 && keep_hi == n && block >= n {
            (0, n)
        } else {
            (start.saturating_sub(overlap), (end + overlap).min(n))
        };
        plan.push(BlockPlan {
            a,
            b,
            core: start..end,
        });
        start = end;
    }
    Ok(plan)
}

/// The buffers of one block, kept for the next.
#[derive(Default)]
struct BlockWork {
    design: DesignBlock,
    y: Vec<f64>,
    scratch: Vec<Vec<[f64; FILTER_LANES]>>,
}

impl BlockWork {
    /// Design and filter the rows of `blk` (the columns over `threads`).
    fn compute(
        &mut self,
        seg: &Segment,
        cfg: &LsConfig,
        sos: Option<&Sos>,
        blk: &BlockPlan,
        threads: usize,
    ) -> Result<()> {
        let (a, b) = (blk.a, blk.b);
        let time = &seg.time[a..b];
        let flux = [&seg.flux[0][a..b], &seg.flux[1][a..b], &seg.flux[2][a..b]];
        let channels = seg.channels.slice(a..b);
        let dir = seg
            .direction
            .map(|d| [&d[0][a..b], &d[1][a..b], &d[2][a..b]]);
        cfg.design
            .columns_along_into(time, flux, channels, dir, &mut self.design);
        self.y.clear();
        self.y.extend_from_slice(&seg.mag[a..b]);
        if let Some(sos) = sos {
            filter_columns(
                sos,
                &mut self.design.columns,
                &mut self.y,
                &mut self.scratch,
                threads,
            )?;
        }
        Ok(())
    }

    /// `map` of the kept rows of the block.
    fn map<T>(&self, blk: &BlockPlan, map: &impl Fn(&[&[f64]], &[f64]) -> Result<T>) -> Result<T> {
        let (ca, cb) = (blk.core.start - blk.a, blk.core.end - blk.a);
        let refs: Vec<&[f64]> = self.design.columns.iter().map(|c| &c[ca..cb]).collect();
        map(&refs, &self.y[ca..cb])
    }
}

/// Segment `k`'s sampling interval (s) and band-pass filter, or the warning
/// that says why it is skipped (no valid time step, too short to filter and
/// trim); columns of unequal length are an error.
fn segment_filter(
    k: usize,
    seg: &Segment,
    cfg: &LsConfig,
) -> Result<std::result::Result<(f64, Option<Sos>), String>> {
    let n = seg.time.len();
    if seg.mag.len() != n || seg.flux.iter().any(|f| f.len() != n) {
        return Err(CompError::data(format!(
            "segment {k}: columns of unequal length"
        )));
    }
    for (j, x) in cfg.design.terms.extras().iter().enumerate() {
        if seg.channels.get(j).is_none_or(|c| c.len() != n) {
            return Err(CompError::data(format!(
                "segment {k}: no channel `{}` of its length for the extra regressor",
                x.channel
            )));
        }
    }
    let dt = median_step(seg.time);
    if dt.is_nan() || dt <= 0.0 {
        return Ok(Err(format!(
            "{} ({n} samples) has no valid time step; skipped",
            seg.name(k)
        )));
    }
    // The band's high edge at or above the flight's Nyquist frequency:
    // the filter design said "invalid argument `high_hz`".
    // (`0.5 / 0.1` is 5.000000000000001: an edge at Nyquist within
    // round-off is at it.)
    if let Some((lo, hi)) = cfg.band_hz
        && hi * dt >= 0.5 * (1.0 - 1e-9)
    {
        let shown = aeromag_core::error::shown;
        return Err(CompError::setting(format!(
            "pass band {}–{} Hz needs a sampling rate above {} Hz, and {} is sampled at {} \
             Hz (median step {} s): lower the band's high edge (--band; the default is 0.1–0.9 Hz), \
             or is the time not in seconds?",
            shown(lo),
            shown(hi),
            shown(2.0 * hi),
            seg.name(k),
            shown((1e3 / dt).round() / 1e3),
            aeromag_core::error::figure(dt)
        )));
    }
    let sos = match cfg.band_hz {
        Some((lo, hi)) => Some(butter(
            cfg.filter_order,
            Band::Bandpass {
                low_hz: lo,
                high_hz: hi,
            },
            1.0 / dt,
        )?),
        None => None,
    };
    if let (Some(s), Some((lo, hi))) = (&sos, cfg.band_hz)
        && s.settling_samples(BLOCK_TOLERANCE)
            .is_none_or(|k| k > MAX_SETTLING_SAMPLES)
    {
        let shown = aeromag_core::error::shown;
        return Err(CompError::setting(format!(
            "pass band {}–{} Hz at {} Hz sampling: the filter's response does not die out within \
             {MAX_SETTLING_SAMPLES} samples (its poles lie too near the unit circle); widen the band \
             or raise its low edge (the default is 0.1–0.9 Hz)",
            shown(lo),
            shown(hi),
            shown((1e3 / dt).round() / 1e3)
        )));
    }
    let ncol = cfg.design.n_columns();
    let min_len = sos
        .as_ref()
        .map_or(ncol, |s| s.padlen() + 1 + 2 * cfg.trim + ncol);
    if n < min_len {
        return Ok(Err(format!(
            "{} has {n} samples, fewer than the {min_len} needed to filter and trim it; skipped",
            seg.name(k)
        )));
    }
    Ok(Ok((dt, sos)))
}

/// Skipped segments named one by one in a fit's warnings; more are
/// counted in one more warning.
pub const LISTED_SKIPS: usize = 3;

/// Which of `segments` a fit under `cfg` uses (the others are too short to
/// filter and trim with its number of columns, or have no time step).
pub(crate) fn usable_segments(segments: &[Segment], cfg: &LsConfig) -> Result<Vec<bool>> {
    validate(cfg)?;
    segments
        .iter()
        .enumerate()
        .map(|(k, seg)| Ok(segment_filter(k, seg, cfg)?.is_ok()))
        .collect()
}

/// The band-passed residual `y − A c` of every segment that
/// [`fit_band_pass_ls`] uses (trimmed like the fit), with its sampling
/// rate (Hz); segments that are skipped are left out.
pub(crate) fn band_passed_residuals(
    segments: &[Segment],
    cfg: &LsConfig,
    coef: &[f64],
) -> Result<Vec<(Vec<f64>, f64)>> {
    validate(cfg)?;
    let ncol = cfg.design.n_columns();
    if coef.len() != ncol {
        return Err(CompError::data(format!(
            "{} coefficients for {ncol} columns",
            coef.len()
        )));
    }
    // One segment's residual (`None`: skipped), its blocks or columns on
    // `threads` threads.
    let residual = |k: usize, threads: usize| -> Result<Option<(Vec<f64>, f64)>> {
        let seg = &segments[k];
        let Ok((dt, sos)) = segment_filter(k, seg, cfg)? else {
            return Ok(None);
        };
        let mut r = Vec::with_capacity(seg.time.len());
        for_each_filtered_block(
            seg,
            dt,
            cfg,
            sos.as_ref(),
            threads,
            |cols, y| {
                let r: Vec<f64> = (0..y.len())
                    .map(|i| y[i] - cols.iter().zip(coef).map(|(c, b)| c[i] * b).sum::<f64>())
                    .collect();
                // A non-finite input spoils its filtered column throughout.
                if all_finite(&r) {
                    Ok(r)
                } else {
                    Err(CompError::data(format!(
                        "{}: a non-finite value in the band-passed residual",
                        seg.name(k)
                    )))
                }
            },
            |block| {
                r.extend(block);
                Ok(())
            },
        )?;
        Ok(Some((r, 1.0 / dt)))
    };
    let mut out = Vec::new();
    for_each_segment_on_cores(segments, residual, |_, r| {
        out.extend(r?);
        Ok(())
    })?;
    Ok(out)
}

/// Rows per thread in one round of [`for_each_segment_on_cores`].
const ROUND_ROWS_PER_THREAD: usize = 1 << 16;

/// `take(k, f(k, threads))` for every segment `k` of `segments` in order,
/// `f` run on the cores: many segments (lines, or the lag search's sampled
/// blocks) several at once, one per core (`threads` 1), in rounds of about
/// [`ROUND_ROWS_PER_THREAD`] rows per thread (the results of a round held
/// until taken; a spawn per round, not per leg); few one at a time, its
/// blocks or columns on the cores. Each segment's result is the same bits
/// either way.
fn for_each_segment_on_cores<T: Send>(
    segments: &[Segment],
    f: impl Fn(usize, usize) -> T + Sync,
    mut take: impl FnMut(usize, T) -> Result<()>,
) -> Result<()> {
    let n = segments.len();
    let threads = aeromag_core::parallel::threads();
    if !(threads > 1 && n >= 2 * threads) {
        for k in 0..n {
            take(k, f(k, threads))?;
        }
        return Ok(());
    }
    let mut first = 0;
    while first < n {
        let (mut end, mut rows) = (first, 0);
        while end < n && (end - first < 2 * threads || rows < threads * ROUND_ROWS_PER_THREAD) {
            rows += segments[end].time.len();
            end += 1;
        }
        let done = aeromag_core::parallel::parallel_map(end - first, threads, |i| f(first + i, 1));
        for (k, d) in (first..end).zip(done) {
            take(k, d)?;
        }
        first = end;
    }
    Ok(())
}

/// Fit the Tolles-Lawson coefficients to calibration segments, under the
/// design's [`Magnitude`]: the first-order model in one solve, the exact
/// magnitude by Gauss–Newton from the first-order solution
/// ([`fit_exact_magnitude`]).
pub fn fit_band_pass_ls(segments: &[Segment], cfg: &LsConfig) -> Result<LsFit> {
    match cfg.design.magnitude {
        Magnitude::FirstOrder => fit_first_order(segments, cfg),
        Magnitude::Exact => fit_exact_magnitude(segments, cfg),
    }
}

/// Most Gauss–Newton steps of [`fit_exact_magnitude`].
pub const MAX_GAUSS_NEWTON_STEPS: usize = 8;

/// The exact-magnitude model `y = |B + ΔB(c)| − |B| (+ bias)` fitted by
/// Gauss–Newton on the band-passed data ([`Magnitude`]).
///
/// Linearised at `c_k`, `|B + ΔB(c)| − |B| ≈ R_k + ê_kᵀ ΔB(c)` with
/// `ê_k = (B + ΔB(c_k))/|B + ΔB(c_k)|`, the direction of the total field,
/// and `R_k = |B + ΔB(c_k)| − |B| − ê_kᵀ ΔB(c_k)` (the second-order
/// remainder, ≈ `|ΔB⊥|²/2|B|`). Each step is therefore the band-pass
/// least-squares fit of `y − R_k` on the design columns built with the
/// direction cosines `ê_k` (the same terms, the same filter and trim), whose
/// solution is `c_{k+1}`. It starts from the first-order fit (`ê_0 = B/|B|`,
/// `R_0 = 0`) and stops when the band-passed residual RMS changes by less
/// than 1e-6 relative, after at most [`MAX_GAUSS_NEWTON_STEPS`] steps (a
/// warning says so if it has not converged). Memory: the total field and
/// the corrected reading of every row (4 series).
pub fn fit_exact_magnitude(segments: &[Segment], cfg: &LsConfig) -> Result<LsFit> {
    let linear = LsConfig {
        design: Design {
            magnitude: Magnitude::FirstOrder,
            ..cfg.design.clone()
        },
        ..cfg.clone()
    };
    let mut fit = fit_first_order(segments, &linear)?;
    let mut steps = 0;
    let mut converged = false;
    while steps < MAX_GAUSS_NEWTON_STEPS {
        // The total field and the corrected reading of every segment.
        let lin: Vec<([Vec<f64>; 3], Vec<f64>)> = segments
            .iter()
            .map(|s| linearised(&linear.design, &fit.coef, s))
            .collect();
        let step: Vec<Segment> = segments
            .iter()
            .zip(&lin)
            .map(|(s, (t, y))| Segment {
                mag: y,
                direction: Some([&t[0], &t[1], &t[2]]),
                ..*s
            })
            .collect();
        let next = fit_first_order(&step, &linear)?;
        steps += 1;
        let change = (next.residual_rms_nt - fit.residual_rms_nt).abs()
            / fit.residual_rms_nt.max(f64::MIN_POSITIVE);
        fit = next;
        if change < 1e-6 {
            converged = true;
            break;
        }
    }
    if converged {
        fit.notes.push(format!(
            "exact magnitude: Gauss–Newton converged in {steps} steps"
        ));
    } else {
        fit.warnings.push(format!(
            "exact magnitude: Gauss–Newton did not converge in {steps} steps"
        ));
    }
    Ok(fit)
}

/// One Gauss–Newton linearisation of the exact-magnitude model at the
/// coefficients `coef` ([`fit_exact_magnitude`]): the total field
/// `B + ΔB(c)` of every row of `s` (x, y, z, nT) and the reading corrected
/// by the second-order remainder, `mag − R`.
pub fn linearised(design: &Design, coef: &[f64], s: &Segment) -> ([Vec<f64>; 3], Vec<f64>) {
    let (d, _) = design.field_vector(coef, s.time, s.flux, s.channels);
    let n = s.time.len();
    let mut total = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
    let mut y = Vec::with_capacity(n);
    for k in 0..n {
        let f = TotalField::at(s.flux, &d, k);
        y.push(s.mag[k] - f.remainder());
        for (axis, v) in total.iter_mut().zip(f.t) {
            axis[k] = v;
        }
    }
    (total, y)
}

/// The band-passed normal equations of the first-order model over the
/// segments, before they are solved.
pub(crate) struct Accumulated {
    /// The normal equations of every column of the design.
    pub ne: NormalEquations,
    /// Segments used.
    pub used: usize,
    /// [`LsFit::effective_dof`].
    pub effective_dof: f64,
    /// Segments skipped, and why.
    pub warnings: Vec<String>,
}

/// Band-pass every column of `cfg`'s first-order design and `mag` on each
/// segment and accumulate the normal equations.
pub(crate) fn accumulate(segments: &[Segment], cfg: &LsConfig) -> Result<Accumulated> {
    validate(cfg)?;
    let mut ne = NormalEquations::new(cfg.design.n_columns());
    let mut warnings = Vec::new();
    let mut used = 0;
    let mut fs_used = Vec::new();
    // One segment's block products (`Ok(Err(w))`: skipped, why), its blocks
    // or columns on `threads` threads.
    let products = |k: usize,
                    threads: usize|
     -> Result<std::result::Result<(f64, Vec<BlockProducts>), String>> {
        let seg = &segments[k];
        let (dt, sos) = match segment_filter(k, seg, cfg)? {
            Ok(f) => f,
            Err(w) => return Ok(Err(w)),
        };
        let context = || seg.name(k);
        let mut blocks = Vec::new();
        for_each_filtered_block(
            seg,
            dt,
            cfg,
            sos.as_ref(),
            threads,
            |cols, y| BlockProducts::of(cols, y).map_err(CompError::estimation(context())),
            |p| {
                blocks.push(p);
                Ok(())
            },
        )?;
        Ok(Ok((dt, blocks)))
    };
    // The segments' products added in segment order.
    let mut skipped_samples = 0;
    for_each_segment_on_cores(segments, products, |k, d| {
        match d? {
            Err(w) => {
                skipped_samples += segments[k].time.len();
                warnings.push(w);
            }
            Ok((dt, blocks)) => {
                for p in &blocks {
                    ne.add_products(p)
                        .map_err(CompError::estimation(segments[k].name(k)))?;
                }
                used += 1;
                fs_used.push(1.0 / dt);
            }
        }
        Ok(())
    })?;
    if used == 0 {
        // The reasons would otherwise be lost with the warnings.
        let why = match warnings.as_slice() {
            [] => String::new(),
            [w] => format!(": {w}"),
            [w, rest @ ..] => format!(": {w} (and {} more)", rest.len()),
        };
        return Err(CompError::data(format!(
            "no segment is long enough to fit{why}"
        )));
    }
    // A flight whose second part is at another rate gave a warning per
    // one-sample segment (1 610 lines) and no total.
    if warnings.len() > LISTED_SKIPS {
        let all: usize = segments.iter().map(|s| s.time.len()).sum();
        let n = warnings.len();
        warnings.truncate(LISTED_SKIPS);
        warnings.push(format!(
            "{n} segments skipped in all ({skipped_samples} of {all} samples), the first {LISTED_SKIPS} above"
        ));
    }
    let independent_fraction = match cfg.band_hz {
        Some((lo, hi)) => {
            let fs = fs_used.iter().sum::<f64>() / fs_used.len() as f64;
            (2.0 * (hi - lo) / fs).min(1.0)
        }
        None => 1.0,
    };
    let effective_dof = ne.rows() as f64 * independent_fraction;
    Ok(Accumulated {
        ne,
        used,
        effective_dof,
        warnings,
    })
}

/// The first-order (linear) band-pass least-squares fit.
fn fit_first_order(segments: &[Segment], cfg: &LsConfig) -> Result<LsFit> {
    let acc = accumulate(segments, cfg)?;
    solve_accumulated(&acc.ne, &acc, cfg)
}

/// The fit of `cfg`'s design from its accumulated normal equations `ne`
/// (those of `acc`, or a [`NormalEquations::subset`] of them that holds
/// exactly `cfg`'s columns in its order); `acc` gives the rows' bookkeeping.
pub(crate) fn solve_accumulated(
    ne: &NormalEquations,
    acc: &Accumulated,
    cfg: &LsConfig,
) -> Result<LsFit> {
    let (used, effective_dof) = (acc.used, acc.effective_dof);
    let terms = cfg.design.n_columns();
    if ne.rows() <= terms {
        return Err(CompError::data(underdetermined(ne.rows(), terms)));
    }
    let mut warnings = acc.warnings.clone();
    let sol = ne
        .solve_with_dof(cfg.lambda, effective_dof)
        .map_err(CompError::estimation("least-squares fit failed"))?;
    let names = cfg.design.column_names();
    if names.len() != sol.coef.len() {
        return Err(CompError::data(format!(
            "{} accumulated columns for a design of {}",
            sol.coef.len(),
            names.len()
        )));
    }
    warnings.extend(diagnose(&sol, &names, cfg.max_vif));
    if cfg.band_hz.is_some() {
        warnings.extend(manoeuvre_warning(&names, &ne.ata(), ne.rows()));
    }
    if let Some(w) = ridge_warning(cfg.lambda, &ne.ata()) {
        warnings.push(w);
    }
    Ok(LsFit {
        coef: sol.coef.iter().copied().collect(),
        std: sol.std.iter().copied().collect(),
        vif: sol.vif.iter().copied().collect(),
        condition: sol.condition,
        residual_rms_nt: (sol.rss / sol.rows as f64).sqrt(),
        rows: sol.rows,
        effective_dof,
        segments_used: used,
        names,
        warnings,
        notes: Vec::new(),
    })
}

/// The refusal of a fit of `terms` terms on `rows` rows (`rows ≤ terms`):
/// such a fit passes through every row, its residual is zero whatever the
/// flight's noise, and its standard deviations are those of a residual
/// with no degree of freedom. Before, 3 rows of a real survey line fitted
/// the three permanent terms with a residual of 0.0008 nT and exit 0.
fn underdetermined(rows: usize, terms: usize) -> String {
    format!(
        "{rows} rows to fit {terms} terms: a fit needs more rows than terms (many more to \
         determine them); fit a longer flight or more of its lines (--lines), or fewer terms \
         (--terms)"
    )
}

/// A warning when the ridge λ (added to each diagonal element of `AᵀA`)
/// outweighs the data: beyond the largest diagonal element every
/// coefficient is pulled towards zero, whatever the flight says, and the
/// standard deviations are those of the prior, not of the data.
fn ridge_warning(lambda: f64, ata: &nalgebra::DMatrix<f64>) -> Option<String> {
    let largest = ata.diagonal().iter().copied().fold(0.0, f64::max);
    (lambda > largest).then(|| {
        format!(
            "ridge λ = {} exceeds every diagonal element of AᵀA (the largest is {:.3e}): \
             the coefficients are shrunk towards zero whatever the flight says; \
             a λ of a small fraction of the diagonal is usual",
            aeromag_core::error::shown(lambda),
            largest
        )
    })
}

/// Plain-language warnings about what the flight does not determine.
pub fn diagnose(sol: &LsSolution, names: &[String], max_vif: f64) -> Vec<String> {
    let mut w = Vec::new();
    let bad = sol.poorly_determined(max_vif);
    if !bad.is_empty() {
        let list: Vec<String> = bad
            .iter()
            .map(|&j| format!("{} (VIF {:.1e})", names[j], sol.vif[j]))
            .collect();
        w.push(format!(
            "poorly determined terms: {} — the flight does not separate them from the other terms \
             (fly all four headings with roll, pitch and yaw manoeuvres, or drop these terms)",
            list.join(", ")
        ));
    }
    if sol.is_ill_conditioned() {
        w.push(format!(
            "the fit is ill-conditioned (scaled condition number {:.2e})",
            sol.condition
        ));
    }
    for dir in sol.null_directions(max_vif * 10.0) {
        let mut idx: Vec<usize> = (0..dir.len()).collect();
        idx.sort_by(|&a, &b| dir[b].abs().total_cmp(&dir[a].abs()));
        let terms: Vec<String> = idx
            .iter()
            .take(4)
            .filter(|&&j| dir[j].abs() > 0.1)
            .map(|&j| format!("{:+.2}·{}", dir[j], names[j]))
            .collect();
        w.push(format!(
            "not determined by this flight: the combination {}",
            terms.join(" ")
        ));
    }
    w
}

/// Below this RMS of a band-passed direction cosine over the rows fitted,
/// the flight barely turns that axis of the aircraft in the band, and the
/// terms it carries rest on turbulence and on the model's errors: their
/// stated standard deviations are then no guide. Measured in the default
/// band (0.1–0.9 Hz; x, y, z): MagNav.jl's real calibration test case
/// (`test_data_TL.mat`, 100 s at 10 Hz) 0.017, 0.013, 0.012; a simulated
/// calibration flight with its manoeuvres 0.019, 0.047, 0.012, and its
/// straight legs alone 0.0012, 0.023, 0.0058 (fitted there, i_xz came
/// out 17 stated σ from the whole flight's, with no warning).
pub const MIN_MANOEUVRE_COSINE_RMS: f64 = 0.005;

/// The warning for a band-pass fit whose permanent-term columns (the
/// band-passed direction cosines `p_x`, `p_y`, `p_z`) vary by less than
/// [`MIN_MANOEUVRE_COSINE_RMS`] RMS over the `rows` fitted (`ata`: their
/// normal matrix, whose diagonal holds the sums of squares).
pub fn manoeuvre_warning(
    names: &[String],
    ata: &nalgebra::DMatrix<f64>,
    rows: usize,
) -> Option<String> {
    let still: Vec<String> = names
        .iter()
        .enumerate()
        .filter(|(_, n)| matches!(n.as_str(), "p_x" | "p_y" | "p_z"))
        .map(|(j, n)| (n, (ata[(j, j)] / rows.max(1) as f64).sqrt()))
        .filter(|(_, rms)| *rms < MIN_MANOEUVRE_COSINE_RMS)
        .map(|(n, rms)| format!("{} {rms:.4}", &n[2..]))
        .collect();
    (!still.is_empty()).then(|| {
        format!(
            "the flight barely manoeuvres: the band-passed direction cosines vary by {} RMS (below \
             {MIN_MANOEUVRE_COSINE_RMS}; a calibration pattern's rolls, pitches and yaws give \
             0.01 and more), so the terms they carry rest on turbulence and the model's errors, and \
             may be off by more than their std: fly the calibration manoeuvres [few-manoeuvres]",
            still.join(", ")
        )
    })
}

/// The longest response of the band-pass filter (to 10⁻¹⁵ of its peak),
/// samples. The default band's lasts about 1.2·10⁵ samples at 1 kHz;
/// 10⁷ is over 11 days at 10 Hz, longer than any leg: a band so narrow,
/// or so low against the sample rate, leaves nothing of the manoeuvres to
/// fit (and beyond it the filter's arithmetic fails).
pub const MAX_SETTLING_SAMPLES: usize = 10_000_000;

/// The most samples [`LsConfig::trim`] may drop at each end of a leg: a
/// filter's transients last some periods of its low edge (tens of seconds,
/// hundreds of samples); 10⁶ samples is over a day at 10 Hz.
pub const MAX_TRIM: usize = 1_000_000;

fn validate(cfg: &LsConfig) -> Result<()> {
    if cfg.trim > MAX_TRIM {
        return Err(CompError::setting(format!(
            "trim {} samples at each end of a leg: at most {MAX_TRIM}",
            cfg.trim
        )));
    }
    if let Some((lo, hi)) = cfg.band_hz
        && !(lo > 0.0 && hi > lo && hi.is_finite())
    {
        return Err(CompError::setting(format!(
            "pass band {lo}–{hi} Hz: need 0 < low < high"
        )));
    }
    if !(cfg.lambda >= 0.0 && cfg.lambda.is_finite()) {
        return Err(CompError::setting(format!(
            "ridge λ = {} must be ≥ 0",
            cfg.lambda
        )));
    }
    cfg.design.validate()
}

/// Zero-phase filter every non-constant column in place (MagNav's rule:
/// standard deviation ≤ ε means constant), spread over the available cores.
/// Each column is filtered independently, so the result does not depend on
/// the number of threads. A column with a non-finite value comes out
/// non-finite throughout rather than as an error (no pass of its own to
/// look for one): the callers' maps find it in what they use.
fn filter_columns(
    sos: &Sos,
    cols: &mut [Vec<f64>],
    y: &mut [f64],
    scratch: &mut Vec<Vec<[f64; FILTER_LANES]>>,
    threads: usize,
) -> Result<()> {
    // Constant columns (the permanent terms on a straight leg) stay as
    // they are; the others go through the filter FILTER_LANES at a time,
    // the groups shared out over the threads (each with its scratch buffer,
    // kept for the next block). Each column's result is the same bits
    // whatever the grouping and the thread count.
    let mut varying: Vec<&mut [f64]> = cols
        .iter_mut()
        .map(|c| c.as_mut_slice())
        .chain(std::iter::once(y))
        .filter(|c| varies(c))
        .collect();
    let threads = threads.max(1);
    if threads == 1 {
        scratch.resize_with(1, Vec::new);
        return sosfiltfilt_columns_propagating_with(sos, &mut varying, &mut scratch[0])
            .map_err(CompError::from);
    }
    let groups = varying.len().div_ceil(FILTER_LANES);
    let per = groups.div_ceil(threads).max(1) * FILTER_LANES;
    scratch.resize_with(threads, Vec::new);
    // One share of the columns per thread.
    let mut jobs: Vec<_> = varying
        .chunks_mut(per)
        .zip(scratch.iter_mut())
        .map(|(chunk, ext)| (chunk, ext, Ok(())))
        .collect();
    for_each_weighted_mut(
        &mut jobs,
        threads,
        |_| 1,
        |(chunk, ext, out)| {
            *out = sosfiltfilt_columns_propagating_with(sos, chunk, ext);
        },
    );
    jobs.into_iter()
        .try_for_each(|(_, _, out)| out.map_err(CompError::from))
}

/// Whether `x` varies by MagNav's rule: its standard deviation (as
/// [`std_dev`] computes it) above `ε` (`f64::EPSILON`), or not a number (a
/// column with a NaN goes through the filter, and the block's normal
/// equations then refuse it).
///
/// Without the standard deviation's two passes over the column when two of
/// its values already settle it: for any two values, `(n − 1) σ² ≥
/// (x_i − x_j)² / 2`, so a spread `max − min` above `4ε √(2(n − 1))` (twice
/// the bound, which covers the rounding of the spread and of the computed
/// σ: relative errors of order `n ε`) proves `σ > ε`. A varying column of a
/// flight settles within its first few values; a constant one is passed to
/// [`std_dev`] whole. Perf put about a sixth of a 10⁷-sample fit's time in
/// the two passes over every column of every block.
fn varies(x: &[f64]) -> bool {
    let Some(&first) = x.first() else {
        return false;
    };
    let enough = 4.0 * f64::EPSILON * (2.0 * (x.len() - 1) as f64).sqrt();
    let (mut lo, mut hi) = (first, first);
    for &v in x {
        (lo, hi) = (lo.min(v), hi.max(v));
        if hi - lo > enough {
            return true;
        }
    }
    let s = std_dev(x);
    s.is_nan() || s > f64::EPSILON
}

fn std_dev(x: &[f64]) -> f64 {
    let n = x.len() as f64;
    if x.len() < 2 {
        return 0.0;
    }
    // Sums in four lanes: one add chain per value would wait on the
    // adder's latency (this runs on every column of every block).
    fn sum4(x: &[f64], f: impl Fn(f64) -> f64) -> f64 {
        let mut s = [0.0; 4];
        let chunks = x.chunks_exact(4);
        let tail: f64 = chunks.remainder().iter().map(|&v| f(v)).sum();
        for c in chunks {
            for l in 0..4 {
                s[l] += f(c[l]);
            }
        }
        (s[0] + s[1]) + (s[2] + s[3]) + tail
    }
    let m = sum4(x, |v| v) / n;
    (sum4(x, |v| (v - m) * (v - m)) / (n - 1.0)).sqrt()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::tolles_lawson::TermSet;
    use aeromag_core::frames::Attitude;
    use nalgebra::Vector3;

    /// A synthetic leg: its times (s), vector readings (nT) and scalar
    /// readings (nT).
    pub(crate) type Leg = (Vec<f64>, [Vec<f64>; 3], Vec<f64>);

    /// A synthetic calibration leg: heading `yaw0` (deg), roll/pitch/yaw
    /// oscillations, Earth field (NED) fixed, interference from `coef`
    /// through the design row itself (a solver test, not a physics test),
    /// plus a slow external variation and white noise.
    fn leg(yaw0: f64, coef: &[f64], terms: &TermSet, t0: f64, maneuvers: bool) -> Leg {
        leg_n(yaw0, coef, terms, t0, maneuvers, 1800)
    }

    pub(crate) fn leg_n(
        yaw0: f64,
        coef: &[f64],
        terms: &TermSet,
        t0: f64,
        maneuvers: bool,
        n: usize,
    ) -> Leg {
        let b_ned = Vector3::new(17_000.0, 1_500.0, 48_000.0);
        let dt = 0.1;
        let (mut t, mut fx, mut fy, mut fz) = (vec![], vec![], vec![], vec![]);
        for i in 0..n {
            let s = i as f64 * dt;
            let (r, p, y) = if maneuvers {
                let w = |period: f64, start: f64, amp: f64| {
                    let s = s % 180.0; // the manoeuvre sequence repeats every 180 s
                    if s >= start && s < start + 50.0 {
                        amp * (std::f64::consts::TAU * (s - start) / period).sin()
                    } else {
                        0.0
                    }
                };
                (w(5.0, 10.0, 10.0), w(4.5, 70.0, 5.0), w(5.5, 125.0, 5.0))
            } else {
                (0.3 * (0.5 * s).sin(), 1.0, 0.0)
            };
            let b = Attitude::from_degrees(r, p, yaw0 + y).c_bn() * b_ned;
            t.push(t0 + s);
            fx.push(b.x);
            fy.push(b.y);
            fz.push(b.z);
        }
        let mut mag = Vec::with_capacity(n);
        let interf = Design::new(terms.clone()).interference(coef, &t, [&fx, &fy, &fz]);
        let mut noise = 12345u64;
        for (i, interf) in interf.into_iter().enumerate() {
            noise = noise
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let u = ((noise >> 11) as f64 / (1u64 << 53) as f64) - 0.5;
            let bt = (fx[i] * fx[i] + fy[i] * fy[i] + fz[i] * fz[i]).sqrt();
            mag.push(bt + interf + 5.0 * (0.002 * t[i]).sin() + 0.02 * u);
        }
        (t, [fx, fy, fz], mag)
    }

    /// A sensor 2000 nT from its aircraft's parts: data made with the exact
    /// magnitude `|B + ΔB| − |B|` (a solver test: the model's own form).
    /// In the band the induced terms absorb most of the second-order term
    /// (the first-order fit's residual is only 2.5× the noise), but the
    /// first-order model applied over the four headings is 0.19 nT off;
    /// Gauss–Newton fits to the noise, finds the coefficients, and the
    /// fitted model applies itself exactly (`interference` under
    /// `Magnitude::Exact`).
    #[test]
    fn exact_magnitude_fits_what_the_projection_cannot() {
        let terms = TermSet::observable16();
        let (exact, coef) = exact_case(&terms, &coef16());
        let legs: Vec<_> = [0.0, 90.0, 180.0, 270.0]
            .iter()
            .enumerate()
            .map(|(k, h)| {
                let (t, f, mut m) = leg(*h, &coef16(), &terms, k as f64 * 1000.0, true);
                to_exact(&terms, &coef16(), &coef, &t, [&f[0], &f[1], &f[2]], &mut m);
                (t, f, m)
            })
            .collect();
        let segs = segments_of(&legs);
        let dev: f64 = {
            let (d, _) = exact.field_vector(&coef, segs[0].time, segs[0].flux, Channels::NONE);
            d[0].iter()
                .zip(&d[1])
                .zip(&d[2])
                .map(|((x, y), z)| (x * x + y * y + z * z).sqrt())
                .fold(0.0, f64::max)
        };
        assert!(dev > 1500.0, "interference {dev} nT");
        let first = fit_band_pass_ls(&segs, &LsConfig::default()).unwrap();
        let cfg = LsConfig {
            design: exact.clone(),
            ..LsConfig::default()
        };
        let gn = fit_band_pass_ls(&segs, &cfg).unwrap();
        assert!(first.residual_rms_nt > 0.012, "{}", first.residual_rms_nt);
        assert!(gn.residual_rms_nt < 0.007, "{}", gn.residual_rms_nt);
        // Applied to every row of the legs, against the truth.
        let applied = |d: &Design, c: &[f64]| -> f64 {
            let (mut truth, mut model) = (Vec::new(), Vec::new());
            for s in &segs {
                truth.extend(exact.interference(&coef, s.time, s.flux));
                model.extend(d.interference(c, s.time, s.flux));
            }
            rms_of_difference(&truth, &model)
        };
        let first_err = applied(&Design::new(terms.clone()), &first.coef);
        let gn_err = applied(&exact, &gn.coef);
        assert_exact_beats_first_order(first_err, gn_err, &gn.notes, &gn.warnings);
        for (k, (a, b)) in gn.coef.iter().zip(&coef).enumerate() {
            assert!(
                (a - b).abs() < 1e-3 * b.abs().max(10.0),
                "coefficient {k}: {a} vs {b}"
            );
        }
    }

    /// The exact-magnitude cases of both methods: the design under
    /// [`Magnitude::Exact`] and the coefficients, 40× `base` (over 1500 nT
    /// of interference, where the projection's second-order term is nT).
    pub(crate) fn exact_case(terms: &TermSet, base: &[f64]) -> (Design, Vec<f64>) {
        let exact = Design {
            magnitude: Magnitude::Exact,
            ..Design::new(terms.clone())
        };
        (exact, base.iter().map(|c| 40.0 * c).collect())
    }

    /// Replace the first-order interference of `base` in the reading `mag`
    /// by the exact one of `coef`; returns the exact interference.
    pub(crate) fn to_exact(
        terms: &TermSet,
        base: &[f64],
        coef: &[f64],
        time: &[f64],
        flux: [&[f64]; 3],
        mag: &mut [f64],
    ) -> Vec<f64> {
        let (exact, _) = exact_case(terms, base);
        let first = Design::new(terms.clone()).interference(base, time, flux);
        let truth = exact.interference(coef, time, flux);
        for ((m, a), t) in mag.iter_mut().zip(first).zip(&truth) {
            *m += t - a;
        }
        truth
    }

    /// RMS about its mean of `a − b`.
    pub(crate) fn rms_of_difference(a: &[f64], b: &[f64]) -> f64 {
        let e: Vec<f64> = a.iter().zip(b).map(|(x, y)| x - y).collect();
        let m = e.iter().sum::<f64>() / e.len() as f64;
        (e.iter().map(|v| (v - m).powi(2)).sum::<f64>() / e.len() as f64).sqrt()
    }

    /// What both methods' exact-magnitude tests claim: the first-order
    /// model applied is off by more than 0.1 nT, the Gauss–Newton fit by
    /// less than 0.01 nT, and it says it converged in a note (it was a
    /// warning), not a warning.
    pub(crate) fn assert_exact_beats_first_order(
        first_err: f64,
        gn_err: f64,
        notes: &[String],
        warnings: &[String],
    ) {
        assert!(first_err > 0.1, "first order {first_err} nT");
        assert!(
            gn_err < 0.01,
            "exact {gn_err} nT, first order {first_err} nT"
        );
        assert!(
            notes.iter().any(|w| w.contains("converged in")),
            "{notes:?}"
        );
        assert!(
            !warnings.iter().any(|w| w.contains("Gauss–Newton")),
            "{warnings:?}"
        );
    }

    /// Segments over synthetic legs.
    pub(crate) fn segments_of(legs: &[Leg]) -> Vec<Segment<'_>> {
        legs.iter()
            .map(|(t, f, m)| Segment {
                time: t,
                flux: [&f[0], &f[1], &f[2]],
                mag: m,
                channels: Default::default(),
                direction: None,
            })
            .collect()
    }

    pub(crate) fn coef16() -> Vec<f64> {
        vec![
            30.0, -12.0, 45.0, 20.0, -5.0, 8.0, 15.0, -3.0, 2.0, -1.5, 0.5, 1.0, -0.7, 0.3, 1.2,
            -0.4,
        ]
    }

    #[test]
    fn recovers_interference_from_a_four_heading_box() {
        let terms = TermSet::observable16();
        let coef = coef16();
        let legs: Vec<_> = [0.0, 90.0, 180.0, 270.0]
            .iter()
            .enumerate()
            .map(|(k, h)| leg(*h, &coef, &terms, k as f64 * 1000.0, true))
            .collect();
        let segs: Vec<Segment> = segments_of(&legs);
        let fit = fit_band_pass_ls(&segs, &LsConfig::default()).unwrap();
        assert_eq!(fit.segments_used, 4);
        // Compare the modelled interference (minus its mean) with the truth.
        let (t, f, _) = &legs[1];
        let flux = [f[0].as_slice(), f[1].as_slice(), f[2].as_slice()];
        let est = Design::new(terms.clone()).interference(&fit.coef, t, flux);
        let tru = Design::new(terms.clone()).interference(&coef, t, flux);
        let d: Vec<f64> = est.iter().zip(&tru).map(|(a, b)| a - b).collect();
        let m = d.iter().sum::<f64>() / d.len() as f64;
        let rms = (d.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / d.len() as f64).sqrt();
        assert!(rms < 0.01, "interference error RMS {rms} nT");
        assert!(fit.warnings.is_empty(), "{:?}", fit.warnings);
        assert!(fit.residual_rms_nt < 0.02, "{}", fit.residual_rms_nt);
        // A ridge beyond every diagonal element of AᵀA zeroes the model:
        // said in a warning; a small one is not.
        for (lambda, warned) in [(1e-6, false), (1e12, true)] {
            let cfg = LsConfig {
                lambda,
                ..LsConfig::default()
            };
            let fit = fit_band_pass_ls(&segs, &cfg).unwrap();
            let ridge = fit.warnings.iter().any(|w| w.contains("ridge λ"));
            assert_eq!(ridge, warned, "λ {lambda}: {:?}", fit.warnings);
        }
    }

    #[test]
    fn one_heading_without_maneuvers_is_reported() {
        let terms = TermSet::observable16();
        let coef = coef16();
        let (t, f, m) = leg(0.0, &coef, &terms, 0.0, false);
        let seg = Segment {
            time: &t,
            flux: [&f[0], &f[1], &f[2]],
            mag: &m,
            channels: Default::default(),
            direction: None,
        };
        match fit_band_pass_ls(&[seg], &LsConfig::default()) {
            Ok(fit) => {
                let text = fit.warnings.join("\n");
                assert!(text.contains("poorly determined terms"), "{text}");
                assert!(text.contains("e_") && text.contains("i_"), "{text}");
            }
            Err(e) => assert!(e.to_string().contains("singular"), "{e}"),
        }
    }

    /// Nine lagged-eddy coefficients for the synthetic legs.
    pub(crate) fn coef_lag9() -> Vec<f64> {
        vec![1.5, -0.8, 0.6, 0.9, -1.2, 0.4, -0.5, 0.7, 1.1]
    }

    #[test]
    fn block_wise_filtering_equals_whole_segment_filtering() {
        // With a lagged eddy group too: its start-up transient at each
        // block's first sample must have decayed inside the block's core.
        let terms = TermSet::observable16().with_eddy_lags(&[0.6]).unwrap();
        let coef: Vec<f64> = coef16().into_iter().chain(coef_lag9()).collect();
        // Long legs (9000 samples) so that blocks have true interior edges.
        let legs: Vec<_> = [0.0, 90.0, 180.0, 270.0]
            .iter()
            .enumerate()
            .map(|(k, h)| leg_n(*h, &coef, &terms, k as f64 * 1000.0, true, 9000))
            .collect();
        let segs: Vec<Segment> = segments_of(&legs);
        let whole = fit_band_pass_ls(&segs, &LsConfig::default()).unwrap();
        let blocked = fit_band_pass_ls(
            &segs,
            &LsConfig {
                block_len: 1000,
                ..LsConfig::default()
            },
        )
        .unwrap();
        assert_eq!(whole.rows, blocked.rows);
        for (a, b) in whole.coef.iter().zip(&blocked.coef) {
            assert!((a - b).abs() <= 1e-9 * a.abs().max(1e-3), "{a} vs {b}");
        }
    }

    #[test]
    fn short_segments_are_skipped_with_a_warning_and_bad_config_rejected() {
        let terms = TermSet::observable16();
        let (t, f, m) = leg(0.0, &coef16(), &terms, 0.0, true);
        let short = Segment {
            time: &t,
            flux: [&f[0], &f[1], &f[2]],
            mag: &m,
            channels: Default::default(),
            direction: None,
        }
        .slice(0..50);
        let e = fit_band_pass_ls(&[short], &LsConfig::default()).unwrap_err();
        assert!(e.to_string().contains("no segment"), "{e}");
        // A segment skipped beside a long one is named by its place, from
        // 1, and its time span (it was "segment 0").
        let long = Segment::new(&t, [&f[0], &f[1], &f[2]], &m);
        let fit = fit_band_pass_ls(&[long, short], &LsConfig::default()).unwrap();
        let name = format!("segment 2 (time {}–{} s) has 50 samples", t[0], t[49]);
        assert!(
            fit.warnings.iter().any(|w| w.starts_with(&name)),
            "{name}: {:?}",
            fit.warnings
        );
        let cfg = LsConfig {
            band_hz: Some((0.9, 0.1)),
            ..LsConfig::default()
        };
        let seg = Segment {
            time: &t,
            flux: [&f[0], &f[1], &f[2]],
            mag: &m,
            channels: Default::default(),
            direction: None,
        };
        assert!(fit_band_pass_ls(&[seg], &cfg).is_err());
        // A trim whose double overflows is a bad setting, not a panic.
        for trim in [MAX_TRIM + 1, usize::MAX / 2 + 1, usize::MAX] {
            let cfg = LsConfig {
                trim,
                ..LsConfig::default()
            };
            let e = fit_band_pass_ls(&[seg], &cfg).unwrap_err();
            assert!(e.is_bad_input() && e.to_string().contains("trim"), "{e}");
        }
        // Bands whose filter never settles (they ended in "unstable
        // band-pass filter", a singular fit, or a fit of nothing).
        for band in [(1e-308, 0.9), (1e-6, 2e-6), (0.1, 0.1 + 1e-10)] {
            let cfg = LsConfig {
                band_hz: Some(band),
                ..LsConfig::default()
            };
            let e = fit_band_pass_ls(&[seg], &cfg).unwrap_err();
            assert!(
                e.is_bad_input() && e.to_string().contains("does not die out"),
                "{e}"
            );
        }
    }

    /// A fit with no more rows than terms passes through every row: it is
    /// refused (it was fitted, residual 0, exit 0); one row more is a fit.
    #[test]
    fn a_fit_needs_more_rows_than_terms() {
        let terms = TermSet::observable16();
        let coef = coef16();
        let cfg = LsConfig {
            band_hz: None,
            trim: 0,
            ..LsConfig::default()
        };
        let n = cfg.design.n_columns();
        // The four-heading box as one segment, `rows[k]` rows spread over
        // leg `k`.
        let fit = |rows: [usize; 4]| {
            let (mut t, mut f, mut m) = (vec![], [vec![], vec![], vec![]], vec![]);
            for (k, (h, r)) in [0.0, 90.0, 180.0, 270.0].iter().zip(rows).enumerate() {
                let (lt, lf, lm) = leg(*h, &coef, &terms, k as f64 * 1000.0, true);
                let every = |v: &[f64], to: &mut Vec<f64>| {
                    to.extend(v.iter().step_by(v.len() / r).take(r));
                };
                every(&lt, &mut t);
                every(&lm, &mut m);
                for (axis, to) in lf.iter().zip(&mut f) {
                    every(axis, to);
                }
            }
            fit_band_pass_ls(&segments_of(&[(t, f, m)]), &cfg)
        };
        assert_eq!(n, 16);
        let e = fit([4, 4, 4, 4]).unwrap_err();
        assert!(
            e.is_bad_input() && e.to_string().contains("16 rows to fit 16 terms"),
            "{e}"
        );
        let r = fit([5, 4, 4, 4]);
        assert!(r.is_ok(), "{:?}", r.err());
    }

    /// A non-finite value inside a segment (the callers split segments at
    /// missing values, so this guards the fit itself) is an error of the
    /// fit and of the band-passed residual, wherever it falls in the
    /// blocks, in a flux component or in `mag`.
    #[test]
    fn a_non_finite_value_in_a_segment_is_an_error() {
        let terms = TermSet::observable16();
        let (t, f, m) = leg_n(0.0, &coef16(), &terms, 0.0, true, 6000);
        let cfg = LsConfig {
            block_len: 1024,
            ..LsConfig::default()
        };
        fn segment<'a>(t: &'a [f64], f: &'a [Vec<f64>; 3], m: &'a [f64]) -> [Segment<'a>; 1] {
            [Segment {
                time: t,
                flux: [&f[0], &f[1], &f[2]],
                mag: m,
                channels: Default::default(),
                direction: None,
            }]
        }
        let coef = fit_band_pass_ls(&segment(&t, &f, &m), &cfg).unwrap().coef;
        for at in [0, 1500, 3000, 5999] {
            for bad in [f64::NAN, f64::INFINITY] {
                for which in 0..4 {
                    let (mut f2, mut m2) = (f.clone(), m.clone());
                    if which < 3 {
                        f2[which][at] = bad;
                    } else {
                        m2[at] = bad;
                    }
                    let s = segment(&t, &f2, &m2);
                    assert!(
                        fit_band_pass_ls(&s, &cfg).is_err(),
                        "{bad} at {at} in {which}"
                    );
                    assert!(
                        band_passed_residuals(&s, &cfg, &coef).is_err(),
                        "{bad} at {at} in {which}"
                    );
                }
            }
        }
    }

    proptest::proptest! {
        /// [`varies`] decides as the standard deviation does (a NaN
        /// anywhere: varies, wherever the shortcut stops): constant
        /// columns (at 0, 1 and any level), columns whose values differ in
        /// their last bits, spreads on either side of its shortcut's
        /// bound, NaN.
        #[test]
        fn varies_is_the_standard_deviation_rule(
            level in proptest::prop_oneof![
                proptest::strategy::Just(0.0),
                proptest::strategy::Just(1.0),
                -1e4f64..1e4
            ],
            spread_exp in proptest::option::of(-40.0f64..2.0),
            noise in proptest::collection::vec(-1.0f64..1.0, 1..300),
            nan_at in proptest::option::of(0usize..300),
        ) {
            let scale = spread_exp.map_or(0.0, |e| 10f64.powf(e));
            let mut x: Vec<f64> = noise.iter().map(|u| level + scale * u).collect();
            if let Some(k) = nan_at.filter(|&k| k < x.len()) {
                x[k] = f64::NAN;
            }
            let s = std_dev(&x);
            proptest::prop_assert_eq!(varies(&x), s.is_nan() || s > f64::EPSILON);
        }
    }
}
