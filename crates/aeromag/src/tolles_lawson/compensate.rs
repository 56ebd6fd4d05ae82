//! A Tolles-Lawson model applied to a flight.

use crate::compensate::{Compensator, OutputColumns};
use crate::error::Result;
use crate::flight::{Flight, SegmentRule, SensorColumns, TlInputs};
use crate::observer::Observer;
use aeromag_compensation::model_file::TlModel;
use aeromag_compensation::tolles_lawson::fit_ls::Segment;
use aeromag_compensation::tolles_lawson::{Design, Magnitude};

/// The columns `compensate` adds: `mag_interf`, `mag_comp`, `comp_flag`.
pub const TL_OUTPUT: OutputColumns = OutputColumns {
    interference: "mag_interf",
    flag: "comp_flag",
    why_missing: "missing values",
    why_beyond: "an edited or corrupted coefficient or bt_scale, or another aircraft's model?",
};

impl Compensator for TlModel {
    fn output(&self) -> OutputColumns {
        TL_OUTPUT
    }

    /// `A c` on every stretch without gaps or missing values (the
    /// derivatives of the eddy terms must not cross them; line changes do
    /// not matter), NaN elsewhere. Reads `time`, `flux_x/y/z`, `mag` and
    /// the channels of the extra regressors.
    fn interference_observed(
        &self,
        flight: &Flight,
        _observer: &mut dyn Observer,
    ) -> Result<Vec<f64>> {
        tl_interference(self, flight, &SensorColumns::default())
    }
}

/// The interference `A c` (nT) of `model` at the sensor `sensor` of
/// `flight`, NaN on rows it cannot be applied to (see
/// [`Compensator::interference_observed`]).
pub(super) fn tl_interference(
    model: &TlModel,
    flight: &Flight,
    sensor: &SensorColumns,
) -> Result<Vec<f64>> {
    let [out] = tl_interferences(model, [&model.coef()[..]], flight, sensor)?;
    Ok(out)
}

/// The largest factor, either way, between a flight's median time step and
/// the sample interval of the model's calibration before the flight's time
/// is taken to be in other units. The eddy-current terms are derivatives
/// per second: a time in milliseconds (a factor of 1000) made them a
/// thousandth of the calibration's, `mag_comp` up to 0.30 nT off, written
/// without a word. Surveys flown at a tenth of the calibration's rate are
/// well within.
pub const MAX_STEP_RATIO: f64 = 100.0;

/// Bad input when the median time step of `flight` and the model's
/// calibration interval differ by more than [`MAX_STEP_RATIO`] (nothing
/// to check for a model file without the interval). The median is worked
/// out only when the mean step is that far off (gaps lengthen the mean).
pub(crate) fn check_time_unit(model: &TlModel, flight: &Flight) -> Result<()> {
    let Some(model_s) = model
        .fit
        .sample_interval_s
        .filter(|d| *d > 0.0 && d.is_finite())
    else {
        return Ok(());
    };
    let Some(t) = flight.column("time").filter(|t| t.len() >= 2) else {
        return Ok(());
    };
    let off = |dt: f64| !(dt <= MAX_STEP_RATIO * model_s && model_s <= MAX_STEP_RATIO * dt);
    let mean_s = (t[t.len() - 1] - t[0]) / (t.len() - 1) as f64;
    if !off(mean_s) {
        return Ok(());
    }
    let median_s = flight.median_step_s()?;
    if !off(median_s) {
        return Ok(());
    }
    Err(crate::Error::bad_file(
        flight.label(),
        format!(
            "column 'time': the flight's median time step is {} where the model was calibrated at {} s \
             (fit.sample_interval_s), {} times {}: is the time in seconds (milliseconds give 1000)? \
             The eddy-current terms are derivatives per second",
            aeromag_core::error::shown(median_s),
            aeromag_core::error::shown(model_s),
            aeromag_core::error::fixed((median_s / model_s).max(model_s / median_s), 0),
            if median_s > model_s {
                "longer"
            } else {
                "shorter"
            }
        ),
    ))
}

/// [`tl_interference`] of `model`'s design under each coefficient vector
/// of `coefs` at once (the design built once per block under the
/// first-order magnitude); each the bits of its own call.
fn tl_interferences<const K: usize>(
    model: &TlModel,
    coefs: [&[f64]; K],
    flight: &Flight,
    sensor: &SensorColumns,
) -> Result<[Vec<f64>; K]> {
    check_time_unit(model, flight)?;
    let (cols, segs) = model_segments(model, flight, sensor)?;
    let whole = cols.whole();
    let n = flight.n_rows();
    // Zeroed (fresh pages, written first by the projection's threads),
    // NaN between the segments; each segment's K output rows.
    let mut outs: [Vec<f64>; K] = std::array::from_fn(|_| vec![0.0; n]);
    let mut parts: Vec<Vec<&mut [f64]>> = segs.iter().map(|_| Vec::with_capacity(K)).collect();
    for o in outs.iter_mut() {
        let (mut rest, mut at) = (o.as_mut_slice(), 0);
        for (r, p) in segs.iter().zip(parts.iter_mut()) {
            let (gap, tail) = std::mem::take(&mut rest).split_at_mut(r.start - at);
            gap.fill(f64::NAN);
            let (seg, tail) = tail.split_at_mut(r.len());
            p.push(seg);
            (rest, at) = (tail, r.end);
        }
        rest.fill(f64::NAN);
    }
    let apply = |r: &std::ops::Range<usize>, out: &mut Vec<&mut [f64]>| {
        let s = whole.slice(r.clone());
        model
            .design
            .interferences_into(&coefs, s.time, s.flux, s.channels, out);
    };
    // Several segments (a model with lags runs its lag filters through
    // each one sample by sample) on the cores by rows, each computed as
    // alone (the same bits); a single one spreads its blocks instead.
    let mut jobs: Vec<_> = segs.iter().zip(parts.iter_mut()).collect();
    let threads = if n < 1 << 16 {
        1
    } else {
        aeromag_core::parallel::threads()
    };
    aeromag_core::parallel::for_each_weighted_mut(
        &mut jobs,
        threads,
        |(r, _)| r.len(),
        |(r, out)| apply(r, out),
    );
    Ok(outs)
}

/// [`tl_interferences`] over the rows of each of `blocks` (rows of
/// `flight`) in turn, handed to `f(outputs)` instead of kept: the
/// same bits row by row, with memory for a block per thread instead of
/// `K` flight-long series (32 MB at 10⁶ rows for the four parts). Blocks
/// on the cores; `f`'s results in block order. `None` when the model's
/// rows cannot be computed apart from those before them
/// ([`Design::rows_apart`]: lagged columns, the exact magnitude).
pub(super) fn tl_interference_blocks<const K: usize, R: Send>(
    model: &TlModel,
    coefs: [&[f64]; K],
    flight: &Flight,
    sensor: &SensorColumns,
    blocks: &[std::ops::Range<usize>],
    f: impl Fn([&[f64]; K]) -> R + Sync,
) -> Result<Option<Vec<R>>> {
    if !model.design.rows_apart() {
        return Ok(None);
    }
    let (cols, segs) = model_segments(model, flight, sensor)?;
    let whole = cols.whole();
    let threads = if flight.n_rows() < 1 << 16 {
        1
    } else {
        aeromag_core::parallel::threads()
    };
    let results = aeromag_core::parallel::parallel_map(blocks.len(), threads, |b| {
        let rows = &blocks[b];
        // NaN between the segments.
        let mut outs: [Vec<f64>; K] = std::array::from_fn(|_| vec![f64::NAN; rows.len()]);
        // The segments that overlap the block (in row order, apart).
        let first = segs.partition_point(|s| s.end <= rows.start);
        for s in segs[first..].iter().take_while(|s| s.start < rows.end) {
            let (a, e) = (s.start.max(rows.start), s.end.min(rows.end));
            let mut parts: Vec<&mut [f64]> = outs
                .iter_mut()
                .map(|o| &mut o[a - rows.start..e - rows.start])
                .collect();
            let seg = whole.slice(s.clone());
            let apart = model.design.interferences_of_rows(
                &coefs,
                seg.time,
                seg.flux,
                seg.channels,
                a - s.start,
                &mut parts,
            );
            debug_assert!(apart, "checked by rows_apart above");
        }
        f(outs.each_ref().map(|o| &o[..]))
    });
    Ok(Some(results))
}

/// The stretches of `flight` that `model` applies to at the sensor
/// `sensor` (no gaps or missing values; line changes do not matter), and
/// the inputs they are read from.
fn model_segments<'a>(
    model: &TlModel,
    flight: &'a Flight,
    sensor: &SensorColumns,
) -> Result<(TlInputs<'a>, Vec<std::ops::Range<usize>>)> {
    let cols =
        TlInputs::of_sensor(flight, sensor)?.with_extras(flight, model.design.terms.extras())?;
    let segs = cols.segments(&SegmentRule::ignoring_lines());
    debug_assert!(segs.short.is_empty());
    Ok((cols, segs.kept))
}

/// Call `f` with every stretch of `flight` that `model` applies to at the
/// sensor `sensor` ([`model_segments`]): its rows and its inputs.
fn for_model_segments(
    model: &TlModel,
    flight: &Flight,
    sensor: &SensorColumns,
    mut f: impl FnMut(std::ops::Range<usize>, &Segment),
) -> Result<()> {
    let (cols, segs) = model_segments(model, flight, sensor)?;
    let whole = cols.whole();
    for r in segs {
        f(r.clone(), &whole.slice(r));
    }
    Ok(())
}

/// How much the first-order projection of a first-order `model` leaves out
/// on `flight` at the sensor `sensor`: the peak-to-peak of its
/// second-order remainder `|ΔB⊥|²/2|B|` (nT) under the model's
/// coefficients; `None` for an exact-magnitude
/// model. Above [`super::calibrate::SECOND_ORDER_NOTE_NT`] the exact
/// magnitude is worth fitting.
pub fn second_order_range_nt(
    model: &TlModel,
    flight: &Flight,
    sensor: &SensorColumns,
) -> Result<Option<f64>> {
    if model.design.magnitude != Magnitude::FirstOrder {
        return Ok(None);
    }
    let coef = model.coef();
    let mut span = Span::default();
    for_model_segments(model, flight, sensor, |_, s| {
        span.add(&model.design, &coef, s);
    })?;
    Ok(Some(span.range()))
}

/// The range of the second-order remainder over segments.
#[derive(Debug, Clone, Copy)]
pub(super) struct Span {
    lo: f64,
    hi: f64,
}

impl Default for Span {
    fn default() -> Self {
        Self {
            lo: f64::INFINITY,
            hi: f64::NEG_INFINITY,
        }
    }
}

impl Span {
    /// Widen by the remainder on the segment `s` under `coef`.
    pub(super) fn add(&mut self, design: &Design, coef: &[f64], s: &Segment) {
        for v in design.second_order_nt(coef, s.time, s.flux, s.channels) {
            self.lo = self.lo.min(v);
            self.hi = self.hi.max(v);
        }
    }

    /// The span of both.
    pub(super) fn merge(self, other: Self) -> Self {
        Self {
            lo: self.lo.min(other.lo),
            hi: self.hi.max(other.hi),
        }
    }

    /// Peak to peak, nT (0 when empty).
    pub(super) fn range(&self) -> f64 {
        (self.hi - self.lo).max(0.0)
    }
}

/// A model's interference split by term group (nT per row, NaN where the
/// model cannot be applied): each part is the model with the other groups'
/// coefficients set to zero (for the exact magnitude, the part alone rather
/// than its share of the magnitude). The `bias` term is in none of them.
#[derive(Debug, Clone, PartialEq)]
pub struct InterferenceParts {
    /// Permanent magnetization (`p_`).
    pub permanent: Vec<f64>,
    /// Induced magnetization (`i_`).
    pub induced: Vec<f64>,
    /// Eddy currents (`e_`, and the lagged `l1_`, `l2_`).
    pub eddy: Vec<f64>,
    /// Extra regressors: the currents (`<channel>:e_x`, …).
    pub currents: Vec<f64>,
}

impl InterferenceParts {
    /// The parts of `model` at the sensor `sensor` of `flight`.
    pub fn of(model: &TlModel, flight: &Flight, sensor: &SensorColumns) -> Result<Self> {
        let coefs = Self::coefficients(model);
        let [permanent, induced, eddy, currents] =
            tl_interferences(model, coefs.each_ref().map(|c| &c[..]), flight, sensor)?;
        Ok(Self {
            permanent,
            induced,
            eddy,
            currents,
        })
    }

    /// The coefficients of each part (permanent, induced, eddy, currents):
    /// `model`'s, the other parts' set to zero.
    pub(super) fn coefficients(model: &TlModel) -> [Vec<f64>; 4] {
        let part = |keep: &dyn Fn(&str) -> bool| -> Vec<f64> {
            model
                .coefficients
                .iter()
                .map(|c| if keep(&c.name) { c.value } else { 0.0 })
                .collect()
        };
        [
            part(&|n| n.starts_with("p_")),
            part(&|n| n.starts_with("i_")),
            part(&|n| n.starts_with("e_") || n.starts_with('l')),
            part(&|n| n.contains(':')),
        ]
    }
}
