//! Fitting the physical rotor model on a flight.

use super::apply::{segment_phase, track_segment};
use super::columns::{RotorColumns, check_rotor_speed, mean_rotor_hz};
use super::{MIN_SEGMENT_S, RotorPreset};
use crate::error::{Error, Result};
use crate::flight::Flight;
use crate::observer::{Note, Notes, Observer};
use aeromag_compensation::CompError;
use aeromag_compensation::model_file::MODEL_FORMAT;
use aeromag_compensation::rotor::blade::MAX_FLAP_RAD;
use aeromag_compensation::rotor::linear::highpass;
use aeromag_compensation::rotor::model_file::{PhaseSource, ROTOR_KIND, RotorModelFile, TailModel};
use aeromag_compensation::rotor::tail::{TailFit, split};
use aeromag_compensation::rotor::{
    BladeTerms, FlapAngles, RotorFit, RotorFitOptions, RotorGeometry, RotorInput, SlowAngleFit,
    SlowAngleOptions, TailRotor, fit_records, fit_slow_angles, fit_with_tail, refine_phase_offset,
};
use aeromag_core::error::{fixed, shown};

/// Alternations of tracking the angles on every stretch and refitting the
/// parameters on all of them, when a record has several stretches between
/// gaps. Measured on a 420 s simulated flight cut in two halves by a gap
/// (share of the rotor interference left on an independent flight): the
/// longest stretch alone 10.9 %, 1 alternation 9.8 %, 3 8.6 %, 6 8.0 %; the
/// whole record without a gap 3.6 %.
const REFINE_ITERATIONS: usize = 3;

/// Where the rotor phase comes from.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum PhaseChoice {
    /// The `rotor_phase` channel when the flight has one, else estimated.
    #[default]
    Auto,
    /// This phase channel (deg, azimuth of a reference blade from the nose
    /// towards the right).
    Column(String),
    /// Estimated from the scalar data even if a channel exists.
    Estimate,
}

/// The rotor fit as a user states it (see [`RotorOptions::from_choices`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RotorChoices {
    /// A named installation.
    pub preset: Option<RotorPreset>,
    /// Rotor hub position (body frame, m).
    pub hub_m: Option<[f64; 3]>,
    /// Sensor position (body frame, m).
    pub sensor_m: Option<[f64; 3]>,
    /// Blade root and tip radius, m.
    pub blade_span_m: Option<[f64; 2]>,
    /// Number of blades.
    pub blades: Option<usize>,
    /// Nominal coning angle, degrees.
    pub coning_deg: Option<f64>,
    /// Nominal longitudinal tilt, degrees.
    pub tilt_lon_deg: Option<f64>,
    /// Phase channel (degrees).
    pub phase_column: Option<String>,
    /// Estimate the phase even if a channel exists.
    pub estimate_phase: bool,
    /// Search band of the rotor frequency, Hz.
    pub rotor_hz: Option<[f64; 2]>,
    /// Window of constant cone angles, s.
    pub window_s: Option<f64>,
    /// Model a tail rotor: the preset's, with any of the `tail_…` values
    /// given overriding it; without a preset all of them are needed.
    pub tail_rotor: bool,
    /// Tail rotor hub (body frame, m).
    pub tail_hub_m: Option<[f64; 3]>,
    /// Direction of the tail rotor's angular velocity (body frame).
    pub tail_spin_axis: Option<[f64; 3]>,
    /// Body direction of a tail blade at azimuth 0.
    pub tail_zero_azimuth: Option<[f64; 3]>,
    /// Tail blade root and tip radius, m.
    pub tail_blade_span_m: Option<[f64; 2]>,
    /// Number of tail blades.
    pub tail_blades: Option<usize>,
    /// Tail rotor speed over main rotor speed.
    pub gear_ratio: Option<f64>,
}

/// What the rotor fit is told: the installation (geometry, required) and
/// how to find the phase.
#[derive(Debug, Clone, PartialEq)]
pub struct RotorOptions {
    /// Hub and sensor positions, blade span and count.
    pub geometry: RotorGeometry,
    /// Nominal cone angles, the start of the slowly varying estimate
    /// (rad).
    pub nominal_angles: FlapAngles,
    /// Phase channel or estimate.
    pub phase: PhaseChoice,
    /// Search band of the rotor frequency when the phase is estimated, Hz
    /// (default 4–6).
    pub rotor_hz_range: [f64; 2],
    /// Window over which the cone angles are taken as constant, s
    /// (default 1).
    pub window_s: f64,
    /// A tail rotor fitted jointly with the main rotor (needs a phase
    /// channel), or none.
    pub tail: Option<TailRotor>,
}

impl RotorOptions {
    /// The options for `geometry` with nominal angles of coning 4° and
    /// longitudinal tilt −1.5° (typical values; they start the estimate).
    pub fn new(geometry: RotorGeometry) -> Self {
        Self {
            geometry,
            nominal_angles: RotorPreset::AeromagSimHelicopter.nominal_angles(),
            phase: PhaseChoice::Auto,
            rotor_hz_range: [4.0, 6.0],
            window_s: 1.0,
            tail: None,
        }
    }

    /// The columns the fit reads besides the canonical ones: the phase
    /// channel it may use (for a lazy read, [`Fields::canonical_and`](aeromag_io::Fields::canonical_and)).
    pub fn extra_columns(&self) -> Vec<&str> {
        match &self.phase {
            PhaseChoice::Auto => vec!["rotor_phase"],
            PhaseChoice::Column(c) => vec![c.as_str()],
            PhaseChoice::Estimate => vec![],
        }
    }

    /// The options a user states (the `aeromag rotor fit` flags, Python's
    /// `fit_rotor` keywords): a preset or the whole geometry, each value
    /// given overriding the preset's. Bad input: no preset and an
    /// incomplete geometry.
    pub fn from_choices(c: &RotorChoices) -> Result<Self> {
        let mut o = match c.preset {
            Some(p) => RotorOptions::preset(p),
            None => match (c.hub_m, c.sensor_m, c.blade_span_m, c.blades) {
                (Some(hub_m), Some(sensor_m), Some([root_m, tip_m]), Some(blades)) => {
                    RotorOptions::new(RotorGeometry::main_rotor(
                        hub_m, sensor_m, root_m, tip_m, blades,
                    ))
                }
                _ => {
                    return Err(crate::Error::bad_input(
                        "the rotor geometry needs a preset, or all of hub_m, sensor_m, blade_span_m and blades (--hub-m, --sensor-m, --blade-span-m, --blades)",
                    ));
                }
            },
        };
        let g = &mut o.geometry;
        g.hub_m = c.hub_m.unwrap_or(g.hub_m);
        g.sensor_m = c.sensor_m.unwrap_or(g.sensor_m);
        if let Some([root, tip]) = c.blade_span_m {
            (g.root_m, g.tip_m) = (root, tip);
        }
        g.blades = c.blades.unwrap_or(g.blades);
        if let Some(d) = c.coning_deg {
            o.nominal_angles.coning_rad = d.to_radians();
        }
        if let Some(d) = c.tilt_lon_deg {
            o.nominal_angles.tilt_lon_rad = d.to_radians();
        }
        o.phase = match (&c.phase_column, c.estimate_phase) {
            (_, true) => PhaseChoice::Estimate,
            (Some(col), false) => PhaseChoice::Column(col.clone()),
            (None, false) => PhaseChoice::Auto,
        };
        o.rotor_hz_range = c.rotor_hz.unwrap_or(o.rotor_hz_range);
        o.window_s = c.window_s.unwrap_or(o.window_s);
        o.tail = Self::tail_from_choices(c, &o.geometry)?;
        Ok(o)
    }

    /// The tail rotor of [`RotorChoices`]: the preset's or the values given
    /// (all needed without a preset), seen from the main geometry's sensor.
    fn tail_from_choices(c: &RotorChoices, main: &RotorGeometry) -> Result<Option<TailRotor>> {
        let any_value = c.tail_hub_m.is_some()
            || c.tail_spin_axis.is_some()
            || c.tail_zero_azimuth.is_some()
            || c.tail_blade_span_m.is_some()
            || c.tail_blades.is_some()
            || c.gear_ratio.is_some();
        if !c.tail_rotor {
            return if any_value {
                Err(crate::Error::bad_input(
                    "tail rotor values given without the tail rotor (--tail-rotor)",
                ))
            } else {
                Ok(None)
            };
        }
        let base = match c.preset {
            Some(p) => p.tail_rotor(),
            None => match (
                c.tail_hub_m,
                c.tail_spin_axis,
                c.tail_zero_azimuth,
                c.tail_blade_span_m,
                c.tail_blades,
                c.gear_ratio,
            ) {
                (Some(hub), Some(axis), Some(zero), Some([root, tip]), Some(blades), Some(k)) => {
                    TailRotor {
                        geometry: RotorGeometry::main_rotor(hub, main.sensor_m, root, tip, blades)
                            .with_plane(axis, zero),
                        gear_ratio: k,
                        coning_rad: 0.0,
                    }
                }
                _ => {
                    return Err(crate::Error::bad_input(
                        "the tail rotor needs a preset, or all of tail_hub_m, tail_spin_axis, tail_zero_azimuth, \
                         tail_blade_span_m, tail_blades and gear_ratio (--tail-hub-m, --tail-spin-axis, \
                         --tail-zero-azimuth, --tail-blade-span-m, --tail-blades, --gear-ratio)",
                    ));
                }
            },
        };
        let mut t = base;
        let g = &mut t.geometry;
        g.sensor_m = main.sensor_m;
        g.hub_m = c.tail_hub_m.unwrap_or(g.hub_m);
        g.spin_axis = c.tail_spin_axis.unwrap_or(g.spin_axis);
        g.zero_azimuth = c.tail_zero_azimuth.unwrap_or(g.zero_azimuth);
        if let Some([root, tip]) = c.tail_blade_span_m {
            (g.root_m, g.tip_m) = (root, tip);
        }
        g.blades = c.tail_blades.unwrap_or(g.blades);
        t.gear_ratio = c.gear_ratio.unwrap_or(t.gear_ratio);
        Ok(Some(t))
    }

    /// The options of a named installation.
    pub fn preset(preset: RotorPreset) -> Self {
        Self {
            nominal_angles: preset.nominal_angles(),
            ..Self::new(preset.geometry())
        }
    }

    fn validate(&self) -> Result<()> {
        self.geometry
            .validate()
            .map_err(|e| Error::bad_input(e.to_string()))?;
        let [lo, hi] = self.rotor_hz_range;
        let cutoff = RotorFitOptions::default().highpass_hz;
        if !(lo > 0.0 && hi > lo && hi.is_finite()) {
            return Err(Error::bad_input(format!(
                "rotor frequency band {},{} Hz (rotor_hz, --rotor-hz): need 0 < LO < HI",
                shown(lo),
                shown(hi)
            )));
        }
        if lo <= cutoff {
            return Err(Error::bad_input(format!(
                "rotor frequency band {},{} Hz (rotor_hz, --rotor-hz): LO must be above {cutoff} Hz, \
                 the high-pass cutoff of the fit (a slower rotor's signal is removed with the manoeuvres)",
                shown(lo),
                shown(hi)
            )));
        }
        let a = &self.nominal_angles;
        for (name, v) in [
            ("coning", a.coning_rad),
            ("longitudinal tilt", a.tilt_lon_rad),
            ("lateral tilt", a.tilt_lat_rad),
        ] {
            if v.is_nan() || v.abs() > MAX_FLAP_RAD {
                return Err(Error::bad_input(format!(
                    "nominal {name} {}° must be within ±{}°",
                    shown(v.to_degrees()),
                    MAX_FLAP_RAD.to_degrees().round()
                )));
            }
        }
        if !(self.window_s.is_finite() && self.window_s > 0.0) {
            return Err(Error::bad_input(format!(
                "window {} s (window_s, --window-s) must be positive",
                shown(self.window_s)
            )));
        }
        if let Some(t) = &self.tail {
            t.validate()
                .map_err(|e| Error::bad_input(format!("tail rotor: {e}")))?;
        }
        Ok(())
    }
}

/// The result of [`fit_rotor`].
#[derive(Debug, Clone)]
pub struct RotorFitResult {
    /// The model file.
    pub model: RotorModelFile,
    /// Notes and warnings (rows bridged or left out, refinement).
    pub notes: Vec<Note>,
}

/// Check that the window of constant cone angles spans at least
/// [`MIN_WINDOW_SAMPLES`] samples and that every stretch fitted holds two
/// windows (four when the phase is estimated: its refinement uses windows
/// twice as long); bad input naming the option otherwise (the library's
/// message named neither the option nor the file).
fn check_window(
    window_s: f64,
    fs: f64,
    segs: &[std::ops::Range<usize>],
    estimated: bool,
    file: &str,
) -> Result<()> {
    let win = (window_s * fs).round();
    let per_stretch = if estimated { 4.0 } else { 2.0 };
    let shortest = segs.iter().map(|s| s.len()).min().unwrap_or(0) as f64;
    if win < MIN_WINDOW_SAMPLES as f64 || per_stretch * win > shortest {
        return Err(Error::bad_file(
            file,
            format!(
                "window {} s (window_s, --window-s) must span at least {MIN_WINDOW_SAMPLES} samples \
                 ({} s at {fs:.3} Hz) and fit {per_stretch} times in every stretch fitted (the shortest is {} s)",
                shown(window_s),
                MIN_WINDOW_SAMPLES as f64 / fs,
                shortest / fs
            ),
        ));
    }
    Ok(())
}

/// Fewest samples in the window of constant cone angles (the library's
/// slowly-varying-angle fit needs 10).
const MIN_WINDOW_SAMPLES: usize = 10;

/// A fitted cone whose mean coning goes beyond ±[`MAX_FLAP_RAD`] is no
/// rotor's: the data do not determine it (a constant reading gave a mean
/// coning of −333 828°, a phase channel quantised to 90° one of −39.6°,
/// both written with exit 0). A failed fit, not bad input. (The angles of
/// single windows may stray further on valid flights: they absorb what the
/// model leaves, e.g. 62° in one window with an estimated phase.)
fn check_fitted_coning(coning_mean_deg: f64) -> Result<()> {
    if coning_mean_deg.is_nan() || coning_mean_deg.abs() > MAX_FLAP_RAD.to_degrees() {
        return Err(CompError::Failed {
            reason: format!(
                "the fitted rotor's mean coning is {}° (a rotor's stays within ±{}°): the flight does \
                 not determine the model (a constant reading, a coarse or wrong phase channel?)",
                fixed(coning_mean_deg, 1),
                MAX_FLAP_RAD.to_degrees().round()
            ),
        }
        .into());
    }
    Ok(())
}

/// The least share of the high-passed reading's variance (over the
/// stretch fitted, its ends left out as the fit leaves them) that a fitted
/// rotor model explains without a warning. The simulated helicopter
/// flights' models explain 99.9 % (a residual of 0.04–0.07 nT of a 2.7 nT
/// signal). A rotor band holding only the fifth harmonic of the rotor
/// (`--estimate-phase --rotor-hz 5,7` for a 4.83 Hz rotor) gave a 6.04 Hz
/// rotor whose model explained 0.2 %, and the main rotor's model of a
/// sensor under the tail boom explains 2.2 % (the tail rotor's signal is
/// the rest: `--tail-rotor`), written without a word. Such a model removes
/// what it explains, so it is kept, with a warning.
pub const MIN_EXPLAINED_VARIANCE: f64 = 0.1;

/// The warning for a fit explaining less than [`MIN_EXPLAINED_VARIANCE`]
/// of the high-passed `mag` (none otherwise).
fn explained_warning(
    fit: &RotorFit,
    mag: &[f64],
    fs: f64,
    o: &RotorFitOptions,
    rotor_hz: f64,
    estimated: bool,
) -> Result<Option<String>> {
    let y = highpass(mag, fs, o.highpass_hz)?;
    let edge = ((o.edge_s * fs).round() as usize).min(y.len() / 2);
    let y = &y[edge..y.len() - edge];
    let signal_nt = (y.iter().map(|v| v * v).sum::<f64>() / y.len().max(1) as f64).sqrt();
    let explained = 1.0 - (fit.residual_rms_nt / signal_nt).powi(2);
    if explained >= MIN_EXPLAINED_VARIANCE {
        return Ok(None);
    }
    let why = if estimated {
        "the rotor phase was estimated from the band's largest spectral peak, which may be another line \
         than this rotor's blade passing (is the rotor band, --rotor-hz, right?)"
    } else {
        "is the phase channel the rotor's (--phase-column)?"
    };
    Ok(Some(format!(
        "the rotor model at f_r {} Hz explains {} % of the high-passed reading's variance (residual {} nT \
         of {} nT): the rest is not this rotor's; {why} A tail rotor seen by the sensor is modelled \
         with --tail-rotor",
        fixed(rotor_hz, 4),
        fixed(100.0 * explained.max(0.0), 1),
        fixed(fit.residual_rms_nt, 4),
        fixed(signal_nt, 4),
    )))
}

/// The warning for a tail rotor left out of the model
/// ([`TailFit::tail_is_seen`]).
fn tail_unseen_warning(j: &TailFit) -> String {
    let n = j.tail_prediction_nt.len().max(1) as f64;
    let mean = j.tail_prediction_nt.iter().sum::<f64>() / n;
    let std = (j
        .tail_prediction_nt
        .iter()
        .map(|v| (v - mean).powi(2))
        .sum::<f64>()
        / n)
        .sqrt();
    format!(
        "the tail rotor is left out of the model: the sensor does not see it (its blade-passing part in the \
         joint fit is {} nT RMS, below the fit's residual of {} nT), so its fitted parameters would be the \
         main rotor's misfit, and its slow part (the rotation average, {} nT std here) an error in the \
         compensated reading; the main rotor is fitted alone",
        fixed(j.tail_highpassed_rms_nt, 4),
        fixed(j.tail.residual_rms_nt, 4),
        fixed(std, 3),
    )
}

/// Options of the phase refinement of a phase estimated from the data:
/// the tracked phase is biased by the heading-dependent phase of the
/// harmonics, so it is refined jointly with the parameters (library docs of
/// `coning`), coning only, over windows twice the final ones.
fn phase_refinement(window_s: f64) -> SlowAngleOptions {
    SlowAngleOptions {
        estimate_phase: true,
        estimate_tilt: false,
        iterations: 6,
        window_s: 2.0 * window_s,
        joint: true,
    }
}

/// Fit the physical main-rotor model (and a tail rotor geared to it, when
/// [`RotorOptions::tail`] names one) on a helicopter flight.
///
/// Reads `time` (s, uniform sampling ≥ 2.5 × the blade-passing frequency),
/// `mag` (nT), `flux_x/y/z` (nT, body axes: the field direction) and the
/// phase channel (deg) when there is one ([`PhaseChoice`]); never a `true_`
/// column. The full linear per-blade model (7 parameters per blade) is
/// fitted on the longest stretch without gaps with the slowly varying
/// coning and tilt; without a phase channel the rotor frequency and phase
/// are estimated from the data (blade-passing peak, complex demodulation,
/// offset by the fit residual, a slowly varying correction). Dropouts of up
/// to 0.1 s are bridged by linear interpolation; with several stretches of
/// at least 10 s the parameters are refined on all of them. A tail rotor
/// needs the phase channel; it is fitted jointly with the main rotor
/// ([`fit_with_tail`]).
///
/// ```
/// use aeromag::prelude::*;
/// use aeromag::rotor::{RotorOptions, RotorPreset, fit_rotor};
/// use aeromag::simulate::{ScenarioKind, simulate_flight};
/// // Learn on one simulated helicopter flight, apply to another.
/// let learn = simulate_flight(ScenarioKind::Helicopter, None, Some(11))?;
/// let other = simulate_flight(ScenarioKind::Helicopter, None, Some(12))?;
/// let fit = fit_rotor(&learn, &RotorOptions::preset(RotorPreset::AeromagSimHelicopter), &mut Silent)?;
/// let interference = fit.model.interference(&other)?; // nT, one per row
/// assert_eq!(interference.len(), other.n_rows());
/// # Ok::<(), aeromag::Error>(())
/// ```
pub fn fit_rotor(
    flight: &Flight,
    opts: &RotorOptions,
    observer: &mut dyn Observer,
) -> Result<RotorFitResult> {
    opts.validate()?;
    let mut notes = Notes::new(observer);
    let file = flight.label();
    let phase_col = match &opts.phase {
        PhaseChoice::Estimate => None,
        PhaseChoice::Column(c) => Some(c.clone()),
        PhaseChoice::Auto => flight.get("rotor_phase").map(|_| "rotor_phase".to_string()),
    };
    if opts.tail.is_some() && phase_col.is_none() {
        return Err(Error::bad_file(
            file,
            "a tail rotor is modelled with a rotor phase channel only (its phase is geared from the main rotor's); \
             the flight has none or the phase is to be estimated",
        ));
    }
    let raw = RotorColumns::of(flight, phase_col.as_deref())?;
    let fs = flight.sample_rate_hz()?;
    // Short dropouts (missing cells, no time gap), spikes of `mag` and
    // glitches of the phase are bridged, so that the stretches on both
    // sides are fitted as one record and one bad sample spoils nothing.
    let bridged = raw.bridged(fs);
    let cols = raw.with(&bridged.columns);
    for n in bridged.notes(flight, "for the fit") {
        notes.push(n);
    }
    let segs = cols.usable_stretches(flight, fs)?;
    let r = segs
        .iter()
        .max_by_key(|r| r.len())
        .cloned()
        .expect("usable_stretches returns at least one");
    let used: usize = segs.iter().map(|s| s.len()).sum();
    if used < flight.n_rows() {
        notes.warn(format!(
            "{} of {} rows are in stretches without gaps or missing values of at least {MIN_SEGMENT_S} s \
             and are fitted; the others are left out",
            used,
            flight.n_rows()
        ));
    }
    let geom = &opts.geometry;
    let fit_opts = RotorFitOptions::default();
    let b = cols.field(&r);
    let mag = &cols.mag[r.clone()];
    let estimated = phase_col.is_none();
    check_window(opts.window_s, fs, &segs, estimated, &file)?;
    let (mut phase, omega) = segment_phase(&cols, &r, fs, geom.blades, opts.rotor_hz_range, &file)?;
    let rotor_hz = mean_rotor_hz(&omega);
    check_rotor_speed(
        rotor_hz,
        fs,
        geom.blades,
        phase_col.as_deref(),
        opts.tail.as_ref(),
        &file,
    )?;
    let nominal = [opts.nominal_angles];
    if estimated {
        notes.stage("estimating the rotor phase");
        notes.check_cancelled()?;
        let inp = RotorInput {
            b_body_nt: &b,
            phase_rad: &phase,
            omega_rad_s: &omega,
            angles: &nominal,
        };
        let c = refine_phase_offset(geom, BladeTerms::Full, &inp, mag, fs, &fit_opts)?;
        phase.iter_mut().for_each(|p| *p += c);
        let inp = RotorInput {
            b_body_nt: &b,
            phase_rad: &phase,
            omega_rad_s: &omega,
            angles: &nominal,
        };
        let o = phase_refinement(opts.window_s);
        notes.check_cancelled()?;
        phase = fit_slow_angles(geom, BladeTerms::Full, &inp, mag, fs, &fit_opts, &o)?.phase_rad;
    }
    let slow_opts = SlowAngleOptions {
        window_s: opts.window_s,
        ..SlowAngleOptions::default()
    };
    let inp = RotorInput {
        b_body_nt: &b,
        phase_rad: &phase,
        omega_rad_s: &omega,
        angles: &nominal,
    };
    notes.stage("fitting the rotor model");
    notes.check_cancelled()?;
    // A tail rotor whose blade-passing signal the sensor does not see is
    // left out (`TailFit::tail_is_seen`).
    let joint = match &opts.tail {
        None => None,
        Some(t) => {
            let j = fit_with_tail(
                geom,
                t,
                BladeTerms::Full,
                &inp,
                mag,
                fs,
                &fit_opts,
                Some(&slow_opts),
            )?;
            if j.tail_is_seen() {
                Some((t, j))
            } else {
                notes.warn(tail_unseen_warning(&j));
                None
            }
        }
    };
    let (slow, tail) = match joint {
        None => (
            fit_slow_angles(geom, BladeTerms::Full, &inp, mag, fs, &fit_opts, &slow_opts)?,
            None,
        ),
        Some((t, j)) => {
            let angles = j.angles.unwrap_or_else(|| vec![opts.nominal_angles]);
            let slow = SlowAngleFit {
                fit: j.main,
                angles,
                phase_rad: phase.clone(),
            };
            let tail = TailModel {
                rotor: t.clone(),
                offset_rad: j.offset_rad,
                model: j.tail,
            };
            (slow, Some(tail))
        }
    };
    let coning_mean_deg =
        slow.angles.iter().map(|x| x.coning_rad).sum::<f64>() / slow.angles.len() as f64 * 180.0
            / std::f64::consts::PI;
    check_fitted_coning(coning_mean_deg)?;
    if let Some(w) = explained_warning(&slow.fit, mag, fs, &fit_opts, rotor_hz, estimated)? {
        notes.warn(w);
    }
    let names: Vec<&str> = ["time", "mag", "flux_x", "flux_y", "flux_z"]
        .into_iter()
        .chain(phase_col.as_deref())
        .collect();
    let mut model = RotorModelFile {
        format: MODEL_FORMAT.into(),
        kind: ROTOR_KIND.into(),
        geometry: geom.clone(),
        tail,
        nominal_angles: opts.nominal_angles,
        model: slow.fit,
        fit_options: fit_opts,
        slow_angles: slow_opts,
        phase: PhaseSource {
            column: phase_col.clone(),
            rotor_hz_range: opts.rotor_hz_range,
        },
        sample_rate_hz: fs,
        rotor_hz,
        coning_mean_deg,
        rows: r.len(),
        columns: flight.column_map_of(&names),
        software_version: env!("CARGO_PKG_VERSION").into(),
    };
    // Several stretches between gaps: the parameters found on the longest
    // are refined on all of them, each with its own phase and slowly varying
    // angles tracked as `rotor apply` would.
    if segs.len() > 1 {
        notes.stage(&format!("refining on {} stretches", segs.len()));
        for round in 0..REFINE_ITERATIONS {
            notes.progress(round as u64, REFINE_ITERATIONS as u64);
            notes.check_cancelled()?;
            // Each stretch tracked alone: the stretches on the cores, the
            // first failure in their order reported.
            let threads = aeromag_core::parallel::threads();
            let regs: Vec<Vec<Vec<f64>>> =
                aeromag_core::parallel::parallel_map(segs.len(), threads, |i| {
                    track_segment(&model, &cols, &segs[i], fs, &file)?.columns(&model, fs)
                })
                .into_iter()
                .collect::<Result<_>>()?;
            let records: Vec<(&[Vec<f64>], &[f64])> = regs
                .iter()
                .zip(&segs)
                .map(|(c, s)| (c.as_slice(), &cols.mag[s.clone()]))
                .collect();
            let joint = fit_records(&records, model.model.terms, fs, &fit_opts)?;
            let p_main = model.model.params.len();
            let (main, tail) = split(&joint, p_main);
            model.model = main;
            if let Some(t) = &mut model.tail {
                t.model = tail;
            }
        }
        model.rows = used;
        notes.note(format!(
            "parameters refined on all {} stretches ({used} rows)",
            segs.len()
        ));
    }
    Ok(RotorFitResult {
        model,
        notes: notes.into_notes(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotor_speed_and_window_out_of_range_are_bad_input_naming_the_option() {
        let tail = RotorPreset::AeromagSimHelicopter.tail_rotor();
        check_rotor_speed(4.8, 100.0, 4, Some("rotor_phase"), Some(&tail), "f.csv").unwrap();
        // A time or heading column given as the phase channel turns at
        // mHz: it was fitted with exit 0.
        let e = check_rotor_speed(0.0028, 100.0, 4, Some("time"), None, "f.csv").unwrap_err();
        let msg = e.to_string();
        assert!(
            e.is_bad_input() && msg.contains("f.csv") && msg.contains("`time`"),
            "{msg}"
        );
        // A rotor whose blades pass above Nyquist: the sampling is named.
        let e = check_rotor_speed(13.0, 100.0, 4, None, None, "f.csv").unwrap_err();
        assert!(
            e.to_string()
                .contains("sampled too slowly for this rotor (at least 104.0 Hz needed)"),
            "{e}"
        );
        // A gear ratio of 2⁶³ failed as a singular fit (exit 1), one of
        // 10⁶ was fitted on aliased data (exit 0).
        for k in [9.3e18, 1e6, 1e-300] {
            let mut t = tail.clone();
            t.gear_ratio = k;
            let e = check_rotor_speed(4.8, 100.0, 4, Some("rotor_phase"), Some(&t), "f.csv")
                .unwrap_err();
            assert!(
                e.is_bad_input() && e.to_string().contains("--gear-ratio"),
                "{e}"
            );
        }
        // The window: the library's message named neither option nor file.
        let segs = [0..1000, 0..4000];
        check_window(1.0, 100.0, &segs, true, "f.csv").unwrap();
        for (w, estimated) in [(1e-300, false), (1e308, false), (6.0, false), (3.0, true)] {
            let e = check_window(w, 100.0, &segs, estimated, "f.csv").unwrap_err();
            assert!(
                e.is_bad_input() && e.to_string().contains("--window-s"),
                "{e}"
            );
        }
        // A band under the fit's high-pass cutoff (0.01–0.02 Hz gave a
        // mean coning of −146°, written with exit 0).
        let mut o = RotorOptions::preset(RotorPreset::AeromagSimHelicopter);
        o.validate().unwrap();
        o.rotor_hz_range = [0.01, 0.02];
        let e = o.validate().unwrap_err();
        assert!(
            e.is_bad_input() && e.to_string().contains("--rotor-hz"),
            "{e}"
        );
    }
}
