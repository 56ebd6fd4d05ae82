//! The tail rotor in the rotor model, fitted jointly with the main rotor
//! (spec `helicopter.md` part A: "the rotating magnetized blades of the
//! main (and tail) rotor"; seed `000_…` §13).
//!
//! The tail rotor's blades are the same linear blade model
//! ([`super::linear`]) in their own plane: [`RotorGeometry::with_plane`]
//! (angular velocity along the tail rotor's axis, azimuth 0 towards a
//! reference direction), with a constant cone. Its rate is geared to the
//! main rotor, so its phase is known from the main rotor's phase up to a
//! constant:
//!
//! `ψ_t(t) = k ψ(t) + φ_0`, `Ω_t = k Ω`
//!
//! (`k` the gear ratio from the type data, `φ_0` unknown; `ψ` the recorded
//! phase smoothed at [`TAIL_PHASE_CUTOFF_HZ`], as the gear multiplies the
//! channel's noise by `k`). The fit ([`fit_with_tail`]):
//!
//! 1. the main rotor's columns (nominal cone) are fitted alone; the tail
//!    rotor is a periodic signal at `k f_r`, not a harmonic of `f_r` for a
//!    non-integer `k`, so it barely biases them;
//! 2. `φ_0` minimises the high-passed residual of the tail rotor's columns
//!    fitted to what the main rotor leaves, over `[0, 2π/N_t)` (blade
//!    labels are arbitrary: a shift by one blade permutes the per-blade
//!    parameters) — a 12-point grid and a golden-section search;
//! 3. the main and tail columns are fitted together by least squares;
//! 4. optionally the main rotor's slowly varying angles are estimated on
//!    the reading minus the tail rotor's part, and step 3 is repeated with
//!    them.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use super::blade::{FlapAngles, RotorGeometry};
use super::coning::{SlowAngleOptions, fit_slow_angles};
use super::linear::{self, BladeTerms, RotorFit, RotorFitOptions, RotorInput, regressors};
use super::phase::smooth_phase;
use crate::error::{CompError, Result};

/// A tail rotor geared to the main rotor (module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TailRotor {
    /// Its geometry: hub, sensor, span and blades, and its plane.
    pub geometry: RotorGeometry,
    /// Tail rotor speed over main rotor speed.
    pub gear_ratio: f64,
    /// Constant cone angle, rad.
    pub coning_rad: f64,
}

impl TailRotor {
    /// Check the geometry and the gear ratio.
    pub fn validate(&self) -> Result<()> {
        self.geometry.validate()?;
        if !(self.gear_ratio.is_finite() && self.gear_ratio > 0.0 && self.coning_rad.is_finite()) {
            return Err(CompError::setting(
                "tail rotor: a positive gear ratio and a finite cone angle required",
            ));
        }
        Ok(())
    }

    /// The main rotor's recorded phase (rad, unwrapped) smoothed for
    /// gearing to the tail rotor ([`TAIL_PHASE_CUTOFF_HZ`]).
    pub fn smoothed_main_phase(main_phase_rad: &[f64], fs_hz: f64) -> Result<Vec<f64>> {
        smooth_phase(main_phase_rad, fs_hz, TAIL_PHASE_CUTOFF_HZ)
    }

    /// The tail rotor's interference (nT) with the parameters of `fit` and
    /// phase offset `offset_rad`, from the main rotor's recorded phase
    /// (rad, unwrapped) and speed (rad/s) sampled at `fs_hz`.
    pub fn predict(
        &self,
        fit: &RotorFit,
        offset_rad: f64,
        b_body_nt: &[Vector3<f64>],
        main_phase_rad: &[f64],
        main_omega_rad_s: &[f64],
        fs_hz: f64,
    ) -> Result<Vec<f64>> {
        let phase = Self::smoothed_main_phase(main_phase_rad, fs_hz)?;
        fit.predict_columns(&self.regressors(
            fit.terms,
            b_body_nt,
            &phase,
            main_omega_rad_s,
            offset_rad,
        )?)
    }

    /// The tail rotor's regressor columns (units as [`linear::regressors`])
    /// for the main rotor's phase (rad, smoothed:
    /// [`Self::smoothed_main_phase`]) and speed (rad/s), with phase offset
    /// `offset_rad`.
    pub fn regressors(
        &self,
        terms: BladeTerms,
        b_body_nt: &[Vector3<f64>],
        main_phase_rad: &[f64],
        main_omega_rad_s: &[f64],
        offset_rad: f64,
    ) -> Result<Vec<Vec<f64>>> {
        self.validate()?;
        let k = self.gear_ratio;
        let phase: Vec<f64> = main_phase_rad.iter().map(|p| k * p + offset_rad).collect();
        let omega: Vec<f64> = main_omega_rad_s.iter().map(|w| k * w).collect();
        let cone = [FlapAngles {
            coning_rad: self.coning_rad,
            ..FlapAngles::default()
        }];
        linear::regressors(
            &self.geometry,
            terms,
            &RotorInput {
                b_body_nt,
                phase_rad: &phase,
                omega_rad_s: &omega,
                angles: &cone,
            },
        )
    }
}

/// Cutoff of the smoothing of the main rotor's phase before it is geared
/// to the tail rotor, Hz ([`super::smooth_phase`]). Measured on the
/// `helicopter` scenario (seed 11, phase channel noise 0.2°, tail rotor at
/// 4 m): the high-passed residual of the tail rotor's columns fitted to its
/// true part is 0.46 nT with the raw phase, 0.19 / 0.11 / 0.14 nT smoothed
/// at 1 / 2 / 5 Hz, 0.007 nT with the true phase.
pub const TAIL_PHASE_CUTOFF_HZ: f64 = 2.0;

/// The result of [`fit_with_tail`].
#[derive(Debug, Clone, PartialEq)]
pub struct TailFit {
    /// The tail rotor's phase offset `φ_0`, rad, in `[0, 2π/N_t)`.
    pub offset_rad: f64,
    /// The main rotor's parameters (fitted jointly).
    pub main: RotorFit,
    /// The tail rotor's parameters (fitted jointly; the residual is the
    /// joint fit's).
    pub tail: RotorFit,
    /// The joint prediction, nT per sample.
    pub prediction_nt: Vec<f64>,
    /// The tail rotor's part of it, nT per sample.
    pub tail_prediction_nt: Vec<f64>,
    /// RMS of the tail rotor's part high-passed as the fit sees the data
    /// (the samples within the fit's edge left out), nT: the blade-passing
    /// signal that determines its parameters ([`Self::tail_is_seen`]).
    pub tail_highpassed_rms_nt: f64,
    /// The main rotor's slowly varying flap angles, when estimated.
    pub angles: Option<Vec<FlapAngles>>,
}

impl TailFit {
    /// Whether the tail rotor's blade-passing signal stands above the
    /// joint fit's residual (the high-passed RMS of its part at least the
    /// residual RMS).
    ///
    /// The fit sees the high-passed data alone; the prediction adds the
    /// tail rotor's slow part (its rotation average, which turns with the
    /// heading), and for a tail rotor far from the sensor that part is
    /// hundreds of times its blade-passing part: in the field of a
    /// rotating set of `N_t` blades at a distance `r` from a hub of
    /// radius `R`, the `N_t`-th harmonic falls off as `(R/r)^{N_t}` more
    /// steeply than the average. Parameters fitted to a blade-passing
    /// signal below the residual are the main rotor's misfit, and that
    /// factor turns them into tens of nT of slow error. Measured on the
    /// `helicopter` scenario (seeds 1 and 11, the preset's tail rotor):
    /// nose-boom sensor 17.7 m from the tail rotor's hub, high-passed part
    /// 0.016–0.023 nT against a residual of 0.064–0.065 nT, slow part of
    /// the prediction 14–18 nT RMS, and the applied model's error mean
    /// −8.1 to −14.2 nT, std 11–12 nT, whether the simulated helicopter
    /// has a tail rotor or not (its true part there is below 0.05 nT);
    /// sensor under the tail boom with a tail rotor, 10.19 against 0.11
    /// nT (error mean 0.52, std 0.21 nT, against −3.1 and 10.4 nT without
    /// the tail rotor modelled); 6 m behind the main shaft, 0.50 against
    /// 0.06 nT; under the tail boom with no tail rotor, 0.001 against
    /// 0.043 nT.
    pub fn tail_is_seen(&self) -> bool {
        self.tail_highpassed_rms_nt >= self.tail.residual_rms_nt
    }
}

/// RMS of `x` (nT) high-passed as the fit high-passes the data, the
/// samples within its edge left out.
fn highpassed_rms(x: &[f64], fs_hz: f64, opts: &RotorFitOptions) -> Result<f64> {
    let hp = linear::highpass(x, fs_hz, opts.highpass_hz)?;
    let edge = ((opts.edge_s * fs_hz).round() as usize).min(hp.len() / 2);
    let kept = &hp[edge..hp.len() - edge];
    Ok((kept.iter().map(|v| v * v).sum::<f64>() / kept.len().max(1) as f64).sqrt())
}

/// Fit the main rotor (geometry `geom`; nominal cone from `input`, or
/// slowly varying with `slow`) and the tail rotor together to `mag_nt`
/// (module docs). `input` gives the field and the main rotor's phase and
/// speed. With `slow`, the angles are estimated on the reading minus the
/// tail rotor's part of a first joint fit with the nominal cone (the tail
/// rotor's signal would otherwise pull them), then the joint fit is
/// repeated with them.
#[allow(clippy::too_many_arguments)]
pub fn fit_with_tail(
    geom: &RotorGeometry,
    tail: &TailRotor,
    terms: BladeTerms,
    input: &RotorInput,
    mag_nt: &[f64],
    fs_hz: f64,
    opts: &RotorFitOptions,
    slow: Option<&SlowAngleOptions>,
) -> Result<TailFit> {
    let phase = TailRotor::smoothed_main_phase(input.phase_rad, fs_hz)?;
    let tail_cols = |c: f64| tail.regressors(terms, input.b_body_nt, &phase, input.omega_rad_s, c);
    let main_cols = regressors(geom, terms, input)?;
    let first = joint(&main_cols, &tail_cols, None, terms, mag_nt, fs_hz, opts)?;
    let Some(slow) = slow else {
        return Ok(first);
    };
    let rest: Vec<f64> = mag_nt
        .iter()
        .zip(&first.tail_prediction_nt)
        .map(|(m, t)| m - t)
        .collect();
    let s = fit_slow_angles(geom, terms, input, &rest, fs_hz, opts, slow)?;
    let main_cols = regressors(
        geom,
        terms,
        &RotorInput {
            angles: &s.angles,
            ..*input
        },
    )?;
    let mut fit = joint(
        &main_cols,
        &tail_cols,
        Some(first.offset_rad),
        terms,
        mag_nt,
        fs_hz,
        opts,
    )?;
    fit.angles = Some(s.angles);
    Ok(fit)
}

/// Steps 1–3 of the module docs for given main-rotor columns (the offset
/// is searched unless given).
fn joint(
    main_cols: &[Vec<f64>],
    tail_cols: &dyn Fn(f64) -> Result<Vec<Vec<f64>>>,
    offset_rad: Option<f64>,
    terms: BladeTerms,
    mag_nt: &[f64],
    fs_hz: f64,
    opts: &RotorFitOptions,
) -> Result<TailFit> {
    let offset = match offset_rad {
        Some(c) => c,
        None => {
            let main = linear::fit_columns(main_cols, terms, mag_nt, fs_hz, opts)?;
            let rest: Vec<f64> = main
                .predict_columns(main_cols)?
                .iter()
                .zip(mag_nt)
                .map(|(p, m)| m - p)
                .collect();
            let blades = tail_cols(0.0)?.len() / terms.per_blade();
            super::minimise_periodic(
                &|c| {
                    Ok(
                        linear::fit_columns(&tail_cols(c)?, terms, &rest, fs_hz, opts)?
                            .residual_rms_nt,
                    )
                },
                std::f64::consts::TAU / blades.max(1) as f64,
                12,
            )?
        }
    };
    let tail = tail_cols(offset)?;
    let p_main = main_cols.len();
    let mut cols = main_cols.to_vec();
    cols.extend(tail);
    let fit = linear::fit_columns(&cols, terms, mag_nt, fs_hz, opts)?;
    let prediction_nt = fit.predict_columns(&cols)?;
    let (main, tail) = split(&fit, p_main);
    let tail_prediction_nt = tail.predict_columns(&cols[p_main..])?;
    let tail_highpassed_rms_nt = highpassed_rms(&tail_prediction_nt, fs_hz, opts)?;
    Ok(TailFit {
        offset_rad: offset,
        main,
        tail,
        prediction_nt,
        tail_prediction_nt,
        tail_highpassed_rms_nt,
        angles: None,
    })
}

/// A joint fit's parameters split after the first `p_main` (main rotor,
/// tail rotor), each with the joint residual.
pub fn split(joint: &RotorFit, p_main: usize) -> (RotorFit, RotorFit) {
    let part = |params: &[f64]| RotorFit {
        params: params.to_vec(),
        ..joint.clone()
    };
    (part(&joint.params[..p_main]), part(&joint.params[p_main..]))
}
