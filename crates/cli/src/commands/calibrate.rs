//! `aeromag calibrate`: fit a Tolles-Lawson model on a calibration flight
//! (library: [`aeromag::calibrate`]).

use crate::args::{self, Band, parsed};
use crate::input::InputArgs;
use crate::progress::Bars;
use aeromag::compensation::kalman::{NoiseModel, q1_unit};
use aeromag::compensation::tolles_lawson::{Convention, Design, ExtraRequest, Magnitude, TermSet};
use aeromag::{
    CalibrateOptions, CalibrateSettings, EddyLag, ExtraSelection, Method, ReferenceChannels,
    calibrate,
};
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
/// Extra regressors (--extra cur_strb,cur_flap:lag): recorded channels,
/// typically the currents of on-board equipment, enter as the channel times
/// the three direction cosines of the field (a current loop's field is fixed
/// in the airframe; its effect on the total field turns with the heading).
/// `NAME:lag` also tries the channel through a first-order lag (a field that
/// follows its current late: eddy currents in the structure around the
/// load), with τ from 0.05 to 2 s, kept by the same likelihood-ratio test.
///
/// Several scalar sensors (--mag mag_1_uc,mag_3_uc,mag_4_uc, with --vector
/// one prefix for all or one per sensor): one model per sensor, written as
/// one multi-sensor model file that `compensate` applies to every sensor
/// (columns mag_N_comp, mag_N_interf, and mag_N_grad = mag_N_comp −
/// first sensor's). --reference-sensor mag_1_uc: that sensor (the tail
/// stinger) is fitted first and its compensated reading is the other
/// sensors' external-field reference over the whole flight: they are fitted
/// to mag_N − reference on every row, unfiltered, with a bias term (a
/// column that is already compensated, such as mag_1_c, serves as it is).
///
/// --lever-arm X,Y,Z: the scalar sensor's position from the navigation point
/// (body frame, m); the `igrf` reference, computed at the navigation point,
/// is then moved to the sensor with the main field's gradient.
///
/// Example:
///   aeromag calibrate --input cal.csv --model model.json
///   aeromag calibrate --input cal.csv --model m.json --terms p3,i6,e9 --convention magnav --lambda 0.01
///   aeromag calibrate --input cal.csv --model model.json --compensated cal_comp.csv
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct Args {
    #[command(flatten)]
    input: InputArgs,
    /// Where to write the model file (JSON).
    #[arg(long, value_name = "MODEL.json")]
    model: PathBuf,
    /// Also write the calibration flight compensated by the fitted model to
    /// this CSV (Geosoft XYZ for `.xyz`, HDF5 for `.h5`): what `aeromag compensate --model MODEL.json` writes for the
    /// same input (every input column plus the interference, compensated
    /// and flag columns), from the flight read once.
    #[arg(long, value_name = "OUT.csv")]
    compensated: Option<PathBuf>,
    /// Fitting method: `ls` (band-pass least squares) or `kalman` (Kalman
    /// filter and smoother with a stochastic model of the external field;
    /// needs `alt` and ground speed from `vn`,`ve` or positions; the
    /// altitude of the vertical-gradient term is cleaned of GNSS noise,
    /// blended with the integrated down velocity `vd` when that is recorded
    /// and agrees with `alt`, else low-passed at 1 Hz).
    #[arg(long, value_enum, default_value_t = Method::default())]
    method: Method,
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
    #[arg(long, value_name = "Q1,Q2,R", value_parser = noise)]
    kalman_noise: Option<NoiseModel>,
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
    /// Extra regressors: recorded channels times the direction cosines,
    /// `NAME` or `NAME:lag` (also through a fitted lag), comma-separated,
    /// e.g. `cur_strb,cur_flap:lag`. SGL channels are found in either
    /// naming (`cur_com_1` = the XYZ export's `CUR_COM1`); the model keeps
    /// the MagNav name.
    #[arg(long, value_name = "NAME[:lag],…", value_parser = extras)]
    extra: Option<Extras>,
    /// Which of the --extra channels are kept, per sensor: `test` (those the
    /// flight shows to matter, by a likelihood-ratio test; the others are
    /// dropped with a note) or `all`.
    #[arg(long, value_enum, default_value_t = ExtraSelection::Test)]
    extra_selection: ExtraSelection,
    /// How the interference vector becomes the scalar interference:
    /// `first-order` (the Tolles-Lawson projection) or `exact` (|B + ΔB| −
    /// |B|, fitted by Gauss–Newton; for sensors whose interference exceeds
    /// about 1 % of the field, where the projection leaves nT; either method).
    #[arg(long, value_enum, default_value_t = Magnitude::FirstOrder)]
    magnitude: Magnitude,
    /// Reference-sensor mode: the scalar sensor (one of --mag) or compensated
    /// column whose compensated reading is the other sensors'
    /// external-field reference, e.g. `mag_1_uc`. The other sensors are
    /// fitted by least squares on every row whatever --method (the
    /// reference removes the external field the Kalman method models).
    #[arg(long, value_name = "NAME")]
    reference_sensor: Option<String>,
    /// Term groups: p3, i6 or i5, e9 or e8, bias (comma-separated).
    #[arg(long, value_parser = terms, default_value_t = Design::default().terms)]
    terms: TermSet,
    /// Derivative convention of the eddy terms: physical (nT/s) or magnav
    /// (MagNav.jl create_TL_A: per-sample central difference).
    #[arg(long, value_enum, ignore_case = true, default_value_t = Design::default().convention)]
    convention: Convention,
    /// Ridge parameter λ ≥ 0 (LS method) [default: 0].
    #[arg(long, value_parser = args::non_negative)]
    lambda: Option<f64>,
    /// Pass band LO,HI in Hz, or `none` to fit unfiltered data (LS method)
    /// [default: 0.1,0.9].
    #[arg(long, value_name = "LO,HI|none")]
    band: Option<Band>,
    /// Samples trimmed at each end of each filtered leg (LS method)
    /// [default: 20].
    #[arg(long)]
    trim: Option<usize>,
    /// Scale of the induced and eddy columns, nT.
    #[arg(long, value_parser = args::positive, default_value_t = Design::default().bt_scale_nt)]
    bt_scale: f64,
    /// Treat the whole file as one leg (ignore the `line` column).
    #[arg(long)]
    no_split_lines: bool,
    /// Known external-field channels subtracted from `mag` before the fit:
    /// `auto` (the `diurnal` and `igrf` columns when present; `igrf`
    /// derived as mag_1_dc − mag_1_igrf, MagNav's way, when a file has
    /// those instead; printed), `none`
    /// (MagNav.jl's way), or a comma-separated list of columns.
    #[arg(long, value_parser = parsed::<ReferenceChannels>, default_value_t = ReferenceChannels::default())]
    reference: ReferenceChannels,
    /// Eddy-current lags of the lagged eddy terms (l9): `auto` (chosen
    /// from the flight by a likelihood-ratio test), `none` (classical
    /// Tolles-Lawson), or lags in seconds, e.g. `0.3,0.8`. Default: `auto`,
    /// but `none` with --convention magnav (MagNav.jl's model exactly).
    #[arg(long, value_name = "auto|none|TAU,…", value_parser = parsed::<EddyLag>)]
    eddy_lag: Option<EddyLag>,
    /// Scalar sensor position X,Y,Z (m, body frame: x forward, y right,
    /// z down) from the navigation point whose position the `igrf` column
    /// was computed at; the reference is then moved to the sensor with the
    /// main field's gradient (needs lat, lon, alt, roll, pitch, yaw).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = args::xyz)]
    lever_arm: Option<[f64; 3]>,
    /// Date of the flight (YYYY-MM-DD) for the main-field gradient used with
    /// --lever-arm (the gradient changes < 0.3 % per year).
    #[arg(long, default_value = "2025-01-01", value_parser = args::decimal_year)]
    date: f64,
}

fn terms(s: &str) -> Result<TermSet, String> {
    TermSet::parse(s).map_err(|e| e.to_string())
}

/// The `--extra` list.
#[derive(Debug, Clone)]
struct Extras(Vec<ExtraRequest>);

fn extras(s: &str) -> Result<Extras, String> {
    ExtraRequest::parse_list(s)
        .map(Extras)
        .map_err(|e| e.to_string())
}

/// `Q1,Q2,R` noise intensities (checked by the library for its order).
fn noise(s: &str) -> Result<NoiseModel, String> {
    let v = args::numbers(s, 3)?;
    Ok(NoiseModel {
        q1: v[0],
        q2_nt2_per_m5: v[1],
        r_nt2: v[2],
    })
}

/// The library's options from the flags.
fn options(a: &Args) -> anyhow::Result<CalibrateOptions> {
    let settings = CalibrateSettings {
        method: a.method,
        terms: Some(a.terms.clone()),
        convention: Some(a.convention),
        ridge_lambda: a.lambda,
        band_hz: a.band.as_ref().map(|b| b.0),
        trim: a.trim,
        bt_scale_nt: Some(a.bt_scale),
        no_split_lines: a.no_split_lines,
        reference: a.reference.clone(),
        eddy_lag: a.eddy_lag.clone(),
        lever_arm_m: a.lever_arm,
        decimal_year: Some(a.date),
        tune: match (a.tune, a.no_tune) {
            (true, _) => Some(true),
            (_, true) => Some(false),
            _ => None,
        },
        kalman_noise: a.kalman_noise,
        field_order: a.field_order,
        series: a.series.is_some(),
        extra: a.extra.clone().map(|x| x.0).unwrap_or_default(),
        magnitude: Some(a.magnitude),
        extra_selection: a.extra_selection,
    };
    Ok(settings.options()?)
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let opts = options(&a)?;
    if a.compensated.as_ref() == Some(&a.model) {
        anyhow::bail!(aeromag::Error::bad_input(
            "--compensated and --model name the same file"
        ));
    }
    crate::output::check_files(
        std::iter::once(a.model.as_path())
            .chain(a.series.as_deref())
            .chain(a.compensated.as_deref()),
        &[a.input.path()],
    )?;
    crate::output::check_tables(a.series.iter().chain(&a.compensated).map(|p| p.as_path()))?;
    if a.input.several_sensors() || a.reference_sensor.is_some() {
        return run_sensors(&a, &opts);
    }
    // Only the canonical columns and named reference channels are read
    // (an HDF5 flight's other fields stay on disk, a text file's are not
    // parsed).
    let mut extra: Vec<&str> = match &a.reference {
        aeromag::ReferenceChannels::Columns(c) => c.iter().map(String::as_str).collect(),
        _ => Vec::new(),
    };
    extra.extend(opts.extra.iter().map(|r| r.channel.as_str()));
    // The simulator's manoeuvre codes, when present, split the table of
    // contributions by manoeuvre.
    extra.push("manoeuvre");
    // The compensated flight has every input column.
    let flight = match &a.compensated {
        Some(_) => a.input.load()?,
        None => a.input.load_canonical(&extra)?,
    };
    print_inputs(&flight, &opts, None, false)?;
    let cal = calibrate(&flight, &opts, &mut Bars::new())?;
    let model = &cal.model;
    if let Some(k) = &cal.kalman {
        if let (Some(path), Some(series)) = (&a.series, &k.series) {
            let mut t = flight.table().clone();
            series.add_to(&mut t)?;
            aeromag::io::write_table(&t, path)?;
            println!(
                "Kalman series (smoothed field, innovations) written to {}",
                path.display()
            );
        }
        let (fit, order) = (&k.fit, k.config.field_prior.order);
        println!(
            "field model of order {order}; noise intensities: q1 = {:.3e} {}, q2 = {:.3e} nT²/m⁵, r = {:.3e} nT² ({})",
            fit.noise.q1,
            q1_unit(order),
            fit.noise.q2_nt2_per_m5,
            fit.noise.r_nt2,
            match &fit.tuning {
                Some(t) => format!(
                    "tuned by maximum likelihood, {} filter runs on {} samples",
                    t.evaluations, t.rows
                ),
                None if fit.noise == NoiseModel::calibration_default_for(order) =>
                    "defaults".into(),
                None => "as given".into(),
            }
        );
        println!(
            "log-likelihood of the innovations {:.1}; normalised innovation variance {:.2}",
            fit.log_likelihood, fit.normalized_innovation_variance
        );
    }
    aeromag::io::atomic::write_file(&a.model, model.to_json()?)
        .map_err(|e| aeromag::Error::write(&a.model, e))?;
    println!(
        "fitted {} terms ({}, method {}) on {} rows in {} legs: residual {:.4} nT RMS, condition {:.2e}",
        model.coefficients.len(),
        model.design.terms,
        model.method,
        model.fit.rows,
        model.fit.segments,
        model.fit.residual_rms_nt,
        model.fit.condition
    );
    match model.design.terms.eddy_lags_s() {
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
    for x in model.design.terms.extras() {
        match x.lag_s {
            Some(tau) => println!(
                "extra regressor {}, and through a lag of {tau:.3} s",
                x.channel
            ),
            None => println!("extra regressor {}", x.channel),
        }
    }
    println!("{:<8} {:>14} {:>12}", "term", "coefficient", "std");
    for c in &model.coefficients {
        println!("{:<8} {:>14.6} {:>12.3e}", c.name, c.value, c.std);
    }
    let parts = cal.contributions(&flight)?;
    println!("interference by part on this flight (RMS about each manoeuvre's mean, nT):");
    println!(
        "{:<11} {:>6} {:>10} {:>10} {:>10} {:>10} {:>10}",
        "group", "rows", "permanent", "induced", "eddy", "currents", "total"
    );
    for g in &parts.groups {
        println!(
            "{:<11} {:>6} {:>10.3} {:>10.3} {:>10.3} {:>10.3} {:>10.3}",
            g.group, g.rows, g.permanent_nt, g.induced_nt, g.eddy_nt, g.currents_nt, g.total_nt
        );
    }
    println!("model written to {}", a.model.display());
    if let Some(out) = &a.compensated {
        use aeromag::Compensator;
        let compensated = model.compensate(&flight)?;
        let detail = crate::output::model_detail(model, "");
        crate::output::write_compensated(flight, compensated, out, &a.model, &detail)?;
    }
    Ok(())
}

/// What the fit reads that the file's names do not say: the fluxgate the
/// MagNav preset chose for flux_x/y/z (SGL files carry four) and the
/// reference channels subtracted from the scalar reading (a derived `igrf`
/// named with its fields).
fn print_inputs(
    flight: &aeromag::Flight,
    opts: &CalibrateOptions,
    reference_sensor: Option<&str>,
    vector_chosen: bool,
) -> anyhow::Result<()> {
    if let Some(v) = flight.preset_vector().filter(|_| !vector_chosen) {
        println!(
            "vector magnetometer: flux_x, flux_y, flux_z = {v} (the first complete one; choose with --vector)"
        );
    }
    let sensor = reference_sensor
        .map(|r| format!(" (the sensors other than {r}: {r} compensated)"))
        .unwrap_or_default();
    println!(
        "reference subtracted from the scalar reading: {}{sensor}",
        opts.reference.describe(flight)?
    );
    Ok(())
}

/// Several sensors (or the reference-sensor mode): one model each.
fn run_sensors(a: &Args, opts: &CalibrateOptions) -> anyhow::Result<()> {
    if a.series.is_some() {
        anyhow::bail!(aeromag::Error::bad_input(
            "--series is for one sensor; calibrate the sensors one by one to get it"
        ));
    }
    let flight = a.input.load()?;
    let set = aeromag::SensorSet {
        sensors: a.input.sensor_columns(&flight)?,
        reference: a.reference_sensor.clone(),
    };
    print_inputs(
        &flight,
        opts,
        a.reference_sensor.as_deref(),
        a.input.vector.is_some(),
    )?;
    let cal = aeromag::calibrate_sensors(&flight, &set, opts, &mut Bars::new())?;
    aeromag::io::atomic::write_file(&a.model, cal.model.to_json()?)
        .map_err(|e| aeromag::Error::write(&a.model, e))?;
    println!(
        "{:<10} {:<12} {:<24} {:>6} {:>8} {:>13} {:>10}",
        "sensor", "column", "vector", "terms", "rows", "residual_nT", "reference"
    );
    for s in &cal.model.sensors {
        let m = &s.model;
        println!(
            "{:<10} {:<12} {:<24} {:>6} {:>8} {:>13.4} {:>10}",
            s.name,
            s.mag,
            s.flux.join(","),
            m.coefficients.len(),
            m.fit.rows,
            m.fit.residual_rms_nt,
            s.reference_sensor.as_deref().unwrap_or("-")
        );
    }
    println!(
        "{} sensor models written to {}",
        cal.model.sensors.len(),
        a.model.display()
    );
    if let Some(out) = &a.compensated {
        use aeromag::CompensateSensors;
        let compensated = cal.model.compensate(&flight)?;
        crate::output::write_compensated_sensors(
            flight,
            compensated,
            out,
            &a.model,
            cal.model.sensors.len(),
        )?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use aeromag::compensation::tolles_lawson::fit_ls::LsConfig;

    /// The LS settings are options (so that the Kalman method can refuse
    /// them when given); the defaults their help states are the library's.
    #[test]
    fn stated_ls_defaults_are_the_librarys() {
        let cmd = <Args as clap::Args>::augment_args(clap::Command::new("calibrate"));
        let help = |id: &str| {
            cmd.get_arguments()
                .find(|a| a.get_id() == id)
                .and_then(|a| a.get_help())
                .map(|h| h.to_string())
                .unwrap()
        };
        let ls = LsConfig::default();
        for (id, value) in [
            ("lambda", ls.lambda.to_string()),
            ("band", Band(ls.band_hz).to_string()),
            ("trim", ls.trim.to_string()),
        ] {
            let h = help(id);
            assert!(h.contains(&format!("[default: {value}]")), "{id}: {h}");
        }
    }
}
