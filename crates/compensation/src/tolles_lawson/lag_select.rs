//! Choosing the eddy-current lags `τ` of the `l9` group from the
//! calibration flight.
//!
//! For each candidate `τ` on a grid the band-pass least-squares fit
//! ([`fit_band_pass_ls`]) is repeated with the lagged group added, and the
//! best candidate (smallest band-passed residual) is tested against the model
//! without it by the likelihood-ratio statistic of the band-passed residual,
//!
//! ```text
//! Λ(τ) = ν ln(RSS_0 / RSS_τ)  ~  χ²_q   if the lag explains nothing,
//! ```
//!
//! with `ν = F ν₀`: `ν₀` the nominal degrees of freedom of the band-passed
//! residual ([`super::fit_ls::LsFit::effective_dof`], rows × `2(f_hi −
//! f_lo)/f_s`) and `F` the in-band spectral flatness of the residual under
//! test ([`spectral_flatness`]). `F ν₀` is Satterthwaite's equivalent number
//! of independent samples of a coloured residual, `tr(C)²/tr(C²)`: geology
//! leaking into the low edge of the band, or a model error at the
//! manoeuvre frequency, concentrates the residual's power in a few bins, and
//! any extra columns then cut its RSS by more than chance would with white
//! noise. On the simulator's box at 1000 m over realistic geology the
//! nominal `ν` took τ = (0.3, 1.0) s (the 1 s lag fitting geology: 0.0103 nT
//! of interference-model error on the independent survey); with `F`
//! (0.36–0.45 there) it takes 0.3 s alone (0.0050 nT). In the quiet box
//! (`F` = 0.68, then 0.93) the choice (0.1, 0.5) s is unchanged. `q` is
//! the number of added
//! columns (9 per lag). The lag is kept when `Λ` exceeds the `χ²_q` quantile
//! at `1 − α/m` (`m` candidates on the grid: a Bonferroni correction, since
//! the best of `m` correlated candidates is tested; `α` = 1 % by default),
//! i.e. when the lagged currents explain more of the in-band signal than `q`
//! extra columns would by chance. A flight whose eddy currents are fast (or
//! absent) keeps the classical model. Lags are added greedily: after the
//! first, a second `τ` is tested against the model that already holds the
//! first, up to `max_lags`.
//!
//! Why a test and not an information criterion: on the simulator's default
//! box BIC (penalty `q ln ν`, 7 per column there) kept one lag where a second
//! one cut the in-band residual RSS by 6 % and brought the Kalman method's
//! survey residual from 7 % above the noise floor to 2 %; AIC (penalty 2 per
//! column) took both but also took a spurious lag on synthetic data without
//! any (a 2 % RSS cut, the best of nine candidates). The test separates the
//! two (`Λ` ≈ 53 against 24.5; threshold 27.6 for nine candidates, 26.9 for
//! the seven of [`DEFAULT_LAG_GRID_S`]).
//!
//! Cost: for the eddy lags of the first-order model, one filtering pass
//! over the design with every grid lag (`O(N·(n + 9m)²)`), each candidate
//! then a subset of its normal equations (`EddyLagUnion`), and one residual
//! pass per greedy step for the flatness; otherwise (an extra regressor's
//! lag, the exact magnitude) `grid × max_lags` least-squares fits. Pass
//! [`within_budget`] segments to bound `N` on long records.

use super::design::Magnitude;
use super::fit_ls::{
    Accumulated, LsConfig, LsFit, Segment, accumulate, band_passed_residuals, fit_band_pass_ls,
    solve_accumulated, usable_segments,
};
use super::terms::TermSet;
use crate::error::{CompError, Result};
use aeromag_core::spectrum::{WelchConfig, welch};
use aeromag_estimation::stats::chi_square_quantile;
use serde::{Deserialize, Serialize};

/// Default candidate lags, s: 0.1–1 s, about 1.5× apart (aircraft skins,
/// frames and control surfaces have `L/R` of 0.1–1 s).
///
/// Longer lags are left out on purpose: over a calibration area with
/// geology the band-passed residual is not white, and a lag of 1.5–2 s — a
/// slow, smooth column — fits part of the anomaly field. On the simulator's
/// box flown at 1000 m over realistic geology a grid up to 2 s took
/// τ = (0.3, 2.0) s and left 0.0255 nT on the independent survey; up to 1 s
/// it took (0.3, 1.0) s and left 0.0153 nT (classical model: 0.0190 nT).
pub const DEFAULT_LAG_GRID_S: [f64; 7] = [0.1, 0.15, 0.2, 0.3, 0.5, 0.7, 1.0];

/// Default candidate lags of an extra regressor (`--extra cur_flap:lag`),
/// s: the eddy grid and longer lags, since the field of structure around a
/// switching load may settle for seconds. A lagged current column moves
/// only when the current does, so the long lags do not fit geology the way
/// a lagged field derivative does.
pub const DEFAULT_EXTRA_LAG_GRID_S: [f64; 10] =
    [0.05, 0.1, 0.15, 0.2, 0.3, 0.5, 0.7, 1.0, 1.5, 2.0];

/// One candidate's score.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LagCandidate {
    /// Lags of the model scored, the candidate last (s).
    pub tau_s: f64,
    /// Number of lags in the scored model, the candidate included.
    pub lags: usize,
    /// RMS of the band-passed fit residual, nT.
    pub residual_rms_nt: f64,
    /// Likelihood-ratio statistic `Λ` against the model without this
    /// candidate.
    pub lr_statistic: f64,
    /// The `χ²_q` threshold `Λ` must exceed for the candidate to be kept.
    pub threshold: f64,
    /// Spectral flatness `F` of the residual the candidate is tested
    /// against (the `ν` of `Λ` is `F` times the nominal dof; module docs).
    #[serde(default = "one")]
    pub spectral_flatness: f64,
}

/// How the lag of one extra regressor (`--extra name:lag`) was chosen.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExtraLagSelection {
    /// The regressor's channel.
    pub channel: String,
    /// The search ([`select_extra_lag`]): `taus_s` holds the chosen lag,
    /// empty when none was significant.
    #[serde(flatten)]
    pub selection: LagSelection,
}

fn one() -> f64 {
    1.0
}

/// The outcome of [`select_eddy_lags`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LagSelection {
    /// The chosen lags, s (empty: the classical model is kept).
    pub taus_s: Vec<f64>,
    /// Residual RMS of the model without lags, nT.
    pub base_residual_rms_nt: f64,
    /// Residual RMS of the chosen model, nT.
    pub residual_rms_nt: f64,
    /// Every candidate scored, in the order tried.
    pub candidates: Vec<LagCandidate>,
    /// Rows the residuals are over: those every candidate can use (a leg's
    /// first rows lack the history of the longest lag), fewer than the
    /// final fit's on short legs (0 in model files written before it).
    #[serde(default)]
    pub rows: usize,
}

fn rss(f: &LsFit) -> f64 {
    f.residual_rms_nt * f.residual_rms_nt * f.rows as f64
}

/// Spectral flatness of band-passed residuals within the pass band
/// `(lo, hi)` Hz: `F = (mean P)² / mean(P²)` over the Welch bins inside the
/// band (Hann, 256-sample segments, the PSDs of the series averaged with
/// their lengths as weights). `F = 1` for white noise; a residual whose
/// power sits in a few bins has `F ≪ 1`. Returns 1 when no series is long
/// enough to estimate it.
pub fn spectral_flatness(residuals: &[(Vec<f64>, f64)], band_hz: (f64, f64)) -> f64 {
    const NPERSEG: usize = 256;
    let mut sum: Vec<f64> = Vec::new();
    let mut freqs: Vec<f64> = Vec::new();
    let mut weight = 0.0;
    for (r, fs) in residuals {
        if r.len() < NPERSEG {
            continue;
        }
        let Ok(psd) = welch(r, &WelchConfig::new(*fs, NPERSEG)) else {
            continue;
        };
        if sum.is_empty() {
            sum = vec![0.0; psd.values.len()];
            freqs = psd.freqs_hz.clone();
        }
        if psd.values.len() != sum.len() {
            continue; // another sampling rate: its bins do not line up
        }
        let w = r.len() as f64;
        for (s, p) in sum.iter_mut().zip(&psd.values) {
            *s += w * p;
        }
        weight += w;
    }
    if weight == 0.0 {
        return 1.0;
    }
    let inband: Vec<f64> = freqs
        .iter()
        .zip(&sum)
        .filter(|(f, _)| (band_hz.0..=band_hz.1).contains(*f))
        .map(|(_, p)| p / weight)
        .collect();
    if inband.len() < 4 {
        return 1.0;
    }
    let n = inband.len() as f64;
    let mean = inband.iter().sum::<f64>() / n;
    let mean_sq = inband.iter().map(|p| p * p).sum::<f64>() / n;
    if mean_sq > 0.0 {
        (mean * mean / mean_sq).min(1.0)
    } else {
        1.0
    }
}

/// Family-wise false-selection probability of each step of
/// [`select_eddy_lags`].
pub const DEFAULT_ALPHA: f64 = 0.01;

/// Rows the selection fits at most (default budget): a calibration flight
/// (10³–10⁵ rows) is used whole; a longer record is sampled
/// ([`within_budget`]), so the ~15 selection fits cost what one fit of
/// 3·10⁶ rows does, and the final fit still uses every row.
pub const DEFAULT_SELECTION_ROWS: usize = 200_000;

/// Rows the lag search of each extra regressor fits at most (default
/// budget): one candidate's three lagged columns are judged on this many
/// rows (at 10 Hz 50 minutes of flight), so that a whole flight with a
/// dozen current channels, each searched with about 20 fits of a design of
/// 100 columns, costs seconds rather than minutes.
pub const DEFAULT_EXTRA_SELECTION_ROWS: usize = 30_000;

/// Length of the blocks [`within_budget`] samples, rows (default).
pub const DEFAULT_SELECTION_BLOCK: usize = 3_000;

/// At most about `max_rows` rows of `segments`, each block its own segment
/// (filtered and trimmed on its own):
/// - a segment whose share of the budget (the same fraction of every
///   segment's length) is at least a tenth of a block (`block_rows / 10`,
///   300 rows by default: three periods of a 0.1 Hz band edge at 10 Hz),
///   or the whole segment when shorter, gives its share as blocks of about
///   `block_rows` rows spread evenly over it (a calibration leg flies its
///   manoeuvres one after the other, so a prefix would hold only the first);
/// - the shorter shares are pooled in segment order, and each time they add
///   up to half a piece the next segment gives one whole piece (itself up
///   to `block_rows` rows, its middle block beyond), so a flight of many
///   short legs is sampled in whole legs spread over the flight rather than
///   in slivers too short to filter. Before, 3·10⁶ rows in legs of 850
///   (the peers' flight repeated) left 57-row slivers, and `calibrate`
///   stopped: "no segment is long enough to fit". A budget below half a
///   piece still gives one: the longest segment's.
pub fn within_budget<'a>(
    segments: &[Segment<'a>],
    max_rows: usize,
    block_rows: usize,
) -> Vec<Segment<'a>> {
    let total: usize = segments.iter().map(|s| s.time.len()).sum();
    if total <= max_rows {
        return segments.to_vec();
    }
    let block_rows = block_rows.max(1);
    let frac = max_rows as f64 / total as f64;
    // The middle `rows` rows of `s`.
    let middle = |s: &Segment<'a>, rows: usize| {
        let a = (s.time.len() - rows) / 2;
        s.slice(a..a + rows)
    };
    let mut out = Vec::new();
    // The pooled shares not yet taken, rows.
    let mut owed = 0.0;
    for s in segments {
        let len = s.time.len();
        let exact = len as f64 * frac;
        if exact < len.min(block_rows / 10).max(1) as f64 {
            owed += exact;
            let piece = len.min(block_rows);
            if owed >= piece as f64 / 2.0 {
                owed -= piece as f64;
                out.push(middle(s, piece));
            }
            continue;
        }
        let share = (exact.ceil() as usize).min(len);
        let blocks = share.div_ceil(block_rows).max(1);
        let blk = share / blocks;
        if blocks == 1 {
            out.push(middle(s, blk));
            continue;
        }
        for k in 0..blocks {
            let a = k * (len - blk) / (blocks - 1);
            out.push(s.slice(a..a + blk));
        }
    }
    if out.is_empty()
        && let Some(s) = segments.iter().rev().max_by_key(|s| s.time.len())
    {
        out.push(middle(s, s.time.len().min(block_rows)));
    }
    out
}

/// The threshold a likelihood-ratio statistic must exceed for the best of
/// `candidates` lags, each adding `columns` columns, to be kept at the
/// false-selection probability `alpha`: the `χ²_columns` quantile at
/// `1 − α/candidates` (Bonferroni over the candidates tried).
pub fn lag_threshold(alpha: f64, candidates: usize, columns: usize) -> Result<f64> {
    let m = candidates.max(1) as f64;
    chi_square_quantile(1.0 - alpha / m, columns as u32)
        .map_err(CompError::estimation("lag selection"))
}

/// Choose up to `max_lags` lags from `grid_s` (s) for `cfg`'s term set (which
/// must hold an eddy group; lagged groups already in it are replaced), each
/// kept at the false-selection probability `alpha` (0 < α < 1). Pass
/// [`within_budget`] segments to bound the cost on long records.
pub fn select_eddy_lags(
    segments: &[Segment],
    cfg: &LsConfig,
    grid_s: &[f64],
    max_lags: usize,
    alpha: f64,
) -> Result<LagSelection> {
    let with = |taus: &[f64]| cfg.design.terms.with_eddy_lags(taus);
    match EddyLagUnion::accumulate(segments, cfg, grid_s, max_lags)? {
        Some(union) => select_lags(segments, cfg, grid_s, max_lags, alpha, with, |c| {
            union.fit(c)
        }),
        None => select_lags(segments, cfg, grid_s, max_lags, alpha, with, |c| {
            fit_band_pass_ls(segments, c)
        }),
    }
}

/// The normal equations of the design with every candidate eddy lag at
/// once, from one filtering pass over the rows: each candidate model of
/// [`select_eddy_lags`] is then a [`NormalEquations::subset`] of them,
/// solved without another pass.
///
/// Each column is filtered on its own and its products with the others do
/// not depend on which other columns are in the design, so a candidate's
/// fit equals its own [`fit_band_pass_ls`] to round-off (the products are
/// summed in another grouping). The search over `m` grid lags and up to two
/// lags then filters `18 + 9m` columns once instead of `27–36` per fit
/// (`2m` fits). `aeromag calibrate` of a 10⁵-sample flight
/// (tools/bench/peers.py gen) took 0.554 s before and 0.235 s after, of
/// which 0.072 s without the search (hyperfine, 5 runs); the model file is
/// the same bytes, since the final fit is its own.
struct EddyLagUnion {
    acc: Accumulated,
    /// The grid, sorted and without repeats (the order of the lagged groups
    /// in the accumulated design).
    grid: Vec<f64>,
    /// Columns of the design without lags, and where its lagged groups go.
    base_columns: usize,
    lag_start: usize,
}

impl EddyLagUnion {
    /// `None` where the shared pass does not apply: the exact-magnitude
    /// model (a Gauss–Newton fit per candidate), or a segment long enough
    /// for the candidate models but too short for the wider design.
    fn accumulate(
        segments: &[Segment],
        cfg: &LsConfig,
        grid_s: &[f64],
        max_lags: usize,
    ) -> Result<Option<Self>> {
        if cfg.design.magnitude != Magnitude::FirstOrder || grid_s.is_empty() {
            return Ok(None);
        }
        let terms = &cfg.design.terms;
        let with = |taus: &[f64]| -> Result<LsConfig> {
            Ok(LsConfig {
                design: cfg.design.with_terms(terms.with_eddy_lags(taus)?),
                ..cfg.clone()
            })
        };
        let mut grid = grid_s.to_vec();
        grid.sort_by(f64::total_cmp);
        grid.dedup();
        let union = with(&grid)?;
        let widest = with(&grid[..max_lags.clamp(1, grid.len())])?;
        if usable_segments(segments, &union)? != usable_segments(segments, &widest)? {
            return Ok(None);
        }
        let base_names = with(&[])?.design.column_names();
        let union_names = union.design.column_names();
        if union_names.len() != base_names.len() + 9 * grid.len() {
            return Ok(None);
        }
        let lag_start = base_names
            .iter()
            .zip(&union_names)
            .take_while(|(a, b)| a == b)
            .count();
        Ok(Some(Self {
            acc: accumulate(segments, &union)?,
            grid,
            base_columns: base_names.len(),
            lag_start,
        }))
    }

    /// The fit of `cfg`, whose lags must be on the grid.
    fn fit(&self, cfg: &LsConfig) -> Result<LsFit> {
        let mut keep: Vec<usize> = (0..self.lag_start).collect();
        for tau in cfg.design.terms.eddy_lags_s() {
            let Some(k) = self.grid.iter().position(|g| g == tau) else {
                return Err(CompError::Failed {
                    reason: format!("eddy lag {tau} s is not on the searched grid"),
                });
            };
            keep.extend(self.lag_start + 9 * k..self.lag_start + 9 * (k + 1));
        }
        let shift = 9 * self.grid.len();
        keep.extend((self.lag_start..self.base_columns).map(|j| j + shift));
        let ne = self
            .acc
            .ne
            .subset(&keep)
            .map_err(CompError::estimation("lag selection"))?;
        solve_accumulated(&ne, &self.acc, cfg)
    }
}

/// Choose the lag of the extra regressor `k` of `cfg`'s term set
/// ([`TermSet::extras`]; a lag it has is replaced) from `grid_s` (s) by
/// the same test as [`select_eddy_lags`]: at most one lag, kept at the
/// false-selection probability `alpha` when its three lagged columns
/// explain more of the in-band signal than chance would. A kept lag is then
/// fitted: the band-passed residual is minimised over `τ` between the grid
/// points either side of it (golden-section search, [`REFINE_STEPS`] fits;
/// the test is not repeated, since the refined lag fits at least as well).
pub fn select_extra_lag(
    segments: &[Segment],
    cfg: &LsConfig,
    k: usize,
    grid_s: &[f64],
    alpha: f64,
) -> Result<LagSelection> {
    let terms = &cfg.design.terms;
    if k >= terms.extras().len() {
        return Err(CompError::InvalidTerms {
            reason: format!("no extra regressor {k}"),
        });
    }
    let with = |taus: &[f64]| {
        let mut extras = terms.extras().to_vec();
        extras[k].lag_s = taus.first().copied();
        terms.with_extras(&extras)
    };
    let mut sel = select_lags(segments, cfg, grid_s, 1, alpha, with, |c| {
        fit_band_pass_ls(segments, c)
    })?;
    if let [tau] = sel.taus_s[..] {
        let mut grid = grid_s.to_vec();
        grid.sort_by(f64::total_cmp);
        let at = grid.iter().position(|g| *g == tau).unwrap_or(0);
        let lo = if at > 0 { grid[at - 1] } else { 0.5 * tau };
        let hi = grid.get(at + 1).copied().unwrap_or(2.0 * tau);
        let fit_at = |t: f64| -> Result<LsFit> {
            fit_band_pass_ls(
                segments,
                &LsConfig {
                    design: cfg.design.with_terms(with(&[t])?),
                    ..cfg.clone()
                },
            )
        };
        let (best_tau, best) = golden_section(lo, hi, |t| Ok(rss(&fit_at(t)?)))?;
        if best < rss(&fit_at(tau)?) {
            sel.taus_s = vec![best_tau];
            sel.residual_rms_nt = fit_at(best_tau)?.residual_rms_nt;
        }
    }
    Ok(sel)
}

/// Fits of the golden-section refinement of an extra regressor's lag.
pub const REFINE_STEPS: usize = 12;

/// Minimise `f` over `[lo, hi]` by golden-section search in
/// [`REFINE_STEPS`] evaluations; returns the best point seen and its
/// value.
fn golden_section(lo: f64, hi: f64, mut f: impl FnMut(f64) -> Result<f64>) -> Result<(f64, f64)> {
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let (mut a, mut b) = (lo, hi);
    let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
    let (mut fc, mut fd) = (f(c)?, f(d)?);
    let mut best = if fc < fd { (c, fc) } else { (d, fd) };
    for _ in 2..REFINE_STEPS {
        if fc < fd {
            b = d;
            (d, fd) = (c, fc);
            c = b - g * (b - a);
            fc = f(c)?;
        } else {
            a = c;
            (c, fc) = (d, fd);
            d = a + g * (b - a);
            fd = f(d)?;
        }
        for (x, v) in [(c, fc), (d, fd)] {
            if v < best.1 {
                best = (x, v);
            }
        }
    }
    Ok(best)
}

/// The greedy likelihood-ratio search of the module docs over the lags
/// that `terms_with(lags)` puts into the model.
fn select_lags(
    segments: &[Segment],
    cfg: &LsConfig,
    grid_s: &[f64],
    max_lags: usize,
    alpha: f64,
    terms_with: impl Fn(&[f64]) -> Result<TermSet>,
    mut fit_of: impl FnMut(&LsConfig) -> Result<LsFit>,
) -> Result<LagSelection> {
    let threshold = |q: usize| lag_threshold(alpha, grid_s.len(), q);
    let with = |taus: &[f64]| -> Result<LsConfig> {
        Ok(LsConfig {
            design: cfg.design.with_terms(terms_with(taus)?),
            ..cfg.clone()
        })
    };
    let base = fit_of(&with(&[])?)?;
    let mut chosen: Vec<f64> = Vec::new();
    let mut current = base.clone();
    let mut candidates = Vec::new();
    while chosen.len() < max_lags {
        // The residual the candidates are tested against: its colour sets ν.
        let flatness = match cfg.band_hz {
            Some(band) => spectral_flatness(
                &band_passed_residuals(segments, &with(&chosen)?, &current.coef)?,
                band,
            ),
            None => 1.0,
        };
        let mut best: Option<(f64, f64, f64, LsFit)> = None;
        for &tau in grid_s.iter().filter(|t| !chosen.contains(t)) {
            let mut taus = chosen.clone();
            taus.push(tau);
            let fit = fit_of(&with(&taus)?)?;
            let nu = (flatness * fit.effective_dof).max(1.0);
            let q = fit.coef.len() - current.coef.len();
            let lr = nu * (rss(&current) / rss(&fit)).ln();
            let thr = threshold(q)?;
            candidates.push(LagCandidate {
                spectral_flatness: flatness,
                tau_s: tau,
                lags: taus.len(),
                residual_rms_nt: fit.residual_rms_nt,
                lr_statistic: lr,
                threshold: thr,
            });
            if lr.is_finite() && best.as_ref().is_none_or(|b| lr > b.1) {
                best = Some((tau, lr, thr, fit));
            }
        }
        match best {
            Some((tau, lr, thr, fit)) if lr > thr => {
                chosen.push(tau);
                current = fit;
            }
            _ => break,
        }
    }
    chosen.sort_by(f64::total_cmp);
    Ok(LagSelection {
        taus_s: chosen,
        base_residual_rms_nt: base.residual_rms_nt,
        residual_rms_nt: current.residual_rms_nt,
        candidates,
        rows: base.rows,
    })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::tolles_lawson::Design;
    use crate::tolles_lawson::TermSet;
    use crate::tolles_lawson::fit_ls::tests::{Leg, coef_lag9, coef16, leg_n, segments_of};

    /// The segments of `legs`, each with its extra-regressor channels.
    pub(crate) fn with_channels<'a, const N: usize>(
        legs: &'a [Leg],
        channels: &'a [[&'a [f64]; N]],
    ) -> Vec<Segment<'a>> {
        use super::super::design::Channels;
        segments_of(legs)
            .into_iter()
            .zip(channels)
            .map(|(s, r)| Segment {
                channels: Channels::new(r),
                ..s
            })
            .collect()
    }

    pub(crate) fn boxed(terms: &TermSet, coef: &[f64]) -> Vec<Leg> {
        [0.0, 90.0, 180.0, 270.0]
            .iter()
            .enumerate()
            .map(|(k, h)| leg_n(*h, coef, terms, k as f64 * 1000.0, true, 1800))
            .collect()
    }

    /// The box with eddy currents lagging by 0.5 s (the lagged group at 20×
    /// the classical one's size).
    fn lagging_box() -> Vec<Leg> {
        let truth = TermSet::observable16().with_eddy_lags(&[0.5]).unwrap();
        let coef: Vec<f64> = coef16()
            .into_iter()
            .chain(coef_lag9().into_iter().map(|c| 20.0 * c))
            .collect();
        boxed(&truth, &coef)
    }

    fn select(legs: &[Leg]) -> LagSelection {
        let segs = segments_of(legs);
        select_eddy_lags(
            &segs,
            &LsConfig::default(),
            &DEFAULT_LAG_GRID_S,
            2,
            DEFAULT_ALPHA,
        )
        .unwrap()
    }

    /// Eddy currents lagging by 0.5 s: the lag is found and the residual
    /// falls to the noise (uniform ±0.01 nT, RMS 0.0058 nT before filtering).
    #[test]
    fn finds_the_lag_of_lagging_eddy_currents() {
        let sel = select(&lagging_box());
        assert!(sel.taus_s.contains(&0.5), "{sel:?}");
        assert!(
            sel.base_residual_rms_nt > 3.0 * sel.residual_rms_nt,
            "{sel:?}"
        );
        assert!(sel.residual_rms_nt < 0.004, "{sel:?}");
        assert_eq!(
            sel.candidates.iter().filter(|c| c.lags == 1).count(),
            DEFAULT_LAG_GRID_S.len()
        );
    }

    /// The shared pass scores every candidate as its own fit does (same
    /// choice; residuals and statistics to round-off), and a segment long
    /// enough for the candidates but not for the wider design falls back
    /// to fitting each candidate.
    #[test]
    fn the_shared_pass_scores_candidates_as_their_own_fits() {
        let truth = TermSet::observable16().with_eddy_lags(&[0.3, 0.7]).unwrap();
        let coef: Vec<f64> = coef16()
            .into_iter()
            .chain(coef_lag9().into_iter().map(|c| 20.0 * c))
            .chain(coef_lag9().into_iter().map(|c| -12.0 * c))
            .collect();
        let legs = boxed(&truth, &coef);
        let segs = segments_of(&legs);
        let cfg = LsConfig::default();
        let grid = DEFAULT_LAG_GRID_S;
        let with = |taus: &[f64]| cfg.design.terms.with_eddy_lags(taus);
        let union = EddyLagUnion::accumulate(&segs, &cfg, &grid, 2)
            .unwrap()
            .expect("the shared pass applies");
        let shared =
            select_lags(&segs, &cfg, &grid, 2, DEFAULT_ALPHA, with, |c| union.fit(c)).unwrap();
        let own = select_lags(&segs, &cfg, &grid, 2, DEFAULT_ALPHA, with, |c| {
            fit_band_pass_ls(&segs, c)
        })
        .unwrap();
        assert_eq!(shared.taus_s, own.taus_s);
        assert_eq!(shared.taus_s.len(), 2, "both rounds are scored");
        assert_eq!(shared.candidates.len(), own.candidates.len());
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * a.abs().max(b.abs());
        for (a, b) in shared.candidates.iter().zip(&own.candidates) {
            assert_eq!((a.tau_s, a.lags), (b.tau_s, b.lags));
            assert!(close(a.residual_rms_nt, b.residual_rms_nt), "{a:?} {b:?}");
            assert!(close(a.lr_statistic, b.lr_statistic), "{a:?} {b:?}");
        }
        // The public entry point takes the shared pass here.
        let public = select_eddy_lags(&segs, &cfg, &grid, 2, DEFAULT_ALPHA).unwrap();
        assert_eq!(public, shared);
        // A leg with room for 36 columns but not for 18 + 9·7 = 81.
        let sos_len = {
            let ok = usable_segments(&segs, &cfg).unwrap();
            assert!(ok.iter().all(|u| *u));
            let all = cfg.design.with_terms(with(&grid).unwrap());
            let wide = LsConfig {
                design: all,
                ..cfg.clone()
            };
            let mut n = 100;
            while !usable_segments(&[segs[0].slice(0..n)], &wide).unwrap()[0] {
                n += 1;
            }
            n
        };
        let mut short = segs.clone();
        short.push(segs[0].slice(0..sos_len - 20));
        assert!(
            EddyLagUnion::accumulate(&short, &cfg, &grid, 2)
                .unwrap()
                .is_none()
        );
        let fallback = select_eddy_lags(&short, &cfg, &grid, 2, DEFAULT_ALPHA).unwrap();
        assert!(!fallback.candidates.is_empty());
    }

    /// Instantaneous eddy currents only: no lag passes the test, the
    /// classical model is kept.
    #[test]
    fn keeps_the_classical_model_when_no_lag_helps() {
        let sel = select(&boxed(&TermSet::observable16(), &coef16()));
        assert!(sel.taus_s.is_empty(), "{sel:?}");
        assert_eq!(sel.residual_rms_nt, sel.base_residual_rms_nt);
        assert!(
            sel.candidates.iter().all(|c| c.lr_statistic < c.threshold),
            "{sel:?}"
        );
    }

    /// Many legs too short for the budget's share of each (25 rows of
    /// 180, too few to filter): whole legs are taken, spread over the
    /// flight, about the budget in all, and the search runs on them. A
    /// budget below half a leg still gives one leg, the longest.
    #[test]
    fn short_legs_are_sampled_whole_not_in_slivers() {
        let legs = lagging_box();
        let segs = segments_of(&legs);
        let short: Vec<Segment> = segs
            .iter()
            .flat_map(|s| (0..10).map(move |k| s.slice(180 * k..180 * (k + 1))))
            .collect();
        assert_eq!(short.len(), 40);
        let cut = within_budget(&short, 1000, 3000);
        let rows: usize = cut.iter().map(|s| s.time.len()).sum();
        assert!(cut.iter().all(|s| s.time.len() == 180), "{rows}");
        assert!((1000 - 180..=1000 + 180).contains(&rows), "{rows}");
        // Spread: the first taken within the first tenth, the last within
        // the last tenth of the legs.
        let index = |c: &Segment| short.iter().position(|s| s.time[0] == c.time[0]).unwrap();
        assert!(index(&cut[0]) < 4 && index(&cut[cut.len() - 1]) >= 36);
        select_eddy_lags(
            &cut,
            &LsConfig::default(),
            &DEFAULT_LAG_GRID_S,
            2,
            DEFAULT_ALPHA,
        )
        .unwrap();
        let mut uneven = short.clone();
        uneven[13] = segs[1].slice(0..300);
        let one = within_budget(&uneven, 10, 3000);
        assert_eq!(one.len(), 1);
        assert_eq!((one[0].time.len(), one[0].time[0]), (300, segs[1].time[0]));
    }

    /// The budget samples every segment alike, and the lag is still found
    /// from a third of the rows.
    #[test]
    fn a_row_budget_cuts_every_segment_alike() {
        let legs = lagging_box();
        let segs = segments_of(&legs);
        // 4 legs of 1800 rows, a third of each: 4 blocks of 150 rows per leg,
        // spread over the leg (first at its start, last at its end).
        let cut = within_budget(&segs, 2400, 150);
        assert_eq!(cut.len(), 16);
        assert!(
            cut.iter()
                .all(|s| s.time.len() == 150 && s.mag.len() == 150 && s.flux[2].len() == 150)
        );
        assert_eq!(
            (cut[0].time[0], cut[3].time[149]),
            (segs[0].time[0], segs[0].time[1799])
        );
        assert_eq!(
            within_budget(&segs, 10_000, 150)
                .iter()
                .map(|s| s.time.len())
                .sum::<usize>(),
            7200
        );
        let sel = select_eddy_lags(
            &cut,
            &LsConfig::default(),
            &DEFAULT_LAG_GRID_S,
            2,
            DEFAULT_ALPHA,
        )
        .unwrap();
        assert!(sel.taus_s.contains(&0.5), "{sel:?}");
    }

    /// A current loop whose field follows its current through a 0.5 s lag
    /// (eddy currents in structure around a switching load): the field is
    /// `kᵀe · L[I]` with `k` fixed in the body, added to a box flown with
    /// the 16-term interference. The channel alone leaves much of it; the
    /// lag search finds the lag (0.42 s, between grid points: the refinement
    /// fits it) and brings the residual to the noise, and a current whose
    /// field does not lag gets no lag.
    #[test]
    fn finds_the_lag_of_a_current_whose_field_lags() {
        use super::super::eddy_lag::FirstOrderLag;
        use super::super::terms::ExtraTerm;
        let mut legs = boxed(&TermSet::observable16(), &coef16());
        let k_nt_per_a = [30.0, -12.0, 20.0];
        // A load switched on and off every 3.7 s, with ramps, and a
        // second one (field without lag) of a 5.3 s cycle.
        let current = |t: f64| 8.0 * f64::from(u8::from(((t / 3.7) as u64).is_multiple_of(2)));
        const TAU: f64 = 0.42; // between the grid's 0.3 and 0.5 s
        let other = |t: f64| 3.0 * f64::from(u8::from(!((t / 5.3) as u64).is_multiple_of(2)));
        let mut chans: Vec<[Vec<f64>; 2]> = Vec::new();
        for (t, f, m) in legs.iter_mut() {
            let (mut lag, mut i1, mut i2) = (FirstOrderLag::new(TAU), vec![], vec![]);
            for (n, ti) in t.iter().enumerate() {
                let bt = (f[0][n].powi(2) + f[1][n].powi(2) + f[2][n].powi(2)).sqrt();
                let e = [f[0][n] / bt, f[1][n] / bt, f[2][n] / bt];
                let (a, b) = (current(*ti), other(*ti));
                let g = lag.step(*ti, a);
                m[n] += (0..3)
                    .map(|i| k_nt_per_a[i] * e[i] * (g + 0.2 * b))
                    .sum::<f64>();
                i1.push(a);
                i2.push(b);
            }
            chans.push([i1, i2]);
        }
        let refs: Vec<[&[f64]; 2]> = chans.iter().map(|[a, b]| [&a[..], &b[..]]).collect();
        let segs = with_channels(&legs, &refs);
        let terms = TermSet::observable16()
            .with_extras(&[ExtraTerm::new("cur_flap"), ExtraTerm::new("cur_tank")])
            .unwrap();
        let cfg = LsConfig {
            design: Design::new(terms),
            ..LsConfig::default()
        };
        let plain = fit_band_pass_ls(&segs, &cfg).unwrap();
        let sel =
            select_extra_lag(&segs, &cfg, 0, &DEFAULT_EXTRA_LAG_GRID_S, DEFAULT_ALPHA).unwrap();
        assert!(
            matches!(sel.taus_s[..], [t] if (t - TAU).abs() < 0.01),
            "{sel:?}"
        );
        assert!(
            plain.residual_rms_nt > 5.0 * sel.residual_rms_nt,
            "{plain:?} {sel:?}"
        );
        assert!(sel.residual_rms_nt < 0.004, "{sel:?}");
        let other =
            select_extra_lag(&segs, &cfg, 1, &DEFAULT_EXTRA_LAG_GRID_S, DEFAULT_ALPHA).unwrap();
        assert!(other.taus_s.is_empty(), "{other:?}");
        assert!(
            select_extra_lag(&segs, &cfg, 2, &DEFAULT_EXTRA_LAG_GRID_S, DEFAULT_ALPHA).is_err()
        );
    }

    /// Geology leaking into the low edge of the band (a smooth along-track
    /// signal at 0.08–0.15 Hz, unrelated to the manoeuvres)
    /// makes the residual coloured: with `ν` scaled by its spectral flatness
    /// no lag is taken for it, while the eddy currents' lag is still found.
    #[test]
    fn geology_in_the_band_does_not_buy_a_lag() {
        let geology = |legs: &mut Vec<Leg>, amp: f64| {
            for (k, (t, _, m)) in legs.iter_mut().enumerate() {
                for (ti, mi) in t.iter().zip(m.iter_mut()) {
                    *mi += (0..8)
                        .map(|j| {
                            let f = 0.08 + 0.01 * j as f64;
                            let phase = 0.7 * (j * 7 + k * 3) as f64;
                            amp * (std::f64::consts::TAU * f * ti + phase).sin()
                        })
                        .sum::<f64>();
                }
            }
        };
        let mut legs = boxed(&TermSet::observable16(), &coef16());
        geology(&mut legs, 0.5);
        let sel = select(&legs);
        // (With the nominal ν, i.e. F = 1, this test took τ = 1 s.)
        assert!(sel.taus_s.is_empty(), "{sel:?}");
        assert!(
            sel.candidates.iter().all(|c| c.spectral_flatness < 0.5),
            "{sel:?}"
        );
        // Lagging eddy currents are still found under weaker geology. (Under
        // the strong one they are not: the price of the test's caution, and
        // why the Kalman method, which models the geology, matters there.)
        let mut legs = lagging_box();
        geology(&mut legs, 0.1);
        let sel = select(&legs);
        assert!(sel.taus_s.contains(&0.5), "{sel:?}");
    }

    #[test]
    fn white_noise_is_flat_and_a_tone_is_not() {
        use rand::SeedableRng;
        use rand_distr::{Distribution, Uniform};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(99);
        let u = Uniform::new(-0.5, 0.5).unwrap();
        let white: Vec<f64> = (0..4000).map(|_| u.sample(&mut rng)).collect();
        let f = spectral_flatness(&[(white.clone(), 10.0)], (0.1, 0.9));
        assert!(f > 0.85 && f <= 1.0, "white {f}");
        let tone: Vec<f64> = (0..4000)
            .map(|i| (std::f64::consts::TAU * 0.3 * i as f64 / 10.0).sin() + 0.01 * white[i])
            .collect();
        let f = spectral_flatness(&[(tone, 10.0)], (0.1, 0.9));
        assert!(f < 0.2, "tone {f}");
        assert_eq!(
            spectral_flatness(&[(vec![1.0; 100], 10.0)], (0.1, 0.9)),
            1.0,
            "too short: no estimate"
        );
    }

    #[test]
    fn needs_an_eddy_group() {
        let legs = boxed(&TermSet::observable16(), &coef16());
        let segs = segments_of(&legs);
        let cfg = LsConfig {
            design: Design::new(TermSet::parse("p3,i5").unwrap()),
            ..LsConfig::default()
        };
        assert!(select_eddy_lags(&segs, &cfg, &DEFAULT_LAG_GRID_S, 2, DEFAULT_ALPHA).is_err());
    }
}
