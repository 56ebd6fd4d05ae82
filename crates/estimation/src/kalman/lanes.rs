//! Four filters stepped together: their `n`-state square-root factors in
//! SIMD lanes — augmented filters of one model ([`AugmentedLanes`]: the
//! likelihood of the noise tuning, the field filter's groups of runs) or
//! plain filters ([`FilterLanes`]: the smoother re-running four blocks at
//! once, [`super::fixed_interval`]).
//!
//! The time update `U ← tri([G, Φ U])` (Householder, both halves upper
//! triangular: [`super::triangularize::triangularize_upper_pair`]) and
//! Carlson's measurement update ([`super::carlson::carlson_update`]) of a
//! small factor are chains of dependent operations — a square root and a
//! division per row or column — so one filter waits on their latency. Four
//! independent filters (four groups of runs of one likelihood evaluation)
//! fill the four lanes of an AVX register instead: each lane does the
//! operations of [`super::SqrtKalmanFilter::predict`] and
//! [`super::SqrtKalmanFilter::update`] in their order, so every lane's factor,
//! gain and innovation variance are **bit for bit** those of its filter
//! stepped alone (the tests compare the bits). Entries of `Φ` that are zero
//! in one lane and not in another are added as `0 · u` in the first, which
//! leaves a sum that started from `+0` unchanged; a lane whose `Φ` or `G` is
//! not upper triangular is an error, not a different algorithm.
//!
//! The right-hand sides and the sums of each lane are its own
//! [`AugmentedFilter`]'s, given the lane's gain; [`AugmentedLanes::take`]
//! hands a lane back as that filter.

// The kernels index several arrays by the same state and lane, as the
// scalar code they mirror does.
#![allow(clippy::needless_range_loop)]

use super::augmented::{AugmentedFilter, Before, RightHandSides};
use super::filter::LeadingConditional;
use super::innovation::Innovation;
use crate::error::{EstError, Result};
use nalgebra::DMatrix;

/// Filters stepped together.
pub const FILTER_LANES: usize = 4;
const L: usize = FILTER_LANES;

/// What one lane does in a step of [`AugmentedLanes::step`].
#[derive(Debug, Clone, Copy)]
pub enum LaneStep<'a> {
    /// Nothing (its filter has no more samples).
    Idle,
    /// A run starts: the prior, then the reading.
    Start(Reading<'a>),
    /// The time update with `Φ` and `G` (`n × n`, upper triangular), then
    /// the reading.
    Next {
        /// The transition.
        phi: &'a DMatrix<f64>,
        /// The noise factor, `Q = G Gᵀ`.
        g: &'a DMatrix<f64>,
        /// The measurement.
        reading: Reading<'a>,
    },
}

/// One measurement of [`AugmentedFilter::update`]: the dynamic row `h`
/// (length `n`), the regressor row `z` (length `m`) and the reading `y`.
#[derive(Debug, Clone, Copy)]
pub struct Reading<'a> {
    /// The dynamic row.
    pub h: &'a [f64],
    /// The regressor row.
    pub z: &'a [f64],
    /// The reading.
    pub y: f64,
}

/// Four upper-triangular `N × N` square-root factors in SIMD lanes, with
/// each lane's last `Φ` and `G`: the time and measurement updates of
/// [`super::SqrtKalmanFilter`] on all four at once, bit for bit (module
/// docs). The factor part of [`AugmentedLanes`] and [`FilterLanes`].
struct FactorLanes<const N: usize, const W: usize> {
    /// `u[j][i][l]`: entry `(i, j)` of lane `l`'s upper factor.
    u: [[[f64; W]; N]; N],
    gain: [[f64; W]; N],
    /// The lanes' last `Φ` and `G`, `phi[i][j][l]` (upper parts).
    phi: [[[f64; W]; N]; N],
    g: [[[f64; W]; N]; N],
}

impl<const N: usize, const W: usize> FactorLanes<N, W> {
    fn new() -> Self {
        Self {
            u: [[[0.0; W]; N]; N],
            gain: [[0.0; W]; N],
            phi: [[[0.0; W]; N]; N],
            g: [[[0.0; W]; N]; N],
        }
    }

    /// Lane `l`'s `Φ` and `G` for the next [`Self::predict`]: both `N × N`
    /// and upper triangular, else an error (nothing changed).
    fn load(&mut self, l: usize, phi: &DMatrix<f64>, g: &DMatrix<f64>) -> Result<()> {
        if phi.shape() != (N, N) || g.shape() != (N, N) {
            return Err(EstError::Dimension(format!(
                "filter lanes: Φ {:?}, G {:?} for {N} states",
                phi.shape(),
                g.shape()
            )));
        }
        // Column-major: the upper part of column j is its rows 0..=j; the
        // rest must be zero.
        let (p, q) = (phi.as_slice(), g.as_slice());
        for j in 0..N {
            let (pc, qc) = (&p[j * N..(j + 1) * N], &q[j * N..(j + 1) * N]);
            if pc[j + 1..].iter().chain(&qc[j + 1..]).any(|v| *v != 0.0) {
                return Err(EstError::Dimension(
                    "filter lanes: Φ and G must be upper triangular".into(),
                ));
            }
        }
        for j in 0..N {
            for i in 0..=j {
                self.phi[i][j][l] = p[i + j * N];
                self.g[i][j][l] = q[i + j * N];
            }
        }
        Ok(())
    }

    /// Whether every lane's `Φ` and `h` are two chains read at their
    /// heads ([`super::augmented::two_chains`]; lanes not moving compute
    /// with the `Φ` they last had, whose results are not kept).
    fn two_chains(&self, h: &[[f64; W]; N]) -> bool {
        let Some(split) = N.checked_sub(2) else {
            return false;
        };
        let mut two = true;
        for i in 0..N {
            for l in 0..W {
                two &= i == 0 || i == split || h[i][l] == 0.0;
            }
            for j in split.max(i)..N {
                for l in 0..W {
                    two &= i >= split || self.phi[i][j][l] == 0.0;
                }
            }
        }
        two
    }

    /// `U ← tri([G, Φ U])` in the `moving` lanes (the others keep their
    /// factor), then Carlson's update with rows `h` and noise variances
    /// `r` in every lane (a lane with `h = 0` keeps its factor); returns
    /// the innovation variances and whether every lane had two chains.
    /// Two chains in every lane (the field models): the products with the
    /// structural zeros left out, as in `augmented::Step` (the same bits:
    /// every sum here starts from +0).
    fn predict_update(
        &mut self,
        moving: [bool; W],
        h: &[[f64; W]; N],
        r: [f64; W],
    ) -> ([f64; W], bool) {
        let two = self.two_chains(h);
        macro_rules! kernel {
            ($k:ident { $($f:ident: $v:expr),* }) => {
                if two {
                    aeromag_core::simd::run($k::<N, W, true> { $($f: $v),* })
                } else {
                    aeromag_core::simd::run($k::<N, W, false> { $($f: $v),* })
                }
            };
        }
        kernel!(Predict {
            u: &mut self.u,
            phi: &self.phi,
            g: &mut self.g,
            moving: moving
        });
        let variance = kernel!(Update {
            u: &mut self.u,
            gain: &mut self.gain,
            h: h,
            r: r
        });
        (variance, two)
    }

    /// Lane `l`'s upper factor.
    fn factor(&self, l: usize) -> DMatrix<f64> {
        DMatrix::from_fn(N, N, |i, j| if i <= j { self.u[j][i][l] } else { 0.0 })
    }

    /// Lane `l`'s factor from the upper part of `s` (`N × N`).
    fn set_factor(&mut self, l: usize, s: impl Fn(usize, usize) -> f64) {
        for j in 0..N {
            for i in 0..N {
                self.u[j][i][l] = if i <= j { s(i, j) } else { 0.0 };
            }
        }
    }

    /// Lane `l`'s gain.
    fn gain(&self, l: usize) -> [f64; N] {
        std::array::from_fn(|i| self.gain[i][l])
    }
}

/// Four [`AugmentedFilter`]s of `N` dynamic states and one prior, stepped
/// together (module docs).
pub struct AugmentedLanes<const N: usize> {
    factors: FactorLanes<N, L>,
    prior: [[f64; N]; N],
    /// A fresh filter (prior and right-hand sides), for each lane's start.
    fresh: AugmentedFilter,
    rhs: Vec<RightHandSides>,
}

impl<const N: usize> AugmentedLanes<N> {
    /// Four fresh filters of [`AugmentedFilter::new`]`(s0, prior_mean,
    /// prior_std)` (`s0` is `N × N`).
    pub fn new(s0: &DMatrix<f64>, prior_mean: &[f64], prior_std: &[f64]) -> Result<Self> {
        if s0.nrows() != N || s0.ncols() != N {
            return Err(EstError::Dimension(format!(
                "filter lanes of {N} states for a {}×{} prior factor",
                s0.nrows(),
                s0.ncols()
            )));
        }
        let fresh = AugmentedFilter::new(s0, prior_mean, prior_std)?;
        let mut prior = [[0.0; N]; N];
        for (j, col) in prior.iter_mut().enumerate() {
            for (i, v) in col.iter_mut().enumerate().take(j + 1) {
                *v = s0[(i, j)];
            }
        }
        let mut lanes = Self {
            factors: FactorLanes::new(),
            prior,
            rhs: vec![fresh.right_hand_sides().clone(); L],
            fresh,
        };
        for l in 0..L {
            lanes.reset_factor(l);
        }
        Ok(lanes)
    }

    /// One step of every lane. The rows are checked first (the errors of
    /// [`AugmentedFilter::update`]); on error nothing has changed.
    pub fn step(&mut self, lanes: [LaneStep<'_>; L], r: f64) -> Result<()> {
        if !(r > 0.0 && r.is_finite()) {
            return Err(EstError::NonFinite {
                what: "measurement noise variance (must be finite and > 0)",
            });
        }
        let mut h = [[0.0; L]; N];
        let mut moving = [false; L];
        for (l, step) in lanes.iter().enumerate() {
            let reading = match step {
                LaneStep::Idle => continue,
                LaneStep::Start(reading) => reading,
                LaneStep::Next { phi, g, reading } => {
                    self.factors.load(l, phi, g)?;
                    moving[l] = true;
                    reading
                }
            };
            if reading.h.len() != N || !aeromag_core::simd::all_finite(reading.h) {
                return Err(EstError::NonFinite {
                    what: "scalar measurement or its row",
                });
            }
            self.rhs[l].check(reading.z, reading.y)?;
            for i in 0..N {
                h[i][l] = reading.h[i];
            }
        }
        for (l, step) in lanes.iter().enumerate() {
            if let LaneStep::Start(_) = step {
                self.reset_factor(l);
                self.rhs[l].start_run();
            }
        }
        // Lanes not moving compute with whatever Φ and G they last had (the
        // lower parts are never written: zero); their results are not kept.
        // Idle lanes: h = 0, so every f_j is 0 and the factor is unchanged.
        let mut rr = [1.0; L];
        for (l, step) in lanes.iter().enumerate() {
            if !matches!(step, LaneStep::Idle) {
                rr[l] = r;
            }
        }
        let (variance, two) = self.factors.predict_update(moving, &h, rr);
        for (l, step) in lanes.iter().enumerate() {
            let gain = self.factors.gain(l);
            let rhs = &mut self.rhs[l];
            match step {
                LaneStep::Idle => continue,
                LaneStep::Start(r) => {
                    rhs.absorb(Before::Waiting, r.h, r.z, r.y, variance[l], &gain)?
                }
                // Φ checked upper triangular above, the two chains in
                // every lane.
                LaneStep::Next {
                    phi, reading: r, ..
                } => {
                    let before = Before::Upper {
                        phi: phi.as_slice(),
                        two_chains: two,
                    };
                    rhs.absorb(before, r.h, r.z, r.y, variance[l], &gain)?
                }
            }
        }
        Ok(())
    }

    /// Every lane records its innovations from now on, and so does every
    /// lane made fresh again ([`AugmentedFilter::record_innovations`];
    /// [`Self::take`] hands them over with the filter).
    pub fn record_innovations(&mut self, on: bool) {
        self.fresh.record_innovations(on);
        for r in &mut self.rhs {
            r.record(on);
        }
    }

    /// Lane `l`'s [`AugmentedFilter::conditional`]: its dynamic states
    /// given the coefficients after its last step.
    pub fn conditional(&self, l: usize) -> LeadingConditional {
        self.rhs[l].conditional(self.factors.factor(l))
    }

    /// Lane `l`'s filter (factor, right-hand sides and sums), the lane
    /// fresh again.
    pub fn take(&mut self, l: usize) -> Result<AugmentedFilter> {
        let factor = self.factors.factor(l);
        let mut f = self.fresh.clone();
        let rhs = std::mem::replace(&mut self.rhs[l], self.fresh.right_hand_sides().clone());
        f.with_factor(&factor, rhs)?;
        self.reset_factor(l);
        Ok(f)
    }

    /// Lane `l`'s factor back to the prior.
    fn reset_factor(&mut self, l: usize) {
        let prior = &self.prior;
        self.factors.set_factor(l, |i, j| prior[j][i]);
    }
}

/// What one lane of [`FilterLanes::step`] does: the time update with `Φ`
/// and `G` (`N × N`, upper triangular) if any, then the measurement
/// `(h, y, r)` if any. Neither: the lane is idle and keeps its estimate.
#[derive(Debug, Clone, Copy, Default)]
pub struct FilterStep<'a> {
    /// `(Φ, G)` of the time update.
    pub predict: Option<(&'a DMatrix<f64>, &'a DMatrix<f64>)>,
    /// The row `h` (length `N`), the reading `y` and its noise variance `r`.
    pub measurement: Option<(&'a [f64], f64, f64)>,
}

/// Four [`super::SqrtKalmanFilter`]s of `N` states stepped together, their
/// factors in SIMD lanes (module docs) and their means beside them: each
/// lane's mean, factor, gain and innovation are bit for bit those of its
/// filter stepped alone with [`super::SqrtKalmanFilter::predict`] and
/// [`super::SqrtKalmanFilter::update`] (test
/// `filter_lanes_are_filters_alone_bit_for_bit`). For the smoother's
/// re-runs of four blocks at once ([`super::fixed_interval`]).
pub struct FilterLanes<const N: usize> {
    factors: FactorLanes<N, L>,
    /// `x[i][l]`: state `i` of lane `l`.
    x: [[f64; L]; N],
}

impl<const N: usize> Default for FilterLanes<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> FilterLanes<N> {
    /// Four filters at zero (set each with [`Self::set`]).
    pub fn new() -> Self {
        Self {
            factors: FactorLanes::new(),
            x: [[0.0; L]; N],
        }
    }

    /// Lane `l`'s mean `x` (length `N`) and upper factor `s` (`N × N`;
    /// the lower part ignored), as [`super::SqrtKalmanFilter::set`].
    pub fn set(&mut self, l: usize, x: &[f64], s: &DMatrix<f64>) -> Result<()> {
        if x.len() != N || s.shape() != (N, N) {
            return Err(EstError::Dimension(
                "filter lanes: state or factor of another size".into(),
            ));
        }
        for (i, v) in x.iter().enumerate() {
            self.x[i][l] = *v;
        }
        self.factors.set_factor(l, |i, j| s[(i, j)]);
        Ok(())
    }

    /// One step of every lane (see [`FilterStep`]); returns each measuring
    /// lane's innovation. Errors (nothing changed): a `Φ` or `G` of another
    /// size or not upper triangular, or the errors of
    /// [`super::SqrtKalmanFilter::update`] (non-finite `h` or `y`, `r` not
    /// finite and positive).
    pub fn step(&mut self, lanes: [FilterStep<'_>; L]) -> Result<[Option<Innovation>; L]> {
        let mut h = [[0.0; L]; N];
        let mut y = [0.0; L];
        let mut r = [1.0; L];
        for (l, step) in lanes.iter().enumerate() {
            if let Some((row, yl, rl)) = step.measurement {
                if !(rl > 0.0 && rl.is_finite()) {
                    return Err(EstError::NonFinite {
                        what: "measurement noise variance (must be finite and > 0)",
                    });
                }
                if row.len() != N {
                    return Err(EstError::Dimension(format!(
                        "Carlson update: state {N}, row {}",
                        row.len()
                    )));
                }
                if !yl.is_finite() || !aeromag_core::simd::all_finite(row) {
                    return Err(EstError::NonFinite {
                        what: "scalar measurement or its row",
                    });
                }
                for i in 0..N {
                    h[i][l] = row[i];
                }
                (y[l], r[l]) = (yl, rl);
            }
        }
        let mut moving = [false; L];
        for (l, step) in lanes.iter().enumerate() {
            if let Some((phi, g)) = step.predict {
                self.factors.load(l, phi, g)?;
                moving[l] = true;
            }
        }
        // x ← Φ x in the moving lanes: each entry summed over the non-zero
        // Φ_ij, j ascending, from +0 (the order of the filter's sparse
        // product).
        let phi = &self.factors.phi;
        let mut x = self.x;
        for i in 0..N {
            let mut acc = [0.0; L];
            for j in i..N {
                for l in 0..L {
                    let p = phi[i][j][l];
                    acc[l] = if p != 0.0 {
                        acc[l] + p * self.x[j][l]
                    } else {
                        acc[l]
                    };
                }
            }
            for l in 0..L {
                if moving[l] {
                    x[i][l] = acc[l];
                }
            }
        }
        // ν = y − hᵀx⁻, subtracted term by term as Carlson's update does.
        let mut nu = y;
        for i in 0..N {
            for l in 0..L {
                nu[l] -= h[i][l] * x[i][l];
            }
        }
        let (variance, _) = self.factors.predict_update(moving, &h, r);
        let mut out = [None; L];
        for (l, step) in lanes.iter().enumerate() {
            if step.measurement.is_some() {
                for i in 0..N {
                    x[i][l] += self.factors.gain[i][l] * nu[l];
                }
                out[l] = Some(Innovation {
                    value: nu[l],
                    variance: variance[l],
                });
            }
        }
        self.x = x;
        Ok(out)
    }

    /// Lane `l`'s mean.
    pub fn state(&self, l: usize) -> [f64; N] {
        std::array::from_fn(|i| self.x[i][l])
    }

    /// Lane `l`'s upper factor into `out` (column-major `N × N`, zeros
    /// below the diagonal).
    pub fn factor_into(&self, l: usize, out: &mut [f64]) {
        for j in 0..N {
            for i in 0..N {
                out[i + j * N] = if i <= j { self.factors.u[j][i][l] } else { 0.0 };
            }
        }
    }

    /// Lane `l`'s Kalman gain of its last measurement
    /// ([`super::SqrtKalmanFilter::last_gain`]).
    pub fn gain(&self, l: usize) -> [f64; N] {
        self.factors.gain(l)
    }
}

/// `U ← tri([G, Φ U])` in every moving lane: [`super::SqrtKalmanFilter::predict`]'s
/// arithmetic (`propagate_impl` with the pair triangularisation), lane by
/// lane. `G` is triangularised in place (each step brings its own).
pub(super) struct Predict<'a, const N: usize, const W: usize, const TWO: bool> {
    pub(super) u: &'a mut [[[f64; W]; N]; N],
    pub(super) phi: &'a [[[f64; W]; N]; N],
    pub(super) g: &'a mut [[[f64; W]; N]; N],
    pub(super) moving: [bool; W],
}

impl<const N: usize, const W: usize, const TWO: bool> aeromag_core::simd::Kernel
    for Predict<'_, N, W, TWO>
{
    type Output = ();
    #[inline(always)]
    fn run(self) {
        // The second chain's first state (N: none).
        let split = if TWO { N - 2 } else { N };
        // [B, A] = [G, Φ U], row-major: b[i][j], a[i][j].
        let b = self.g;
        let mut a = [[[0.0; W]; N]; N];
        // A = Φ U: each entry summed over l ascending from +0 (the sparse
        // sum's order; the zeros of Φ add nothing).
        for k in 0..N {
            // Φ is zero between the chains.
            let from = if k >= split { split } else { 0 };
            for i in from..=k {
                let p = self.phi[i][k];
                for j in k..N {
                    let ukj = self.u[j][k];
                    for l in 0..W {
                        a[i][j][l] += p[l] * ukj[l];
                    }
                }
            }
        }
        // Rows from the last: the reflection of row i acts on B[:, i..N]
        // and the pivot column A[:, i].
        for i in (0..N).rev() {
            let pivot = a[i][i];
            let mut off2 = [0.0; W];
            for j in i..N {
                for l in 0..W {
                    off2[l] += b[i][j][l] * b[i][j][l];
                }
            }
            let mut reflect = [false; W];
            let mut alpha = [0.0; W];
            let mut vp = [0.0; W];
            let mut beta = [0.0; W];
            for l in 0..W {
                reflect[l] = off2[l] > 0.0;
                let norm = (off2[l] + pivot[l] * pivot[l]).sqrt();
                alpha[l] = if pivot[l] >= 0.0 { -norm } else { norm };
                vp[l] = pivot[l] - alpha[l];
                beta[l] = 2.0 / (off2[l] + vp[l] * vp[l]);
            }
            let vb = b[i];
            for r in 0..i {
                let mut t = [0.0; W];
                for l in 0..W {
                    t[l] = a[r][i][l] * vp[l];
                }
                for j in i..N {
                    for l in 0..W {
                        t[l] += b[r][j][l] * vb[j][l];
                    }
                }
                let mut bt = [0.0; W];
                for l in 0..W {
                    bt[l] = beta[l] * t[l];
                }
                for j in i..N {
                    for l in 0..W {
                        let v = b[r][j][l] - bt[l] * vb[j][l];
                        b[r][j][l] = if reflect[l] { v } else { b[r][j][l] };
                    }
                }
                for l in 0..W {
                    let v = a[r][i][l] - bt[l] * vp[l];
                    a[r][i][l] = if reflect[l] { v } else { a[r][i][l] };
                }
            }
            for l in 0..W {
                if reflect[l] {
                    a[i][i][l] = alpha[l];
                }
                // A non-negative diagonal (a sign flip of the column).
                if a[i][i][l] < 0.0 {
                    a[i][i][l] = -a[i][i][l];
                    for row in a.iter_mut().take(i) {
                        row[i][l] = -row[i][l];
                    }
                }
            }
        }
        for j in 0..N {
            for i in 0..=j {
                for l in 0..W {
                    if self.moving[l] {
                        self.u[j][i][l] = a[i][j][l];
                    }
                }
            }
        }
    }
}

/// Carlson's update of every lane ([`super::carlson::carlson_update`]'s
/// arithmetic, the state mean left out: it is zero in an augmented filter);
/// returns the innovation variances.
struct Update<'a, const N: usize, const W: usize, const TWO: bool> {
    u: &'a mut [[[f64; W]; N]; N],
    gain: &'a mut [[f64; W]; N],
    h: &'a [[f64; W]; N],
    r: [f64; W],
}

impl<const N: usize, const W: usize, const TWO: bool> aeromag_core::simd::Kernel
    for Update<'_, N, W, TWO>
{
    type Output = [f64; W];
    #[inline(always)]
    fn run(self) -> [f64; W] {
        // The second chain's first state (N: none).
        let split = if TWO { N - 2 } else { N };
        // f = Uᵀh, each summed over its rows in order (h is zero but at
        // the chains' heads).
        let mut f = [[0.0; W]; N];
        for (j, fj) in f.iter_mut().enumerate() {
            for i in 0..=j {
                if TWO && i != 0 && i != split {
                    continue;
                }
                for l in 0..W {
                    fj[l] += self.u[j][i][l] * self.h[i][l];
                }
            }
        }
        let mut alpha = self.r;
        let mut eta = [[0.0; W]; N];
        let mut zeta = [[0.0; W]; N];
        for j in 0..N {
            for l in 0..W {
                let beta = alpha[l];
                alpha[l] += f[j][l] * f[j][l];
                let inv_gamma = 1.0 / (alpha[l] * beta).sqrt();
                eta[j][l] = beta * inv_gamma;
                zeta[j][l] = f[j][l] * inv_gamma;
            }
        }
        let mut k = [[0.0; W]; N];
        for j in 0..N {
            for i in 0..=j {
                for l in 0..W {
                    let a = self.u[j][i][l];
                    let moves = f[j][l] != 0.0;
                    let s = eta[j][l] * a - zeta[j][l] * k[i][l];
                    let ki = k[i][l] + f[j][l] * a;
                    self.u[j][i][l] = if moves { s } else { a };
                    k[i][l] = if moves { ki } else { k[i][l] };
                }
            }
        }
        for i in 0..N {
            for l in 0..W {
                self.gain[i][l] = k[i][l] * (1.0 / alpha[l]);
            }
        }
        alpha
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rnd(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((*seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    }

    /// `Φ` and `G` (upper triangular) of chains of integrators over a
    /// random step (0 when `k % 37 == 5`: `Φ = I` and `G = 0`, no
    /// reflection); with `two`, two chains (states `0..N−2` and `N−2..N`).
    fn lane_transition<const N: usize>(
        seed: &mut u64,
        k: usize,
        two: bool,
    ) -> (DMatrix<f64>, DMatrix<f64>) {
        let d = if k % 37 == 5 { 0.0 } else { 0.5 + rnd(seed) };
        let cross = |i: usize, j: usize| two && i < N - 2 && j >= N - 2;
        let phi = DMatrix::from_fn(N, N, |i, j| {
            if i == j {
                1.0
            } else if i < j && !cross(i, j) {
                d.powi((j - i) as i32) / (1 + j - i) as f64
            } else {
                0.0
            }
        });
        let g = DMatrix::from_fn(N, N, |i, j| {
            if i <= j && !cross(i, j) {
                0.05 * d * (1.0 + 0.1 * (i + 2 * j) as f64)
            } else {
                0.0
            }
        });
        (phi, g)
    }

    /// A measurement row reading the first state and (with `two`, the
    /// head of the second chain, else the last state), that one exactly
    /// zero when `k % 11 == 0`.
    fn lane_row<const N: usize>(seed: &mut u64, k: usize, two: bool) -> Vec<f64> {
        let mut h = vec![0.0; N];
        h[0] = 1.0 + 0.5 * rnd(seed);
        h[if two { N - 2 } else { N - 1 }] = if k.is_multiple_of(11) { 0.0 } else { rnd(seed) };
        h
    }

    /// Four lanes with their own transitions, rows, run starts and idle
    /// steps: each lane's filter is bit for bit the filter stepped alone.
    /// With `two`, Φ, G and h are two chains (states `0..N−2` and
    /// `N−2..N`, read at their heads: the kernels that skip the zeros).
    fn lanes_equal_filters_alone<const N: usize>(two: bool) {
        let mut seed = 11 + N as u64 + two as u64;
        // A diagonal prior: at each run start `f_j = 0` for the states the
        // row does not see (Carlson leaves those columns alone).
        let s0 = DMatrix::from_fn(N, N, |i, j| if i == j { 2.0 / (1 + i) as f64 } else { 0.0 });
        let m = 7;
        let prior_mean: Vec<f64> = (0..m).map(|j| 0.1 * j as f64).collect();
        let prior_std = vec![30.0; m];
        let template = AugmentedFilter::new(&s0, &prior_mean, &prior_std).unwrap();
        let mut lanes = AugmentedLanes::<N>::new(&s0, &prior_mean, &prior_std).unwrap();
        let mut alone: Vec<AugmentedFilter> = (0..L).map(|_| template.clone()).collect();
        // Per lane and step: a transition, a run start or idle.
        let r = 0.03;
        for k in 0..900 {
            let mut mats = Vec::new();
            let mut plan = Vec::new();
            for l in 0..L {
                mats.push(lane_transition::<N>(&mut seed, k + l, two));
                let what = if k == 0 || (k + 3 * l) % 250 == 0 {
                    1
                } else if l == 3 && k > 700 {
                    0 // idle at the end
                } else {
                    2
                };
                let h = lane_row::<N>(&mut seed, k + l, two);
                let z: Vec<f64> = (0..m).map(|_| 10.0 * rnd(&mut seed)).collect();
                let y = 3.0 * rnd(&mut seed) + z[0] - 0.5 * z[3];
                plan.push((what, h, z, y));
            }
            let steps: [LaneStep; L] = std::array::from_fn(|l| {
                let (what, h, z, y) = &plan[l];
                let reading = Reading { h, z, y: *y };
                match what {
                    0 => LaneStep::Idle,
                    1 => LaneStep::Start(reading),
                    _ => LaneStep::Next {
                        phi: &mats[l].0,
                        g: &mats[l].1,
                        reading,
                    },
                }
            });
            lanes.step(steps, r).unwrap();
            for (l, f) in alone.iter_mut().enumerate() {
                let (what, h, z, y) = &plan[l];
                match what {
                    0 => continue,
                    1 => f.start_run().unwrap(),
                    _ => f.predict(&mats[l].0, &mats[l].1).unwrap(),
                }
                f.update(h, z, *y, r).unwrap();
                if k % 97 == 0 {
                    assert_eq!(
                        lanes.conditional(l),
                        f.conditional(),
                        "N {N}, lane {l}, step {k}"
                    );
                }
            }
        }
        for (l, f) in alone.iter_mut().enumerate() {
            let mut lane = lanes.take(l).unwrap();
            let (a, b) = (lane.conditional(), f.conditional());
            let bits = |m: &DMatrix<f64>| m.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&a.factor), bits(&b.factor), "N {N}, lane {l}: factor");
            assert_eq!(bits(&a.weight), bits(&b.weight), "N {N}, lane {l}: states");
            assert_eq!(
                lane.log_likelihood().unwrap().to_bits(),
                f.log_likelihood().unwrap().to_bits(),
                "N {N}, lane {l}: likelihood"
            );
        }
        // A lane taken is fresh again.
        let again = lanes.take(0).unwrap().conditional();
        let fresh = template.conditional();
        assert_eq!(again, fresh);
        assert!(again.weight.iter().all(|v| *v == 0.0));
    }

    #[test]
    fn each_lane_is_its_filter_alone_bit_for_bit() {
        for two in [false, true] {
            lanes_equal_filters_alone::<5>(two);
            lanes_equal_filters_alone::<6>(two);
            lanes_equal_filters_alone::<8>(two);
        }
    }

    /// The two-chain kernels leave out products with structural zeros: the
    /// factors, gains and variances are the dense kernels' to the bit.
    #[test]
    fn two_chain_kernels_are_the_dense_kernels_bit_for_bit() {
        use aeromag_core::simd::Kernel;
        const N: usize = 8;
        let mut seed = 5;
        let cross = |i: usize, j: usize| i < N - 2 && j >= N - 2;
        for round in 0..200 {
            let mut u = [[[0.0; L]; N]; N];
            let (mut phi, mut g) = (u, u);
            let mut h = [[0.0; L]; N];
            for j in 0..N {
                for i in 0..=j {
                    for l in 0..L {
                        u[j][i][l] = rnd(&mut seed) + if i == j { 1.0 } else { 0.0 };
                        if !cross(i, j) {
                            phi[i][j][l] = rnd(&mut seed);
                            g[i][j][l] = 0.1 * rnd(&mut seed);
                        }
                    }
                }
            }
            for l in 0..L {
                h[0][l] = 1.0;
                // Some rows read the B_z chain at exactly zero.
                h[N - 2][l] = if (round + l) % 7 == 0 {
                    0.0
                } else {
                    rnd(&mut seed)
                };
            }
            let moving = [true, true, round % 3 != 0, true];
            let (mut a, mut b) = (u, u);
            let (mut ga, mut gb) = (g, g);
            Predict::<N, L, true> {
                u: &mut a,
                phi: &phi,
                g: &mut ga,
                moving,
            }
            .run();
            Predict::<N, L, false> {
                u: &mut b,
                phi: &phi,
                g: &mut gb,
                moving,
            }
            .run();
            let bits = |x: &[[[f64; L]; N]; N]| {
                x.as_flattened()
                    .as_flattened()
                    .iter()
                    .map(|v| v.to_bits())
                    .collect::<Vec<_>>()
            };
            assert_eq!(bits(&a), bits(&b), "predict, round {round}");
            let (mut ga, mut gb) = ([[0.0; L]; N], [[0.0; L]; N]);
            let r = [0.03, 0.1, 1.0, 0.5];
            let va = Update::<N, L, true> {
                u: &mut a,
                gain: &mut ga,
                h: &h,
                r,
            }
            .run();
            let vb = Update::<N, L, false> {
                u: &mut b,
                gain: &mut gb,
                h: &h,
                r,
            }
            .run();
            assert_eq!(bits(&a), bits(&b), "update, round {round}");
            assert_eq!(va.map(f64::to_bits), vb.map(f64::to_bits));
            assert_eq!(
                ga.as_flattened()
                    .iter()
                    .map(|v| v.to_bits())
                    .collect::<Vec<_>>(),
                gb.as_flattened()
                    .iter()
                    .map(|v| v.to_bits())
                    .collect::<Vec<_>>()
            );
        }
    }

    /// Four plain filters with their own transitions, rows, restarts,
    /// steps without a time update or a measurement and idle steps: each
    /// lane's mean, factor, gain and innovation are bit for bit those of
    /// its [`super::super::SqrtKalmanFilter`] stepped alone.
    fn filter_lanes_equal_filters_alone<const N: usize>(two: bool) {
        use super::super::SqrtKalmanFilter;
        let mut seed = 29 + N as u64 + two as u64;
        let s0 = DMatrix::from_fn(N, N, |i, j| {
            if i <= j {
                1.0 / (1 + i + j) as f64
            } else {
                0.0
            }
        });
        let x0: Vec<f64> = (0..N).map(|i| 0.3 * i as f64 - 1.0).collect();
        let mut lanes = FilterLanes::<N>::new();
        let mut alone: Vec<SqrtKalmanFilter> = (0..L)
            .map(|_| SqrtKalmanFilter::new(&x0, &s0).unwrap())
            .collect();
        for l in 0..L {
            lanes.set(l, &x0, &s0).unwrap();
        }
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        for k in 0..600 {
            let mut mats = Vec::new();
            let mut rows = Vec::new();
            let mut plan = Vec::new();
            for l in 0..L {
                mats.push(lane_transition::<N>(&mut seed, k + l, two));
                let h = lane_row::<N>(&mut seed, k + l, two);
                rows.push(h);
                // 0: idle, 1: measurement only, 2: time update only, 3: both.
                let what = if l == 2 && (300..320).contains(&k) {
                    0
                } else if (k + l) % 13 == 0 {
                    1
                } else if (k + 2 * l) % 17 == 0 {
                    2
                } else {
                    3
                };
                plan.push((what, 3.0 * rnd(&mut seed), 0.01 + 0.1 * (l as f64)));
            }
            if k == 450 {
                // A restart of lane 1 from another estimate.
                let s = DMatrix::from_fn(N, N, |i, j| {
                    if i <= j {
                        0.5 + 0.1 * (i * j) as f64
                    } else {
                        0.0
                    }
                });
                lanes.set(1, &vec![2.0; N], &s).unwrap();
                alone[1].set(&vec![2.0; N], &s).unwrap();
            }
            let steps: [FilterStep; L] = std::array::from_fn(|l| {
                let (what, y, r) = plan[l];
                FilterStep {
                    predict: (what >= 2).then_some((&mats[l].0, &mats[l].1)),
                    measurement: (what == 1 || what == 3).then_some((&rows[l][..], y, r)),
                }
            });
            let got = lanes.step(steps).unwrap();
            for (l, f) in alone.iter_mut().enumerate() {
                let (what, y, r) = plan[l];
                if what >= 2 {
                    f.predict(&mats[l].0, &mats[l].1).unwrap();
                }
                if what == 1 || what == 3 {
                    let inn = f.update(&rows[l], y, r).unwrap();
                    let lane = got[l].expect("a measuring lane has an innovation");
                    assert_eq!(
                        (lane.value.to_bits(), lane.variance.to_bits()),
                        (inn.value.to_bits(), inn.variance.to_bits()),
                        "N {N}, lane {l}, step {k}: innovation"
                    );
                    assert_eq!(
                        bits(&lanes.gain(l)),
                        bits(f.last_gain()),
                        "N {N}, lane {l}, step {k}: gain"
                    );
                } else {
                    assert!(got[l].is_none());
                }
                assert_eq!(
                    bits(&lanes.state(l)),
                    bits(f.state().as_slice()),
                    "N {N}, lane {l}, step {k}: mean"
                );
                let mut s = vec![0.0; N * N];
                lanes.factor_into(l, &mut s);
                assert_eq!(
                    bits(&s),
                    bits(f.factor().as_slice()),
                    "N {N}, lane {l}, step {k}: factor"
                );
            }
        }
        // Refused: a lower Φ, a bad reading; nothing changes.
        let before = (lanes.state(0), lanes.gain(0));
        let lower = DMatrix::from_fn(N, N, |i, j| if i >= j { 1.0 } else { 0.0 });
        let g = DMatrix::zeros(N, N);
        let h = vec![1.0; N];
        let refused = [
            FilterStep {
                predict: Some((&lower, &g)),
                measurement: None,
            },
            FilterStep {
                predict: None,
                measurement: Some((&h, f64::NAN, 1.0)),
            },
            FilterStep {
                predict: None,
                measurement: Some((&h, 1.0, 0.0)),
            },
        ];
        for first in refused {
            let idle = FilterStep::default();
            assert!(lanes.step([first, idle, idle, idle]).is_err());
        }
        assert_eq!((lanes.state(0), lanes.gain(0)), before);
    }

    #[test]
    fn filter_lanes_are_filters_alone_bit_for_bit() {
        for two in [false, true] {
            filter_lanes_equal_filters_alone::<5>(two);
            filter_lanes_equal_filters_alone::<6>(two);
            filter_lanes_equal_filters_alone::<8>(two);
        }
    }

    #[test]
    fn bad_rows_and_lower_transitions_are_errors() {
        let s0 = DMatrix::identity(2, 2);
        let mut lanes = AugmentedLanes::<2>::new(&s0, &[0.0], &[1.0]).unwrap();
        assert!(AugmentedLanes::<3>::new(&s0, &[0.0], &[1.0]).is_err());
        let h = [1.0, 0.0];
        let ok = Reading {
            h: &h,
            z: &[1.0],
            y: 0.5,
        };
        let nan = Reading { y: f64::NAN, ..ok };
        let idle = LaneStep::Idle;
        assert!(
            lanes
                .step([LaneStep::Start(ok), idle, idle, idle], 1.0)
                .is_ok()
        );
        assert!(
            lanes
                .step([LaneStep::Start(nan), idle, idle, idle], 1.0)
                .is_err()
        );
        assert!(
            lanes
                .step([LaneStep::Start(ok), idle, idle, idle], 0.0)
                .is_err()
        );
        let lower = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.5, 1.0]);
        let g = DMatrix::zeros(2, 2);
        let next = LaneStep::Next {
            phi: &lower,
            g: &g,
            reading: ok,
        };
        assert!(lanes.step([next, idle, idle, idle], 1.0).is_err());
    }
}
