//! `aeromag rotor fit` and `aeromag rotor apply`: the physical main-rotor
//! model (spec `helicopter.md` part A, seed `000_…` ch. 3; library
//! `aeromag_compensation::rotor`) fitted on a user's flight file, saved as a
//! versioned JSON model and applied to other files.
//!
//! Fit: the full linear per-blade model (7 parameters per blade: hard and
//! soft magnetisation along and across the blade, eddy currents) with the
//! dipole integral along each blade, and the slowly varying coning and
//! tip-path-plane tilt estimated jointly (`fit_slow_angles`). The rotor
//! phase comes from a phase channel (deg) or, without one, from the data:
//! the blade-passing peak of the spectrum, complex demodulation, a phase
//! offset by minimising the fit residual, then a slowly varying phase
//! correction estimated with the parameters.
//!
//! Apply: the blade parameters stay fixed; on the new record the phase is
//! taken from its channel or estimated and aligned with the model over a
//! whole revolution (`align_phase_offset`), and the slowly varying angles
//! are tracked with the parameters fixed (`track_slow_angles`). Output:
//! every input column plus `rotor_interf` (modelled rotor interference, nT,
//! slow part included), `mag_comp = mag − rotor_interf` (nT) and
//! `rotor_flag` (0 compensated, 1 not: a missing value in the row or a
//! segment shorter than 10 s between gaps).

use crate::exit::bad_input;
use crate::flight::{add_compensation, parse_numbers};
use crate::input::InputArgs;
use aeromag_compensation::rotor::study::{nominal_angles, scenario_geometry};
use aeromag_compensation::rotor::{
    BladeTerms, FlapAngles, RotorFitOptions, RotorGeometry, RotorInput, SlowAngleOptions,
    align_phase_offset, estimate_phase, fit_records, fit_slow_angles, refine_phase_offset,
    regressors, rotor_speed, track_slow_angles, unwrap_deg,
};
use aeromag_compensation::tolles_lawson::segments::{median_step, split_segments};
use aeromag_io::FlightTable;
use nalgebra::Vector3;
use std::collections::BTreeMap;
use std::ops::Range;
use std::path::{Path, PathBuf};

use aeromag_compensation::model_file::MODEL_FORMAT;
pub use aeromag_compensation::rotor::model_file::{PhaseSource, ROTOR_KIND, RotorModelFile};
/// Longest dropout (consecutive rows with a missing value, time steps
/// regular) that `rotor fit` bridges by linear interpolation, s.
const MAX_FILL_S: f64 = 0.1;

/// Alternations of tracking the angles on every stretch and refitting the
/// parameters on all of them, when a record has several stretches between
/// gaps. Measured on a 420 s simulated flight cut in two halves by a gap
/// (share of the rotor interference left on an independent flight): the
/// longest stretch alone 10.9 %, 1 alternation 9.8 %, 3 8.6 %, 6 8.0 %; the
/// whole record without a gap 3.6 %.
const REFINE_ITERATIONS: usize = 3;

/// Bridge runs of at most `max_len` non-finite values between finite ones
/// by linear interpolation in time (`period`: interpolate the shortest way
/// round, for a phase in degrees), when the time steps across the run are
/// regular (no time gap).
fn bridge_dropouts(time: &[f64], x: &[f64], max_len: usize, period: Option<f64>) -> Vec<f64> {
    let mut out = x.to_vec();
    let dt = median_step(time);
    let n = x.len();
    let mut k = 0;
    while k < n {
        if x[k].is_finite() {
            k += 1;
            continue;
        }
        let start = k;
        while k < n && !x[k].is_finite() {
            k += 1;
        }
        let (a, b) = (start.wrapping_sub(1), k);
        if start == 0 || b >= n || b - start > max_len {
            continue;
        }
        let span = time[b] - time[a];
        if !(span > 0.0 && span <= (b - a) as f64 * dt * 1.5) {
            continue;
        }
        let mut d = x[b] - x[a];
        if let Some(p) = period {
            d = (d + 0.5 * p).rem_euclid(p) - 0.5 * p;
        }
        for i in start..b {
            out[i] = x[a] + d * (time[i] - time[a]) / span;
        }
    }
    out
}

/// Shortest record processed between gaps, s.
const MIN_SEGMENT_S: f64 = 10.0;

/// Fit the physical main-rotor model on a helicopter flight file.
///
/// Needs `time` (s, uniform sampling ≥ 2.5 × the blade-passing frequency),
/// `mag` (nT) and `flux_x/y/z` (nT, body axes: the field direction), and a
/// rotor phase channel (deg, azimuth of a reference blade from the nose
/// towards the right) if there is one: `--phase-column COL`, by default
/// `rotor_phase` when the file has it. Without a phase channel (or with
/// --estimate-phase) the rotor frequency and phase are estimated from the
/// scalar data (search band --rotor-hz). The geometry defaults to the
/// simulator's helicopter (hub 0,0,−2.6 m, sensor 5,0,0.6 m, blades 0.8 to
/// 7.5 m, 4 blades, nominal coning 4°, tilt −1.5°). Dropouts of up to
/// 0.1 s (missing values, regular time steps) are bridged by linear
/// interpolation; across longer gaps the model is fitted on the longest
/// stretch and its parameters refined on every stretch of at least 10 s.
/// Columns named `true_…` are never read.
///
/// Example:
///   aeromag rotor fit --input heli.csv --model rotor.json
///   aeromag rotor fit --input heli.csv --model rotor.json --estimate-phase --rotor-hz 4.5,5.2
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct FitArgs {
    #[command(flatten)]
    input: InputArgs,
    /// Model file to write (JSON).
    #[arg(long, value_name = "ROTOR.json")]
    model: PathBuf,
    /// Rotor phase channel, deg (default `rotor_phase` if present).
    #[arg(long, value_name = "COL")]
    phase_column: Option<String>,
    /// Estimate the rotor phase from the data even if a phase channel exists.
    #[arg(long)]
    estimate_phase: bool,
    /// Search band of the rotor frequency when the phase is estimated, Hz.
    #[arg(long, value_name = "LO,HI", default_value = "4,6")]
    rotor_hz: String,
    /// Rotor hub position, body axes (x forward, y right, z down), m.
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    hub_m: Option<String>,
    /// Scalar sensor position, body axes, m.
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    sensor_m: Option<String>,
    /// Magnetised span of a blade from the hub, m.
    #[arg(long, value_name = "ROOT,TIP")]
    blade_span_m: Option<String>,
    /// Number of blades.
    #[arg(long)]
    blades: Option<usize>,
    /// Nominal coning angle, deg (the start of the slowly varying estimate).
    #[arg(long, allow_hyphen_values = true)]
    coning_deg: Option<f64>,
    /// Nominal longitudinal tilt of the tip-path plane, deg.
    #[arg(long, allow_hyphen_values = true)]
    tilt_lon_deg: Option<f64>,
    /// Window over which the cone angles are taken as constant, s.
    #[arg(long, default_value_t = 1.0)]
    window_s: f64,
}

/// Apply a rotor model (from `aeromag rotor fit`) to a flight file.
///
/// Writes every input column plus `rotor_interf` (modelled rotor
/// interference, nT), `mag_comp` (mag − rotor_interf, nT) and `rotor_flag`
/// (0 compensated, 1 not: a missing value in the row, or a stretch shorter
/// than 10 s between gaps). Every input row is written, in order.
///
/// Example:
///   aeromag rotor apply --model rotor.json --input heli2.csv --out heli2_comp.csv
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct ApplyArgs {
    /// Model file written by `aeromag rotor fit`.
    #[arg(long, value_name = "ROTOR.json")]
    model: PathBuf,
    #[command(flatten)]
    input: InputArgs,
    /// Output CSV file.
    #[arg(long, value_name = "OUT.csv")]
    out: PathBuf,
}

/// Sample rate from the median time step, Hz (bad input without two
/// increasing time stamps).
pub(crate) fn sample_rate(table: &FlightTable, time: &[f64]) -> anyhow::Result<f64> {
    let dt = median_step(time);
    if dt > 0.0 {
        Ok(1.0 / dt)
    } else {
        Err(bad_input!(
            "{}: fewer than two increasing time samples",
            table.file_label()
        ))
    }
}

/// Rows where every listed column is finite, the segments of such rows
/// (split at time gaps over 1.5 steps and at `line` changes when given) of
/// at least `min_len` rows, and the short ones.
pub(crate) fn usable_segments(
    time: &[f64],
    line: Option<&[f64]>,
    cols: &[&[f64]],
    min_len: usize,
) -> (Vec<bool>, Vec<Range<usize>>, Vec<Range<usize>>) {
    let usable: Vec<bool> = (0..time.len())
        .map(|k| time[k].is_finite() && cols.iter().all(|c| c[k].is_finite()))
        .collect();
    let (segs, short) = split_segments(time, line, &usable, 1.5, min_len);
    (usable, segs, short)
}

/// The columns a rotor fit or application reads.
struct RotorColumns<'a> {
    time: &'a [f64],
    mag: &'a [f64],
    flux: [&'a [f64]; 3],
    phase: Option<&'a [f64]>,
}

impl<'a> RotorColumns<'a> {
    fn from_table(t: &'a FlightTable, phase: Option<&str>) -> anyhow::Result<Self> {
        Ok(Self {
            time: t.require("time")?,
            mag: t.require("mag")?,
            flux: [
                t.require("flux_x")?,
                t.require("flux_y")?,
                t.require("flux_z")?,
            ],
            phase: phase.map(|p| t.require(p)).transpose()?,
        })
    }

    fn all(&self) -> Vec<&'a [f64]> {
        let mut v = vec![self.mag, self.flux[0], self.flux[1], self.flux[2]];
        v.extend(self.phase);
        v
    }

    fn field(&self, r: &Range<usize>) -> Vec<Vector3<f64>> {
        r.clone()
            .map(|k| Vector3::new(self.flux[0][k], self.flux[1][k], self.flux[2][k]))
            .collect()
    }
}

/// Phase (rad, unwrapped) and rotor speed (rad/s) of one segment: from the
/// channel, or estimated from `mag` (steps 1–2 of the library's `phase`).
fn segment_phase(
    cols: &RotorColumns,
    r: &Range<usize>,
    fs: f64,
    blades: usize,
    band: [f64; 2],
) -> anyhow::Result<(Vec<f64>, Vec<f64>)> {
    let phase = match cols.phase {
        Some(p) => unwrap_deg(&p[r.clone()]),
        None => estimate_phase(&cols.mag[r.clone()], fs, blades, band[0], band[1])?.phase_rad,
    };
    let omega = rotor_speed(&phase, fs, 1.0)?;
    Ok((phase, omega))
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

/// Options of the tracking on new data with a phase estimated from it: the
/// final options plus a slowly varying phase correction.
fn tracking_with_phase(o: &SlowAngleOptions) -> SlowAngleOptions {
    SlowAngleOptions {
        estimate_phase: true,
        iterations: o.iterations.max(6),
        ..*o
    }
}

fn check_column_name(t: &FlightTable, name: &str) -> anyhow::Result<()> {
    if name.starts_with("true_") {
        return Err(bad_input!(
            "{}: `{name}` is a simulation truth column; the rotor model never reads truth",
            t.file_label()
        ));
    }
    Ok(())
}

pub fn fit(a: FitArgs) -> anyhow::Result<()> {
    let table = a.input.load()?;
    let file = table.file_label();
    let base = scenario_geometry();
    let hub = a
        .hub_m
        .as_deref()
        .map(|s| parse_numbers("--hub-m", s, 3))
        .transpose()?;
    let sensor = a
        .sensor_m
        .as_deref()
        .map(|s| parse_numbers("--sensor-m", s, 3))
        .transpose()?;
    let span = a
        .blade_span_m
        .as_deref()
        .map(|s| parse_numbers("--blade-span-m", s, 2))
        .transpose()?;
    let geom = RotorGeometry {
        hub_m: hub.map_or(base.hub_m, |v| [v[0], v[1], v[2]]),
        sensor_m: sensor.map_or(base.sensor_m, |v| [v[0], v[1], v[2]]),
        root_m: span.as_ref().map_or(base.root_m, |v| v[0]),
        tip_m: span.as_ref().map_or(base.tip_m, |v| v[1]),
        blades: a.blades.unwrap_or(base.blades),
    };
    geom.validate().map_err(|e| bad_input!("{e}"))?;
    let nom = nominal_angles();
    let angles = FlapAngles {
        coning_rad: a.coning_deg.map_or(nom.coning_rad, f64::to_radians),
        tilt_lon_rad: a.tilt_lon_deg.map_or(nom.tilt_lon_rad, f64::to_radians),
        tilt_lat_rad: nom.tilt_lat_rad,
    };
    let band = parse_numbers("--rotor-hz", &a.rotor_hz, 2)?;
    if !(band[0] > 0.0 && band[1] > band[0]) {
        return Err(bad_input!("--rotor-hz {}: need 0 < LO < HI", a.rotor_hz));
    }
    if !(a.window_s.is_finite() && a.window_s > 0.0) {
        return Err(bad_input!("--window-s {} must be positive", a.window_s));
    }
    let phase_col = match (&a.phase_column, a.estimate_phase) {
        (_, true) => None,
        (Some(c), false) => Some(c.clone()),
        (None, false) => table.get("rotor_phase").map(|_| "rotor_phase".to_string()),
    };
    if let Some(c) = &phase_col {
        check_column_name(&table, c)?;
    }
    let raw = RotorColumns::from_table(&table, phase_col.as_deref())?;
    let fs = sample_rate(&table, raw.time)?;
    // Short dropouts (missing cells, no time gap) are bridged so that the
    // stretches on both sides are fitted as one record.
    let max_fill = (MAX_FILL_S * fs).round().max(1.0) as usize;
    let raw_cols = raw.all();
    let filled: Vec<Vec<f64>> = raw_cols
        .iter()
        .enumerate()
        .map(|(k, c)| {
            bridge_dropouts(
                raw.time,
                c,
                max_fill,
                if k == 4 { Some(360.0) } else { None },
            )
        })
        .collect();
    let bridged = (0..raw.time.len())
        .filter(|&i| {
            raw_cols.iter().any(|c| !c[i].is_finite()) && filled.iter().all(|c| c[i].is_finite())
        })
        .count();
    let cols = RotorColumns {
        time: raw.time,
        mag: &filled[0],
        flux: [&filled[1], &filled[2], &filled[3]],
        phase: raw.phase.map(|_| filled[4].as_slice()),
    };
    if bridged > 0 {
        eprintln!(
            "note: {bridged} rows with a missing value in a dropout of at most {MAX_FILL_S} s are bridged by linear interpolation for the fit"
        );
    }
    let min_len = (MIN_SEGMENT_S * fs).ceil() as usize;
    let (_, segs, _) = usable_segments(cols.time, None, &cols.all(), min_len);
    let r = segs
        .iter()
        .max_by_key(|r| r.len())
        .cloned()
        .ok_or_else(|| {
            bad_input!("{file}: no stretch of ≥ {MIN_SEGMENT_S} s without gaps or missing values")
        })?;
    let used: usize = segs.iter().map(|s| s.len()).sum();
    if used < table.n_rows() {
        eprintln!(
            "warning: {} of {} rows are in stretches without gaps or missing values of at least {MIN_SEGMENT_S} s \
             and are fitted; the others are left out",
            used,
            table.n_rows()
        );
    }
    let fit_opts = RotorFitOptions::default();
    let b = cols.field(&r);
    let mag = &cols.mag[r.clone()];
    let (mut phase, omega) = segment_phase(&cols, &r, fs, geom.blades, [band[0], band[1]])?;
    let nominal = [angles];
    let estimated = phase_col.is_none();
    if estimated {
        let inp = RotorInput {
            b_body_nt: &b,
            phase_rad: &phase,
            omega_rad_s: &omega,
            angles: &nominal,
        };
        let c = refine_phase_offset(&geom, BladeTerms::Full, &inp, mag, fs, &fit_opts)?;
        phase.iter_mut().for_each(|p| *p += c);
    }
    if estimated {
        let inp = RotorInput {
            b_body_nt: &b,
            phase_rad: &phase,
            omega_rad_s: &omega,
            angles: &nominal,
        };
        let o = phase_refinement(a.window_s);
        phase = fit_slow_angles(&geom, BladeTerms::Full, &inp, mag, fs, &fit_opts, &o)?.phase_rad;
    }
    let slow_opts = SlowAngleOptions {
        window_s: a.window_s,
        ..SlowAngleOptions::default()
    };
    let inp = RotorInput {
        b_body_nt: &b,
        phase_rad: &phase,
        omega_rad_s: &omega,
        angles: &nominal,
    };
    let slow = fit_slow_angles(
        &geom,
        BladeTerms::Full,
        &inp,
        mag,
        fs,
        &fit_opts,
        &slow_opts,
    )?;
    let rotor_hz = omega.iter().sum::<f64>() / omega.len() as f64 / std::f64::consts::TAU;
    let coning_mean_deg =
        slow.angles.iter().map(|x| x.coning_rad).sum::<f64>() / slow.angles.len() as f64 * 180.0
            / std::f64::consts::PI;
    let mut columns = BTreeMap::new();
    for c in ["time", "mag", "flux_x", "flux_y", "flux_z"]
        .into_iter()
        .chain(phase_col.as_deref())
    {
        columns.insert(c.to_string(), table.resolve(c).unwrap_or(c).to_string());
    }
    let mut model = RotorModelFile {
        format: MODEL_FORMAT.into(),
        kind: ROTOR_KIND.into(),
        geometry: geom,
        nominal_angles: angles,
        model: slow.fit,
        fit_options: fit_opts,
        slow_angles: slow_opts,
        phase: PhaseSource {
            column: phase_col.clone(),
            rotor_hz_range: [band[0], band[1]],
        },
        sample_rate_hz: fs,
        rotor_hz,
        coning_mean_deg,
        rows: r.len(),
        columns,
        software_version: env!("CARGO_PKG_VERSION").into(),
    };
    // Several stretches between gaps: the parameters found on the longest
    // are refined on all of them, each with its own phase and slowly varying
    // angles tracked as `rotor apply` would.
    if segs.len() > 1 {
        for _ in 0..REFINE_ITERATIONS {
            let tracked: Vec<TrackedSegment> = segs
                .iter()
                .map(|s| track_segment(&model, &cols, s, fs))
                .collect::<anyhow::Result<_>>()?;
            let regs: Vec<Vec<Vec<f64>>> = tracked
                .iter()
                .map(|t| regressors(&model.geometry, model.model.terms, &t.input()))
                .collect::<Result<_, _>>()?;
            let records: Vec<(&[Vec<f64>], &[f64])> = regs
                .iter()
                .zip(&segs)
                .map(|(c, s)| (c.as_slice(), &cols.mag[s.clone()]))
                .collect();
            model.model = fit_records(&records, model.model.terms, fs, &fit_opts)?;
        }
        model.rows = used;
        eprintln!(
            "note: parameters refined on all {} stretches ({used} rows)",
            segs.len()
        );
    }
    std::fs::write(&a.model, serde_json::to_string_pretty(&model)?)
        .map_err(|e| anyhow::anyhow!("cannot write '{}': {e}", a.model.display()))?;
    println!(
        "fitted the rotor model on {} rows of {file} ({:.3} Hz, f_r {rotor_hz:.4} Hz, phase {}): {} parameters, \
         high-passed residual {:.4} nT, mean coning {coning_mean_deg:.2}°; written to {}",
        model.rows,
        fs,
        phase_col
            .as_deref()
            .map_or("estimated from the data".to_string(), |c| format!(
                "from `{c}`"
            )),
        model.model.params.len(),
        model.model.residual_rms_nt,
        a.model.display()
    );
    Ok(())
}

/// Read and check a rotor model file.
pub fn load_model(path: &Path) -> anyhow::Result<RotorModelFile> {
    crate::flight::load_model_file(path, RotorModelFile::from_json)
}

/// Modelled rotor interference for every row (NaN where not compensated)
/// of `table` with `model`.
pub fn rotor_interference(model: &RotorModelFile, table: &FlightTable) -> anyhow::Result<Vec<f64>> {
    let phase_col = model.phase.column.as_deref();
    let cols = RotorColumns::from_table(table, phase_col)?;
    let fs = sample_rate(table, cols.time)?;
    if (fs / model.sample_rate_hz - 1.0).abs() > 0.01 {
        eprintln!(
            "warning: {}: sample rate {fs:.3} Hz differs from the model's {:.3} Hz",
            table.file_label(),
            model.sample_rate_hz
        );
    }
    let min_len = (MIN_SEGMENT_S * fs).ceil() as usize;
    let (_, segs, _) = usable_segments(cols.time, None, &cols.all(), min_len);
    let mut out = vec![f64::NAN; table.n_rows()];
    for r in segs {
        let t = track_segment(model, &cols, &r, fs)?;
        let p = model.model.predict(&model.geometry, &t.input())?;
        out[r].copy_from_slice(&p);
    }
    Ok(out)
}

/// One stretch of a record with the rotor phase, speed and slowly varying
/// angles found for it with a fitted model.
struct TrackedSegment {
    b: Vec<Vector3<f64>>,
    omega: Vec<f64>,
    phase: Vec<f64>,
    angles: Vec<FlapAngles>,
}

impl TrackedSegment {
    fn input(&self) -> RotorInput<'_> {
        RotorInput {
            b_body_nt: &self.b,
            phase_rad: &self.phase,
            omega_rad_s: &self.omega,
            angles: &self.angles,
        }
    }
}

/// Phase (from the channel, or estimated and aligned to `model`) and the
/// slowly varying angles (tracked with `model`'s parameters fixed) of rows
/// `r`: what `rotor apply` does to a stretch, and what `rotor fit` does to
/// the stretches it refits on.
fn track_segment(
    model: &RotorModelFile,
    cols: &RotorColumns,
    r: &Range<usize>,
    fs: f64,
) -> anyhow::Result<TrackedSegment> {
    let g = &model.geometry;
    let nominal = [model.nominal_angles];
    let b = cols.field(r);
    let mag = &cols.mag[r.clone()];
    let (mut phase, omega) = segment_phase(cols, r, fs, g.blades, model.phase.rotor_hz_range)?;
    let estimated = model.phase.column.is_none();
    if estimated {
        let inp = RotorInput {
            b_body_nt: &b,
            phase_rad: &phase,
            omega_rad_s: &omega,
            angles: &nominal,
        };
        let c = align_phase_offset(g, &model.model, &inp, mag, fs, &model.fit_options)?;
        phase.iter_mut().for_each(|p| *p += c);
    }
    let inp = RotorInput {
        b_body_nt: &b,
        phase_rad: &phase,
        omega_rad_s: &omega,
        angles: &nominal,
    };
    let opts = if estimated {
        tracking_with_phase(&model.slow_angles)
    } else {
        model.slow_angles
    };
    let slow = track_slow_angles(g, &model.model, &inp, mag, fs, &model.fit_options, &opts)?;
    Ok(TrackedSegment {
        b,
        omega,
        phase: slow.phase_rad,
        angles: slow.angles,
    })
}

pub fn apply(a: ApplyArgs) -> anyhow::Result<()> {
    let model = load_model(&a.model)?;
    let mut table = a.input.load()?;
    let interf = rotor_interference(&model, &table)?;
    let missing = add_compensation(&mut table, "rotor_interf", "rotor_flag", interf)?;
    let why = format!("missing values or stretches under {MIN_SEGMENT_S} s");
    crate::flight::write_compensated(&table, &a.out, &a.model, "", missing, "rotor_flag", &why)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dropouts_are_bridged_but_not_time_gaps_or_long_runs() {
        let t: Vec<f64> = (0..10).map(|k| k as f64 * 0.01).collect();
        let nan = f64::NAN;
        let x = [0.0, 1.0, nan, 3.0, nan, nan, nan, 7.0, 8.0, nan];
        let y = bridge_dropouts(&t, &x, 2, None);
        assert_eq!(y[2], 2.0);
        assert!(
            y[4].is_nan() && y[5].is_nan() && y[6].is_nan(),
            "a run of 3 > 2 stays"
        );
        assert!(y[9].is_nan(), "no value after the run");
        // A phase in degrees is interpolated the short way round 360°.
        let p = bridge_dropouts(&t[..3], &[350.0, nan, 10.0], 1, Some(360.0));
        assert!((p[1] - 360.0).abs() < 1e-9, "{}", p[1]);
        // A time gap across the run: left alone.
        let tg = [0.0, 0.01, 0.02, 0.5, 0.51];
        assert!(bridge_dropouts(&tg, &[0.0, 1.0, nan, 3.0, 4.0], 2, None)[2].is_nan());
    }
}
