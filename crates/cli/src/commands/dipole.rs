//! `aeromag dipole`: dipole parameters from gradiometer differences (spec
//! `gradiometry.md`, seed 004; library `aeromag_gradiometry`).
//!
//! - `simulate`: the `gradiometer` scenario (also `aeromag simulate gradiometer`);
//! - `locate`: the square-root IEKF over a pass read from a file;
//! - `crlb`: the Cramér–Rao bound of a configured pass;
//! - `convergence`: the seed's fig. 2 convergence map.

use crate::exit::bad_input;
use crate::report_section::{Block, ReportSection};
use aeromag_core::field::igrf::IgrfModel;
use aeromag_core::frames::Attitude;
use aeromag_core::frames::geodetic::Geodetic;
use aeromag_gradiometry::config::GradiometerConfig;
use aeromag_gradiometry::convergence::{
    ConvergenceCase, ConvergenceMap, Initialisation, convergence_map,
};
use aeromag_gradiometry::efficiency::{
    Efficiency, efficient_locate, monte_carlo, scalar_pass_crlb, tensor_pass_crlb, well_posed,
};
use aeromag_gradiometry::forward::Background;
use aeromag_gradiometry::geometry::Layout;
use aeromag_gradiometry::locate::{Located, locate_scalar, locate_tensor};
use aeromag_gradiometry::motion::{Motion, NavFix};
use aeromag_gradiometry::sim::{
    Gradiometer, SimEpoch, SystemMotion, scalar_epochs, simulate, tensor_epochs,
};
use aeromag_io::{FlightTable, IoError};
use aeromag_report::{Heatmap, LinePlot, Report, Series, Table};
use nalgebra::{SVector, Vector3};
use serde_json::json;
use std::path::{Path, PathBuf};

/// Magnetic dipole (object) parameters from tensor or scalar gradiometer
/// differences with a square-root iterated EKF (seed 004).
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    command: Sub,
}

#[derive(Debug, clap::Subcommand)]
enum Sub {
    Simulate(SimulateArgs),
    Locate(LocateArgs),
    Crlb(CrlbArgs),
    Convergence(ConvergenceArgs),
}

/// Simulate the `gradiometer` scenario: a stationary gradiometer with an
/// object driving past, or a mobile gradiometer passing a fixed object;
/// tensor (four fluxgates) or scalar (four scalar sensors) gradiometer in a
/// tetrahedron, cross or planar layout; sensor noise and bias, natural
/// variations common to all sensors, the IGRF field and gradient, an object
/// with permanent and induced moment. Writes DIR/gradiometer.csv (one row
/// per epoch: `time`; system `lat, lon, alt`, `north_m, east_m, down_m`,
/// `roll, pitch, yaw` (deg); the object's known track `obj_north_m,
/// obj_east_m, obj_down_m, obj_yaw` (deg); readings `b1_x … b4_z` (tensor,
/// nT, body frame) or `f1 … f4` (scalar, nT); truth `true_x_m, true_y_m,
/// true_z_m` (object relative to the gradiometer centre, body frame) and
/// `true_mx_am2, true_my_am2, true_mz_am2`) and DIR/gradiometer.toml (the
/// scenario, every default filled in).
///
/// Examples:
///   aeromag dipole simulate --out grad/
///   aeromag dipole simulate --print-config > my.toml
///   aeromag dipole simulate --config my.toml --seed 3 --out grad2/
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct SimulateArgs {
    /// Scenario file (TOML); fields not given take the defaults.
    #[arg(long, value_name = "FILE.toml")]
    pub config: Option<PathBuf>,
    /// Random seed (overrides the scenario file's seed).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Output folder (created if needed).
    #[arg(long, value_name = "DIR", required_unless_present = "print_config")]
    pub out: Option<PathBuf>,
    /// Print the default scenario (TOML) and exit.
    #[arg(long)]
    pub print_config: bool,
}

/// Locate the object over a pass with the square-root IEKF: detection,
/// multi-start (or the seed's plain IEKF), filter (or re-linearised passes),
/// per epoch. Reads the system's navigation (`time, lat, lon, alt,
/// north_m, east_m, down_m, roll, pitch, yaw`), the object's track
/// (`obj_north_m, obj_east_m, obj_down_m, obj_yaw`: its motion, and for the
/// scalar gradiometer its known position) and the readings (`b1_x … b4_z`
/// or `f1 … f4`); never the `true_` columns. Geometry, noise and estimator
/// settings come from the scenario file (the one `simulate` writes) and the
/// flags. Writes EST.csv: `time, detected, x_m, y_m, z_m, mx_am2, my_am2,
/// mz_am2` (body frame), their standard deviations `sd_…`, `iterations,
/// residual_nt, converged` and the estimability measures `mu_…`.
///
/// Example: `aeromag dipole locate --input grad/gradiometer.csv --config grad/gradiometer.toml --out est.csv`
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
struct LocateArgs {
    /// The pass (CSV as written by `aeromag dipole simulate`).
    #[arg(long, short = 'i', value_name = "FILE")]
    input: PathBuf,
    /// Scenario file (TOML): geometry, noise, estimator settings.
    #[arg(long, value_name = "FILE.toml")]
    config: Option<PathBuf>,
    /// Gradiometer (overrides the file): tensor or scalar.
    #[arg(long)]
    gradiometer: Option<String>,
    /// Layout (overrides the file): tetrahedron, cross, planar.
    #[arg(long)]
    layout: Option<String>,
    /// Baseline, m (overrides the file).
    #[arg(long)]
    baseline_m: Option<f64>,
    /// Sensor noise σ, nT (overrides the file).
    #[arg(long)]
    noise_nt: Option<f64>,
    /// Passes over the data (overrides the file; 1 = filter).
    #[arg(long)]
    passes: Option<usize>,
    /// Multi-start initialisation (the default of the scenario file).
    #[arg(long, conflicts_with = "plain")]
    multistart: bool,
    /// The seed's plain IEKF from `estimator.initial_position_m` instead.
    #[arg(long)]
    plain: bool,
    /// Output CSV of the per-epoch estimates.
    #[arg(long, value_name = "EST.csv")]
    out: PathBuf,
}

/// Cramér–Rao bound (standard deviation of each parameter) of the configured
/// pass: geometry, sensor noise, trajectory and object of the scenario file,
/// the known motion, white contrasts; at the closest approach and at the
/// end of the pass, from every epoch up to it.
///
/// Example: `aeromag dipole crlb --config grad/gradiometer.toml --json`
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
struct CrlbArgs {
    /// Scenario file (TOML); absent = the defaults.
    #[arg(long, value_name = "FILE.toml")]
    config: Option<PathBuf>,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
}

/// Convergence map of the IEKF from a grid of starting positions: the seed's
/// fig. 2 case (tensor gradiometer, tetrahedron of 1 m baseline, dipole of
/// 100 A·m² at (5, 0, 0.306) m, 1 nT noise, zero initial moment, starts on an
/// n³ grid over [−20, 20]³ m). Runs the plain IEKF (converges from about the
/// half-space facing the source) and the multi-start initialisation
/// (converges from every start), prints the fractions, and writes slices of
/// the iteration counts as heatmaps to DIR/index.html.
///
/// Example: `aeromag dipole convergence --grid 40 --out conv/`
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
struct ConvergenceArgs {
    /// Starts per axis (n³ in all).
    #[arg(long, default_value_t = 40)]
    grid: usize,
    /// Worker threads (the result does not depend on it).
    #[arg(long, default_value_t = 2)]
    threads: usize,
    /// Output folder for the report.
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    match a.command {
        Sub::Simulate(s) => simulate_scenario(s),
        Sub::Locate(l) => locate(l),
        Sub::Crlb(c) => crlb(c),
        Sub::Convergence(c) => convergence(c),
    }
}

/// Read and validate a scenario file (absent = defaults); errors are bad input.
fn read_config(path: Option<&Path>) -> anyhow::Result<GradiometerConfig> {
    match path {
        None => Ok(GradiometerConfig::default()),
        Some(p) => {
            let text = std::fs::read_to_string(p)
                .map_err(|e| bad_input!("cannot read scenario file '{}': {e}", p.display()))?;
            GradiometerConfig::from_toml(&text).map_err(|e| bad_input!("'{}': {e}", p.display()))
        }
    }
}

const TRUTH: [&str; 6] = [
    "true_x_m",
    "true_y_m",
    "true_z_m",
    "true_mx_am2",
    "true_my_am2",
    "true_mz_am2",
];

/// Reading columns of the four sensors.
fn sensor_columns(g: Gradiometer) -> Vec<String> {
    match g {
        Gradiometer::Tensor => (1..=4)
            .flat_map(|i| ["x", "y", "z"].map(|a| format!("b{i}_{a}")))
            .collect(),
        Gradiometer::Scalar => (1..=4).map(|i| format!("f{i}")).collect(),
    }
}

/// The simulated pass as a table (columns in [`SimulateArgs`]).
fn pass_table(cfg: &GradiometerConfig, sim: &[SimEpoch]) -> anyhow::Result<FlightTable> {
    let mut t = FlightTable::new();
    let mut add = |name: &str, f: &dyn Fn(&SimEpoch) -> f64| -> anyhow::Result<()> {
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

/// `aeromag dipole simulate` and `aeromag simulate gradiometer`.
pub fn simulate_scenario(a: SimulateArgs) -> anyhow::Result<()> {
    let mut cfg = read_config(a.config.as_deref())?;
    if a.print_config {
        print!("{}", cfg.to_toml()?);
        return Ok(());
    }
    if let Some(s) = a.seed {
        cfg.seed = s;
        cfg.validate().map_err(|e| bad_input!("--seed: {e}"))?;
    }
    let out = a.out.ok_or_else(|| bad_input!("--out DIR is required"))?;
    let sim = simulate(&cfg.scenario()?)?;
    let table = pass_table(&cfg, &sim)?;
    std::fs::create_dir_all(&out)?;
    let csv = out.join("gradiometer.csv");
    let toml = out.join("gradiometer.toml");
    aeromag_io::write_csv(&table, &csv)?;
    std::fs::write(&toml, cfg.to_toml()?)?;
    println!(
        "simulated gradiometer ({:?} system, {:?} gradiometer, {:?} {} m; seed {}): {} epochs × {} columns",
        cfg.system.motion,
        cfg.system.gradiometer,
        cfg.system.layout,
        cfg.system.baseline_m,
        cfg.seed,
        table.n_rows(),
        table.columns().len()
    );
    println!("  data      {}", csv.display());
    println!("  scenario  {}", toml.display());
    Ok(())
}

/// A required numeric column without missing values (bad input otherwise,
/// naming file, row, line and column).
fn column<'a>(t: &'a FlightTable, name: &str) -> anyhow::Result<&'a [f64]> {
    // Columns outside the canonical set are read as text when a cell is not
    // a number: name the first such cell.
    if let Some(text) = t.text_column(name)
        && let Some(row) = text.iter().position(|c| c.trim().parse::<f64>().is_err())
    {
        return Err(bad_input!(
            "'{}': column '{name}' at data row {}{}: '{}' is not a number",
            t.file_label(),
            row + 1,
            t.line_of_row(row)
                .map_or(String::new(), |l| format!(" (line {l})")),
            text[row]
        ));
    }
    let v = t.require(name)?;
    if let Some(row) = v.iter().position(|x| !x.is_finite()) {
        return Err(IoError::MissingValue {
            file: t.file_label(),
            column: name.to_string(),
            row,
            line: t.line_of_row(row),
        }
        .into());
    }
    Ok(v)
}

/// The filter input of a measured pass: readings, IGRF background at the
/// navigated position and attitude, motion from consecutive fixes. The
/// truth fields of the returned epochs are NaN (never read).
fn epochs_from_table(
    t: &FlightTable,
    cfg: &GradiometerConfig,
) -> anyhow::Result<(Vec<SimEpoch>, Vec<Vector3<f64>>)> {
    let col = |n: &str| column(t, n);
    let time = col("time")?;
    let (lat, lon, alt) = (col("lat")?, col("lon")?, col("alt")?);
    let sys = [col("north_m")?, col("east_m")?, col("down_m")?];
    let att = [col("roll")?, col("pitch")?, col("yaw")?];
    let obj = [col("obj_north_m")?, col("obj_east_m")?, col("obj_down_m")?];
    let obj_yaw = col("obj_yaw")?;
    let names = sensor_columns(cfg.system.gradiometer);
    let readings = names
        .iter()
        .map(|n| col(n))
        .collect::<anyhow::Result<Vec<_>>>()?;
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
        epochs.push(SimEpoch {
            t_s: time[j],
            vector_nt,
            scalar_nt,
            true_position_m: Vector3::repeat(f64::NAN),
            true_moment_am2: Vector3::repeat(f64::NAN),
            background: Background::from_igrf(&igrf, &geo, &f.system_attitude),
            motion,
            system_position_ned_m: f.system_position_ned_m,
            system_geodetic: geo,
            system_attitude: f.system_attitude,
            object_position_ned_m: f.object_position_ned_m,
            object_yaw_rad: f.object_yaw_rad,
        });
    }
    Ok((epochs, positions))
}

/// Per-epoch estimates as rows of 6 values (state order `x, y, z, mx, my,
/// mz`; NaN where not estimated) and the flags.
struct Track {
    x: Vec<[f64; 6]>,
    sd: Vec<[f64; 6]>,
    mu: Vec<[f64; 6]>,
    detected: Vec<bool>,
    iterations: Vec<f64>,
    residual_nt: Vec<f64>,
    converged: Vec<bool>,
}

impl Track {
    fn from_tensor(out: &[Option<Located<6>>]) -> Self {
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
        }
    }

    /// Scalar system: the known position, σ and μ of the position NaN.
    fn from_scalar(out: &[Located<3>], positions: &[Vector3<f64>]) -> Self {
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
        }
    }

    fn to_table(&self, time: &[f64]) -> anyhow::Result<FlightTable> {
        let mut t = FlightTable::new();
        t.add_column("time", time.to_vec())?;
        let flag = |v: &[bool]| v.iter().map(|&b| f64::from(u8::from(b))).collect();
        t.add_column("detected", flag(&self.detected))?;
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
        t.add_column("converged", flag(&self.converged))?;
        Ok(t)
    }
}

/// Run the configured estimator on a pass.
fn estimate(
    cfg: &GradiometerConfig,
    epochs: &[SimEpoch],
    positions: &[Vector3<f64>],
) -> anyhow::Result<Track> {
    let geometry = cfg.geometry()?;
    let lc = cfg.locate_config(None).map_err(|e| bad_input!("{e}"))?;
    Ok(match cfg.system.gradiometer {
        Gradiometer::Tensor => {
            let input = tensor_epochs(epochs, &geometry, &cfg.processing());
            Track::from_tensor(&locate_tensor(&input, &lc)?)
        }
        Gradiometer::Scalar => {
            let input = scalar_epochs(epochs, &geometry, positions, &cfg.processing())?;
            Track::from_scalar(&locate_scalar(&input, &lc)?, positions)
        }
    })
}

fn locate(a: LocateArgs) -> anyhow::Result<()> {
    let mut cfg = read_config(a.config.as_deref())?;
    let parse = |flag: &str, v: &str| -> anyhow::Result<toml::Value> {
        toml::Value::try_from(v).map_err(|e| bad_input!("{flag} {v}: {e}"))
    };
    if let Some(g) = &a.gradiometer {
        cfg.system.gradiometer = parse("--gradiometer", g)?
            .try_into()
            .map_err(|_| bad_input!("--gradiometer {g}: expected tensor or scalar"))?;
    }
    if let Some(l) = &a.layout {
        cfg.system.layout = parse("--layout", l)?
            .try_into()
            .map_err(|_| bad_input!("--layout {l}: expected tetrahedron, cross or planar"))?;
    }
    if let Some(b) = a.baseline_m {
        cfg.system.baseline_m = b;
    }
    if let Some(s) = a.noise_nt {
        match cfg.system.gradiometer {
            Gradiometer::Tensor => cfg.sensors.vector.noise_nt = s,
            Gradiometer::Scalar => cfg.sensors.scalar.noise_nt = s,
        }
    }
    if let Some(p) = a.passes {
        cfg.estimator.passes = p;
    }
    if a.multistart {
        cfg.estimator.multistart = true;
    }
    if a.plain {
        cfg.estimator.multistart = false;
    }
    cfg.validate()
        .map_err(|e| bad_input!("settings (scenario file and flags): {e}"))?;
    let table = crate::input::load(&a.input, None)?;
    if table.n_rows() <= cfg.estimator.quiet_epochs {
        return Err(bad_input!(
            "'{}' has {} rows, not more than estimator.quiet_epochs = {}",
            a.input.display(),
            table.n_rows(),
            cfg.estimator.quiet_epochs
        ));
    }
    let (epochs, positions) = epochs_from_table(&table, &cfg)?;
    let track = estimate(&cfg, &epochs, &positions)?;
    let time: Vec<f64> = epochs.iter().map(|e| e.t_s).collect();
    aeromag_io::write_csv(&track.to_table(&time)?, &a.out)?;
    let n = track.x.len();
    match track.detected.iter().position(|&d| d) {
        None => println!("object not detected in {n} epochs"),
        Some(j0) => {
            let (x, sd) = (track.x[n - 1], track.sd[n - 1]);
            println!(
                "{:?} gradiometer: estimates from epoch {j0} (t = {:.2} s) of {n}; {} of them converged",
                cfg.system.gradiometer,
                time[j0],
                track.converged.iter().filter(|&&c| c).count()
            );
            println!(
                "final position (m)    {:9.3} {:9.3} {:9.3}  σ {:.3e} {:.3e} {:.3e}",
                x[0], x[1], x[2], sd[0], sd[1], sd[2]
            );
            println!(
                "final moment (A·m²)   {:9.2} {:9.2} {:9.2}  σ {:.3e} {:.3e} {:.3e}",
                x[3], x[4], x[5], sd[3], sd[4], sd[5]
            );
        }
    }
    println!("estimates written to {}", a.out.display());
    Ok(())
}

/// CRLB standard deviations at one epoch, state order (NaN for the scalar
/// system's known position).
fn crlb_at(cfg: &GradiometerConfig, sim: &[SimEpoch], j: usize) -> anyhow::Result<[f64; 6]> {
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

fn crlb(a: CrlbArgs) -> anyhow::Result<()> {
    let cfg = read_config(a.config.as_deref())?;
    let sim = simulate(&cfg.scenario()?)?;
    let closest = (0..sim.len())
        .min_by(|&i, &j| {
            sim[i]
                .true_position_m
                .norm()
                .total_cmp(&sim[j].true_position_m.norm())
        })
        .unwrap_or(0);
    let last = sim.len() - 1;
    const NAMES: [&str; 6] = ["x_m", "y_m", "z_m", "mx_am2", "my_am2", "mz_am2"];
    let mut rows = Vec::new();
    for (tag, j) in [("closest_approach", closest), ("end", last)] {
        rows.push((tag, j, crlb_at(&cfg, &sim, j)?));
    }
    if a.json {
        let entry = |(_, j, sd): &(&str, usize, [f64; 6])| {
            let std: serde_json::Map<String, serde_json::Value> = NAMES
                .iter()
                .zip(sd)
                .filter(|(_, v)| v.is_finite())
                .map(|(n, v)| (n.to_string(), json!(v)))
                .collect();
            json!({ "epoch": j, "time_s": sim[*j].t_s, "range_m": sim[*j].true_position_m.norm(), "std": std })
        };
        let v = json!({
            "gradiometer": cfg.system.gradiometer,
            "system": cfg.system.motion,
            "sigma_nt": cfg.sensor_sigma_nt(),
            "closest_approach": entry(&rows[0]),
            "end": entry(&rows[1]),
        });
        println!("{}", serde_json::to_string_pretty(&v)?);
        return Ok(());
    }
    println!(
        "Cramér–Rao bound ({:?} gradiometer, {:?} system, σ = {} nT), standard deviations from every epoch up to:",
        cfg.system.gradiometer,
        cfg.system.motion,
        cfg.sensor_sigma_nt()
    );
    println!(
        "{:<18} {:>6} {:>9} {}",
        "",
        "epoch",
        "range m",
        NAMES.map(|n| format!("{n:>12}")).join("")
    );
    for (tag, j, sd) in &rows {
        println!(
            "{tag:<18} {j:>6} {:>9.2} {}",
            sim[*j].true_position_m.norm(),
            sd.map(|v| format!("{v:>12.4e}")).join("")
        );
    }
    Ok(())
}

/// A slice through the source of the iteration counts (NaN = no convergence).
fn slice_heatmap(
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
/// grid, with their run times (s).
fn both_maps(
    case: &ConvergenceCase,
    threads: usize,
) -> anyhow::Result<Vec<(&'static str, ConvergenceMap, f64)>> {
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
fn map_figures(
    case: &ConvergenceCase,
    maps: &[(&'static str, ConvergenceMap, f64)],
) -> anyhow::Result<Vec<Block>> {
    let mut out = Vec::new();
    for (tag, map, _) in maps {
        for (axis, v) in [(2, case.position_m.z), (1, case.position_m.y)] {
            out.push(Block::Figure {
                svg: slice_heatmap(case, map, axis, v, tag).to_svg()?,
                caption: format!("{tag}: iterations per start (grey: no convergence)."),
            });
        }
    }
    Ok(out)
}

fn convergence(a: ConvergenceArgs) -> anyhow::Result<()> {
    if !(2..=200).contains(&a.grid) {
        return Err(bad_input!("--grid {} must be in 2…200", a.grid));
    }
    let case = ConvergenceCase::seed_fig2(a.grid);
    let toward = case.position_m.normalize();
    let mut r = Report::new("aeromag — IEKF convergence map (seed 004, fig. 2 case)");
    r.section("Convergence map").paragraph(format!(
        "Tensor gradiometer, dipole at ({:.2}, {:.2}, {:.3}) m, {} starts on a {}³ grid over [−20, 20]³ m. \
         Grey cells: the IEKF did not reach the source.",
        case.position_m.x,
        case.position_m.y,
        case.position_m.z,
        a.grid.pow(3),
        a.grid
    ));
    let maps = both_maps(&case, a.threads)?;
    let mut rows = Vec::new();
    for (tag, map, secs) in &maps {
        let near = map.fraction_where(&case, |s| s.dot(&toward) > 1.0);
        let far = map.fraction_where(&case, |s| s.dot(&toward) < -1.0);
        println!(
            "{tag:<12} converged from {:6.2} % of {} starts (facing the source {:6.2} %, opposite {:6.2} %) in {secs:.2} s",
            100.0 * map.converged_fraction(),
            map.outcomes.len(),
            100.0 * near,
            100.0 * far
        );
        rows.push(vec![
            tag.to_string(),
            format!("{:.2}", 100.0 * map.converged_fraction()),
            format!("{:.2}", 100.0 * near),
            format!("{:.2}", 100.0 * far),
        ]);
    }
    let mut sec = ReportSection::new("Convergence map slices");
    sec.blocks = map_figures(&case, &maps)?;
    sec.append_to(&mut r);
    r.table(Table::new(
        [
            "initialisation",
            "converged (%)",
            "facing the source (%)",
            "opposite (%)",
        ]
        .map(String::from)
        .to_vec(),
        rows,
        "Converged fraction of the starts.",
    ));
    let path = a.out.join("index.html");
    r.write_html(&path)?;
    println!("report written to {}", path.display());
    Ok(())
}

/// Worst block efficiency (position and moment) of a set of runs.
fn worst(runs: &[(String, Efficiency)]) -> f64 {
    runs.iter()
        .flat_map(|(_, e)| e.position.into_iter().chain([e.moment]))
        .fold(0.0, f64::max)
}

fn fmt3(v: Option<f64>) -> String {
    v.map_or("–".into(), |x| format!("{x:.3}"))
}

/// Estimation errors with their ±2σ bands and `MeasureS` over the default
/// pass (tensor, stationary system, realistic: biases, variations, yawing
/// object), from 1 s after the detection on; plots with captions.
fn pass_plots() -> anyhow::Result<Vec<(LinePlot, String)>> {
    let cfg = GradiometerConfig::default();
    let sim = simulate(&cfg.scenario()?)?;
    let pos: Vec<Vector3<f64>> = sim.iter().map(|e| e.true_position_m).collect();
    let track = estimate(&cfg, &sim, &pos)?;
    let from = track.detected.iter().position(|&d| d).map_or(0, |j| j + 10);
    let t: Vec<f64> = sim[from..].iter().map(|e| e.t_s).collect();
    let mut out = Vec::new();
    for (block, unit, title) in [(0, "m", "Position"), (3, "A·m²", "Moment")] {
        let mut p = LinePlot::new(
            format!("{title} error and ±2σ band (body frame)"),
            "time (s)",
            format!("estimate − truth ({unit})"),
        );
        for k in 0..3 {
            let c = aeromag_report::PALETTE[k % aeromag_report::PALETTE.len()];
            let axis = ["x", "y", "z"][k];
            let err: Vec<f64> = (from..sim.len())
                .map(|j| {
                    let truth = if block == 0 {
                        sim[j].true_position_m[k]
                    } else {
                        sim[j].true_moment_am2[k]
                    };
                    track.x[j][block + k] - truth
                })
                .collect();
            let band = |s: f64| -> Vec<f64> {
                track.sd[from..]
                    .iter()
                    .map(|sd| s * 2.0 * sd[block + k])
                    .collect()
            };
            p = p
                .with_series(Series::points(format!("{axis} error"), t.clone(), err).with_color(c))
                .with_series(
                    Series::line(format!("{axis} ±2σ"), t.clone(), band(1.0)).with_color(c),
                )
                .with_series(Series::line("", t.clone(), band(-1.0)).with_color(c));
        }
        out.push((
            p,
            format!(
                "{title} over the default pass (object 6 m east, 2 m below, closest at 30 s): error of \
                 the estimate against the truth (dots) inside the filter's ±2σ band (lines)."
            ),
        ));
    }
    let mut mu = LinePlot::new(
        "Estimability MeasureS over the pass",
        "time (s)",
        "μ = 1 − σ⁺/σ⁰",
    );
    for (k, n) in ["x", "y", "z", "Mx", "My", "Mz"].iter().enumerate() {
        mu = mu.with_series(Series::line(
            *n,
            t.clone(),
            track.mu[from..].iter().map(|m| m[k]).collect(),
        ));
    }
    out.push((
        mu,
        "Estimability of each component (0: nothing learnt from the measurements, 1: determined by them)."
            .into(),
    ));
    Ok(out)
}

fn pass_figures() -> anyhow::Result<Vec<Block>> {
    pass_plots()?
        .into_iter()
        .map(|(p, caption)| {
            Ok(Block::Figure {
                svg: p.to_svg()?,
                caption,
            })
        })
        .collect()
}

/// The gradiometry study for `aeromag demo`: the `gradiometry.*` summary
/// object (`efficiency_tensor`: the worst RMS/CRLB of position and moment
/// over the stationary and mobile tensor systems; `efficiency_scalar`: the
/// worst of the moment over both scalar systems; `convergence_fraction`:
/// multi-start share of the seed's fig. 2 starts that converge) and the
/// report section (efficiency table, estimates ± 2σ and `MeasureS` over the
/// default pass, convergence-map slices). `quick`: 12 instead of 40
/// Monte-Carlo trials per case and a 10³ instead of 16³ map.
pub fn demo_gradiometry(quick: bool) -> anyhow::Result<(serde_json::Value, Option<ReportSection>)> {
    let (trials, grid) = if quick { (12, 10) } else { (40, 16) };
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get().min(4));
    let mut tensor = Vec::new();
    let mut scalar = Vec::new();
    for motion in [SystemMotion::Stationary, SystemMotion::Mobile] {
        let s = well_posed(motion, Layout::Tetrahedron)?;
        let name = format!("{motion:?}").to_lowercase();
        let lt = efficient_locate(s.vector_sensor.noise_nt)?;
        tensor.push((
            name.clone(),
            monte_carlo(&s, Gradiometer::Tensor, &lt, trials, 1000, threads)?,
        ));
        let ls = efficient_locate(s.scalar_sensor.noise_nt)?;
        scalar.push((
            name,
            monte_carlo(&s, Gradiometer::Scalar, &ls, trials, 2000, threads)?,
        ));
    }
    let case = ConvergenceCase::seed_fig2(grid);
    let maps = both_maps(&case, threads)?;
    let fraction = maps
        .iter()
        .find(|(tag, _, _)| *tag == "multi-start")
        .map_or(f64::NAN, |(_, m, _)| m.converged_fraction());
    let plain = maps
        .iter()
        .find(|(tag, _, _)| *tag == "plain IEKF")
        .map_or(f64::NAN, |(_, m, _)| m.converged_fraction());
    let keys = json!({
        "efficiency_tensor": worst(&tensor),
        "efficiency_scalar": worst(&scalar),
        "convergence_fraction": fraction,
        "convergence_fraction_plain": plain,
        "trials": trials,
    });
    let mut sec = ReportSection::new("Dipole parameters from gradiometers (seed 004)");
    sec.blocks.push(Block::Paragraph(format!(
        "Monte-Carlo efficiency RMS/CRLB ({trials} trials per case, well-posed 20 m passes, tetrahedron of 1 m) of \
         the square-root IEKF with a windowed multi-start and re-linearised passes: worst {:.3} (tensor), {:.3} \
         (scalar); the goal is ≤ 1.2. Convergence from the seed's fig. 2 starts ({}³ grid): plain IEKF {:.1} %, \
         multi-start {:.1} %.",
        worst(&tensor),
        worst(&scalar),
        grid,
        100.0 * plain,
        100.0 * fraction
    )));
    let rows = tensor
        .iter()
        .map(|r| ("tensor", r))
        .chain(scalar.iter().map(|r| ("scalar", r)))
        .map(|(g, (m, e))| {
            vec![
                g.to_string(),
                m.clone(),
                fmt3(e.position),
                format!("{:.3}", e.moment),
                e.names
                    .iter()
                    .zip(&e.per_parameter)
                    .map(|(n, v)| format!("{n} {v:.2}"))
                    .collect::<Vec<_>>()
                    .join(", "),
            ]
        })
        .collect();
    sec.blocks.push(Block::Table(Table::new(
        [
            "gradiometer",
            "system",
            "position RMS/CRLB",
            "moment RMS/CRLB",
            "per parameter",
        ]
        .map(String::from)
        .to_vec(),
        rows,
        "Efficiency at the end of the pass (1 = efficient).",
    )));
    sec.blocks.extend(pass_figures()?);
    sec.blocks.extend(map_figures(&case, &maps)?);
    Ok((keys, Some(sec)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn demo_keys_meet_the_issue_figures() {
        let t = std::time::Instant::now();
        let (keys, sec) = demo_gradiometry(false).unwrap();
        let secs = t.elapsed().as_secs_f64();
        eprintln!("demo_gradiometry(false): {keys} in {secs:.2} s");
        let v = |k: &str| keys[k].as_f64().unwrap_or_else(|| panic!("missing {k}"));
        assert!(
            v("efficiency_tensor") <= 1.2 && v("efficiency_scalar") <= 1.2,
            "{keys}"
        );
        assert_eq!(v("convergence_fraction"), 1.0);
        assert!(v("convergence_fraction_plain") < 0.9);
        let sec = sec.unwrap();
        let figures = sec
            .blocks
            .iter()
            .filter(|b| matches!(b, Block::Figure { .. }))
            .count();
        assert_eq!(figures, 3 + 4, "pass figures and map slices");
    }
}
