//! Online application of a Tolles-Lawson model: one sample in, its
//! compensated value out, with latency 0 (issue 21).
//!
//! The row of a sample is the batch design row under the causal
//! convention ([`Design::causal`]): the eddy columns' derivative is the
//! backward difference `(B_i − B_{i−1}) / (t_i − t_{i−1})` (0 at a run's
//! first sample), and the lagged eddy derivatives and lagged extra channels
//! run through the same first-order filters as in the batch path
//! ([`super::eddy_lag::FirstOrderLag`]), restarted with each run. The
//! interference is the row's dot product with the coefficients in column
//! order (`Σ_k A_k c_k` from −0.0, as [`Design::interference_with`] sums
//! it), or under [`Magnitude::Exact`] `|B + ΔB| − |B| + bias` with `ΔB`
//! summed the same way along each body axis. So a stream gives, bit for
//! bit, what [`Design::interference_with`] gives under
//! [`Design::causal`] on the same runs.
//!
//! A **run** is what the batch path calls a segment: consecutive usable
//! samples (time, `mag`, the three field components and every extra
//! channel finite, the field not all zero) whose time steps are at most
//! `max_step_s`. A sample that is not usable is not compensated and ends
//! the run; a step over `max_step_s` starts a new one; a time stamp that
//! does not increase is not compensated and leaves the state as it was,
//! as if the sample had not arrived.
//!
//! Memory: the model, one row and the filters' states, whatever the
//! stream's length.
//!
//! ```
//! use aeromag_compensation::tolles_lawson::online::{OnlineSample, OnlineTl, SampleStatus};
//! use aeromag_compensation::tolles_lawson::{Design, TermSet};
//! let design = Design::new(TermSet::parse("p3,i5,e8")?);
//! let mut coef = vec![0.0; 16];
//! coef[2] = 10.0; // p_z: 10 nT along the field's z direction cosine
//! let mut online = OnlineTl::new(&design, &coef, 0.15)?;
//! let out = online.push(&OnlineSample {
//!     time_s: 0.0,
//!     flux_nt: [0.0, 0.0, 50_000.0],
//!     mag_nt: 50_010.0,
//!     channels: &[],
//! });
//! assert_eq!(out.status, SampleStatus::Started);
//! assert_eq!(out.compensated_nt, 50_000.0);
//! # Ok::<(), aeromag_compensation::CompError>(())
//! ```

use super::design::{Lags, TotalField};
use super::terms::backward_difference;
use super::{Design, Magnitude};
use crate::error::{CompError, Result};
use aeromag_core::field::{MAX_FIELD_NT, MIN_READING_NT};

/// One sample of a stream: time (s), the vector magnetometer (body frame,
/// nT), the scalar reading (nT) and the extra regressors' channels in the
/// model's order ([`super::TermSet::extras`]).
#[derive(Debug, Clone, Copy)]
pub struct OnlineSample<'a> {
    /// Time, s.
    pub time_s: f64,
    /// Vector magnetometer x, y, z (body frame), nT.
    pub flux_nt: [f64; 3],
    /// Scalar magnetometer, nT.
    pub mag_nt: f64,
    /// The extra regressors' channels, in the model's order.
    pub channels: &'a [f64],
}

impl OnlineSample<'_> {
    /// Whether `mag` and the vector magnetometer are readings of a
    /// magnetic field: finite, within ±[`MAX_FIELD_NT`] (beyond is a
    /// corrupted value: 1e308 ran through an adaptive compensator's state)
    /// and not [below a reading](Self::below_reading).
    pub fn readings_usable(&self) -> bool {
        let field = |v: &f64| v.abs() <= MAX_FIELD_NT;
        field(&self.mag_nt) && self.flux_nt.iter().all(field) && self.below_reading().is_none()
    }

    /// `("mag", mag)` when the scalar reading is below [`MIN_READING_NT`],
    /// else `("|flux|", magnitude)` when the vector magnetometer's
    /// magnitude is (all zero included): a dropout value, a negated
    /// reading or another unit (tesla, gauss, µT), no reading of Earth's
    /// field. `None` otherwise (NaN included).
    pub fn below_reading(&self) -> Option<(&'static str, f64)> {
        let [x, y, z] = self.flux_nt;
        let norm = (x * x + y * y + z * z).sqrt();
        if self.mag_nt < MIN_READING_NT {
            Some(("mag", self.mag_nt))
        } else if norm < MIN_READING_NT {
            Some(("|flux|", norm))
        } else {
            None
        }
    }
}

/// What happened to a sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SampleStatus {
    /// Compensated, continuing the run.
    Compensated,
    /// Compensated, the first sample of a run (the stream's first, or after
    /// a gap or a sample that could not be used): derivative 0, the lags
    /// restarted.
    Started,
    /// Not compensated: an input is missing (not finite), `mag` or a
    /// `flux` component is beyond any magnetic field
    /// ([`MAX_FIELD_NT`]), or `mag` or the vector magnetometer's magnitude
    /// is below a reading of Earth's field ([`MIN_READING_NT`]: a dropout
    /// value such as 0, another unit). The run ends.
    Missing,
    /// Not compensated: its time does not increase. The state is kept
    /// (until [`RESYNC_SAMPLES`] samples in a row go back together).
    TimeBackwards,
}

impl SampleStatus {
    /// Whether the sample was compensated.
    pub fn is_compensated(self) -> bool {
        matches!(self, SampleStatus::Compensated | SampleStatus::Started)
    }
}

/// The result of one sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OnlineOutput {
    /// Modelled interference, nT (NaN when not compensated).
    pub interference_nt: f64,
    /// `mag − interference`, nT (NaN when not compensated).
    pub compensated_nt: f64,
    /// What happened.
    pub status: SampleStatus,
}

/// Samples in a row whose time goes back from the last increasing time,
/// each advancing on the one before within a run's step, after which the
/// stream takes their clock (the last of them starts a run; the others
/// stay [`SampleStatus::TimeBackwards`]). Found by fuzzing: one time of
/// 1e308 or 99 999, or a seconds-of-day clock wrapping at midnight, made
/// every later sample "time going back" for the rest of the stream.
pub const RESYNC_SAMPLES: usize = 10;

/// The last sample of the current run.
#[derive(Debug, Clone, Copy)]
struct Last {
    time_s: f64,
    flux_nt: [f64; 3],
}

/// The causal design rows of a stream, sample by sample: the run logic
/// (gaps, missing values, time going back), the backward-difference
/// derivative and the lag filters of [the module docs](self). After
/// [`OnlineRows::advance`] accepts a sample, [`OnlineRows::row_along`]
/// gives its row along any direction. [`OnlineTl`] applies fixed
/// coefficients to these rows; the adaptive estimators
/// ([`crate::kalman::online`], [`super::rls`]) update theirs with them.
#[derive(Debug, Clone)]
pub struct OnlineRows {
    design: Design,
    max_step_s: f64,
    lags: Lags,
    /// The last sample of the run, `None` between runs.
    last: Option<Last>,
    /// The last increasing time stamp seen.
    last_time_s: Option<f64>,
    /// The samples in a row whose time went back, each advancing on the
    /// one before by at most `max_step_s`: the last one's time and how
    /// many ([`RESYNC_SAMPLES`]).
    back: Option<(f64, usize)>,
    /// The current sample's inputs: field, derivative, lagged derivatives,
    /// extra channels `[x, L_τ[x]]`.
    b: [f64; 3],
    db: [f64; 3],
    lagged: Vec<[f64; 3]>,
    extra: Vec<[f64; 2]>,
}

impl OnlineRows {
    /// Rows of `design` under the causal convention, runs broken at time
    /// steps over `max_step_s` (s; the batch rule is 1.5 × the sample
    /// interval). A step not positive is [`CompError::InvalidSetting`].
    pub fn new(design: &Design, max_step_s: f64) -> Result<Self> {
        design.validate()?;
        if !(max_step_s > 0.0 && max_step_s.is_finite()) {
            return Err(CompError::setting(format!(
                "the longest time step of a run must be positive, got {max_step_s} s"
            )));
        }
        let design = design.causal();
        Ok(Self {
            lags: Lags::new(&design.terms),
            extra: vec![[f64::NAN; 2]; design.terms.extras().len()],
            lagged: vec![[0.0; 3]; design.terms.eddy_lags_s().len()],
            b: [f64::NAN; 3],
            db: [0.0; 3],
            design,
            max_step_s,
            last: None,
            last_time_s: None,
            back: None,
        })
    }

    /// The design the rows are built with (causal).
    pub fn design(&self) -> &Design {
        &self.design
    }

    /// The longest time step within a run, s.
    pub fn max_step_s(&self) -> f64 {
        self.max_step_s
    }

    /// Number of extra channels a sample must carry.
    pub fn n_channels(&self) -> usize {
        self.extra.len()
    }

    /// Take the next sample ([module docs](self)): when the status
    /// [is compensated](SampleStatus::is_compensated), its row is ready
    /// ([`Self::row_along`], [`Self::field_nt`]). A sample with fewer or
    /// more channels than the model's is [`SampleStatus::Missing`].
    pub fn advance(&mut self, s: &OnlineSample) -> SampleStatus {
        if let Some(t0) = self.last_time_s
            && s.time_s.is_finite()
            && s.time_s <= t0
        {
            // Samples going back that run on among themselves: after
            // RESYNC_SAMPLES of them the stream's clock is theirs (the
            // time before was a spike, or the clock wrapped at midnight).
            let count = match self.back {
                Some((b, k)) if s.time_s > b && s.time_s - b <= self.max_step_s => k + 1,
                _ => 1,
            };
            if count < RESYNC_SAMPLES {
                self.back = Some((s.time_s, count));
                return SampleStatus::TimeBackwards;
            }
            self.back = None;
            self.last = None;
            self.last_time_s = None;
        } else {
            self.back = None;
        }
        let usable = s.time_s.is_finite()
            && s.readings_usable()
            && s.channels.len() == self.extra.len()
            && s.channels.iter().all(|v| v.is_finite());
        if s.time_s.is_finite() {
            self.last_time_s = Some(s.time_s);
        }
        if !usable {
            self.last = None;
            return SampleStatus::Missing;
        }
        let last = self.last.filter(|l| s.time_s - l.time_s <= self.max_step_s);
        if last.is_none() {
            self.lags = Lags::new(&self.design.terms);
        }
        let conv = self.design.convention;
        self.db = match last {
            Some(l) if self.design.terms.has_eddy() => [0, 1, 2]
                .map(|k| backward_difference(conv, l.flux_nt[k], s.flux_nt[k], l.time_s, s.time_s)),
            _ => [0.0; 3],
        };
        for ((x, &v), lag) in self
            .extra
            .iter_mut()
            .zip(s.channels)
            .zip(&mut self.lags.extra)
        {
            *x = [v, lag.as_mut().map_or(f64::NAN, |l| l.step(s.time_s, v))];
        }
        if !self.lagged.is_empty() {
            self.lagged
                .copy_from_slice(self.lags.eddy.step(s.time_s, self.db));
        }
        self.b = s.flux_nt;
        self.last = Some(Last {
            time_s: s.time_s,
            flux_nt: s.flux_nt,
        });
        if last.is_some() {
            SampleStatus::Compensated
        } else {
            SampleStatus::Started
        }
    }

    /// The accepted sample's vector field (body frame), nT.
    pub fn field_nt(&self) -> [f64; 3] {
        self.b
    }

    /// The accepted sample's design row along the direction of `dir`
    /// ([`super::TermSet::row_along`]: `dir = b` is the first-order row, a
    /// body axis the exact model's component along it) into `out`.
    pub fn row_along(&self, dir: [f64; 3], out: &mut [f64]) {
        self.design.terms.row_along(
            dir,
            self.b,
            self.db,
            &self.lagged,
            &self.extra,
            self.design.bt_scale_nt,
            out,
        );
    }

    /// Forget the stream: the next sample starts a run, whatever its time.
    pub fn reset(&mut self) {
        self.last = None;
        self.last_time_s = None;
        self.back = None;
        self.lags = Lags::new(&self.design.terms);
    }
}

/// `row · c`, summed from −0.0 in column order: the bits of
/// [`Design::interference_with`]'s sum (−0.0 is the identity of f64
/// addition).
pub(crate) fn dot(row: &[f64], c: &[f64]) -> f64 {
    let mut acc = -0.0;
    for (v, c) in row.iter().zip(c) {
        acc += v * c;
    }
    acc
}

/// The body axes, the directions of the exact model's three components.
pub(crate) const AXES: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// A Tolles-Lawson model applied sample by sample ([module docs](self)).
#[derive(Debug, Clone)]
pub struct OnlineTl {
    rows: OnlineRows,
    /// Coefficients; under the exact magnitude with the bias set to 0.
    coef: Vec<f64>,
    /// The bias coefficient under the exact magnitude (0 otherwise).
    bias: f64,
    row: Vec<f64>,
}

impl OnlineTl {
    /// The model `design` with coefficients `coef`, runs broken at time
    /// steps over `max_step_s` (s; the batch rule is 1.5 × the sample
    /// interval). Bad settings (coefficients not matching the design, a
    /// step not positive) are [`CompError::InvalidSetting`].
    pub fn new(design: &Design, coef: &[f64], max_step_s: f64) -> Result<Self> {
        let rows = OnlineRows::new(design, max_step_s)?;
        let n = design.n_columns();
        if coef.len() != n {
            return Err(CompError::setting(format!(
                "{} coefficients for a design of {n} columns",
                coef.len()
            )));
        }
        let mut coef = coef.to_vec();
        let bias = match (design.magnitude, design.terms.bias_column()) {
            (Magnitude::Exact, Some(k)) => std::mem::replace(&mut coef[k], 0.0),
            _ => 0.0,
        };
        Ok(Self {
            rows,
            coef,
            bias,
            row: vec![0.0; n],
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

    /// Compensate one sample ([module docs](self)). Never fails: a sample
    /// that cannot be compensated says why in its status. A sample with
    /// fewer or more channels than the model's is [`SampleStatus::Missing`].
    pub fn push(&mut self, s: &OnlineSample) -> OnlineOutput {
        let status = self.rows.advance(s);
        if !status.is_compensated() {
            return OnlineOutput::not(status);
        }
        let b = self.rows.field_nt();
        let interference_nt = match self.rows.design().magnitude {
            Magnitude::FirstOrder => {
                self.rows.row_along(b, &mut self.row);
                dot(&self.row, &self.coef)
            }
            Magnitude::Exact => {
                let d = AXES.map(|axis| {
                    self.rows.row_along(axis, &mut self.row);
                    dot(&self.row, &self.coef)
                });
                TotalField::of(b, d).change() + self.bias
            }
        };
        OnlineOutput::compensated(s.mag_nt, interference_nt, status)
    }

    /// Forget the stream: the next sample starts a run, whatever its time.
    pub fn reset(&mut self) {
        self.rows.reset();
    }
}

impl OnlineOutput {
    /// A compensated sample: reading `mag_nt` minus `interference_nt`.
    pub fn compensated(mag_nt: f64, interference_nt: f64, status: SampleStatus) -> Self {
        Self {
            interference_nt,
            compensated_nt: mag_nt - interference_nt,
            status,
        }
    }

    /// The output of a sample that was not compensated.
    pub fn not(status: SampleStatus) -> Self {
        Self {
            interference_nt: f64::NAN,
            compensated_nt: f64::NAN,
            status,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tolles_lawson::design::Channels;
    use crate::tolles_lawson::fit_ls::tests::leg_n;
    use crate::tolles_lawson::segments::split_segments;
    use crate::tolles_lawson::{ExtraTerm, TermSet};

    /// Rows 0..n of a manoeuvring leg at 10 Hz with uneven steps, a gap
    /// (2 s), a missing field value, a missing channel value, a zero field
    /// and two extra channels (a strobe and a slow ramp, lagged).
    /// Time, field, reading and the two channels.
    type Stream = (Vec<f64>, [Vec<f64>; 3], Vec<f64>, [Vec<f64>; 2]);

    fn stream(n: usize) -> Stream {
        let terms = TermSet::observable16();
        let (mut t, mut f, m) = leg_n(30.0, &[0.0; 16], &terms, 0.0, true, n);
        for (k, v) in t.iter_mut().enumerate() {
            *v += 1e-3 * (k % 3) as f64 + if k >= 700 { 2.0 } else { 0.0 };
        }
        f[1][300] = f64::NAN;
        for c in &mut f {
            c[901] = 0.0;
        }
        let strobe: Vec<f64> = (0..n).map(|k| 5.0 * ((k / 7) % 2) as f64).collect();
        let mut ramp: Vec<f64> = (0..n).map(|k| (k % 50) as f64 * 0.1).collect();
        ramp[1200] = f64::NAN;
        (t, f, m, [strobe, ramp])
    }

    /// The batch path under the causal convention on the same runs.
    fn batch(
        design: &Design,
        coef: &[f64],
        t: &[f64],
        f: [&[f64]; 3],
        ch: [&[f64]; 2],
    ) -> Vec<f64> {
        let usable: Vec<bool> = (0..t.len())
            .map(|k| {
                f.iter().all(|c| c[k].is_finite())
                    && ch.iter().all(|c| c[k].is_finite())
                    && f.iter().any(|c| c[k] != 0.0)
            })
            .collect();
        let (runs, _) = split_segments(t, None, &usable, 1.5, 1);
        let mut out = vec![f64::NAN; t.len()];
        let causal = design.causal();
        for r in runs {
            let chs = [&ch[0][r.clone()], &ch[1][r.clone()]];
            let v = causal.interference_with(
                coef,
                &t[r.clone()],
                f.map(|c| &c[r.clone()]),
                Channels::new(&chs),
            );
            out[r].copy_from_slice(&v);
        }
        out
    }

    /// Sample by sample equals the batch path under the causal convention,
    /// bit for bit, through a gap, missing values and a zero field, for
    /// both magnitudes, eddy lags and lagged extra channels.
    #[test]
    fn online_equals_the_causal_batch_bit_for_bit() {
        let n = 1500;
        let (t, f, m, ch) = stream(n);
        let terms = TermSet::parse("p3,i5,e8,l9,bias")
            .unwrap()
            .with_eddy_lags(&[0.3])
            .unwrap()
            .with_extras(&[ExtraTerm::new("strobe"), ExtraTerm::lagged("ramp", 0.4)])
            .unwrap();
        let ncol = terms.n_columns();
        let coef: Vec<f64> = (0..ncol).map(|k| 40.0 * ((k as f64) * 0.7).sin()).collect();
        for magnitude in [Magnitude::FirstOrder, Magnitude::Exact] {
            let design = Design {
                magnitude,
                ..Design::new(terms.clone())
            };
            let want = batch(&design, &coef, &t, [&f[0], &f[1], &f[2]], [&ch[0], &ch[1]]);
            let mut online = OnlineTl::new(&design, &coef, 1.5 * 0.1).unwrap();
            let mut started = 0;
            for k in 0..n {
                let out = online.push(&OnlineSample {
                    time_s: t[k],
                    flux_nt: [f[0][k], f[1][k], f[2][k]],
                    mag_nt: m[k],
                    channels: &[ch[0][k], ch[1][k]],
                });
                assert_eq!(
                    out.interference_nt.to_bits(),
                    want[k].to_bits(),
                    "{magnitude:?} row {k}: {} vs {}",
                    out.interference_nt,
                    want[k]
                );
                assert_eq!(out.status.is_compensated(), want[k].is_finite());
                started += usize::from(out.status == SampleStatus::Started);
            }
            // The stream's start, after the missing field value, the gap,
            // the zero field and the missing channel value.
            assert_eq!(started, 5, "{magnitude:?}");
        }
    }

    /// A time stamp that does not increase is flagged and leaves the state
    /// as it was: the stream goes on as if it had not arrived.
    #[test]
    fn time_going_back_is_flagged_and_skipped() {
        let n = 200;
        let (t, f, m, _) = stream(1500);
        let design = Design::new(TermSet::parse("p3,i5,e8").unwrap());
        let coef: Vec<f64> = (0..16).map(|k| k as f64 - 7.0).collect();
        let mut clean = OnlineTl::new(&design, &coef, 0.15).unwrap();
        let mut dirty = clean.clone();
        let sample = |k: usize, time_s: f64| OnlineSample {
            time_s,
            flux_nt: [f[0][k], f[1][k], f[2][k]],
            mag_nt: m[k],
            channels: &[],
        };
        for k in 0..n {
            let a = clean.push(&sample(k, t[k]));
            if k == 50 {
                for back in [t[k - 1] - 5.0, t[k - 1]] {
                    let out = dirty.push(&sample(k, back));
                    assert_eq!(out.status, SampleStatus::TimeBackwards);
                    assert!(out.compensated_nt.is_nan());
                }
            }
            let b = dirty.push(&sample(k, t[k]));
            assert_eq!(a, b, "row {k}");
        }
        // One time far ahead (a corrupted cell): the samples after it go
        // back, and after RESYNC_SAMPLES of them the stream runs on its
        // clock again; so it does when the clock jumps back for good.
        for jump in [1e308, -86_400.0] {
            let mut o = OnlineTl::new(&design, &coef, 0.15).unwrap();
            let mut statuses = Vec::new();
            for k in 0..n {
                let time_s = match (k, jump > 0.0) {
                    (50, true) => jump,
                    (k, false) if k >= 50 => t[k] + jump,
                    _ => t[k],
                };
                statuses.push(o.push(&sample(k, time_s)).status);
            }
            let back = statuses
                .iter()
                .filter(|s| **s == SampleStatus::TimeBackwards)
                .count();
            assert_eq!(back, RESYNC_SAMPLES - 1, "{jump}");
            let resync = if jump > 0.0 { 51 } else { 50 } + RESYNC_SAMPLES - 1;
            assert_eq!(statuses[resync], SampleStatus::Started, "{jump}");
            assert!(
                statuses[resync + 1..]
                    .iter()
                    .all(|s| *s == SampleStatus::Compensated)
            );
        }
    }

    #[test]
    fn bad_settings_and_wrong_channel_counts() {
        let design = Design::new(TermSet::parse("p3").unwrap());
        assert!(OnlineTl::new(&design, &[1.0, 2.0], 0.15).is_err());
        assert!(OnlineTl::new(&design, &[1.0, 2.0, 3.0], 0.0).is_err());
        assert!(OnlineTl::new(&design, &[1.0, 2.0, 3.0], f64::NAN).is_err());
        let mut o = OnlineTl::new(&design, &[1.0, 2.0, 3.0], 0.15).unwrap();
        let out = o.push(&OnlineSample {
            time_s: 0.0,
            flux_nt: [1.0, 2.0, 3.0],
            mag_nt: 4.0,
            channels: &[1.0],
        });
        assert_eq!(out.status, SampleStatus::Missing);
        // A reading beyond any magnetic field is a corrupted value: missing
        // (flux of 1e308 gave an interference of 0 flagged compensated, and
        // NaN afterwards).
        let b = [20_000.0, 1_000.0, 45_000.0];
        for (k, (flux_nt, mag_nt)) in [
            (b, 49_300.0),
            (b, 1e308),
            ([1e308, 1e308, 1e308], 49_300.0),
            (b, -2e6),
            (b, 49_300.0),
        ]
        .into_iter()
        .enumerate()
        {
            let out = o.push(&OnlineSample {
                time_s: 1.0 + 0.1 * k as f64,
                flux_nt,
                mag_nt,
                channels: &[],
            });
            let usable = mag_nt.abs() < 1e6 && flux_nt[0] < 1e6;
            assert_eq!(out.status.is_compensated(), usable, "{k}");
            assert_eq!(out.interference_nt.is_finite(), usable, "{k}");
        }
    }
}
