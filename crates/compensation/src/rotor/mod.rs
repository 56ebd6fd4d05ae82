//! Helicopter main-rotor interference (spec `helicopter.md` part A; seed
//! `000_…` chapter 3, §§14–17).
//!
//! A helicopter's rotating, magnetised and conducting blades add to the
//! slow fuselage interference a fast part at the rotor frequency `f_r`, the
//! blade-passing frequency `N f_r` and their harmonics, which changes with
//! the rotor cone (coning and flapping follow the load). The physical model
//! of the thesis:
//!
//! * magnetic masses `ΔB_m = λ D_I (Q_K + B_r I) r_p`,
//! * eddy currents `ΔB_i = γ D_I (dB/dt − [ω×] B) ≈ −γ D_I [ω×] B`,
//!
//! with `D_I` the dipole integral along the blade ([`blade`]); linear in
//! the per-blade parameters ([`linear`]), fitted by least squares to the
//! high-passed data. The rotor phase comes from a phase channel
//! ([`phase::unwrap_deg`], [`phase::rotor_speed`]) or from the data
//! ([`phase::estimate_phase`] + [`refine_phase_offset`]). The cone's slow
//! evolution is estimated jointly ([`coning`]).
//!
//! Baselines for comparison: low-pass below the blade-passing frequency
//! ([`lowpass`]), notches at the harmonics ([`notch`]), rotor-phase
//! synchronous averaging ([`synchronous`]). A tail rotor geared to the main
//! rotor is fitted jointly with it ([`tail`]). [`study`] runs the whole
//! comparison on a record with known truth.
//!
//! ## Measured on the `helicopter` scenario of `aeromag-sim`
//!
//! Seed 11, default scenario (4 headings, 100 Hz, 290 rpm, 4 blades, rotor
//! interference 3.36 nT RMS at the nose-boom sensor, anomaly 12.4 nT RMS);
//! residual rotor interference RMS and share of the rotor RMS (test
//! `sim_tests::model_beats_the_filters`):
//!
//! | method | residual | removes anomaly / 0.5 s bumps / 0.1 s bumps |
//! |---|---|---|
//! | simplified model (3 per blade), nominal cone | 3.81 nT (113 %) | – |
//! | simplified model + slowly varying cone | 2.29 nT (68 %) | 0.00 / 0.00 / 0.06 % |
//! | full model (7 per blade), nominal cone | 0.264 nT (7.8 %) | – |
//! | full model + slowly varying cone and tilt | **0.118 nT (3.5 %)** | 0.00 / 0.00 / 1.07 % |
//! | low-pass at 0.8 f_bp (15.5 Hz) | 2.42 nT (72 %) | 0.00 / 0.00 / 0.00 % |
//! | low-pass at 0.8 f_r (3.9 Hz) | 1.89 nT (56 %) | 0.00 / 0.00 / 2.26 % |
//! | notches at 1…16 f_r | 1.90 nT (57 %) | 0.00 / 0.00 / 0.43 % |
//! | synchronous averaging, 10 s blocks | 1.91 nT (57 %) | 0.00 / 0.00 / 4.54 % |
//!
//! The thesis' simplified model on a rotor that satisfies its assumptions
//! (`aeromag_sim`'s `RotorConfig::simplified`: blades turning uniformly in a
//! fixed cone, hard and soft magnetisation along the blade, eddy currents
//! without lag; same flight, seed 11): 0.126 nT (4.3 % of 2.93 nT) against
//! 89.7 % for the best filter — there it beats filtering, as the thesis
//! says; on the default rotor it does not (113 % against 56 %). Test
//! `crates/aeromag/tests/rotor.rs`.
//!
//! Tail rotor ([`tail`]; `[tail_rotor]` of the scenario: 3 blades, geared
//! 4.37:1, 21.1 Hz): at the nose-boom sensor its part is 0.016 nT RMS; at
//! a sensor under the tail boom, 4 m from its hub, 10.5 of 10.6 nT. The
//! main-rotor model alone leaves 98.9 % there; fitted jointly with the tail
//! rotor (phase offset estimated 37.00°, simulated 37°), 2.2 %; the best
//! filter 21 %.
//!
//! The filters cannot remove the slow part of the rotor field (its mean
//! over a revolution changes with heading, attitude and cone, ≈ 56 % of the
//! rotor RMS here); the physical model predicts it. The best filter leaves
//! 16× the model's residual. The simplified model is worse than nothing
//! here because the simulated blades also have hard and soft magnetisation
//! across the spar and lagging eddy currents, which it cannot represent; its
//! prediction of the slow part is then wrong.
//!
//! Without a phase channel (seed 12, headings 30/120/210/300°; test
//! `sim_tests::works_without_a_phase_channel`): rotor frequency to 10⁻⁴ Hz;
//! the demodulated phase is biased by up to 12° (the phase of each harmonic
//! moves with the field direction), the joint refinement
//! ([`coning::SlowAngleOptions::estimate_phase`]) brings it to ≤ 2.9°, and the
//! full model with slowly varying cone leaves 0.243 nT (7.3 %).
//!
//! Applying a fitted model to another flight: the blade parameters stay
//! fixed, the phase of the new record (from its channel, or estimated and
//! aligned over a whole revolution by [`align_phase_offset`]) and its slowly
//! varying angles are tracked by [`track_slow_angles`]. Fit on seed 11,
//! applied to seed 12 (phase channel): 0.122 nT (3.6 %); fit on seed 13 and
//! applied to seed 14 without phase channels: 0.176 nT (5.2 %) (CLI test
//! `crates/cli/tests/rotor.rs`, `aeromag rotor fit|apply`); fit on seed 11
//! with its phase channel, applied to seed 12 with the phase estimated from
//! the data: 3.4 % (test `sim_tests::a_fitted_model_applies_to_another_flight`).
//!
//! The estimated coning reduces the residual but does not reproduce the
//! true coning angle (estimation error 0.99° RMS against a true variation
//! of 0.36° RMS): the angles absorb other unmodelled slow effects.

pub mod blade;
pub mod coning;
pub mod linear;
pub mod lowpass;
pub mod model_file;
pub mod notch;
pub mod phase;
#[cfg(test)]
mod sim_tests;
pub mod study;
pub mod synchronous;
pub mod tail;

pub use blade::{FlapAngles, RotorGeometry, blade_axes, dipole_integral};
pub use coning::{SlowAngleFit, SlowAngleOptions, fit_slow_angles, track_slow_angles};
pub use linear::{BladeTerms, RotorFit, RotorFitOptions, RotorInput, fit, fit_records, regressors};
pub use phase::{PhaseEstimate, estimate_phase, rotor_speed, smooth_phase, unwrap_deg};
pub use tail::{TailFit, TailRotor, fit_with_tail};

use crate::error::Result;

/// Step 3 of [`phase`]: the constant `c ∈ [0, 2π/N)` added to an estimated
/// phase that minimises the residual of the rotor-model fit (a 12-point
/// grid, then 14 golden-section steps around the best point: final
/// bracket ≈ 0.005 of the grid step). Returns `c`
/// (rad).
pub fn refine_phase_offset(
    geom: &RotorGeometry,
    terms: BladeTerms,
    input: &RotorInput,
    mag_nt: &[f64],
    fs_hz: f64,
    opts: &RotorFitOptions,
) -> Result<f64> {
    let period = std::f64::consts::TAU / geom.blades.max(1) as f64;
    let cost = |c: f64| -> Result<f64> {
        let shifted: Vec<f64> = input.phase_rad.iter().map(|p| p + c).collect();
        let inp = RotorInput {
            phase_rad: &shifted,
            ..*input
        };
        Ok(fit(geom, terms, &inp, mag_nt, fs_hz, opts)?.residual_rms_nt)
    };
    minimise_periodic(&cost, period, 12)
}

/// The constant `c ∈ [0, 2π)` added to a phase estimated from new data that
/// best aligns it with a fitted `model` (parameters fixed): minimises the
/// RMS of `HP[mag] − HP[prediction]` over a grid of `12 N` points and a
/// golden-section search, as [`refine_phase_offset`]. With per-blade
/// parameters the whole revolution is searched (the blade labels matter).
/// Returns `c` (rad).
pub fn align_phase_offset(
    geom: &RotorGeometry,
    model: &RotorFit,
    input: &RotorInput,
    mag_nt: &[f64],
    fs_hz: f64,
    opts: &RotorFitOptions,
) -> Result<f64> {
    let y = linear::highpass(mag_nt, fs_hz, opts.highpass_hz)?;
    let n = y.len();
    let edge = ((opts.edge_s * fs_hz).round() as usize).min(n / 4);
    let cost = |c: f64| -> Result<f64> {
        let shifted: Vec<f64> = input.phase_rad.iter().map(|p| p + c).collect();
        let inp = RotorInput {
            phase_rad: &shifted,
            ..*input
        };
        let p = linear::highpass(&model.predict(geom, &inp)?, fs_hz, opts.highpass_hz)?;
        Ok((edge..n - edge).map(|k| (y[k] - p[k]).powi(2)).sum::<f64>())
    };
    minimise_periodic(&cost, std::f64::consts::TAU, 12 * geom.blades.max(1))
}

/// Minimise a `period`-periodic `cost` over a grid of `grid` points, then
/// 14 golden-section steps in the bracket of ± one grid step around the
/// best point. Returns the minimiser in `[0, period)`.
pub(crate) fn minimise_periodic(
    cost: &dyn Fn(f64) -> Result<f64>,
    period: f64,
    grid: usize,
) -> Result<f64> {
    let step = period / grid as f64;
    let mut best = (0.0, f64::INFINITY);
    for i in 0..grid {
        let c = i as f64 * step;
        let v = cost(c)?;
        if v < best.1 {
            best = (c, v);
        }
    }
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut a, mut b) = (best.0 - step, best.0 + step);
    let (mut x1, mut x2) = (b - g * (b - a), a + g * (b - a));
    let (mut f1, mut f2) = (cost(x1)?, cost(x2)?);
    for _ in 0..14 {
        if f1 < f2 {
            b = x2;
            x2 = x1;
            f2 = f1;
            x1 = b - g * (b - a);
            f1 = cost(x1)?;
        } else {
            a = x1;
            x1 = x2;
            f1 = f2;
            x2 = a + g * (b - a);
            f2 = cost(x2)?;
        }
    }
    Ok((0.5 * (a + b)).rem_euclid(period))
}
