//! Dipole parameters from gradiometer passes on files (spec
//! `gradiometry.md`, seed 004; algorithms in [`aeromag_gradiometry`]):
//! the pass file format ([`pass_table`], [`read_pass`]), locating the
//! object over a pass ([`locate_pass`] → [`Track`]), the Cramér–Rao bound
//! of a configured pass ([`crlb()`]), the convergence maps of the seed's
//! fig. 2 ([`both_maps`]) and simulating a pass to a folder
//! ([`simulate_to_dir`]). The algorithms' modules are re-exported here
//! (`aeromag::gradiometry::sim`, `::locate`, `::crlb`, …).

pub use aeromag_gradiometry::{
    GradiometryError, config, convergence, crlb, decorrelate, efficiency, estimability, forward,
    geometry, locate, motion, pass, sim, sr_iekf,
};

use crate::error::{Error, Result};
use crate::flight::Flight;
use crate::observer::Note;
use aeromag_core::error::shown;
use aeromag_core::field::igrf::IgrfModel;
use aeromag_core::frames::Attitude;
use aeromag_core::frames::geodetic::Geodetic;
use aeromag_gradiometry::config::GradiometerConfig;
use aeromag_gradiometry::convergence::{
    ConvergenceCase, ConvergenceMap, Initialisation, convergence_map,
};
use aeromag_gradiometry::efficiency::{scalar_pass_crlb, tensor_pass_crlb};
use aeromag_gradiometry::forward::Background;
use aeromag_gradiometry::locate::{LocateConfig, Located, locate_scalar, locate_tensor};
use aeromag_gradiometry::motion::{Motion, NavFix};
use aeromag_gradiometry::sim::{
    Epoch, Gradiometer, SimEpoch, scalar_epochs, simulate, tensor_epochs,
};
use aeromag_io::FlightTable;
use aeromag_report::{Block, Heatmap};
use nalgebra::{SVector, Vector3};
use serde::Serialize;
use std::borrow::Borrow;
use std::path::{Path, PathBuf};

/// A gradiometer scenario file (absent: the defaults), read and checked
/// (bad input naming the file otherwise).
pub fn read_config(path: Option<&Path>) -> Result<GradiometerConfig> {
    match path {
        None => Ok(GradiometerConfig::default()),
        Some(p) => {
            let text = crate::model_file::read_text_file(p)?;
            let bad = |e: Error| Error::in_text(p.display().to_string(), e);
            let cfg = GradiometerConfig::from_toml(&text).map_err(|e| bad(e.into()))?;
            // TOML nan and inf, which the configuration's own checks let through.
            aeromag_sim::scenario::config::parse_table(&text).map_err(|e| bad(e.into()))?;
            Ok(cfg)
        }
    }
}

/// The `aeromag dipole locate` choices that override a scenario file's
/// (Python's `locate_dipole` keywords): every value given replaces the
/// file's.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LocateSettings {
    /// `tensor` or `scalar` gradiometer.
    pub gradiometer: Option<Gradiometer>,
    /// Sensor layout.
    pub layout: Option<aeromag_gradiometry::geometry::Layout>,
    /// Baseline between sensors, m.
    pub baseline_m: Option<f64>,
    /// Sensor noise, nT (of the vector sensors for a tensor gradiometer,
    /// of the scalar ones otherwise).
    pub noise_nt: Option<f64>,
    /// Filter passes over the epochs.
    pub passes: Option<usize>,
    /// Multi-start initialisation on (`Some(true)`) or off.
    pub multistart: Option<bool>,
}

impl LocateSettings {
    /// Apply these choices to `cfg` and check the result (bad input naming
    /// what is wrong).
    pub fn apply(&self, cfg: &mut GradiometerConfig) -> Result<()> {
        use aeromag_gradiometry::config::{MAX_PASSES, NOISE_RANGE_NT};
        use aeromag_gradiometry::geometry::BASELINE_RANGE_M;
        let check = |flag: &str, v: Option<f64>, (lo, hi): (f64, f64), unit: &str| match v {
            Some(v) if !(lo..=hi).contains(&v) => Err(Error::bad_input(format!(
                "{flag} {}: expected {}…{}{unit}",
                shown(v),
                shown(lo),
                shown(hi)
            ))),
            _ => Ok(()),
        };
        check(
            "--baseline-m (baseline_m)",
            self.baseline_m,
            BASELINE_RANGE_M,
            " m",
        )?;
        check(
            "--noise-nt (noise_nt)",
            self.noise_nt,
            NOISE_RANGE_NT,
            " nT",
        )?;
        check(
            "--passes (passes)",
            self.passes.map(|p| p as f64),
            (1.0, MAX_PASSES as f64),
            "",
        )?;
        if let Some(g) = self.gradiometer {
            cfg.system.gradiometer = g;
        }
        if let Some(l) = self.layout {
            cfg.system.layout = l;
        }
        if let Some(b) = self.baseline_m {
            cfg.system.baseline_m = b;
        }
        if let Some(s) = self.noise_nt {
            match cfg.system.gradiometer {
                Gradiometer::Tensor => cfg.sensors.vector.noise_nt = s,
                Gradiometer::Scalar => cfg.sensors.scalar.noise_nt = s,
            }
        }
        if let Some(p) = self.passes {
            cfg.estimator.passes = p;
        }
        if let Some(m) = self.multistart {
            cfg.estimator.multistart = m;
        }
        cfg.validate()
            .map_err(|e| Error::bad_input(format!("settings (scenario file and choices): {e}")))
    }
}

/// A gradiometer or layout by its scenario-file name (`tensor`,
/// `tetrahedron`, …); bad input listing the names otherwise.
pub fn parse_name<T: serde::de::DeserializeOwned>(
    what: &str,
    name: &str,
    names: &str,
) -> Result<T> {
    serde_json::from_value(serde_json::Value::String(name.to_string()))
        .map_err(|_| Error::bad_input(format!("{what} '{name}': expected {names}")))
}

/// A simulated gradiometer pass as the table `aeromag simulate
/// gradiometer` writes (sensor columns, navigation, `true_` columns).
pub fn simulate_pass(cfg: &GradiometerConfig) -> Result<FlightTable> {
    cfg.validate()
        .map_err(|e| Error::bad_input(format!("scenario: {e}")))?;
    let sim = simulate(&cfg.scenario()?)?;
    let table = pass_table(cfg, &sim)?;
    // The simulator models nothing as missing: NaN or ∞ is an overflow of
    // the scenario's values (a noise of 10³⁰⁸ nT).
    for c in table.columns() {
        if let Some(v) = c.values()
            && let Some(k) = v.iter().position(|x| !x.is_finite())
        {
            return Err(Error::bad_input(format!(
                "scenario: the values are too large for the simulator: the simulated `{}` is {} at epoch {}",
                c.name(),
                v[k],
                k + 1
            )));
        }
    }
    // The pass must be one the reader takes (readings beyond any field, a
    // speed of 3·10⁸ m/s, a longitude of 400° were written with exit 0 and
    // refused by `dipole locate`).
    let mut measured = FlightTable::new();
    measured.set_source("simulated pass");
    for name in pass_columns(cfg.system.gradiometer) {
        measured.add_column(&name, table.require(&name)?.to_vec())?;
    }
    read_pass(&Flight::from_table(measured)?, cfg).map_err(|e| {
        Error::bad_input(format!(
            "scenario: the simulated pass is one `dipole locate` refuses: {e}"
        ))
    })?;
    Ok(table)
}

/// The files [`simulate_to_dir`] writes.
#[derive(Debug, Clone)]
pub struct SimulatedPass {
    /// The pass table, `DIR/gradiometer.csv`.
    pub csv: PathBuf,
    /// The scenario with every default filled in, `DIR/gradiometer.toml`.
    pub scenario: PathBuf,
    /// Rows (epochs) and columns of the table.
    pub rows: usize,
    /// Columns of the table.
    pub columns: usize,
}

/// The files [`simulate_to_dir`] writes in its folder: the pass and its
/// scenario.
pub const SIMULATED_FILES: [&str; 2] = ["gradiometer.csv", "gradiometer.toml"];

/// Simulate the configured pass and write `DIR/gradiometer.csv`
/// ([`pass_table`]) and `DIR/gradiometer.toml`, as a set.
pub fn simulate_to_dir(cfg: &GradiometerConfig, out: &Path) -> Result<SimulatedPass> {
    let table = simulate_pass(cfg)?;
    crate::model_file::create_output_folder(out)?;
    let [csv, scenario] = SIMULATED_FILES.map(|n| out.join(n));
    let text = cfg.to_toml()?;
    // The two as a set, checked first (the CSV was replaced before a
    // folder in the place of the scenario failed its write).
    let werr = |(path, e): (std::path::PathBuf, std::io::Error)| Error::write(path, e);
    let mut set =
        aeromag_io::atomic::FileSet::new([csv.as_path(), scenario.as_path()]).map_err(werr)?;
    set.write(&csv, |w| aeromag_io::write_csv_to(&table, w))
        .map_err(werr)?;
    set.write(&scenario, |w| std::io::Write::write_all(w, text.as_bytes()))
        .map_err(werr)?;
    set.commit().map_err(werr)?;
    Ok(SimulatedPass {
        csv,
        scenario,
        rows: table.n_rows(),
        columns: table.columns().len(),
    })
}

/// Names of the six state components, in state order.
pub const STATE_NAMES: [&str; 6] = ["x_m", "y_m", "z_m", "mx_am2", "my_am2", "mz_am2"];

/// The Cramér–Rao bound at one epoch of a pass.
#[derive(Debug, Clone, Serialize)]
pub struct CrlbAt {
    /// Epoch index.
    pub epoch: usize,
    /// Its time, s.
    pub time_s: f64,
    /// Range to the object, m.
    pub range_m: f64,
    /// Standard deviations in [`STATE_NAMES`] order (NaN for the scalar
    /// system's known position).
    #[serde(skip)]
    pub std: [f64; 6],
}

/// The Cramér–Rao bound of a configured pass at the closest approach and at
/// its end, from every epoch up to each.
#[derive(Debug, Clone)]
pub struct CrlbReport {
    /// The configuration (gradiometer, system, noise).
    pub config: GradiometerConfig,
    /// At the closest approach.
    pub closest_approach: CrlbAt,
    /// At the end of the pass.
    pub end: CrlbAt,
}

impl CrlbReport {
    /// The report as `aeromag dipole crlb --json` prints it: gradiometer,
    /// system motion, sensor σ (nT), and at the closest approach and the
    /// end of the pass the epoch, time (s), range (m) and the standard
    /// deviation of each determined state (m, A·m²).
    pub fn to_json(&self) -> serde_json::Value {
        let entry = |at: &CrlbAt| {
            let std: serde_json::Map<String, serde_json::Value> = STATE_NAMES
                .iter()
                .zip(&at.std)
                .filter(|(_, v)| v.is_finite())
                .map(|(n, v)| (n.to_string(), serde_json::json!(v)))
                .collect();
            serde_json::json!({ "epoch": at.epoch, "time_s": at.time_s, "range_m": at.range_m, "std": std })
        };
        serde_json::json!({
            "gradiometer": self.config.system.gradiometer,
            "system": self.config.system.motion,
            "sigma_nt": self.config.sensor_sigma_nt(),
            "closest_approach": entry(&self.closest_approach),
            "end": entry(&self.end),
        })
    }
}

/// The Cramér–Rao bound (standard deviation of each parameter) of the
/// configured pass: geometry, sensor noise, trajectory and object of the
/// scenario, the known motion, white contrasts.
///
/// ```
/// use aeromag::gradiometry::config::GradiometerConfig;
/// use aeromag::gradiometry::{STATE_NAMES, crlb};
/// let bound = crlb(&GradiometerConfig::default())?;
/// for (name, sd) in STATE_NAMES.iter().zip(bound.end.std) {
///     assert!(sd > 0.0 && sd.is_finite(), "{name}");
/// }
/// # Ok::<(), aeromag::Error>(())
/// ```
pub fn crlb(cfg: &GradiometerConfig) -> Result<CrlbReport> {
    let sim = simulate(&cfg.scenario()?)?;
    let closest = (0..sim.len())
        .min_by(|&i, &j| {
            sim[i]
                .true_position_m
                .norm()
                .total_cmp(&sim[j].true_position_m.norm())
        })
        .unwrap_or(0);
    let at = |j: usize| -> Result<CrlbAt> {
        Ok(CrlbAt {
            epoch: j,
            time_s: sim[j].t_s,
            range_m: sim[j].true_position_m.norm(),
            std: crlb_at(cfg, &sim, j)?,
        })
    };
    Ok(CrlbReport {
        config: cfg.clone(),
        closest_approach: at(closest)?,
        end: at(sim.len() - 1)?,
    })
}

/// The truth columns of a simulated pass (never read by the estimators).
pub const TRUTH: [&str; 6] = [
    "true_x_m",
    "true_y_m",
    "true_z_m",
    "true_mx_am2",
    "true_my_am2",
    "true_mz_am2",
];

/// Reading columns of the four sensors: `b1_x … b4_z` (tensor, nT, body
/// frame) or `f1 … f4` (scalar, nT).
pub fn sensor_columns(g: Gradiometer) -> Vec<String> {
    match g {
        Gradiometer::Tensor => (1..=4)
            .flat_map(|i| ["x", "y", "z"].map(|a| format!("b{i}_{a}")))
            .collect(),
        Gradiometer::Scalar => (1..=4).map(|i| format!("f{i}")).collect(),
    }
}

/// The columns [`read_pass`] reads: `time`, the system's `lat, lon, alt,
/// north_m, east_m, down_m, roll, pitch, yaw`, the object's known track
/// `obj_north_m, obj_east_m, obj_down_m, obj_yaw` and the readings
/// ([`sensor_columns`]); never the truth ([`TRUTH`]).
pub fn pass_columns(g: Gradiometer) -> Vec<String> {
    [
        "time",
        "lat",
        "lon",
        "alt",
        "north_m",
        "east_m",
        "down_m",
        "roll",
        "pitch",
        "yaw",
        "obj_north_m",
        "obj_east_m",
        "obj_down_m",
        "obj_yaw",
    ]
    .into_iter()
    .map(String::from)
    .chain(sensor_columns(g))
    .collect()
}

/// The simulated pass as a table (one row per epoch): `time`; system
/// `lat, lon, alt`, `north_m, east_m, down_m`, `roll, pitch, yaw` (deg); the
/// object's known track `obj_north_m, obj_east_m, obj_down_m, obj_yaw`
/// (deg); the readings ([`sensor_columns`]); the truth ([`TRUTH`]: object
/// relative to the gradiometer centre, body frame, m, and its moment, A·m²).
pub fn pass_table(cfg: &GradiometerConfig, sim: &[SimEpoch]) -> Result<FlightTable> {
    let mut t = FlightTable::new();
    let mut add = |name: &str, f: &dyn Fn(&SimEpoch) -> f64| -> Result<()> {
        t.add_column(name, sim.iter().map(f).collect())?;
        Ok(())
    };
    add("time", &|e| e.t_s)?;
    add("lat", &|e| e.system_geodetic.lat_deg)?;
    add("lon", &|e| e.system_geodetic.lon_deg)?;
    add("alt", &|e| e.system_geodetic.alt_m)?;
    for (k, n) in ["north_m", "east_m", "down_m"].iter().enumerate() {
        add(n, &|e| e.system_position_ned_m[k])?;
    }
    add("roll", &|e| e.system_attitude.roll.to_degrees())?;
    add("pitch", &|e| e.system_attitude.pitch.to_degrees())?;
    add("yaw", &|e| e.system_attitude.yaw.to_degrees())?;
    for (k, n) in ["obj_north_m", "obj_east_m", "obj_down_m"]
        .iter()
        .enumerate()
    {
        add(n, &|e| e.object_position_ned_m[k])?;
    }
    add("obj_yaw", &|e| e.object_yaw_rad.to_degrees())?;
    let names = sensor_columns(cfg.system.gradiometer);
    for (c, name) in names.iter().enumerate() {
        match cfg.system.gradiometer {
            Gradiometer::Tensor => add(name, &|e| e.vector_nt[c / 3][c % 3])?,
            Gradiometer::Scalar => add(name, &|e| e.scalar_nt[c])?,
        }
    }
    for (k, n) in TRUTH.iter().enumerate() {
        if k < 3 {
            add(n, &|e| e.true_position_m[k])?;
        } else {
            add(n, &|e| e.true_moment_am2[k - 3])?;
        }
    }
    Ok(t)
}

/// A measured pass read from a flight table ([`pass_table`]'s columns; the
/// truth columns are never read): the epochs and the object's position
/// relative to the gradiometer centre from the known tracks (body frame, m:
/// what the scalar gradiometer's filter is given).
#[derive(Debug, Clone)]
pub struct MeasuredPass {
    /// Readings, IGRF background at the navigated position and attitude,
    /// motion from consecutive fixes.
    pub epochs: Vec<Epoch>,
    /// The object's known position, body frame, m.
    pub positions_m: Vec<Vector3<f64>>,
    /// Warnings about the pass as read (time gaps).
    pub notes: Vec<Note>,
}

/// A step between epochs this many times the median step is a gap in the
/// pass, warned of: the object may pass unseen in it (a 10 s gap at the
/// closest approach gave "object not detected", exit 0, without a word).
pub const GAP_STEPS: f64 = 3.0;

/// The warning for the time gaps of a pass (steps above [`GAP_STEPS`] times
/// the median step), naming the first and the longest; none without gaps.
fn gap_warning(t: &Flight, time: &[f64]) -> Option<Note> {
    let steps: Vec<f64> = time.windows(2).map(|w| w[1] - w[0]).collect();
    let median = aeromag_compensation::tolles_lawson::segments::median_step(time);
    let gaps: Vec<usize> = (0..steps.len())
        .filter(|&j| steps[j] > GAP_STEPS * median)
        .collect();
    let first = *gaps.first()?;
    let longest = *gaps
        .iter()
        .max_by(|&&a, &&b| steps[a].total_cmp(&steps[b]))?;
    let fig = aeromag_core::error::figure;
    let longest = if gaps.len() > 1 {
        format!(
            ", the longest {} s before data row {}",
            fig(steps[longest]),
            t.file_row(longest + 1) + 1
        )
    } else {
        String::new()
    };
    Some(Note::warning(format!(
        "{}: {} time gap(s) in the pass (steps over {GAP_STEPS} times the median {} s), the first {} s \
         before data row {}{longest}: the object may have passed unseen there; the filter bridges \
         them with its motion model",
        t.label(),
        gaps.len(),
        fig(median),
        fig(steps[first]),
        t.file_row(first + 1) + 1,
    )))
}

/// Extent of a pass's local frame, m (positions `north_m`, `obj_north_m`,
/// …): 1000 km, far beyond the range at which a gradiometer sees a dipole.
pub const PASS_EXTENT_M: f64 = 1e6;

/// Read a measured pass for the configured gradiometer from `t`: every
/// value must be a finite number within its physical range — readings
/// within ±[`aeromag_io::MAX_FIELD_NT`], positions within
/// ±[`PASS_EXTENT_M`], angles within ±360°, latitudes within ±90°,
/// heights −10 km…1000 km, time steps increasing and within
/// [`aeromag_gradiometry::sim::DT_RANGE_S`] (bad input naming file, line,
/// row and column otherwise).
pub fn read_pass(t: &Flight, cfg: &GradiometerConfig) -> Result<MeasuredPass> {
    if t.n_rows() <= cfg.estimator.quiet_epochs {
        return Err(Error::bad_file(
            t.label(),
            format!(
                "{} rows, not more than estimator.quiet_epochs = {}",
                t.n_rows(),
                cfg.estimator.quiet_epochs
            ),
        ));
    }
    // Every value finite and within what the quantity can physically be
    // (a cell of 1e308 would otherwise surface as a failed fit far away).
    let within = |n: &str, (lo, hi): (f64, f64), what: &str| -> Result<&[f64]> {
        let v = t.finite(n)?;
        match v.iter().position(|x| !(lo..=hi).contains(x)) {
            Some(row) => Err(t.bad_value(
                row,
                n,
                format!(
                    "{} is not {what} ({}…{})",
                    shown(v[row]),
                    shown(lo),
                    shown(hi)
                ),
            )),
            None => Ok(v),
        }
    };
    let angle = (-360.0, 360.0);
    let local = (-PASS_EXTENT_M, PASS_EXTENT_M);
    let local_what = "a position in the pass's local frame, m";
    let time = t.finite("time")?;
    let (lo, hi) = aeromag_gradiometry::sim::DT_RANGE_S;
    if let Some(j) = (1..time.len()).find(|&j| !(lo..=hi).contains(&(time[j] - time[j - 1]))) {
        return Err(t.bad_value(
            j,
            "time",
            format!(
                "step {} s from the previous row is not a sample interval ({}…{} s, increasing)",
                shown(time[j] - time[j - 1]),
                shown(lo),
                shown(hi)
            ),
        ));
    }
    // Headings may be recorded unwrapped (an object turning for minutes
    // passes 360°: the simulator's own longer passes were refused); the
    // motion model takes their steps modulo a turn.
    let unwrapped = (-1e6, 1e6);
    let (lat, lon) = (
        within("lat", (-90.0, 90.0), "a latitude, deg")?,
        within("lon", angle, "a longitude, deg")?,
    );
    let alt = within("alt", (-1e4, 1e6), "a height where the IGRF holds, m")?;
    let sys = [
        within("north_m", local, local_what)?,
        within("east_m", local, local_what)?,
        within("down_m", local, local_what)?,
    ];
    let att = [
        within("roll", angle, "an angle, deg")?,
        within("pitch", angle, "an angle, deg")?,
        within("yaw", unwrapped, "a heading, deg")?,
    ];
    let obj = [
        within("obj_north_m", local, local_what)?,
        within("obj_east_m", local, local_what)?,
        within("obj_down_m", local, local_what)?,
    ];
    let obj_yaw = within("obj_yaw", unwrapped, "a heading, deg")?;
    let names = sensor_columns(cfg.system.gradiometer);
    let field = (-aeromag_io::MAX_FIELD_NT, aeromag_io::MAX_FIELD_NT);
    let readings = names
        .iter()
        .map(|n| within(n, field, "a magnetic field reading, nT"))
        .collect::<Result<Vec<_>>>()?;
    let igrf = IgrfModel::new(cfg.environment.decimal_year)?;
    let fix = |j: usize| NavFix {
        system_position_ned_m: Vector3::new(sys[0][j], sys[1][j], sys[2][j]),
        system_attitude: Attitude::from_degrees(att[0][j], att[1][j], att[2][j]),
        object_position_ned_m: Vector3::new(obj[0][j], obj[1][j], obj[2][j]),
        object_yaw_rad: obj_yaw[j].to_radians(),
    };
    let mut epochs = Vec::with_capacity(t.n_rows());
    let mut positions = Vec::with_capacity(t.n_rows());
    for j in 0..t.n_rows() {
        let f = fix(j);
        let motion = if j == 0 {
            Motion::between(&f, &f, 0.0)
        } else {
            Motion::between(&fix(j - 1), &f, time[j] - time[j - 1])
        };
        let geo = Geodetic {
            lat_deg: lat[j],
            lon_deg: lon[j],
            alt_m: alt[j],
        };
        let mut vector_nt = [Vector3::zeros(); 4];
        let mut scalar_nt = [0.0; 4];
        for i in 0..4 {
            match cfg.system.gradiometer {
                Gradiometer::Tensor => {
                    vector_nt[i] = Vector3::from_fn(|k, _| readings[3 * i + k][j]);
                }
                Gradiometer::Scalar => scalar_nt[i] = readings[i][j],
            }
        }
        positions
            .push(f.system_attitude.c_bn() * (f.object_position_ned_m - f.system_position_ned_m));
        epochs.push(Epoch {
            t_s: time[j],
            vector_nt,
            scalar_nt,
            background: Background::from_igrf(&igrf, &geo, &f.system_attitude),
            motion,
            system_position_ned_m: f.system_position_ned_m,
            system_geodetic: geo,
            system_attitude: f.system_attitude,
            object_position_ned_m: f.object_position_ned_m,
            object_yaw_rad: f.object_yaw_rad,
        });
    }
    check_reading_units(t, cfg, &names, &epochs)?;
    check_track_outside_array(t, cfg, &positions)?;
    Ok(MeasuredPass {
        epochs,
        positions_m: positions,
        notes: gap_warning(t, time).into_iter().collect(),
    })
}

/// The readings of each sensor in nT: the median magnitude of its
/// readings over the pass within a factor [`FIELD_UNIT_FACTOR`] of the
/// IGRF's at the pass, else bad input naming its columns. Readings in µT
/// (53 for 53 000 nT) were read as a pass on which the object was not
/// detected, exit 0.
fn check_reading_units(
    t: &Flight,
    cfg: &GradiometerConfig,
    names: &[String],
    epochs: &[Epoch],
) -> Result<()> {
    let median = |mut v: Vec<f64>| aeromag_io::median_in_place(&mut v).unwrap_or(f64::NAN);
    if epochs.is_empty() {
        return Ok(());
    }
    let igrf = median(
        epochs
            .iter()
            .map(|e| e.background.field_nt.norm())
            .collect(),
    );
    for i in 0..4 {
        let (columns, reading): (Vec<&str>, Vec<f64>) = match cfg.system.gradiometer {
            Gradiometer::Tensor => (
                names[3 * i..3 * i + 3].iter().map(String::as_str).collect(),
                epochs.iter().map(|e| e.vector_nt[i].norm()).collect(),
            ),
            Gradiometer::Scalar => (
                vec![names[i].as_str()],
                epochs.iter().map(|e| e.scalar_nt[i].abs()).collect(),
            ),
        };
        let m = median(reading);
        if !(igrf / FIELD_UNIT_FACTOR..=igrf * FIELD_UNIT_FACTOR).contains(&m) {
            return Err(t.bad_column(
                columns[0],
                format!(
                    "sensor {} ({}) reads a median field of {} nT where the IGRF at the pass gives {} nT: \
                     another unit (µT, pT?) or another channel? expected nT",
                    i + 1,
                    columns.join(", "),
                    aeromag_core::error::fixed(m, 3),
                    aeromag_core::error::fixed(igrf, 1)
                ),
            ));
        }
    }
    Ok(())
}

/// For the scalar gradiometer, which takes the object's positions from
/// the tracks as known: the object's track relative to the gradiometer
/// (`positions_m`, body frame, m) stays outside the sphere through the
/// gradiometer's sensors, else bad input naming the first row inside it
/// (an object passing between the sensors would strike the frame). The
/// object's track in km (the default pass's 6 m closest approach read as
/// 6 mm) gave a moment of about 2 A·m² against 1200 and "0.00" mean
/// innovations, exit 0. The tensor gradiometer estimates the position and
/// takes only the object's motion from the track (a track of zeros is a
/// still object of unknown place), and its innovations show a track in km.
fn check_track_outside_array(
    t: &Flight,
    cfg: &GradiometerConfig,
    positions_m: &[Vector3<f64>],
) -> Result<()> {
    if cfg.system.gradiometer != Gradiometer::Scalar {
        return Ok(());
    }
    let radius = cfg
        .geometry()?
        .offsets_m()
        .iter()
        .map(|o| o.norm())
        .fold(0.0, f64::max);
    match positions_m.iter().position(|r| r.norm() <= radius) {
        Some(row) => Err(t.bad_value(
            row,
            "obj_north_m",
            format!(
                "the object's track passes {} m from the gradiometer's centre, inside the sphere through \
                 its sensors ({} m): the object's (obj_north_m, obj_east_m, obj_down_m) or the system's \
                 positions (north_m, east_m, down_m) in another unit than metres (km?)",
                aeromag_core::error::figure(positions_m[row].norm()),
                aeromag_core::error::figure(radius)
            ),
        )),
        None => Ok(()),
    }
}

/// How far (a factor either way) the median field a gradiometer's sensor
/// reads over a pass may lie from the IGRF's before its unit is taken to
/// be wrong: the object adds hundreds of nT near the closest approach and
/// the variations a few nT, on a field of 20 000–65 000 nT; a unit off by
/// 1000 is a factor of 1000.
pub const FIELD_UNIT_FACTOR: f64 = 2.0;

/// Per-epoch estimates over a pass: rows of 6 values in state order `x, y,
/// z` (m, body frame, object relative to the gradiometer centre), `mx, my,
/// mz` (A·m²); NaN where not estimated.
#[derive(Debug, Clone)]
pub struct Track {
    /// Estimates.
    pub x: Vec<[f64; 6]>,
    /// Their standard deviations.
    pub sd: Vec<[f64; 6]>,
    /// Estimability of each component (`MeasureS`, μ = σ⁺/σ⁰: 0 =
    /// determined by the measurements, 1 = left at its prior).
    pub mu: Vec<[f64; 6]>,
    /// Whether the object was detected at the epoch.
    pub detected: Vec<bool>,
    /// IEKF iterations.
    pub iterations: Vec<f64>,
    /// RMS measurement residual, nT.
    pub residual_nt: Vec<f64>,
    /// Whether the iteration converged.
    pub converged: Vec<bool>,
    /// The epoch's normalised innovation squared over the number of
    /// contrasts `Z` ([`aeromag_gradiometry::pass::normalised_innovation`]
    /// / `Z`): about 1 on average when the filter's σ describe its errors.
    pub nis: Vec<f64>,
}

impl Track {
    /// The track of a tensor gradiometer's filter.
    pub fn from_tensor(out: &[Option<Located<6>>]) -> Self {
        let nan = [f64::NAN; 6];
        let arr = |v: SVector<f64, 6>| std::array::from_fn(|k| v[k]);
        Self {
            x: out
                .iter()
                .map(|o| o.map_or(nan, |l| arr(l.step.posterior.x)))
                .collect(),
            sd: out
                .iter()
                .map(|o| o.map_or(nan, |l| arr(l.step.posterior.sigma())))
                .collect(),
            mu: out
                .iter()
                .map(|o| o.map_or(nan, |l| arr(l.step.estimability)))
                .collect(),
            detected: out.iter().map(Option::is_some).collect(),
            iterations: out
                .iter()
                .map(|o| o.map_or(f64::NAN, |l| l.step.iterations as f64))
                .collect(),
            residual_nt: out
                .iter()
                .map(|o| o.map_or(f64::NAN, |l| l.residual_nt))
                .collect(),
            converged: out
                .iter()
                .map(|o| o.is_some_and(|l| l.step.converged))
                .collect(),
            nis: out
                .iter()
                .map(|o| o.map_or(f64::NAN, |l| l.step.nis / 9.0))
                .collect(),
        }
    }

    /// Scalar system: the known position, σ and μ of the position NaN.
    pub fn from_scalar(out: &[Located<3>], positions: &[Vector3<f64>]) -> Self {
        let six = |p: [f64; 3], m: SVector<f64, 3>| [p[0], p[1], p[2], m[0], m[1], m[2]];
        let nan3 = [f64::NAN; 3];
        Self {
            x: out
                .iter()
                .zip(positions)
                .map(|(l, p)| six([p.x, p.y, p.z], l.step.posterior.x))
                .collect(),
            sd: out
                .iter()
                .map(|l| six(nan3, l.step.posterior.sigma()))
                .collect(),
            mu: out.iter().map(|l| six(nan3, l.step.estimability)).collect(),
            detected: vec![true; out.len()],
            iterations: out.iter().map(|l| l.step.iterations as f64).collect(),
            residual_nt: out.iter().map(|l| l.residual_nt).collect(),
            converged: out.iter().map(|l| l.step.converged).collect(),
            nis: out.iter().map(|l| l.step.nis / 3.0).collect(),
        }
    }

    /// The mean of [`Track::nis`] over the epochs estimated (from the
    /// detection on): about 1 when the filter's covariance describes its
    /// errors; `None` when nothing was estimated.
    pub fn mean_nis(&self) -> Option<f64> {
        let (sum, n) = self
            .nis
            .iter()
            .filter(|v| v.is_finite())
            .fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
        (n > 0).then(|| sum / n as f64)
    }

    /// A warning when the filter's innovations are beyond what its
    /// covariance allows ([`Track::mean_nis`] above [`MAX_MEAN_NIS`]) or
    /// far below it (under [`MIN_MEAN_NIS`]): its estimates and their σ
    /// are then not to be trusted.
    pub fn inconsistency_warning(&self) -> Option<String> {
        let m = self.mean_nis()?;
        if m > MAX_MEAN_NIS {
            Some(format!(
                "the filter's normalised innovations squared average {m:.1} per contrast, where a filter \
                 whose σ describe its errors averages about 1 (above {MAX_MEAN_NIS} here): the estimates \
                 and their σ are not to be trusted. A filter locked on a wrong solution (--plain from \
                 the half-space away from the object?), sensor columns swapped or mis-mapped, positions \
                 (north_m …, obj_north_m …) in another unit than metres, or quiet epochs \
                 (estimator.quiet_epochs) that are not quiet, or none (0) on sensors with biases?"
            ))
        } else if m < MIN_MEAN_NIS {
            Some(format!(
                "the filter's normalised innovations squared average {} per contrast, where a filter \
                 whose σ describe its errors averages about 1 (below {MIN_MEAN_NIS} here): its model \
                 predicts far larger innovations than the readings show, and the estimates and their σ \
                 are not to be trusted. A sensor noise (--noise-nt, sensors.vector.noise_nt or \
                 sensors.scalar.noise_nt) larger than the sensors' own, or positions (north_m …, \
                 obj_north_m …) in another unit than metres?",
                aeromag_core::error::figure(m)
            ))
        } else {
            None
        }
    }

    /// The estimates as a table: `time, detected, x_m, y_m, z_m, mx_am2,
    /// my_am2, mz_am2`, their standard deviations `sd_…`, the estimability
    /// measures `mu_…` (μ = σ⁺/σ⁰, 0 = determined), `iterations,
    /// residual_nt, converged, nis` ([`Track::nis`]).
    pub fn to_table(&self, time: &[f64]) -> Result<FlightTable> {
        let mut t = FlightTable::new();
        t.add_column("time", time.to_vec())?;
        let flag = |v: &[bool]| v.iter().map(|&b| f64::from(u8::from(b))).collect();
        t.add_integer_column("detected", flag(&self.detected))?;
        const N: [&str; 6] = ["x_m", "y_m", "z_m", "mx_am2", "my_am2", "mz_am2"];
        for (prefix, rows) in [("", &self.x), ("sd_", &self.sd), ("mu_", &self.mu)] {
            for (k, n) in N.iter().enumerate() {
                let name = if prefix == "mu_" {
                    format!("mu_{}", n.split('_').next().unwrap_or(n))
                } else {
                    format!("{prefix}{n}")
                };
                t.add_column(&name, rows.iter().map(|r| r[k]).collect())?;
            }
        }
        t.add_column("iterations", self.iterations.clone())?;
        t.add_column("residual_nt", self.residual_nt.clone())?;
        t.add_integer_column("converged", flag(&self.converged))?;
        t.add_column("nis", self.nis.clone())?;
        Ok(t)
    }
}

/// The largest mean normalised innovation squared per contrast
/// ([`Track::mean_nis`]) of a track whose filter is taken as consistent.
/// An honest filter gives 1 (the mean of χ²/Z over a pass of n epochs has
/// a standard deviation of √(2/(Z n)), 0.03 over the default pass).
/// Measured (default scenario): correct passes 0.93–0.99 (tensor
/// gradiometer, seeds 1–6, stationary and mobile), 0.82–0.85 (scalar);
/// the plain IEKF locked 180 m from the object 3709, sensor 1's and
/// sensor 2's columns swapped 3509, a file starting with the object near
/// (its quiet epochs not quiet) 176, `quiet_epochs = 0` 419.
pub const MAX_MEAN_NIS: f64 = 3.0;

/// The smallest mean normalised innovation squared per contrast of a
/// track whose filter is taken as consistent (see [`MAX_MEAN_NIS`]).
/// Measured (default scenario): correct scalar passes 0.72–0.78 (seeds
/// 1–4, stationary and mobile; their σ are conservative), tensor passes
/// about 1; the scalar gradiometer given the object's track in km (its
/// known positions 1000 times too near) 0.00.
pub const MIN_MEAN_NIS: f64 = 0.25;

/// Locate the object over a pass with the configured estimator (the
/// square-root IEKF: detection, multi-start or the seed's plain IEKF,
/// filter or re-linearised passes). `positions` is the object's known
/// position (body frame, m), used by the scalar gradiometer.
///
/// ```
/// use aeromag::gradiometry::config::GradiometerConfig;
/// use aeromag::gradiometry::sim::simulate;
/// use aeromag::gradiometry::{locate_pass, pass_table, read_pass};
/// use aeromag::{Flight, FlightTable};
/// // The default pass as a survey would record it: without its truth columns.
/// let cfg = GradiometerConfig::default();
/// let table = pass_table(&cfg, &simulate(&cfg.scenario()?)?)?;
/// let mut recorded = FlightTable::new();
/// for c in table.columns().iter().filter(|c| !c.name().starts_with("true_")) {
///     recorded.add_column(c.name(), c.values().unwrap_or_default().to_vec())?;
/// }
/// let pass = read_pass(&Flight::from_table(recorded)?, &cfg)?;
/// let track = locate_pass(&cfg, &pass.epochs, &pass.positions_m)?;
/// let last = track.x.len() - 1;
/// assert!(track.detected[last]);
/// println!("object at {:?} m (body frame)", &track.x[last][..3]);
/// # Ok::<(), aeromag::Error>(())
/// ```
pub fn locate_pass<E: Borrow<Epoch>>(
    cfg: &GradiometerConfig,
    epochs: &[E],
    positions: &[Vector3<f64>],
) -> Result<Track> {
    cfg.validate()
        .map_err(|e| Error::bad_input(format!("settings: {e}")))?;
    let geometry = cfg.geometry()?;
    let lc = cfg
        .locate_config(None)
        .map_err(|e| Error::bad_input(e.to_string()))?;
    Ok(match cfg.system.gradiometer {
        Gradiometer::Tensor => {
            let input = tensor_epochs(epochs, &geometry, &cfg.processing());
            let out = locate_tensor(&input, &lc)?;
            if lc.passes > 1 {
                let filter = locate_tensor(&input, &LocateConfig { passes: 1, ..lc })?;
                check_passes_agree(&filter, &out)?;
            }
            Track::from_tensor(&out)
        }
        Gradiometer::Scalar => {
            let input = scalar_epochs(
                epochs,
                &geometry,
                positions,
                &cfg.processing(),
                lc.iekf.sigma_nt,
            )?;
            Track::from_scalar(&locate_scalar(&input, &lc)?, positions)
        }
    })
    .and_then(|track| check_some_converged(cfg, track))
}

/// A track of which no epoch's iterations converged, else a failure
/// ([`aeromag_gradiometry::GradiometryError::Diverged`], not bad input):
/// its estimates are the last iterates of every epoch, not solutions.
/// Correct passes converge at nearly every epoch (335 of the default
/// pass's 340); with `estimator.quiet_epochs = 0` on sensors with biases
/// (the default scenario's 5 nT) none of 343 did, and before this check
/// `dipole locate` reported the estimates with exit 0.
fn check_some_converged(cfg: &GradiometerConfig, track: Track) -> Result<Track> {
    let estimated = track.detected.iter().filter(|&&d| d).count();
    if estimated == 0 || track.converged.iter().any(|&c| c) {
        return Ok(track);
    }
    let nis = track
        .mean_nis()
        .map_or_else(|| "not finite".into(), |m| format!("{m:.1}"));
    let cause = if cfg.estimator.quiet_epochs == 0 {
        "estimator.quiet_epochs = 0 removes no sensor bias and takes the IGRF background as the \
         model's: sensors with biases (sensors.*.bias_sigma_nt) need quiet epochs at the start of \
         the pass (the default is 50)"
    } else {
        "quiet epochs (estimator.quiet_epochs) that are not quiet, sensor columns swapped or \
         mis-mapped, readings or positions in another unit, or too few iterations \
         (estimator.max_iterations)?"
    };
    Err(Error::Gradiometry(GradiometryError::Diverged(format!(
        "none of the {estimated} epochs estimated converged within estimator.max_iterations = {} \
         (their normalised innovations squared average {nis} per contrast, about 1 for a filter \
         whose σ describe its errors): {cause}",
        cfg.estimator.max_iterations
    ))))
}

/// How far the re-linearised passes' final position may lie from the
/// filter's, as a fraction of the filter's range to the object, before the
/// passes count as diverged. Both estimate the same object from the same
/// data: they differ in precision (the filter is over-confident where it
/// linearised early epochs about a poor estimate: 17 of its σ on the
/// well-posed pass, 0.4 % of the range), not by a tenth of the distance to
/// the object.
pub const PASSES_AGREEMENT_FRACTION: f64 = 0.1;

/// The re-linearised passes' final position within
/// [`PASSES_AGREEMENT_FRACTION`] of the range of the filter's, else a
/// failure ([`aeromag_gradiometry::GradiometryError::Diverged`], not bad
/// input).
///
/// The passes linearise every epoch about the trajectory carried back from
/// the first pass's *final* estimate; that pass runs with the extra noise
/// `estimator.first_pass_extra_*`, and when the pass ends far from the
/// object (the default 120 m pass ends 60 m away, 60 baselines) it forgets
/// the object and ends at the zero-moment solution next to the
/// gradiometer. The passes then converge confidently to that wrong point.
fn check_passes_agree(filter: &[Option<Located<6>>], passes: &[Option<Located<6>>]) -> Result<()> {
    let (Some(Some(f)), Some(Some(p))) = (filter.last(), passes.last()) else {
        return Ok(());
    };
    let (xf, xp) = (f.step.posterior.x, p.step.posterior.x);
    let (rf, rp) = (xf.fixed_rows::<3>(0), xp.fixed_rows::<3>(0));
    if (rp - rf).norm() <= PASSES_AGREEMENT_FRACTION * rf.norm() {
        return Ok(());
    }
    let fmt = |x: &SVector<f64, 6>| format!("({:.3}, {:.3}, {:.3})", x[0], x[1], x[2]);
    Err(Error::Gradiometry(GradiometryError::Diverged(format!(
        "the re-linearised passes end at {} m, {:.3} m from the filter's {} m (more than {} of its \
         range): their first pass, with the extra noise estimator.first_pass_extra_position_m / \
         _moment_am2, lost the object before the end of the pass; use passes = 1 (the filter) \
         or smaller extra noise",
        fmt(&xp),
        (rp - rf).norm(),
        fmt(&xf),
        PASSES_AGREEMENT_FRACTION
    ))))
}

/// CRLB standard deviations at epoch `j` from every epoch up to it, state
/// order (NaN for the scalar system's known position).
pub fn crlb_at(cfg: &GradiometerConfig, sim: &[SimEpoch], j: usize) -> Result<[f64; 6]> {
    let g = cfg.geometry()?;
    let sigma = cfg.sensor_sigma_nt();
    Ok(match cfg.system.gradiometer {
        Gradiometer::Tensor => {
            let b = tensor_pass_crlb(&sim[..=j], &g, sigma)?;
            std::array::from_fn(|k| b[(k, k)].sqrt())
        }
        Gradiometer::Scalar => {
            let b = scalar_pass_crlb(&sim[..=j], &g, sigma)?;
            std::array::from_fn(|k| {
                if k < 3 {
                    f64::NAN
                } else {
                    b[(k - 3, k - 3)].sqrt()
                }
            })
        }
    })
}

/// A slice through the source of the iteration counts (NaN = no convergence).
pub fn slice_heatmap(
    case: &ConvergenceCase,
    map: &ConvergenceMap,
    axis: usize,
    value: f64,
    tag: &str,
) -> Heatmap {
    let coords: Vec<f64> = (0..case.grid_n).map(|i| case.start(i, 0, 0).x).collect();
    let k = (0..case.grid_n)
        .min_by(|&a, &b| {
            (coords[a] - value)
                .abs()
                .total_cmp(&(coords[b] - value).abs())
        })
        .unwrap_or(0);
    let values = map
        .slice(axis, k)
        .into_iter()
        .map(|v| v.map_or(f64::NAN, f64::from))
        .collect();
    let (name, xl, yl) = if axis == 1 {
        ("y", "x start (m)", "z start (m)")
    } else {
        ("z", "x start (m)", "y start (m)")
    };
    let mut h = Heatmap::new(
        format!("IEKF iterations ({tag}), slice {name} = {:.2} m", coords[k]),
        xl,
        yl,
        coords.clone(),
        coords,
        values,
        "iterations",
    );
    h.equal_aspect = true;
    h
}

/// The plain and multi-start maps of the seed's fig. 2 case on a `grid³`
/// grid, with their run times (s; for the record, not a result).
pub fn both_maps(
    case: &ConvergenceCase,
    threads: usize,
) -> Result<Vec<(&'static str, ConvergenceMap, f64)>> {
    [
        (Initialisation::None, "plain IEKF"),
        (Initialisation::MultiStart, "multi-start"),
    ]
    .into_iter()
    .map(|(init, tag)| {
        let t = std::time::Instant::now();
        let map = convergence_map(case, init, threads.max(1))?;
        Ok((tag, map, t.elapsed().as_secs_f64()))
    })
    .collect()
}

/// Slices z and y through the source of each map as report figures.
pub fn map_figures(
    case: &ConvergenceCase,
    maps: &[(&'static str, ConvergenceMap, f64)],
) -> Result<Vec<Block>> {
    let mut out = Vec::new();
    for (tag, map, _) in maps {
        for (axis, v) in [(2, case.position_m.z), (1, case.position_m.y)] {
            let heatmap = slice_heatmap(case, map, axis, v, tag);
            // A slice where no start converged (likely on a coarse grid) is
            // a result, not a plot: say so instead of drawing nothing.
            out.push(if heatmap.values.iter().any(|v| v.is_finite()) {
                Block::Figure {
                    svg: heatmap.to_svg()?,
                    caption: format!("{tag}: iterations per start (grey: no convergence)."),
                }
            } else {
                Block::Paragraph(format!(
                    "{}: no start of this slice converged (nothing to draw).",
                    heatmap.title
                ))
            });
        }
    }
    Ok(out)
}
