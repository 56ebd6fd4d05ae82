//! `aeromag calibrate`: fit a Tolles-Lawson model on a calibration flight.

use crate::exit::bad_input;
use crate::flight::{TlColumns, parse_band, parse_lever_arm, reference_columns, reference_sum};
use crate::input::InputArgs;
use aeromag_compensation::kalman::{
    DEFAULT_ORDER, KalmanConfig, KalmanFit, KalmanSegment, KalmanSeries, NoiseModel, ORDERS,
    X2Prior, fit_kalman, ground_speed_from_positions, ground_speed_from_velocity, q1_unit,
};
use aeromag_compensation::model_file::{Coefficient, FitStats, MODEL_FORMAT, TL_KIND, TlModel};
use aeromag_compensation::reference_field::LeverArm;
use aeromag_compensation::tolles_lawson::fit_ls::{LsConfig, Segment, fit_band_pass_ls};
use aeromag_compensation::tolles_lawson::lag_select::{
    DEFAULT_ALPHA, DEFAULT_LAG_GRID_S, DEFAULT_SELECTION_BLOCK, DEFAULT_SELECTION_ROWS,
    LagSelection, lag_threshold, select_eddy_lags, within_budget,
};
use aeromag_compensation::tolles_lawson::{Convention, TermSet};
use aeromag_io::FlightTable;
use std::ops::Range;
use std::path::PathBuf;

/// Fit the aircraft's magnetic interference model (Tolles-Lawson / Leliak)
/// on a calibration flight and save it as a model file (JSON).
///
/// Method `ls`: band-pass least squares (Butterworth order 4, zero-phase,
/// default 0.1–0.9 Hz, 20 samples trimmed at each end of each leg), the
/// industry and MagNav.jl baseline. The flight is split into legs at changes
/// of the `line` column, at time gaps and at missing values; each leg is
/// filtered on its own. Terms not determined by the flight (one heading,
/// missing manoeuvres) are named in a warning.
///
/// Eddy currents with a time constant (--eddy-lag, default `auto`): aircraft
/// skins and frames carry eddy currents that follow dB/dt through a lag of
/// 0.1–1 s, which the classical eddy terms (e8/e9) cannot represent. `auto`
/// tries lagged eddy groups (l9) with τ from 0.1 to 1 s and keeps up to two
/// lags only when a likelihood-ratio test on the band-passed residual finds
/// them significant (1 % false-selection probability); otherwise the
/// classical model is kept. `none` keeps the classical model (MagNav.jl's,
/// the default with --convention magnav); a list such as `0.3,0.8` fixes the
/// lags. `auto` runs about 15 extra fits on at most 200 000 rows (a longer
/// record is sampled: blocks spread evenly over every leg).
///
/// --lever-arm X,Y,Z: the scalar sensor's position from the navigation point
/// (body frame, m); the `igrf` reference, computed at the navigation point,
/// is then moved to the sensor with the main field's gradient.
///
/// Example:
///   aeromag calibrate --input cal.csv --model model.json
///   aeromag calibrate --input cal.csv --model m.json --terms p3,i6,e9 --convention magnav --lambda 0.01
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct Args {
    #[command(flatten)]
    input: InputArgs,
    /// Where to write the model file (JSON).
    #[arg(long, value_name = "MODEL.json")]
    model: PathBuf,
    /// Fitting method: `ls` (band-pass least squares) or `kalman` (Kalman
    /// filter and smoother with a stochastic model of the external field;
    /// needs `alt` and ground speed from `vn`,`ve` or positions; the
    /// altitude of the vertical-gradient term is cleaned of GNSS noise,
    /// blended with the integrated down velocity `vd` when that is recorded
    /// and agrees with `alt`, else low-passed at 1 Hz).
    #[arg(long, default_value = "ls")]
    method: String,
    /// With --method kalman: tune the noise intensities q1, q2, r by maximum
    /// likelihood of the innovations, starting from --kalman-noise or the
    /// documented defaults. This is the default unless --kalman-noise is
    /// given; the flag makes it tune from the given values.
    #[arg(long, conflicts_with = "no_tune")]
    tune: bool,
    /// With --method kalman: use the noise intensities as given (the
    /// documented defaults, or --kalman-noise), without tuning.
    #[arg(long)]
    no_tune: bool,
    /// With --method kalman: noise intensities Q1,Q2,R (q1 in nT²/m^(2n−1),
    /// i.e. nT²/m¹¹ for the default order n = 6 and nT²/m⁵ for n = 3: the
    /// spectral density of the n-th along-track derivative of B^h; q2 in
    /// nT²/m⁵: that of d²B_z/ds²; r in nT²: the measurement noise variance),
    /// e.g. from an earlier calibration. Default 6.2e-29,1e-15,4e-4 (n = 6),
    /// 3.9e-20,1e-15,4e-4 (n = 4), 1e-15,1e-15,4e-4 (n = 3). Given values are used as they are, unless
    /// --tune is also given (then they are the starting point).
    #[arg(long, value_name = "Q1,Q2,R")]
    kalman_noise: Option<String>,
    /// With --method kalman: order n of the along-track field model, B^h the
    /// n-th integral of white noise (2–6). 3 is the thesis' model; the
    /// default 6 separates the field from the manoeuvres better over
    /// geology (library docs of aeromag_compensation::kalman::anomaly_model).
    /// Default 6.
    #[arg(long, value_name = "N")]
    field_order: Option<usize>,
    /// With --method kalman: write every input row plus the series
    /// kalman_reading (reference removed), kalman_compensated, kalman_field
    /// (the smoothed external field), kalman_innovation and
    /// kalman_innovation_std (nT; empty where a row was not used) to this CSV.
    #[arg(long, value_name = "FILE.csv")]
    series: Option<PathBuf>,
    /// Term groups: p3, i6 or i5, e9 or e8, bias (comma-separated).
    #[arg(long, default_value = "p3,i5,e8")]
    terms: String,
    /// Derivative convention of the eddy terms: physical (nT/s) or magnav
    /// (MagNav.jl create_TL_A: per-sample central difference).
    #[arg(long, default_value = "physical")]
    convention: String,
    /// Ridge parameter λ ≥ 0.
    #[arg(long, default_value_t = 0.0)]
    lambda: f64,
    /// Pass band LO,HI in Hz, or `none` to fit unfiltered data.
    #[arg(long, default_value = "0.1,0.9")]
    band: String,
    /// Samples trimmed at each end of each filtered leg.
    #[arg(long, default_value_t = 20)]
    trim: usize,
    /// Scale of the induced and eddy columns, nT.
    #[arg(long, default_value_t = 50_000.0)]
    bt_scale: f64,
    /// Treat the whole file as one leg (ignore the `line` column).
    #[arg(long)]
    no_split_lines: bool,
    /// Known external-field channels subtracted from `mag` before the fit:
    /// `auto` (the `diurnal` and `igrf` columns when present), `none`
    /// (MagNav.jl's way), or a comma-separated list of columns.
    #[arg(long, default_value = "auto")]
    reference: String,
    /// Eddy-current lags of the lagged eddy terms (l9): `auto` (chosen
    /// from the flight by a likelihood-ratio test), `none` (classical
    /// Tolles-Lawson), or lags in seconds, e.g. `0.3,0.8`. Default: `auto`,
    /// but `none` with --convention magnav (MagNav.jl's model exactly).
    #[arg(long, value_name = "auto|none|TAU,…")]
    eddy_lag: Option<String>,
    /// Scalar sensor position X,Y,Z (m, body frame: x forward, y right,
    /// z down) from the navigation point whose position the `igrf` column
    /// was computed at; the reference is then moved to the sensor with the
    /// main field's gradient (needs lat, lon, alt, roll, pitch, yaw).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    lever_arm: Option<String>,
    /// Date of the flight (YYYY-MM-DD) for the main-field gradient used with
    /// --lever-arm (the gradient changes < 0.3 % per year).
    #[arg(long, default_value = "2025-01-01")]
    date: String,
}

/// How a model is fitted on a table, besides the term configuration.
#[derive(Debug, Clone)]
pub struct FitOptions {
    /// Lagged eddy-current terms.
    pub eddy_lag: EddyLag,
    /// Split the flight into legs at changes of `line`.
    pub split_lines: bool,
    /// Reference channels: `auto`, `none` or a list (see --reference).
    pub reference: String,
    /// Sensor lever arm for the `igrf` reference.
    pub lever_arm: Option<LeverArm>,
}

impl FitOptions {
    /// `auto` lags and references, legs split at line changes, no lever arm.
    pub fn auto() -> Self {
        Self {
            eddy_lag: EddyLag::Auto,
            split_lines: true,
            reference: "auto".into(),
            lever_arm: None,
        }
    }
}

/// `Q1,Q2,R` noise intensities of the Kalman method.
fn parse_noise(s: &str, order: usize) -> anyhow::Result<NoiseModel> {
    let v = crate::flight::parse_numbers("--kalman-noise", s, 3)?;
    let noise = NoiseModel {
        q1: v[0],
        q2_nt2_per_m5: v[1],
        r_nt2: v[2],
    };
    if noise.is_valid() {
        Ok(noise)
    } else {
        Err(bad_input!(
            "--kalman-noise `{s}`: need q1 ≥ 0 ({}), q2 ≥ 0 (nT²/m⁵) and r > 0 (nT²)",
            q1_unit(order)
        ))
    }
}

/// A `YYYY-MM-DD` date as a decimal year.
fn parse_decimal_year(s: &str) -> anyhow::Result<f64> {
    aeromag_core::time::Date::parse(s)
        .map(|d| d.decimal_year())
        .map_err(|e| bad_input!("--date `{s}`: {e}"))
}

/// How the lagged eddy-current terms are chosen.
#[derive(Debug, Clone, PartialEq)]
pub enum EddyLag {
    /// Classical model, no lagged terms.
    None,
    /// Up to two lags from [`DEFAULT_LAG_GRID_S`], kept if significant.
    Auto,
    /// These lags, s.
    Fixed(Vec<f64>),
}

impl std::str::FromStr for EddyLag {
    type Err = anyhow::Error;
    fn from_str(s: &str) -> anyhow::Result<Self> {
        match s.trim() {
            "auto" => Ok(EddyLag::Auto),
            "none" | "" => Ok(EddyLag::None),
            list => list
                .split(',')
                .map(|t| match t.trim().parse::<f64>() {
                    Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
                    _ => Err(bad_input!("--eddy-lag `{s}`: expected auto, none or lags in seconds > 0 such as 0.3,0.8")),
                })
                .collect::<anyhow::Result<Vec<f64>>>()
                .map(EddyLag::Fixed),
        }
    }
}

/// Build the LS configuration from the command-line flags.
fn config(a: &Args) -> anyhow::Result<LsConfig> {
    let terms = TermSet::parse(&a.terms).map_err(|e| bad_input!("--terms: {e}"))?;
    let convention: Convention = a
        .convention
        .parse()
        .map_err(|e| bad_input!("--convention: {e}"))?;
    let band_hz = if a.band.trim().eq_ignore_ascii_case("none") {
        None
    } else {
        Some(parse_band(&a.band)?)
    };
    if !(a.lambda >= 0.0 && a.lambda.is_finite()) {
        return Err(bad_input!("--lambda {} must be ≥ 0", a.lambda));
    }
    if !(a.bt_scale > 0.0 && a.bt_scale.is_finite()) {
        return Err(bad_input!("--bt-scale {} must be > 0", a.bt_scale));
    }
    Ok(LsConfig {
        terms,
        convention,
        bt_scale_nt: a.bt_scale,
        band_hz,
        trim: a.trim,
        lambda: a.lambda,
        ..LsConfig::default()
    })
}

/// Fit a model on a loaded calibration table; warnings go to stderr.
pub fn fit_model(
    table: &FlightTable,
    cfg: &LsConfig,
    opts: &FitOptions,
) -> anyhow::Result<TlModel> {
    let cols = TlColumns::from_table(table)?;
    let (ref_cols, y) = reduced_mag(table, &cols, opts)?;
    let cols = TlColumns { mag: &y, ..cols };
    let (segs, _) = cols.segments(opts.split_lines, 1);
    let left_out = cols.usable().iter().filter(|u| !**u).count();
    if left_out > 0 {
        eprintln!(
            "warning: {} of {} rows have missing values and are not used by the fit",
            left_out,
            table.n_rows()
        );
    }
    let segments: Vec<Segment> = segs.iter().map(|r| whole(&cols).slice(r.clone())).collect();
    let (terms, selection) = choose_terms(table, &segments, cfg, &opts.eddy_lag)?;
    let cfg = &LsConfig {
        terms,
        ..cfg.clone()
    };
    let spinner = crate::progress::spinner("fitting");
    let fit =
        fit_band_pass_ls(&segments, cfg).map_err(|e| bad_input!("{}: {e}", table.file_label()))?;
    spinner.finish_and_clear();
    for w in &fit.warnings {
        eprintln!("warning: {w}");
    }
    Ok(TlModel {
        format: MODEL_FORMAT.into(),
        kind: TL_KIND.into(),
        method: "ls".into(),
        terms: cfg.terms.clone(),
        convention: cfg.convention,
        bt_scale_nt: cfg.bt_scale_nt,
        band_hz: cfg.band_hz,
        filter_order: cfg.filter_order,
        trim: cfg.trim,
        lambda: cfg.lambda,
        coefficients: fit
            .names
            .iter()
            .zip(fit.coef.iter().zip(&fit.std))
            .map(|(n, (v, s))| Coefficient {
                name: n.clone(),
                value: *v,
                std: *s,
            })
            .collect(),
        fit: FitStats {
            rows: fit.rows,
            segments: fit.segments_used,
            condition: fit.condition,
            residual_rms_nt: fit.residual_rms_nt,
            warnings: fit.warnings.clone(),
            eddy_lag_selection: selection,
        },
        columns: model_columns(
            table,
            &["time", "flux_x", "flux_y", "flux_z", "mag"],
            &ref_cols,
        ),
        reference: ref_cols,
        lever_arm: opts.lever_arm,
        software_version: env!("CARGO_PKG_VERSION").into(),
    })
}

/// The reference channels of `opts` and `mag` reduced by their sum.
fn reduced_mag(
    table: &FlightTable,
    cols: &TlColumns,
    opts: &FitOptions,
) -> anyhow::Result<(Vec<String>, Vec<f64>)> {
    let ref_cols = reference_columns(table, &opts.reference)?;
    let ref_sum = reference_sum(table, &ref_cols, opts.lever_arm.as_ref())?;
    let y = cols.mag.iter().zip(&ref_sum).map(|(m, r)| m - r).collect();
    Ok((ref_cols, y))
}

/// All rows of `cols` as one fitting segment (to be sliced into legs).
fn whole<'a>(cols: &TlColumns<'a>) -> Segment<'a> {
    Segment {
        time: cols.time,
        flux: cols.flux,
        mag: cols.mag,
    }
}

/// Canonical column name → the file's column name, for the model file.
fn model_columns(
    table: &FlightTable,
    base: &[&str],
    ref_cols: &[String],
) -> std::collections::BTreeMap<String, String> {
    base.iter()
        .map(|c| c.to_string())
        .chain(ref_cols.iter().cloned())
        .map(|c| {
            let file = table.resolve(&c).unwrap_or(&c).to_string();
            (c, file)
        })
        .collect()
}

/// The term set with the eddy-current lags of `lag` (`auto`: chosen on
/// `segments` by the band-pass LS likelihood-ratio search, on the row
/// budget), and the search when one ran. Used by both fitting methods.
fn choose_terms(
    table: &FlightTable,
    segments: &[Segment],
    cfg: &LsConfig,
    lag: &EddyLag,
) -> anyhow::Result<(TermSet, Option<LagSelection>)> {
    let with = |taus: &[f64]| {
        cfg.terms
            .with_eddy_lags(taus)
            .map_err(|e| bad_input!("--eddy-lag: {e}"))
    };
    match lag {
        EddyLag::None => Ok((with(&[])?, None)),
        EddyLag::Fixed(taus) => Ok((with(taus)?, None)),
        EddyLag::Auto if !cfg.terms.has_eddy() => Ok((cfg.terms.clone(), None)),
        EddyLag::Auto => {
            let spinner = crate::progress::spinner("choosing eddy-current lags");
            let sample = within_budget(segments, DEFAULT_SELECTION_ROWS, DEFAULT_SELECTION_BLOCK);
            let sel = select_eddy_lags(&sample, cfg, &DEFAULT_LAG_GRID_S, 2, DEFAULT_ALPHA)
                .map_err(|e| bad_input!("{}: {e}", table.file_label()))?;
            spinner.finish_and_clear();
            if sel.taus_s.is_empty() {
                eprintln!(
                    "note: eddy-current lags: no lag is significant; classical eddy terms kept"
                );
            } else {
                eprintln!(
                    "note: eddy-current lags τ = {:?} s chosen (likelihood-ratio test): band-passed residual {:.4} → {:.4} nT RMS",
                    sel.taus_s, sel.base_residual_rms_nt, sel.residual_rms_nt
                );
            }
            Ok((with(&sel.taus_s)?, Some(sel)))
        }
    }
}

/// Lags of the Kalman method's first pass (s): a pair that brackets the
/// 0.1–1 s of aircraft skins and frames, so that the field model of that
/// pass does not have to absorb lagged eddy currents.
const PASS1_LAGS_S: [f64; 2] = [0.15, 0.5];

/// The Kalman method's own test of further lags, after the band-pass
/// choice on the field-removed data: while fewer than two lags are in the
/// model, try each remaining lag of [`DEFAULT_LAG_GRID_S`] and add the best
/// if the likelihood-ratio statistic of the profile likelihoods
/// ([`KalmanFit::profile_log_likelihood`]), with the noise intensities of
/// the first pass fixed, exceeds the threshold of the band-pass test
/// ([`lag_threshold`]: χ² for the added columns at [`DEFAULT_ALPHA`],
/// Bonferroni over the candidates). The band-pass test sees only the band and its
/// residual's spectral flatness; the Kalman innovations are whitened by the
/// field model, so a lag that the band-pass test left out at the margin
/// (over the quiet box of demo seed 2: τ = 0.15 s beside 0.5 s, LR ≈ 38)
/// is taken.
fn add_lags_by_kalman_likelihood(
    segments: &[KalmanSegment],
    cfg: &KalmanConfig,
    mut terms: TermSet,
    first: &KalmanFit,
    fail: impl Fn(aeromag_compensation::CompError) -> anyhow::Error,
) -> anyhow::Result<TermSet> {
    if terms.eddy_lags_s().len() >= 2 {
        return Ok(terms);
    }
    // Untuned passes with the first pass's noise intensities.
    let mut fixed = KalmanConfig {
        noise: first.noise,
        compute_series: false,
        ..cfg.clone()
    };
    fixed.tuning.enabled = false;
    let profile = |terms: &TermSet| -> anyhow::Result<(f64, usize)> {
        let c = KalmanConfig {
            terms: terms.clone(),
            ..fixed.clone()
        };
        let f = fit_kalman(segments, &c).map_err(&fail)?;
        Ok((f.profile_log_likelihood(), f.coef.len()))
    };
    let spinner = crate::progress::spinner("Kalman likelihood-ratio test of further lags");
    let (mut base, mut m) = profile(&terms)?;
    while terms.eddy_lags_s().len() < 2 {
        let lags = terms.eddy_lags_s().to_vec();
        let mut best: Option<(f64, usize, TermSet, f64)> = None;
        for &tau in DEFAULT_LAG_GRID_S.iter().filter(|t| !lags.contains(t)) {
            let mut with: Vec<f64> = lags.clone();
            with.push(tau);
            with.sort_by(f64::total_cmp);
            let cand = cfg.terms.with_eddy_lags(&with).map_err(&fail)?;
            let (ll, mc) = profile(&cand)?;
            if ll.is_finite() && best.as_ref().is_none_or(|b| ll > b.0) {
                best = Some((ll, mc, cand, tau));
            }
        }
        let Some((ll, mc, cand, tau)) = best else {
            break;
        };
        let tried = DEFAULT_LAG_GRID_S.len() - lags.len();
        let dof = mc - m;
        let threshold = lag_threshold(DEFAULT_ALPHA, tried, dof).map_err(&fail)?;
        let lr = 2.0 * (ll - base);
        if lr <= threshold {
            break;
        }
        eprintln!(
            "note: Kalman likelihood-ratio test adds the lag τ = {tau} s (LR {lr:.1} > {threshold:.1}, {dof} columns)"
        );
        terms = cand;
        base = ll;
        m = mc;
    }
    spinner.finish_and_clear();
    Ok(terms)
}

/// The scalar sensor's altitude (m) for the field model's `Δz B_z` term.
///
/// 1. The navigation altitude `alt` is cleaned on each leg `segs` (module
///    docs of [`aeromag_compensation::kalman::altitude`]): blended with the
///    integrated down velocity `vd` when that column is recorded and agrees
///    with `alt` (a warning says so when it does not), else low-passed at
///    1 Hz. A noisy altitude times the vertical gradient of a low
///    calibration otherwise spoils the coefficients.
/// 2. With a lever arm it is moved to the sensor with the attitude (a pitch
///    of 5° moves a sensor 9.5 m behind the reference point by 0.8 m, in
///    step with the manoeuvre).
fn sensor_altitude(
    table: &FlightTable,
    segs: &[Range<usize>],
    lever: Option<&LeverArm>,
) -> anyhow::Result<Vec<f64>> {
    use aeromag_compensation::kalman::altitude::{
        AltitudeSmoothing, AltitudeSource, NavRun, check_down_velocity, smooth_altitude,
    };
    let time = table.require("time")?;
    let alt = table.require("alt")?;
    let vd = table.column("vd");
    let runs: Vec<NavRun> = segs
        .iter()
        .map(|r| NavRun {
            time: &time[r.clone()],
            alt_m: &alt[r.clone()],
            down_velocity_m_s: vd.map(|v| &v[r.clone()]),
        })
        .collect();
    let cfg = AltitudeSmoothing::default();
    let check = check_down_velocity(&runs, &cfg);
    let use_vd = check.is_some_and(|c| c.accepted);
    if let Some(c) = check.filter(|c| !c.accepted) {
        eprintln!(
            "warning: {}: `vd` does not follow the change of `alt` (slope {:.2}, correlation {:.2} \
             over 0.02–0.5 Hz; a down velocity in m/s gives ≈ 1, 1): the altitude is low-passed \
             instead of blended with it",
            table.file_label(),
            c.slope,
            c.correlation
        );
    }
    let mut clean = alt.to_vec();
    let mut how = AltitudeSource::AsRecorded;
    for (r, run) in segs.iter().zip(&runs) {
        let (s, h) = smooth_altitude(run, use_vd, &cfg);
        clean[r.clone()].copy_from_slice(&s);
        if how == AltitudeSource::AsRecorded {
            how = h;
        }
    }
    match (how, check) {
        (AltitudeSource::Blended(fc), Some(c)) => eprintln!(
            "note: altitude of the vertical-gradient term: `alt` blended with the integrated `vd` \
             (crossover {fc} Hz; they agree with slope {:.3}, correlation {:.3})",
            c.slope, c.correlation
        ),
        (AltitudeSource::LowPass(fc), _) => eprintln!(
            "note: altitude of the vertical-gradient term: `alt` low-passed at {fc} Hz{}",
            if vd.is_none() {
                " (no `vd` column to blend with)"
            } else {
                ""
            }
        ),
        _ => {}
    }
    let Some(lever) = lever else {
        return Ok(clean);
    };
    let [_, _, sensor_alt] = crate::flight::sensor_track_at(table, &clean, lever.arm_m)?;
    Ok(sensor_alt)
}

/// Ground speed (m/s) from `vn`, `ve` when present, else from the positions.
fn ground_speed(table: &FlightTable) -> anyhow::Result<Vec<f64>> {
    Ok(match (table.column("vn"), table.column("ve")) {
        (Some(vn), Some(ve)) => ground_speed_from_velocity(vn, ve),
        _ => ground_speed_from_positions(
            table.require("time")?,
            table.require("lat")?,
            table.require("lon")?,
        ),
    })
}

/// One series of a Kalman fit (`pick` from each segment's [`KalmanSeries`])
/// placed on the `n` rows of the table the segments `segs` come from; NaN on
/// the other rows.
fn on_rows(
    n: usize,
    segs: &[Range<usize>],
    series: &[KalmanSeries],
    pick: impl Fn(&KalmanSeries) -> &[f64],
) -> Vec<f64> {
    let mut out = vec![f64::NAN; n];
    for (r, s) in segs.iter().zip(series) {
        out[r.clone()].copy_from_slice(pick(s));
    }
    out
}

/// Names of the per-row series of the Kalman method ([`fit_model_kalman`]).
pub const KALMAN_SERIES: [&str; 5] = [
    "kalman_reading",
    "kalman_compensated",
    "kalman_field",
    "kalman_innovation",
    "kalman_innovation_std",
];

/// Fit a model with the Kalman method on a loaded calibration table. With
/// `cfg.compute_series`, also the per-row series named in
/// [`KALMAN_SERIES`] on the table's rows (NaN where a row was not used): the
/// reading with the reference channels removed (nT), the compensated reading
/// `mag − H1 X̂1`, the smoothed external field, the pass-1 innovation and its
/// predicted standard deviation.
pub fn fit_model_kalman(
    table: &FlightTable,
    cfg: &KalmanConfig,
    opts: &FitOptions,
) -> anyhow::Result<(TlModel, KalmanFit, Vec<Vec<f64>>)> {
    let cols = TlColumns::from_table(table)?;
    let (ref_cols, y) = reduced_mag(table, &cols, opts)?;
    let cols = TlColumns { mag: &y, ..cols };
    let (segs, _) = cols.segments(opts.split_lines, 1);
    let alt = sensor_altitude(table, &segs, opts.lever_arm.as_ref())?;
    let speed = ground_speed(table)?;
    let segments: Vec<KalmanSegment> = segs
        .iter()
        .map(|r| KalmanSegment {
            data: whole(&cols).slice(r.clone()),
            alt_m: &alt[r.clone()],
            speed_m_s: &speed[r.clone()],
        })
        .collect();
    let fail = |e: aeromag_compensation::CompError| bad_input!("{}: {e}", table.file_label());
    // `auto` chooses the lags with the band-pass LS machinery on the same
    // legs, after a first Kalman pass (with the bracketing lags
    // PASS1_LAGS_S) has removed its smoothed field: over geology the
    // band-pass leaves part of the anomaly field in the band, where it hides
    // lagged eddy currents (or buys a spurious slow lag); the field model
    // takes it out first.
    let ls = LsConfig {
        terms: cfg.terms.clone(),
        convention: cfg.convention,
        bt_scale_nt: cfg.bt_scale_nt,
        ..LsConfig::default()
    };
    let (terms, selection, tuned) = match opts.eddy_lag {
        EddyLag::Auto if cfg.terms.has_eddy() => {
            let spinner = crate::progress::spinner("Kalman pass 1: removing the field");
            let pass1 = KalmanConfig {
                terms: cfg.terms.with_eddy_lags(&PASS1_LAGS_S).map_err(fail)?,
                compute_series: true,
                ..cfg.clone()
            };
            let first = fit_kalman(&segments, &pass1).map_err(fail)?;
            spinner.finish_and_clear();
            let field = on_rows(y.len(), &segs, &first.series, |s| &s.external_nt);
            let y_field_removed: Vec<f64> = y.iter().zip(&field).map(|(a, b)| a - b).collect();
            let reduced = TlColumns {
                mag: &y_field_removed,
                ..cols
            };
            let (rsegs, _) = reduced.segments(opts.split_lines, 1);
            let data: Vec<Segment> = rsegs
                .iter()
                .map(|r| whole(&reduced).slice(r.clone()))
                .collect();
            let (terms, selection) = choose_terms(table, &data, &ls, &opts.eddy_lag)?;
            let terms = add_lags_by_kalman_likelihood(&segments, cfg, terms, &first, fail)?;
            (
                terms,
                selection,
                first.tuning.is_some().then_some(first.noise),
            )
        }
        _ => {
            let data: Vec<Segment> = segments.iter().map(|k| k.data).collect();
            let (terms, selection) = choose_terms(table, &data, &ls, &opts.eddy_lag)?;
            (terms, selection, None)
        }
    };
    let mut cfg = KalmanConfig {
        terms,
        ..cfg.clone()
    };
    // Pass 1 searched the likelihood globally (kalman::tuning, several
    // starts) on the same flight with nearly the same terms: the final fit
    // refines its maximum locally.
    if let Some(noise) = tuned {
        cfg.noise = noise;
        cfg.tuning.grid_starts = 0;
    }
    let cfg = &cfg;
    let spinner = crate::progress::spinner("Kalman filter and smoother");
    let fit = fit_kalman(&segments, cfg).map_err(fail)?;
    spinner.finish_and_clear();
    let rows: Vec<Vec<f64>> = if fit.series.is_empty() {
        Vec::new()
    } else {
        let compensated = on_rows(y.len(), &segs, &fit.series, |s| &s.compensated_nt);
        let reading = y
            .iter()
            .zip(&compensated)
            .map(|(v, c)| if c.is_nan() { f64::NAN } else { *v })
            .collect();
        vec![
            reading,
            compensated,
            on_rows(y.len(), &segs, &fit.series, |s| &s.external_nt),
            on_rows(y.len(), &segs, &fit.series, |s| &s.innovation_nt),
            on_rows(y.len(), &segs, &fit.series, |s| &s.innovation_std_nt),
        ]
    };
    for w in &fit.warnings {
        eprintln!("warning: {w}");
    }
    let mut model = fit.to_model(cfg);
    model.columns = model_columns(
        table,
        &["time", "flux_x", "flux_y", "flux_z", "mag", "alt"],
        &ref_cols,
    );
    model.reference = ref_cols;
    model.lever_arm = opts.lever_arm;
    model.fit.eddy_lag_selection = selection;
    Ok((model, fit, rows))
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let table = a.input.load()?;
    let opts = FitOptions {
        eddy_lag: match &a.eddy_lag {
            Some(s) => s.parse()?,
            None if a.convention.trim().eq_ignore_ascii_case("magnav") => EddyLag::None,
            None => EddyLag::Auto,
        },
        split_lines: !a.no_split_lines,
        reference: a.reference.clone(),
        lever_arm: match &a.lever_arm {
            Some(s) => Some(LeverArm {
                arm_m: parse_lever_arm(s)?,
                decimal_year: parse_decimal_year(&a.date)?,
            }),
            None => None,
        },
    };
    if a.series.is_some() && a.method != "kalman" {
        return Err(bad_input!("--series needs --method kalman"));
    }
    if a.field_order.is_some() && a.method != "kalman" {
        return Err(bad_input!("--field-order needs --method kalman"));
    }
    let field_order = a.field_order.unwrap_or(DEFAULT_ORDER);
    let model = match a.method.as_str() {
        "ls" => fit_model(&table, &config(&a)?, &opts)?,
        "kalman" => {
            let ls = config(&a)?;
            if !ORDERS.contains(&field_order) {
                return Err(bad_input!(
                    "--field-order {field_order}: must be in {}–{}",
                    ORDERS.start(),
                    ORDERS.end()
                ));
            }
            let mut cfg = KalmanConfig {
                terms: ls.terms,
                convention: ls.convention,
                bt_scale_nt: ls.bt_scale_nt,
                noise: NoiseModel::calibration_default_for(field_order),
                field_prior: X2Prior {
                    order: field_order,
                    ..X2Prior::default()
                },
                ..KalmanConfig::default()
            };
            cfg.tuning.enabled = a.tune || !(a.no_tune || a.kalman_noise.is_some());
            if let Some(text) = &a.kalman_noise {
                cfg.noise = parse_noise(text, field_order)?;
            }
            cfg.compute_series = a.series.is_some();
            let (model, fit, rows) = fit_model_kalman(&table, &cfg, &opts)?;
            if let Some(path) = &a.series {
                let mut t = table.clone();
                for (name, col) in KALMAN_SERIES.iter().zip(rows) {
                    t.add_column(name, col)?;
                }
                aeromag_io::write_csv(&t, path)?;
                println!(
                    "Kalman series (smoothed field, innovations) written to {}",
                    path.display()
                );
            }
            println!(
                "field model of order {}; noise intensities: q1 = {:.3e} {}, q2 = {:.3e} nT²/m⁵, r = {:.3e} nT² ({})",
                cfg.field_prior.order,
                fit.noise.q1,
                q1_unit(cfg.field_prior.order),
                fit.noise.q2_nt2_per_m5,
                fit.noise.r_nt2,
                match &fit.tuning {
                    Some(t) => format!(
                        "tuned by maximum likelihood, {} filter runs on {} samples",
                        t.evaluations, t.rows
                    ),
                    None => "defaults".into(),
                }
            );
            println!(
                "log-likelihood of the innovations {:.1}; normalised innovation variance {:.2}",
                fit.log_likelihood, fit.normalized_innovation_variance
            );
            model
        }
        m => return Err(bad_input!("--method {m}: use `ls` or `kalman`")),
    };
    let cfg_terms = model.terms.clone();
    std::fs::write(&a.model, model.to_json()?)
        .map_err(|e| anyhow::anyhow!("cannot write model file '{}': {e}", a.model.display()))?;
    println!(
        "fitted {} terms ({}, method {}) on {} rows in {} legs: residual {:.4} nT RMS, condition {:.2e}",
        model.coefficients.len(),
        cfg_terms,
        model.method,
        model.fit.rows,
        model.fit.segments,
        model.fit.residual_rms_nt,
        model.fit.condition
    );
    match cfg_terms.eddy_lags_s() {
        [] => {}
        [tau] => println!("eddy-current lag of the l_ terms: {tau} s"),
        taus => println!(
            "eddy-current lags: {}",
            taus.iter()
                .enumerate()
                .map(|(k, t)| format!("l{}_ terms {t} s", k + 1))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
    println!("{:<8} {:>14} {:>12}", "term", "coefficient", "std");
    for c in &model.coefficients {
        println!("{:<8} {:>14.6} {:>12.3e}", c.name, c.value, c.std);
    }
    println!("model written to {}", a.model.display());
    Ok(())
}
