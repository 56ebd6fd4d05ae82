//! The joint regularised least-squares fit of the derivative coefficient `k`
//! and the per-line levels at the crossovers (re-adjustment, seed `000_…`
//! §9; spec `compensation.md`, "Survey altitude").
//!
//! ## Equations (units nT, s)
//!
//! Each crossover `x` of lines `a < b` gives one observation
//!
//! ```text
//! d_x = m_a − m_b = k (Ḃ_a − Ḃ_b) + (o_a − o_b) + (s_a τ_a − s_b τ_b) + ε_x
//! ```
//!
//! with `Ḃ` the along-track derivatives (nT/s), `k` in s, `o_L` the level
//! offset of line `L` (nT), and — only if `drift` is on — `s_L` the drift of
//! line `L` (nT at the ends of its crossover time span), `τ = (t − t_L)/h_L`,
//! `t_L` and `h_L` the middle and half-length of the times of the line's
//! crossovers (a line whose crossovers are all at one time has no drift
//! unknown). The unknowns minimise
//!
//! ```text
//! Σ_x ε_x²  +  λ Σ_L (o_L² + s_L²)  +  (Σ_L o_L)²            (datum: zero mean)
//! ```
//!
//! * The data only see differences of levels: adding one constant to every
//!   offset changes nothing. The datum removes that freedom: either the
//!   offsets have zero mean (`Datum::ZeroMean`, the penalty above, which is
//!   met exactly since no other term depends on the common mode), or one
//!   line — usually a tie — is held at zero level (`Datum::Fixed`: its
//!   offset and drift are not unknowns).
//! * The ridge `λ` (dimensionless: in units of one crossover's weight) is a
//!   prior of standard deviation `σ/√λ` on every offset and drift. It makes
//!   the problem solvable when parts of it are not determined by the data —
//!   groups of lines with no crossover between them (reported as
//!   `components` > 1), and with drifts the planar tilt of the whole block
//!   (a tilt along the ties is absorbed by the lines' drifts and vice versa:
//!   two exact null directions, which the ridge sets to the minimum-norm
//!   solution). It shrinks an offset determined by `n_L` crossovers by the
//!   factor `n_L/(n_L + λ)`: with the default `λ = 10⁻³` under 0.1 %.
//! * With `estimate_k = false` and no drift this is plain tie-line
//!   levelling (offsets only).
//!
//! **Altitude term** (`altitude_term`, on by default). The two passes of a
//! crossover are flown at different heights `h_a ≠ h_b`, so the field they
//! see differs by `∂B/∂h (h_a − h_b)`. With the profile operators `S_a`,
//! `S_b` of the two lines ([`super::vertical_gradient`]), `∂B/∂h ≈
//! −c (S_a + S_b)`, and the observation gains the term
//!
//! ```text
//! d_x = … + c · g_x,        g_x = −(S_a + S_b)(h_a − h_b)      (nT)
//! ```
//!
//! with one dimensionless scale `c` for the survey (≈ 0.78 for an isotropic
//! field crossed at right angles), estimated with the rest. Crossovers
//! without altitudes or profile operators get `g_x = 0`, and the term is
//! dropped when no crossover has one. It only explains crossover
//! differences: the levelled series is not moved to a common height, so
//! [`LevellingFit::rms_levelled_nt`] (the differences of the levelled
//! series) is reported beside the model residual.
//!
//! The normal equations are accumulated and solved with
//! [`aeromag_estimation::least_squares::NormalEquations`] (equilibrated,
//! eigen-decomposed; condition number reported). Cost `O(N_x p²) + O(p³)`
//! for `p` unknowns (dense rows; fine for a few hundred lines).
//!
//! **Robust weighting** (`robust`, on by default). A crossover can be
//! wrong by far more than the others: a GNSS height error of several
//! metres where the vertical gradient is strong, a spike, a pass in a turn.
//! The fit is iteratively reweighted with Huber weights
//! `w_x = min(1, K σ̂/|r_x|)`, `K` = [`HUBER_K`] = 2, `σ̂` the median
//! absolute residual × 1.4826 (scaled for the fitted unknowns), until the
//! weights settle; Gaussian crossovers keep weight 1, an outlier's pull
//! on `k` is bounded. On the demo survey of seed 5 one crossover (a 5.4 m
//! GNSS height error between the passes at a 9 nT/s gradient) had moved
//! `k` from ≈ −0.11 to −0.14 s; with the weights −0.110 ± 0.007 s.
//! [`LevellingFit::weights`] reports them.
//!
//! **Uncertainties.** With `C = (AᵀA + P)⁻¹` (`P` the ridge and datum
//! terms; `A` and `d` weighted by `√w_x`) the estimate is `c = C Aᵀ d`, so
//! `Cov(c) = σ̂² C AᵀA C`, with `σ̂² = Σ (w_x r_x)²/(N_x − p_eff)` from the
//! crossover residuals `r_x` (an outlier counts as `K σ̂`: Huber's
//! clipped residual) and
//! `p_eff` the unknowns minus one per group of connected lines left free by
//! the datum. This assumes independent crossover errors (it ignores the
//! tilt null directions of the drift model, so with drifts σ is slightly
//! optimistic), and errors of equal size. They are not of equal size: the
//! altitude term's errors (GNSS height errors, the profile estimate of the
//! gradient) grow with the gradient, and so does `|ΔḂ|`, so that
//! covariance is too small for `k`. The reported standard deviations are
//! therefore the larger of it and the heteroscedasticity-consistent
//! sandwich (MacKinnon & White's HC3)
//!
//! ```text
//! Cov_HC3(c) = C (Σ_x a_x a_xᵀ (w_x r_x)²/(1 − h_x)²) C,    h_x = w_x a_xᵀ C a_x
//! ```
//!
//! (`a_x` the design row, `h_x` its leverage). A crossover whose leverage
//! is within `10λ` of 1 — the only crossover of its line, whose residual
//! only measures the ridge — is left out of the sandwich; the classical
//! term covers its line. Over 25 simulated surveys the spread of `k` was
//! 1.4× the classical `σ` and 1.1× the sandwich's.

use super::crossovers::Crossover;
use super::tracks::bad;
use crate::error::{CompError, Result};
use aeromag_estimation::least_squares::NormalEquations;
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// How the common level of all lines is fixed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Datum {
    /// The offsets of all lines have zero mean.
    ZeroMean,
    /// The line with this label (usually a tie) keeps its level: offset and
    /// drift 0.
    Fixed(i64),
}

/// What to estimate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LevellingConfig {
    /// Estimate the derivative coefficient `k` (s). `false`: `k = 0`, plain
    /// tie-line levelling. Default `true`.
    pub estimate_k: bool,
    /// Estimate a linear drift per line as well as an offset. Default `false`.
    pub drift: bool,
    /// Ridge `λ ≥ 0` on offsets and drifts (module docs). Default `1e-3`.
    pub lambda: f64,
    /// The datum. Default [`Datum::ZeroMean`].
    pub datum: Datum,
    /// Explain the altitude differences of the crossovers with the
    /// vertical-gradient term (module docs). Default `true`.
    #[serde(default = "yes")]
    pub altitude_term: bool,
    /// Down-weight outlying crossovers (Huber weights, iteratively
    /// reweighted; module docs). Default `true`.
    #[serde(default = "yes")]
    pub robust: bool,
}

fn yes() -> bool {
    true
}

impl Default for LevellingConfig {
    fn default() -> Self {
        Self {
            estimate_k: true,
            drift: false,
            lambda: 1e-3,
            datum: Datum::ZeroMean,
            altitude_term: true,
            robust: true,
        }
    }
}

/// The level of one line.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LineLevel {
    /// Line label.
    pub label: i64,
    /// Number of crossovers on this line.
    pub crossovers: usize,
    /// Offset `o_L`, nT.
    pub offset_nt: f64,
    /// Standard deviation of the offset, nT (0 for the fixed line).
    pub offset_std_nt: f64,
    /// Drift `s_L`, nT at `t_ref_s ± half_span_s` (0 without a drift unknown).
    pub drift_nt: f64,
    /// Standard deviation of the drift, nT.
    pub drift_std_nt: f64,
    /// Middle of the line's crossover times, s.
    pub t_ref_s: f64,
    /// Half-length of the line's crossover time span, s (0: no drift unknown).
    pub half_span_s: f64,
    /// Whether this line is the fixed datum.
    pub fixed: bool,
}

impl LineLevel {
    /// The level `o_L + s_L (t − t_L)/h_L` at time `t` (s), nT.
    pub fn level_nt(&self, t: f64) -> f64 {
        if self.half_span_s > 0.0 {
            self.offset_nt + self.drift_nt * (t - self.t_ref_s) / self.half_span_s
        } else {
            self.offset_nt
        }
    }
}

/// The result of [`fit_levelling`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LevellingFit {
    /// The configuration used.
    pub config: LevellingConfig,
    /// Derivative coefficient `k`, s (0 if not estimated).
    pub k_s: f64,
    /// Its standard deviation, s (0 if not estimated).
    pub k_std_s: f64,
    /// One entry per line that has crossovers, by label.
    pub lines: Vec<LineLevel>,
    /// Residual `r_x = d_x − model` of each crossover (same order as the
    /// input), nT.
    pub residuals_nt: Vec<f64>,
    /// Weight of each crossover in the fit (1 without robust weighting; < 1
    /// for an outlier, module docs).
    pub weights: Vec<f64>,
    /// Crossovers with weight < 1.
    pub downweighted: usize,
    /// RMS of the crossover differences `d_x` before levelling, nT.
    pub rms_before_nt: f64,
    /// RMS of the residuals after levelling (the whole model, with the
    /// altitude term), nT.
    pub rms_after_nt: f64,
    /// RMS of the crossover differences of the levelled series,
    /// `d − k ΔḂ − Δlevel` (without the altitude term, which explains but
    /// does not remove the true field's difference between the heights), nT.
    pub rms_levelled_nt: f64,
    /// Whether the altitude term was fitted (on, and some crossover has it).
    pub altitude_term_used: bool,
    /// Scale `c` of the vertical gradient `∂B/∂h ≈ −c (S_a + S_b)`
    /// (dimensionless; 0 if the term was not fitted).
    pub vertical_scale: f64,
    /// Its standard deviation.
    pub vertical_scale_std: f64,
    /// Crossovers with altitudes and profile operators on both sides.
    pub altitude_corrected: usize,
    /// Estimated standard deviation of one crossover difference, `σ̂`, nT.
    pub sigma_nt: f64,
    /// Degrees of freedom `N_x − p_eff`.
    pub dof: usize,
    /// Condition number of the equilibrated normal matrix (with ridge and datum).
    pub condition: f64,
    /// Groups of lines connected by crossovers; > 1 means the relative level
    /// of the groups is set by the ridge, not by data.
    pub components: usize,
}

impl LevellingFit {
    /// The level of line `label`, if it has crossovers.
    pub fn line(&self, label: i64) -> Option<&LineLevel> {
        self.lines
            .binary_search_by_key(&label, |l| l.label)
            .ok()
            .map(|k| &self.lines[k])
    }
}

/// Fit `k`, offsets (and drifts) to the crossovers (module docs).
///
/// Errors: no crossovers, a non-finite crossover, a fixed datum label
/// without crossovers, fewer crossovers than effective unknowns, a singular
/// system (e.g. `λ = 0` with drifts).
pub fn fit_levelling(crossovers: &[Crossover], cfg: &LevellingConfig) -> Result<LevellingFit> {
    if crossovers.is_empty() {
        return Err(bad("no crossovers to level".into()));
    }
    if !(cfg.lambda.is_finite() && cfg.lambda >= 0.0) {
        return Err(bad(format!(
            "ridge λ = {} must be finite and ≥ 0",
            cfg.lambda
        )));
    }
    if let Some((k, _)) = crossovers.iter().enumerate().find(|(_, x)| {
        ![
            x.a.value_nt,
            x.b.value_nt,
            x.a.derivative_nt_per_s,
            x.b.derivative_nt_per_s,
            x.a.time_s,
            x.b.time_s,
        ]
        .iter()
        .all(|v| v.is_finite())
    }) {
        return Err(bad(format!(
            "crossover {k} has a non-finite value, derivative or time"
        )));
    }

    // Lines, their crossover time spans and the unknowns' layout.
    let mut spans: BTreeMap<i64, (f64, f64, usize)> = BTreeMap::new();
    for x in crossovers {
        for s in [&x.a, &x.b] {
            let e = spans
                .entry(s.label)
                .or_insert((f64::INFINITY, f64::NEG_INFINITY, 0));
            e.0 = e.0.min(s.time_s);
            e.1 = e.1.max(s.time_s);
            e.2 += 1;
        }
    }
    if let Datum::Fixed(l) = cfg.datum
        && !spans.contains_key(&l)
    {
        return Err(bad(format!("the fixed datum line {l} has no crossovers")));
    }
    // The altitude regressor g_x of each crossover (module docs).
    let altitude: Vec<f64> = crossovers.iter().map(altitude_regressor).collect();
    let altitude_corrected = altitude.iter().filter(|g| **g != 0.0).count();
    let alt_used = cfg.altitude_term && altitude_corrected > 0;
    let alt_index = usize::from(cfg.estimate_k);
    let first_level = alt_index + usize::from(alt_used);
    let mut lines: Vec<LineLevel> = Vec::with_capacity(spans.len());
    // (offset index, drift index) of each line in the unknown vector.
    let mut index: Vec<(Option<usize>, Option<usize>)> = Vec::with_capacity(spans.len());
    let mut p = first_level;
    for (&label, &(t0, t1, count)) in &spans {
        let fixed = cfg.datum == Datum::Fixed(label);
        let half = if cfg.drift && !fixed {
            0.5 * (t1 - t0)
        } else {
            0.0
        };
        let oi = (!fixed).then(|| {
            p += 1;
            p - 1
        });
        let si = (half > 0.0).then(|| {
            p += 1;
            p - 1
        });
        index.push((oi, si));
        lines.push(LineLevel {
            label,
            crossovers: count,
            offset_nt: 0.0,
            offset_std_nt: 0.0,
            drift_nt: 0.0,
            drift_std_nt: 0.0,
            t_ref_s: 0.5 * (t0 + t1),
            half_span_s: half,
            fixed,
        });
    }
    let labels: Vec<i64> = spans.keys().copied().collect();
    let pos = |label: i64| labels.binary_search(&label).unwrap_or(0);
    let components = count_components(crossovers, &labels);
    let free_modes = match cfg.datum {
        Datum::ZeroMean => components,
        Datum::Fixed(_) => components - 1,
    };
    let p_eff = p - free_modes;
    if crossovers.len() <= p_eff {
        // Only the parameters this fit has, and only the advice it can take
        // (`--tie-only` was told to drop k, which it does not fit).
        let mut fitted = vec!["offsets"];
        let mut fewer = Vec::new();
        if cfg.drift {
            fitted.push("drifts");
            fewer.push("no drift");
        }
        if cfg.estimate_k {
            fitted.insert(0, "k");
            fewer.push("no k");
        }
        if alt_used {
            fitted.push("altitude term");
            fewer.push("no altitude term");
        }
        let advice = if fewer.is_empty() {
            "fly more ties".to_string()
        } else {
            format!("fit fewer ({}) or fly more ties", fewer.join(", "))
        };
        return Err(bad(format!(
            "{} crossovers cannot determine {p_eff} parameters ({}) with a residual to spare: {advice}",
            crossovers.len(),
            fitted.join(", "),
        )));
    }

    // Design rows.
    let line_index: Vec<(usize, usize)> = crossovers
        .iter()
        .map(|x| (pos(x.a.label), pos(x.b.label)))
        .collect();
    let row_of = |x: &Crossover, &(ia, ib): &(usize, usize), g: f64, row: &mut [f64]| {
        row.fill(0.0);
        if cfg.estimate_k {
            row[0] = x.a.derivative_nt_per_s - x.b.derivative_nt_per_s;
        }
        if alt_used {
            row[alt_index] = g;
        }
        for (side, li, sign) in [(&x.a, ia, 1.0), (&x.b, ib, -1.0)] {
            let (oi, si) = index[li];
            if let Some(oi) = oi {
                row[oi] += sign;
            }
            if let Some(si) = si {
                row[si] += sign * (side.time_s - lines[li].t_ref_s) / lines[li].half_span_s;
            }
        }
    };
    let mut row = vec![0.0; p];
    // One weighted solve: (unpenalised normal equations, penalised ones,
    // solution, residuals).
    let mut solve = |weights: &[f64]| -> Result<_> {
        let mut data = NormalEquations::new(p);
        for (((x, li), &g), &w) in crossovers
            .iter()
            .zip(&line_index)
            .zip(&altitude)
            .zip(weights)
        {
            row_of(x, li, g, &mut row);
            data.add_row(&row, x.difference_nt(), w)
                .map_err(|e| bad(e.to_string()))?;
        }
        let mut all = data.clone();
        if cfg.lambda > 0.0 {
            for j in first_level..p {
                row.fill(0.0);
                row[j] = 1.0;
                all.add_row(&row, 0.0, cfg.lambda)
                    .map_err(|e| bad(e.to_string()))?;
            }
        }
        if cfg.datum == Datum::ZeroMean {
            row.fill(0.0);
            for (oi, _) in &index {
                if let Some(oi) = oi {
                    row[*oi] = 1.0;
                }
            }
            all.add_row(&row, 0.0, 1.0)
                .map_err(|e| bad(e.to_string()))?;
        }
        // Classified by the solve's own error: a singular system is a
        // failed fit (exit 1), not bad input (it was called bad input).
        let sol = all.solve(0.0).map_err(|e| {
            let hint = if cfg.lambda == 0.0 {
                " (use a ridge λ > 0)"
            } else {
                ""
            };
            CompError::estimation(format!("levelling{hint}"))(e)
        })?;
        let residuals: Vec<f64> = crossovers
            .iter()
            .zip(&line_index)
            .zip(&altitude)
            .map(|((x, li), &g)| {
                row_of(x, li, g, &mut row);
                x.difference_nt()
                    - row
                        .iter()
                        .zip(sol.coef.iter())
                        .map(|(a, b)| a * b)
                        .sum::<f64>()
            })
            .collect();
        Ok((data, all, sol, residuals))
    };
    // Iteratively reweighted: Huber weights from the residuals' MAD scale.
    let mut weights = vec![1.0; crossovers.len()];
    let (data, all, sol, residuals_nt) = {
        let mut it = 0;
        loop {
            let out = solve(&weights)?;
            if !cfg.robust || it == ROBUST_MAX_ITERATIONS {
                break out;
            }
            let next = huber_weights(&out.3, out.3.len().saturating_sub(p_eff));
            let change = next
                .iter()
                .zip(&weights)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            weights = next;
            it += 1;
            if change < 1e-4 {
                break solve(&weights)?;
            }
        }
    };
    let c = &sol.coef;
    let vertical_scale = if alt_used { c[alt_index] } else { 0.0 };
    let n = crossovers.len() as f64;
    let rms = |v: &mut dyn Iterator<Item = f64>| (v.map(|r| r * r).sum::<f64>() / n).sqrt();
    let rms_before_nt = rms(&mut crossovers.iter().map(|x| x.difference_nt()));
    let rms_after_nt = rms(&mut residuals_nt.iter().copied());
    let rms_levelled_nt = rms(&mut residuals_nt
        .iter()
        .zip(&altitude)
        .map(|(r, g)| r + vertical_scale * g));
    // σ̂ from the clipped residuals w·r, and Cov(c) = σ̂² C AᵀWA C (W the weights).
    let dof = crossovers.len() - p_eff;
    let sigma2 = residuals_nt
        .iter()
        .zip(&weights)
        .map(|(r, w)| (w * r).powi(2))
        .sum::<f64>()
        / dof as f64;
    let cinv = all
        .ata()
        .cholesky()
        .ok_or_else(|| bad("the levelling normal matrix is not positive definite".into()))?
        .inverse();
    let cov: DMatrix<f64> = &cinv * data.ata() * &cinv * sigma2;
    // The heteroscedasticity-consistent (HC3) sandwich C M C, M = Σ a aᵀ
    // (w r)²/(1 − h)², h = w aᵀ C a the leverage; each standard deviation
    // is the larger of the two.
    let mut meat = DMatrix::<f64>::zeros(p, p);
    for ((((x, li), &g), &r), &w) in crossovers
        .iter()
        .zip(&line_index)
        .zip(&altitude)
        .zip(&residuals_nt)
        .zip(&weights)
    {
        row_of(x, li, g, &mut row);
        let a = DVector::from_column_slice(&row);
        let h = (w * (a.transpose() * &cinv * &a)[(0, 0)]).min(1.0);
        if 1.0 - h > (10.0 * cfg.lambda).max(1e-9) {
            meat.ger(((w * r) / (1.0 - h)).powi(2), &a, &a, 1.0);
        }
    }
    let hc3: DMatrix<f64> = &cinv * meat * &cinv;
    let std = DVector::from_fn(p, |j, _| cov[(j, j)].max(hc3[(j, j)]).max(0.0).sqrt());

    for (line, &(oi, si)) in lines.iter_mut().zip(&index) {
        if let Some(oi) = oi {
            line.offset_nt = c[oi];
            line.offset_std_nt = std[oi];
        }
        if let Some(si) = si {
            line.drift_nt = c[si];
            line.drift_std_nt = std[si];
        }
    }
    let (k_s, k_std_s) = if cfg.estimate_k {
        (c[0], std[0])
    } else {
        (0.0, 0.0)
    };
    Ok(LevellingFit {
        config: cfg.clone(),
        k_s,
        k_std_s,
        lines,
        residuals_nt,
        downweighted: weights.iter().filter(|w| **w < 1.0).count(),
        weights,
        rms_before_nt,
        rms_after_nt,
        rms_levelled_nt,
        altitude_term_used: alt_used,
        vertical_scale,
        vertical_scale_std: if alt_used { std[alt_index] } else { 0.0 },
        altitude_corrected,
        sigma_nt: sigma2.sqrt(),
        dof,
        condition: sol.condition,
        components,
    })
}

/// Huber's tuning constant, in units of the robust scale `σ̂`.
pub const HUBER_K: f64 = 2.0;
/// At most this many reweighting iterations.
const ROBUST_MAX_ITERATIONS: usize = 30;

/// Huber weights `w = min(1, K σ̂ / |r|)` with `K` = [`HUBER_K`] and
/// `σ̂ = 1.4826 · median|r| · √(N/dof)` (the MAD scale of the residuals,
/// corrected for the fitted unknowns).
fn huber_weights(residuals: &[f64], dof: usize) -> Vec<f64> {
    let mut a: Vec<f64> = residuals.iter().map(|r| r.abs()).collect();
    a.sort_by(f64::total_cmp);
    let n = a.len();
    if n == 0 || dof == 0 {
        return vec![1.0; n];
    }
    let med = if n % 2 == 1 {
        a[n / 2]
    } else {
        0.5 * (a[n / 2 - 1] + a[n / 2])
    };
    let scale = 1.4826 * med * (n as f64 / dof as f64).sqrt();
    residuals
        .iter()
        .map(|r| {
            let lim = HUBER_K * scale;
            if r.abs() <= lim || scale == 0.0 {
                1.0
            } else {
                lim / r.abs()
            }
        })
        .collect()
}

/// The altitude regressor `g_x = −(S_a + S_b)(h_a − h_b)` (nT), 0 where a
/// side has no altitude or profile operator.
fn altitude_regressor(x: &Crossover) -> f64 {
    let g =
        -(x.a.profile_gradient_nt_per_m + x.b.profile_gradient_nt_per_m) * (x.a.alt_m - x.b.alt_m);
    if g.is_finite() { g } else { 0.0 }
}

/// Number of connected groups of lines (union–find over the crossovers).
fn count_components(crossovers: &[Crossover], labels: &[i64]) -> usize {
    let idx = |l: i64| labels.binary_search(&l).unwrap_or(0);
    let mut parent: Vec<usize> = (0..labels.len()).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for x in crossovers {
        let (ra, rb) = (
            root(&mut parent, idx(x.a.label)),
            root(&mut parent, idx(x.b.label)),
        );
        if ra != rb {
            parent[ra.max(rb)] = ra.min(rb);
        }
    }
    (0..labels.len())
        .filter(|&i| root(&mut parent, i) == i)
        .count()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::levelling::crossovers::CrossoverSide;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, Normal};

    /// Synthetic crossovers of `nl` lines (labels 1…) and `nt` ties (101…):
    /// levels `o_L + s_L τ`, derivative term `k Ḃ`, noise σ.
    pub(crate) fn synthetic(
        nl: usize,
        nt: usize,
        k: f64,
        offset: &dyn Fn(i64) -> f64,
        drift: &dyn Fn(i64, f64) -> f64,
        sigma: f64,
        seed: u64,
    ) -> Vec<Crossover> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let g = Normal::new(0.0, 1.0).unwrap();
        let mut out = Vec::new();
        let side = |label: i64, time_s: f64, field: f64, bdot: f64, noise: f64| CrossoverSide {
            label,
            row: 0,
            fraction: 0.0,
            time_s,
            value_nt: field + k * bdot + offset(label) + drift(label, time_s) + noise,
            derivative_nt_per_s: bdot,
            alt_m: f64::NAN,
            profile_gradient_nt_per_m: f64::NAN,
        };
        for l in 0..nl {
            for t in 0..nt {
                let field = 50_000.0 + 100.0 * g.sample(&mut rng);
                let (ba, bb) = (3.0 * g.sample(&mut rng), 3.0 * g.sample(&mut rng));
                let ta = 1000.0 * l as f64 + 100.0 * t as f64;
                let tb = 20_000.0 + 1000.0 * t as f64 + 50.0 * l as f64;
                let a = side(1 + l as i64, ta, field, ba, sigma * g.sample(&mut rng));
                let b = side(101 + t as i64, tb, field, bb, sigma * g.sample(&mut rng));
                out.push(Crossover {
                    a,
                    b,
                    north_m: 0.0,
                    east_m: 0.0,
                    angle_deg: 90.0,
                });
            }
        }
        out
    }

    fn zero_mean_offsets(label: i64) -> f64 {
        // Deterministic, mean ≠ 0 before the datum.
        ((label * 37) % 11) as f64 * 0.7 - 1.0
    }

    /// Crossovers flown at different heights over a field with vertical
    /// gradient `−c (S_a + S_b)`: the altitude term recovers `c` and keeps
    /// `k` sharp; without it the height differences inflate σ_k.
    #[test]
    fn altitude_term_explains_height_differences() {
        let mut x = synthetic(12, 4, -0.1, &zero_mean_offsets, &|_, _| 0.0, 0.02, 11);
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let g = Normal::new(0.0, 1.0).unwrap();
        let c_true = 0.8;
        for xo in &mut x {
            xo.a.alt_m = 100.0 + 6.0 * g.sample(&mut rng);
            xo.b.alt_m = 100.0 + 6.0 * g.sample(&mut rng);
            xo.a.profile_gradient_nt_per_m = 0.04 * g.sample(&mut rng);
            xo.b.profile_gradient_nt_per_m = 0.04 * g.sample(&mut rng);
            // Side a sees the field at its height relative to side b's.
            xo.a.value_nt += -c_true
                * (xo.a.profile_gradient_nt_per_m + xo.b.profile_gradient_nt_per_m)
                * (xo.a.alt_m - xo.b.alt_m);
        }
        let with = fit_levelling(&x, &LevellingConfig::default()).unwrap();
        assert!(with.altitude_term_used && with.altitude_corrected == x.len());
        assert!(
            (with.vertical_scale - c_true).abs() < 4.0 * with.vertical_scale_std
                && with.vertical_scale_std < 0.05,
            "c = {} ± {}",
            with.vertical_scale,
            with.vertical_scale_std
        );
        assert!(
            (with.k_s + 0.1).abs() < 4.0 * with.k_std_s,
            "k = {} ± {}",
            with.k_s,
            with.k_std_s
        );
        // The levelled series keeps the height differences; the model explains them.
        assert!(with.rms_levelled_nt > 3.0 * with.rms_after_nt);
        let without = fit_levelling(
            &x,
            &LevellingConfig {
                altitude_term: false,
                ..LevellingConfig::default()
            },
        )
        .unwrap();
        assert!(!without.altitude_term_used && without.vertical_scale == 0.0);
        assert!(without.rms_levelled_nt == without.rms_after_nt);
        assert!(
            without.k_std_s > 3.0 * with.k_std_s,
            "σ_k {} without vs {} with",
            without.k_std_s,
            with.k_std_s
        );
        // Sides without heights give no altitude regressor: the term drops out.
        for xo in &mut x {
            xo.a.alt_m = f64::NAN;
        }
        let none = fit_levelling(&x, &LevellingConfig::default()).unwrap();
        assert!(!none.altitude_term_used && none.altitude_corrected == 0);
    }

    #[test]
    fn recovers_k_and_offsets_up_to_the_datum() {
        let x = synthetic(12, 4, -0.1, &zero_mean_offsets, &|_, _| 0.0, 0.02, 7);
        let fit = fit_levelling(&x, &LevellingConfig::default()).unwrap();
        let z = (fit.k_s + 0.1) / fit.k_std_s;
        assert!(z.abs() < 4.0, "k = {} ± {}", fit.k_s, fit.k_std_s);
        assert!(fit.k_std_s < 0.002, "σ_k {}", fit.k_std_s);
        // Offsets equal the truth minus its mean, within their σ.
        let mean = fit
            .lines
            .iter()
            .map(|l| zero_mean_offsets(l.label))
            .sum::<f64>()
            / fit.lines.len() as f64;
        let sum: f64 = fit.lines.iter().map(|l| l.offset_nt).sum();
        assert!(sum.abs() < 1e-9, "datum: Σo = {sum}");
        for l in &fit.lines {
            let z = (l.offset_nt - (zero_mean_offsets(l.label) - mean)) / l.offset_std_nt;
            assert!(z.abs() < 4.5, "line {}: z = {z}", l.label);
        }
        assert!(
            (fit.sigma_nt / (0.02 * 2f64.sqrt()) - 1.0).abs() < 0.2,
            "σ̂ {}",
            fit.sigma_nt
        );
        assert!(fit.rms_after_nt < fit.rms_before_nt / 20.0);
        assert_eq!(fit.components, 1);
        assert_eq!(fit.dof, 48 - (1 + 16 - 1));
    }

    /// One mis-tie of 2 nT among 48 crossovers: robust weighting
    /// gives it a small weight and keeps k; plain least squares is pulled.
    #[test]
    fn robust_weighting_rejects_a_mis_tie() {
        let mut x = synthetic(12, 4, -0.1, &zero_mean_offsets, &|_, _| 0.0, 0.02, 7);
        // A steep gradient on one pass (ΔḂ += 10 nT/s, with its k term)
        // and a 2 nT mis-tie there (100 σ).
        x[17].a.derivative_nt_per_s += 10.0;
        x[17].a.value_nt += -0.1 * 10.0 + 2.0;
        let robust = fit_levelling(&x, &LevellingConfig::default()).unwrap();
        let plain = fit_levelling(
            &x,
            &LevellingConfig {
                robust: false,
                ..LevellingConfig::default()
            },
        )
        .unwrap();
        assert!(robust.weights[17] < 0.1, "{}", robust.weights[17]);
        assert_eq!(plain.downweighted, 0);
        assert!(plain.weights.iter().all(|w| *w == 1.0));
        let z = (robust.k_s + 0.1) / robust.k_std_s;
        assert!(
            z.abs() < 3.0,
            "robust k = {} ± {}",
            robust.k_s,
            robust.k_std_s
        );
        assert!(
            (plain.k_s + 0.1).abs() > 3.0 * (robust.k_s + 0.1).abs(),
            "plain {} robust {} ± {}",
            plain.k_s,
            robust.k_s,
            robust.k_std_s
        );
        // Gaussian crossovers keep (nearly) full weight.
        let clean = synthetic(12, 4, -0.1, &zero_mean_offsets, &|_, _| 0.0, 0.02, 7);
        let f = fit_levelling(&clean, &LevellingConfig::default()).unwrap();
        let low = f.weights.iter().filter(|w| **w < 0.8).count();
        assert!(low <= 1, "{:?}", f.weights);
    }

    #[test]
    fn k_std_is_calibrated() {
        // Over independent draws the z-scores of k have unit spread.
        let z: Vec<f64> = (0..40)
            .map(|s| {
                let x = synthetic(10, 3, 0.05, &zero_mean_offsets, &|_, _| 0.0, 0.05, 100 + s);
                let f = fit_levelling(&x, &LevellingConfig::default()).unwrap();
                (f.k_s - 0.05) / f.k_std_s
            })
            .collect();
        let rms = (z.iter().map(|v| v * v).sum::<f64>() / z.len() as f64).sqrt();
        assert!((0.7..1.35).contains(&rms), "RMS z = {rms}");
    }

    #[test]
    fn fixed_tie_datum_and_plain_levelling() {
        let x = synthetic(8, 3, 0.0, &zero_mean_offsets, &|_, _| 0.0, 0.0, 3);
        let cfg = LevellingConfig {
            estimate_k: false,
            datum: Datum::Fixed(102),
            lambda: 0.0,
            ..Default::default()
        };
        let fit = fit_levelling(&x, &cfg).unwrap();
        assert_eq!((fit.k_s, fit.k_std_s), (0.0, 0.0));
        let tie = fit.line(102).unwrap();
        assert!(tie.fixed && tie.offset_nt == 0.0);
        for l in &fit.lines {
            let truth = zero_mean_offsets(l.label) - zero_mean_offsets(102);
            assert!((l.offset_nt - truth).abs() < 1e-9, "line {}", l.label);
        }
        assert!(fit.rms_after_nt < 1e-9);
        assert!(fit.rms_before_nt > 0.5);
    }

    #[test]
    fn drift_per_line_removes_linear_drifts() {
        let drift = |label: i64, t: f64| 3e-3 * ((label % 5) as f64 - 2.0) * (t - 10_000.0);
        let x = synthetic(12, 4, -0.1, &zero_mean_offsets, &drift, 0.01, 11);
        let off = fit_levelling(&x, &LevellingConfig::default()).unwrap();
        let cfg = LevellingConfig {
            drift: true,
            ..Default::default()
        };
        let fit = fit_levelling(&x, &cfg).unwrap();
        // Offsets alone cannot absorb the drifts; with drifts the residual is
        // at the noise level (σ√2 per difference, less the fitted share).
        assert!(off.rms_after_nt > 0.1, "{}", off.rms_after_nt);
        assert!(fit.rms_after_nt < 0.02, "{}", fit.rms_after_nt);
        assert!(
            (fit.k_s + 0.1).abs() < 4.0 * fit.k_std_s,
            "k {} ± {}",
            fit.k_s,
            fit.k_std_s
        );
        assert!(fit.lines.iter().all(|l| l.half_span_s > 0.0));
        assert_eq!(fit.dof, 48 - (1 + 32 - 1));
    }

    #[test]
    fn disconnected_groups_are_reported_and_regularised() {
        let mut x = synthetic(4, 2, 0.0, &zero_mean_offsets, &|_, _| 0.0, 0.0, 5);
        let mut y = synthetic(3, 2, 0.0, &zero_mean_offsets, &|_, _| 0.0, 0.0, 6);
        for c in &mut y {
            c.a.label += 50;
            c.b.label += 50;
        }
        x.extend(y);
        let cfg = LevellingConfig {
            estimate_k: false,
            lambda: 1e-8,
            ..Default::default()
        };
        let fit = fit_levelling(&x, &cfg).unwrap();
        assert_eq!(fit.components, 2);
        assert!(fit.rms_after_nt < 1e-6, "{}", fit.rms_after_nt);
        // Each group is levelled exactly (differences of offsets within a group).
        for (p, q) in [(1, 102), (52, 151)] {
            let d = fit.line(p).unwrap().offset_nt - fit.line(q).unwrap().offset_nt;
            let shift = if p > 50 { 50 } else { 0 };
            let t = zero_mean_offsets(p - shift) - zero_mean_offsets(q - shift);
            assert!((d - t).abs() < 1e-6, "{p}-{q}: {d} vs {t}");
        }
        // Without the ridge the relative level of the two groups is undetermined.
        let e = fit_levelling(&x, &LevellingConfig { lambda: 0.0, ..cfg }).unwrap_err();
        assert!(e.to_string().contains("λ > 0"), "{e}");
    }

    /// A line with a single crossover: its residual is ≈ 0 and its leverage
    /// ≈ 1/(1 + λ), so the sandwich must leave it out — otherwise the
    /// line's offset would get a standard deviation of the size of the
    /// offset itself (5 nT here) instead of ≈ σ.
    #[test]
    fn a_line_with_one_crossover_gets_an_honest_offset_std() {
        let mut x = synthetic(6, 4, -0.1, &zero_mean_offsets, &|_, _| 0.0, 0.01, 11);
        let mut lone = x[0];
        lone.a.label = 77;
        lone.a.value_nt += 5.0;
        x.push(lone);
        let fit = fit_levelling(&x, &LevellingConfig::default()).unwrap();
        let l = fit.line(77).unwrap();
        assert_eq!(l.crossovers, 1);
        assert!(
            l.offset_std_nt < 0.1 && l.offset_std_nt > 0.3 * fit.sigma_nt,
            "offset {} ± {} nT, σ̂ {}",
            l.offset_nt,
            l.offset_std_nt,
            fit.sigma_nt
        );
    }

    #[test]
    fn bad_input_is_an_error() {
        assert!(fit_levelling(&[], &LevellingConfig::default()).is_err());
        let x = synthetic(3, 2, 0.0, &zero_mean_offsets, &|_, _| 0.0, 0.01, 1);
        let cfg = LevellingConfig {
            datum: Datum::Fixed(999),
            ..Default::default()
        };
        assert!(
            fit_levelling(&x, &cfg)
                .unwrap_err()
                .to_string()
                .contains("999")
        );
        assert!(
            fit_levelling(
                &x,
                &LevellingConfig {
                    lambda: -1.0,
                    ..Default::default()
                }
            )
            .is_err()
        );
        // 6 crossovers, 1 + 10 drifts/offsets − 1: underdetermined.
        let e = fit_levelling(
            &x,
            &LevellingConfig {
                drift: true,
                ..Default::default()
            },
        )
        .unwrap_err();
        assert!(e.to_string().contains("cannot determine"), "{e}");
        assert!(
            e.to_string().contains("(k, offsets, drifts)")
                && e.to_string().contains("fit fewer (no drift, no k)"),
            "{e}"
        );
        // Offsets alone (`--tie-only`): neither k nor drift to drop.
        let e = fit_levelling(
            &x[..2],
            &LevellingConfig {
                estimate_k: false,
                ..Default::default()
            },
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("(offsets)") && e.ends_with(": fly more ties"),
            "{e}"
        );
        // The same rate at both sides of every crossover (`--rate-of
        // time`): the lag's column is zero, the system singular — a failed
        // fit, not bad input (it exited 2).
        let mut flat = x.clone();
        for c in &mut flat {
            c.a.derivative_nt_per_s = 1.0;
            c.b.derivative_nt_per_s = 1.0;
        }
        let e = fit_levelling(&flat, &LevellingConfig::default()).unwrap_err();
        assert!(
            !e.is_bad_input() && e.to_string().contains("singular"),
            "{e}"
        );
        let mut y = x.clone();
        y[2].b.derivative_nt_per_s = f64::NAN;
        assert!(
            fit_levelling(&y, &LevellingConfig::default())
                .unwrap_err()
                .to_string()
                .contains("crossover 2")
        );
    }
}
