//! The extension with slowly varying coning and tip-path-plane tilt (spec
//! `helicopter.md` part A: "estimate a slowly varying coning angle
//! jointly"; the thesis names the evolution of the rotor cone as the
//! weakness of the filtering methods).
//!
//! The interference `T(θ, β(t))` is linear in the blade parameters `θ` and
//! nonlinear in the flap angles `β = (β0, a1, b1)`. Alternating
//! (Gauss–Newton on `β` with `θ` fixed, then least squares on `θ`):
//!
//! 1. fit `θ` with the current angles ([`super::linear::fit_columns`]);
//! 2. linearise in the angles: `H_i = ∂T/∂β_i = Σ θ_c ∂g_c/∂β_i` by
//!    forward differences (`Δβ = 10⁻⁴ rad`), high-passed like the data, and
//!    solve one joint Gauss–Newton least-squares problem for the blade
//!    parameters and a constant increment `δβ_{w,i}` on every window `w` of
//!    `window_s`: `y ≈ Σ θ_c G_c + Σ δβ_{w,i} 1_w H_i` (`G_c` the
//!    high-passed regressors; sparse rows, dense normal equations solved by
//!    Cholesky with a 10⁻⁶ equilibrated ridge on the increments); the
//!    increments at the window centres are interpolated linearly to every
//!    sample (the joint step lets the parameters and the angles move
//!    together). With `joint = false` (default) the increments are instead
//!    solved window by window with the parameters fixed (alternating);
//! 3. repeat `iterations` times, then refit `θ`.
//!
//! With `estimate_tilt = false` only the coning `β0` varies. With
//! `estimate_phase = true` a slowly varying correction of the rotor phase
//! `δψ(t)` is estimated the same way (∂T/∂ψ by forward differences): this
//! is the nonlinear refinement of a phase tracked from the data
//! ([`super::phase`]), whose harmonic phase also moves slowly with the
//! heading and the attitude (the soft-iron part of every harmonic depends
//! on the field direction).

use serde::{Deserialize, Serialize};

use super::blade::{FlapAngles, RotorGeometry};
use super::linear::{
    BladeTerms, RotorFit, RotorFitOptions, RotorInput, fit_columns, highpass, regressors,
};
use crate::error::{CompError, Result};

/// Options of the slowly-varying-angle fit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SlowAngleOptions {
    /// Window over which the angles are taken as constant, s. Default 1.
    pub window_s: f64,
    /// Gauss–Newton/least-squares alternations. Default 3.
    pub iterations: usize,
    /// Also estimate the two tilts. Default true.
    pub estimate_tilt: bool,
    /// Also estimate a slowly varying rotor-phase correction. Default false
    /// (a phase channel is trusted).
    pub estimate_phase: bool,
    /// Joint Gauss–Newton step (parameters and increments together) instead
    /// of alternating. Default false; use true with `estimate_phase` (the
    /// phase tracked from data is biased by the heading-dependent phase of
    /// the harmonics, which the parameters absorb when alternating).
    pub joint: bool,
}

impl Default for SlowAngleOptions {
    fn default() -> Self {
        Self {
            window_s: 1.0,
            iterations: 3,
            estimate_tilt: true,
            estimate_phase: false,
            joint: false,
        }
    }
}

/// A fit with slowly varying flap angles.
#[derive(Debug, Clone, PartialEq)]
pub struct SlowAngleFit {
    /// The blade parameters (fitted with the final angles).
    pub fit: RotorFit,
    /// The flap angles at every sample.
    pub angles: Vec<FlapAngles>,
    /// The (refined) rotor phase at every sample, rad.
    pub phase_rad: Vec<f64>,
}

fn with<'a>(input: &RotorInput<'a>, angles: &'a [FlapAngles], phase: &'a [f64]) -> RotorInput<'a> {
    RotorInput {
        angles,
        phase_rad: phase,
        ..*input
    }
}

/// Fit the blade parameters and slowly varying angles, starting from the
/// angles of `input` (module docs).
pub fn fit_slow_angles(
    geom: &RotorGeometry,
    terms: BladeTerms,
    input: &RotorInput,
    mag_nt: &[f64],
    fs_hz: f64,
    fit_opts: &RotorFitOptions,
    opts: &SlowAngleOptions,
) -> Result<SlowAngleFit> {
    slow_angles(geom, terms, input, mag_nt, fs_hz, fit_opts, opts, None)
}

/// Apply a fitted model to new data: the blade parameters of `model` stay
/// fixed and only the slowly varying angles (and, with
/// `opts.estimate_phase`, the phase correction) are estimated on `mag_nt`,
/// window by window (the alternating step of the module docs; `opts.joint`
/// is ignored). The returned [`SlowAngleFit::fit`] holds `model`'s
/// parameters and the residual on this record.
pub fn track_slow_angles(
    geom: &RotorGeometry,
    model: &RotorFit,
    input: &RotorInput,
    mag_nt: &[f64],
    fs_hz: f64,
    fit_opts: &RotorFitOptions,
    opts: &SlowAngleOptions,
) -> Result<SlowAngleFit> {
    let opts = SlowAngleOptions {
        joint: false,
        ..*opts
    };
    slow_angles(
        geom,
        model.terms,
        input,
        mag_nt,
        fs_hz,
        fit_opts,
        &opts,
        Some(model),
    )
}

/// RMS of the high-passed residual `y − HP[Σ θ G]` of fixed parameters
/// (`edge_s` excluded at each end), nT.
fn fixed_residual(
    model: &RotorFit,
    cols: &[Vec<f64>],
    y_hp: &[f64],
    fs_hz: f64,
    fit_opts: &RotorFitOptions,
) -> Result<f64> {
    let n = y_hp.len();
    let pred = highpass(&model.predict_columns(cols)?, fs_hz, fit_opts.highpass_hz)?;
    let edge = ((fit_opts.edge_s * fs_hz).round() as usize).min(n / 4);
    let m = (n - 2 * edge).max(1) as f64;
    Ok(((edge..n - edge)
        .map(|k| (y_hp[k] - pred[k]).powi(2))
        .sum::<f64>()
        / m)
        .sqrt())
}

#[allow(clippy::too_many_arguments)]
fn slow_angles(
    geom: &RotorGeometry,
    terms: BladeTerms,
    input: &RotorInput,
    mag_nt: &[f64],
    fs_hz: f64,
    fit_opts: &RotorFitOptions,
    opts: &SlowAngleOptions,
    fixed: Option<&RotorFit>,
) -> Result<SlowAngleFit> {
    let n = mag_nt.len();
    let win = (opts.window_s * fs_hz).round() as usize;
    if win < 10 || n < 2 * win {
        return Err(CompError::setting(
            "slow-angle fit: window too short or data shorter than two windows",
        ));
    }
    let mut angles: Vec<FlapAngles> = (0..n)
        .map(|k| {
            input.angles[if input.angles.len() == 1 {
                0
            } else {
                k.min(input.angles.len() - 1)
            }]
        })
        .collect();
    let y = highpass(mag_nt, fs_hz, fit_opts.highpass_hz)?;
    let mut active = vec![0usize];
    if opts.estimate_tilt {
        active.extend([1, 2]);
    }
    if opts.estimate_phase {
        active.push(3);
    }
    let na = active.len();
    let eps = 1e-4;
    let mut phase = input.phase_rad.to_vec();
    let mut cols = regressors(geom, terms, &with(input, &angles, &phase))?;
    let refit = |cols: &[Vec<f64>]| -> Result<RotorFit> {
        match fixed {
            None => fit_columns(cols, terms, mag_nt, fs_hz, fit_opts),
            Some(m) => Ok(RotorFit {
                residual_rms_nt: fixed_residual(m, cols, &y, fs_hz, fit_opts)?,
                ..m.clone()
            }),
        }
    };
    let mut fit = refit(&cols)?;
    for _ in 0..opts.iterations {
        let pred = highpass(&fit.predict_columns(&cols)?, fs_hz, fit_opts.highpass_hz)?;
        let base = fit.predict_columns(&cols)?;
        let mut derivs = Vec::with_capacity(na);
        for &i in &active {
            let shifted: Vec<FlapAngles> = angles
                .iter()
                .map(|a| {
                    let mut b = *a;
                    match i {
                        0 => b.coning_rad += eps,
                        1 => b.tilt_lon_rad += eps,
                        2 => b.tilt_lat_rad += eps,
                        _ => {}
                    }
                    b
                })
                .collect();
            let ph: Vec<f64> = phase
                .iter()
                .map(|p| if i == 3 { p + eps } else { *p })
                .collect();
            let p = fit.predict(geom, &with(input, &shifted, &ph))?;
            let d: Vec<f64> = p.iter().zip(&base).map(|(a, b)| (a - b) / eps).collect();
            derivs.push(highpass(&d, fs_hz, fit_opts.highpass_hz)?);
        }
        let mut centres = Vec::new();
        let mut steps: Vec<[f64; 4]> = Vec::new();
        if !opts.joint {
            // Per-window increments with the blade parameters fixed.
            let mut start = 0;
            while start + win <= n {
                let end = if start + 2 * win > n { n } else { start + win };
                let mut ata = nalgebra::DMatrix::<f64>::zeros(na, na);
                let mut atb = nalgebra::DVector::<f64>::zeros(na);
                for k in start..end {
                    let r = y[k] - pred[k];
                    for i in 0..na {
                        atb[i] += derivs[i][k] * r;
                        for j in 0..na {
                            ata[(i, j)] += derivs[i][k] * derivs[j][k];
                        }
                    }
                }
                let scale = (0..na).map(|i| ata[(i, i)]).fold(0.0, f64::max).max(1e-300);
                for i in 0..na {
                    ata[(i, i)] += 1e-8 * scale;
                }
                let mut s4 = [0.0; 4];
                if let Some(x) = ata.lu().solve(&atb) {
                    for (i, &a) in active.iter().enumerate() {
                        s4[a] = x[i];
                    }
                }
                centres.push(0.5 * (start + end - 1) as f64);
                steps.push(s4);
                start = end;
            }
        } else {
            // Joint Gauss–Newton step: blade parameters θ (all samples) and
            // per-window increments δ_{w,i} of the active slow quantities:
            // y ≈ Σ_c θ_c G_c + Σ_{w,i} δ_{w,i} 1_w(t) H_i(t).
            let g: Vec<Vec<f64>> = cols
                .iter()
                .map(|c| highpass(c, fs_hz, fit_opts.highpass_hz))
                .collect::<Result<_>>()?;
            let np = g.len();
            let nw = n / win;
            let m = np + nw * na;
            let edge = ((fit_opts.edge_s * fs_hz).round() as usize).min(n / 4);
            let mut ata = nalgebra::DMatrix::<f64>::zeros(m, m);
            let mut atb = nalgebra::DVector::<f64>::zeros(m);
            let mut row = vec![0.0; np + na];
            let mut idx = vec![0usize; np + na];
            for k in edge..n - edge {
                let w = (k / win).min(nw - 1);
                for c in 0..np {
                    row[c] = g[c][k];
                    idx[c] = c;
                }
                for i in 0..na {
                    row[np + i] = derivs[i][k];
                    idx[np + i] = np + w * na + i;
                }
                for (a, &ia) in idx.iter().enumerate() {
                    atb[ia] += row[a] * y[k];
                    for (b, &ib) in idx.iter().enumerate() {
                        ata[(ia, ib)] += row[a] * row[b];
                    }
                }
            }
            // Equilibrated ridge (1e-6 of each diagonal) keeps uninformative
            // windows at zero increment.
            for i in 0..m {
                let d = ata[(i, i)];
                ata[(i, i)] += if i < np { 1e-12 * d } else { 1e-6 * d + 1e-300 };
            }
            let sol = ata
                .cholesky()
                .ok_or_else(|| CompError::Singular {
                    reason: "slow-angle fit: singular normal equations".into(),
                })?
                .solve(&atb);
            for w in 0..nw {
                let mut s4 = [0.0; 4];
                for (i, &a) in active.iter().enumerate() {
                    s4[a] = sol[np + w * na + i];
                }
                let end = if w + 1 == nw { n } else { (w + 1) * win };
                centres.push(0.5 * (w * win + end - 1) as f64);
                steps.push(s4);
            }
        }
        for (k, (a, ph)) in angles.iter_mut().zip(phase.iter_mut()).enumerate() {
            let kf = k as f64;
            let j = centres.partition_point(|c| *c <= kf);
            let s = if j == 0 {
                steps[0]
            } else if j >= centres.len() {
                steps[centres.len() - 1]
            } else {
                let w = (kf - centres[j - 1]) / (centres[j] - centres[j - 1]);
                std::array::from_fn(|i| (1.0 - w) * steps[j - 1][i] + w * steps[j][i])
            };
            a.coning_rad += s[0];
            a.tilt_lon_rad += s[1];
            a.tilt_lat_rad += s[2];
            *ph += s[3];
        }
        cols = regressors(geom, terms, &with(input, &angles, &phase))?;
        fit = refit(&cols)?;
    }
    Ok(SlowAngleFit {
        fit,
        angles,
        phase_rad: phase,
    })
}
