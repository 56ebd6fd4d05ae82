//! Fixed-interval smoothing of a whole record with checkpointing: the
//! square-root filter forward, the square-root RTS smoother (or, for the
//! means alone, the modified Bryson–Frazier recursion) backward, in
//! `O(√N · n²)` memory instead of `O(N · n²)`.
//!
//! The RTS backward step at `k` needs the filtered estimate at `k`, the
//! smoother gain `C_k` and the prediction `x⁻_{k+1}`. Storing them for every
//! step costs `N (n² + 2n)` numbers (1.6 GB for `N = 10⁷`, `n = 5`). Instead:
//!
//! 1. **forward** ([`filter_checkpoints`]): run the filter over all `N`
//!    steps, report the innovations and the log-likelihood, and keep only a
//!    [`Checkpoint`] (the filtered `(x, S)`) every `L` steps;
//! 2. **backward** ([`smooth_from_checkpoints`]), block by block from the
//!    last: restart the filter from the checkpoint before the block, re-run it
//!    over the block, then run backward through the block, starting from
//!    what the following block carried over:
//!    * with covariances, the square-root RTS steps ([`super::rts`]): the
//!      re-run stores `(x_k, S_k, C_k, x⁻_{k+1})` and the smoothed estimate
//!      is carried over;
//!    * means only, the modified Bryson–Frazier recursion ([`super::mbf`]):
//!      the re-run stores `(x_k, S_k)` and the update `(h_k, K_k, ν_k/α_k)`,
//!      the adjoint `λ` is carried over, and no smoother gain (two
//!      triangular solves per step) is formed. Same means up to round-off
//!      (tested), at a fraction of the backward cost.
//!
//! The re-run repeats exactly the same floating-point operations from an
//! exact copy of the state, so the result is bit-identical whatever `L`
//! (tested). The re-runs of different blocks are independent: for the
//! means of 5, 6 or 8 states they run four blocks at a time in SIMD lanes
//! ([`super::FilterLanes`], bit for bit the filter alone; test
//! `smoothing_in_lanes_is_block_by_block_bit_for_bit`). On the field model
//! of order 6 (10⁵ samples in runs of 900, one thread,
//! `cargo bench -p aeromag-compensation --bench smoother`) the smoother
//! took 60–64 ms against 85–91 ms block by block (three alternating
//! criterion runs each, AMD EPYC, 2026-12-02). Cost: two forward passes
//! plus one backward pass; memory
//! `(N/L + L)(n² + 2n)` numbers, minimal near `L = √N` (the default).
//! Checkpoints may also come from elsewhere — for example from the
//! conditional distribution of a larger filter
//! ([`super::SqrtKalmanFilter::leading_conditional`]) — which saves the first
//! forward pass. This is the classical checkpointing of adjoint/backward
//! sweeps (A. Griewank, "Achieving logarithmic growth of temporal and spatial
//! complexity in reverse automatic differentiation", *Optim. Methods Softw.*
//! 1 (1992) 35–54), applied to the RTS recursion.

use super::filter::SqrtKalmanFilter;
use super::innovation::Innovation;
use super::lanes::{FILTER_LANES, FilterLanes, FilterStep};
use super::mbf::{MbfAdjoint, MbfUpdate};
use super::rts::SqrtRts;
use crate::error::{EstError, Result};
use nalgebra::DMatrix;

/// A linear-Gaussian state-space model over steps `0..steps()`:
///
/// ```text
/// x_0 ~ N(x̄_0, S_0 S_0ᵀ),   x_k = Φ_k x_{k−1} + G_k w_k (k ≥ 1),   y_k = h_kᵀ x_k + v_k,  v_k ~ N(0, r_k)
/// ```
pub trait StateSpaceModel {
    /// Number of states `n`.
    fn dim(&self) -> usize;
    /// Number of steps `N`.
    fn steps(&self) -> usize;
    /// The prior at step 0 (before its measurement): mean into `x0`
    /// (length `n`), upper-triangular factor into `s0` (`n × n`).
    fn prior(&self, x0: &mut [f64], s0: &mut DMatrix<f64>);
    /// The number of columns `q` of every `G_k`.
    fn noise_dim(&self) -> usize;
    /// The transition from step `k − 1` to `k` (`k ≥ 1`): `Φ_k` into `phi`
    /// (`n × n`) and the noise factor `G_k` into `g` (`n × q`).
    fn transition(&self, k: usize, phi: &mut DMatrix<f64>, g: &mut DMatrix<f64>);
    /// The scalar measurement at step `k`: fill `h` (length `n`) and return
    /// `Some((y, r))`, or `None` when step `k` has no measurement.
    fn measurement(&self, k: usize, h: &mut [f64]) -> Option<(f64, f64)>;
}

/// The filtered estimate at a step (after its measurement): enough to
/// restart the filter there.
#[derive(Debug, Clone, PartialEq)]
pub struct Checkpoint {
    /// The step.
    pub step: usize,
    /// Filtered mean (length `n`).
    pub mean: Vec<f64>,
    /// Filtered upper-triangular factor (`n × n`).
    pub factor: DMatrix<f64>,
}

/// Settings of [`fixed_interval_smooth`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SmootherOptions {
    /// Steps per checkpoint block `L`; 0 chooses [`default_block_len`].
    pub block_len: usize,
    /// Whether to compute the smoothed covariance factors (costs one more
    /// `n × (2n+q)` triangularisation per step).
    pub covariance: bool,
}

/// The default checkpoint interval for `steps` steps: `max(64, ⌈√N⌉)`.
pub fn default_block_len(steps: usize) -> usize {
    ((steps as f64).sqrt().ceil() as usize).max(64)
}

/// Work buffers of one model size.
struct Buffers {
    phi: DMatrix<f64>,
    g: DMatrix<f64>,
    h: Vec<f64>,
    x0: Vec<f64>,
    s0: DMatrix<f64>,
}

impl Buffers {
    fn new<M: StateSpaceModel>(model: &M) -> Self {
        let (n, q) = (model.dim(), model.noise_dim());
        let mut b = Self {
            phi: DMatrix::zeros(n, n),
            g: DMatrix::zeros(n, q),
            h: vec![0.0; n],
            x0: vec![0.0; n],
            s0: DMatrix::zeros(n, n),
        };
        model.prior(&mut b.x0, &mut b.s0);
        b
    }
}

/// Forward pass: filter the record, call `on_innovation(k, ν)` for every
/// measurement, keep a [`Checkpoint`] after every `every` steps (never after
/// the last step). Returns the log-likelihood and the checkpoints.
pub fn filter_checkpoints<M: StateSpaceModel>(
    model: &M,
    every: usize,
    mut on_innovation: impl FnMut(usize, &Innovation),
) -> Result<(f64, Vec<Checkpoint>)> {
    let big_n = model.steps();
    let every = every.max(1);
    let mut b = Buffers::new(model);
    let mut filter = SqrtKalmanFilter::new(&b.x0, &b.s0)?;
    let mut checkpoints = Vec::with_capacity(big_n / every);
    let mut log_lik = 0.0;
    for k in 0..big_n {
        if k > 0 {
            model.transition(k, &mut b.phi, &mut b.g);
            filter.predict(&b.phi, &b.g).map_err(|e| at_step(e, k))?;
        }
        if let Some((y, r)) = model.measurement(k, &mut b.h) {
            let inn = filter.update(&b.h, y, r).map_err(|e| at_step(e, k))?;
            log_lik += inn.log_likelihood();
            on_innovation(k, &inn);
        }
        if (k + 1) % every == 0 && k + 1 < big_n {
            checkpoints.push(Checkpoint {
                step: k,
                mean: filter.state().as_slice().to_vec(),
                factor: filter.factor().clone(),
            });
        }
    }
    Ok((log_lik, checkpoints))
}

/// Backward pass from checkpoints (module docs): `checkpoints` must have
/// strictly increasing steps `< N − 1` and hold the filtered estimates of
/// this model at those steps. Calls `on_smoothed(k, x^s_k, S^s_k)` for
/// `k = N−1` down to `0` (the factor only with `covariance`).
pub fn smooth_from_checkpoints<M: StateSpaceModel>(
    model: &M,
    checkpoints: &[Checkpoint],
    covariance: bool,
    mut on_smoothed: impl FnMut(usize, &[f64], Option<&DMatrix<f64>>),
) -> Result<()> {
    let n = model.dim();
    let big_n = model.steps();
    if big_n == 0 {
        return Ok(());
    }
    let (starts, ends, l) = blocks(checkpoints, n, big_n)?;
    if !covariance {
        return smooth_means(model, checkpoints, &starts, &ends, l, true, on_smoothed);
    }
    let mut b = Buffers::new(model);
    let mut filter = SqrtKalmanFilter::new(&b.x0, &b.s0)?;
    let mut rts = SqrtRts::new(n);
    let mut xf = vec![0.0; l * n];
    let mut xp = vec![0.0; l * n];
    let mut cs: Vec<DMatrix<f64>> = (0..l).map(|_| DMatrix::zeros(n, n)).collect();
    let mut sf: Vec<DMatrix<f64>> = if covariance {
        (0..l).map(|_| DMatrix::zeros(n, n)).collect()
    } else {
        Vec::new()
    };
    let mut s_prev = DMatrix::zeros(n, n);
    let mut x_next = vec![0.0; n];
    let mut s_next = DMatrix::zeros(n, n);
    let mut x_s = vec![0.0; n];
    let mut s_s = DMatrix::zeros(n, n);
    for blk in (0..starts.len()).rev() {
        let (k0, k1) = (starts[blk], ends[blk]);
        restart(&mut filter, &b, checkpoints, blk)?;
        for k in k0..k1 {
            if k > 0 {
                model.transition(k, &mut b.phi, &mut b.g);
                s_prev.copy_from(filter.factor());
                filter.predict(&b.phi, &b.g).map_err(|e| at_step(e, k))?;
                if k > k0 {
                    let i = k - 1 - k0;
                    rts.gain(&s_prev, &b.phi, filter.factor(), &mut cs[i])
                        .map_err(|e| at_step(e, k))?;
                    xp[i * n..(i + 1) * n].copy_from_slice(filter.state().as_slice());
                }
            }
            if let Some((y, r)) = model.measurement(k, &mut b.h) {
                filter.update(&b.h, y, r).map_err(|e| at_step(e, k))?;
            }
            let i = k - k0;
            xf[i * n..(i + 1) * n].copy_from_slice(filter.state().as_slice());
            if covariance {
                sf[i].copy_from(filter.factor());
            }
        }
        if k1 < big_n {
            // Gain of the block's last step towards the next block.
            model.transition(k1, &mut b.phi, &mut b.g);
            s_prev.copy_from(filter.factor());
            filter.predict(&b.phi, &b.g).map_err(|e| at_step(e, k1))?;
            let i = k1 - 1 - k0;
            rts.gain(&s_prev, &b.phi, filter.factor(), &mut cs[i])
                .map_err(|e| at_step(e, k1))?;
            xp[i * n..(i + 1) * n].copy_from_slice(filter.state().as_slice());
        }
        for k in (k0..k1).rev() {
            let i = k - k0;
            if k == big_n - 1 {
                x_s.copy_from_slice(&xf[i * n..(i + 1) * n]);
                if covariance {
                    s_s.copy_from(&sf[i]);
                }
            } else {
                rts.mean(
                    &xf[i * n..(i + 1) * n],
                    &cs[i],
                    &x_next,
                    &xp[i * n..(i + 1) * n],
                    &mut x_s,
                );
                if covariance {
                    model.transition(k + 1, &mut b.phi, &mut b.g);
                    rts.factor(&sf[i], &cs[i], &b.phi, &b.g, &s_next, &mut s_s)?;
                }
            }
            on_smoothed(k, &x_s, if covariance { Some(&s_s) } else { None });
            x_next.copy_from_slice(&x_s);
            if covariance {
                s_next.copy_from(&s_s);
            }
        }
    }
    Ok(())
}

/// Put the filter at the start of block `blk` ([`block_start`]).
fn restart(
    filter: &mut SqrtKalmanFilter,
    b: &Buffers,
    checkpoints: &[Checkpoint],
    blk: usize,
) -> Result<()> {
    let (x, s) = block_start(b, checkpoints, blk);
    filter.set(x, s)
}

/// The filtered estimate block `blk` starts from: the prior for the first
/// block, else the checkpoint before it.
fn block_start<'a>(
    b: &'a Buffers,
    checkpoints: &'a [Checkpoint],
    blk: usize,
) -> (&'a [f64], &'a DMatrix<f64>) {
    match blk.checked_sub(1) {
        None => (&b.x0, &b.s0),
        Some(c) => (&checkpoints[c].mean, &checkpoints[c].factor),
    }
}

/// The blocks between checkpoints: block `b` covers `[starts[b], ends[b])`
/// (`starts[0] = 0`, `starts[b+1] = checkpoints[b].step + 1`), and the
/// longest block's length. Error if the checkpoints are out of order, out of
/// range or of another size.
fn blocks(
    checkpoints: &[Checkpoint],
    n: usize,
    big_n: usize,
) -> Result<(Vec<usize>, Vec<usize>, usize)> {
    let mut starts = vec![0usize];
    for (i, c) in checkpoints.iter().enumerate() {
        if c.step + 1 >= big_n
            || c.step < *starts.last().unwrap_or(&0)
            || c.mean.len() != n
            || c.factor.shape() != (n, n)
        {
            return Err(EstError::Dimension(format!(
                "checkpoint {i} (step {}) is out of order, out of range or of another size",
                c.step
            )));
        }
        starts.push(c.step + 1);
    }
    let ends: Vec<usize> = starts
        .iter()
        .skip(1)
        .copied()
        .chain(std::iter::once(big_n))
        .collect();
    let l = starts
        .iter()
        .zip(&ends)
        .map(|(s, e)| e - s)
        .max()
        .unwrap_or(1);
    Ok((starts, ends, l))
}

/// The means only ([`smooth_from_checkpoints`] without covariances), by the
/// modified Bryson–Frazier recursion ([`super::mbf`]): per block, the filter
/// is re-run forward storing the filtered `(x_k, S_k)` and its update
/// `(h_k, K_k, ν_k/α_k)`, then the adjoint runs backward through the block,
/// carried over from the following one. No smoother gain is formed.
///
/// The blocks' re-runs are independent (each starts from its checkpoint):
/// for 5, 6 or 8 states with `n` noise columns (the field models), four
/// blocks are re-run together in SIMD lanes ([`FilterLanes`], bit for bit
/// the filter alone), then the adjoint runs back through the four. A batch
/// whose steps the lanes do not take (a `Φ` or `G` not upper triangular, a
/// bad measurement) is re-run block by block, as every block of another
/// size is (and every block without `lanes`), and meets the same error at
/// the same step.
fn smooth_means<M: StateSpaceModel>(
    model: &M,
    checkpoints: &[Checkpoint],
    starts: &[usize],
    ends: &[usize],
    l: usize,
    lanes: bool,
    on_smoothed: impl FnMut(usize, &[f64], Option<&DMatrix<f64>>),
) -> Result<()> {
    let mut run = MeansRun {
        model,
        checkpoints,
        starts,
        ends,
        b: Buffers::new(model),
        adjoint: MbfAdjoint::new(model.dim()),
        x_s: vec![0.0; model.dim()],
        on_smoothed,
    };
    let mut filter = SqrtKalmanFilter::new(&run.b.x0, &run.b.s0)?;
    let n = model.dim();
    match (lanes, n, model.noise_dim()) {
        (true, 5, 5) => run.in_lanes::<5>(&mut filter, l),
        (true, 6, 6) => run.in_lanes::<6>(&mut filter, l),
        (true, 8, 8) => run.in_lanes::<8>(&mut filter, l),
        _ => {
            let mut rec = BlockRecord::new(l, n);
            for blk in (0..starts.len()).rev() {
                run.rerun(&mut filter, blk, &mut rec)?;
                run.backward(blk, &rec);
            }
            Ok(())
        }
    }
}

/// [`smooth_from_checkpoints`] without covariances, every block re-run on
/// its own with the filter alone: the reference of the lanes' re-runs in
/// the tests.
#[cfg(test)]
pub(super) fn smooth_means_block_by_block<M: StateSpaceModel>(
    model: &M,
    checkpoints: &[Checkpoint],
    on_smoothed: impl FnMut(usize, &[f64], Option<&DMatrix<f64>>),
) -> Result<()> {
    let (starts, ends, l) = blocks(checkpoints, model.dim(), model.steps())?;
    smooth_means(model, checkpoints, &starts, &ends, l, false, on_smoothed)
}

/// The forward re-run of one block as the MBF recursion needs it, step
/// `k0 + i` at index `i`: filtered means and factors, and the update (row,
/// gain, `ν/α`) of each step with a measurement.
struct BlockRecord {
    n: usize,
    xf: Vec<f64>,
    sf: Vec<f64>,
    rows: Vec<f64>,
    gains: Vec<f64>,
    weighted: Vec<Option<f64>>,
}

impl BlockRecord {
    fn new(l: usize, n: usize) -> Self {
        Self {
            n,
            xf: vec![0.0; l * n],
            sf: vec![0.0; l * n * n],
            rows: vec![0.0; l * n],
            gains: vec![0.0; l * n],
            weighted: vec![None; l],
        }
    }

    /// Step `i`'s update: `(h, K, ν/α)`, or none.
    fn set_update(&mut self, i: usize, update: Option<(&[f64], &[f64], f64)>) {
        let n = self.n;
        self.weighted[i] = update.map(|(h, gain, w)| {
            self.rows[i * n..(i + 1) * n].copy_from_slice(h);
            self.gains[i * n..(i + 1) * n].copy_from_slice(gain);
            w
        });
    }
}

/// The state of [`smooth_means`]: the model, its blocks and the adjoint
/// carried from block to block.
struct MeansRun<'a, M, F> {
    model: &'a M,
    checkpoints: &'a [Checkpoint],
    starts: &'a [usize],
    ends: &'a [usize],
    b: Buffers,
    adjoint: MbfAdjoint,
    x_s: Vec<f64>,
    on_smoothed: F,
}

impl<M: StateSpaceModel, F: FnMut(usize, &[f64], Option<&DMatrix<f64>>)> MeansRun<'_, M, F> {
    /// Re-run block `blk` forward with `filter` into `rec`.
    fn rerun(
        &mut self,
        filter: &mut SqrtKalmanFilter,
        blk: usize,
        rec: &mut BlockRecord,
    ) -> Result<()> {
        let (model, b, n) = (self.model, &mut self.b, self.model.dim());
        let (k0, k1) = (self.starts[blk], self.ends[blk]);
        restart(filter, b, self.checkpoints, blk)?;
        for k in k0..k1 {
            if k > 0 {
                model.transition(k, &mut b.phi, &mut b.g);
                filter.predict(&b.phi, &b.g).map_err(|e| at_step(e, k))?;
            }
            let i = k - k0;
            let update = match model.measurement(k, &mut b.h) {
                Some((y, r)) => {
                    let inn = filter.update(&b.h, y, r).map_err(|e| at_step(e, k))?;
                    Some((&b.h[..], filter.last_gain(), inn.value / inn.variance))
                }
                None => None,
            };
            rec.set_update(i, update);
            rec.xf[i * n..(i + 1) * n].copy_from_slice(filter.state().as_slice());
            rec.sf[i * n * n..(i + 1) * n * n].copy_from_slice(filter.factor().as_slice());
        }
        Ok(())
    }

    /// The adjoint backward through block `blk` from its record, calling
    /// `on_smoothed` for each step, the last first.
    fn backward(&mut self, blk: usize, rec: &BlockRecord) {
        let (model, b, n) = (self.model, &mut self.b, self.model.dim());
        let big_n = model.steps();
        let k0 = self.starts[blk];
        for k in (k0..self.ends[blk]).rev() {
            let i = k - k0;
            let phi_next = if k + 1 < big_n {
                model.transition(k + 1, &mut b.phi, &mut b.g);
                Some(b.phi.as_slice())
            } else {
                None
            };
            let update = rec.weighted[i].map(|w| MbfUpdate {
                row: &rec.rows[i * n..(i + 1) * n],
                gain: &rec.gains[i * n..(i + 1) * n],
                weighted_innovation: w,
            });
            self.adjoint.step(
                phi_next,
                &rec.xf[i * n..(i + 1) * n],
                &rec.sf[i * n * n..(i + 1) * n * n],
                update,
                &mut self.x_s,
            );
            (self.on_smoothed)(k, &self.x_s, None);
        }
    }

    /// [`smooth_means`] with the blocks re-run four at a time in lanes,
    /// the last four first; a batch the lanes refuse block by block with
    /// `filter`.
    fn in_lanes<const N: usize>(&mut self, filter: &mut SqrtKalmanFilter, l: usize) -> Result<()> {
        let mut lanes = FilterLanes::<N>::new();
        let mut recs: Vec<BlockRecord> =
            (0..FILTER_LANES).map(|_| BlockRecord::new(l, N)).collect();
        let mut phi: [DMatrix<f64>; FILTER_LANES] = std::array::from_fn(|_| DMatrix::zeros(N, N));
        let mut g = phi.clone();
        let mut h = [[0.0; N]; FILTER_LANES];
        let mut blk_end = self.starts.len();
        while blk_end > 0 {
            let first = blk_end.saturating_sub(FILTER_LANES);
            // Lane j re-runs block blk_end − 1 − j.
            let blocks: Vec<usize> = (first..blk_end).rev().collect();
            let in_lanes =
                self.rerun_in_lanes(&mut lanes, &blocks, &mut phi, &mut g, &mut h, &mut recs);
            for (j, &blk) in blocks.iter().enumerate() {
                if in_lanes.is_err() {
                    self.rerun(filter, blk, &mut recs[j])?;
                }
                self.backward(blk, &recs[j]);
            }
            blk_end = first;
        }
        Ok(())
    }

    /// Re-run `blocks` (at most [`FILTER_LANES`]) forward together, block
    /// `blocks[j]` in lane `j`, into `recs[j]`; `phi`, `g` and `h` are each
    /// lane's workspace.
    fn rerun_in_lanes<const N: usize>(
        &mut self,
        lanes: &mut FilterLanes<N>,
        blocks: &[usize],
        phi: &mut [DMatrix<f64>; FILTER_LANES],
        g: &mut [DMatrix<f64>; FILTER_LANES],
        h: &mut [[f64; N]; FILTER_LANES],
        recs: &mut [BlockRecord],
    ) -> Result<()> {
        let model = self.model;
        for (j, &blk) in blocks.iter().enumerate() {
            let (x, s) = block_start(&self.b, self.checkpoints, blk);
            lanes.set(j, x, s)?;
        }
        let len = |j: usize| blocks.get(j).map_or(0, |&b| self.ends[b] - self.starts[b]);
        let longest = (0..blocks.len()).map(len).max().unwrap_or(0);
        for i in 0..longest {
            let mut ry = [None; FILTER_LANES];
            let mut predicts = [false; FILTER_LANES];
            for (j, &blk) in blocks.iter().enumerate() {
                if i >= len(j) {
                    continue;
                }
                let k = self.starts[blk] + i;
                if k > 0 {
                    model.transition(k, &mut phi[j], &mut g[j]);
                    predicts[j] = true;
                }
                ry[j] = model.measurement(k, &mut h[j]);
            }
            let steps: [FilterStep<'_>; FILTER_LANES] = std::array::from_fn(|j| FilterStep {
                predict: predicts[j].then_some((&phi[j], &g[j])),
                measurement: ry[j].map(|(y, r)| (&h[j][..], y, r)),
            });
            let innovations = lanes.step(steps)?;
            for (j, rec) in recs.iter_mut().enumerate().take(blocks.len()) {
                if i >= len(j) {
                    continue;
                }
                let gain = lanes.gain(j);
                rec.set_update(
                    i,
                    innovations[j].map(|inn| (&h[j][..], &gain[..], inn.value / inn.variance)),
                );
                rec.xf[i * N..(i + 1) * N].copy_from_slice(&lanes.state(j));
                lanes.factor_into(j, &mut rec.sf[i * N * N..(i + 1) * N * N]);
            }
        }
        Ok(())
    }
}

/// Filter forward and smooth backward (module docs): [`filter_checkpoints`]
/// then [`smooth_from_checkpoints`].
///
/// `on_innovation(k, ν)` is called in the forward pass for every step with
/// a measurement; `on_smoothed(k, x^s_k, S^s_k)` in the backward pass, for
/// `k = N−1` down to `0` (the factor is `Some` only with
/// [`SmootherOptions::covariance`]). Returns the log-likelihood of the
/// innovations.
pub fn fixed_interval_smooth<M: StateSpaceModel>(
    model: &M,
    opts: &SmootherOptions,
    on_innovation: impl FnMut(usize, &Innovation),
    on_smoothed: impl FnMut(usize, &[f64], Option<&DMatrix<f64>>),
) -> Result<f64> {
    let l = if opts.block_len > 0 {
        opts.block_len
    } else {
        default_block_len(model.steps())
    };
    let (log_lik, checkpoints) = filter_checkpoints(model, l, on_innovation)?;
    smooth_from_checkpoints(model, &checkpoints, opts.covariance, on_smoothed)?;
    Ok(log_lik)
}

fn at_step(e: EstError, k: usize) -> EstError {
    EstError::AtStep {
        step: k,
        source: Box::new(e),
    }
}
