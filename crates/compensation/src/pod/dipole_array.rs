//! The joint equivalent-dipole-array solve (spec `helicopter.md` part B
//! "Reproduce the paper, then beat it").
//!
//! The small-signal model linearises the helicopter's field in the pod's
//! displacement; with a 40 m cable a 5° manoeuvre or swing moves the pod
//! ≈ 3.5 m, 9 % of its distance to the sources, and the neglected
//! higher-order terms of the `1/r³` field cost several per cent of
//! compensation. Here the helicopter is represented by equivalent dipoles
//! at fixed body points `r_s` (default [`default_source_points`]), each
//! with a permanent moment, an induced moment linear in `u` and an
//! eddy-current moment linear in `u'`, and the field at the pod's position
//! `p_b` (from [`super::trajectory`]) is evaluated exactly:
//!
//! `ΔB(t) = Σ_s uᵀ D(p_b − r_s) (m_s + X_s u + E_s u')`,
//!
//! `D(r)` the dipole matrix (T per A·m², [`aeromag_core::field::dipole::
//! dipole_matrix`]); the unknowns `m_s` (3), `X_s` (3×3), `E_s` (3×3) per
//! point are linear, so one least-squares fit over all samples of all
//! learning headings (high-passed as in [`super::fit`]) solves them jointly.
//! Moments come out in A·m² per unit direction cosine (the Earth field's
//! magnitude is absorbed in `X_s`, `E_s`).

use aeromag_core::field::dipole::dipole_matrix;
use nalgebra::{DMatrix, DVector, Vector3};

use super::fit::{PodHeading, detrend, lstsq, prepare};
use crate::{CompError, Result};

/// Unknowns per source point: permanent (3), induced (9), eddy (9).
pub const PER_SOURCE: usize = 21;

/// Default equivalent source points (body frame, m): along the fuselage at
/// x = −6, −2, 2 m, 1 m above the cabin floor.
pub fn default_source_points() -> Vec<[f64; 3]> {
    vec![[-6.0, 0.0, -1.0], [-2.0, 0.0, -1.0], [2.0, 0.0, -1.0]]
}

/// A fitted equivalent dipole array.
#[derive(Debug, Clone, PartialEq)]
pub struct DipoleArrayModel {
    /// Source points, body frame, m.
    pub sources_m: Vec<[f64; 3]>,
    /// `PER_SOURCE` coefficients per source, in source order.
    pub coefficients: Vec<f64>,
}

/// Regressors of one sample (nT per coefficient): for each source, the
/// projection `uᵀ D(p − r_s) e_i` times `1`, `u_j`, `u'_j`.
fn row(sources: &[[f64; 3]], u: &[f64; 3], du: &[f64; 3], p: &[f64; 3]) -> Vec<f64> {
    let uv = Vector3::from(*u);
    let mut r = Vec::with_capacity(sources.len() * PER_SOURCE);
    for s in sources {
        let d = dipole_matrix(&(Vector3::from(*p) - Vector3::from(*s)));
        let w = d.transpose() * uv * 1e9; // nT per A·m²
        r.extend(w.iter());
        for i in 0..3 {
            r.extend(u.iter().map(|uj| w[i] * uj));
        }
        for i in 0..3 {
            r.extend(du.iter().map(|dj| w[i] * dj));
        }
    }
    r
}

/// Regressor columns of heading `h` (high-passed when `hp`) and its
/// high-passed `s0`.
fn columns(sources: &[[f64; 3]], h: &PodHeading, hp: bool) -> Result<(Vec<Vec<f64>>, Vec<f64>)> {
    let p = prepare(h)?;
    let rows: Vec<Vec<f64>> = (0..h.u.len())
        .map(|k| row(sources, &h.u[k], &p.du[k], &h.pod_body_m[k]))
        .collect();
    let m = sources.len() * PER_SOURCE;
    let cols = (0..m)
        .map(|c| {
            let col: Vec<f64> = rows.iter().map(|r| r[c]).collect();
            if hp { detrend(&col) } else { col }
        })
        .collect();
    Ok((cols, p.s0))
}

/// Farthest source point taken, m (the helicopter hangs some tens of metres
/// above the pod; 1e300 m made the design NaN).
pub const MAX_SOURCE_M: f64 = 1000.0;

/// Most source points of a dipole array (the default has 3). Each adds
/// [`PER_SOURCE`] coefficients and the solve's time grows with their
/// square: 30 points took 60 s on a 12-minute flight at 20 Hz and 300 did
/// not finish.
pub const MAX_SOURCE_POINTS: usize = 8;

/// Check source points: 1 to [`MAX_SOURCE_POINTS`] of them, each within
/// [`MAX_SOURCE_M`] of the body frame's origin (bad input otherwise).
pub fn check_source_points(sources: &[[f64; 3]]) -> Result<()> {
    if sources.is_empty() || sources.len() > MAX_SOURCE_POINTS {
        return Err(CompError::setting(format!(
            "{} source points: 1 to {MAX_SOURCE_POINTS} are taken",
            sources.len()
        )));
    }
    if let Some(p) = sources.iter().find(|p| {
        p.iter().any(|x| x.is_nan()) || p.iter().map(|x| x * x).sum::<f64>().sqrt() > MAX_SOURCE_M
    }) {
        return Err(CompError::setting(format!(
            "source point ({}) m is not within {MAX_SOURCE_M} m of the body frame's origin: metres expected",
            p.map(aeromag_core::error::shown).join(", ")
        )));
    }
    Ok(())
}

/// Fit the equivalent dipole array at `sources` (body frame, m) jointly on
/// all `headings`. Errors: no headings, sources refused by
/// [`check_source_points`], bad data.
pub fn fit_dipole_array(headings: &[PodHeading], sources: &[[f64; 3]]) -> Result<DipoleArrayModel> {
    if headings.is_empty() {
        return Err(CompError::data("dipole-array pod fit needs headings"));
    }
    check_source_points(sources)?;
    let m = sources.len() * PER_SOURCE;
    let mut cols: Vec<Vec<f64>> = vec![Vec::new(); m];
    let mut y = Vec::new();
    for h in headings {
        let (c, s0) = columns(sources, h, true)?;
        for (dst, src) in cols.iter_mut().zip(c) {
            dst.extend(src);
        }
        y.extend(s0);
    }
    let a = DMatrix::from_fn(y.len(), m, |r, c| cols[c][r]);
    let x = lstsq(a, &DVector::from_vec(y))?;
    Ok(DipoleArrayModel {
        sources_m: sources.to_vec(),
        coefficients: x.iter().copied().collect(),
    })
}

/// High-passed prediction of `model` on heading `h`, nT.
pub fn predict_dipole_array(model: &DipoleArrayModel, h: &PodHeading) -> Result<Vec<f64>> {
    predict(model, h, true)
}

/// Prediction of `model` on heading `h` without the high-pass: the field of
/// the equivalent array at the pod projected on `u`, nT (its constant is
/// not determined by the high-passed fit).
pub fn predict_dipole_array_raw(model: &DipoleArrayModel, h: &PodHeading) -> Result<Vec<f64>> {
    predict(model, h, false)
}

fn predict(model: &DipoleArrayModel, h: &PodHeading, hp: bool) -> Result<Vec<f64>> {
    if model.coefficients.len() != model.sources_m.len() * PER_SOURCE {
        return Err(CompError::data(
            "dipole-array model: wrong coefficient count",
        ));
    }
    let (cols, s0) = columns(&model.sources_m, h, hp)?;
    Ok((0..s0.len())
        .map(|k| {
            cols.iter()
                .zip(&model.coefficients)
                .map(|(c, x)| c[k] * x)
                .sum()
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_inputs_are_errors() {
        let h = PodHeading {
            total_nt: vec![0.0; 20],
            track_nt: vec![0.0; 20],
            u: vec![[0.7, 0.0, 0.7]; 20],
            pod_body_m: vec![[-13.0, 0.0, 38.0]; 20],
            dt_s: 0.05,
        };
        assert!(fit_dipole_array(std::slice::from_ref(&h), &[]).is_err());
        assert!(fit_dipole_array(&[], &default_source_points()).is_err());
        assert!(fit_dipole_array(std::slice::from_ref(&h), &[[f64::NAN, 0.0, 0.0]]).is_err());
        // 300 source points ran for minutes; more than MAX_SOURCE_POINTS
        // are refused before the solve, as bad input.
        let many: Vec<[f64; 3]> = (0..=MAX_SOURCE_POINTS)
            .map(|k| [k as f64, 0.0, -1.0])
            .collect();
        let e = fit_dipole_array(std::slice::from_ref(&h), &many).unwrap_err();
        assert!(
            e.is_bad_input() && e.to_string().contains("source points"),
            "{e}"
        );
        assert!(check_source_points(&many[..MAX_SOURCE_POINTS]).is_ok());
        let m = DipoleArrayModel {
            sources_m: default_source_points(),
            coefficients: vec![0.0; 3],
        };
        assert!(predict_dipole_array(&m, &h).is_err());
    }
}
