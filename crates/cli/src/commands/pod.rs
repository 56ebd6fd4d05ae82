//! `aeromag pod`: towed magnetometer pod under a helicopter (spec
//! `helicopter.md` part B, seed `002_…`; library [`aeromag::pod`]).

use crate::args;
use crate::input::InputArgs;
use crate::progress::Bars;
use aeromag::ModelFile;
use aeromag::pod::{HeadingRate, PodMethod, PodModelFile, PodSetup, apply_pod, fit_pod};
use aeromag::{Compensated, Compensator};
use std::path::PathBuf;

/// Towed magnetometer pod: small-signal model (seed 002) and equivalent
/// dipole array, fitted on learning headings and applied to other flights.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    command: Sub,
}

#[derive(Debug, clap::Subcommand)]
enum Sub {
    Fit(FitArgs),
    Apply(ApplyArgs),
}

/// Fit the pod interference model on a learning flight.
///
/// Needs `time` (s), `mag` (nT, the pod's scalar reading), `roll`, `pitch`,
/// `yaw` (deg, the helicopter's attitude), `cable_inclination` (deg below
/// the horizontal) and `cable_azimuth` (deg from magnetic north), and
/// `line` (one label per straight heading; without it headings are split
/// at time gaps only); `lat` and `alt` when a gradient is given. Columns
/// named `true_…` are never read.
///
/// Example (the seed's scenario):
///   aeromag simulate pod --out pod/
///   aeromag pod fit --input pod/pod.csv --model pod.json --method dipole-array \
///       --cable-length-m 40 --attach-m 0,0,1.2 --inclination-deg 45 \
///       --grad-north-nt-per-km 5.91 --grad-up-nt-per-km -25.91
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct FitArgs {
    #[command(flatten)]
    input: InputArgs,
    /// Model file to write (JSON).
    #[arg(long, value_name = "POD.json")]
    model: PathBuf,
    /// Solve: two-step (seed), joint, dipole-array.
    #[arg(long, value_enum, default_value_t = PodMethod::default())]
    method: PodMethod,
    /// Cable length, m (at most 1000).
    #[arg(long)]
    cable_length_m: f64,
    /// Cable attachment point, body axes (x forward, y right, z down), m
    /// (default 0,0,0; within ±1000 m).
    #[arg(long, value_name = "A,B,C", allow_hyphen_values = true, value_parser = args::xyz)]
    attach_m: Option<[f64; 3]>,
    /// Inclination of the Earth field, deg (positive down).
    #[arg(long, allow_hyphen_values = true)]
    inclination_deg: f64,
    /// Declination of the Earth field from the yaw reference, deg (0 when
    /// yaw and cable azimuth are magnetic).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    declination_deg: f64,
    /// Known north gradient of the field, nT/km (the track term).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    grad_north_nt_per_km: f64,
    /// Known upward gradient of the field, nT/km.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    grad_up_nt_per_km: f64,
    /// Equivalent source points of the dipole array, body axes, m
    /// (default: x = −6, −2, 2 m along the fuselage, z = −1 m; 1 to 8
    /// points within 1000 m).
    #[arg(long, value_name = "X,Y,Z;X,Y,Z;…", allow_hyphen_values = true, value_parser = source_points)]
    source_points: Option<SourcePoints>,
}

/// Apply a pod model (from `aeromag pod fit`) to a flight file.
///
/// Writes every input column plus `pod_interf` (modelled interference, nT),
/// `mag_comp` (mag − pod_interf, nT) and `pod_flag` (0 compensated, 1 not:
/// a missing value in the row, or a heading shorter than 10 s). Every input
/// row is written, in order. Prints the compensation rate per heading.
///
/// Example:
///   aeromag pod apply --model pod.json --input pod2/pod.csv --out pod2_comp.csv
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct ApplyArgs {
    /// Model file written by `aeromag pod fit`.
    #[arg(long, value_name = "POD.json")]
    model: PathBuf,
    #[command(flatten)]
    input: InputArgs,
    #[arg(long, value_name = "OUT.csv", help = crate::output::TABLE_OUT_HELP)]
    out: PathBuf,
}

/// Points `X,Y,Z;X,Y,Z;…` (m).
#[derive(Debug, Clone)]
struct SourcePoints(Vec<[f64; 3]>);

fn source_points(s: &str) -> Result<SourcePoints, String> {
    s.split(';')
        .map(args::xyz)
        .collect::<Result<_, _>>()
        .map(SourcePoints)
}

fn print_rates(label: &str, r: &[HeadingRate]) {
    for h in r {
        println!(
            "  {label} heading {:6.1}° (rows {}–{}): rate {:.2} %",
            h.heading_deg,
            h.rows[0] + 1,
            h.rows[1],
            100.0 * h.rate
        );
    }
}

fn fit(a: FitArgs) -> anyhow::Result<()> {
    crate::output::check_files([a.model.as_path()], &[a.input.path()])?;
    let setup = PodSetup {
        cable_length_m: a.cable_length_m,
        attach_m: a.attach_m.unwrap_or_default(),
        inclination_deg: a.inclination_deg,
        declination_deg: a.declination_deg,
        grad_north_nt_per_km: a.grad_north_nt_per_km,
        grad_up_nt_per_km: a.grad_up_nt_per_km,
    };
    let t = a.input.load_canonical(&aeromag::pod::POD_COLUMNS)?;
    let sources = a.source_points.as_ref().map(|p| p.0.as_slice());
    let model = fit_pod(&t, &setup, a.method, sources, &mut Bars::new())?.model;
    model.write(&a.model)?;
    println!(
        "fitted the {} pod model on {} headings of {} ({} coefficients); written to {}",
        a.method.name(),
        model.learning.len(),
        t.file_label(),
        model.coefficients.len(),
        a.model.display()
    );
    print_rates("learning", &model.learning);
    Ok(())
}

fn apply(a: ApplyArgs) -> anyhow::Result<()> {
    crate::output::check_files([a.out.as_path()], &[a.input.path(), a.model.as_path()])?;
    crate::output::check_tables([a.out.as_path()])?;
    let model = PodModelFile::read(&a.model)?;
    let t = a.input.load()?;
    let applied = apply_pod(&model, &t)?;
    let out = Compensated::new(&t, model.output(), applied.interf_nt)?;
    crate::output::write_compensated(t, out, &a.out, &a.model, model.method.name())?;
    print_rates("", &applied.per_heading);
    if !applied.per_heading.is_empty() {
        println!(
            "  all headings pooled: rate {:.2} %",
            100.0 * applied.pooled
        );
    }
    Ok(())
}

pub fn run(a: Args) -> anyhow::Result<()> {
    match a.command {
        Sub::Fit(f) => fit(f),
        Sub::Apply(x) => apply(x),
    }
}
