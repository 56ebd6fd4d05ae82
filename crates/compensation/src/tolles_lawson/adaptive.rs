//! Adaptive online compensation: the coefficients are updated sample by
//! sample while the stream is compensated (issue 21, "adaptive mode").
//!
//! Each sample is compensated with the coefficients *before* it is used
//! (latency 0, the compensated value never contains its own update), then
//! the coefficients are updated with it by a [`CoefficientEstimator`]: the
//! thesis' Kalman filter with the field states ([`crate::kalman::online`])
//! or recursive least squares with forgetting ([`super::rls`]).
//!
//! ## The measurement
//!
//! The rows are those of the fixed-model path ([`OnlineRows`], the causal
//! convention). Under the first-order magnitude the measurement is linear,
//! `y = mag = h_k · c + B_ext + v`, `h_k` the row along the field. Under the
//! exact magnitude, `mag = |B + ΔB(c)| − |B| + bias + B_ext + v` is
//! linearised at the current estimate `ĉ` (an extended Kalman step, one
//! Gauss–Newton linearisation per sample):
//!
//! ```text
//! J_k = ∂h/∂c |ĉ = the row along t̂ = (B + ΔB(ĉ)) / |B + ΔB(ĉ)|   (bias column 1)
//! y_k = mag − h(ĉ) + J_k ĉ = J_k c + B_ext + v
//! ```
//!
//! Along with the row go the time step (s), the along-track step (m, from
//! the ground speed) and the altitude, which the Kalman filter's field
//! model needs ([`AdaptiveStep`]).
//!
//! Memory: the rows' state and the estimator's `O(m²)`, whatever the
//! stream's length.

use super::design::TotalField;
use super::online::{AXES, OnlineOutput, OnlineRows, OnlineSample, SampleStatus, dot};
use super::{Design, Magnitude};
use crate::error::{CompError, Result};
use aeromag_core::field::{MAX_ALT_M, MAX_GROUND_SPEED_M_S};

/// What an estimator gets for one sample.
#[derive(Debug, Clone, Copy)]
pub struct AdaptiveStep<'a> {
    /// The row (the Jacobian under the exact magnitude), column order.
    pub row: &'a [f64],
    /// The (linearised) reading `y = row · c + B_ext + v`, nT.
    pub y_nt: f64,
    /// Time since the run's previous sample, s (0 at a run's first sample).
    pub dt_s: f64,
    /// Path length since the run's previous sample, m (0 at a run's first;
    /// NaN when the speed is unknown and the estimator does not need it).
    pub along_track_m: f64,
    /// Altitude, m (NaN when unknown).
    pub alt_m: f64,
}

/// The normalised innovation squared `ν²/σ²` beyond which a sample is an
/// outlier that an estimator does not learn from (it is still
/// compensated): 100 standard deviations, far beyond any innovation of a
/// valid sample (the simulated flights' largest are below 10 σ). Found by
/// fuzzing: one `mag` of 900 000 nT (below [`MAX_FIELD_NT`]) or 0 made the
/// Kalman filter's `mag_comp` −555 000 nT on the next samples and moved a
/// coefficient from −22 to 48 290, all flagged compensated; RLS was 500–1400
/// nT off afterwards.
///
/// [`MAX_FIELD_NT`]: aeromag_core::field::MAX_FIELD_NT
pub const OUTLIER_NIS: f64 = 1e4;

/// What an estimator did with a sample ([`CoefficientEstimator::update`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Update {
    /// The sample updated the estimate.
    Learnt,
    /// Its innovation was beyond [`OUTLIER_NIS`]: the estimate is unchanged
    /// (the Kalman filter's prediction to the sample's time is kept).
    Outlier,
}

/// An estimator of the coefficients, updated one sample at a time.
pub trait CoefficientEstimator: std::fmt::Debug + Send + Sync {
    /// The current estimate, column order.
    fn coefficients(&self) -> &[f64];
    /// Their standard deviations, column order.
    fn coefficient_std(&self) -> Vec<f64>;
    /// A new run starts with the next sample (after a gap or an unusable
    /// sample): the field may have jumped.
    fn start_run(&mut self) -> Result<()>;
    /// Update with one sample, unless its innovation is beyond
    /// [`OUTLIER_NIS`]. On error the estimate is unchanged.
    fn update(&mut self, step: &AdaptiveStep) -> Result<Update>;
    /// The mean normalised innovation squared `ν²/σ²` over the updates so
    /// far, when the estimator predicts its innovations' variance (≈ 1
    /// when its model fits the data; ≫ 1: the field or the reading varies
    /// more than the model allows, and the adaptation is not to be trusted).
    fn mean_nis(&self) -> Option<f64> {
        None
    }
    /// Whether the estimator needs the ground speed (the Kalman filter's
    /// field model runs along the track): without it a sample is not
    /// learnt from.
    fn needs_speed(&self) -> bool {
        false
    }
    /// A copy behind a box (the estimators are `Clone`).
    fn boxed_clone(&self) -> Box<dyn CoefficientEstimator>;
}

impl Clone for Box<dyn CoefficientEstimator> {
    fn clone(&self) -> Self {
        self.boxed_clone()
    }
}

/// The navigation of one sample, for the field model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Navigation {
    /// Ground speed, m/s.
    pub speed_m_s: f64,
    /// Altitude, m (NaN when unknown: the vertical gradient is not used).
    pub alt_m: f64,
}

/// A Tolles-Lawson model whose coefficients adapt as samples arrive
/// ([module docs](self)).
#[derive(Debug, Clone)]
pub struct AdaptiveTl {
    rows: OnlineRows,
    estimator: Box<dyn CoefficientEstimator>,
    /// The a-priori coefficients (bias zeroed under the exact magnitude).
    coef: Vec<f64>,
    bias_column: Option<usize>,
    row: Vec<f64>,
    /// Whether the estimator has not yet been told of the current run.
    pending_start: bool,
    /// The time of the last sample learnt from in this run, s.
    last_learnt_s: f64,
    failed_updates: u64,
    outliers: u64,
}

impl AdaptiveTl {
    /// The rows of `design` (runs broken at steps over `max_step_s`, s),
    /// the coefficients estimated by `estimator` (seeded with the model's).
    pub fn new(
        design: &Design,
        max_step_s: f64,
        estimator: Box<dyn CoefficientEstimator>,
    ) -> Result<Self> {
        let rows = OnlineRows::new(design, max_step_s)?;
        let n = design.n_columns();
        if estimator.coefficients().len() != n {
            return Err(CompError::setting(format!(
                "{} coefficients for a design of {n} columns",
                estimator.coefficients().len()
            )));
        }
        Ok(Self {
            bias_column: match design.magnitude {
                Magnitude::Exact => design.terms.bias_column(),
                Magnitude::FirstOrder => None,
            },
            rows,
            estimator,
            coef: vec![0.0; n],
            row: vec![0.0; n],
            pending_start: true,
            last_learnt_s: f64::NAN,
            failed_updates: 0,
            outliers: 0,
        })
    }

    /// The design the rows are built with (causal).
    pub fn design(&self) -> &Design {
        self.rows.design()
    }

    /// Number of extra channels a sample must carry.
    pub fn n_channels(&self) -> usize {
        self.rows.n_channels()
    }

    /// The current coefficients, column order.
    pub fn coefficients(&self) -> &[f64] {
        self.estimator.coefficients()
    }

    /// Their standard deviations, column order.
    pub fn coefficient_std(&self) -> Vec<f64> {
        self.estimator.coefficient_std()
    }

    /// [`CoefficientEstimator::mean_nis`] of the estimator.
    pub fn mean_nis(&self) -> Option<f64> {
        self.estimator.mean_nis()
    }

    /// Updates the estimator refused (numerically): the sample was
    /// compensated, the coefficients kept.
    pub fn failed_updates(&self) -> u64 {
        self.failed_updates
    }

    /// Samples not learnt from as outliers ([`OUTLIER_NIS`]): compensated
    /// with the coefficients they found.
    pub fn outliers(&self) -> u64 {
        self.outliers
    }

    /// Compensate one sample with the current coefficients, then update
    /// them with it ([module docs](self)). Never fails: a sample that cannot
    /// be compensated says why in its status, and a sample without a usable
    /// ground speed is compensated but not learnt from by an estimator that
    /// needs it ([`CoefficientEstimator::needs_speed`]).
    pub fn push(&mut self, s: &OnlineSample, nav: Navigation) -> OnlineOutput {
        let status = self.rows.advance(s);
        if !status.is_compensated() {
            return OnlineOutput::not(status);
        }
        self.coef.copy_from_slice(self.estimator.coefficients());
        let b = self.rows.field_nt();
        let (interference_nt, y_nt) = match self.rows.design().magnitude {
            Magnitude::FirstOrder => {
                self.rows.row_along(b, &mut self.row);
                let h = dot(&self.row, &self.coef);
                (h, s.mag_nt)
            }
            Magnitude::Exact => {
                let bias = self
                    .bias_column
                    .map_or(0.0, |k| std::mem::replace(&mut self.coef[k], 0.0));
                let d = AXES.map(|axis| {
                    self.rows.row_along(axis, &mut self.row);
                    dot(&self.row, &self.coef)
                });
                let total = TotalField::of(b, d);
                let h = total.change() + bias;
                if let Some(k) = self.bias_column {
                    self.coef[k] = bias;
                }
                self.rows.row_along(total.t, &mut self.row);
                (h, s.mag_nt - h + dot(&self.row, &self.coef))
            }
        };
        if status == SampleStatus::Started {
            self.pending_start = true;
        }
        // A speed or an altitude beyond any aircraft's is a corrupted value
        // (a speed of 1e308 made the coefficients NaN): unknown.
        let speed_known = (0.0..=MAX_GROUND_SPEED_M_S).contains(&nav.speed_m_s);
        let alt_m = if nav.alt_m.abs() <= MAX_ALT_M {
            nav.alt_m
        } else {
            f64::NAN
        };
        if speed_known || !self.estimator.needs_speed() {
            let dt_s = if self.pending_start {
                0.0
            } else {
                s.time_s - self.last_learnt_s
            };
            let started = !self.pending_start || self.estimator.start_run().is_ok();
            let step = AdaptiveStep {
                row: &self.row,
                y_nt,
                dt_s,
                along_track_m: if speed_known {
                    nav.speed_m_s * dt_s
                } else {
                    f64::NAN
                },
                alt_m,
            };
            match started.then(|| self.estimator.update(&step)) {
                Some(Ok(Update::Learnt)) => {
                    self.pending_start = false;
                    self.last_learnt_s = s.time_s;
                }
                Some(Ok(Update::Outlier)) => self.outliers += 1,
                _ => self.failed_updates += 1,
            }
        }
        OnlineOutput::compensated(s.mag_nt, interference_nt, status)
    }

    /// Forget the stream's run state (the coefficients are kept).
    pub fn reset(&mut self) {
        self.rows.reset();
        self.pending_start = true;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kalman::online::{OnlineKalman, OnlineKalmanSettings};
    use crate::tolles_lawson::TermSet;
    use crate::tolles_lawson::fit_ls::tests::leg_n;
    use crate::tolles_lawson::rls::{Rls, RlsSettings};

    /// Four manoeuvring legs (headings 30°, 120°, 210°, 300°, flown one
    /// after the other) with known coefficients (`p3,i5`), the estimators
    /// started from wrong ones: they learn them, under both magnitudes;
    /// without the ground speed the Kalman filter learns nothing and RLS
    /// (which does not need it) still learns. Dropout readings and corrupt
    /// navigation values leave what they learn as it is.
    #[test]
    fn the_estimators_learn_wrong_starting_coefficients() {
        let terms = TermSet::parse("p3,i5").unwrap();
        let truth = [12.0, -6.0, 4.0, 3.0, -1.5, 2.0, 1.0, -2.5];
        let start: Vec<f64> = truth
            .iter()
            .enumerate()
            .map(|(k, c)| c + if k % 2 == 0 { 3.0 } else { -2.0 })
            .collect();
        let leg = 1800;
        let (mut t, mut f, mut m) = (Vec::new(), [vec![], vec![], vec![]], Vec::new());
        for (k, yaw) in [30.0, 120.0, 210.0, 300.0].into_iter().enumerate() {
            let (lt, lf, lm) = leg_n(yaw, &truth, &terms, 0.1 * (k * leg) as f64, true, leg);
            t.extend(lt);
            m.extend(lm);
            for (a, b) in f.iter_mut().zip(lf) {
                a.extend(b);
            }
        }
        let n = t.len();
        let err = |c: &[f64]| -> f64 {
            c.iter()
                .zip(&truth)
                .map(|(a, b)| (a - b).powi(2))
                .sum::<f64>()
                .sqrt()
        };
        let e0 = err(&start);
        // With `glitches`, two readings are far off (900 000 nT, and 5 000
        // nT: a 0 is no reading at all and not compensated, see
        // `OnlineSample::below_reading`) and one speed and one altitude are
        // 1e308 (found by fuzzing: each turned the coefficients into NaN or
        // thousands of nT off).
        let run_with =
            |design: &Design, est: Box<dyn CoefficientEstimator>, speed: f64, glitches: bool| {
                let mut tl = AdaptiveTl::new(design, 0.15, est).unwrap();
                for k in 0..n {
                    let glitch = glitches && [1000, 4000, 2000, 3000].contains(&k);
                    let out = tl.push(
                        &OnlineSample {
                            time_s: t[k],
                            flux_nt: [f[0][k], f[1][k], f[2][k]],
                            mag_nt: match k {
                                1000 if glitch => 900_000.0,
                                4000 if glitch => 5_000.0,
                                _ => m[k],
                            },
                            channels: &[],
                        },
                        Navigation {
                            speed_m_s: if glitch && k == 2000 { 1e308 } else { speed },
                            alt_m: if glitch && k == 3000 { 1e308 } else { f64::NAN },
                        },
                    );
                    assert!(out.status.is_compensated());
                }
                assert_eq!(tl.failed_updates(), 0);
                let learning = speed.is_finite() || !tl.estimator.needs_speed();
                let outliers = if glitches && learning { 2 } else { 0 };
                assert_eq!(tl.outliers(), outliers, "no valid sample is an outlier");
                (err(tl.coefficients()), tl.coefficient_std(), tl.mean_nis())
            };
        let run = |design: &Design, est: Box<dyn CoefficientEstimator>, speed: f64| {
            let clean = run_with(design, est.clone(), speed, false);
            let glitched = run_with(design, est, speed, true);
            assert!(
                glitched.0 <= 1.2 * clean.0 && glitched.2.is_none_or(|v| v.is_finite()),
                "glitches: {} against {}",
                glitched.0,
                clean.0
            );
            clean
        };
        let std = [5.0; 8];
        for magnitude in [Magnitude::FirstOrder, Magnitude::Exact] {
            let design = Design {
                magnitude,
                ..Design::new(terms.clone())
            };
            let settings = OnlineKalmanSettings::default();
            let kalman = || Box::new(OnlineKalman::new(&design, &start, &std, &settings).unwrap());
            let (e, sd, nis) = run(&design, kalman(), 80.0);
            assert!(e < 0.1 * e0, "{magnitude:?} Kalman: {e} vs {e0}");
            // Every coefficient learnt from: below a third of its prior (5 × 3).
            assert!(sd.iter().all(|s| *s > 0.0 && *s < 5.0), "{sd:?}");
            assert!(nis.is_some_and(|v| v.is_finite()));
            let (e, _, _) = run(&design, kalman(), f64::NAN);
            assert_eq!(e, e0, "no speed, nothing learnt");
            let rls = Box::new(Rls::new(&start, &std, RlsSettings::default()).unwrap());
            // Differenced rows carry little of the manoeuvres: RLS learns
            // more slowly (0.31 e0 here; fitting the readings themselves,
            // `differenced: false`, it diverges on the slow external
            // variation: 40 e0).
            let (e, _, nis) = run(&design, rls, f64::NAN);
            assert!(e < 0.5 * e0, "{magnitude:?} RLS: {e} vs {e0}");
            assert!(nis.is_none());
        }
    }

    #[test]
    fn bad_settings_are_setting_errors() {
        let design = Design::new(TermSet::parse("p3").unwrap());
        let s = OnlineKalmanSettings::default();
        assert!(OnlineKalman::new(&design, &[1.0; 2], &[1.0; 2], &s).is_err());
        for drift in [-1.0, 50.5, 1e308, f64::NAN] {
            let bad = OnlineKalmanSettings {
                permanent_drift_nt_per_sqrt_h: drift,
                ..s.clone()
            };
            let e = OnlineKalman::new(&design, &[1.0; 3], &[1.0; 3], &bad).unwrap_err();
            assert!(
                e.is_bad_input() && e.to_string().contains("from 0 to 50"),
                "{e}"
            );
        }
        // Noise intensities beyond a field's and a magnetometer's (the
        // filter's arithmetic failed on them: NaN coefficients).
        for q1 in [1e308, -1.0] {
            let mut bad = s.clone();
            bad.noise.q1 = q1;
            let e = OnlineKalman::new(&design, &[1.0; 3], &[1.0; 3], &bad).unwrap_err();
            assert!(
                e.is_bad_input() && e.to_string().contains("Kalman noise"),
                "{e}"
            );
        }
        let bad = OnlineKalmanSettings {
            coef_std_floor: 0.0,
            ..s.clone()
        };
        assert!(OnlineKalman::new(&design, &[1.0; 3], &[1.0; 3], &bad).is_err());
        // A memory too short to hold the coefficients diverged (311 nT of
        // interference where there are 23).
        for memory_s in [0.0, 1.0, 30.0, 299.0, f64::NAN] {
            let rls = RlsSettings {
                memory_s,
                ..RlsSettings::default()
            };
            let e = Rls::new(&[1.0; 3], &[1.0; 3], rls).unwrap_err();
            assert!(
                e.is_bad_input() && e.to_string().contains("at least 300 s"),
                "{e}"
            );
        }
        let rls = RlsSettings {
            memory_s: 300.0,
            ..RlsSettings::default()
        };
        assert!(Rls::new(&[1.0; 3], &[1.0; 3], rls).is_ok());
        let est = Box::new(Rls::new(&[1.0; 2], &[1.0; 2], RlsSettings::default()).unwrap());
        assert!(AdaptiveTl::new(&design, 0.15, est).is_err());
    }
}
