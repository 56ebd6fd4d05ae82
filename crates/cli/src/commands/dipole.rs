//! `aeromag dipole`: dipole parameters from gradiometer differences (spec
//! `gradiometry.md`, seed 004; library [`aeromag::gradiometry`]).
//!
//! - `simulate`: the `gradiometer` scenario (also `aeromag simulate gradiometer`);
//! - `locate`: the square-root IEKF over a pass read from a file;
//! - `crlb`: the Cramér–Rao bound of a configured pass;
//! - `convergence`: the seed's fig. 2 convergence map.

use crate::exit::bad_input;
use aeromag::core::parallel::MAX_THREADS;
use aeromag::gradiometry::{
    LocateSettings, STATE_NAMES, both_maps, locate_pass, map_figures, parse_name, pass_columns,
    read_config, read_pass,
};
use aeromag::report::{Report, ReportSection, Table};
use aeromag_gradiometry::convergence::ConvergenceCase;
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
/// or `f1 … f4`, nT); never the `true_` columns. Angles are in degrees
/// (an `obj_yaw` in radians reads as a turn 57 times slower, which the
/// file cannot show: the moment is then reported in a wrongly turned
/// frame), positions in metres. Geometry, noise and estimator
/// settings come from the scenario file (the one `simulate` writes) and the
/// flags. Writes EST.csv: `time, detected, x_m, y_m, z_m, mx_am2, my_am2,
/// mz_am2` (body frame), their standard deviations `sd_…`, `iterations,
/// residual_nt, converged`, the estimability measures `mu_…`
/// (μ = σ⁺/σ⁰: 0 = determined by the measurements, 1 = left at its prior)
/// and `nis`, the epoch's normalised innovation squared per contrast
/// (about 1 on average when the σ describe the errors). A mean `nis` above
/// 3 or below 0.25 is warned of: the filter is locked on a wrong solution
/// or its inputs are not what they say (swapped sensors, quiet epochs
/// that are not quiet, positions in another unit), and its estimates and
/// σ are not to be trusted; a pass of which no epoch's iterations
/// converge is a failure (exit 1). Readings whose median field is not the IGRF's
/// within a factor 2 are refused (another unit), as is, for the scalar
/// gradiometer, an object's track passing inside the sphere through the
/// sensors (positions in km?); time gaps in the pass are warned of.
/// The scalar gradiometer does not estimate the position (it is known from
/// the tracks): its `sd_x_m … mu_z` cells are empty and the summary says
/// "σ not estimated".
///
/// Example: `aeromag dipole locate --input grad/gradiometer.csv --config grad/gradiometer.toml --out est.csv`
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
#[command(mut_arg("input", |a| a.value_name("FILE").help("The pass (CSV as written by `aeromag dipole simulate`)")))]
#[command(mut_arg("file", |a| a.value_name("FILE")))]
struct LocateArgs {
    #[command(flatten)]
    input: crate::input::InputFile,
    /// Map the navigation's canonical column names onto the file's names,
    /// e.g. `time=t,yaw=heading` (time, lat, lon, alt, roll, pitch, yaw;
    /// the pass's other columns keep the names above).
    #[arg(long, value_name = "MAP")]
    columns: Option<String>,
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
    /// Passes over the data (overrides the file), 1…100: 1 = the filter;
    /// more = re-linearised passes, a failure (exit 1) when they end
    /// farther from the filter's position than a tenth of its range (their
    /// noisier first pass lost the object, as on a pass that ends far from
    /// it).
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
    /// Worker threads, 1…64 (the result does not depend on it).
    #[arg(long, default_value_t = 2)]
    threads: usize,
    /// Output folder for the report.
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    match a.command {
        Sub::Simulate(s) => crate::output::simulate_gradiometer(
            s.config.as_deref(),
            s.seed,
            s.out.as_deref(),
            s.print_config,
        ),
        Sub::Locate(l) => locate(l),
        Sub::Crlb(c) => crlb(c),
        Sub::Convergence(c) => convergence(c),
    }
}

fn locate(a: LocateArgs) -> anyhow::Result<()> {
    // The scenario file is an input too (`--config X --out X` replaced it
    // with the estimates).
    let inputs: Vec<&Path> = std::iter::once(a.input.path())
        .chain(a.config.as_deref())
        .collect();
    crate::output::check_files([a.out.as_path()], &inputs)?;
    crate::output::check_tables([a.out.as_path()])?;
    let mut cfg = read_config(a.config.as_deref())?;
    let settings = LocateSettings {
        gradiometer: a
            .gradiometer
            .as_deref()
            .map(|g| parse_name("--gradiometer", g, "tensor or scalar"))
            .transpose()?,
        layout: a
            .layout
            .as_deref()
            .map(|l| parse_name("--layout", l, "tetrahedron, cross or planar"))
            .transpose()?,
        baseline_m: a.baseline_m,
        noise_nt: a.noise_nt,
        passes: a.passes,
        multistart: match (a.multistart, a.plain) {
            (true, _) => Some(true),
            (_, true) => Some(false),
            _ => None,
        },
    };
    settings.apply(&mut cfg)?;
    let table = crate::input::load_only(
        a.input.path(),
        pass_columns(cfg.system.gradiometer),
        a.columns.as_deref(),
    )?;
    let pass = read_pass(&table, &cfg)?;
    for n in &pass.notes {
        eprintln!("{n}");
    }
    let track = locate_pass(&cfg, &pass.epochs, &pass.positions_m)?;
    let time: Vec<f64> = pass.epochs.iter().map(|e| e.t_s).collect();
    aeromag::io::write_table(&track.to_table(&time)?, &a.out)?;
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
            let sigma = if sd[..3].iter().all(|v| v.is_finite()) {
                format!("σ {:.3e} {:.3e} {:.3e}", sd[0], sd[1], sd[2])
            } else {
                "σ not estimated (known from the tracks)".to_string()
            };
            println!(
                "final position (m)    {:9.3} {:9.3} {:9.3}  {sigma}",
                x[0], x[1], x[2]
            );
            println!(
                "final moment (A·m²)   {:9.2} {:9.2} {:9.2}  σ {:.3e} {:.3e} {:.3e}",
                x[3], x[4], x[5], sd[3], sd[4], sd[5]
            );
            if let Some(m) = track.mean_nis() {
                println!(
                    "mean normalised innovation squared per contrast {m:.2} (about 1 when the σ describe the errors)"
                );
            }
            if let Some(w) = track.inconsistency_warning() {
                eprintln!("warning: {w}");
            }
        }
    }
    println!("estimates written to {}", a.out.display());
    Ok(())
}

fn crlb(a: CrlbArgs) -> anyhow::Result<()> {
    let cfg = read_config(a.config.as_deref())?;
    let report = aeromag::gradiometry::crlb(&cfg)?;
    const NAMES: [&str; 6] = STATE_NAMES;
    let rows = [
        ("closest_approach", &report.closest_approach),
        ("end", &report.end),
    ];
    if a.json {
        let v = report.to_json();
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
    for (tag, at) in &rows {
        println!(
            "{tag:<18} {:>6} {:>9.2} {}",
            at.epoch,
            at.range_m,
            at.std.map(|v| format!("{v:>12.4e}")).join("")
        );
    }
    Ok(())
}

fn convergence(a: ConvergenceArgs) -> anyhow::Result<()> {
    if !(2..=200).contains(&a.grid) {
        return Err(bad_input!("--grid {} must be in 2…200", a.grid));
    }
    if !(1..=MAX_THREADS).contains(&a.threads) {
        return Err(bad_input!(
            "--threads {} must be in 1…{MAX_THREADS}",
            a.threads
        ));
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
