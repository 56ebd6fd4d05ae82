//! `aeromag level`: levelling at line/tie-line crossovers with the
//! survey-altitude `k·d|B0|/dt` term.

use crate::exit::bad_input;
use crate::input::InputArgs;
use aeromag_compensation::levelling::{
    LevellingConfig, RowFlag, SurveyLevelling, SurveyTracks, TrackConfig, level_survey,
};
use aeromag_io::FlightTable;
use std::path::PathBuf;

/// Level a (compensated) survey: find the crossovers of lines and tie lines,
/// fit the coefficient k (s) of the d|B0|/dt term jointly with a level offset
/// per line (regularised least squares; the offsets have zero mean), apply
/// them, and report the crossover differences before and after.
///
/// Lines are told apart by the `line` column (label 0 = not on a line, e.g.
/// turns). Crossovers are computed at the scalar sensor's position: give the
/// sensor's lever arm from the navigation reference point with --lever-arm
/// (body frame x forward, y right, z down; m), otherwise a stinger's offset
/// along the track is mistaken for a time lag.
///
/// Writes every input column plus `<value>_level` and `level_flag`
/// (0 levelled, 1 line without crossovers, 2 not on a line, 3 missing value).
///
/// Examples:
///   aeromag level --input survey_comp.csv --out survey_level.csv
///   aeromag level --input s.csv --out o.csv --value mag --lever-arm -9.5,0,-0.6 --tie-only
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct Args {
    #[command(flatten)]
    input: InputArgs,
    /// Output CSV file.
    #[arg(long, value_name = "OUT.csv")]
    out: PathBuf,
    /// Column to level (default `mag_comp`, else `mag`).
    #[arg(long)]
    value: Option<String>,
    /// Sensor lever arm X,Y,Z from the navigation point, body frame, m.
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    lever_arm: Option<String>,
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
    #[arg(long, default_value_t = 1e-3)]
    lambda: f64,
    /// Known external-field channels subtracted from the value before the
    /// crossovers are formed: `none` (default), `auto` (`diurnal` and `igrf`
    /// when present) or a comma-separated list such as `diurnal`. With the
    /// base station subtracted the micropulsations (0.1–1 nT at periods of
    /// 10–300 s, which per-line offsets cannot follow) leave the crossovers,
    /// and the d|B0|/dt coefficient k is determined far better. The levelled
    /// column is then the reduced value, levelled.
    #[arg(long, default_value = "none", value_name = "none|auto|COLS")]
    reference: String,
    /// Also write the crossover table to this CSV: one row per crossover
    /// with both lines, position, times, altitudes, values, d|B0|/dt,
    /// the difference, what the fitted model leaves of it and its weight.
    #[arg(long, value_name = "FILE.csv")]
    crossovers: Option<PathBuf>,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let mut table = a.input.load()?;
    let value_name = match &a.value {
        Some(v) => v.clone(),
        None if table.column("mag_comp").is_some() => "mag_comp".into(),
        None => "mag".into(),
    };
    let out_name = format!("{value_name}_level");
    if table.get(&out_name).is_some() || table.get("level_flag").is_some() {
        return Err(bad_input!(
            "{}: already has `{out_name}` or `level_flag`",
            table.file_label()
        ));
    }
    if !(a.lambda >= 0.0 && a.lambda.is_finite()) {
        return Err(bad_input!("--lambda {} must be ≥ 0", a.lambda));
    }
    let cfg = LevellingConfig {
        estimate_k: !a.tie_only,
        drift: a.drift,
        lambda: a.lambda,
        altitude_term: !(a.tie_only || a.no_altitude_term),
        robust: !a.no_robust,
        ..LevellingConfig::default()
    };
    let lever = a
        .lever_arm
        .as_deref()
        .map(crate::flight::parse_lever_arm)
        .transpose()?;
    let spinner = crate::progress::spinner("levelling");
    let LevelTable {
        levelling: lev,
        reference_columns: ref_cols,
        rate_column,
    } = level_table(
        &table,
        &value_name,
        a.rate_of.as_deref(),
        lever,
        &a.reference,
        &cfg,
    )?;
    spinner.finish_and_clear();
    if !ref_cols.is_empty() {
        println!("levelling {value_name} − {}", ref_cols.join(" − "));
    }
    if cfg.estimate_k {
        println!("d|B0|/dt regressor: along-track derivative of `{rate_column}`");
    }
    let f = &lev.fit;
    let flags: Vec<f64> = lev
        .levelled
        .flag
        .iter()
        .map(|fl| match fl {
            RowFlag::Levelled => 0.0,
            RowFlag::NoCrossovers => 1.0,
            RowFlag::NotOnLine => 2.0,
            RowFlag::Missing => 3.0,
        })
        .collect();
    let n = table.n_rows();
    table.add_column(&out_name, lev.levelled.value_nt.clone())?;
    table.add_column("level_flag", flags)?;
    aeromag_io::write_csv(&table, &a.out)?;
    println!(
        "{} crossovers ({} skipped in gaps, {} with missing values, {} too shallow)",
        lev.crossovers.crossovers.len(),
        lev.crossovers.skipped_gap,
        lev.crossovers.skipped_missing,
        lev.crossovers.skipped_shallow
    );
    if cfg.estimate_k {
        println!("k (d|B0|/dt term) = {:.4} ± {:.4} s", f.k_s, f.k_std_s);
    }
    if f.altitude_term_used {
        println!(
            "altitude term: vertical-gradient scale c = {:.3} ± {:.3} ({} of {} crossovers with heights; ≈ 0.78 for an isotropic field)",
            f.vertical_scale,
            f.vertical_scale_std,
            f.altitude_corrected,
            lev.crossovers.crossovers.len()
        );
        println!(
            "crossover differences RMS: {:.4} nT before, {:.4} nT model residual, {:.4} nT levelled series (keeps the height differences)",
            f.rms_before_nt, f.rms_after_nt, f.rms_levelled_nt
        );
    } else {
        if cfg.altitude_term {
            eprintln!(
                "warning: no crossover has heights and profiles on both sides; the altitude term is left out"
            );
        }
        println!(
            "crossover differences RMS: {:.4} nT before, {:.4} nT after levelling",
            f.rms_before_nt, f.rms_after_nt
        );
    }
    if cfg.robust {
        println!(
            "robust weighting: {} of {} crossovers down-weighted (Huber, {} σ̂ = {:.4} nT){}",
            f.downweighted,
            f.weights.len(),
            aeromag_compensation::levelling::HUBER_K,
            f.sigma_nt,
            if f.downweighted > 0 {
                "; --crossovers writes the weights"
            } else {
                ""
            }
        );
    }
    if f.components > 1 {
        eprintln!(
            "warning: the lines form {} groups that never cross; their relative levels rest on the penalty, not the data",
            f.components
        );
    }
    println!(
        "{:>10} {:>11} {:>12} {:>10}",
        "line", "crossovers", "offset (nT)", "std (nT)"
    );
    for l in &f.lines {
        println!(
            "{:>10} {:>11} {:>12.4} {:>10.4}",
            l.label, l.crossovers, l.offset_nt, l.offset_std_nt
        );
    }
    println!(
        "{n} rows written to {} (column {out_name})",
        a.out.display()
    );
    if let Some(path) = &a.crossovers {
        write_crossovers(&lev.crossovers.crossovers, f, path)?;
        println!("crossover table written to {}", path.display());
    }
    Ok(())
}

/// The crossover table of `--crossovers` (units in the column names).
fn write_crossovers(
    xs: &[aeromag_compensation::levelling::Crossover],
    fit: &aeromag_compensation::levelling::LevellingFit,
    path: &std::path::Path,
) -> anyhow::Result<()> {
    let mut t = aeromag_io::FlightTable::new();
    let col = |f: &dyn Fn(&aeromag_compensation::levelling::Crossover) -> f64| -> Vec<f64> {
        xs.iter().map(f).collect()
    };
    let columns: Vec<(&str, Vec<f64>)> = vec![
        ("line_a", col(&|x| x.a.label as f64)),
        ("line_b", col(&|x| x.b.label as f64)),
        ("north_m", col(&|x| x.north_m)),
        ("east_m", col(&|x| x.east_m)),
        ("angle_deg", col(&|x| x.angle_deg)),
        ("time_a_s", col(&|x| x.a.time_s)),
        ("time_b_s", col(&|x| x.b.time_s)),
        ("alt_a_m", col(&|x| x.a.alt_m)),
        ("alt_b_m", col(&|x| x.b.alt_m)),
        ("value_a_nt", col(&|x| x.a.value_nt)),
        ("value_b_nt", col(&|x| x.b.value_nt)),
        ("rate_a_nt_per_s", col(&|x| x.a.derivative_nt_per_s)),
        ("rate_b_nt_per_s", col(&|x| x.b.derivative_nt_per_s)),
        (
            "profile_gradient_a_nt_per_m",
            col(&|x| x.a.profile_gradient_nt_per_m),
        ),
        (
            "profile_gradient_b_nt_per_m",
            col(&|x| x.b.profile_gradient_nt_per_m),
        ),
        ("difference_nt", col(&|x| x.difference_nt())),
        ("residual_nt", fit.residuals_nt.clone()),
        ("weight", fit.weights.clone()),
    ];
    for (name, v) in columns {
        t.add_column(name, v)?;
    }
    aeromag_io::write_csv(&t, path)?;
    Ok(())
}

/// What [`level_table`] did.
pub struct LevelTable {
    /// The levelling.
    pub levelling: SurveyLevelling,
    /// The reference channels subtracted from the value.
    pub reference_columns: Vec<String>,
    /// The column whose derivative is the `d|B0|/dt` regressor.
    pub rate_column: String,
}

/// Level `value_name` of `table` (the command's docs): sensor positions
/// from the lever arm (body frame, m) when given, the reference channels
/// (`none`, `auto` or a list) subtracted, the `d|B0|/dt` regressor the
/// derivative of `rate_of` (default `mag` when present, else the value),
/// crossovers found and fitted with `cfg`.
pub fn level_table(
    table: &FlightTable,
    value_name: &str,
    rate_of: Option<&str>,
    lever_arm_m: Option<[f64; 3]>,
    reference: &str,
    cfg: &LevellingConfig,
) -> anyhow::Result<LevelTable> {
    let positions = lever_arm_m
        .map(|arm| crate::flight::sensor_track(table, arm))
        .transpose()?;
    let (lat, lon, alt) = match &positions {
        Some([la, lo, al]) => (la.as_slice(), lo.as_slice(), al.as_slice()),
        None => (
            table.require("lat")?,
            table.require("lon")?,
            table.require("alt")?,
        ),
    };
    let ref_cols = crate::flight::reference_columns(table, reference)?;
    let reference = crate::flight::reference_sum(table, &ref_cols, None)?;
    let value: Vec<f64> = table
        .require(value_name)?
        .iter()
        .zip(&reference)
        .map(|(v, r)| v - r)
        .collect();
    let rate_column = match rate_of {
        Some(c) => c.to_string(),
        None if table.column("mag").is_some() => "mag".into(),
        None => value_name.to_string(),
    };
    // The column as recorded (the sensor lags the reference fields too);
    // not needed, and its gaps not imposed, without the k term.
    let sensed = cfg
        .estimate_k
        .then(|| table.require(&rate_column))
        .transpose()?;
    let tracks = SurveyTracks {
        time: table.require("time")?,
        lat,
        lon,
        alt,
        line: table.require("line")?,
        value: &value,
        sensed,
    };
    let levelling = level_survey(&tracks, &TrackConfig::default(), cfg)
        .map_err(|e| bad_input!("{}: {e}", table.file_label()))?;
    Ok(LevelTable {
        levelling,
        reference_columns: ref_cols,
        rate_column,
    })
}
