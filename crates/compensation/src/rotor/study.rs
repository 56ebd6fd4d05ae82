//! The rotor-interference comparison of spec `helicopter.md` part A ("What
//! to show", issue 5): the physical model against the filter baselines on a
//! record whose true rotor interference and anomaly are known (the
//! `helicopter` scenario of `aeromag-sim`). One implementation shared by the
//! crate's tests, `aeromag rotor study` and `aeromag demo`.
//!
//! Metrics (all RMS about the mean, nT, `edge` samples at each end
//! excluded):
//! * residual rotor interference: `true_rotor − prediction` for the model
//!   (fitted to the full scalar record: fuselage, anomaly and noise
//!   included); for the linear baselines the part of `true_rotor` they let
//!   through;
//! * signal removed: the part of a signal each method takes away, by
//!   linearity (the method applied to the signal alone with the same phase,
//!   field and angles), relative to the signal's RMS. Three signals: the
//!   record's true anomaly, and trains of Gaussian bumps of 0.5 s and 0.1 s
//!   standard width ([`bumps`]; shallow sources passed at speed), which is
//!   what low-pass filters hurt.
//!
//! Methods: full model (7 terms per blade) with nominal cone; the same with
//! slowly varying cone and tilt ([`fit_slow_angles`]); the thesis'
//! simplified model (3 per blade) in both forms; with a tail rotor, the
//! full model with slowly varying cone fitted jointly with it
//! ([`fit_with_tail`]; the study's prediction is then this one); low-pass at 0.8 of
//! the blade-passing and of the rotor frequency; notches at 1…16 `f_r`;
//! synchronous averaging over 10 s blocks.

use nalgebra::Vector3;

use super::lowpass::lowpass;
use super::notch::{NotchOptions, notch_harmonics};
use super::synchronous::synchronous_template;
use super::{
    BladeTerms, FlapAngles, RotorFitOptions, RotorGeometry, RotorInput, SlowAngleOptions,
    TailRotor, fit, fit_slow_angles, fit_with_tail, linear, regressors, rotor_speed, unwrap_deg,
};
use crate::error::{CompError, Result};

/// Rotor geometry of the `helicopter` scenario of `aeromag-sim` (defaults):
/// hub at (0, 0, −2.6) m, nose-boom sensor at (5, 0, 0.6) m (body axes),
/// blades from 0.8 to 7.5 m, 4 blades.
pub fn scenario_geometry() -> RotorGeometry {
    RotorGeometry::main_rotor([0.0, 0.0, -2.6], [5.0, 0.0, 0.6], 0.8, 7.5, 4)
}

/// The tail rotor of the `helicopter` scenario's `[tail_rotor]` table
/// (defaults) seen from a sensor at `sensor_m` (body axes, m): hub at
/// (−12.7, −1.0, −2.4) m, blades from 0.3 to 1.95 m, 3 blades, turning
/// about −y with azimuth 0 up, geared 4.37 to the main rotor, cone 1°.
pub fn scenario_tail_rotor(sensor_m: [f64; 3]) -> TailRotor {
    TailRotor {
        geometry: RotorGeometry::main_rotor([-12.7, -1.0, -2.4], sensor_m, 0.3, 1.95, 3)
            .with_plane([0.0, -1.0, 0.0], [0.0, 0.0, -1.0]),
        gear_ratio: 4.37,
        coning_rad: 1f64.to_radians(),
    }
}

/// Nominal rotor cone of the scenario: coning 4°, longitudinal tilt −1.5°.
pub fn nominal_angles() -> FlapAngles {
    FlapAngles {
        coning_rad: 4f64.to_radians(),
        tilt_lon_rad: (-1.5f64).to_radians(),
        tilt_lat_rad: 0.0,
    }
}

/// A train of Gaussian bumps (nT) of standard width `sigma_s` (s), one every
/// 25 s starting at 12.5 s, amplitudes alternating +5 and −3 nT, sampled at
/// `fs_hz` for `n` samples.
pub fn bumps(n: usize, fs_hz: f64, sigma_s: f64) -> Vec<f64> {
    let count = (n as f64 / fs_hz / 25.0) as usize;
    (0..n)
        .map(|k| {
            let t = k as f64 / fs_hz;
            (0..count)
                .map(|i| {
                    let t0 = 12.5 + 25.0 * i as f64;
                    let amp = if i % 2 == 0 { 5.0 } else { -3.0 };
                    amp * (-(t - t0).powi(2) / (2.0 * sigma_s * sigma_s)).exp()
                })
                .sum()
        })
        .collect()
}

/// Standard deviation (RMS about the mean) of `x` without `edge` samples at
/// each end, in the unit of `x` (0 if nothing is left).
pub fn std_mid(x: &[f64], edge: usize) -> f64 {
    if x.len() <= 2 * edge {
        return 0.0;
    }
    let s = &x[edge..x.len() - edge];
    let m = s.iter().sum::<f64>() / s.len() as f64;
    (s.iter().map(|v| (v - m).powi(2)).sum::<f64>() / s.len() as f64).sqrt()
}

fn diff(a: &[f64], b: &[f64]) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| x - y).collect()
}

/// Columns of a record with known truth (units as named; one value per
/// sample, all the same length).
#[derive(Debug, Clone, Copy)]
pub struct StudyInput<'a> {
    /// Scalar magnetometer reading, nT.
    pub mag_nt: &'a [f64],
    /// Vector magnetometer in body axes, nT.
    pub b_body_nt: &'a [Vector3<f64>],
    /// Rotor phase channel, deg (wrapped or not).
    pub rotor_phase_deg: &'a [f64],
    /// True rotor interference, nT.
    pub true_rotor_nt: &'a [f64],
    /// True anomaly, nT.
    pub true_anomaly_nt: &'a [f64],
    /// Sampling rate, Hz.
    pub fs_hz: f64,
    /// Samples excluded at each end of every metric.
    pub edge: usize,
    /// A tail rotor to fit jointly with the main rotor (one more method),
    /// or none.
    pub tail: Option<&'a TailRotor>,
}

/// One method's figures.
#[derive(Debug, Clone, PartialEq)]
pub struct MethodResult {
    /// Method description.
    pub name: String,
    /// Residual rotor interference RMS, nT.
    pub residual_nt: f64,
    /// Share of the anomaly RMS removed (NaN when not evaluated).
    pub removed_anomaly: f64,
    /// Share of the 0.5 s bumps removed (NaN when not evaluated).
    pub removed_bumps_05: f64,
    /// Share of the 0.1 s bumps removed (NaN when not evaluated).
    pub removed_bumps_01: f64,
    /// `true` for a filter baseline, `false` for a model.
    pub is_filter: bool,
}

/// Result of [`evaluate`].
#[derive(Debug, Clone, PartialEq)]
pub struct RotorStudy {
    /// RMS of the true rotor interference, nT.
    pub rotor_rms_nt: f64,
    /// RMS of the true anomaly, nT.
    pub anomaly_rms_nt: f64,
    /// Mean rotor frequency `f_r`, Hz.
    pub rotor_hz: f64,
    /// Residual of the full model with slowly varying cone, nT.
    pub residual_model_nt: f64,
    /// Smallest residual of the filter baselines, nT.
    pub residual_best_filter_nt: f64,
    /// Residual of the thesis' simplified model (3 parameters per blade,
    /// nominal cone), nT.
    pub residual_simplified_nt: f64,
    /// With a tail rotor: the residual of the full model with slowly
    /// varying cone fitted jointly with the tail rotor, nT.
    pub residual_with_tail_nt: Option<f64>,
    /// With a tail rotor: its estimated phase offset, rad.
    pub tail_offset_rad: Option<f64>,
    /// Every method, models first.
    pub methods: Vec<MethodResult>,
    /// Prediction of the full model with slowly varying cone (and the tail
    /// rotor, when given), nT per sample.
    pub prediction_nt: Vec<f64>,
    /// Estimated coning angle per sample, rad.
    pub coning_rad: Vec<f64>,
}

/// The filter baseline with the smallest residual, if any.
fn best_filter(methods: &[MethodResult]) -> Option<&MethodResult> {
    methods
        .iter()
        .filter(|m| m.is_filter)
        .min_by(|a, b| a.residual_nt.total_cmp(&b.residual_nt))
}

impl RotorStudy {
    /// The filter baseline with the smallest residual.
    pub fn best_filter(&self) -> Option<&MethodResult> {
        best_filter(&self.methods)
    }
}

/// Run the comparison (module docs) on `input` with the rotor geometry
/// `geom`.
///
/// Errors for columns of different lengths, a record shorter than
/// `2·edge + 1` samples, or when a fit or filter fails.
pub fn evaluate(geom: &RotorGeometry, input: &StudyInput) -> Result<RotorStudy> {
    let n = input.mag_nt.len();
    if [
        input.b_body_nt.len(),
        input.rotor_phase_deg.len(),
        input.true_rotor_nt.len(),
        input.true_anomaly_nt.len(),
    ]
    .iter()
    .any(|&l| l != n)
        || n <= 2 * input.edge
    {
        return Err(CompError::data(
            "rotor study: columns of different lengths or record too short",
        ));
    }
    let (fs, edge) = (input.fs_hz, input.edge);
    let (mag, rot, anom) = (input.mag_nt, input.true_rotor_nt, input.true_anomaly_nt);
    let bump = bumps(n, fs, 0.5);
    let sharp = bumps(n, fs, 0.1);
    let phase = unwrap_deg(input.rotor_phase_deg);
    let omega = rotor_speed(&phase, fs, 1.0)?;
    let f_r = omega.iter().sum::<f64>() / omega.len() as f64 / std::f64::consts::TAU;
    let nominal = [nominal_angles()];
    let rin = RotorInput {
        b_body_nt: input.b_body_nt,
        phase_rad: &phase,
        omega_rad_s: &omega,
        angles: &nominal,
    };
    let opts = RotorFitOptions::default();
    let r_rms = std_mid(rot, edge);
    let mut methods = Vec::new();

    // Both blade models, each with the nominal cone and with the slowly
    // varying cone; the full model's slow-cone fit is the study's model.
    let mut slow_fits = Vec::new();
    for terms in [BladeTerms::Full, BladeTerms::Simplified] {
        let label = match terms {
            BladeTerms::Full => "model (7 per blade)",
            BladeTerms::Simplified => "simplified model (3 per blade)",
        };
        let f = fit(geom, terms, &rin, mag, fs, &opts)?;
        let p = f.predict(geom, &rin)?;
        methods.push(MethodResult {
            name: format!("{label}, nominal cone"),
            residual_nt: std_mid(&diff(rot, &p), edge),
            removed_anomaly: f64::NAN,
            removed_bumps_05: f64::NAN,
            removed_bumps_01: f64::NAN,
            is_filter: false,
        });
        let slow = fit_slow_angles(
            geom,
            terms,
            &rin,
            mag,
            fs,
            &opts,
            &SlowAngleOptions::default(),
        )?;
        let inp_s = RotorInput {
            angles: &slow.angles,
            ..rin
        };
        let cols = regressors(geom, terms, &inp_s)?;
        let pred = slow.fit.predict_columns(&cols)?;
        let removed = |sig: &[f64]| -> Result<f64> {
            let f = linear::fit_columns(&cols, terms, sig, fs, &opts)?;
            Ok(std_mid(&f.predict_columns(&cols)?, edge) / std_mid(sig, edge))
        };
        methods.push(MethodResult {
            name: format!("{label} + slowly varying cone"),
            residual_nt: std_mid(&diff(rot, &pred), edge),
            removed_anomaly: removed(anom)?,
            removed_bumps_05: removed(&bump)?,
            removed_bumps_01: removed(&sharp)?,
            is_filter: false,
        });
        slow_fits.push((slow, pred));
    }
    let (slow, mut pred) = slow_fits.swap_remove(0);
    let model_res = methods[1].residual_nt;
    let simplified_res = methods[2].residual_nt;
    let mut tail_fit = None;
    if let Some(tail) = input.tail {
        let t = fit_with_tail(
            geom,
            tail,
            BladeTerms::Full,
            &rin,
            mag,
            fs,
            &opts,
            Some(&SlowAngleOptions::default()),
        )?;
        methods.push(MethodResult {
            name: "model (7 per blade) + slowly varying cone + tail rotor".into(),
            residual_nt: std_mid(&diff(rot, &t.prediction_nt), edge),
            removed_anomaly: f64::NAN,
            removed_bumps_05: f64::NAN,
            removed_bumps_01: f64::NAN,
            is_filter: false,
        });
        pred = t.prediction_nt.clone();
        tail_fit = Some((methods.last().map_or(f64::NAN, |m| m.residual_nt), t));
    }

    // Linear baselines: residual = what they let through of the rotor part.
    let lin = |name: String, f: &dyn Fn(&[f64]) -> Result<Vec<f64>>| -> Result<MethodResult> {
        let lost = |sig: &[f64]| -> Result<f64> {
            Ok(std_mid(&diff(sig, &f(sig)?), edge) / std_mid(sig, edge))
        };
        Ok(MethodResult {
            name,
            residual_nt: std_mid(&f(rot)?, edge),
            removed_anomaly: lost(anom)?,
            removed_bumps_05: lost(&bump)?,
            removed_bumps_01: lost(&sharp)?,
            is_filter: true,
        })
    };
    let bp = geom.blades as f64 * f_r;
    methods.push(lin(
        format!("low-pass {:.1} Hz (0.8 f_bp)", 0.8 * bp),
        &|x| lowpass(x, fs, 0.8 * bp, 6),
    )?);
    methods.push(lin(
        format!("low-pass {:.1} Hz (0.8 f_r)", 0.8 * f_r),
        &|x| lowpass(x, fs, 0.8 * f_r, 6),
    )?);
    methods.push(lin("notches 1…16 f_r".into(), &|x| {
        notch_harmonics(x, fs, f_r, &NotchOptions::default())
    })?);
    methods.push(lin("synchronous averaging, 10 s".into(), &|x| {
        Ok(diff(
            x,
            &synchronous_template(x, &phase, fs, 64, 10.0, 2.0)?,
        ))
    })?);
    let best_filter = best_filter(&methods).map_or(f64::INFINITY, |m| m.residual_nt);
    Ok(RotorStudy {
        rotor_rms_nt: r_rms,
        anomaly_rms_nt: std_mid(anom, edge),
        rotor_hz: f_r,
        residual_model_nt: model_res,
        residual_best_filter_nt: best_filter,
        residual_simplified_nt: simplified_res,
        residual_with_tail_nt: tail_fit.as_ref().map(|t| t.0),
        tail_offset_rad: tail_fit.as_ref().map(|t| t.1.offset_rad),
        methods,
        prediction_nt: pred,
        coning_rad: slow.angles.iter().map(|a| a.coning_rad).collect(),
    })
}
