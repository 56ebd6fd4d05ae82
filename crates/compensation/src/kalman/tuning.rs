//! Automatic tuning of the noise intensities `q₁, q₂, r` by maximum
//! likelihood of the innovations.
//!
//! The pass-1 filter ([`super::joint_filter`]) gives the exact Gaussian
//! log-likelihood of the readings as the sum of the innovation terms
//! `−½(ln 2πσ_k² + ν_k²/σ_k²)` ([`aeromag_estimation::kalman::Innovation`]).
//! It is maximised over `θ = (ln q₁, ln q₂, ln r)` (or the subset selected in
//! [`TuningConfig`]) with the derivative-free Nelder–Mead method
//! ([`aeromag_estimation::optimize::nelder_mead()`]), starting from the
//! configured intensities with steps of one decade, within ±8 decades of the
//! start (±6 for `r`).
//!
//! **Default.** [`TuningConfig::default`] leaves tuning off (library callers
//! choose); `aeromag calibrate --method kalman` and the demo tune, because
//! with the lagged eddy-current terms ([`crate::tolles_lawson::TermSet`]
//! group `l9`) in the model the unexplained part is no longer dominated by
//! coloured manoeuvre signal, and the maximum-likelihood intensities follow
//! the field of the calibration area (with field order 4, q₁ ≈ 5·10⁻¹⁹
//! nT²/m⁷ over realistic geology at 1000 m and ≈ 2·10⁻¹⁶ at 300 m, against
//! the untuned default 3.9·10⁻²⁰, and 2–8·10⁻²³ over the quiet box).
//! Interference-model error on the independent demo survey (`true_interf`
//! − model, per line, mean removed), seeds 1–5, with tuning and the lag
//! choice of the CLI (×10⁻³ nT, band-pass LS / Kalman with the default
//! field order 6 / Kalman with order 4; calibrations `aeromag simulate
//! calibration` with `[pattern] altitude_m` and `[anomaly] area =
//! "realistic"`, survey of `aeromag demo --seed N`):
//!
//! | area, altitude | seed 1 | seed 2 | seed 3 | seed 4 | seed 5 |
//! |---|---|---|---|---|---|
//! | quiet box, 3 km | 1.6 / 1.8 / 1.9 | 2.8 / 2.7 / 3.1 | 1.9 / 1.8 / 2.3 | 2.2 / 1.9 / 2.2 | 2.5 / 2.4 / 2.5 |
//! | geology, 1000 m | 4.3 / 2.3 / 2.3 | 13.5 / 3.4 / 3.1 | 5.0 / 2.7 / 2.7 | 5.6 / 3.3 / 3.3 | 3.5 / 3.2 / 3.3 |
//! | geology, 600 m | 13.4 / 4.2 / 5.6 | 17.8 / 3.1 / 3.6 | 8.7 / 2.1 / 3.6 | 13.7 / 2.7 / 3.1 | 14.9 / 6.5 / 6.4 |
//! | geology, 300 m | 18.0 / 4.6 / 5.8 | 17.8 / 7.2 / 10.9 | 16.4 / 9.2 / 12.5 | 15.3 / 9.0 / 9.0 | 26.3 / 8.3 / 9.7 |
//!
//! Over geology the Kalman method (order 6) is below LS in all 15 cases and
//! at most half of it in 9 (all five at 600 m, three at 300 m); in the
//! quiet box it is below LS on four seeds and 0.2·10⁻³ nT above on seed 1.
//! On the full survey residual (`mag_comp − true_external − true_lag`,
//! which holds the 0.011 nT noise floor) the ratio Kalman/LS is 1.00 in the
//! quiet box, 0.65–0.98 at 1000 m, 0.54–0.79 at 600 m and 0.48–0.75 at
//! 300 m. Seed 2's figures include the lag τ = 0.1 s that the Kalman
//! likelihood-ratio test adds to the band-pass choice (CLI
//! `add_lags_by_kalman_likelihood`). With the fixed defaults (order 3) the
//! Kalman method was 2–5× worse than the tuned figures at 300–600 m.
//!
//! **Why tuning used to be off.** The likelihood treats everything the
//! Tolles-Lawson model does not explain as either field or white noise, and
//! on the simulator that part is coloured: eddy currents are lags, not
//! `M dB/dt`; the fluxgate sees the aircraft's own field; the simulated
//! diurnal variation has an `f⁻³` spectrum with 0.1 nT RMS in 0.1–0.9 Hz. The
//! likelihood is then largest for a model flexible enough to follow it, and
//! a flexible field model absorbs the manoeuvre signal. Survey interference
//! error after calibrating on the default calibration scenario (thesis order
//! 3, before the lagged eddy terms; seed 7;
//! band-pass LS 0.0237 nT): fixed defaults 0.0210 nT; tuning `q₂, r`
//! 0.0313 nT (ML drove `q₂` to 5·10⁻⁸ and `r` to 3·10⁻³); tuning all three
//! 0.0437 nT (`q₁ → 3·10⁻¹⁰`, a field free up to ~1 Hz); tuning `r` alone
//! 0.0285 nT (`r → 0.03 nT²`). With the base-station diurnal subtracted
//! (LS 0.0171 nT): fixed 0.0156, `r` alone 0.0156, `q₂, r` 0.0165, all three
//! 0.0187 nT. So the defaults
//! ([`NoiseModel::calibration_default`], derived from the field statistics
//! in [`super::anomaly_model`]) are used unless tuning is asked for; when
//! the model fits the data (test `maximum_likelihood_recovers_the_noise_intensities`)
//! the tuning recovers the true intensities.
//!
//! For speed the likelihood is evaluated on a *decimated* copy of the flight:
//! every `D`-th sample (`D = ⌈N / max_rows⌉`), design rows taken from the
//! full-rate data, the path length summed over the skipped samples. The field
//! model is continuous in the path length, so the decimated record is an
//! exact sub-sampling of the same model; `r` stays a per-sample variance
//! (the noise is white). The values found are reported and used for the
//! full-rate passes.

use super::anomaly_model::{NoiseModel, X2Prior};
use super::joint_filter::JointFilter;
use crate::error::{CompError, Result};
use aeromag_estimation::optimize::{NelderMeadOptions, nelder_mead};
use serde::{Deserialize, Serialize};

/// Settings of the maximum-likelihood tuning.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TuningConfig {
    /// Whether to tune (default false: see the module docs).
    pub enabled: bool,
    /// Tune `q₁` (default true when tuning).
    pub tune_q1: bool,
    /// Tune `q₂` (default true).
    pub tune_q2: bool,
    /// Tune `r` (default true).
    pub tune_r: bool,
    /// Largest number of samples the likelihood is evaluated on (the flight
    /// is decimated to at most this many; default 20 000).
    pub max_rows: usize,
    /// Evaluation budget of Nelder–Mead (default 200).
    pub max_evaluations: usize,
}

impl Default for TuningConfig {
    fn default() -> Self {
        Self {
            enabled: false,
            tune_q1: true,
            tune_q2: true,
            tune_r: true,
            max_rows: 20_000,
            max_evaluations: 200,
        }
    }
}

/// What the tuning did.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TuningReport {
    /// The starting intensities.
    pub initial: NoiseModel,
    /// The maximum-likelihood intensities (used for the fit).
    pub tuned: NoiseModel,
    /// Log-likelihood of the decimated record at the start.
    pub log_likelihood_initial: f64,
    /// Log-likelihood at the optimum.
    pub log_likelihood: f64,
    /// Function evaluations (filter runs).
    pub evaluations: usize,
    /// Whether Nelder–Mead met its tolerances (0.01 in log-likelihood, 0.02
    /// in each `ln` parameter).
    pub converged: bool,
    /// Decimation factor `D`.
    pub decimation: usize,
    /// Samples in the decimated record.
    pub rows: usize,
}

/// A decimated copy of the flight: design rows, centred readings, altitude
/// offsets, path length since the previous kept sample, run starts.
#[derive(Debug, Clone, Default)]
pub struct Subset {
    /// Coefficients per row.
    pub m: usize,
    /// Row-major design rows.
    pub rows: Vec<f64>,
    /// Centred readings `mag − y_ref`, nT.
    pub y: Vec<f64>,
    /// `alt − z0`, m.
    pub dz: Vec<f64>,
    /// Path length from the previous kept sample of the same run, m.
    pub d: Vec<f64>,
    /// Whether the sample starts a run.
    pub start: Vec<bool>,
}

impl Subset {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.y.len()
    }

    /// Whether the subset is empty.
    pub fn is_empty(&self) -> bool {
        self.y.is_empty()
    }

    /// Log-likelihood of the subset under `noise` (pass-1 filter).
    pub fn log_likelihood(
        &self,
        coef_mean: &[f64],
        coef_std: &[f64],
        x2_prior: &X2Prior,
        noise: NoiseModel,
    ) -> Result<f64> {
        let mut f = JointFilter::new(coef_mean, coef_std, x2_prior, noise)?;
        let mut ll = 0.0;
        for k in 0..self.len() {
            if self.start[k] {
                f.start_run()?;
            }
            ll += f
                .step(
                    self.d[k],
                    &self.rows[k * self.m..(k + 1) * self.m],
                    self.dz[k],
                    self.y[k],
                )?
                .log_likelihood();
        }
        Ok(ll)
    }
}

/// Maximise the likelihood of `subset` over the selected `ln q₁, ln q₂,
/// ln r` from `start` (the others stay at their start values).
pub fn tune(
    subset: &Subset,
    coef_mean: &[f64],
    coef_std: &[f64],
    x2_prior: &X2Prior,
    start: NoiseModel,
    cfg: &TuningConfig,
    decimation: usize,
) -> Result<TuningReport> {
    if subset.len() < 10 {
        return Err(CompError::BadData(format!(
            "{} samples are too few to tune the noise intensities",
            subset.len()
        )));
    }
    let floor = 1e-80; // q₁ of order 6 is ≈ 1e-36 nT²/m¹¹
    let all = [
        start.q1.max(floor).ln(),
        start.q2_nt2_per_m5.max(floor).ln(),
        start.r_nt2.ln(),
    ];
    let free: Vec<usize> = [cfg.tune_q1, cfg.tune_q2, cfg.tune_r]
        .iter()
        .enumerate()
        .filter(|(_, t)| **t)
        .map(|(i, _)| i)
        .collect();
    let dec = std::f64::consts::LN_10;
    let span = [8.0 * dec, 8.0 * dec, 6.0 * dec];
    let to_noise = |t: &[f64]| {
        let mut v = [start.q1, start.q2_nt2_per_m5, start.r_nt2];
        for (j, &i) in free.iter().enumerate() {
            v[i] = t[j].exp();
        }
        NoiseModel {
            q1: v[0],
            q2_nt2_per_m5: v[1],
            r_nt2: v[2],
        }
    };
    let ll0 = subset.log_likelihood(coef_mean, coef_std, x2_prior, start)?;
    let report = |tuned, ll, evaluations, converged| TuningReport {
        initial: start,
        tuned,
        log_likelihood_initial: ll0,
        log_likelihood: ll,
        evaluations,
        converged,
        decimation,
        rows: subset.len(),
    };
    if free.is_empty() {
        return Ok(report(start, ll0, 1, true));
    }
    let theta0: Vec<f64> = free.iter().map(|&i| all[i]).collect();
    let objective = |t: &[f64]| {
        if free
            .iter()
            .enumerate()
            .any(|(j, &i)| (t[j] - all[i]).abs() > span[i])
        {
            return f64::INFINITY;
        }
        match subset.log_likelihood(coef_mean, coef_std, x2_prior, to_noise(t)) {
            Ok(ll) => -ll,
            Err(_) => f64::INFINITY,
        }
    };
    let opts = NelderMeadOptions {
        initial_step: vec![dec; free.len()],
        f_tol: 1e-2,
        x_tol: 0.02,
        max_evaluations: cfg.max_evaluations,
    };
    let res = nelder_mead(objective, &theta0, &opts)
        .map_err(|e| CompError::BadData(format!("noise tuning: {e}")))?;
    Ok(if -res.f >= ll0 {
        report(to_noise(&res.x), -res.f, res.evaluations + 1, res.converged)
    } else {
        report(start, ll0, res.evaluations + 1, res.converged)
    })
}
