//! Choosing the eddy-current lags of a calibration: the band-pass
//! likelihood-ratio search (both methods) and the Kalman method's own test
//! of further lags.

use super::calibrate::EddyLag;
use crate::error::{Error, InFile, Result};
use crate::observer::Notes;
use aeromag_compensation::kalman::{
    CoefficientPass, KalmanConfig, KalmanFit, KalmanSegment, fit_kalman,
};
use aeromag_compensation::tolles_lawson::extra_select::{ChannelSelection, select_extra_channels};
use aeromag_compensation::tolles_lawson::fit_ls::{
    LsConfig, Segment, fit_exact_magnitude, linearised,
};
use aeromag_compensation::tolles_lawson::lag_select::{
    DEFAULT_ALPHA, DEFAULT_EXTRA_LAG_GRID_S, DEFAULT_EXTRA_SELECTION_ROWS, DEFAULT_LAG_GRID_S,
    DEFAULT_SELECTION_BLOCK, DEFAULT_SELECTION_ROWS, ExtraLagSelection, LagSelection,
    lag_threshold, select_eddy_lags, select_extra_lag, within_budget,
};
use aeromag_compensation::tolles_lawson::{Design, ExtraRequest, Magnitude, TermSet};
use aeromag_core::parallel::{parallel_map, threads};

/// Passes of the extra regressors' lag searches at most ([`choose_terms`]).
pub const MAX_EXTRA_LAG_PASSES: usize = 3;

/// The segments the term searches fit. The searches fit the first-order
/// model ([`choose_terms`], [`test_extra_channels`]); under the exact
/// magnitude the reading they see is corrected by the second-order
/// remainder `R = |B + ΔB| − |B| − eᵀΔB` (≈ |ΔB⊥|²/2|B|) of an
/// exact-magnitude fit of every candidate term (for the lag searches the
/// extras instantaneous and the eddy terms without lags; for the channel
/// test the terms with their chosen lags), and their direction cosines are
/// those of the modelled total field: one Gauss–Newton linearisation at
/// that fit. The
/// remainder is otherwise left in the searches' residual, where it hides
/// the terms under test. Measured (tools/validate, seed 23: a cabin
/// sensor with 215 nT of interference, 193 of it from currents): without
/// the correction the band-passed residual with every current was 3.56 nT
/// and the air conditioner's terms (15 nT on the survey) were dropped.
struct SearchSegments {
    /// Per segment: the total field (x, y, z, nT) and the corrected reading
    /// (nT); empty under the first-order magnitude.
    linearised: Vec<([Vec<f64>; 3], Vec<f64>)>,
}

impl SearchSegments {
    /// The linearisation of `segments` under `cfg` when `searching` (no
    /// search runs otherwise) and the magnitude is exact. `file` names the
    /// flight in errors.
    pub fn new(file: &str, segments: &[Segment], cfg: &LsConfig, searching: bool) -> Result<Self> {
        let linearised = match cfg.design.magnitude {
            Magnitude::Exact if searching => {
                let fit = fit_exact_magnitude(segments, cfg).in_file(file)?;
                let design = Design {
                    magnitude: Magnitude::FirstOrder,
                    ..cfg.design.clone()
                };
                segments
                    .iter()
                    .map(|s| linearised(&design, &fit.coef, s))
                    .collect()
            }
            _ => Vec::new(),
        };
        Ok(Self { linearised })
    }

    /// `segments` (those [`SearchSegments::new`] was given) as the searches
    /// see them.
    pub fn of<'a>(&'a self, segments: &[Segment<'a>]) -> Vec<Segment<'a>> {
        if self.linearised.is_empty() {
            return segments.to_vec();
        }
        segments
            .iter()
            .zip(&self.linearised)
            .map(|(s, (t, y))| Segment {
                mag: y,
                direction: Some([&t[0], &t[1], &t[2]]),
                ..*s
            })
            .collect()
    }
}

/// Whether [`choose_terms`] searches anything for `lag` and `requests`
/// (an `auto` eddy lag, or an extra regressor asked with `:lag`).
fn searches(lag: &EddyLag, requests: &[ExtraRequest]) -> bool {
    matches!(lag, EddyLag::Auto) || requests.iter().any(|r| r.lag)
}

/// The terms a calibration fits and how their lags were chosen.
#[derive(Debug, Clone)]
pub(super) struct TermChoice {
    /// The terms, with the chosen lags.
    pub terms: TermSet,
    /// The eddy-lag search, when `auto` ran it.
    pub eddy: Option<LagSelection>,
    /// The lag search of each extra regressor asked for with `:lag`.
    pub extras: Vec<ExtraLagSelection>,
}

/// The term set of `cfg` with the eddy-current lags of `lag` (`auto`:
/// chosen on `segments` by the band-pass LS likelihood-ratio search, on the
/// row budget), then the lag of each extra regressor that `requests` asks
/// to lag (`name:lag`; the same search, one lag at most, in the requests'
/// order), and the searches that ran. `cfg`'s terms hold the extra
/// regressors of `requests`, without lags. Used by both methods; `file`
/// names the flight in errors.
pub(super) fn choose_terms(
    file: &str,
    segments: &[Segment],
    cfg: &LsConfig,
    lag: &EddyLag,
    requests: &[ExtraRequest],
    notes: &mut Notes,
) -> Result<TermChoice> {
    // The searches fit the first-order model (an exact-magnitude fit is
    // Gauss–Newton steps of it; the terms it needs are the same), on the
    // reading corrected by the second-order remainder ([`SearchSegments`]).
    let search = SearchSegments::new(file, segments, cfg, searches(lag, requests))?;
    let segments = &search.of(segments);
    let cfg = &LsConfig {
        design: Design {
            magnitude: Magnitude::FirstOrder,
            ..cfg.design.clone()
        },
        ..cfg.clone()
    };
    let with = |taus: &[f64]| {
        cfg.design
            .terms
            .with_eddy_lags(taus)
            .map_err(|e| Error::bad_input(format!("eddy lags: {e}")))
    };
    let sample = |rows| within_budget(segments, rows, DEFAULT_SELECTION_BLOCK);
    let (mut terms, eddy) = match lag {
        EddyLag::None => (with(&[])?, None),
        EddyLag::Fixed(taus) => (with(taus)?, None),
        EddyLag::Auto if !cfg.design.terms.has_eddy() => (cfg.design.terms.clone(), None),
        EddyLag::Auto => {
            notes.stage("choosing eddy-current lags");
            notes.check_cancelled()?;
            let sel = select_eddy_lags(
                &sample(DEFAULT_SELECTION_ROWS),
                cfg,
                &DEFAULT_LAG_GRID_S,
                2,
                DEFAULT_ALPHA,
            )
            .in_file(file)?;
            if sel.taus_s.is_empty() {
                notes.note("eddy-current lags: no lag is significant; classical eddy terms kept");
            } else {
                // The search's rows, which on short legs are fewer than the
                // fit's: the residuals differed from the fit's without a word.
                notes.note(format!(
                    "eddy-current lags τ = {:?} s chosen (likelihood-ratio test): band-passed residual {:.4} → {:.4} nT RMS over the {} rows every candidate lag can use",
                    sel.taus_s, sel.base_residual_rms_nt, sel.residual_rms_nt, sel.rows
                ));
            }
            (with(&sel.taus_s)?, Some(sel))
        }
    };
    let extra_sample = sample(DEFAULT_EXTRA_SELECTION_ROWS);
    // Each lag is searched with the others in the model; a lag missing
    // while another is searched is mimicked by it (on a cabin sensor the
    // flap's lag came out at 1.02 s, truth 0.3 s, while the heater's 0.8 s
    // lag was not yet in), so the searches are repeated, the others at
    // their last values, until no lag changes.
    let mut extras: Vec<ExtraLagSelection> = Vec::new();
    for pass in 0..MAX_EXTRA_LAG_PASSES {
        let before: Vec<Option<f64>> = terms.extras().iter().map(|x| x.lag_s).collect();
        extras.clear();
        for (k, r) in requests.iter().enumerate().filter(|(_, r)| r.lag) {
            notes.stage(&format!(
                "choosing the lag of {} (pass {})",
                r.channel,
                pass + 1
            ));
            notes.check_cancelled()?;
            let c = LsConfig {
                design: cfg.design.with_terms(terms.clone()),
                ..cfg.clone()
            };
            let sel = select_extra_lag(
                &extra_sample,
                &c,
                k,
                &DEFAULT_EXTRA_LAG_GRID_S,
                DEFAULT_ALPHA,
            )
            .in_file(file)?;
            let mut x = terms.extras().to_vec();
            x[k].lag_s = sel.taus_s.first().copied();
            terms = terms.with_extras(&x).in_file(file)?;
            extras.push(ExtraLagSelection {
                channel: r.channel.clone(),
                selection: sel,
            });
        }
        let after: Vec<Option<f64>> = terms.extras().iter().map(|x| x.lag_s).collect();
        if after == before || extras.len() < 2 {
            break;
        }
    }
    for ExtraLagSelection {
        channel,
        selection: sel,
    } in &extras
    {
        match sel.taus_s.first() {
            None => notes.note(format!(
                "{channel}: no lag is significant; its instantaneous terms kept"
            )),
            Some(tau) => notes.note(format!(
                "{channel}: lag τ = {tau:.3} s chosen (likelihood-ratio test): band-passed residual {:.4} → {:.4} nT RMS",
                sel.base_residual_rms_nt, sel.residual_rms_nt
            )),
        }
    }
    Ok(TermChoice {
        terms,
        eddy,
        extras,
    })
}

/// Test the extra regressors of `terms` (their lags chosen) on `segments`
/// by backward elimination
/// ([`aeromag_compensation::tolles_lawson::extra_select`], first-order
/// fit, on the row budget of the lag searches), with a note for each
/// channel dropped and one for the outcome. `file` names the flight in
/// errors.
pub(super) fn test_extra_channels(
    file: &str,
    segments: &[Segment],
    ls: &LsConfig,
    terms: &TermSet,
    notes: &mut Notes,
) -> Result<ChannelSelection> {
    let search = SearchSegments::new(
        file,
        segments,
        &LsConfig {
            design: ls.design.with_terms(terms.clone()),
            ..ls.clone()
        },
        true,
    )?;
    let segments = &search.of(segments);
    let cfg = LsConfig {
        design: Design {
            magnitude: Magnitude::FirstOrder,
            ..ls.design.with_terms(terms.clone())
        },
        ..ls.clone()
    };
    let sample = within_budget(
        segments,
        DEFAULT_EXTRA_SELECTION_ROWS,
        DEFAULT_SELECTION_BLOCK,
    );
    let sel = select_extra_channels(&sample, &cfg, DEFAULT_ALPHA).in_file(file)?;
    for t in sel.tests.iter().filter(|t| !t.kept) {
        notes.note(format!(
            "{}: not significant for this sensor (likelihood ratio {:.1} < {:.1} for its {} columns): dropped",
            t.channel, t.lr_statistic, t.threshold, t.columns
        ));
    }
    if sel.kept.len() < sel.tests.len() {
        notes.note(format!(
            "extra regressors kept: {} of {} (band-passed residual {:.4} nT RMS with all, {:.4} with these)",
            sel.kept.len(),
            sel.tests.len(),
            sel.residual_all_nt,
            sel.residual_kept_nt
        ));
    }
    Ok(sel)
}

/// The Kalman method's own test of further lags, after the band-pass
/// choice on the field-removed data: while fewer than two lags are in the
/// model, try each remaining lag of [`DEFAULT_LAG_GRID_S`] and add the best
/// if the likelihood-ratio statistic of the profile likelihoods
/// ([`KalmanFit::profile_log_likelihood`]), with the noise intensities of
/// the first pass fixed, exceeds the threshold of the band-pass test
/// ([`lag_threshold`]: χ² for the added columns at [`DEFAULT_ALPHA`],
/// Bonferroni over the candidates). The band-pass test sees only the band
/// and its residual's spectral flatness; the Kalman innovations are
/// whitened by the field model, so a lag that the band-pass test left out
/// at the margin (over the quiet box of demo seed 2: τ = 0.15 s beside
/// 0.5 s, LR ≈ 38) is taken.
pub(super) fn add_lags_by_kalman_likelihood(
    file: &str,
    segments: &[KalmanSegment],
    cfg: &KalmanConfig,
    mut terms: TermSet,
    first: &KalmanFit,
    notes: &mut Notes,
) -> Result<TermSet> {
    if terms.eddy_lags_s().len() >= 2 {
        return Ok(terms);
    }
    // Untuned passes with the first pass's noise intensities.
    let mut fixed = KalmanConfig {
        noise: first.noise,
        compute_series: false,
        // Only the likelihood and the covariances are used.
        coefficient_pass: CoefficientPass::Augmented,
        ..cfg.clone()
    };
    fixed.tuning.enabled = false;
    let profile = |terms: &TermSet| -> Result<(f64, usize)> {
        let c = KalmanConfig {
            design: fixed.design.with_terms(terms.clone()),
            ..fixed.clone()
        };
        let f = fit_kalman(segments, &c).in_file(file)?;
        Ok((f.profile_log_likelihood(), f.coef.len()))
    };
    notes.stage("Kalman likelihood-ratio test of further lags");
    notes.check_cancelled()?;
    let (mut base, mut m) = profile(&terms)?;
    while terms.eddy_lags_s().len() < 2 {
        notes.check_cancelled()?;
        let lags = terms.eddy_lags_s().to_vec();
        let mut best: Option<(f64, usize, TermSet, f64)> = None;
        let candidates = DEFAULT_LAG_GRID_S
            .iter()
            .filter(|t| !lags.contains(t))
            .map(|&tau| {
                let mut with: Vec<f64> = lags.clone();
                with.push(tau);
                with.sort_by(f64::total_cmp);
                Ok((tau, terms.with_eddy_lags(&with).in_file(file)?))
            })
            .collect::<Result<Vec<(f64, TermSet)>>>()?;
        // Independent filter runs over the whole flight: shared out over
        // the cores, then taken in grid order as one at a time.
        let profiles = parallel_map(candidates.len(), threads(), |i| profile(&candidates[i].1));
        for ((tau, cand), p) in candidates.into_iter().zip(profiles) {
            let (ll, mc) = p?;
            if ll.is_finite() && best.as_ref().is_none_or(|b| ll > b.0) {
                best = Some((ll, mc, cand, tau));
            }
        }
        let Some((ll, mc, cand, tau)) = best else {
            break;
        };
        let tried = DEFAULT_LAG_GRID_S.len() - lags.len();
        let dof = mc - m;
        let threshold = lag_threshold(DEFAULT_ALPHA, tried, dof).in_file(file)?;
        let lr = 2.0 * (ll - base);
        if lr <= threshold {
            break;
        }
        notes.note(format!(
            "Kalman likelihood-ratio test adds the lag τ = {tau} s (LR {lr:.1} > {threshold:.1}, {dof} columns)"
        ));
        terms = cand;
        base = ll;
        m = mc;
    }
    Ok(terms)
}
