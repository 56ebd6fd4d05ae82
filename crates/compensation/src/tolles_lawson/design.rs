//! The Tolles-Lawson design: which terms, how the eddy-current derivative is
//! formed and the scale of the induced and eddy columns — everything that
//! turns a vector-magnetometer record into design-matrix rows. One
//! [`Design`] is shared by the band-pass LS fit, the Kalman fit, the
//! streaming row builder and the model file, so a model is applied with
//! exactly the rows it was fitted on.

use super::eddy_lag::LagBank;
use super::terms::{Convention, DEFAULT_BT_SCALE_NT, TermSet, derivative};
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
        let n = time.len();
        let mut cols = vec![vec![0.0; n]; self.n_columns()];
        self.for_each_row(time, flux, |i, row| {
            for (c, v) in cols.iter_mut().zip(row) {
                c[i] = *v;
            }
        });
        cols
    }

    /// Modelled interference `A c` (nT) over one contiguous segment.
    pub fn interference(&self, coef: &[f64], time: &[f64], flux: [&[f64]; 3]) -> Vec<f64> {
        let mut out = vec![0.0; time.len()];
        self.for_each_row(time, flux, |i, row| {
            out[i] = row.iter().zip(coef).map(|(a, c)| a * c).sum();
        });
        out
    }

    /// Call `f(i, row)` for every sample of one contiguous segment, in
    /// order: derivatives over the segment ([`derivative`]), lagged
    /// derivatives started at its first sample ([`LagBank`]).
    fn for_each_row(&self, time: &[f64], flux: [&[f64]; 3], mut f: impl FnMut(usize, &[f64])) {
        let db = self.derivatives(time, flux);
        let mut lags = LagBank::new(self.terms.eddy_lags_s());
        let mut row = vec![0.0; self.n_columns()];
        for i in 0..time.len() {
            let d = [db[0][i], db[1][i], db[2][i]];
            let lagged = lags.step(time[i], d);
            self.terms.row(
                [flux[0][i], flux[1][i], flux[2][i]],
                d,
                lagged,
                self.bt_scale_nt,
                &mut row,
            );
            f(i, &row);
        }
    }

    /// Field derivatives for the eddy columns (zeros when no eddy group is used).
    fn derivatives(&self, time: &[f64], flux: [&[f64]; 3]) -> [Vec<f64>; 3] {
        if self.terms.has_eddy() {
            [0, 1, 2].map(|k| derivative(flux[k], time, self.convention))
        } else {
            let n = time.len();
            [vec![0.0; n], vec![0.0; n], vec![0.0; n]]
        }
    }
}
