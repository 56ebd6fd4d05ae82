//! The Tolles-Lawson design: which terms, how the eddy-current derivative is
//! formed and the scale of the induced and eddy columns — everything that
//! turns a vector-magnetometer record into design-matrix rows. One
//! [`Design`] is shared by the band-pass LS fit, the Kalman fit, the
//! streaming row builder and the model file, so a model is applied with
//! exactly the rows it was fitted on.

use super::eddy_lag::LagBank;
use super::terms::{Convention, DEFAULT_BT_SCALE_NT, TermSet, derivative_into};
use crate::error::{CompError, Result};
use serde::{Deserialize, Serialize};

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
}

impl Default for Design {
    /// The 16 observable terms `p3,i5,e8`, the physical convention and
    /// [`DEFAULT_BT_SCALE_NT`].
    fn default() -> Self {
        Self {
            terms: TermSet::observable16(),
            convention: Convention::Physical,
            bt_scale_nt: DEFAULT_BT_SCALE_NT,
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

    /// Check the terms and that `bt_scale` is finite and positive.
    pub fn validate(&self) -> Result<()> {
        if !(self.bt_scale_nt > 0.0 && self.bt_scale_nt.is_finite()) {
            return Err(CompError::setting(format!(
                "bt_scale {} must be positive",
                self.bt_scale_nt
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
    pub fn columns(&self, time: &[f64], flux: [&[f64]; 3]) -> Vec<Vec<f64>> {
        let mut block = DesignBlock::default();
        self.columns_into(time, flux, &mut block);
        block.columns
    }

    /// [`Design::columns`] into `block.columns`, reusing the block's
    /// allocations (a fit builds one block after another of the same size:
    /// fresh multi-megabyte buffers each time would cost more in page
    /// faults than the arithmetic).
    pub fn columns_into(&self, time: &[f64], flux: [&[f64]; 3], block: &mut DesignBlock) {
        self.derivatives_into(time, flux, &mut block.db);
        let mut lags = LagBank::new(self.terms.eddy_lags_s());
        let DesignBlock {
            columns,
            db,
            lagged,
            e,
        } = block;
        self.block_columns(0..time.len(), time, flux, db, &mut lags, lagged, e, columns);
    }

    /// Modelled interference `A c` (nT) over one contiguous segment, built
    /// in blocks of rows (memory: the derivatives and one block of columns).
    /// Each sample is `Σ_k A_k c_k` summed in column order, as a row's dot
    /// product with `c`.
    pub fn interference(&self, coef: &[f64], time: &[f64], flux: [&[f64]; 3]) -> Vec<f64> {
        const BLOCK: usize = 4096;
        let n = time.len();
        let mut db = Default::default();
        self.derivatives_into(time, flux, &mut db);
        let mut lags = LagBank::new(self.terms.eddy_lags_s());
        let (mut lagged, mut e, mut cols) = (Vec::new(), Default::default(), Vec::new());
        let mut out = Vec::with_capacity(n);
        for start in (0..n).step_by(BLOCK) {
            let r = start..(start + BLOCK).min(n);
            self.block_columns(
                r.clone(),
                time,
                flux,
                &db,
                &mut lags,
                &mut lagged,
                &mut e,
                &mut cols,
            );
            // −0.0 is the identity of f64 addition (what `Iterator::sum`
            // starts from), so this is the bits of `row · c`.
            let mut acc = vec![-0.0; r.len()];
            for (col, c) in cols.iter().zip(coef) {
                for (a, v) in acc.iter_mut().zip(col) {
                    *a += v * c;
                }
            }
            out.extend(acc);
        }
        out
    }

    /// The columns of rows `r` of a segment into `out` (derivatives `db`
    /// over the whole segment; `lags` stepped through every earlier row,
    /// so that the lagged derivatives start at the segment's first sample;
    /// `lagged` and `e` are scratch).
    #[allow(clippy::too_many_arguments)]
    fn block_columns(
        &self,
        r: std::ops::Range<usize>,
        time: &[f64],
        flux: [&[f64]; 3],
        db: &[Vec<f64>; 3],
        lags: &mut LagBank,
        lagged: &mut Vec<[Vec<f64>; 3]>,
        e: &mut [Vec<f64>; 3],
        out: &mut Vec<Vec<f64>>,
    ) {
        let n_lags = self.terms.eddy_lags_s().len();
        lagged.resize_with(n_lags, Default::default);
        for l in lagged.iter_mut() {
            l.iter_mut().for_each(Vec::clear);
        }
        if n_lags > 0 {
            for i in r.clone() {
                let d = [db[0][i], db[1][i], db[2][i]];
                for (l, g) in lagged.iter_mut().zip(lags.step(time[i], d)) {
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
        self.terms.columns_into(
            flux.map(|f| &f[r.clone()]),
            [&db[0][r.clone()], &db[1][r.clone()], &db[2][r.clone()]],
            &lagged,
            self.bt_scale_nt,
            e,
            out,
        )
    }

    /// Field derivatives for the eddy columns into `db` (zeros when no
    /// eddy group is used).
    fn derivatives_into(&self, time: &[f64], flux: [&[f64]; 3], db: &mut [Vec<f64>; 3]) {
        for (k, d) in db.iter_mut().enumerate() {
            if self.terms.has_eddy() {
                derivative_into(flux[k], time, self.convention, d);
            } else {
                d.clear();
                d.resize(time.len(), 0.0);
            }
        }
    }
}

/// Reusable buffers of [`Design::columns_into`]: the design columns of the
/// last block (`columns[k][n]`) and the scratch they are built from.
#[derive(Debug, Clone, Default)]
pub struct DesignBlock {
    /// The columns of the last block built.
    pub columns: Vec<Vec<f64>>,
    db: [Vec<f64>; 3],
    lagged: Vec<[Vec<f64>; 3]>,
    e: [Vec<f64>; 3],
}
