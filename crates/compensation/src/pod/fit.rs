//! Fitting and applying the pod model: the seed's two-step solve, the joint
//! solve, and the compensation rate per heading (spec `helicopter.md` part
//! B "Fit", seed `002_…` §4, eqs. 19–20).
//!
//! High-pass: every series of a heading is detrended (its least-squares
//! straight line removed). This removes the trends of the track term
//! (`V t` along north) and the steady interference, like the seed's
//! high-pass FIR, without edge transients.
//!
//! * **Two-step** ([`fit_two_step`]): on each heading `k` solve the 7
//!   heading coefficients `W_k` from the normal equations of
//!   `s0 = s − s3` on `D = (v1, v2, v1', v2', x, y, z)` (eq. 20); then solve
//!   `θ` from `W_k = M(U_k) θ` stacked over the headings (eqs. 6, 10–12).
//!   Compensation uses the small-signal model with the heading's `U`.
//! * **Joint** ([`fit_joint`]): one least-squares fit of the
//!   [`super::model::N_JOINT`] parameters on every sample of every heading
//!   with the regressors of [`super::model::large_signal_row`]
//!   (instantaneous `u`, no linearisation in `u`, every sample weighted
//!   equally instead of every heading coefficient, and the gradient of the
//!   eddy-current field that the seed's eqs. 10–12 omit); [`predict_joint`]
//!   applies it. With strong eddy currents in the helicopter the omitted
//!   eddy gradient, not the linearisation in the displacement, is what
//!   holds the seed's 43-parameter model back (module docs of [`super`]).
//!
//! Both least-squares problems are solved by a column-scaled SVD with
//! truncation ([`RCOND`]): level flights at one site leave some parameter
//! combinations unobservable (e.g. `U3` is nearly the same on every
//! heading); the minimum-norm solution predicts the observable ones.

use nalgebra::{DMatrix, DVector};

use super::model::{
    N_HEADING, N_JOINT, N_PARAMS, free_axes, heading_coefficients, heading_design, large_signal_row,
};
use crate::{CompError, Result};

/// Relative singular-value cut-off of the least-squares solves.
pub const RCOND: f64 = 1e-9;

/// One straight heading of pod data (one value per sample).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PodHeading {
    /// Scalar field at the pod, nT.
    pub total_nt: Vec<f64>,
    /// Track term `s3 = k_x x_N + k_h h`, nT (known gradients times the
    /// pod's north position and altitude; trends are removed later).
    pub track_nt: Vec<f64>,
    /// Direction cosines of the Earth field in the body frame.
    pub u: Vec<[f64; 3]>,
    /// Pod position in the body frame, m (from [`super::trajectory`]).
    pub pod_body_m: Vec<[f64; 3]>,
    /// Sample interval, s.
    pub dt_s: f64,
}

/// Result of [`fit_two_step`].
#[derive(Debug, Clone, PartialEq)]
pub struct TwoStepFit {
    /// Heading coefficients `W1..W7` per learning heading (step 1).
    pub heading_coefficients: Vec<[f64; N_HEADING]>,
    /// Model parameters `θ` (step 2), see [`super::model`].
    pub theta: Vec<f64>,
}

/// Remove the least-squares straight line from `x` (the high-pass).
pub fn detrend(x: &[f64]) -> Vec<f64> {
    let n = x.len() as f64;
    if x.len() < 2 {
        return vec![0.0; x.len()];
    }
    let tm = (n - 1.0) / 2.0;
    let xm = x.iter().sum::<f64>() / n;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (i, v) in x.iter().enumerate() {
        let t = i as f64 - tm;
        sxy += t * (v - xm);
        sxx += t * t;
    }
    let slope = sxy / sxx;
    x.iter()
        .enumerate()
        .map(|(i, v)| v - xm - slope * (i as f64 - tm))
        .collect()
}

fn rms(x: &[f64]) -> f64 {
    (x.iter().map(|v| v * v).sum::<f64>() / x.len().max(1) as f64).sqrt()
}

/// Per-heading quantities: steady `U`, rates `u'`, displacements `δp`.
pub(super) struct Prepared {
    pub(super) u0: [f64; 3],
    pub(super) du: Vec<[f64; 3]>,
    pub(super) dp: Vec<[f64; 3]>,
    /// High-passed `s0 = s − s3`.
    pub(super) s0: Vec<f64>,
}

pub(super) fn prepare(h: &PodHeading) -> Result<Prepared> {
    prepare_about(h, None)
}

/// [`prepare`] with the pod displacement `δp` taken about `reference` (body
/// frame, m) instead of the heading's mean position.
fn prepare_about(h: &PodHeading, reference: Option<[f64; 3]>) -> Result<Prepared> {
    let n = h.total_nt.len();
    if n < 16 || h.track_nt.len() != n || h.u.len() != n || h.pod_body_m.len() != n {
        return Err(CompError::data(format!(
            "pod heading needs ≥ 16 samples and equal lengths (total {n}, track {}, u {}, pod {})",
            h.track_nt.len(),
            h.u.len(),
            h.pod_body_m.len()
        )));
    }
    if !(h.dt_s.is_finite() && h.dt_s > 0.0) {
        return Err(CompError::setting("pod heading: dt_s must be positive"));
    }
    let finite = |v: &[f64; 3]| v.iter().all(|x| x.is_finite());
    if h.total_nt.iter().chain(&h.track_nt).any(|x| !x.is_finite())
        || !h.u.iter().all(finite)
        || !h.pod_body_m.iter().all(finite)
    {
        return Err(CompError::data("pod heading: non-finite input"));
    }
    let mean3 = |v: &[[f64; 3]]| {
        let mut m = [0.0; 3];
        v.iter()
            .for_each(|p| (0..3).for_each(|i| m[i] += p[i] / n as f64));
        m
    };
    let u0 = mean3(&h.u);
    let pm = reference.unwrap_or_else(|| mean3(&h.pod_body_m));
    let du = (0..n)
        .map(|k| {
            let (a, b) = (k.saturating_sub(1), (k + 1).min(n - 1));
            let span = (b - a) as f64 * h.dt_s;
            [0, 1, 2].map(|i| (h.u[b][i] - h.u[a][i]) / span)
        })
        .collect();
    let dp = h
        .pod_body_m
        .iter()
        .map(|p| [p[0] - pm[0], p[1] - pm[1], p[2] - pm[2]])
        .collect();
    let s: Vec<f64> = h
        .total_nt
        .iter()
        .zip(&h.track_nt)
        .map(|(a, b)| a - b)
        .collect();
    Ok(Prepared {
        u0,
        du,
        dp,
        s0: detrend(&s),
    })
}

/// Column-scaled, truncated-SVD least squares `min |A x − y|`.
pub(super) fn lstsq(a: DMatrix<f64>, y: &DVector<f64>) -> Result<DVector<f64>> {
    // Columns that are zero up to rounding (e.g. a `U1 = 0` heading set)
    // are dropped, not blown up to unit norm.
    let norms: Vec<f64> = (0..a.ncols()).map(|j| a.column(j).norm()).collect();
    let big = norms.iter().copied().fold(0.0, f64::max);
    let scale: Vec<f64> = norms
        .iter()
        .map(|&s| if s > 1e-12 * big { 1.0 / s } else { 0.0 })
        .collect();
    let mut a = a;
    for (j, s) in scale.iter().enumerate() {
        a.column_mut(j).scale_mut(*s);
    }
    // nalgebra's SVD never returns on NaN (a source point of 1e300 m ran
    // `pod fit` until killed): refuse non-finite values, and bound the
    // iterations.
    if a.iter().chain(y.iter()).any(|v| !v.is_finite()) {
        return Err(CompError::data(
            "pod least squares: non-finite values in the design",
        ));
    }
    let svd = a
        // `svd`'s own tolerance (5 ε), so the same bits where it converges.
        .try_svd(true, true, 5.0 * f64::EPSILON, 10_000)
        .ok_or_else(|| CompError::Singular {
            reason: "pod least squares: the SVD did not converge".into(),
        })?;
    let smax = svd.singular_values.max();
    let x = svd
        .solve(y, RCOND * smax)
        .map_err(|e| CompError::Singular {
            reason: format!("pod least squares: {e}"),
        })?;
    Ok(DVector::from_iterator(
        x.len(),
        x.iter().zip(&scale).map(|(v, s)| v * s),
    ))
}

/// The 7 regressor columns `D` of eq. 19: `v_a, v_b, v_a', v_b', x, y, z`
/// with `(a, b)` the free axes of the heading ([`free_axes`]: `1, 2` unless
/// `|U3|` is not the largest component) (high-passed when `hp`, else about
/// the heading's mean `U` and pod position).
fn small_signal_columns(h: &PodHeading, p: &Prepared, hp: bool) -> Vec<Vec<f64>> {
    let col = |f: &dyn Fn(usize) -> f64| {
        let c: Vec<f64> = (0..h.u.len()).map(f).collect();
        if hp { detrend(&c) } else { c }
    };
    let (a, b, _) = free_axes(&p.u0);
    vec![
        col(&|k| h.u[k][a] - p.u0[a]),
        col(&|k| h.u[k][b] - p.u0[b]),
        col(&|k| p.du[k][a]),
        col(&|k| p.du[k][b]),
        col(&|k| p.dp[k][0]),
        col(&|k| p.dp[k][1]),
        col(&|k| p.dp[k][2]),
    ]
}

/// Step 1 of the seed: heading coefficients `W1..W7` of one heading from
/// the normal equations of eq. 20. Errors: bad data.
pub fn fit_heading_coefficients(h: &PodHeading) -> Result<[f64; N_HEADING]> {
    let p = prepare(h)?;
    let cols = small_signal_columns(h, &p, true);
    let n = p.s0.len();
    let a = DMatrix::from_fn(n, N_HEADING, |r, c| cols[c][r]);
    let w = lstsq(a, &DVector::from_column_slice(&p.s0))?;
    Ok([0, 1, 2, 3, 4, 5, 6].map(|i| w[i]))
}

/// The seed's two-step solve over the learning `headings`: step 1 on each
/// heading, step 2 `θ` from `W_k = M(U_k) θ`. Errors: bad data.
pub fn fit_two_step(headings: &[PodHeading]) -> Result<TwoStepFit> {
    if headings.is_empty() {
        return Err(CompError::data("two-step pod fit needs headings"));
    }
    let mut ws = Vec::with_capacity(headings.len());
    let mut rows: Vec<[f64; N_PARAMS]> = Vec::new();
    let mut y = Vec::new();
    for h in headings {
        let w = fit_heading_coefficients(h)?;
        let m = heading_design(&prepare(h)?.u0)?;
        for (i, wi) in w.iter().enumerate() {
            rows.push(std::array::from_fn(|k| m[k][i]));
            y.push(*wi);
        }
        ws.push(w);
    }
    let a = DMatrix::from_fn(rows.len(), N_PARAMS, |r, c| rows[r][c]);
    let theta = lstsq(a, &DVector::from_vec(y))?;
    Ok(TwoStepFit {
        heading_coefficients: ws,
        theta: theta.iter().copied().collect(),
    })
}

/// Large-signal regressor columns (high-passed when `hp`).
fn joint_columns(h: &PodHeading, p: &Prepared, hp: bool) -> Vec<Vec<f64>> {
    let rows: Vec<[f64; N_JOINT]> = (0..h.u.len())
        .map(|k| large_signal_row(&h.u[k], &p.du[k], &p.dp[k]))
        .collect();
    (0..N_JOINT)
        .map(|c| {
            let col: Vec<f64> = rows.iter().map(|r| r[c]).collect();
            if hp { detrend(&col) } else { col }
        })
        .collect()
}

/// Result of [`fit_joint`]: the large-signal model expanded about a fixed
/// pod position.
#[derive(Debug, Clone, PartialEq)]
pub struct JointFit {
    /// Parameters: [`N_JOINT`] (or the [`N_PARAMS`] of a two-step fit, no
    /// eddy gradient), see [`super::model`].
    pub theta: Vec<f64>,
    /// Reference pod position of the expansion, body frame, m: the mean
    /// over all learning samples (`δp = p − reference`, the same on every
    /// heading, so that `P`, `A`, `b` are the coefficients at one point).
    pub reference_m: [f64; 3],
}

/// The joint solve of `θ` ([`super::model::N_JOINT`] parameters): one
/// least-squares fit of the high-passed large-signal model on all samples
/// of all `headings`, displacements about the mean pod position of all
/// samples. Errors: bad data.
pub fn fit_joint(headings: &[PodHeading]) -> Result<JointFit> {
    let count: usize = headings.iter().map(|h| h.pod_body_m.len()).sum();
    if count == 0 {
        return Err(CompError::data("joint pod fit needs headings"));
    }
    let mut reference = [0.0; 3];
    for p in headings.iter().flat_map(|h| &h.pod_body_m) {
        (0..3).for_each(|i| reference[i] += p[i] / count as f64);
    }
    let mut cols: Vec<Vec<f64>> = vec![Vec::new(); N_JOINT];
    let mut y = Vec::new();
    for h in headings {
        let p = prepare_about(h, Some(reference))?;
        for (c, col) in joint_columns(h, &p, true).into_iter().enumerate() {
            cols[c].extend(col);
        }
        y.extend(p.s0);
    }
    let a = DMatrix::from_fn(y.len(), N_JOINT, |r, c| cols[c][r]);
    Ok(JointFit {
        theta: lstsq(a, &DVector::from_vec(y))?.iter().copied().collect(),
        reference_m: reference,
    })
}

/// High-passed small-signal prediction `Σ W_i(U) D_i` on heading `h`, nT.
pub fn predict_small_signal(theta: &[f64], h: &PodHeading) -> Result<Vec<f64>> {
    small_signal(theta, h, true)
}

/// Small-signal prediction `Σ W_i(U) D_i` on heading `h` without the
/// high-pass (`v`, `v'`, `δp` about the heading's mean), nT: the
/// interference about its mean on the heading, for compensating a record.
pub fn predict_small_signal_raw(theta: &[f64], h: &PodHeading) -> Result<Vec<f64>> {
    small_signal(theta, h, false)
}

fn small_signal(theta: &[f64], h: &PodHeading, hp: bool) -> Result<Vec<f64>> {
    let p = prepare(h)?;
    let w = heading_coefficients(theta, &p.u0)?;
    let cols = small_signal_columns(h, &p, hp);
    Ok((0..p.s0.len())
        .map(|k| (0..N_HEADING).map(|i| w[i] * cols[i][k]).sum())
        .collect())
}

/// High-passed large-signal prediction of `fit` on heading `h`, nT.
pub fn predict_joint(fit: &JointFit, h: &PodHeading) -> Result<Vec<f64>> {
    joint(fit, h, true)
}

/// [`predict_joint`] without the high-pass: the large-signal model
/// `ΔB(u, u', δp)` of [`super::model`] (`δp` about `fit.reference_m`), up to
/// its undetermined constant, nT.
pub fn predict_joint_raw(fit: &JointFit, h: &PodHeading) -> Result<Vec<f64>> {
    joint(fit, h, false)
}

fn joint(fit: &JointFit, h: &PodHeading, hp: bool) -> Result<Vec<f64>> {
    let theta = &fit.theta;
    if theta.len() != N_PARAMS && theta.len() != N_JOINT {
        return Err(CompError::data(format!(
            "pod model needs {N_PARAMS} or {N_JOINT} parameters, got {}",
            theta.len()
        )));
    }
    if fit.reference_m.iter().any(|x| !x.is_finite()) {
        return Err(CompError::data("pod model: non-finite reference position"));
    }
    let p = prepare_about(h, Some(fit.reference_m))?;
    let cols = joint_columns(h, &p, hp);
    Ok((0..p.s0.len())
        .map(|k| theta.iter().zip(&cols).map(|(t, c)| t * c[k]).sum())
        .collect())
}

/// Compensation rate of heading `h` with the high-passed model prediction
/// `pred` (nT): `1 − RMS(after)/RMS(before)`, `before` the high-passed
/// field, `after` the high-passed `s − s3 − pred` (spec `helicopter.md`
/// part B). Errors: bad data, length mismatch, zero `before`.
pub fn compensation_rate(h: &PodHeading, pred: &[f64]) -> Result<f64> {
    let p = prepare(h)?;
    if pred.len() != p.s0.len() {
        return Err(CompError::data(
            "prediction length differs from the heading",
        ));
    }
    let before = rms(&detrend(&h.total_nt));
    if before <= 0.0 {
        return Err(CompError::data("heading without interference"));
    }
    let after: Vec<f64> = p.s0.iter().zip(pred).map(|(s, m)| s - m).collect();
    Ok(1.0 - rms(&after) / before)
}

/// Compensation rate of a whole set of headings (the seed's §5 states one
/// rate for its 8 independent headings, Fig. 7): `1 − √(Σ after² / Σ
/// before²)` over all samples of all headings, `before` and `after` as in
/// [`compensation_rate`] (each heading high-passed on its own). Headings
/// with a large interference weigh more than in the per-heading minimum or
/// mean. Errors: as [`compensation_rate`], count mismatch, no headings.
pub fn compensation_rate_pooled<H: std::borrow::Borrow<PodHeading>>(
    headings: &[H],
    preds: &[Vec<f64>],
) -> Result<f64> {
    if headings.is_empty() || headings.len() != preds.len() {
        return Err(CompError::data(format!(
            "pooled rate needs one prediction per heading ({} headings, {} predictions)",
            headings.len(),
            preds.len()
        )));
    }
    let (mut before, mut after) = (0.0, 0.0);
    for (h, pred) in headings.iter().zip(preds) {
        let h = h.borrow();
        let n = h.total_nt.len() as f64;
        let b = rms(&detrend(&h.total_nt));
        let r = compensation_rate(h, pred)?;
        before += n * b * b;
        after += n * (b * (1.0 - r)).powi(2);
    }
    Ok(1.0 - (after / before).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// NaN in the design is an error at once (nalgebra's SVD never
    /// returned on it: `pod fit` with a source point at 1e300 m hung).
    #[test]
    fn a_non_finite_design_is_an_error_not_a_hang() {
        let mut a = DMatrix::from_fn(20, 3, |i, j| {
            ((i + 1) * (j + 2)) as f64 % 7.0 + 0.1 * i as f64
        });
        let y = DVector::from_fn(20, |i, _| i as f64);
        assert!(lstsq(a.clone(), &y).is_ok());
        a[(4, 1)] = f64::NAN;
        assert!(lstsq(a, &y).unwrap_err().is_bad_input());
    }

    #[test]
    fn detrend_removes_lines_only() {
        let x: Vec<f64> = (0..50).map(|i| 3.0 + 0.2 * i as f64).collect();
        assert!(detrend(&x).iter().all(|v| v.abs() < 1e-12));
        let s: Vec<f64> = (0..50).map(|i| (i as f64 * 0.7).sin()).collect();
        assert!(rms(&detrend(&s)) > 0.5);
    }

    /// A level heading whose field is exactly the small-signal model of
    /// `theta` (eq. 19 with `W = M(U) θ`): the seed's manoeuvres (5° at
    /// 0.1 Hz, pitch, roll, yaw in turn) and a pod swinging by metres.
    fn small_signal_heading(theta: &[f64], heading_deg: f64) -> PodHeading {
        use super::super::trajectory::direction_cosines;
        use aeromag_core::frames::Attitude;
        let (n, dt) = (600, 0.05);
        let psi0 = heading_deg.to_radians();
        let mut h = PodHeading {
            dt_s: dt,
            total_nt: vec![0.0; n],
            track_nt: vec![0.0; n],
            ..PodHeading::default()
        };
        for k in 0..n {
            let t = k as f64 * dt;
            let a = 5f64.to_radians() * (0.2 * std::f64::consts::PI * t).sin();
            let att = match k / 200 {
                0 => Attitude::new(0.0, a, psi0),
                1 => Attitude::new(a, 0.0, psi0),
                _ => Attitude::new(0.0, 0.0, psi0 + a),
            };
            h.u.push(direction_cosines(45f64.to_radians(), 0.0, &att));
            let w = 0.49 * t + psi0;
            h.pod_body_m.push([
                -13.7 + 3.0 * w.sin(),
                1.2 * (0.31 * t).sin(),
                38.8 + w.cos(),
            ]);
        }
        let p = prepare(&h).unwrap();
        let w = heading_coefficients(theta, &p.u0).unwrap();
        let cols = small_signal_columns(&h, &p, false);
        h.total_nt = (0..n)
            .map(|k| (0..N_HEADING).map(|i| w[i] * cols[i][k]).sum())
            .collect();
        h
    }

    /// Implementation check of the seed's two-step solve: on data that are
    /// exactly the small-signal model, step 1 recovers each heading's
    /// `W1..W7` and step 2 maps them to parameters that give the true
    /// heading coefficients and ≈ 100 % compensation on the seed's
    /// independent headings (only the combinations of `θ` that level
    /// flights observe are identified, and only those are needed).
    #[test]
    fn two_step_is_exact_on_small_signal_data() {
        let theta: Vec<f64> = (0..N_PARAMS)
            .map(|k| ((k * 37 % 11) as f64 - 5.0) * if k < 16 { 2.0 } else { 0.05 })
            .collect();
        let learn: Vec<PodHeading> = [0.0, 90.0, 180.0, 270.0, 45.0, 135.0, 225.0, 315.0]
            .iter()
            .map(|&d| small_signal_heading(&theta, d))
            .collect();
        let fit = fit_two_step(&learn).unwrap();
        for (h, w) in learn.iter().zip(&fit.heading_coefficients) {
            let truth = heading_coefficients(&theta, &prepare(h).unwrap().u0).unwrap();
            for (a, b) in w.iter().zip(&truth) {
                assert!((a - b).abs() < 1e-6 * (1.0 + b.abs()), "{w:?} {truth:?}");
            }
        }
        for d in [30.0, 120.0, 210.0, 300.0, 70.0, 160.0, 250.0, 340.0] {
            let h = small_signal_heading(&theta, d);
            let u0 = prepare(&h).unwrap().u0;
            let got = heading_coefficients(&fit.theta, &u0).unwrap();
            let truth = heading_coefficients(&theta, &u0).unwrap();
            for (a, b) in got.iter().zip(&truth) {
                assert!(
                    (a - b).abs() < 1e-6 * (1.0 + b.abs()),
                    "{d}: {got:?} {truth:?}"
                );
            }
            let pred = predict_small_signal(&fit.theta, &h).unwrap();
            assert!(compensation_rate(&h, &pred).unwrap() > 0.9999);
        }
        // Pooled rate: a zero prediction leaves everything, a perfect one
        // nothing; mismatched counts are errors.
        let zero: Vec<Vec<f64>> = learn.iter().map(|h| vec![0.0; h.u.len()]).collect();
        assert!(compensation_rate_pooled(&learn, &zero).unwrap().abs() < 1e-12);
        let exact: Vec<Vec<f64>> = learn.iter().map(|h| detrend(&h.total_nt)).collect();
        assert!((compensation_rate_pooled(&learn, &exact).unwrap() - 1.0).abs() < 1e-12);
        assert!(compensation_rate_pooled(&learn, &exact[..3]).is_err());
    }

    #[test]
    fn bad_headings_are_errors() {
        let h = PodHeading {
            total_nt: vec![1.0; 20],
            dt_s: 0.05,
            ..PodHeading::default()
        };
        assert!(fit_heading_coefficients(&h).is_err());
        assert!(fit_two_step(&[]).is_err());
        assert!(fit_joint(&[]).is_err());
    }
}
