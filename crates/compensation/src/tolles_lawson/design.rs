//! Building the Tolles-Lawson design matrix over a segment.

use super::eddy_lag::LagBank;
use super::terms::{Convention, TermSet, derivative};

/// The design-matrix columns (column-major, `n_columns` vectors of the
/// segment's length) for the vector-magnetometer series `flux` (nT, body
/// frame) and time stamps `time` (s) of one contiguous segment.
pub fn design_columns(
    terms: &TermSet,
    convention: Convention,
    bt_scale_nt: f64,
    time: &[f64],
    flux: [&[f64]; 3],
) -> Vec<Vec<f64>> {
    let n = time.len();
    let ncol = terms.n_columns();
    let mut cols = vec![vec![0.0; n]; ncol];
    for_each_row(terms, convention, bt_scale_nt, time, flux, |i, row| {
        for (c, v) in cols.iter_mut().zip(row) {
            c[i] = *v;
        }
    });
    cols
}

/// Call `f(i, row)` for every sample of one contiguous segment, in order:
/// derivatives over the segment ([`derivative`]), lagged derivatives started
/// at its first sample ([`LagBank`]).
fn for_each_row(
    terms: &TermSet,
    convention: Convention,
    bt_scale_nt: f64,
    time: &[f64],
    flux: [&[f64]; 3],
    mut f: impl FnMut(usize, &[f64]),
) {
    let db = derivatives(terms, convention, time, flux);
    let mut lags = LagBank::new(terms.eddy_lags_s());
    let mut row = vec![0.0; terms.n_columns()];
    for i in 0..time.len() {
        let d = [db[0][i], db[1][i], db[2][i]];
        let lagged = lags.step(time[i], d);
        terms.row(
            [flux[0][i], flux[1][i], flux[2][i]],
            d,
            lagged,
            bt_scale_nt,
            &mut row,
        );
        f(i, &row);
    }
}

/// Field derivatives for the eddy columns (zeros when no eddy group is used).
fn derivatives(
    terms: &TermSet,
    convention: Convention,
    time: &[f64],
    flux: [&[f64]; 3],
) -> [Vec<f64>; 3] {
    if terms.has_eddy() {
        [0, 1, 2].map(|k| derivative(flux[k], time, convention))
    } else {
        let n = time.len();
        [vec![0.0; n], vec![0.0; n], vec![0.0; n]]
    }
}

/// Modelled interference `A c` (nT) over one segment.
pub fn interference(
    terms: &TermSet,
    convention: Convention,
    bt_scale_nt: f64,
    coef: &[f64],
    time: &[f64],
    flux: [&[f64]; 3],
) -> Vec<f64> {
    let mut out = vec![0.0; time.len()];
    for_each_row(terms, convention, bt_scale_nt, time, flux, |i, row| {
        out[i] = row.iter().zip(coef).map(|(a, c)| a * c).sum();
    });
    out
}
