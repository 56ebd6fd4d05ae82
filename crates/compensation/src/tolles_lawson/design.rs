//! The Tolles-Lawson design: which terms, how the eddy-current derivative is
//! formed and the scale of the induced and eddy columns — everything that
//! turns a vector-magnetometer record into design-matrix rows. One
//! [`Design`] is shared by the band-pass LS fit, the Kalman fit, the
//! streaming row builder and the model file, so a model is applied with
//! exactly the rows it was fitted on.

use super::eddy_lag::{FirstOrderLag, LagBank};
use super::terms::{
    Convention, DEFAULT_BT_SCALE_NT, Differencing, ExtraSeries, TermSet, derivative_rows_into,
};
use crate::error::{CompError, Result};
use serde::{Deserialize, Serialize};

/// The range of `bt_scale`, nT: the field magnitude the induced and eddy
/// terms are divided by (MagNav's `Bt_scale`, 50 000 nT), 1 nT (no scaling)
/// to 10⁶ nT (beyond any magnetic field). A smaller value makes the terms
/// overflow (1e-308 gave every row an infinite interference).
pub const BT_SCALE_RANGE_NT: (f64, f64) = (1.0, 1e6);

/// The terms, the derivative convention of the eddy columns and `bt_scale`
/// (nT) of a Tolles-Lawson model.
///
/// The design row of a sample with body-frame field `b` (nT) and derivative
/// `ḃ` is [`TermSet::row`]: `e = b/|b|`, permanent `e_i`, induced
/// `e_i b_j / bt_scale`, eddy `e_i ḃ_j / bt_scale` (and the lagged eddy
/// columns); the modelled interference is `A c` (nT).
///
/// ```
/// use aeromag_compensation::tolles_lawson::{Design, TermSet};
/// let design = Design::new(TermSet::parse("p3,i5")?);
/// let time = [0.0, 0.1, 0.2];
/// let (x, y, z) = ([20_000.0; 3], [1_000.0; 3], [45_000.0; 3]);
/// let cols = design.columns(&time, [&x, &y, &z]);
/// assert_eq!(cols.len(), 8);
/// let coef = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
/// let a = design.interference(&coef, &time, [&x, &y, &z]);
/// assert!((a[0] - 20_000.0 / 49_254.44).abs() < 1e-6); // e_x
/// # Ok::<(), aeromag_compensation::CompError>(())
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Design {
    /// Term groups (and the lags of the lagged eddy groups).
    pub terms: TermSet,
    /// Derivative convention of the eddy columns.
    pub convention: Convention,
    /// Scale of the induced and eddy columns, nT.
    pub bt_scale_nt: f64,
    /// How the interference vector becomes the scalar interference: the
    /// Tolles-Lawson projection (default) or the exact magnitude.
    #[serde(default, skip_serializing_if = "Magnitude::is_first_order")]
    pub magnitude: Magnitude,
    /// Central (default, batch) or backward (causal) differences for the
    /// eddy columns' derivative: how the model is applied, not how it was
    /// fitted ([`Design::causal`]).
    #[serde(default, skip_serializing_if = "Differencing::is_centred")]
    pub differencing: Differencing,
}

/// How the modelled interference vector `ΔB` (body frame) becomes the
/// scalar sensor's interference.
///
/// Every design column but `bias` is one component of a vector model:
/// column `e_i s` is the contribution `s` to `ΔB_i` (`s` = 1, `B_j/bt`,
/// `Ḃ_j/bt`, a lagged derivative or an extra channel), so that
/// `ΔB = Σ_k c_k s_k u_{i(k)}` and the Tolles-Lawson interference is its
/// projection `eᵀΔB`. That projection is the first order of
/// `|B + ΔB| − |B| = eᵀΔB + |ΔB⊥|²/(2|B|) + …`: for a sensor whose
/// interference is 1 % of the field (500 nT) the second-order term reaches
/// 2.5 nT, for 1000 nT about 10 nT.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Magnitude {
    /// `eᵀΔB` (+ bias): the classical model, linear in the coefficients.
    #[default]
    FirstOrder,
    /// `|B + ΔB| − |B|` (+ bias), `B` the vector magnetometer's field:
    /// fitted by Gauss–Newton from the first-order solution
    /// ([`super::fit_ls::fit_band_pass_ls`]).
    Exact,
}

impl Magnitude {
    fn is_first_order(&self) -> bool {
        *self == Magnitude::FirstOrder
    }
}

impl std::fmt::Display for Magnitude {
    /// `first-order` or `exact`, as in files and on the command line.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Magnitude::FirstOrder => "first-order",
            Magnitude::Exact => "exact",
        })
    }
}

impl std::str::FromStr for Magnitude {
    type Err = CompError;
    /// `first-order` or `exact`.
    fn from_str(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "first-order" => Ok(Magnitude::FirstOrder),
            "exact" => Ok(Magnitude::Exact),
            o => Err(CompError::setting(format!(
                "magnitude `{o}`: use first-order or exact"
            ))),
        }
    }
}

impl Default for Design {
    /// The 16 observable terms `p3,i5,e8`, the physical convention and
    /// [`DEFAULT_BT_SCALE_NT`].
    fn default() -> Self {
        Self {
            terms: TermSet::observable16(),
            convention: Convention::Physical,
            bt_scale_nt: DEFAULT_BT_SCALE_NT,
            magnitude: Magnitude::FirstOrder,
            differencing: Differencing::Centred,
        }
    }
}

impl Design {
    /// `terms` with the default convention and scale.
    pub fn new(terms: TermSet) -> Self {
        Self {
            terms,
            ..Self::default()
        }
    }

    /// This design with other terms.
    pub fn with_terms(&self, terms: TermSet) -> Self {
        Self {
            terms,
            ..self.clone()
        }
    }

    /// This design under the causal convention: the eddy columns take
    /// backward differences ([`Differencing::Backward`]), so that a sample's
    /// row needs no later sample. The lags (eddy and extra regressors) are
    /// causal filters already.
    pub fn causal(&self) -> Self {
        Self {
            differencing: Differencing::Backward,
            ..self.clone()
        }
    }

    /// Check the terms and that `bt_scale` is a field magnitude
    /// ([`BT_SCALE_RANGE_NT`]).
    pub fn validate(&self) -> Result<()> {
        let (lo, hi) = BT_SCALE_RANGE_NT;
        if !(self.bt_scale_nt >= lo && self.bt_scale_nt <= hi) {
            return Err(CompError::setting(format!(
                "bt_scale {} must be a field magnitude from {lo} to {hi:e} nT (MagNav's 50000)",
                aeromag_core::error::shown(self.bt_scale_nt)
            )));
        }
        self.terms.validate()
    }

    /// Number of design columns.
    pub fn n_columns(&self) -> usize {
        self.terms.n_columns()
    }

    /// Column (coefficient) names in order.
    pub fn column_names(&self) -> Vec<String> {
        self.terms.column_names()
    }

    /// The design-matrix columns (column-major, `n_columns` vectors of the
    /// segment's length) for the vector-magnetometer series `flux` (nT,
    /// body frame) and time stamps `time` (s) of one contiguous segment.
    /// Without extra regressors (their columns, if the terms have any, are
    /// NaN: [`Design::columns_with`]).
    pub fn columns(&self, time: &[f64], flux: [&[f64]; 3]) -> Vec<Vec<f64>> {
        self.columns_with(time, flux, Channels::NONE)
    }

    /// [`Design::columns`] with the extra regressors' channels (one per
    /// [`TermSet::extras`], in order, each of the segment's length).
    pub fn columns_with(
        &self,
        time: &[f64],
        flux: [&[f64]; 3],
        channels: Channels,
    ) -> Vec<Vec<f64>> {
        let mut block = DesignBlock::default();
        self.columns_into(time, flux, channels, &mut block);
        block.columns
    }

    /// [`Design::columns`] into `block.columns`, reusing the block's
    /// allocations (a fit builds one block after another of the same size:
    /// fresh multi-megabyte buffers each time would cost more in page
    /// faults than the arithmetic).
    pub fn columns_into(
        &self,
        time: &[f64],
        flux: [&[f64]; 3],
        channels: Channels,
        block: &mut DesignBlock,
    ) {
        self.columns_along_into(time, flux, channels, None, block)
    }

    /// [`Design::columns_into`] with the direction cosines of `dir` (the
    /// total field `B + ΔB` of a Gauss–Newton step of the exact-magnitude
    /// model) rather than of the vector magnetometer's field.
    pub fn columns_along_into(
        &self,
        time: &[f64],
        flux: [&[f64]; 3],
        channels: Channels,
        dir: Option<[&[f64]; 3]>,
        block: &mut DesignBlock,
    ) {
        self.derivatives_into(time, flux, 0..time.len(), &mut block.db);
        let mut lags = Lags::new(&self.terms);
        let DesignBlock {
            columns,
            db,
            scratch,
        } = block;
        self.block_columns(
            0..time.len(),
            time,
            flux,
            dir,
            channels,
            [&db[0][..], &db[1][..], &db[2][..]],
            &mut lags,
            scratch,
            columns,
        );
    }

    /// Modelled interference `A c` (nT) over one contiguous segment, built
    /// in blocks of rows (memory: the derivatives and one block of columns).
    /// Each sample is `Σ_k A_k c_k` summed in column order, as a row's dot
    /// product with `c`.
    ///
    /// Without extra regressors (their columns, if the terms have any, are
    /// NaN: [`Design::interference_with`]).
    pub fn interference(&self, coef: &[f64], time: &[f64], flux: [&[f64]; 3]) -> Vec<f64> {
        self.interference_with(coef, time, flux, Channels::NONE)
    }

    /// [`Design::interference`] with the extra regressors' channels, under
    /// the design's [`Magnitude`].
    pub fn interference_with(
        &self,
        coef: &[f64],
        time: &[f64],
        flux: [&[f64]; 3],
        channels: Channels,
    ) -> Vec<f64> {
        let mut out = vec![0.0; time.len()];
        self.interference_with_into(coef, time, flux, channels, &mut out);
        out
    }

    /// [`Design::interference_with_into`] for several coefficient vectors
    /// at once: `outs[k]` is the interference under `coefs[k]`, the bits of
    /// its own call. Under the first-order magnitude the design is built
    /// once for all of them.
    pub fn interferences_into(
        &self,
        coefs: &[&[f64]],
        time: &[f64],
        flux: [&[f64]; 3],
        channels: Channels,
        outs: &mut [&mut [f64]],
    ) {
        match self.magnitude {
            Magnitude::FirstOrder => {
                let inputs = Inputs {
                    time,
                    flux,
                    channels,
                    dir: None,
                };
                self.projections_into(coefs, inputs, outs)
            }
            Magnitude::Exact => {
                for (coef, out) in coefs.iter().zip(outs.iter_mut()) {
                    self.interference_with_into(coef, time, flux, channels, out);
                }
            }
        }
    }

    /// [`Design::interference_with`] into `out` (of the segment's length),
    /// without a buffer of its own under the first-order magnitude.
    pub fn interference_with_into(
        &self,
        coef: &[f64],
        time: &[f64],
        flux: [&[f64]; 3],
        channels: Channels,
        out: &mut [f64],
    ) {
        match self.magnitude {
            Magnitude::FirstOrder => self.projected_into(coef, time, flux, channels, None, out),
            Magnitude::Exact => {
                let (d, bias) = self.field_vector(coef, time, flux, channels);
                for (k, o) in out.iter_mut().enumerate() {
                    *o = TotalField::at(flux, &d, k).change() + bias;
                }
            }
        }
    }

    /// Whether [`Design::interferences_of_rows`] computes rows apart from
    /// those before them: under the first-order magnitude without lagged
    /// columns (whose state runs from the segment's start).
    pub fn rows_apart(&self) -> bool {
        self.magnitude == Magnitude::FirstOrder && !self.lagged()
    }

    /// Rows `start..start + len` of [`Design::interferences_into`] on a
    /// segment (`outs[k]` of `len` rows each): the bits of those rows of
    /// the whole call, without computing the others. `false` (nothing
    /// written) when the design does not compute rows apart
    /// ([`Design::rows_apart`]).
    pub fn interferences_of_rows(
        &self,
        coefs: &[&[f64]],
        time: &[f64],
        flux: [&[f64]; 3],
        channels: Channels,
        start: usize,
        outs: &mut [&mut [f64]],
    ) -> bool {
        if !self.rows_apart() {
            return false;
        }
        self.project_rows(
            coefs,
            Inputs {
                time,
                flux,
                channels,
                dir: None,
            },
            start,
            outs,
        );
        true
    }

    /// Whether the design has lagged columns (eddy lags, lagged extras).
    fn lagged(&self) -> bool {
        !self.terms.eddy_lags_s().is_empty() || self.terms.extra_lags_s().next().is_some()
    }

    /// The modelled interference vector `ΔB` (nT, body frame; [`Magnitude`]
    /// docs) of every sample, and the bias coefficient (0 without a `bias`
    /// term), which is not part of the vector.
    pub fn field_vector(
        &self,
        coef: &[f64],
        time: &[f64],
        flux: [&[f64]; 3],
        channels: Channels,
    ) -> ([Vec<f64>; 3], f64) {
        let n = time.len();
        let bias = self.terms.bias_column();
        let b = bias.and_then(|k| coef.get(k).copied()).unwrap_or(0.0);
        let mut c = coef.to_vec();
        if let Some(k) = bias
            && k < c.len()
        {
            c[k] = 0.0;
        }
        // Column e_i s along the unit axis u_a is s when i = a, else 0.
        let (one, zero) = (vec![1.0; n], vec![0.0; n]);
        let axis = |a: usize| -> [&[f64]; 3] {
            std::array::from_fn(|i| if i == a { &one[..] } else { &zero[..] })
        };
        let d = [0, 1, 2].map(|a| {
            let mut v = vec![0.0; n];
            self.projected_into(&c, time, flux, channels, Some(axis(a)), &mut v);
            v
        });
        (d, b)
    }

    /// The second-order remainder of the projection, `|B + ΔB| − |B| −
    /// eᵀΔB` (nT), of every sample under the coefficients `coef`: what the
    /// first-order model leaves out (≈ `|ΔB⊥|²/2|B|`).
    pub fn second_order_nt(
        &self,
        coef: &[f64],
        time: &[f64],
        flux: [&[f64]; 3],
        channels: Channels,
    ) -> Vec<f64> {
        let (d, _) = self.field_vector(coef, time, flux, channels);
        (0..time.len())
            .map(|k| TotalField::at(flux, &d, k).beyond_projection())
            .collect()
    }

    /// `A c` with the direction cosines of `dir` (default: of `flux`) into
    /// `out` (of the segment's length): [`Design::projections_into`] with
    /// one coefficient vector.
    fn projected_into(
        &self,
        coef: &[f64],
        time: &[f64],
        flux: [&[f64]; 3],
        channels: Channels,
        dir: Option<[&[f64]; 3]>,
        out: &mut [f64],
    ) {
        let inputs = Inputs {
            time,
            flux,
            channels,
            dir,
        };
        self.projections_into(&[coef], inputs, &mut [out]);
    }

    /// `A c_k` for each coefficient vector `coefs[k]` into `outs[k]` (each
    /// of the segment's length), with the direction cosines of `dir`
    /// (default: of `flux`): the design is built once per block of
    /// [`PROJECTION_BLOCK`] rows for all of them, the derivatives block by
    /// block too, so the memory beyond the outputs is a few blocks whatever
    /// the segment's length. Each output is the bits of its own single
    /// projection. Without lagged columns the blocks are independent and
    /// are shared out over the available cores (each row's sum is the same
    /// bits whatever the thread count); lagged columns carry their state
    /// from block to block, one thread.
    fn projections_into(&self, coefs: &[&[f64]], inputs: Inputs, outs: &mut [&mut [f64]]) {
        let n = inputs.time.len();
        debug_assert!(outs.iter().all(|o| o.len() == n) && outs.len() == coefs.len());
        let threads = aeromag_core::parallel::threads();
        let project =
            |start: usize, parts: &mut [&mut [f64]]| self.project_rows(coefs, inputs, start, parts);
        if self.lagged() || n < 4 * PROJECTION_BLOCK {
            project(0, outs);
        } else {
            aeromag_core::parallel::for_each_rows_mut(outs, threads, PROJECTION_BLOCK, project);
        }
    }

    /// Rows `start..start + len` of [`Design::projections_into`] into
    /// `parts` (the outputs' rows there), in blocks of
    /// [`PROJECTION_BLOCK`]; lagged columns start at `start` (the
    /// segment's first row for them).
    fn project_rows(
        &self,
        coefs: &[&[f64]],
        inputs: Inputs,
        start: usize,
        parts: &mut [&mut [f64]],
    ) {
        let Inputs {
            time,
            flux,
            channels,
            dir,
        } = inputs;
        let len = parts.first().map_or(0, |p| p.len());
        let mut lags = Lags::new(&self.terms);
        let (mut scratch, mut cols) = (Scratch::default(), Vec::new());
        let mut db: [Vec<f64>; 3] = Default::default();
        for a in (0..len).step_by(PROJECTION_BLOCK) {
            let local = a..(a + PROJECTION_BLOCK).min(len);
            let r = start + local.start..start + local.end;
            self.derivatives_into(time, flux, r.clone(), &mut db);
            self.block_columns(
                r,
                time,
                flux,
                dir,
                channels,
                [&db[0][..], &db[1][..], &db[2][..]],
                &mut lags,
                &mut scratch,
                &mut cols,
            );
            for (part, coef) in parts.iter_mut().zip(coefs) {
                let acc = &mut part[local.clone()];
                // −0.0 is the identity of f64 addition (what
                // `Iterator::sum` starts from), so this is the bits of
                // `row · c`.
                acc.fill(-0.0);
                // A zero coefficient adds nothing (the columns are
                // finite) but the sign of an exact zero: skipped (a
                // part of the model has most of them).
                for (col, c) in cols.iter().zip(*coef).filter(|(_, c)| **c != 0.0) {
                    for (a, v) in acc.iter_mut().zip(col) {
                        *a += v * c;
                    }
                }
            }
        }
    }

    /// The columns of rows `r` of a segment into `out` (`db`: the
    /// derivatives of those rows; `lags` stepped through every earlier row,
    /// so that the lagged derivatives and channels start at the segment's
    /// first sample; the direction cosines of `dir`, default `flux`).
    #[allow(clippy::too_many_arguments)]
    fn block_columns(
        &self,
        r: std::ops::Range<usize>,
        time: &[f64],
        flux: [&[f64]; 3],
        dir: Option<[&[f64]; 3]>,
        channels: Channels,
        db: [&[f64]; 3],
        lags: &mut Lags,
        scratch: &mut Scratch,
        out: &mut Vec<Vec<f64>>,
    ) {
        let Scratch { lagged, extra, e } = scratch;
        let n_lags = self.terms.eddy_lags_s().len();
        lagged.resize_with(n_lags, Default::default);
        for l in lagged.iter_mut() {
            l.iter_mut().for_each(Vec::clear);
        }
        if n_lags > 0 {
            for i in r.clone() {
                let j = i - r.start;
                let d = [db[0][j], db[1][j], db[2][j]];
                for (l, g) in lagged.iter_mut().zip(lags.eddy.step(time[i], d)) {
                    for (axis, v) in l.iter_mut().zip(g) {
                        axis.push(*v);
                    }
                }
            }
        }
        let lagged: Vec<[&[f64]; 3]> = lagged
            .iter()
            .map(|l| [&l[0][..], &l[1][..], &l[2][..]])
            .collect();
        extra.resize_with(lags.extra.len(), Vec::new);
        for (k, (lag, out)) in lags.extra.iter_mut().zip(extra.iter_mut()).enumerate() {
            out.clear();
            if let (Some(lag), Some(x)) = (lag, channels.get(k)) {
                out.extend(r.clone().map(|i| lag.step(time[i], x[i])));
            }
        }
        let series: Vec<ExtraSeries> = (0..self.terms.extras().len())
            .map(|k| ExtraSeries {
                values: channels.get(k).map_or(&[][..], |x| &x[r.clone()]),
                lagged: extra.get(k).map_or(&[][..], |v| &v[..]),
            })
            .collect();
        self.terms.columns_into(
            dir.unwrap_or(flux).map(|f| &f[r.clone()]),
            flux.map(|f| &f[r.clone()]),
            db,
            &lagged,
            &series,
            self.bt_scale_nt,
            e,
            out,
        )
    }

    /// Field derivatives for the eddy columns of rows `r` of the segment
    /// into `db` (zeros when no eddy group is used).
    fn derivatives_into(
        &self,
        time: &[f64],
        flux: [&[f64]; 3],
        r: std::ops::Range<usize>,
        db: &mut [Vec<f64>; 3],
    ) {
        for (k, d) in db.iter_mut().enumerate() {
            if self.terms.has_eddy() {
                derivative_rows_into(
                    flux[k],
                    time,
                    self.convention,
                    self.differencing,
                    r.clone(),
                    d,
                );
            } else {
                d.clear();
                d.resize(r.len(), 0.0);
            }
        }
    }
}

/// What a projection reads of a segment: its times, the vector
/// magnetometer's readings (nT), the extra regressors' channels, and the
/// series the direction cosines come from (`dir`; default `flux`).
#[derive(Clone, Copy)]
struct Inputs<'a> {
    time: &'a [f64],
    flux: [&'a [f64]; 3],
    channels: Channels<'a>,
    dir: Option<[&'a [f64]; 3]>,
}

/// Rows per block of [`Design::projected_into`].
const PROJECTION_BLOCK: usize = 4096;

fn norm(v: [f64; 3]) -> f64 {
    dot(v, v).sqrt()
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The field `b` of the vector magnetometer, the modelled interference
/// `d = ΔB` and the total `t = b + d` at one sample (nT).
#[derive(Debug, Clone, Copy)]
pub(crate) struct TotalField {
    pub(crate) b: [f64; 3],
    pub(crate) d: [f64; 3],
    pub(crate) t: [f64; 3],
}

impl TotalField {
    /// Sample `k` of the series `flux` and `d`.
    pub(crate) fn at(flux: [&[f64]; 3], d: &[Vec<f64>; 3], k: usize) -> Self {
        Self::of(
            [flux[0][k], flux[1][k], flux[2][k]],
            [d[0][k], d[1][k], d[2][k]],
        )
    }

    /// The field `b` and the interference `d` of one sample.
    pub(crate) fn of(b: [f64; 3], d: [f64; 3]) -> Self {
        Self {
            b,
            d,
            t: [b[0] + d[0], b[1] + d[1], b[2] + d[2]],
        }
    }

    /// `|b + d| − |b|`: the exact change of the magnitude.
    pub(crate) fn change(&self) -> f64 {
        norm(self.t) - norm(self.b)
    }

    /// `|b + d| − |b| − eᵀd` with `e = b/|b|`: what the Tolles-Lawson
    /// projection leaves out.
    pub(crate) fn beyond_projection(&self) -> f64 {
        self.change() - dot(self.b, self.d) / norm(self.b)
    }

    /// `|b + d| − |b| − êᵀd` with `ê = t/|t|`: what the projection on the
    /// total field's direction leaves out (the Gauss–Newton remainder).
    pub(crate) fn remainder(&self) -> f64 {
        self.change() - dot(self.t, self.d) / norm(self.t)
    }
}

/// Reusable buffers of [`Design::columns_into`]: the design columns of the
/// last block (`columns[k][n]`) and the scratch they are built from.
#[derive(Debug, Clone, Default)]
pub struct DesignBlock {
    /// The columns of the last block built.
    pub columns: Vec<Vec<f64>>,
    db: [Vec<f64>; 3],
    scratch: Scratch,
}

/// Scratch of one block: lagged derivatives, lagged extra channels and the
/// direction cosines.
#[derive(Debug, Clone, Default)]
struct Scratch {
    lagged: Vec<[Vec<f64>; 3]>,
    extra: Vec<Vec<f64>>,
    e: [Vec<f64>; 3],
}

/// The lags of a segment, stepped row by row from its first sample: the
/// eddy lags of the derivatives and the lag of each extra regressor that
/// has one.
#[derive(Debug, Clone)]
pub(crate) struct Lags {
    pub(crate) eddy: LagBank,
    pub(crate) extra: Vec<Option<FirstOrderLag>>,
}

impl Lags {
    pub(crate) fn new(terms: &TermSet) -> Self {
        Self {
            eddy: LagBank::new(terms.eddy_lags_s()),
            extra: terms
                .extras()
                .iter()
                .map(|x| x.lag_s.map(FirstOrderLag::new))
                .collect(),
        }
    }
}

/// The recorded channels of a design's extra regressors over a segment, one
/// per [`TermSet::extras`] in order, each as long as the segment, without
/// copying them: slicing ([`Channels::slice`]) narrows the window.
///
/// ```
/// use aeromag_compensation::tolles_lawson::design::Channels;
/// let (strobe, flap) = ([0.0, 5.0, 0.0, 5.0], [1.0, 1.0, 2.0, 2.0]);
/// let all = [&strobe[..], &flap[..]];
/// let c = Channels::new(&all).slice(1..3);
/// assert_eq!(c.get(1), Some(&[1.0, 2.0][..]));
/// assert_eq!(c.get(2), None);
/// ```
#[derive(Debug, Clone, Copy)]
pub struct Channels<'a> {
    series: &'a [&'a [f64]],
    start: usize,
    len: Option<usize>,
}

impl<'a> Channels<'a> {
    /// No channels.
    pub const NONE: Channels<'static> = Channels {
        series: &[],
        start: 0,
        len: None,
    };

    /// The channels `series`, whole.
    pub fn new(series: &'a [&'a [f64]]) -> Self {
        Self {
            series,
            start: 0,
            len: None,
        }
    }

    /// Rows `r` of the current window (relative to it).
    pub fn slice(&self, r: std::ops::Range<usize>) -> Self {
        Self {
            series: self.series,
            start: self.start + r.start,
            len: Some(r.len()),
        }
    }

    /// Channel `k` over the window (`None` when there is no channel `k`
    /// or it is shorter than the window).
    pub fn get(&self, k: usize) -> Option<&'a [f64]> {
        let s = self.series.get(k)?;
        let end = self.len.map_or(s.len(), |l| self.start + l);
        s.get(self.start..end)
    }

    /// Number of channels.
    pub fn count(&self) -> usize {
        self.series.len()
    }
}

impl Default for Channels<'_> {
    /// [`Channels::NONE`].
    fn default() -> Self {
        Channels::NONE
    }
}
