//! `aeromag level`: levelling at line/tie-line crossovers with the
//! survey-altitude `k·d|B0|/dt` term (library: [`aeromag::level`]).

use crate::args;
use crate::input::InputArgs;
use crate::progress::Bars;
use aeromag::ReferenceChannels;
use aeromag::compensation::levelling::{HUBER_K, LevellingConfig, LineLevel};
use aeromag::level::{LevelFitChoices, LevelOptions, level};
use std::path::PathBuf;

/// Level a (compensated) survey at the crossovers of its lines and tie
/// lines, and write it with the levelled column `<value>_level`.
///
/// The crossovers are found at the sensor's position; one level per line
/// (and with --drift a linear drift) is fitted jointly with `k` of the
/// survey-altitude `k·d|B0|/dt` term (the field's rate along the track
/// times the scalar channel's lag), the altitude term and robust weights.
/// It prints the crossovers' differences before and after and `k`. A
/// label flown in two passes (another line's rows between them: a
/// re-flight under the first flight's label) is levelled per pass,
/// `1003 (pass 2)`, with the warning [line-repeated].
///
/// Examples:
///   aeromag level -i survey_comp.csv --out levelled.csv
///   aeromag level -i survey_comp.csv --reference auto --crossovers x.csv --out levelled.csv
///   aeromag level -i survey.xyz --tie-only --out levelled.csv
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct Args {
    #[command(flatten)]
    input: InputArgs,
    #[arg(long, value_name = "OUT.csv", help = crate::output::TABLE_OUT_HELP)]
    out: PathBuf,
    /// Column to level (default: the compensated reading, names in any
    /// case: `mag_comp`, else the first `mag_<k>_comp` of a multi-sensor
    /// `compensate`; else `mag`, with the warning [uncompensated-default]).
    #[arg(long)]
    value: Option<String>,
    /// Sensor lever arm X,Y,Z from the navigation point, body frame, m.
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = args::xyz)]
    lever_arm: Option<[f64; 3]>,
    /// Positions already projected: the columns EASTING,NORTHING (m),
    /// e.g. `X,Y`, in place of lat/lon (default: lat/lon; in a file
    /// without them, the first of x,y, easting,northing, utm_x,utm_y,
    /// utm-x,utm-y, utm_easting,utm_northing, any case), UTM coordinates of the zone
    /// --utm-zone.
    #[arg(long, value_name = "EASTING,NORTHING", value_parser = args::projected_columns)]
    xy: Option<aeromag::map::ProjectedColumns>,
    /// The UTM zone of projected positions (--xy), e.g. `37N` or
    /// `EPSG:32637`: the crossovers are found on the Earth.
    #[arg(long, value_name = "ZONE", value_parser = args::utm_zone)]
    utm_zone: Option<aeromag::grid::projection::UtmZone>,
    /// Column whose along-track derivative is the regressor of the
    /// d|B0|/dt term, as recorded (default `mag`, the uncompensated
    /// reading, when the file has it; else the column levelled). A lag of the scalar channel
    /// acts on everything the sensor sees, the aircraft's own interference
    /// included, and the compensated value has lost the interference's rate
    /// but not its lag.
    #[arg(long, value_name = "COLUMN")]
    rate_of: Option<String>,
    /// Plain tie-line levelling: offsets only, no d|B0|/dt term.
    #[arg(long)]
    tie_only: bool,
    /// Also fit a linear drift per line.
    #[arg(long)]
    drift: bool,
    /// Leave out the altitude term. By default the crossovers' height
    /// differences are explained by the vertical gradient, estimated from the
    /// two crossing profiles (∂B/∂h ≈ −c (S_a + S_b), S the profile's |κ|
    /// operator, one scale c fitted for the survey); this sharpens k. The
    /// levelled series is not reduced to a common height either way.
    #[arg(long)]
    no_altitude_term: bool,
    /// Plain least squares: do not down-weight outlying crossovers. By
    /// default the fit is iteratively reweighted with Huber weights (2σ̂,
    /// σ̂ from the median absolute residual), so one bad crossover (a GNSS
    /// height error at a steep gradient, a spike) cannot pull k.
    #[arg(long)]
    no_robust: bool,
    /// Ridge penalty on the offsets (and drifts).
    #[arg(long, value_parser = args::non_negative, default_value_t = LevellingConfig::default().lambda)]
    lambda: f64,
    /// Known external-field channels subtracted from the value before the
    /// crossovers are formed: `none` (default), `auto` (`diurnal` and `igrf`
    /// when present) or a comma-separated list such as `diurnal`. With the
    /// base station subtracted the micropulsations (0.1–1 nT at periods of
    /// 10–300 s, which per-line offsets cannot follow) leave the crossovers,
    /// and the d|B0|/dt coefficient k is determined far better. The levelled
    /// column is then the reduced value, levelled.
    ///
    /// Without this option, a file with `diurnal` or `igrf` columns gets a
    /// note naming them and `--reference auto` (`calibrate`'s default).
    #[arg(long, value_name = "none|auto|COLS",
          value_parser = args::parsed::<ReferenceChannels>)]
    reference: Option<ReferenceChannels>,
    /// Labels of the tie lines (e.g. `901,902`), for files whose labels
    /// do not say it: crossovers are then formed only between a line and a
    /// tie. Not needed with a `line_type` column (Geosoft XYZ `Line`/`Tie`
    /// records) or labels such as `L1020`/`T901` that mark ties; the labels
    /// given are ties whatever the file says. Without any of these (or a
    /// file whose records are all `Line`), any two crossing lines form a
    /// crossover.
    #[arg(long, value_name = "LABEL,LABEL", value_delimiter = ',')]
    ties: Vec<String>,
    /// Also write the crossover table to this CSV: one row per crossover
    /// with both lines, position, times, altitudes, values, d|B0|/dt,
    /// the difference, what the fitted model leaves of it and its weight.
    #[arg(long, value_name = "FILE.csv")]
    crossovers: Option<PathBuf>,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    crate::output::check_files(
        std::iter::once(a.out.as_path()).chain(a.crossovers.as_deref()),
        &[a.input.path()],
    )?;
    crate::output::check_tables(std::iter::once(a.out.as_path()).chain(a.crossovers.as_deref()))?;
    let flight = a.input.load()?;
    let opts = LevelOptions {
        value: a.value.clone(),
        rate_of: a.rate_of.clone(),
        lever_arm_m: a.lever_arm,
        projected: a.xy.clone(),
        zone: a.utm_zone,
        reference: a.reference.clone().unwrap_or(ReferenceChannels::None),
        note_unused_reference: a.reference.is_none(),
        fit: LevelFitChoices {
            tie_only: a.tie_only,
            drift: a.drift,
            no_altitude_term: a.no_altitude_term,
            no_robust: a.no_robust,
            ridge_lambda: a.lambda,
        }
        .config(),
        ties: a.ties.clone(),
        ..LevelOptions::default()
    };
    let lev = level(&flight, &opts, &mut Bars::new())?;
    let value_name = &lev.value_column;
    let out_name = lev.output_column();
    if lev.reference_columns.is_empty() {
        println!("levelling {value_name}");
    } else {
        println!(
            "levelling {value_name} − {}",
            lev.reference_columns.join(" − ")
        );
    }
    if opts.fit.estimate_k {
        println!(
            "d|B0|/dt regressor: along-track derivative of `{}`",
            lev.rate_column
        );
    }
    let n = flight.n_rows();
    let mut table = flight.into_table();
    lev.add_to(&mut table)?;
    aeromag::io::write_table(&table, &a.out)?;
    let (xs, f) = (&lev.levelling.crossovers, &lev.levelling.fit);
    println!(
        "{} crossovers ({} skipped in gaps, {} with missing values, {} too shallow)",
        xs.crossovers.len(),
        xs.skipped_gap,
        xs.skipped_missing,
        xs.skipped_shallow
    );
    if opts.fit.estimate_k {
        println!("k (d|B0|/dt term) = {:.4} ± {:.4} s", f.k_s, f.k_std_s);
    }
    if f.altitude_term_used {
        println!(
            "altitude term: vertical-gradient scale c = {:.3} ± {:.3} ({} of {} crossovers with heights; ≈ 0.78 for an isotropic field)",
            f.vertical_scale,
            f.vertical_scale_std,
            f.altitude_corrected,
            xs.crossovers.len()
        );
        println!(
            "crossover differences RMS: {:.4} nT before, {:.4} nT model residual, {:.4} nT levelled series (keeps the height differences)",
            f.rms_before_nt, f.rms_after_nt, f.rms_levelled_nt
        );
    } else {
        println!(
            "crossover differences RMS: {:.4} nT before, {:.4} nT after levelling",
            f.rms_before_nt, f.rms_after_nt
        );
    }
    if opts.fit.robust {
        println!(
            "robust weighting: {} of {} crossovers down-weighted (Huber, {} σ̂ = {:.4} nT){}",
            f.downweighted,
            f.weights.len(),
            HUBER_K,
            f.sigma_nt,
            if f.downweighted > 0 {
                "; --crossovers writes the weights"
            } else {
                ""
            }
        );
    }
    // Labels such as `L1020.01 (pass 2)` widen the first column.
    let label = |l: &LineLevel| lev.lines.label(l.label).unwrap_or("?");
    let w = f
        .lines
        .iter()
        .map(|l| label(l).chars().count())
        .fold(10, usize::max);
    println!(
        "{:>w$} {:>11} {:>12} {:>10}",
        "line", "crossovers", "offset (nT)", "std (nT)"
    );
    for l in &f.lines {
        println!(
            "{:>w$} {:>11} {:>12.4} {:>10.4}",
            label(l),
            l.crossovers,
            l.offset_nt,
            l.offset_std_nt
        );
    }
    println!(
        "{n} rows written to {} (column {out_name})",
        a.out.display()
    );
    if let Some(path) = &a.crossovers {
        aeromag::io::write_table(&lev.crossover_table()?, path)?;
        println!("crossover table written to {}", path.display());
    }
    Ok(())
}
