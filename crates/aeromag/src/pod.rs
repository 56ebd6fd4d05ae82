//! Towed magnetometer pod under a helicopter on flights (spec
//! `helicopter.md` part B, seed `002_…`; algorithms in
//! [`aeromag_compensation::pod`]).
//!
//! [`fit_pod`] reads a learning flight (straight headings, one `line` label
//! per heading), builds for every sample the direction cosines `u` of the
//! Earth field in the body frame (attitude + field inclination and
//! declination), the pod position from the cable geometry (length,
//! attachment point, recorded inclination and azimuth) and the track term
//! `s3 = k_x x_N + k_h h` of the known field gradients, and solves the
//! model by one of three methods ([`PodMethod`]):
//!
//! * `two-step` — the seed's: 7 heading coefficients per heading, then the
//!   43 model parameters; pod position by the seed's eqs. 7–8;
//! * `joint` — the large-signal model (the seed's 43 parameters plus the
//!   24 of the eddy-current gradient that the seed's eqs. 10–12 omit) in
//!   one least-squares fit over all samples; exact pod position;
//! * `dipole-array` — an equivalent dipole array (3 points × 21 moments)
//!   whose field is evaluated exactly at the swinging pod (the improvement
//!   that reaches ≥ 97 %).
//!
//! [`apply_pod`] gives the interference of every row and the compensation
//! rate per heading, `1 − RMS(after) / RMS(before)` of the detrended
//! (high-passed) series, `after = mag − s3 − pod_interf` (a fraction);
//! [`PodModelFile`] is a [`Compensator`] (`pod_interf`, `mag_comp`,
//! `pod_flag`).

use crate::compensate::{Compensator, OutputColumns};
use crate::error::{Error, Result};
use crate::flight::{Flight, SegmentRule, finite_segments};
use crate::observer::{Note, Notes, Observer};
use aeromag_compensation::model_file::MODEL_FORMAT;
use aeromag_compensation::pod::{
    Cable, DipoleArrayModel, JointFit, PodHeading, compensation_rate, compensation_rate_pooled,
    default_source_points, direction_cosines, fit_dipole_array, fit_joint, fit_two_step,
    pod_offset_ned, pod_position_exact, pod_position_seed, predict_dipole_array,
    predict_dipole_array_raw, predict_joint, predict_joint_raw, predict_small_signal,
    predict_small_signal_raw,
};
use aeromag_core::frames::{Attitude, Geodetic};
use std::collections::BTreeMap;
use std::ops::Range;

pub use aeromag_compensation::pod::model_file::{
    HeadingRate, POD_KIND, PodMethod, PodModelFile, PodSetup,
};

/// Shortest heading processed, s.
pub const MIN_HEADING_S: f64 = 10.0;

/// The columns `pod apply` adds: `pod_interf`, `mag_comp`, `pod_flag`.
pub const POD_OUTPUT: OutputColumns = OutputColumns {
    interference: "pod_interf",
    flag: "pod_flag",
    why_missing: "missing values or headings under 10 s",
    why_beyond: "an edited or corrupted parameter, another pod's model, or the pod's columns \
                 mapped wrongly?",
};

/// Names of the 43 small-signal parameters (`aeromag_compensation::pod::
/// model`).
/// With `eddy_gradient`, the 24 eddy-current gradient names follow (the
/// joint solve's large-signal model).
fn theta_names(eddy_gradient: bool) -> Vec<String> {
    let base = ["P1", "P2", "P3", "a11", "a12", "a13", "a22", "a23"];
    let eddy = ["b11", "b12", "b13", "b21", "b22", "b23", "b31", "b32"];
    let grad = ["P1", "P2", "P3", "a11", "a12", "a13", "a22", "a23", "g0"];
    let mut v: Vec<String> = base.iter().chain(&eddy).map(|s| s.to_string()).collect();
    for axis in ["x", "y", "z"] {
        v.extend(grad.iter().map(|g| format!("d{axis}_{g}")));
    }
    if eddy_gradient {
        for axis in ["x", "y", "z"] {
            v.extend(eddy.iter().map(|g| format!("d{axis}_{g}")));
        }
    }
    v
}

/// Names of the dipole-array coefficients for `n` source points.
fn array_names(n: usize) -> Vec<String> {
    let mut v = Vec::new();
    for s in 0..n {
        let ax = ["x", "y", "z"];
        v.extend(ax.iter().map(|i| format!("s{s}_m_{i}")));
        for kind in ["X", "E"] {
            for i in ax {
                v.extend(ax.iter().map(|j| format!("s{s}_{kind}_{i}{j}")));
            }
        }
    }
    v
}

/// One straight heading of a table.
struct Heading {
    rows: Range<usize>,
    heading_deg: f64,
    data: PodHeading,
}

fn deg(x: &[f64]) -> Vec<f64> {
    x.iter().map(|d| d.to_radians()).collect()
}

/// Check that finite values of column `name` lie in `(lo, hi)`; bad input
/// naming the file, the data row and the column otherwise.
fn check_range(t: &Flight, name: &str, v: &[f64], lo: f64, hi: f64) -> Result<()> {
    if let Some(k) = v
        .iter()
        .position(|x| x.is_finite() && !(*x > lo && *x < hi))
    {
        return Err(Error::bad_value(
            t.file_label(),
            k,
            t.resolve(name).unwrap_or(name),
            format!(
                "{} deg is outside ({lo}, {hi})",
                aeromag_core::error::shown(v[k])
            ),
        ));
    }
    Ok(())
}

/// The cable angles in degrees, not radians (a fit on a cable inclination
/// in radians learnt 2–30 % where the degrees gave 99 %, and a good model
/// applied to such a file made the data worse, with exit 0):
/// - a towed cable hangs 10–80° below the horizontal, so an inclination
///   that never exceeds π/2 (1.57°) is in radians;
/// - the cable trails the aircraft, so its azimuth turns with the heading:
///   an azimuth that stays within ±2π while the yaw (degrees) spans more
///   than 4π is in radians.
fn check_cable_degrees(t: &Flight, ci: &[f64], ca: &[f64], yaw: &[f64]) -> Result<()> {
    let span = |v: &[f64]| -> Option<(f64, f64)> {
        let finite = v.iter().copied().filter(|x| x.is_finite());
        let lo = finite.clone().fold(f64::INFINITY, f64::min);
        let hi = finite.fold(f64::NEG_INFINITY, f64::max);
        (lo <= hi).then_some((lo, hi))
    };
    let two_pi = std::f64::consts::TAU;
    let radians = |name: &str, what: String| {
        Err(t.bad_column(name, format!("{what}: radians? expected degrees")))
    };
    if let Some((_, hi)) = span(ci)
        && hi <= std::f64::consts::FRAC_PI_2
    {
        return radians(
            "cable_inclination",
            format!(
                "the cable inclination never exceeds {hi:.3} deg (a towed cable hangs 10–80° below the horizontal)"
            ),
        );
    }
    if let (Some((lo, hi)), Some((ylo, yhi))) = (span(ca), span(yaw))
        && lo >= -two_pi
        && hi <= two_pi
        && yhi - ylo > 2.0 * two_pi
    {
        return radians(
            "cable_azimuth",
            format!(
                "the cable azimuth stays within {lo:.3}…{hi:.3} deg while the heading turns through {:.1} deg",
                yhi - ylo
            ),
        );
    }
    Ok(())
}

/// The columns [`fit_pod`] and [`apply_pod`] read besides the canonical
/// ones (for a lazy read, [`Fields::canonical_and`](aeromag_io::Fields::canonical_and)).
pub const POD_COLUMNS: [&str; 2] = ["cable_inclination", "cable_azimuth"];

/// Directions of learning headings a pod fit needs, at least
/// [`MIN_HEADING_SEPARATION_DEG`] apart: the attitude-dependent terms are
/// determined only by headings around the compass (the seed's learning set
/// has eight, 45° apart), as a Tolles-Lawson box needs four.
pub const MIN_LEARNING_DIRECTIONS: usize = 4;

/// Smallest angle between two learning headings counted as two directions,
/// degrees.
pub const MIN_HEADING_SEPARATION_DEG: f64 = 30.0;

/// Split `t` into headings and build the model inputs of each with the
/// pod trajectory of `method`. Returns the headings and the sample rate.
/// The headings of `t` (straight stretches of at least [`MIN_HEADING_S`]
/// with every column finite), the sample rate, Hz, and the number of rows
/// left out for a missing value.
fn headings(t: &Flight, setup: &PodSetup, method: PodMethod) -> Result<(Vec<Heading>, f64, usize)> {
    let time = t.require("time")?;
    let mag = t.require("mag")?;
    let (roll, pitch, yaw) = (t.require("roll")?, t.require("pitch")?, t.require("yaw")?);
    let (ci, ca) = (t.require("cable_inclination")?, t.require("cable_azimuth")?);
    check_range(t, "cable_inclination", ci, 0.0, 90.0)?;
    check_range(t, "roll", roll, -90.0, 90.0)?;
    check_range(t, "pitch", pitch, -90.0, 90.0)?;
    check_cable_degrees(t, ci, ca, yaw)?;
    let track = setup.grad_north_nt_per_km != 0.0 || setup.grad_up_nt_per_km != 0.0;
    let (lat, alt) = if track {
        (Some(t.require("lat")?), Some(t.require("alt")?))
    } else {
        (None, None)
    };
    let mut cols: Vec<&[f64]> = vec![mag, roll, pitch, yaw, ci, ca];
    cols.extend(lat);
    cols.extend(alt);
    let fs = t.sample_rate_hz()?;
    let min_len = (MIN_HEADING_S * fs).ceil() as usize;
    let rule = SegmentRule::default().min_len(min_len);
    let (usable, segs) = finite_segments(time, t.line_numbers(), &cols, &rule);
    let missing = usable.iter().filter(|u| !**u).count();
    let segs = segs.kept;
    let cable = Cable {
        length_m: setup.cable_length_m,
        attach_m: setup.attach_m,
        declination_rad: 0.0,
    };
    let (inc, dec) = (
        setup.inclination_deg.to_radians(),
        setup.declination_deg.to_radians(),
    );
    let (kx, kh) = (
        setup.grad_north_nt_per_km / 1e3,
        setup.grad_up_nt_per_km / 1e3,
    );
    let mut out = Vec::with_capacity(segs.len());
    for r in segs {
        let (roll, pitch, yaw) = (
            deg(&roll[r.clone()]),
            deg(&pitch[r.clone()]),
            deg(&yaw[r.clone()]),
        );
        let (ci, ca) = (deg(&ci[r.clone()]), deg(&ca[r.clone()]));
        let psi0 = yaw
            .iter()
            .map(|y| y.sin())
            .sum::<f64>()
            .atan2(yaw.iter().map(|y| y.cos()).sum::<f64>());
        let origin = lat.map(|l| Geodetic::new(l[r.start], 0.0, 0.0));
        let mut h = PodHeading {
            total_nt: mag[r.clone()].to_vec(),
            dt_s: 1.0 / fs,
            ..PodHeading::default()
        };
        for k in 0..r.len() {
            let att = Attitude::new(roll[k], pitch[k], yaw[k]);
            let p = match method {
                PodMethod::TwoStep => pod_position_seed(&cable, &att, psi0, ci[k], ca[k]),
                _ => pod_position_exact(&cable, &att, ci[k], ca[k]),
            };
            let s3 = match (origin, lat, alt) {
                (Some(o), Some(lat), Some(alt)) => {
                    let north = o.ned_offset_to(&Geodetic::new(lat[r.start + k], 0.0, 0.0))[0];
                    let off = pod_offset_ned(&cable, &att, ci[k], ca[k]);
                    kx * (north + off.x) + kh * (alt[r.start + k] - off.z)
                }
                _ => 0.0,
            };
            h.track_nt.push(s3);
            h.u.push(direction_cosines(inc, dec, &att));
            h.pod_body_m.push([p.x, p.y, p.z]);
        }
        out.push(Heading {
            rows: r,
            heading_deg: (psi0.to_degrees().rem_euclid(360.0) * 1e6).round() / 1e6 % 360.0,
            data: h,
        });
    }
    Ok((out, fs, missing))
}

/// Prediction of `model` on heading `h`: high-passed (for rates) or raw.
fn predict(model: &PodModelFile, h: &PodHeading, hp: bool) -> Result<Vec<f64>> {
    let c = &model.coefficients;
    Ok(match (model.method, hp) {
        (PodMethod::TwoStep, true) => predict_small_signal(c, h)?,
        (PodMethod::TwoStep, false) => predict_small_signal_raw(c, h)?,
        (PodMethod::Joint, hp) => {
            let f = JointFit {
                theta: c.clone(),
                reference_m: model.reference_m,
            };
            if hp {
                predict_joint(&f, h)?
            } else {
                predict_joint_raw(&f, h)?
            }
        }
        (PodMethod::DipoleArray, hp) => {
            let m = DipoleArrayModel {
                sources_m: model.sources_m.clone(),
                coefficients: c.clone(),
            };
            if hp {
                predict_dipole_array(&m, h)?
            } else {
                predict_dipole_array_raw(&m, h)?
            }
        }
    })
}

/// Compensation rate of `model` on every heading of `hs`.
/// Rate per heading, and pooled over all headings' samples
/// ([`compensation_rate_pooled`]).
fn rates(model: &PodModelFile, hs: &[Heading]) -> Result<(Vec<HeadingRate>, f64)> {
    let preds = hs
        .iter()
        .map(|h| predict(model, &h.data, true))
        .collect::<Result<Vec<_>>>()?;
    let per_heading = hs
        .iter()
        .zip(&preds)
        .map(|(h, p)| {
            Ok(HeadingRate {
                heading_deg: h.heading_deg,
                rows: [h.rows.start, h.rows.end],
                rate: compensation_rate(&h.data, p)?,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let data: Vec<&PodHeading> = hs.iter().map(|h| &h.data).collect();
    Ok((per_heading, compensation_rate_pooled(&data, &preds)?))
}

/// Fit a pod model on the learning flight `t` (module docs) by `method`.
/// `sources`: equivalent source points of the dipole array (body axes, m;
/// `None`: the library's default points). The model records the
/// compensation rate of each learning heading.
///
/// ```
/// use aeromag::Silent;
/// use aeromag::pod::{PodMethod, PodSetup, apply_pod, fit_pod};
/// use aeromag::simulate::{ScenarioKind, simulate_flight};
/// // The seed's installation: 40 m cable, 45° inclination.
/// let setup = PodSetup {
///     cable_length_m: 40.0,
///     attach_m: [0.0, 0.0, 1.2],
///     inclination_deg: 45.0,
///     declination_deg: 0.0,
///     grad_north_nt_per_km: 5.91,
///     grad_up_nt_per_km: -25.91,
/// };
/// let learn = simulate_flight(ScenarioKind::Pod, Some("swing_sine = true\n"), None)?;
/// let model = fit_pod(&learn, &setup, PodMethod::DipoleArray, None, &mut Silent)?.model;
/// let test = simulate_flight(ScenarioKind::Pod, Some("swing_sine = true\n"), Some(1001))?;
/// let applied = apply_pod(&model, &test)?;
/// assert!(applied.per_heading.iter().all(|h| h.rate > 0.9)); // > 90 % removed
/// # Ok::<(), aeromag::Error>(())
/// ```
pub fn fit_pod(
    t: &Flight,
    setup: &PodSetup,
    method: PodMethod,
    sources: Option<&[[f64; 3]]>,
    observer: &mut dyn Observer,
) -> Result<PodFit> {
    setup
        .validate()
        .map_err(|e| Error::bad_input(e.to_string()))?;
    let mut notes = Notes::new(observer);
    let (hs, fs, missing) = headings(t, setup, method)?;
    // Left out without a word before, where the Tolles-Lawson and rotor
    // fits say so.
    if missing > 0 {
        notes.warn(format!(
            "{missing} of {} rows of {} have missing values (mag, attitude, cable angles{}) and are \
             not fitted",
            t.n_rows(),
            t.file_label(),
            if setup.grad_north_nt_per_km != 0.0 || setup.grad_up_nt_per_km != 0.0 {
                ", lat, alt"
            } else {
                ""
            }
        ));
    }
    if hs.is_empty() {
        return Err(Error::bad_file(
            t.file_label(),
            format!("no heading of ≥ {MIN_HEADING_S} s without gaps or missing values"),
        ));
    }
    // One heading (or 10 s of one) was fitted to 63 coefficients without
    // a word, and the model applied to the other headings gave an
    // "interference" of ±295 000 nT, flagged compensated.
    let mut directions: Vec<f64> = Vec::new();
    for h in &hs {
        let apart = |d: &f64| {
            let a = (h.heading_deg - d).rem_euclid(360.0);
            a.min(360.0 - a) >= MIN_HEADING_SEPARATION_DEG
        };
        if directions.iter().all(apart) {
            directions.push(h.heading_deg);
        }
    }
    if directions.len() < MIN_LEARNING_DIRECTIONS {
        let flown: Vec<String> = hs
            .iter()
            .map(|h| format!("{:.0}°", h.heading_deg))
            .collect();
        return Err(Error::bad_file(
            t.file_label(),
            format!(
                "the pod model needs learning headings in at least {MIN_LEARNING_DIRECTIONS} directions \
                 {MIN_HEADING_SEPARATION_DEG}° or more apart (a box: 0, 90, 180, 270°) to be \
                 determined; the rows fitted hold {} heading(s): {}",
                hs.len(),
                flown.join(", ")
            ),
        ));
    }
    notes.stage("fitting the pod model");
    notes.check_cancelled()?;
    let data: Vec<PodHeading> = hs.iter().map(|h| h.data.clone()).collect();
    let mut reference = [0.0; 3];
    let (names, coefficients, sources_m, heading_coefficients) = match method {
        PodMethod::TwoStep => {
            let f = fit_two_step(&data)?;
            (theta_names(false), f.theta, vec![], f.heading_coefficients)
        }
        PodMethod::Joint => {
            let f = fit_joint(&data)?;
            reference = f.reference_m;
            (theta_names(true), f.theta, vec![], vec![])
        }
        PodMethod::DipoleArray => {
            let points = sources.map_or_else(default_source_points, |p| p.to_vec());
            let m = fit_dipole_array(&data, &points)?;
            (
                array_names(m.sources_m.len()),
                m.coefficients,
                m.sources_m,
                vec![],
            )
        }
    };
    let mut columns = BTreeMap::new();
    for c in [
        "time",
        "mag",
        "roll",
        "pitch",
        "yaw",
        "cable_inclination",
        "cable_azimuth",
        "line",
        "lat",
        "alt",
    ] {
        if let Some(f) = t.resolve(c) {
            columns.insert(c.to_string(), f.to_string());
        }
    }
    let mut model = PodModelFile {
        format: MODEL_FORMAT.into(),
        kind: POD_KIND.into(),
        method,
        trajectory: if method == PodMethod::TwoStep {
            "seed-eq7-8"
        } else {
            "exact"
        }
        .into(),
        setup: *setup,
        coefficient_names: names,
        coefficients,
        sources_m,
        reference_m: reference,
        heading_coefficients,
        learning: vec![],
        sample_rate_hz: fs,
        columns,
        software_version: env!("CARGO_PKG_VERSION").into(),
    };
    model.learning = rates(&model, &hs)?.0;
    Ok(PodFit {
        model,
        notes: notes.into_notes(),
    })
}

/// The result of [`fit_pod`].
#[derive(Debug, Clone)]
pub struct PodFit {
    /// The model file.
    pub model: PodModelFile,
    /// Notes and warnings (rows left out).
    pub notes: Vec<Note>,
}

/// What [`apply_pod`] returns.
#[derive(Debug, Clone)]
pub struct PodApplied {
    /// The modelled interference of every row, nT (NaN where not
    /// compensated).
    pub interf_nt: Vec<f64>,
    /// The compensation rate of each heading (a fraction).
    pub per_heading: Vec<HeadingRate>,
    /// The rate pooled over all headings' samples.
    pub pooled: f64,
}

/// Apply `model` to the flight `t`: the interference of every heading of at
/// least 10 s and the compensation rates.
pub fn apply_pod(model: &PodModelFile, t: &Flight) -> Result<PodApplied> {
    let (hs, _, _) = headings(t, &model.setup, model.method)?;
    let mut out = vec![f64::NAN; t.n_rows()];
    for h in &hs {
        out[h.rows.clone()].copy_from_slice(&predict(model, &h.data, false)?);
    }
    let (per_heading, pooled) = rates(model, &hs)?;
    Ok(PodApplied {
        interf_nt: out,
        per_heading,
        pooled,
    })
}

impl Compensator for PodModelFile {
    fn output(&self) -> OutputColumns {
        POD_OUTPUT
    }

    /// About each heading's mean for `two-step` and `joint`, the array's
    /// field for `dipole-array` (nT); NaN outside headings of at least 10 s.
    fn interference_observed(
        &self,
        flight: &Flight,
        _observer: &mut dyn Observer,
    ) -> Result<Vec<f64>> {
        Ok(apply_pod(self, flight)?.interf_nt)
    }
}
