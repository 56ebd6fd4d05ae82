//! Pass 1 without the coefficients in the state: the field filter applied
//! to the reading and to every design column, the coefficients integrated
//! out ([`AugmentedFilter`], de Jong 1991).
//!
//! With the coefficients constant, the joint filter's likelihood, final
//! coefficients, their covariance and the field given the coefficients at
//! any sample (the smoother's restart points) follow from the field filter
//! of `n_f = order + 2` states alone, run on `m + 1` right-hand sides. The
//! coefficients then no longer link the runs: groups of runs are filtered
//! on all cores and their sums added in run order. The noise tuning
//! ([`super::tuning`]) evaluates its likelihood this way, and
//! [`super::fit::CoefficientPass::Augmented`] fits the coefficients this
//! way; what it cannot give on its own is the joint filter's sequential
//! innovations (each made with the coefficients estimated from the samples
//! before): [`super::fit::CoefficientPass::Split`] records its whitened
//! innovations for the coefficients' recursive least squares, which does.
//!
//! [`filter_groups`] filters the groups four at a time in SIMD lanes
//! ([`AugmentedLanes`]: the small square-root factor's updates are chains
//! of square roots and divisions, which four filters fill side by side),
//! every group bit for bit what [`FieldFilter`] gives over it alone.

use super::anomaly_model::{AnomalyTransition, B_H, NoiseModel, StepTransition, X2Prior};
use super::joint_filter::est;
use crate::error::{CompError, Result};
use aeromag_estimation::kalman::{
    AugmentedFilter, AugmentedLanes, FILTER_LANES, LaneStep, LeadingConditional, Reading,
};
use nalgebra::DMatrix;
use std::borrow::Cow;

/// Samples per group of runs filtered on one thread (a fixed partition:
/// the same sums, the same bits, with any number of threads).
pub const SAMPLES_PER_GROUP: usize = 2048;

/// Contiguous groups of runs, each of at least [`SAMPLES_PER_GROUP`]
/// samples (the last may be shorter), from the runs' lengths.
pub fn groups_of_runs(lengths: impl IntoIterator<Item = usize>) -> Vec<std::ops::Range<usize>> {
    let mut groups = Vec::new();
    let (mut from, mut samples, mut count) = (0, 0, 0);
    for len in lengths {
        samples += len;
        count += 1;
        if samples >= SAMPLES_PER_GROUP {
            groups.push(from..count);
            from = count;
            samples = 0;
        }
    }
    if from < count {
        groups.push(from..count);
    }
    groups
}

/// One filter over the groups of runs that `parts` were filtered over, in
/// order (their sums added in that order: the same bits however the groups
/// were shared out). [`CompError::UnusableData`] if there are none.
pub fn merge_in_order(parts: impl IntoIterator<Item = AugmentedFilter>) -> Result<AugmentedFilter> {
    let mut total: Option<AugmentedFilter> = None;
    for mut f in parts {
        match total.as_mut() {
            None => total = Some(f),
            Some(t) => t.merge(&mut f).map_err(est)?,
        }
    }
    total.ok_or_else(|| CompError::data("no usable samples".to_string()))
}

/// The noise intensities and the field prior are usable: a
/// [`CompError::InvalidSetting`] naming the bad one otherwise.
pub fn check_field_model(noise: &NoiseModel, x2_prior: &X2Prior) -> Result<()> {
    if !noise.is_valid() {
        return Err(CompError::setting(format!(
            "invalid noise intensities {noise:?} (q ≥ 0, r > 0, finite)"
        )));
    }
    check_prior(x2_prior)
}

/// A usable field prior: a [`CompError::InvalidSetting`] otherwise.
fn check_prior(x2_prior: &X2Prior) -> Result<()> {
    if !x2_prior.is_valid() {
        return Err(CompError::setting(format!(
            "invalid field prior {x2_prior:?} (positive, finite)"
        )));
    }
    Ok(())
}

/// The field filter over one group of runs: the transition for each step
/// (recomputed only when the step length changes) and the measurement row
/// `h = e_{B^h} + Δz e_{B_z}`.
pub struct FieldFilter {
    filter: AugmentedFilter,
    transition: StepTransition,
    h: Vec<f64>,
    b_z: usize,
    r_nt2: f64,
}

impl FieldFilter {
    /// A filter of `model` (recording its innovations if it says so).
    pub fn new(model: &FieldModelSpec<'_>) -> Result<Self> {
        model.check()?;
        let mut h = vec![0.0; model.x2_prior.dim()];
        h[B_H] = 1.0;
        let mut filter =
            AugmentedFilter::new(&model.x2_prior.factor(), model.coef_mean, model.coef_std)
                .map_err(est)?;
        filter.record_innovations(model.record_innovations);
        Ok(Self {
            filter,
            transition: StepTransition::new(model.transition.clone()),
            h,
            b_z: model.x2_prior.b_z(),
            r_nt2: model.r_nt2,
        })
    }

    /// One sample: a new run starts here (`first`), or the field moves on
    /// by `d_m` metres; then the design row `row`, altitude offset `dz_m`
    /// and centred reading `y_nt`.
    pub fn step(&mut self, first: bool, d_m: f64, row: &[f64], dz_m: f64, y_nt: f64) -> Result<()> {
        if first {
            self.filter.start_run().map_err(est)?;
        } else {
            let (phi, g) = self.transition.step(d_m)?;
            self.filter.predict(phi, g).map_err(est)?;
        }
        self.h[self.b_z] = dz_m;
        self.filter
            .update(&self.h, row, y_nt, self.r_nt2)
            .map_err(est)?;
        Ok(())
    }

    /// [`Self::new`] going on from `filter` (a filter of this model: a lane
    /// of [`AugmentedLanes`] taken mid-group).
    fn resume(filter: AugmentedFilter, model: &FieldModelSpec<'_>) -> Result<Self> {
        let mut f = Self::new(model)?;
        f.filter = filter;
        Ok(f)
    }

    /// The underlying filter (its sums, the field given the coefficients).
    pub fn filter(&self) -> &AugmentedFilter {
        &self.filter
    }

    /// The underlying filter, to merge or solve.
    pub fn into_filter(self) -> AugmentedFilter {
        self.filter
    }
}

/// The samples of one group of runs for [`filter_groups`]: sample `k`
/// starts a run (`first[k]`; sample 0 always does) or moves the field on
/// by `d_m[k]` metres, then has the design row `rows[k m..(k + 1) m]`, the
/// altitude offset `dz_m[k]` and the centred reading `y_nt[k]` (the
/// arguments of [`FieldFilter::step`]); the field given the coefficients
/// is kept after the samples where `keep[k]` (empty: none).
#[derive(Debug, Clone, Default)]
pub struct GroupSamples<'a> {
    /// A run starts at the sample.
    pub first: Cow<'a, [bool]>,
    /// Along-track step from the sample before, m.
    pub d_m: Cow<'a, [f64]>,
    /// The design rows, row after row.
    pub rows: Cow<'a, [f64]>,
    /// Altitude offset from the reference, m.
    pub dz_m: Cow<'a, [f64]>,
    /// The centred reading, nT.
    pub y_nt: Cow<'a, [f64]>,
    /// Keep the field given the coefficients after the sample.
    pub keep: Cow<'a, [bool]>,
}

impl GroupSamples<'_> {
    fn len(&self) -> usize {
        self.y_nt.len()
    }

    /// Sample `k`'s arguments of [`FieldFilter::step`].
    fn at(&self, k: usize, m: usize) -> StepArgs<'_> {
        (
            k == 0 || self.first[k],
            self.d_m[k],
            &self.rows[k * m..(k + 1) * m],
            self.dz_m[k],
            self.y_nt[k],
        )
    }

    fn keeps(&self, k: usize) -> bool {
        self.keep.get(k).copied().unwrap_or(false)
    }
}

/// [`GroupSamples`] built sample by sample.
pub struct OwnedSamples {
    first: Vec<bool>,
    d_m: Vec<f64>,
    rows: Vec<f64>,
    dz_m: Vec<f64>,
    y_nt: Vec<f64>,
    keep: Vec<bool>,
}

impl OwnedSamples {
    /// Room for `len` samples of `m` regressors.
    pub fn with_capacity(len: usize, m: usize) -> Self {
        Self {
            first: Vec::with_capacity(len),
            d_m: Vec::with_capacity(len),
            rows: Vec::with_capacity(len * m),
            dz_m: Vec::with_capacity(len),
            y_nt: Vec::with_capacity(len),
            keep: Vec::with_capacity(len),
        }
    }

    /// One more sample (the fields of [`GroupSamples`]).
    pub fn push(&mut self, first: bool, d_m: f64, row: &[f64], dz_m: f64, y_nt: f64, keep: bool) {
        self.first.push(first);
        self.d_m.push(d_m);
        self.rows.extend_from_slice(row);
        self.dz_m.push(dz_m);
        self.y_nt.push(y_nt);
        self.keep.push(keep);
    }

    /// The samples.
    pub fn into_samples(self) -> GroupSamples<'static> {
        GroupSamples {
            first: Cow::Owned(self.first),
            d_m: Cow::Owned(self.d_m),
            rows: Cow::Owned(self.rows),
            dz_m: Cow::Owned(self.dz_m),
            y_nt: Cow::Owned(self.y_nt),
            keep: Cow::Owned(self.keep),
        }
    }
}

/// The arguments of [`FieldFilter::step`]: `(first, d_m, row, dz_m, y_nt)`.
type StepArgs<'s> = (bool, f64, &'s [f64], f64, f64);

/// A group filtered by [`filter_groups`]: its filter (sums, last state) and
/// the field given the coefficients after each kept sample (index in the
/// group, conditional).
#[derive(Debug, Clone)]
pub struct FilteredGroup {
    /// The filter after the group's last sample.
    pub filter: AugmentedFilter,
    /// `(k, X2 | X1)` after each sample `k` with `keep[k]`.
    pub kept: Vec<(usize, LeadingConditional)>,
    /// With [`FieldModelSpec::record_innovations`], each sample's whitened
    /// innovations ([`AugmentedFilter::take_innovations`]), otherwise empty.
    pub innovations: Vec<f64>,
}

impl FilteredGroup {
    /// The kept conditionals of a group of runs of `lengths` samples each,
    /// run by run (run-local steps), appended to `out`.
    pub fn kept_by_run(
        kept: Vec<(usize, LeadingConditional)>,
        lengths: impl IntoIterator<Item = usize>,
        out: &mut Vec<Vec<(usize, LeadingConditional)>>,
    ) {
        let mut kept = kept.into_iter().peekable();
        let mut offset = 0;
        for len in lengths {
            let mut cps = Vec::new();
            while let Some((k, c)) = kept.next_if(|(k, _)| *k < offset + len) {
                cps.push((k - offset, c));
            }
            out.push(cps);
            offset += len;
        }
    }

    fn of(mut filter: AugmentedFilter, kept: Vec<(usize, LeadingConditional)>) -> Result<Self> {
        let innovations = filter.take_innovations().map_err(est)?;
        Ok(Self {
            filter,
            kept,
            innovations,
        })
    }
}

/// The field filter's model ([`FieldFilter::new`]): the field prior, the
/// transition for the noise intensities in use, the white-noise variance
/// and the coefficients' prior.
pub struct FieldModelSpec<'a> {
    /// The field states' prior.
    pub x2_prior: &'a X2Prior,
    /// The transition for the noise intensities.
    pub transition: &'a AnomalyTransition,
    /// White-noise variance, nT².
    pub r_nt2: f64,
    /// The coefficients' prior means.
    pub coef_mean: &'a [f64],
    /// The coefficients' prior standard deviations.
    pub coef_std: &'a [f64],
    /// Record the innovations ([`FilteredGroup::innovations`]).
    pub record_innovations: bool,
}

impl FieldModelSpec<'_> {
    /// A usable field prior and white-noise variance: a
    /// [`CompError::InvalidSetting`] naming the bad one otherwise.
    fn check(&self) -> Result<()> {
        check_prior(self.x2_prior)?;
        if !(self.r_nt2 > 0.0 && self.r_nt2.is_finite()) {
            return Err(CompError::setting(format!(
                "white-noise variance {} nT² must be finite and > 0",
                self.r_nt2
            )));
        }
        Ok(())
    }
}

/// The field filter ([`FieldFilter`]) over each of `groups` groups of runs
/// (`load(g)`: group `g`'s samples), the groups shared over `threads`
/// threads and, for the field models of orders 3, 4 and 6, filtered four at
/// a time in SIMD lanes ([`AugmentedLanes`]): every group's filter bit for
/// bit [`FieldFilter`]'s over it alone, returned in group order.
pub fn filter_groups<'a>(
    groups: usize,
    threads: usize,
    model: &FieldModelSpec<'_>,
    load: impl Fn(usize) -> Result<GroupSamples<'a>> + Sync,
) -> Result<Vec<FilteredGroup>> {
    model.check()?;
    let threads = threads.clamp(1, groups.max(1));
    let per_thread = aeromag_core::parallel::parallel_map(threads, threads, |t| {
        let mine: Vec<usize> = (t..groups).step_by(threads).collect();
        // Lanes pay for four factors' updates whatever the number of groups
        // in them: worth it from three groups on (measured on one simulated
        // calibration box, 3 groups: one at a time is faster for 1 or 2).
        let lanes = mine.len() >= MIN_GROUPS_FOR_LANES;
        let filtered = match model.x2_prior.dim() {
            5 if lanes => lanes_over::<5>(&mine, model, &load),
            6 if lanes => lanes_over::<6>(&mine, model, &load),
            8 if lanes => lanes_over::<8>(&mine, model, &load),
            _ => mine.iter().map(|&g| one_group(&load(g)?, model)).collect(),
        };
        filtered.map(|f| mine.into_iter().zip(f).collect::<Vec<_>>())
    });
    let mut out: Vec<Option<FilteredGroup>> = (0..groups).map(|_| None).collect();
    for part in per_thread {
        for (g, f) in part? {
            out[g] = Some(f);
        }
    }
    Ok(out
        .into_iter()
        .map(|f| f.expect("every group filtered"))
        .collect())
}

/// Fewest groups a thread filters in lanes ([`filter_groups`]).
const MIN_GROUPS_FOR_LANES: usize = 3;

/// One group with [`FieldFilter`].
fn one_group(samples: &GroupSamples<'_>, model: &FieldModelSpec<'_>) -> Result<FilteredGroup> {
    go_on(
        FieldFilter::new(model)?,
        samples,
        0,
        Vec::new(),
        model.coef_mean.len(),
    )
}

/// The samples `from..` of a group through `f`, the conditionals kept.
fn go_on(
    mut f: FieldFilter,
    samples: &GroupSamples<'_>,
    from: usize,
    mut kept: Vec<(usize, LeadingConditional)>,
    m: usize,
) -> Result<FilteredGroup> {
    for k in from..samples.len() {
        let (first, d, row, dz, y) = samples.at(k, m);
        f.step(first, d, row, dz, y)?;
        if samples.keeps(k) {
            kept.push((k, f.filter().conditional()));
        }
    }
    FilteredGroup::of(f.into_filter(), kept)
}

/// The groups `mine` in four lanes of `N` field states, a lane whose group
/// is done taking the next one.
fn lanes_over<'a, const N: usize>(
    mine: &[usize],
    model: &FieldModelSpec<'_>,
    load: &(impl Fn(usize) -> Result<GroupSamples<'a>> + Sync),
) -> Result<Vec<FilteredGroup>> {
    let m = model.coef_mean.len();
    let mut lanes =
        AugmentedLanes::<N>::new(&model.x2_prior.factor(), model.coef_mean, model.coef_std)
            .map_err(est)?;
    lanes.record_innovations(model.record_innovations);
    let mut transitions: Vec<StepTransition> = (0..FILTER_LANES)
        .map(|_| StepTransition::new(model.transition.clone()))
        .collect();
    let b_z = model.x2_prior.b_z();
    let mut h = [[0.0; N]; FILTER_LANES];
    for hl in &mut h {
        hl[B_H] = 1.0;
    }
    // Per lane: the group's position in `mine`, its samples, the next
    // sample and the kept conditionals.
    type Lane<'a> = (
        usize,
        GroupSamples<'a>,
        usize,
        Vec<(usize, LeadingConditional)>,
    );
    let mut at: [Option<Lane<'a>>; FILTER_LANES] = std::array::from_fn(|_| None);
    let mut next_group = 0;
    let mut done: Vec<Option<FilteredGroup>> = (0..mine.len()).map(|_| None).collect();
    loop {
        for (l, slot) in at.iter_mut().enumerate() {
            while slot.is_none() && next_group < mine.len() {
                let samples = load(mine[next_group])?;
                if samples.len() == 0 {
                    done[next_group] =
                        Some(FilteredGroup::of(lanes.take(l).map_err(est)?, Vec::new())?);
                } else {
                    *slot = Some((next_group, samples, 0, Vec::new()));
                }
                next_group += 1;
            }
        }
        let active = at.iter().filter(|a| a.is_some()).count();
        if active == 0 {
            break;
        }
        if active == 1 && next_group == mine.len() {
            // The last group alone: on without the lanes.
            let l = at.iter().position(Option::is_some).expect("an active lane");
            let (i, samples, k, kept) = at[l].take().expect("an active lane");
            let f = FieldFilter::resume(lanes.take(l).map_err(est)?, model)?;
            done[i] = Some(go_on(f, &samples, k, kept, m)?);
            break;
        }
        let samples: [Option<StepArgs<'_>>; FILTER_LANES] =
            std::array::from_fn(|l| at[l].as_ref().map(|(_, s, k, _)| s.at(*k, m)));
        for (hl, s) in h.iter_mut().zip(&samples) {
            if let Some((_, _, _, dz, _)) = s {
                hl[b_z] = *dz;
            }
        }
        let mut mats: [Option<(&DMatrix<f64>, &DMatrix<f64>)>; FILTER_LANES] = [None; FILTER_LANES];
        for ((t, s), mat) in transitions.iter_mut().zip(&samples).zip(&mut mats) {
            if let Some((false, d, ..)) = s {
                *mat = Some(t.step(*d)?);
            }
        }
        let steps: [LaneStep; FILTER_LANES] = std::array::from_fn(|l| match &samples[l] {
            None => LaneStep::Idle,
            Some((_, _, row, _, y)) => {
                let reading = Reading {
                    h: &h[l],
                    z: row,
                    y: *y,
                };
                match mats[l] {
                    Some((phi, g)) => LaneStep::Next { phi, g, reading },
                    None => LaneStep::Start(reading),
                }
            }
        });
        lanes.step(steps, model.r_nt2).map_err(est)?;
        for (l, slot) in at.iter_mut().enumerate() {
            let finished = match slot {
                None => continue,
                Some((_, samples, k, kept)) => {
                    if samples.keeps(*k) {
                        kept.push((*k, lanes.conditional(l)));
                    }
                    *k += 1;
                    *k == samples.len()
                }
            };
            if finished {
                let (i, _, _, kept) = slot.take().expect("an active lane");
                done[i] = Some(FilteredGroup::of(lanes.take(l).map_err(est)?, kept)?);
            }
        }
    }
    Ok(done
        .into_iter()
        .map(|f| f.expect("every group filtered"))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kalman::anomaly_model::NoiseModel;

    /// Groups of unequal lengths (a lane whose group ends takes the next,
    /// the last one goes on alone) on one and two threads, with kept
    /// conditionals and recorded innovations: every group bit for bit the
    /// field filter over it alone.
    #[test]
    fn groups_in_lanes_are_each_group_alone() {
        for (order, m) in [(3, 5), (6, 9)] {
            let prior = X2Prior {
                order,
                ..X2Prior::default()
            };
            let noise = NoiseModel::calibration_default();
            let transition = AnomalyTransition::new(&noise, order);
            let (coef_mean, coef_std) = (vec![0.0; m], vec![100.0; m]);
            let lengths = [300usize, 40, 517, 129, 260, 3, 411];
            let mut seed = 5u64;
            let mut rnd = move || {
                seed = seed
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
            };
            let groups: Vec<OwnedSamples> = lengths
                .iter()
                .map(|&len| {
                    let mut g = OwnedSamples::with_capacity(len, m);
                    for k in 0..len {
                        let row: Vec<f64> = (0..m).map(|_| rnd()).collect();
                        let first = k == 0 || k % 97 == 0;
                        let d = if k % 13 == 0 { 0.0 } else { 9.0 + rnd() };
                        g.push(
                            first,
                            d,
                            &row,
                            5.0 * rnd(),
                            3.0 * rnd() + row[0],
                            k % 50 == 49,
                        );
                    }
                    g
                })
                .collect();
            let samples: Vec<GroupSamples<'static>> =
                groups.into_iter().map(OwnedSamples::into_samples).collect();
            for record in [false, true] {
                let model = FieldModelSpec {
                    x2_prior: &prior,
                    transition: &transition,
                    r_nt2: noise.r_nt2,
                    coef_mean: &coef_mean,
                    coef_std: &coef_std,
                    record_innovations: record,
                };
                let alone: Vec<FilteredGroup> = samples
                    .iter()
                    .map(|s| one_group(s, &model).unwrap())
                    .collect();
                for threads in [1, 2, 3] {
                    let lanes =
                        filter_groups(samples.len(), threads, &model, |g| Ok(samples[g].clone()))
                            .unwrap();
                    for (g, (mut a, mut b)) in
                        lanes.into_iter().zip(alone.iter().cloned()).enumerate()
                    {
                        let what =
                            format!("order {order}, group {g}, threads {threads}, record {record}");
                        assert_eq!(a.filter.conditional(), b.filter.conditional(), "{what}");
                        assert_eq!(a.kept.len(), b.kept.len(), "{what}");
                        for ((ka, ca), (kb, cb)) in a.kept.iter().zip(&b.kept) {
                            assert_eq!((ka, ca), (kb, cb), "{what}");
                        }
                        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                        assert_eq!(bits(&a.innovations), bits(&b.innovations), "{what}");
                        if !record {
                            assert_eq!(
                                a.filter.log_likelihood().unwrap().to_bits(),
                                b.filter.log_likelihood().unwrap().to_bits(),
                                "{what}"
                            );
                        } else {
                            assert!(!a.innovations.is_empty());
                        }
                    }
                }
            }
        }
    }
}
