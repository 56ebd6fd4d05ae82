//! Building the Tolles-Lawson design matrix over a segment.

use super::terms::{derivative, Convention, TermSet};

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
    let db = derivatives(terms, convention, time, flux);
    let mut cols = vec![vec![0.0; n]; ncol];
    let mut row = vec![0.0; ncol];
    for i in 0..n {
        terms.row([flux[0][i], flux[1][i], flux[2][i]], [db[0][i], db[1][i], db[2][i]], bt_scale_nt, &mut row);
        for (c, v) in cols.iter_mut().zip(&row) {
            c[i] = *v;
        }
    }
    cols
}

/// Field derivatives for the eddy columns (zeros when no eddy group is used).
fn derivatives(terms: &TermSet, convention: Convention, time: &[f64], flux: [&[f64]; 3]) -> [Vec<f64>; 3] {
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
    let ncol = terms.n_columns();
    let db = derivatives(terms, convention, time, flux);
    let mut row = vec![0.0; ncol];
    (0..time.len())
        .map(|i| {
            terms.row([flux[0][i], flux[1][i], flux[2][i]], [db[0][i], db[1][i], db[2][i]], bt_scale_nt, &mut row);
            row.iter().zip(coef).map(|(a, c)| a * c).sum()
        })
        .collect()
}
