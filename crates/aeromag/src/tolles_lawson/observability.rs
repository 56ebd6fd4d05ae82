//! What a calibration flight determines: observability and estimability of
//! the interference coefficients (thesis sections 10 and 12).

use super::calibrate::{CalibrateOptions, EddyLag, calibrate};
use super::kalman::KalmanOptions;
use crate::error::{Error, Result};
use crate::flight::{Flight, LeverArm, TlInputs};
use crate::observer::{Note, Observer};
use aeromag_compensation::observability::Observability;
use aeromag_compensation::tolles_lawson::fit_ls::LsConfig;
use aeromag_compensation::tolles_lawson::{Design, TermGroup, TermSet};
use serde::Serialize;

/// How well the flight determines one coefficient, from its effect
/// uncertainty `effect_std_nt` (and μ).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Verdict {
    /// Effect uncertainty below 0.01 nT.
    WellDetermined,
    /// 0.01–0.1 nT.
    Determined,
    /// 0.1–1 nT.
    WeaklyDetermined,
    /// 1 nT or more, or μ > 0.9: the flight leaves it near its prior.
    NotDetermined,
}

impl Verdict {
    /// The verdict for estimability `mu` and effect uncertainty `effect_nt`.
    pub fn of(mu: f64, effect_nt: f64) -> Self {
        if mu > 0.9 || effect_nt >= 1.0 {
            Verdict::NotDetermined
        } else if effect_nt >= 0.1 {
            Verdict::WeaklyDetermined
        } else if effect_nt >= 0.01 {
            Verdict::Determined
        } else {
            Verdict::WellDetermined
        }
    }

    /// The verdict in words, as the command prints it.
    pub fn words(self) -> &'static str {
        match self {
            Verdict::WellDetermined => "well determined",
            Verdict::Determined => "determined",
            Verdict::WeaklyDetermined => "weakly determined",
            Verdict::NotDetermined => "NOT determined by this flight",
        }
    }
}

/// One coefficient's estimability on a flight.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CoefficientVerdict {
    /// Coefficient name (`p_x`, `i_xy`, …).
    pub name: String,
    /// Estimability μ = √(P_post/P_prior): near 0 determined by the
    /// flight, near 1 not (for the prior σ = 1000 per coefficient).
    pub mu: f64,
    /// Posterior standard deviation, in the coefficient's unit.
    pub std: f64,
    /// Effect uncertainty, nT: the standard deviation times the size of
    /// the term's design column over a full calibration (1 for permanent
    /// terms, |B|/bt_scale for induced, |B|·(0.1 rad/s)/bt_scale for eddy
    /// terms: a 6°/s manoeuvre; for an extra regressor `<channel>:e_i`, the
    /// channel's RMS on the flight, A: a current that never changes is as
    /// large a column as one that does, but the flight cannot tell its terms
    /// from the permanent ones).
    pub effect_std_nt: f64,
    /// The verdict.
    pub verdict: Verdict,
}

/// What a calibration flight determines ([`observability`]).
#[derive(Debug, Clone)]
pub struct FlightObservability {
    /// Rank, condition number, eigenvalues, μ and the weak combinations.
    pub observability: Observability,
    /// Per coefficient: μ, standard deviation, effect uncertainty, verdict.
    pub coefficients: Vec<CoefficientVerdict>,
    /// Samples the filter used.
    pub rows: usize,
    /// Notes of the underlying Kalman fit.
    pub notes: Vec<Note>,
}

impl FlightObservability {
    /// Names of the coefficients this flight cannot determine.
    pub fn undetermined(&self) -> Vec<&str> {
        self.coefficients
            .iter()
            .filter(|c| c.verdict == Verdict::NotDetermined)
            .map(|c| c.name.as_str())
            .collect()
    }
}

/// Observability and estimability of the coefficients of `terms` on a
/// calibration flight (thesis sections 10 and 12). `terms` may hold extra
/// regressors ([`TermSet::with_extras`]; their channels are read from the
/// flight): the current terms of a cabin sensor, which a flight determines
/// only when each current changes at several headings.
///
/// Runs the Kalman filter of the Kalman method with its default noise
/// intensities, untuned, without lags (the external field is a random
/// process along the track, so it is marginalised, not filtered away), then
/// [`aeromag_compensation::observability::observability`] on the prior and
/// posterior covariances, and rates each term by its effect uncertainty in
/// nT ([`CoefficientVerdict`]). With a lever arm the sensor's altitude is
/// used. Use it to check a flight, or a simulated pattern before flying it.
pub fn observability(
    flight: &Flight,
    terms: &TermSet,
    lever_arm: Option<LeverArm>,
    observer: &mut dyn Observer,
) -> Result<FlightObservability> {
    if terms.groups().contains(&TermGroup::L9) {
        return Err(Error::bad_input(
            "the lagged eddy-current terms (l9) are not assessed here; give the terms without l9",
        ));
    }
    let opts = CalibrateOptions {
        ls: LsConfig {
            design: Design::new(terms.clone()),
            ..LsConfig::default()
        },
        kalman: KalmanOptions {
            tune: false,
            ..KalmanOptions::default()
        },
        eddy_lag: EddyLag::None,
        lever_arm,
        ..CalibrateOptions::kalman()
    };
    let cal = calibrate(flight, &opts, observer)?;
    let outcome = cal
        .kalman
        .ok_or_else(|| Error::bad_input("observability needs the Kalman method"))?;
    let fit = &outcome.fit;
    let o = aeromag_compensation::observability::observability(
        &fit.names,
        &fit.prior_covariance,
        &fit.posterior_covariance,
        1e6,
    )?;
    // Effect uncertainty of each term, nT: its standard deviation times the
    // size its column takes over a full set of headings and manoeuvres —
    // 1 for the permanent terms (e_i spans ±1), |B|/bt_scale for the induced
    // terms, and |B|·0.1 rad/s / bt_scale for the eddy terms (the body-frame
    // field rate of a 6°/s manoeuvre). The column's spread on *this* flight
    // would hide exactly what a poor flight fails to exercise.
    let cols = TlInputs::of(flight)?;
    let bt: Vec<f64> = (0..cols.time.len())
        .map(|i| {
            (cols.flux[0][i].powi(2) + cols.flux[1][i].powi(2) + cols.flux[2][i].powi(2)).sqrt()
        })
        .filter(|v| v.is_finite())
        .collect();
    let bt_mean = bt.iter().sum::<f64>() / bt.len().max(1) as f64;
    let bt_scale = outcome.config.design.bt_scale_nt;
    let coefficients = o
        .names
        .iter()
        .zip(&fit.std)
        .zip(&o.estimability)
        .map(|((name, &sd), &mu)| {
            let scale = match (name.split_once(':'), name.as_bytes().first()) {
                (Some((channel, _)), _) => channel_spread(flight, channel),
                (None, Some(b'p')) => 1.0,
                (None, Some(b'i')) => bt_mean / bt_scale,
                (None, Some(b'e')) => 0.1 * bt_mean / bt_scale,
                _ => 1.0,
            };
            let effect = sd * scale;
            CoefficientVerdict {
                name: name.clone(),
                mu,
                std: sd,
                effect_std_nt: effect,
                verdict: Verdict::of(mu, effect),
            }
        })
        .collect();
    Ok(FlightObservability {
        observability: o,
        coefficients,
        rows: fit.rows,
        notes: cal.notes,
    })
}

/// RMS of the flight's column `channel` over its finite values (1 when it
/// has none: the coefficient's own unit).
fn channel_spread(flight: &Flight, channel: &str) -> f64 {
    let Some(x) = flight.table().column(channel) else {
        return 1.0;
    };
    let (ss, n) = x
        .iter()
        .filter(|v| v.is_finite())
        .fold((0.0, 0usize), |(s, n), v| (s + v * v, n + 1));
    if n == 0 { 1.0 } else { (ss / n as f64).sqrt() }
}
