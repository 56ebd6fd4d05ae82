//! Method 2 end to end: runs, tuning, pass 1 (coefficients), pass 2 (the
//! smoothed external field), outputs and diagnostics.
//!
//! Pass 1 is the joint filter over the runs in turn
//! ([`CoefficientPass::Joint`], the default: it also gives the sequential
//! innovations) or the field filter with the coefficients integrated out
//! over groups of runs on all cores ([`CoefficientPass::Augmented`]: the
//! same coefficients, covariance, likelihood and field to round-off, test
//! `the_augmented_pass_gives_the_joint_fit`). Pass 2 smooths each run on
//! its own, the runs on all cores, while pass 1's design rows are formed a
//! few blocks ahead on a second thread.

use super::anomaly_model::{AnomalyTransition, NoiseModel, X2Prior};
use super::field_filter::{
    FieldModelSpec, FilteredGroup, GroupSamples, OwnedSamples, check_field_model, filter_groups,
    groups_of_runs, merge_in_order,
};
use super::field_smoother::{FieldModel, smooth_field};
use super::joint_filter::{JointFilter, est};
use super::rows::{for_each_design_row, for_each_design_row_ahead, for_every_nth_design_row};
use super::track::step_length;
use super::tuning::{Subset, TuningConfig, TuningReport, tune};
use crate::error::{CompError, Result};
use crate::model_file::{
    Coefficient, FitStats, KalmanSettings, MODEL_FORMAT, MethodSettings, TlModel,
};
use crate::tolles_lawson::Design;
use crate::tolles_lawson::fit_ls::{LsFit, Segment, diagnose};
use crate::tolles_lawson::segments::split_segments;
use aeromag_core::cancel::{check, never};
use aeromag_core::parallel::{parallel_map, threads};
use aeromag_estimation::kalman::{
    Checkpoint, FILTER_LANES, Innovation, LeadingConditional, SqrtKalmanFilter, default_block_len,
    upper_cholesky,
};
use aeromag_estimation::least_squares::NormalEquations;
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};
use std::ops::Range;

/// One contiguous piece of a calibration flight with what the field model
/// needs besides the Tolles-Lawson inputs (equal-length slices).
#[derive(Debug, Clone, Copy)]
pub struct KalmanSegment<'a> {
    /// Time (s, increasing), vector magnetometer (nT, body), scalar reading (nT).
    pub data: Segment<'a>,
    /// Altitude of the sensor or the navigation point, m (only its
    /// variation matters: `Δz = alt − z0`).
    pub alt_m: &'a [f64],
    /// Ground speed, m/s ([`super::track`]).
    pub speed_m_s: &'a [f64],
}

/// Settings of the Kalman fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct KalmanConfig {
    /// The design of `X1`: terms (default `p3,i5,e8`), derivative
    /// convention, scale of the induced and eddy columns (default 50 000 nT).
    #[serde(flatten)]
    pub design: Design,
    /// Noise intensities (the start point when tuning).
    pub noise: NoiseModel,
    /// Maximum-likelihood tuning of the intensities.
    pub tuning: TuningConfig,
    /// Order of the along-track field model and the prior of its states at
    /// every run start (set [`Self::noise`] to match the order:
    /// [`NoiseModel::calibration_default_for`]).
    pub field_prior: X2Prior,
    /// Prior standard deviation of every coefficient (mean 0), in its own
    /// units (nT for `p`, `i`, `bias`; nT·s for physical-convention eddy
    /// terms). Default 1000: effectively diffuse, finite so that
    /// `μ_i = √(P_post,ii / P_prior,ii)` is defined.
    pub coef_prior_std: f64,
    /// Reference altitude `z0`, m; `None` = the mean altitude of the flight.
    pub z0_m: Option<f64>,
    /// Whether to compute the per-sample series (compensated reading,
    /// smoothed field, innovations); `false` gives only the coefficients
    /// and their covariances (pass 1).
    pub compute_series: bool,
    /// Checkpoint block of the smoother (0 = `max(64, ⌈√N⌉)`).
    pub smoother_block_len: usize,
    /// Variance inflation factor above which a term is reported as poorly
    /// determined (default 1e4).
    pub max_vif: f64,
    /// How pass 1 estimates the coefficients (default: the joint filter).
    #[serde(default)]
    pub coefficient_pass: CoefficientPass,
}

/// How pass 1 estimates the coefficients.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CoefficientPass {
    /// The joint square-root filter of field and coefficients over the
    /// runs in turn (the thesis): also gives the sequential innovations,
    /// each with the coefficients estimated from the samples before it
    /// (their statistics and the innovation series).
    #[default]
    Joint,
    /// The field filter with the coefficients integrated out
    /// ([`super::field_filter`]), groups of runs on all cores: the same
    /// coefficients, covariance, likelihood and smoothed field to
    /// round-off, without innovations (their statistics NaN, their series
    /// NaN). For fits whose innovations nobody reads: the Kalman method's
    /// field removal and its likelihood-ratio tests of further lags.
    Augmented,
    /// The joint filter split in two (de Jong 1991): the field filter with
    /// the coefficients integrated out, groups of runs on the cores, hands
    /// each sample's whitened innovations (`E_k/√S_k`, `e_k/√S_k`) to the
    /// recursive least squares of the coefficients over the runs in turn
    /// (Carlson's square-root update of `m` states), which gives the joint
    /// filter's sequential innovations `ν_k = e_k − E_k (β̂_{k−1} − β₀)`,
    /// `σ_k² = S_k (1 + Ẽ_k P_{k−1} Ẽ_kᵀ)`, its coefficients, covariance and
    /// likelihood — the same to round-off, with the field filter's work on
    /// every core and overlapping the least squares.
    Split,
}

impl Default for KalmanConfig {
    fn default() -> Self {
        Self {
            design: Design::default(),
            noise: NoiseModel::calibration_default(),
            tuning: TuningConfig::default(),
            field_prior: X2Prior::default(),
            coef_prior_std: 1000.0,
            z0_m: None,
            compute_series: true,
            smoother_block_len: 0,
            max_vif: 1e4,
            coefficient_pass: CoefficientPass::Joint,
        }
    }
}

/// Per-sample outputs of one input segment (same length; NaN at samples the
/// fit could not use).
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct KalmanSeries {
    /// `mag − H1 X̂1`, nT.
    pub compensated_nt: Vec<f64>,
    /// Smoothed external field `B^h + Δz B_z` (plus the removed constant), nT.
    pub external_nt: Vec<f64>,
    /// Pass-1 innovation `ν_k`, nT.
    pub innovation_nt: Vec<f64>,
    /// Its predicted standard deviation `σ_k`, nT.
    pub innovation_std_nt: Vec<f64>,
}

/// The result of [`fit_kalman`].
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct KalmanFit {
    /// Coefficient names (column order).
    pub names: Vec<String>,
    /// Coefficients `X̂1` (final filtered = smoothed).
    pub coef: Vec<f64>,
    /// Their standard deviations `√diag(P1)`.
    pub std: Vec<f64>,
    /// Prior covariance of `X1` (diagonal, `coef_prior_std²`).
    pub prior_covariance: DMatrix<f64>,
    /// Posterior covariance `P1` of `X1` (from the final factor).
    pub posterior_covariance: DMatrix<f64>,
    /// Variance inflation factor of each coefficient in the information
    /// the data gave, `P1⁻¹ − P0⁻¹` (the analogue of the least-squares VIF;
    /// ∞ when that matrix is singular).
    pub vif: Vec<f64>,
    /// Scaled condition number of `P1⁻¹ − P0⁻¹` (∞ when singular).
    pub condition: f64,
    /// Order of the along-track field model used ([`X2Prior::order`]).
    pub field_order: usize,
    /// Noise intensities used (`q₁` in nT²/m^{2n−1}, `n` the field order).
    pub noise: NoiseModel,
    /// The tuning, when it ran.
    pub tuning: Option<TuningReport>,
    /// Reference altitude `z0`, m.
    pub z0_m: f64,
    /// The constant removed from the reading before filtering, nT.
    pub y_ref_nt: f64,
    /// Log-likelihood of all innovations of pass 1.
    pub log_likelihood: f64,
    /// Mean of `ν²/σ²` over the samples after the first five of each run
    /// (≈ 1 when the noise model fits).
    pub normalized_innovation_variance: f64,
    /// RMS of the innovations over the same samples, nT.
    pub innovation_rms_nt: f64,
    /// RMS of `compensated − smoothed field` (the estimated sensor-level
    /// residual), nT; NaN without series.
    pub residual_rms_nt: f64,
    /// Samples used.
    pub rows: usize,
    /// Contiguous runs (the field model restarts at each).
    pub runs: usize,
    /// Input segments with at least one run.
    pub segments_used: usize,
    /// Warnings for the user.
    pub warnings: Vec<String>,
    /// Notes for the user ([`LsFit::notes`]).
    pub notes: Vec<String>,
    /// Per-segment series (empty without [`KalmanConfig::compute_series`]).
    pub series: Vec<KalmanSeries>,
}

#[derive(Debug, Clone)]
struct Run {
    seg: usize,
    range: Range<usize>,
}

/// The Kalman fit of the exact-magnitude model `|B + ΔB| − |B|`
/// ([`crate::tolles_lawson::Magnitude::Exact`]) by Gauss–Newton, as the
/// band-pass fit does it
/// ([`crate::tolles_lawson::fit_ls::fit_exact_magnitude`]): the first-order
/// fit of `cfg` (tuned as `cfg` says), then fits of the reading corrected by
/// the second-order remainder on rows whose direction cosines are those of
/// the total field `B + ΔB(c_k)`, with the noise intensities of the first
/// fit fixed, until no coefficient moves by more than 1e-3 of its standard
/// deviation (at most
/// [`MAX_GAUSS_NEWTON_STEPS`](crate::tolles_lawson::fit_ls::MAX_GAUSS_NEWTON_STEPS)
/// steps; a warning says how many). The first fit's tuning report is kept.
pub fn fit_kalman_exact(segments: &[KalmanSegment], cfg: &KalmanConfig) -> Result<KalmanFit> {
    fit_kalman_exact_cancellable(segments, cfg, &mut never)
}

/// [`fit_kalman_exact`], each of its fits asking `cancel` as
/// [`fit_kalman_cancellable`] does.
pub fn fit_kalman_exact_cancellable(
    segments: &[KalmanSegment],
    cfg: &KalmanConfig,
    cancel: &mut dyn FnMut() -> bool,
) -> Result<KalmanFit> {
    use crate::tolles_lawson::fit_ls::{MAX_GAUSS_NEWTON_STEPS, linearised};
    let first = fit_kalman_cancellable(segments, cfg, cancel)?;
    let mut fixed = KalmanConfig {
        noise: first.noise,
        ..cfg.clone()
    };
    fixed.tuning.enabled = false;
    let tuning = first.tuning.clone();
    let mut fit = first;
    let (mut steps, mut converged) = (0, false);
    while steps < MAX_GAUSS_NEWTON_STEPS {
        let lin: Vec<([Vec<f64>; 3], Vec<f64>)> = segments
            .iter()
            .map(|s| linearised(&cfg.design, &fit.coef, &s.data))
            .collect();
        let step: Vec<KalmanSegment> = segments
            .iter()
            .zip(&lin)
            .map(|(s, (t, y))| KalmanSegment {
                data: Segment {
                    mag: y,
                    direction: Some([&t[0], &t[1], &t[2]]),
                    ..s.data
                },
                ..*s
            })
            .collect();
        let next = fit_kalman_cancellable(&step, &fixed, cancel)?;
        steps += 1;
        let moved = next
            .coef
            .iter()
            .zip(&fit.coef)
            .zip(&next.std)
            .map(|((a, b), s)| (a - b).abs() / s.max(f64::MIN_POSITIVE))
            .fold(0.0, f64::max);
        fit = next;
        if moved < 1e-3 {
            converged = true;
            break;
        }
    }
    fit.tuning = tuning;
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

/// Samples of the joint filter between two questions to the cancellation
/// probe ([`fit_kalman_cancellable`]): a few milliseconds of filtering.
pub const CANCEL_ROWS: usize = 4096;

/// Runs shorter than this are skipped (the eddy derivatives need 3 samples).
const MIN_RUN: usize = 3;

/// Fit the Tolles-Lawson coefficients jointly with the stochastic field
/// model (spec `compensation.md`, Method 2; module docs of [`super`]).
pub fn fit_kalman(segments: &[KalmanSegment], cfg: &KalmanConfig) -> Result<KalmanFit> {
    fit_kalman_cancellable(segments, cfg, &mut never)
}

/// [`fit_kalman`], asking `cancel` ([`aeromag_core::cancel`]) on the
/// calling thread before every evaluation of the noise tuning, every
/// [`CANCEL_ROWS`] samples of the joint filter, every round of the split
/// pass's groups and before the smoother: [`CompError::Cancelled`] as soon
/// as it says to stop. The same fit as [`fit_kalman`] when it never does.
pub fn fit_kalman_cancellable(
    segments: &[KalmanSegment],
    cfg: &KalmanConfig,
    cancel: &mut dyn FnMut() -> bool,
) -> Result<KalmanFit> {
    validate(cfg)?;
    let m = cfg.design.n_columns();
    let names = cfg.design.column_names();
    let spec = &cfg.design;
    let mut warnings = Vec::new();

    // ---- runs: maximal stretches of usable samples.
    let mut runs = Vec::new();
    let mut unusable = 0usize;
    let mut short = 0usize;
    for (si, s) in segments.iter().enumerate() {
        let n = s.data.time.len();
        let d = &s.data;
        if d.mag.len() != n
            || d.flux.iter().any(|f| f.len() != n)
            || s.alt_m.len() != n
            || s.speed_m_s.len() != n
        {
            return Err(CompError::data(format!(
                "segment {si}: columns of unequal length"
            )));
        }
        let usable: Vec<bool> = (0..n)
            .map(|i| {
                let f = [d.flux[0][i], d.flux[1][i], d.flux[2][i]];
                d.time[i].is_finite()
                    && d.mag[i].is_finite()
                    && f.iter().all(|v| v.is_finite())
                    && f.iter().any(|v| *v != 0.0)
                    && s.alt_m[i].is_finite()
                    && s.speed_m_s[i].is_finite()
                    && s.speed_m_s[i] >= 0.0
            })
            .collect();
        unusable += usable.iter().filter(|u| !**u).count();
        let (kept, _) = split_segments(d.time, None, &usable, f64::INFINITY, 1);
        for r in kept {
            if let Some(k) = (r.start + 1..r.end).find(|&k| {
                d.time[k].partial_cmp(&d.time[k - 1]) != Some(std::cmp::Ordering::Greater)
            }) {
                return Err(CompError::data(format!(
                    "segment {si}: time does not increase at row {k}"
                )));
            }
            if r.len() < MIN_RUN {
                short += r.len();
                continue;
            }
            runs.push(Run { seg: si, range: r });
        }
    }
    if unusable > 0 {
        warnings.push(format!("{unusable} samples have missing or invalid values (mag, flux, alt, speed) and are not used"));
    }
    if short > 0 {
        warnings.push(format!(
            "{short} samples in runs shorter than {MIN_RUN} samples are not used"
        ));
    }
    let rows: usize = runs.iter().map(|r| r.range.len()).sum();
    if rows < m + cfg.field_prior.dim() {
        return Err(CompError::data(format!(
            "{rows} usable samples are too few for {m} coefficients"
        )));
    }

    // ---- reference altitude and reading.
    let mean_over = |pick: fn(&KalmanSegment<'_>, Range<usize>) -> f64| {
        runs.iter()
            .map(|r| pick(&segments[r.seg], r.range.clone()))
            .sum::<f64>()
            / rows as f64
    };
    let z0 = cfg
        .z0_m
        .unwrap_or_else(|| mean_over(|s, r| s.alt_m[r].iter().sum()));
    let y_ref = mean_over(|s, r| s.data.mag[r].iter().sum());
    let coef_mean = vec![0.0; m];
    let coef_std = vec![cfg.coef_prior_std; m];

    // ---- maximum-likelihood tuning on a decimated copy.
    let mut noise = cfg.noise;
    let mut tuning = None;
    if cfg.tuning.enabled {
        let dec = rows.div_ceil(cfg.tuning.max_rows.max(1)).max(1);
        let subset = decimated_subset(segments, &runs, spec, dec, z0, y_ref);
        let rep = tune(
            &subset,
            &coef_mean,
            &coef_std,
            &cfg.field_prior,
            noise,
            &cfg.tuning,
            dec,
            cancel,
        )?;
        if !rep.converged {
            warnings.push(format!(
                "noise tuning stopped after {} evaluations without meeting its tolerance; using the best values found",
                rep.evaluations
            ));
        }
        noise = rep.tuned;
        tuning = Some(rep);
    }

    // ---- pass 1: the coefficients and the smoother's restart points.
    let mut series: Vec<KalmanSeries> = if cfg.compute_series {
        segments
            .iter()
            .map(|s| {
                let n = s.data.time.len();
                KalmanSeries {
                    compensated_nt: vec![f64::NAN; n],
                    external_nt: vec![f64::NAN; n],
                    innovation_nt: vec![f64::NAN; n],
                    innovation_std_nt: vec![f64::NAN; n],
                }
            })
            .collect()
    } else {
        Vec::new()
    };
    let inputs = PassInputs {
        segments,
        runs: &runs,
        cfg,
        noise,
        z0,
        y_ref,
        coef_mean: &coef_mean,
        coef_std: &coef_std,
    };
    let Pass1 {
        coef,
        posterior_covariance,
        factor,
        log_lik,
        innovations,
        conditionals,
    } = match cfg.coefficient_pass {
        CoefficientPass::Joint => joint_pass(&inputs, &mut series, cancel)?,
        CoefficientPass::Augmented => {
            check(cancel)?;
            augmented_pass(&inputs)?
        }
        CoefficientPass::Split => split_pass(&inputs, &mut series, cancel)?,
    };
    let std: Vec<f64> = (0..m)
        .map(|j| posterior_covariance[(j, j)].max(0.0).sqrt())
        .collect();
    let (vif, condition, diag_warnings) = information_diagnostics(
        &factor,
        cfg.coef_prior_std * cfg.coef_prior_std,
        &names,
        cfg.max_vif,
    )?;
    warnings.extend(diag_warnings);

    // ---- compensated series and pass 2: the smoothed field.
    let mut residual_rms_nt = f64::NAN;
    if cfg.compute_series {
        check(cancel)?;
        let transition = AnomalyTransition::new(&noise, cfg.field_prior.order);
        // The runs are independent given X̂1: each run's compensated reading
        // and smoothed field on the cores (run-local slices, the same
        // arithmetic), written back in run order.
        let per_run = parallel_map(runs.len(), threads(), |r| -> Result<(Vec<f64>, Vec<f64>)> {
            let (run, cps) = (&runs[r], &conditionals[r]);
            let s = &segments[run.seg];
            let range = run.range.clone();
            let checkpoints: Vec<Checkpoint> = cps
                .iter()
                .map(|(step, c)| Checkpoint {
                    step: *step,
                    mean: c.mean_given(&coef),
                    factor: c.factor.clone(),
                })
                .collect();
            let mut compensated = vec![0.0; range.len()];
            for_each_design_row(spec, &s.data, range.clone(), |i, row| {
                let a: f64 = row.iter().zip(&coef).map(|(a, c)| a * c).sum();
                compensated[i - range.start] = s.data.mag[i] - a;
            });
            let model = FieldModel {
                time: &s.data.time[range.clone()],
                speed_m_s: &s.speed_m_s[range.clone()],
                alt_m: &s.alt_m[range.clone()],
                compensated_nt: &compensated,
                offset: 0,
                len: range.len(),
                y_ref_nt: y_ref,
                z0_m: z0,
                noise,
                prior: cfg.field_prior,
                transition: transition.clone(),
            };
            let mut external = vec![0.0; range.len()];
            smooth_field(&model, &checkpoints, &mut external)?;
            Ok((compensated, external))
        });
        let mut res2 = 0.0;
        for (run, done) in runs.iter().zip(per_run) {
            let (compensated, external) = done?;
            let out = &mut series[run.seg];
            out.compensated_nt[run.range.clone()].copy_from_slice(&compensated);
            out.external_nt[run.range.clone()].copy_from_slice(&external);
            for (c, e) in compensated.iter().zip(&external) {
                let e = c - e;
                res2 += e * e;
            }
        }
        residual_rms_nt = (res2 / rows as f64).sqrt();
    }
    // The innovation statistics (NaN without innovations).
    let (niv, innovation_rms_nt) = match &innovations {
        Some(sums) => {
            let n = sums.count.max(1) as f64;
            (sums.chi2 / n, (sums.ss / n).sqrt())
        }
        None => (f64::NAN, f64::NAN),
    };
    if innovations.as_ref().is_some_and(|sums| sums.count > 0) && !(0.25..=4.0).contains(&niv) {
        warnings.push(format!(
            "the innovations are {:.1}× {} than the noise model predicts (mean ν²/σ² = {niv:.2}): the noise \
             intensities do not fit this flight; subtract a base-station diurnal record, or tune them \
             (standard deviations of the coefficients are unreliable)",
            niv.sqrt().max(1.0 / niv.sqrt()),
            if niv > 1.0 { "larger" } else { "smaller" }
        ));
    }
    Ok(KalmanFit {
        names,
        coef,
        std,
        prior_covariance: DMatrix::from_diagonal(&nalgebra::DVector::from_iterator(
            m,
            coef_std.iter().map(|s| s * s),
        )),
        posterior_covariance,
        vif,
        condition,
        field_order: cfg.field_prior.order,
        noise,
        tuning,
        z0_m: z0,
        y_ref_nt: y_ref,
        log_likelihood: log_lik,
        normalized_innovation_variance: niv,
        innovation_rms_nt,
        residual_rms_nt,
        rows,
        runs: runs.len(),
        segments_used: {
            let mut s: Vec<usize> = runs.iter().map(|r| r.seg).collect();
            s.dedup();
            s.len()
        },
        warnings,
        notes: Vec::new(),
        series,
    })
}

/// What pass 1 needs besides the configuration.
struct PassInputs<'a> {
    segments: &'a [KalmanSegment<'a>],
    runs: &'a [Run],
    cfg: &'a KalmanConfig,
    noise: NoiseModel,
    z0: f64,
    y_ref: f64,
    coef_mean: &'a [f64],
    coef_std: &'a [f64],
}

/// Pass 1's results: the coefficients' posterior (mean, covariance and its
/// upper factor), the log-likelihood, the innovation statistics (the joint
/// filter's only) and per run the smoother's restart points (run-local
/// step, `X2 | X1`).
struct Pass1 {
    coef: Vec<f64>,
    posterior_covariance: DMatrix<f64>,
    factor: DMatrix<f64>,
    log_lik: f64,
    innovations: Option<InnovationSums>,
    conditionals: Vec<Vec<(usize, LeadingConditional)>>,
}

/// Sums over the innovations past each run's first `n_f` samples: `Σ ν²/σ²`,
/// `Σ ν²` and their number.
struct InnovationSums {
    chi2: f64,
    ss: f64,
    count: usize,
}

/// A pass's sequential innovations as they come (the joint filter's, or
/// the split pass's least squares'): the log-likelihood of all of them,
/// [`InnovationSums`] past each run's first `n_f` samples, and the series.
struct InnovationTally {
    log_lik: f64,
    sums: InnovationSums,
    n_f: usize,
}

impl InnovationTally {
    fn new(n_f: usize) -> Self {
        Self {
            log_lik: 0.0,
            sums: InnovationSums {
                chi2: 0.0,
                ss: 0.0,
                count: 0,
            },
            n_f,
        }
    }

    /// The innovation of row `i` of segment `seg` (`local`: its index in
    /// its run), into the sums and into `series` (when computed).
    fn add(
        &mut self,
        inn: &Innovation,
        local: usize,
        seg: usize,
        i: usize,
        series: &mut [KalmanSeries],
    ) {
        self.log_lik += inn.log_likelihood();
        if local >= self.n_f {
            self.sums.chi2 += inn.value * inn.value / inn.variance;
            self.sums.ss += inn.value * inn.value;
            self.sums.count += 1;
        }
        if let Some(o) = series.get_mut(seg) {
            o.innovation_nt[i] = inn.value;
            o.innovation_std_nt[i] = inn.std();
        }
    }
}

/// Whether pass 1 keeps a restart point of the smoother after the
/// run-local sample `local` of a run of `len` samples: every smoother block
/// ([`KalmanConfig::smoother_block_len`]) but the last, when the series are
/// computed.
fn restart_point(cfg: &KalmanConfig, local: usize, len: usize) -> bool {
    let every = if cfg.smoother_block_len > 0 {
        cfg.smoother_block_len
    } else {
        default_block_len(len)
    };
    cfg.compute_series && (local + 1).is_multiple_of(every) && local + 1 < len
}

/// Pass 1 by the joint filter over the runs in turn; the innovations go
/// into `series` (when computed).
fn joint_pass(
    p: &PassInputs,
    series: &mut [KalmanSeries],
    cancel: &mut dyn FnMut() -> bool,
) -> Result<Pass1> {
    let mut jf = JointFilter::new(p.coef_mean, p.coef_std, &p.cfg.field_prior, p.noise)?;
    let mut tally = InnovationTally::new(p.cfg.field_prior.dim());
    // Per run: restart points of the pass-2 smoother (run-local step, X2 | X1).
    let mut conditionals: Vec<Vec<(usize, LeadingConditional)>> = vec![Vec::new(); p.runs.len()];
    // The design rows are formed on a second thread while the filter runs.
    let run_list: Vec<(&Segment, Range<usize>)> = p
        .runs
        .iter()
        .map(|r| (&p.segments[r.seg].data, r.range.clone()))
        .collect();
    let (mut err, mut current, mut since_asked) = (None, usize::MAX, 0usize);
    for_each_design_row_ahead(&p.cfg.design, &run_list, |r, i, row| {
        since_asked += 1;
        if since_asked == CANCEL_ROWS {
            since_asked = 0;
            if let Err(c) = check(cancel) {
                err = Some(c.into());
                return false;
            }
        }
        let run = &p.runs[r];
        let s = &p.segments[run.seg];
        let len = run.range.len();
        if r != current {
            current = r;
            if let Err(e) = jf.start_run() {
                err = Some(e);
                return false;
            }
        }
        let d = if i == run.range.start {
            0.0
        } else {
            step_length(s.data.time, s.speed_m_s, i)
        };
        match jf.step(d, row, s.alt_m[i] - p.z0, s.data.mag[i] - p.y_ref) {
            Ok(inn) => {
                let local = i - run.range.start;
                tally.add(&inn, local, run.seg, i, series);
                if restart_point(p.cfg, local, len) {
                    match jf.field_conditional() {
                        Ok(c) => conditionals[r].push((local, c)),
                        Err(e) => {
                            err = Some(e);
                            return false;
                        }
                    }
                }
                true
            }
            Err(e) => {
                let name = p.segments[run.seg].data.name(run.seg);
                err = Some(e.at(format!("{name}, its row {i}")));
                false
            }
        }
    });
    if let Some(e) = err {
        return Err(e);
    }
    Ok(Pass1 {
        coef: jf.coefficients().to_vec(),
        posterior_covariance: jf.coefficient_covariance(),
        factor: jf.coefficient_factor(),
        log_lik: tally.log_lik,
        innovations: Some(tally.sums),
        conditionals,
    })
}

/// The groups of runs of the field filter's passes and the transition of
/// their noise intensities, the model checked.
fn pass_groups(p: &PassInputs) -> Result<(Vec<Range<usize>>, AnomalyTransition)> {
    check_field_model(&p.noise, &p.cfg.field_prior)?;
    Ok((
        groups_of_runs(p.runs.iter().map(|r| r.range.len())),
        AnomalyTransition::new(&p.noise, p.cfg.field_prior.order),
    ))
}

impl PassInputs<'_> {
    /// The field filter's model of these inputs under `transition`.
    fn field_model<'t>(
        &'t self,
        transition: &'t AnomalyTransition,
        record: bool,
    ) -> FieldModelSpec<'t> {
        FieldModelSpec {
            x2_prior: &self.cfg.field_prior,
            transition,
            r_nt2: self.noise.r_nt2,
            coef_mean: self.coef_mean,
            coef_std: self.coef_std,
            record_innovations: record,
        }
    }
}

/// The samples of `runs` (a group of runs) for the field filter
/// ([`filter_groups`]): design rows formed run by run, checked here so that
/// an error names the segment and row.
fn group_samples(p: &PassInputs, runs: &[Run]) -> Result<GroupSamples<'static>> {
    let spec = &p.cfg.design;
    let len: usize = runs.iter().map(|r| r.range.len()).sum();
    let mut g = OwnedSamples::with_capacity(len, spec.n_columns());
    for run in runs {
        let s = &p.segments[run.seg];
        let mut err = None;
        for_each_design_row(spec, &s.data, run.range.clone(), |i, row| {
            if err.is_some() {
                return;
            }
            let first = i == run.range.start;
            let d = if first {
                0.0
            } else {
                step_length(s.data.time, s.speed_m_s, i)
            };
            let (dz, y) = (s.alt_m[i] - p.z0, s.data.mag[i] - p.y_ref);
            let usable = d >= 0.0
                && d.is_finite()
                && dz.is_finite()
                && y.is_finite()
                && aeromag_core::simd::all_finite(row);
            if !usable {
                err = Some(
                    CompError::data(format!(
                        "non-finite design row, reading or altitude, or an along-track step {d} m \
                         (must be finite and ≥ 0)"
                    ))
                    .at(format!(
                        "{}, its row {i}",
                        p.segments[run.seg].data.name(run.seg)
                    )),
                );
                return;
            }
            let local = i - run.range.start;
            g.push(
                first,
                d,
                row,
                dz,
                y,
                restart_point(p.cfg, local, run.range.len()),
            );
        });
        if let Some(e) = err {
            return Err(e);
        }
    }
    Ok(g.into_samples())
}

/// Pass 1 by the field filter with the coefficients integrated out
/// ([`super::field_filter`]): groups of runs on the cores, their sums
/// added in run order.
fn augmented_pass(p: &PassInputs) -> Result<Pass1> {
    let (groups, transition) = pass_groups(p)?;
    let model = p.field_model(&transition, false);
    let filtered = filter_groups(groups.len(), threads(), &model, |gi| {
        group_samples(p, &p.runs[groups[gi].clone()])
    })?;
    let mut filters = Vec::with_capacity(filtered.len());
    let mut conditionals = Vec::with_capacity(p.runs.len());
    for (group, done) in groups.iter().zip(filtered) {
        let lengths = p.runs[group.clone()].iter().map(|r| r.range.len());
        FilteredGroup::kept_by_run(done.kept, lengths, &mut conditionals);
        filters.push(done.filter);
    }
    let sol = merge_in_order(filters)?.solve().map_err(est)?;
    Ok(Pass1 {
        factor: upper_cholesky(&sol.covariance).map_err(est)?,
        coef: sol.coef,
        posterior_covariance: sol.covariance,
        log_lik: sol.log_likelihood,
        innovations: None,
        conditionals,
    })
}

/// Pass 1 as [`CoefficientPass::Split`]: rounds of groups of runs through
/// the field filter on the cores, each round's whitened innovations fed to
/// the coefficients' recursive least squares while the next round is
/// filtered; the innovations go into `series` (when computed).
fn split_pass(
    p: &PassInputs,
    series: &mut [KalmanSeries],
    cancel: &mut dyn FnMut() -> bool,
) -> Result<Pass1> {
    let cfg = p.cfg;
    let (groups, transition) = pass_groups(p)?;
    let model = p.field_model(&transition, true);
    let m = p.coef_mean.len();
    let mut rls = SqrtKalmanFilter::new(
        &vec![0.0; m],
        &DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(p.coef_std)),
    )
    .map_err(est)?;
    let mut tally = InnovationTally::new(cfg.field_prior.dim());
    let mut conditionals: Vec<Vec<(usize, LeadingConditional)>> = Vec::with_capacity(p.runs.len());
    // The least squares of one round's groups, in run order.
    let mut absorb = |first_group: usize,
                      done: Vec<FilteredGroup>,
                      series: &mut [KalmanSeries],
                      conditionals: &mut Vec<Vec<(usize, LeadingConditional)>>|
     -> Result<()> {
        for (gi, group) in done.into_iter().enumerate() {
            let runs = &p.runs[groups[first_group + gi].clone()];
            let mut rows = group.innovations.chunks_exact(m + 2);
            let lengths = runs.iter().map(|r| r.range.len());
            FilteredGroup::kept_by_run(group.kept, lengths, conditionals);
            for run in runs {
                for i in run.range.clone() {
                    let w = rows.next().ok_or_else(|| {
                        CompError::data("split pass: fewer innovations than samples".to_string())
                    })?;
                    let (z, e, s_k) = (&w[..m], w[m], w[m + 1]);
                    let white = rls.update(z, e, 1.0).map_err(est)?;
                    let inn = Innovation {
                        value: white.value * s_k.sqrt(),
                        variance: white.variance * s_k,
                    };
                    tally.add(&inn, i - run.range.start, run.seg, i, series);
                }
            }
        }
        Ok(())
    };
    // Rounds of a few groups per core and lane: memory O(round), the least
    // squares of a round overlapping the filtering of the next ones.
    let round = threads() * FILTER_LANES;
    // The least squares on a thread of its own, taking the rounds in order
    // from a channel of two: the filter runs at most two rounds ahead.
    let (to_ls, from_filter) = std::sync::mpsc::sync_channel::<(usize, Vec<FilteredGroup>)>(2);
    std::thread::scope(|scope| -> Result<()> {
        let ls = scope.spawn(|| -> Result<()> {
            for (first, done) in from_filter {
                absorb(first, done, series, &mut conditionals)?;
            }
            Ok(())
        });
        let filtered = (0..groups.len()).step_by(round).try_for_each(|start| {
            check(cancel)?;
            let end = (start + round).min(groups.len());
            let done = filter_groups(end - start, threads(), &model, |gi| {
                group_samples(p, &p.runs[groups[start + gi].clone()])
            })?;
            // A closed channel: the least squares failed (its error below).
            let _ = to_ls.send((start, done));
            Ok(())
        });
        drop(to_ls);
        let ls = ls
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        filtered.and(ls)
    })?;
    let delta = rls.state().as_slice();
    Ok(Pass1 {
        coef: p.coef_mean.iter().zip(delta).map(|(b, d)| b + d).collect(),
        posterior_covariance: rls.covariance(),
        factor: rls.factor().clone(),
        log_lik: tally.log_lik,
        innovations: Some(tally.sums),
        conditionals,
    })
}

/// Every `dec`-th sample of every run, for the likelihood: the lag filters
/// step through every sample, the design rows are formed at the kept ones
/// alone; the runs on all cores, joined in run order.
fn decimated_subset(
    segments: &[KalmanSegment],
    runs: &[Run],
    spec: &Design,
    dec: usize,
    z0: f64,
    y_ref: f64,
) -> Subset {
    let m = spec.n_columns();
    let parts = parallel_map(runs.len(), threads(), |r| {
        let run = &runs[r];
        let s = &segments[run.seg];
        let mut sub = Subset {
            m,
            ..Subset::default()
        };
        // The path since the kept sample before, summed step by step.
        let mut dist = 0.0;
        for i in run.range.clone() {
            if i > run.range.start {
                dist += step_length(s.data.time, s.speed_m_s, i);
            }
            if (i - run.range.start).is_multiple_of(dec) {
                sub.d.push(dist);
                dist = 0.0;
            }
        }
        for_every_nth_design_row(spec, &s.data, run.range.clone(), dec, |i, row| {
            sub.rows.extend_from_slice(row);
            sub.y.push(s.data.mag[i] - y_ref);
            sub.dz.push(s.alt_m[i] - z0);
            sub.start.push(i == run.range.start);
        });
        sub
    });
    let mut sub = Subset {
        m,
        ..Subset::default()
    };
    for p in parts {
        sub.rows.extend_from_slice(&p.rows);
        sub.y.extend_from_slice(&p.y);
        sub.dz.extend_from_slice(&p.dz);
        sub.d.extend_from_slice(&p.d);
        sub.start.extend_from_slice(&p.start);
    }
    sub
}

/// VIF, scaled condition number and plain-language warnings from the
/// information the *data* gave about the coefficients (with the field
/// marginalised), `J = P1⁻¹ − P0⁻¹` (`P1 = U_c U_cᵀ` posterior, `P0` prior),
/// through the least-squares diagnostics ([`diagnose`]): `J` is written as
/// `RᵀR` (eigenvalues clipped at 0) and accumulated as normal equations. The
/// prior is excluded so that a flight that determines nothing is reported
/// as such (its posterior merely equals the prior).
fn information_diagnostics(
    u: &DMatrix<f64>,
    prior_var: f64,
    names: &[String],
    max_vif: f64,
) -> Result<(Vec<f64>, f64, Vec<String>)> {
    let m = u.nrows();
    let a = u.clone().try_inverse().ok_or_else(|| CompError::Singular {
        reason: "the coefficient covariance is singular".into(),
    })?;
    let mut j = a.transpose() * &a;
    for i in 0..m {
        j[(i, i)] -= 1.0 / prior_var;
    }
    let eig = nalgebra::SymmetricEigen::new(j);
    let mut ne = NormalEquations::new(m);
    for k in 0..m {
        let lam = eig.eigenvalues[k].max(0.0).sqrt();
        let row: Vec<f64> = eig.eigenvectors.column(k).iter().map(|v| v * lam).collect();
        ne.add_row(&row, 0.0, 1.0)
            .map_err(CompError::estimation("information matrix"))?;
    }
    // The prior as ridge keeps the solve defined; VIF and condition are of the data part.
    let sol = ne
        .solve(1.0 / prior_var)
        .map_err(CompError::estimation("information matrix"))?;
    let warnings = diagnose(&sol, names, max_vif);
    Ok((sol.vif.iter().copied().collect(), sol.condition, warnings))
}

fn validate(cfg: &KalmanConfig) -> Result<()> {
    cfg.design.validate()?;
    if !(cfg.coef_prior_std > 0.0 && cfg.coef_prior_std.is_finite()) {
        return Err(CompError::setting(format!(
            "coefficient prior std {} must be positive",
            cfg.coef_prior_std
        )));
    }
    if let Some(z) = cfg.z0_m
        && !z.is_finite()
    {
        return Err(CompError::setting("reference altitude z0 must be finite"));
    }
    Ok(())
}

impl KalmanFit {
    /// The profile log-likelihood of the coefficients, for comparing models
    /// with different terms: [`KalmanFit::log_likelihood`] is the marginal
    /// likelihood under the coefficients' prior `N(0, P0)`, which penalises
    /// every added coefficient by its prior width (with the diffuse default,
    /// a model with more terms always loses). For a linear-Gaussian model
    /// `ℓ_marginal = ℓ_profile − ½ ln det(P0 P1⁻¹) + ½ X̂1ᵀ P0⁻¹ X̂1`; with a
    /// diffuse prior the last term vanishes, so
    /// `ℓ_profile ≈ ℓ_marginal + ½ (ln det P0 − ln det P1)`. Twice the
    /// difference of two nested models is the likelihood-ratio statistic
    /// (χ² with the number of added coefficients). NaN if a covariance is
    /// not positive definite.
    pub fn profile_log_likelihood(&self) -> f64 {
        let log_det = |m: &DMatrix<f64>| {
            m.clone()
                .cholesky()
                .map(|c| 2.0 * c.l().diagonal().iter().map(|v| v.ln()).sum::<f64>())
                .unwrap_or(f64::NAN)
        };
        self.log_likelihood
            + 0.5 * (log_det(&self.prior_covariance) - log_det(&self.posterior_covariance))
    }

    /// The fit in the shape of the band-pass least-squares result, so
    /// callers can report and store both the same way (VIF and condition are
    /// those of the posterior information; the residual is
    /// [`KalmanFit::residual_rms_nt`], or the innovation RMS without series).
    pub fn to_ls_fit(&self) -> LsFit {
        LsFit {
            names: self.names.clone(),
            coef: self.coef.clone(),
            std: self.std.clone(),
            vif: self.vif.clone(),
            condition: self.condition,
            residual_rms_nt: self.model_residual(),
            rows: self.rows,
            effective_dof: self.rows as f64,
            segments_used: self.segments_used,
            warnings: self.warnings.clone(),
            notes: self.notes.clone(),
        }
    }

    fn model_residual(&self) -> f64 {
        if self.residual_rms_nt.is_finite() {
            self.residual_rms_nt
        } else {
            self.innovation_rms_nt
        }
    }

    /// A model file (`"method": "kalman"` with the field-model order and the
    /// noise intensities). The caller fills [`TlModel::columns`] (and
    /// `reference` if it subtracted known channels).
    pub fn to_model(&self, cfg: &KalmanConfig) -> TlModel {
        TlModel {
            format: MODEL_FORMAT.into(),
            kind: crate::model_file::TL_KIND.into(),
            design: cfg.design.clone(),
            method: MethodSettings::Kalman(KalmanSettings {
                field_order: Some(self.field_order),
                noise: Some(self.noise),
            }),
            coefficients: Coefficient::list(&self.names, &self.coef, &self.std),
            fit: FitStats {
                rows: self.rows,
                segments: self.segments_used,
                condition: self.condition,
                residual_rms_nt: self.model_residual(),
                warnings: self.warnings.clone(),
                eddy_lag_selection: None,
                extra_lag_selection: Vec::new(),
                extra_channel_selection: None,
                sample_interval_s: None,
            },
            reference: Vec::new(),
            lever_arm: None,
            columns: Default::default(),
            software_version: env!("CARGO_PKG_VERSION").into(),
        }
    }
}
