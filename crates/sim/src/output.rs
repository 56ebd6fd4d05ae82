//! The result of a simulation: named columns, the scenario file and the
//! truth metadata, and writing them to a directory.
//!
//! Files written by [`Simulation::write_to_dir`] (stem = scenario name):
//!
//! * `<stem>.csv` — `#` comment lines (scenario, seed, units, altitude
//!   reference), then the table written by `aeromag-io`'s CSV writer: header
//!   row of column names (the canonical names of `data-formats.md` and the
//!   `true_…` truth columns, see the crate docs), values in the shortest
//!   representation that round-trips.
//! * `<stem>.toml` — the scenario with every default filled in.
//! * `<stem>.truth.json` — the truth metadata (aircraft parts and their
//!   field at each sensor, noise levels, anomaly and diurnal parameters,
//!   column list with units).

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::error::{Result, SimError};
use crate::scenario::ScenarioKind;

/// One output column.
#[derive(Debug, Clone, PartialEq)]
pub struct Column {
    /// Column name.
    pub name: String,
    /// Unit (`"nT"`, `"deg"`, `"m"`, `"m/s"`, `"s"`, `"A"`, `"-"`).
    pub unit: &'static str,
    /// What the column holds.
    pub description: String,
    /// One value per sample.
    pub values: Vec<f64>,
}

/// A finished simulation.
#[derive(Debug, Clone)]
pub struct Simulation {
    /// Which scenario produced it.
    pub kind: ScenarioKind,
    /// The seed used.
    pub seed: u64,
    /// The columns, all of the same length, in output order.
    pub columns: Vec<Column>,
    /// The scenario file with every default filled in.
    pub scenario_toml: String,
    /// Truth metadata (JSON text).
    pub truth_json: String,
}

/// Paths of the files written by [`Simulation::write_to_dir`].
#[derive(Debug, Clone, PartialEq)]
pub struct WrittenFiles {
    /// The data table.
    pub csv: PathBuf,
    /// The filled-in scenario file.
    pub scenario: PathBuf,
    /// The truth metadata.
    pub truth: PathBuf,
}

impl Simulation {
    /// Number of samples.
    pub fn n_rows(&self) -> usize {
        self.columns.first().map_or(0, |c| c.values.len())
    }

    /// The values of column `name`.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.columns
            .iter()
            .find(|c| c.name == name)
            .map(|c| c.values.as_slice())
    }

    /// The column names in order.
    pub fn column_names(&self) -> Vec<&str> {
        self.columns.iter().map(|c| c.name.as_str()).collect()
    }

    /// Every value finite: the simulator models nothing as missing, so a
    /// NaN or ∞ is an overflow of values too large for it (an area of
    /// 10³⁰⁸ m²), [`SimError::Overflow`] naming the first such column and
    /// sample.
    pub fn check_finite(&self) -> Result<()> {
        for c in &self.columns {
            if let Some(k) = c.values.iter().position(|v| !v.is_finite()) {
                let at = self
                    .column("time")
                    .map(|t| format!(" (time {} s)", t[k]))
                    .unwrap_or_default();
                return Err(SimError::Overflow {
                    column: c.name.clone(),
                    sample: k + 1,
                    value: c.values[k],
                    at,
                });
            }
        }
        Ok(())
    }

    /// The columns as an [`aeromag_io::FlightTable`] (in memory, numeric
    /// columns in output order), for processing without a file.
    pub fn to_flight_table(&self) -> Result<aeromag_io::FlightTable> {
        let mut t = aeromag_io::FlightTable::new();
        for c in &self.columns {
            t.add_column(&c.name, c.values.clone())?;
        }
        Ok(t)
    }

    /// Write the CSV text to `w`: `#` comment lines (scenario, seed, altitude
    /// reference, units), then the table by [`aeromag_io::write_csv_to`]
    /// (header row, shortest round-trip numbers).
    pub fn write_csv<W: Write>(&self, w: W) -> Result<()> {
        self.write_table_csv(&self.to_flight_table()?, w)
    }

    /// The flight as aeromag's readers would take it: `table`
    /// ([`Simulation::to_flight_table`]) passes the time and unit checks a
    /// file read back gets ([`aeromag_io::check_time`],
    /// [`aeromag_io::check_units`]; their warnings are left to the reader),
    /// else [`SimError::Unreadable`]. A scenario with values far beyond a
    /// real instrument's (`scalar.lag_s = 1e9` wrote `mag` of 5.4·10⁸ nT)
    /// is refused before anything is written.
    pub fn check_readable(table: &aeromag_io::FlightTable) -> Result<()> {
        let unreadable = |e: aeromag_io::IoError| SimError::Unreadable {
            reason: e.to_string(),
        };
        if table.column("time").is_some() {
            aeromag_io::check_time(table).map_err(unreadable)?;
        }
        aeromag_io::check_units(table).map_err(unreadable)?;
        Ok(())
    }

    /// [`Simulation::write_csv`] of the table already made of it.
    fn write_table_csv<W: Write>(&self, table: &aeromag_io::FlightTable, mut w: W) -> Result<()> {
        let werr = |e| SimError::Write {
            path: PathBuf::from("<csv stream>"),
            source: e,
        };
        writeln!(
            w,
            "# aeromag-sim {} scenario `{}`, seed {}",
            env!("CARGO_PKG_VERSION"),
            self.kind.name(),
            self.seed
        )
        .map_err(werr)?;
        writeln!(
            w,
            "# alt: WGS84 ellipsoidal height; columns prefixed true_ are simulation truth"
        )
        .map_err(werr)?;
        let units: Vec<String> = self
            .columns
            .iter()
            .map(|c| format!("{}[{}]", c.name, c.unit))
            .collect();
        writeln!(w, "# units: {}", units.join(" ")).map_err(werr)?;
        aeromag_io::write_csv_to(table, &mut w).map_err(werr)
    }

    /// The three files [`Simulation::write_to_dir`] writes for `kind`:
    /// `<stem>.csv`, `<stem>.toml` and `<stem>.truth.json`, `stem` being
    /// the scenario name (for checking them before a run).
    pub fn file_names(kind: ScenarioKind) -> [String; 3] {
        let stem = kind.name();
        [
            format!("{stem}.csv"),
            format!("{stem}.toml"),
            format!("{stem}.truth.json"),
        ]
    }

    /// Write `<stem>.csv`, `<stem>.toml` and `<stem>.truth.json` into `dir`
    /// (created if missing), `stem` being the scenario name; nothing when
    /// the readers would refuse the flight ([`Simulation::check_readable`]).
    /// The three are written as a set ([`aeromag_io::atomic::FileSet`]):
    /// all checked first, then all old or all new after an error or an
    /// interruption (the flight was renamed into place before the scenario
    /// and the truth were written).
    pub fn write_to_dir(&self, dir: &Path) -> Result<WrittenFiles> {
        let mut table = self.to_flight_table()?;
        let [csv, scenario, truth] = Self::file_names(self.kind).map(|n| dir.join(n));
        table.set_source(
            csv.file_name()
                .map_or_else(String::new, |n| n.to_string_lossy().into_owned()),
        );
        Self::check_readable(&table)?;
        std::fs::create_dir_all(dir).map_err(|e| SimError::Write {
            path: dir.to_path_buf(),
            source: e,
        })?;
        let files = WrittenFiles {
            csv,
            scenario,
            truth,
        };
        let werr = |(path, source): (PathBuf, std::io::Error)| SimError::Write { path, source };
        let mut set = aeromag_io::atomic::FileSet::new(
            [&files.csv, &files.scenario, &files.truth].map(|p| p.as_path()),
        )
        .map_err(werr)?;
        let mut failure: Option<SimError> = None;
        set.write(&files.csv, |w| {
            self.write_table_csv(&table, w).map_err(|e| {
                let io = std::io::Error::other(e.to_string());
                failure = Some(e);
                io
            })
        })
        .map_err(|e| match failure.take() {
            Some(SimError::Write { source, .. }) => SimError::Write {
                path: files.csv.clone(),
                source,
            },
            Some(other) => other,
            None => werr(e),
        })?;
        set.write(&files.scenario, |w| {
            w.write_all(self.scenario_toml.as_bytes())
        })
        .map_err(werr)?;
        set.write(&files.truth, |w| w.write_all(self.truth_json.as_bytes()))
            .map_err(werr)?;
        set.commit().map_err(werr)?;
        Ok(files)
    }
}

/// Units and descriptions of the fixed columns (current channels are added
/// per loop, extra sensors' columns per sensor: [`EXTRA_SENSOR_CATALOGUE`]). The crate docs list the same table.
pub const COLUMN_CATALOGUE: &[(&str, &str, &str)] = &[
    (
        "time",
        "s",
        "time, seconds after 00:00 UTC of the flight date",
    ),
    (
        "lat",
        "deg",
        "latitude of the navigation reference point (GNSS/INS, with errors)",
    ),
    (
        "lon",
        "deg",
        "longitude of the navigation reference point (with errors)",
    ),
    (
        "alt",
        "m",
        "WGS84 ellipsoidal height of the navigation reference point (with errors)",
    ),
    ("vn", "m/s", "velocity north (with errors)"),
    ("ve", "m/s", "velocity east (with errors)"),
    ("vd", "m/s", "velocity down (with errors)"),
    ("roll", "deg", "roll φ (INS, with errors)"),
    ("pitch", "deg", "pitch θ (INS, with errors)"),
    ("yaw", "deg", "yaw ψ in (−180, 180] (INS, with errors)"),
    ("mag", "nT", "scalar magnetometer, uncompensated"),
    ("flux_x", "nT", "fluxgate x (body axes, with sensor errors)"),
    ("flux_y", "nT", "fluxgate y"),
    ("flux_z", "nT", "fluxgate z"),
    (
        "line",
        "-",
        "line label: calibration leg 1..n, survey line/tie label, 0 in turns and transits",
    ),
    (
        "manoeuvre",
        "-",
        "manoeuvre code: 0 none, 1 roll, 2 pitch, 3 yaw",
    ),
    (
        "diurnal",
        "nT",
        "base-station record of the diurnal variation (relative to take-off, with noise)",
    ),
    (
        "igrf",
        "nT",
        "IGRF-14 total field at the recorded position and time",
    ),
    (
        "true_lat",
        "deg",
        "true latitude of the navigation reference point",
    ),
    ("true_lon", "deg", "true longitude"),
    ("true_alt", "m", "true ellipsoidal height"),
    (
        "true_sensor_alt",
        "m",
        "true ellipsoidal height of the scalar sensor",
    ),
    ("true_vn", "m/s", "true velocity north"),
    ("true_ve", "m/s", "true velocity east"),
    ("true_vd", "m/s", "true velocity down"),
    ("true_roll", "deg", "true roll"),
    ("true_pitch", "deg", "true pitch"),
    ("true_yaw", "deg", "true yaw in (−180, 180]"),
    (
        "true_external",
        "nT",
        "|B_ext| at the scalar sensor: what a perfect compensation yields",
    ),
    (
        "true_interf",
        "nT",
        "|B_ext + ΔB| − |B_ext| at the scalar sensor (exact)",
    ),
    ("true_igrf", "nT", "|B_IGRF| at the scalar sensor"),
    (
        "true_anomaly",
        "nT",
        "|B_IGRF + B_anom| − |B_IGRF| at the scalar sensor",
    ),
    (
        "true_diurnal",
        "nT",
        "|B_ext| − |B_IGRF + B_anom|: true_igrf + true_anomaly + true_diurnal = true_external",
    ),
    (
        "true_heading_error",
        "nT",
        "heading error of the scalar sensor",
    ),
    (
        "true_lag",
        "nT",
        "lag contribution y − x of the scalar sensor (≈ −τ d|B|/dt)",
    ),
    (
        "true_mag_noise",
        "nT",
        "white noise of the scalar sensor: mag = true_external + true_interf + true_heading_error + true_lag + true_mag_noise",
    ),
    (
        "true_interf_perm",
        "nT",
        "projection on B_ext/|B_ext| of the permanent parts' field at the scalar sensor",
    ),
    (
        "true_interf_induced",
        "nT",
        "projection of the induced parts' field",
    ),
    (
        "true_interf_eddy",
        "nT",
        "projection of the eddy currents' field",
    ),
    (
        "true_interf_current",
        "nT",
        "projection of the on-board currents' field",
    ),
    (
        "true_ext_x",
        "nT",
        "external field at the scalar sensor, body x",
    ),
    (
        "true_ext_y",
        "nT",
        "external field at the scalar sensor, body y",
    ),
    (
        "true_ext_z",
        "nT",
        "external field at the scalar sensor, body z",
    ),
    (
        "true_interf_x",
        "nT",
        "aircraft field ΔB at the scalar sensor, body x",
    ),
    (
        "true_interf_y",
        "nT",
        "aircraft field ΔB at the scalar sensor, body y",
    ),
    (
        "true_interf_z",
        "nT",
        "aircraft field ΔB at the scalar sensor, body z",
    ),
    (
        "true_flux_x",
        "nT",
        "true total field at the fluxgate (external + aircraft), body x, before sensor errors",
    ),
    (
        "true_flux_y",
        "nT",
        "true total field at the fluxgate, body y",
    ),
    (
        "true_flux_z",
        "nT",
        "true total field at the fluxgate, body z",
    ),
];

/// Units and descriptions of the columns of the optional extra sensors
/// (`<k>`: 2, 3, … for scalar sensors; `<j>`: b, c, … for fluxgates; `<a>`:
/// x, y, z). The crate docs list the same table.
pub const EXTRA_SENSOR_CATALOGUE: &[(&str, &str, &str)] = &[
    (
        "mag_<k>",
        "nT",
        "extra scalar magnetometer k (k = 2, 3, …), uncompensated",
    ),
    (
        "flux_<j>_<a>",
        "nT",
        "extra fluxgate j (j = b, c, …), body axis a, with its sensor errors",
    ),
    (
        "true_interf_<k>",
        "nT",
        "|B_ext + ΔB| − |B_ext| at extra scalar sensor k (exact)",
    ),
    (
        "true_external_<k>",
        "nT",
        "|B_ext| at extra scalar sensor k: what a perfect compensation of mag_<k> yields",
    ),
    (
        "true_flux_<j>_<a>",
        "nT",
        "true total field at extra fluxgate j (external + aircraft), body axis a, before sensor errors",
    ),
];

/// The sensor index `k ≥ 2` of a name `<prefix><k>`.
fn extra_scalar_index(name: &str, prefix: &str) -> Option<u32> {
    let k = name.strip_prefix(prefix)?;
    if k.is_empty() || !k.bytes().all(|b| b.is_ascii_digit()) || k.starts_with('0') {
        return None;
    }
    k.parse().ok().filter(|k| *k >= 2)
}

/// The letter `b..=z` and axis of a name `<prefix><j>_<a>`.
fn extra_fluxgate_axis(name: &str, prefix: &str) -> Option<(char, char)> {
    let rest = name.strip_prefix(prefix)?.as_bytes();
    match rest {
        [j @ b'b'..=b'z', b'_', a @ (b'x' | b'y' | b'z')] => Some((*j as char, *a as char)),
        _ => None,
    }
}

/// Unit and description of a column name (current channels and extra
/// sensors included).
pub fn describe(name: &str) -> Option<(&'static str, String)> {
    if let Some(&(_, u, d)) = COLUMN_CATALOGUE.iter().find(|(n, _, _)| *n == name) {
        return Some((u, d.to_string()));
    }
    if let Some(k) = extra_scalar_index(name, "mag_") {
        return Some((
            "nT",
            format!("extra scalar magnetometer {k}, uncompensated"),
        ));
    }
    if let Some(k) = extra_scalar_index(name, "true_interf_") {
        return Some((
            "nT",
            format!("|B_ext + ΔB| − |B_ext| at extra scalar sensor {k} (mag_{k}, exact)"),
        ));
    }
    if let Some(k) = extra_scalar_index(name, "true_external_") {
        return Some((
            "nT",
            format!(
                "|B_ext| at extra scalar sensor {k}: what a perfect compensation of mag_{k} yields"
            ),
        ));
    }
    if let Some((j, a)) = extra_fluxgate_axis(name, "flux_") {
        return Some((
            "nT",
            format!("extra fluxgate {j} {a} (body axes, with sensor errors)"),
        ));
    }
    if let Some((j, a)) = extra_fluxgate_axis(name, "true_flux_") {
        return Some((
            "nT",
            format!(
                "true total field at extra fluxgate {j} (external + aircraft), body {a}, before sensor errors"
            ),
        ));
    }
    if let Some(k) = extra_scalar_index(name, "true_interf_current_") {
        return Some((
            "nT",
            format!(
                "on-board currents' part of the interference at extra scalar sensor {k}, projected on B_ext/|B_ext|"
            ),
        ));
    }
    if let Some(loop_name) = name.strip_prefix("true_cur_") {
        return Some((
            "A",
            format!("true current of the on-board loop `{loop_name}`"),
        ));
    }
    if let Some(loop_name) = name.strip_prefix("cur_") {
        return Some((
            "A",
            format!("recorded current of the on-board loop `{loop_name}`"),
        ));
    }
    // The SGL installation's names of the stinger sensors' columns.
    let stinger = crate::scenario::installation::stinger_name(name)?;
    let (unit, what) = describe(&stinger)?;
    Some((
        unit,
        format!("{what} (SGL layout: `{stinger}` of the stinger installation)"),
    ))
}
