//! `aeromag rotor`: helicopter main-rotor interference (spec `helicopter.md`
//! part A, seed 000 ch. 3; library [`aeromag::rotor`] and
//! [`aeromag::studies::RotorStudyRun`]).

use crate::args;
use crate::input::InputArgs;
use crate::progress::Bars;
use aeromag::report::Report;
use aeromag::rotor::{RotorChoices, RotorOptions, RotorPreset, fit_rotor};
use aeromag::studies::{RotorStudyRun, Study, StudyOutcome, StudySize, pct};
use aeromag::{Compensator, ModelFile};
use std::path::PathBuf;

/// Helicopter main-rotor interference: physical blade model against filters.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    command: Sub,
}

// Parsed once per run: the variants' sizes do not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, clap::Subcommand)]
enum Sub {
    Study(StudyArgs),
    Fit(FitArgs),
    Apply(ApplyArgs),
}

/// Simulates the `helicopter` scenario (4 headings with manoeuvres, 290 rpm,
/// 4 blades, nose-boom sensor, rotor phase channel), fits the physical rotor
/// model (magnetic masses and eddy currents of each blade, slowly varying
/// cone) and the filter baselines (low-pass, notches, synchronous averaging),
/// and compares the residual rotor interference and the share of anomaly
/// signal each removes. Also runs the thesis' simplified model (3 parameters
/// per blade) on the default rotor and on one that satisfies its
/// assumptions, and the same flight with a tail rotor seen from a sensor
/// under the tail boom, fitted with and without it. Prints the table and
/// those figures; writes DIR/summary.json and DIR/index.html.
///
/// Example: `aeromag rotor study --out rotor-study`
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
struct StudyArgs {
    /// Output folder.
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// Seed of the simulated flight.
    #[arg(long, default_value_t = RotorStudyRun::default().seed)]
    seed: u64,
}

/// Fit the physical main-rotor model on a helicopter flight file.
///
/// Needs `time` (s, uniform sampling ≥ 2.5 × the blade-passing frequency),
/// `mag` (nT) and `flux_x/y/z` (nT, body axes: the field direction), and a
/// rotor phase channel (deg, azimuth of a reference blade from the nose
/// towards the right) if there is one: `--phase-column COL`, by default
/// `rotor_phase` when the file has it. Without a phase channel (or with
/// --estimate-phase) the rotor frequency and phase are estimated from the
/// scalar data (search band --rotor-hz). Dropouts of up to 0.1 s (missing
/// values, regular time steps) and spikes of `mag` (a sample standing out
/// from its neighbours by 50 times the flight's typical second difference;
/// a warning names them) are bridged by linear interpolation; across
/// longer gaps the model is fitted on the longest stretch and its
/// parameters refined on every stretch of at least 10 s. Within a stretch
/// every time step must be within 2 % of the median (resample an irregular
/// record first). Columns named `true_…` are never read, however mapped.
///
/// The rotor geometry is required: either a named installation
/// (--preset aeromag-sim-helicopter: the helicopter of `aeromag simulate
/// helicopter`, hub 0,0,−2.6 m, sensor 5,0,0.6 m, blades 0.8 to 7.5 m,
/// 4 blades, nominal coning 4°, tilt −1.5°), whose values the flags below
/// override, or all of --hub-m, --sensor-m, --blade-span-m and --blades.
///
/// --tail-rotor adds a tail rotor geared to the main rotor (its phase is the
/// main rotor's phase channel times the gear ratio plus an offset found in
/// the fit), fitted jointly with it: where the sensor is near the tail
/// (a tail-boom installation); at a nose boom its field is negligible. A
/// tail rotor whose blade-passing signal stays below the joint fit's
/// residual is left out of the model, with a warning: its parameters would
/// be fitted to the main rotor's misfit, and its slow part (the rotation
/// average, which turns with the heading) would put tens of nT of error
/// into the compensated reading.
///
/// Example:
///   aeromag rotor fit --input heli.csv --model rotor.json --preset aeromag-sim-helicopter
///   aeromag rotor fit --input tailboom.csv --model rotor.json --preset aeromag-sim-helicopter \
///       --sensor-m -10,0,0.3 --tail-rotor
///   aeromag rotor fit --input heli.csv --model rotor.json --hub-m 0,0,-2.6 --sensor-m 5,0,0.6 \
///       --blade-span-m 0.8,7.5 --blades 4 --estimate-phase --rotor-hz 4.5,5.2
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
struct FitArgs {
    #[command(flatten)]
    input: InputArgs,
    /// Model file to write (JSON).
    #[arg(long, value_name = "ROTOR.json")]
    model: PathBuf,
    /// A named rotor installation (its geometry and nominal angles).
    #[arg(long, value_enum)]
    preset: Option<RotorPreset>,
    /// Rotor phase channel, deg (default `rotor_phase` if present).
    #[arg(long, value_name = "COL")]
    phase_column: Option<String>,
    /// Estimate the rotor phase from the data even if a phase channel exists.
    #[arg(long, conflicts_with = "phase_column")]
    estimate_phase: bool,
    /// Search band of the rotor frequency when the phase is estimated, Hz
    /// (default 4,6; LO above 2 Hz, the fit's high-pass cutoff).
    #[arg(long, value_name = "LO,HI", value_parser = args::pair)]
    rotor_hz: Option<[f64; 2]>,
    /// Rotor hub position, body axes (x forward, y right, z down), m
    /// (within ±100 m).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = args::xyz,
          required_unless_present = "preset")]
    hub_m: Option<[f64; 3]>,
    /// Scalar sensor position, body axes, m (within ±100 m).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = args::xyz,
          required_unless_present = "preset")]
    sensor_m: Option<[f64; 3]>,
    /// Magnetised span of a blade from the hub, m (0 ≤ ROOT, TIP ≤ 100,
    /// TIP − ROOT ≥ 0.01).
    #[arg(long, value_name = "ROOT,TIP", value_parser = args::pair,
          required_unless_present = "preset")]
    blade_span_m: Option<[f64; 2]>,
    /// Number of blades.
    #[arg(long, required_unless_present = "preset")]
    blades: Option<usize>,
    /// Nominal coning angle, deg (the start of the slowly varying estimate;
    /// default 4 or the preset's).
    #[arg(long, allow_hyphen_values = true)]
    coning_deg: Option<f64>,
    /// Nominal longitudinal tilt of the tip-path plane, deg (default −1.5
    /// or the preset's).
    #[arg(long, allow_hyphen_values = true)]
    tilt_lon_deg: Option<f64>,
    /// Window over which the cone angles are taken as constant, s (default 1;
    /// at least 10 samples, and at most half the shortest stretch fitted).
    #[arg(long)]
    window_s: Option<f64>,
    /// Also model a tail rotor, geared to the main rotor and fitted jointly
    /// with it (needs the phase channel): the preset's, or all of the
    /// --tail-… flags and --gear-ratio.
    #[arg(long)]
    tail_rotor: bool,
    /// Tail rotor hub position, body axes, m.
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = args::xyz,
          requires = "tail_rotor")]
    tail_hub_m: Option<[f64; 3]>,
    /// Direction of the tail rotor's angular velocity, body axes.
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = args::xyz,
          requires = "tail_rotor")]
    tail_spin_axis: Option<[f64; 3]>,
    /// Body direction of a tail blade at azimuth 0.
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = args::xyz,
          requires = "tail_rotor")]
    tail_zero_azimuth: Option<[f64; 3]>,
    /// Magnetised span of a tail blade from its hub, m.
    #[arg(long, value_name = "ROOT,TIP", value_parser = args::pair, requires = "tail_rotor")]
    tail_blade_span_m: Option<[f64; 2]>,
    /// Number of tail blades.
    #[arg(long, requires = "tail_rotor")]
    tail_blades: Option<usize>,
    /// Tail rotor speed over main rotor speed (the tail rotor turning
    /// between 2 Hz and Nyquist).
    #[arg(long, requires = "tail_rotor")]
    gear_ratio: Option<f64>,
}

/// Apply a rotor model (from `aeromag rotor fit`) to a flight file.
///
/// Writes every input column plus `rotor_interf` (modelled rotor
/// interference, nT), `mag_comp` (mag − rotor_interf, nT) and `rotor_flag`
/// (0 compensated, 1 not: a missing value in the row, or a stretch shorter
/// than 10 s between gaps). Every input row is written, in order. The
/// flight is checked as `rotor fit` checks it (the phase channel's rotor
/// speed, uniform time steps), and dropouts and spikes of `mag` are
/// bridged alike to track the rotor's slowly varying cone.
///
/// Example:
///   aeromag rotor apply --model rotor.json --input heli2.csv --out heli2_comp.csv
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
struct ApplyArgs {
    /// Model file written by `aeromag rotor fit`.
    #[arg(long, value_name = "ROTOR.json")]
    model: PathBuf,
    #[command(flatten)]
    input: InputArgs,
    #[arg(long, value_name = "OUT.csv", help = crate::output::TABLE_OUT_HELP)]
    out: PathBuf,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    match a.command {
        Sub::Study(s) => study(s),
        Sub::Fit(f) => fit(f),
        Sub::Apply(x) => apply(x),
    }
}

/// The library's options from the flags: the preset's values (if any)
/// overridden by the flags given.
fn options(a: &FitArgs) -> anyhow::Result<RotorOptions> {
    Ok(RotorOptions::from_choices(&RotorChoices {
        preset: a.preset,
        hub_m: a.hub_m,
        sensor_m: a.sensor_m,
        blade_span_m: a.blade_span_m,
        blades: a.blades,
        coning_deg: a.coning_deg,
        tilt_lon_deg: a.tilt_lon_deg,
        phase_column: a.phase_column.clone(),
        estimate_phase: a.estimate_phase,
        rotor_hz: a.rotor_hz,
        window_s: a.window_s,
        tail_rotor: a.tail_rotor,
        tail_hub_m: a.tail_hub_m,
        tail_spin_axis: a.tail_spin_axis,
        tail_zero_azimuth: a.tail_zero_azimuth,
        tail_blade_span_m: a.tail_blade_span_m,
        tail_blades: a.tail_blades,
        gear_ratio: a.gear_ratio,
    })?)
}

fn fit(a: FitArgs) -> anyhow::Result<()> {
    crate::output::check_files([a.model.as_path()], &[a.input.path()])?;
    let opts = options(&a)?;
    let flight = a.input.load_canonical(&opts.extra_columns())?;
    let fit = fit_rotor(&flight, &opts, &mut Bars::new())?;
    let model = &fit.model;
    model.write(&a.model)?;
    println!(
        "fitted the rotor model on {} rows of {} ({:.3} Hz, f_r {:.4} Hz, phase {}): {} parameters, \
         high-passed residual {:.4} nT, mean coning {:.2}°{}; written to {}",
        model.rows,
        flight.file_label(),
        model.sample_rate_hz,
        model.rotor_hz,
        model
            .phase
            .column
            .as_deref()
            .map_or("estimated from the data".to_string(), |c| format!(
                "from `{c}`"
            )),
        model.model.params.len(),
        model.model.residual_rms_nt,
        model.coning_mean_deg,
        model.tail.as_ref().map_or(String::new(), |t| format!(
            ", tail rotor {} parameters, phase offset {:.2}°",
            t.model.params.len(),
            t.offset_rad.to_degrees()
        )),
        a.model.display()
    );
    Ok(())
}

fn apply(a: ApplyArgs) -> anyhow::Result<()> {
    crate::output::check_files([a.out.as_path()], &[a.input.path(), a.model.as_path()])?;
    crate::output::check_tables([a.out.as_path()])?;
    let model = aeromag::rotor::RotorModelFile::read(&a.model)?;
    let flight = a.input.load()?;
    let out = model.compensate_observed(&flight, &mut Bars::new())?;
    crate::output::write_compensated(flight, out, &a.out, &a.model, "")
}

fn study(a: StudyArgs) -> anyhow::Result<()> {
    crate::output::check_folder(&a.out)?;
    let out = RotorStudyRun { seed: a.seed }.run(StudySize::Full, &mut Bars::new())?;
    let s = &out.study;
    println!(
        "rotor interference RMS {:.3} nT, anomaly RMS {:.3} nT, f_r {:.3} Hz",
        s.rotor_rms_nt, s.anomaly_rms_nt, s.rotor_hz
    );
    for m in &s.methods {
        println!(
            "{:44} residual {:.4} nT ({:>6} %), removes anomaly {:>5} %, 0.5 s bumps {:>5} %, 0.1 s bumps {:>5} %",
            m.name,
            m.residual_nt,
            pct(m.residual_nt / s.rotor_rms_nt),
            pct(m.removed_anomaly),
            pct(m.removed_bumps_05),
            pct(m.removed_bumps_01)
        );
    }
    let sum = out.summary();
    println!(
        "simplified model (3 per blade): {:.2} % of the rotor RMS on a rotor that satisfies its assumptions \
         (best filter {:.2} %), {:.2} % on the default rotor (best filter {:.2} %)",
        100.0 * sum.simplified_fraction_ideal_rotor,
        100.0 * sum.best_filter_fraction_ideal_rotor,
        100.0 * sum.simplified_fraction_default_rotor,
        100.0 * sum.best_filter_fraction_default_rotor
    );
    println!(
        "tail rotor, sensor under the tail boom: residual {:.2} % of the rotor RMS with the main rotor modelled, \
         {:.2} % with main and tail rotor",
        100.0 * sum.tail_unmodelled_residual_fraction,
        100.0 * sum.tail_residual_fraction
    );
    std::fs::create_dir_all(&a.out).map_err(|e| aeromag::Error::write(&a.out, e))?;
    let summary = serde_json::json!({ "rotor": sum });
    aeromag::io::atomic::write_file(
        &a.out.join("summary.json"),
        serde_json::to_string_pretty(&summary)?,
    )
    .map_err(|e| aeromag::Error::write(a.out.join("summary.json"), e))?;
    let mut r = Report::new("aeromag — helicopter rotor interference study");
    out.section()?.append_to(&mut r);
    let path = a.out.join("index.html");
    r.write_html(&path)?;
    println!("report written to {}", path.display());
    Ok(())
}
