//! `aeromag microlevel`: the corrugation left along the lines after
//! levelling, removed by a directional filter of the grid (library:
//! [`aeromag::map::microlevel`]).

use crate::args;
use crate::input::InputArgs;
use crate::progress::Bars;
use aeromag::grid::projection::UtmZone;
use aeromag::map::{MicrolevelOptions, microlevel};
use aeromag_core::error::shown;
use std::path::PathBuf;

/// Micro-level a levelled survey (Minty 1991) and write it with the
/// micro-levelled column `<column>_mlev` and its correction
/// `<column>_mlev_corr`.
///
/// The column is gridded by minimum curvature; a high-pass Butterworth
/// filter across the lines (cut-off: --cutoff line spacings) times a
/// directional cosine filter isolates the stripes along the lines; the
/// median of their value along each line (or their running mean over
/// --along-line metres) is the line's correction.
///
/// Examples:
///   aeromag microlevel -i levelled.csv --out micro.csv
///   aeromag microlevel -i levelled.csv --column mag_comp_level --cell 50 --out micro.csv
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct Args {
    #[command(flatten)]
    input: InputArgs,
    #[arg(long, value_name = "OUT.csv", help = crate::output::TABLE_OUT_HELP)]
    out: PathBuf,
    /// Column to micro-level (default: the most processed magnetic column).
    #[arg(long)]
    column: Option<String>,
    /// Cell of the working grid, m (default: a quarter of the line spacing,
    /// rounded down to 1, 2, 2.5 or 5 × 10ᵏ m).
    #[arg(long, value_parser = args::positive)]
    cell: Option<f64>,
    /// Cut-off wavelength of the high-pass filter, in line spacings, at
    /// least 2 (the stripes between adjacent lines are 2 line spacings
    /// and more across them).
    #[arg(long, default_value_t = 4.0)]
    cutoff: f64,
    /// Length of an along-line running mean of the correction, m (for
    /// level errors that drift along long lines; default: one level per
    /// line, the median of the corrugation sampled along it).
    #[arg(long, value_parser = args::positive)]
    along_line: Option<f64>,
    /// Power of the directional cosine filter (higher: narrower around the
    /// across-line direction).
    #[arg(long, default_value_t = 2.0, value_parser = args::non_negative)]
    cosine_power: f64,
    #[command(flatten)]
    min_curvature: args::MinCurvatureArgs,
    /// UTM zone, e.g. `37N` (default: the data's); with projected
    /// positions (--xy), the zone they are in.
    #[arg(long, value_name = "ZONE", value_parser = args::utm_zone)]
    utm_zone: Option<UtmZone>,
    /// Positions already projected: the columns EASTING,NORTHING (m),
    /// e.g. `X,Y`, in place of lat/lon (default: lat/lon; in a file
    /// without them, the first of x,y, easting,northing, utm_x,utm_y,
    /// utm-x,utm-y, utm_easting,utm_northing, any case). Their UTM zone, when given
    /// with --utm-zone, is the grid's coordinate system; without it the
    /// grid has none [no-crs].
    #[arg(long, value_name = "EASTING,NORTHING", value_parser = args::projected_columns)]
    xy: Option<aeromag::map::ProjectedColumns>,
    /// Sensor lever arm X,Y,Z from the navigation point, body frame, m:
    /// grid at the sensor's positions (needs roll, pitch, yaw and alt).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = args::xyz)]
    lever_arm: Option<[f64; 3]>,
}

/// [`aeromag::core::error::fixed`], and in exponent form too below 10⁻³,
/// where the decimals would show nothing (`--cutoff 1e-300`).
fn fixed(x: f64, decimals: usize) -> String {
    if x != 0.0 && x.abs() < 1e-3 {
        shown(x)
    } else {
        aeromag::core::error::fixed(x, decimals)
    }
}

pub fn run(a: Args) -> anyhow::Result<()> {
    crate::output::check_files([a.out.as_path()], &[a.input.path()])?;
    crate::output::check_tables([a.out.as_path()])?;
    let flight = a.input.load()?;
    let opts = MicrolevelOptions {
        column: a.column.clone(),
        cell_m: a.cell,
        zone: a.utm_zone,
        projected: a.xy.clone(),
        lever_arm_m: a.lever_arm,
        cutoff_line_spacings: a.cutoff,
        along_line_m: a.along_line,
        cosine_power: a.cosine_power,
        min_curvature: a.min_curvature.settings(),
    };
    let m = microlevel(&flight, &opts, &mut Bars::new())?;
    let mut table = flight.into_table();
    m.add_to(&mut table)?;
    aeromag::io::write_table(&table, &a.out)?;
    println!(
        "micro-levelled {} → {} ({} lines at {:.1}° from grid north, spacing {:.1} m)",
        m.column,
        m.output_column(),
        m.lines.traverse_lines,
        m.lines.direction_deg,
        m.lines.spacing_m,
    );
    println!(
        "working grid: cell {} m, minimum curvature with tension {}, {} sweeps on the final grid, {}",
        m.cell_m,
        opts.min_curvature.tension,
        m.gridding.final_sweeps(),
        if m.gridding.converged {
            "converged"
        } else {
            "NOT converged"
        }
    );
    println!(
        "filter: high-pass cut-off {} m ({} line spacings); correction {}",
        fixed(opts.cutoff_line_spacings * m.lines.spacing_m, 0),
        shown(opts.cutoff_line_spacings),
        m.along_line_m
            .map_or("one level per line (median)".into(), |a| format!(
                "averaged along the lines over {} m",
                fixed(a, 0)
            ))
    );
    println!(
        "correction {}: RMS {:.3} nT, largest {:.3} nT",
        m.correction_column(),
        m.correction_rms_nt,
        m.correction_max_nt
    );
    match m.crossover_rms_nt {
        Some((before, after)) => println!(
            "crossover differences RMS: {before:.4} nT before, {after:.4} nT after micro-levelling"
        ),
        None => println!("no crossovers to check the correction against"),
    }
    println!("wrote {}", a.out.display());
    Ok(())
}
