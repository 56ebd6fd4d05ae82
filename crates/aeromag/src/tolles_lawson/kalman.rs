//! The Kalman method on a flight: the sensor's altitude, ground speed, the
//! first pass that removes the field before the lag choice, the final fit
//! and its per-row series.

use super::calibrate::{CalibrateOptions, EddyLag, fit_rule, model_columns, reduced_mag};
use super::lags::{add_lags_by_kalman_likelihood, choose_terms};
use crate::error::{Error, InFile, Result};
use crate::flight::{Flight, LeverArm, TlInputs, sensor_track_at};
use crate::observer::Notes;
use aeromag_compensation::kalman::altitude::{
    AltitudeSmoothing, AltitudeSource, NavRun, check_down_velocity, smooth_altitude,
};
use aeromag_compensation::kalman::{
    CoefficientPass, DEFAULT_ORDER, KalmanConfig, KalmanFit, KalmanSegment, KalmanSeries,
    NoiseModel, ORDERS, X2Prior, fit_kalman_cancellable, fit_kalman_exact_cancellable,
    ground_speed_from_positions, ground_speed_from_velocity,
};
use aeromag_compensation::model_file::TlModel;
use aeromag_compensation::tolles_lawson::fit_ls::{LsConfig, Segment};
use aeromag_compensation::tolles_lawson::lag_select::LagSelection;
use aeromag_compensation::tolles_lawson::{ExtraRequest, Magnitude};
use aeromag_io::FlightTable;
use std::ops::Range;

/// Settings of the Kalman method that the band-pass fit does not have.
#[derive(Debug, Clone, PartialEq)]
pub struct KalmanOptions {
    /// Order `n` of the along-track field model, `B^h` the `n`-th integral
    /// of white noise ([`ORDERS`], default [`DEFAULT_ORDER`]; 3 is the
    /// thesis' model).
    pub field_order: usize,
    /// Noise intensities (`q₁` in nT²/m^(2n−1), `q₂` in nT²/m⁵, `r` in
    /// nT²); `None`: the documented defaults for the order
    /// ([`NoiseModel::calibration_default_for`]).
    pub noise: Option<NoiseModel>,
    /// Tune the intensities by maximum likelihood of the innovations,
    /// starting from `noise` (default true).
    pub tune: bool,
    /// Compute the per-row series ([`KalmanSeriesColumns`]).
    pub series: bool,
}

impl Default for KalmanOptions {
    fn default() -> Self {
        Self {
            field_order: DEFAULT_ORDER,
            noise: None,
            tune: true,
            series: false,
        }
    }
}

impl KalmanOptions {
    /// The filter configuration for the terms, convention and scale of `ls`
    /// (bad input for an order outside [`ORDERS`] or invalid intensities).
    pub fn config(&self, ls: &LsConfig) -> Result<KalmanConfig> {
        if !ORDERS.contains(&self.field_order) {
            return Err(Error::bad_input(format!(
                "field order {}: must be in {}–{}",
                self.field_order,
                ORDERS.start(),
                ORDERS.end()
            )));
        }
        let noise = match self.noise {
            Some(n) => {
                n.check(self.field_order)?;
                n
            }
            None => NoiseModel::calibration_default_for(self.field_order),
        };
        let mut cfg = KalmanConfig {
            design: ls.design.clone(),
            noise,
            field_prior: X2Prior {
                order: self.field_order,
                ..X2Prior::default()
            },
            compute_series: self.series,
            ..KalmanConfig::default()
        };
        cfg.tuning.enabled = self.tune;
        Ok(cfg)
    }
}

/// Names of the per-row series of the Kalman method, in
/// [`KalmanSeriesColumns`] order.
pub const KALMAN_SERIES: [&str; 5] = [
    "kalman_reading",
    "kalman_compensated",
    "kalman_field",
    "kalman_innovation",
    "kalman_innovation_std",
];

/// The Kalman method's per-row series on the rows of the calibration
/// flight (NaN where a row was not used), nT.
#[derive(Debug, Clone, Default)]
pub struct KalmanSeriesColumns {
    /// The reading with the reference channels removed.
    pub reading: Vec<f64>,
    /// The compensated reading `mag − H1 X̂1`.
    pub compensated: Vec<f64>,
    /// The smoothed external field.
    pub field: Vec<f64>,
    /// The pass-1 innovation.
    pub innovation: Vec<f64>,
    /// Its predicted standard deviation.
    pub innovation_std: Vec<f64>,
}

impl KalmanSeriesColumns {
    /// The series in [`KALMAN_SERIES`] order.
    pub fn columns(&self) -> [&[f64]; 5] {
        [
            &self.reading,
            &self.compensated,
            &self.field,
            &self.innovation,
            &self.innovation_std,
        ]
    }

    /// Add them to `table` under the names of [`KALMAN_SERIES`].
    pub fn add_to(&self, table: &mut FlightTable) -> Result<()> {
        for (name, col) in KALMAN_SERIES.iter().zip(self.columns()) {
            table.add_column(name, col.to_vec())?;
        }
        Ok(())
    }
}

/// What the Kalman method found besides the model.
#[derive(Debug, Clone)]
pub struct KalmanOutcome {
    /// The fit: noise intensities and their tuning, likelihood,
    /// innovation statistics, covariances.
    pub fit: KalmanFit,
    /// The configuration of the final fit (terms with the chosen lags).
    pub config: KalmanConfig,
    /// How the altitude of the vertical-gradient term was obtained.
    pub altitude: AltitudeSource,
    /// The per-row series, when asked for ([`KalmanOptions::series`]).
    pub series: Option<KalmanSeriesColumns>,
}

/// Lags of the Kalman method's first pass (s): a pair that brackets the
/// 0.1–1 s of aircraft skins and frames, so that the field model of that
/// pass does not have to absorb lagged eddy currents.
const PASS1_LAGS_S: [f64; 2] = [0.15, 0.5];

/// The Kalman method on a flight (the Kalman branch of `calibrate`).
pub(super) fn fit_kalman_flight(
    flight: &Flight,
    opts: &CalibrateOptions,
    reference_nt: Option<&[f64]>,
    notes: &mut Notes,
) -> Result<(TlModel, Option<LagSelection>, KalmanOutcome)> {
    let ls = opts.ls_with_extras()?;
    let cfg = opts.kalman.config(&ls)?;
    let file = flight.label();
    let cols =
        TlInputs::of_sensor(flight, &opts.sensor)?.with_extras(flight, ls.design.terms.extras())?;
    let (ref_cols, y) = reduced_mag(flight, &cols, opts, reference_nt)?;
    let cols = cols.with_mag(&y);
    let segs = cols.segments(&fit_rule(opts)).kept;
    let (alt, altitude) = sensor_altitude(flight, &segs, opts.lever_arm.as_ref(), notes)?;
    let speed = ground_speed(flight)?;
    let segments: Vec<KalmanSegment> = segs
        .iter()
        .map(|r| KalmanSegment {
            data: cols.whole().slice(r.clone()),
            alt_m: &alt[r.clone()],
            speed_m_s: &speed[r.clone()],
        })
        .collect();
    // `auto` chooses the lags with the band-pass LS machinery on the same
    // legs, after a first Kalman pass (with the bracketing lags
    // PASS1_LAGS_S) has removed its smoothed field: over geology the
    // band-pass leaves part of the anomaly field in the band, where it hides
    // lagged eddy currents (or buys a spurious slow lag); the field model
    // takes it out first.
    let ls = LsConfig {
        design: cfg.design.clone(),
        ..LsConfig::default()
    };
    // The lags of the extra regressors first, by the band-pass search on
    // the data as recorded: a first pass without them would leave a lagged
    // current's field to its field model and its eddy terms, and the
    // searches below would see what that left.
    let (cfg, ls, extra_lags, requests) = if opts.extra.iter().any(|r| r.lag) {
        let data: Vec<Segment> = segments.iter().map(|k| k.data).collect();
        let pre = choose_terms(&file, &data, &ls, &EddyLag::None, &opts.extra, notes)?;
        let terms = cfg
            .design
            .terms
            .with_extras(pre.terms.extras())
            .in_file(&file)?;
        let design = cfg.design.with_terms(terms);
        let requests: Vec<ExtraRequest> = opts
            .extra
            .iter()
            .map(|r| ExtraRequest {
                lag: false,
                ..r.clone()
            })
            .collect();
        (
            KalmanConfig {
                design: design.clone(),
                ..cfg
            },
            LsConfig { design, ..ls },
            pre.extras,
            requests,
        )
    } else {
        (cfg, ls, Vec::new(), opts.extra.clone())
    };
    let (choice, tuned) = match opts.eddy_lag {
        EddyLag::Auto if cfg.design.terms.has_eddy() => {
            notes.stage("Kalman pass 1: removing the field");
            notes.check_cancelled()?;
            let pass1 = KalmanConfig {
                design: cfg.design.with_terms(
                    cfg.design
                        .terms
                        .with_eddy_lags(&PASS1_LAGS_S)
                        .in_file(&file)?,
                ),
                compute_series: true,
                // Only its coefficients, field and intensities are used:
                // no innovations, the runs on all cores.
                coefficient_pass: CoefficientPass::Augmented,
                ..cfg.clone()
            };
            let first = fit_kalman_cancellable(&segments, &pass1, &mut || notes.cancelled())
                .in_file(&file)?;
            let field = on_rows(y.len(), &segs, &first.series, |s| &s.external_nt);
            let y_field_removed: Vec<f64> = y.iter().zip(&field).map(|(a, b)| a - b).collect();
            let reduced = cols.with_mag(&y_field_removed);
            let rsegs = reduced.segments(&fit_rule(opts)).kept;
            let data: Vec<Segment> = rsegs
                .iter()
                .map(|r| reduced.whole().slice(r.clone()))
                .collect();
            let mut choice = choose_terms(&file, &data, &ls, &opts.eddy_lag, &requests, notes)?;
            choice.terms =
                add_lags_by_kalman_likelihood(&file, &segments, &cfg, choice.terms, &first, notes)?;
            (choice, first.tuning.is_some().then_some(first.noise))
        }
        _ => {
            let data: Vec<Segment> = segments.iter().map(|k| k.data).collect();
            let choice = choose_terms(&file, &data, &ls, &opts.eddy_lag, &requests, notes)?;
            (choice, None)
        }
    };
    let selection = choice.eddy;
    // The final fit's sequential innovations by the joint filter split in
    // two: the field filter on the cores, the coefficients' least squares
    // alongside (the joint filter's results to round-off).
    let mut cfg = KalmanConfig {
        design: cfg.design.with_terms(choice.terms),
        coefficient_pass: CoefficientPass::Split,
        ..cfg
    };
    // Pass 1 searched the likelihood globally (kalman::tuning, several
    // starts) on the same flight with nearly the same terms: the final fit
    // refines its maximum locally.
    if let Some(noise) = tuned {
        cfg.noise = noise;
        cfg.tuning.grid_starts = 0;
    }
    notes.stage("Kalman filter and smoother");
    notes.check_cancelled()?;
    let cancel = &mut || notes.cancelled();
    let fit = match cfg.design.magnitude {
        Magnitude::FirstOrder => fit_kalman_cancellable(&segments, &cfg, cancel),
        Magnitude::Exact => fit_kalman_exact_cancellable(&segments, &cfg, cancel),
    }
    .in_file(&file)?;
    let series = (!fit.series.is_empty()).then(|| {
        let compensated = on_rows(y.len(), &segs, &fit.series, |s| &s.compensated_nt);
        let reading = y
            .iter()
            .zip(&compensated)
            .map(|(v, c)| if c.is_nan() { f64::NAN } else { *v })
            .collect();
        KalmanSeriesColumns {
            reading,
            compensated,
            field: on_rows(y.len(), &segs, &fit.series, |s| &s.external_nt),
            innovation: on_rows(y.len(), &segs, &fit.series, |s| &s.innovation_nt),
            innovation_std: on_rows(y.len(), &segs, &fit.series, |s| &s.innovation_std_nt),
        }
    });
    for w in &fit.warnings {
        notes.warn(w.clone());
    }
    for n in &fit.notes {
        notes.note(n.clone());
    }
    let mut model = fit.to_model(&cfg);
    model.columns = model_columns(
        flight,
        &opts.sensor,
        &["time", "flux_x", "flux_y", "flux_z", "mag", "alt"],
        &ref_cols,
    );
    model.reference = ref_cols;
    model.lever_arm = opts.lever_arm;
    model.fit.eddy_lag_selection = selection.clone();
    model.fit.extra_lag_selection = extra_lags;
    Ok((
        model,
        selection,
        KalmanOutcome {
            fit,
            config: cfg,
            altitude,
            series,
        },
    ))
}

/// The scalar sensor's altitude (m) for the field model's `Δz B_z` term,
/// and how it was obtained.
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
    flight: &Flight,
    segs: &[Range<usize>],
    lever: Option<&LeverArm>,
    notes: &mut Notes,
) -> Result<(Vec<f64>, AltitudeSource)> {
    let time = flight.require("time")?;
    let alt = kalman_needs(
        flight,
        "alt",
        "the altitude (m), through which the field's vertical gradient changes the reading",
    )?;
    let vd = flight.column("vd");
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
        notes.warn(format!(
            "{}: `vd` does not follow the change of `alt` (slope {:.2}, correlation {:.2} \
             over 0.02–0.5 Hz; a down velocity in m/s gives ≈ 1, 1): the altitude is low-passed \
             instead of blended with it",
            flight.label(),
            c.slope,
            c.correlation
        ));
    }
    let mut clean = alt.to_vec();
    let mut how = AltitudeSource::AsRecorded;
    // Each run on its own (on the cores), written back in order.
    let smoothed =
        aeromag_core::parallel::parallel_map(runs.len(), aeromag_core::parallel::threads(), |i| {
            smooth_altitude(&runs[i], use_vd, &cfg)
        });
    for (r, (s, h)) in segs.iter().zip(smoothed) {
        clean[r.clone()].copy_from_slice(&s);
        if how == AltitudeSource::AsRecorded {
            how = h;
        }
    }
    match (how, check) {
        (AltitudeSource::Blended(fc), Some(c)) => notes.note(format!(
            "altitude of the vertical-gradient term: `alt` blended with the integrated `vd` \
             (crossover {fc} Hz; they agree with slope {:.3}, correlation {:.3})",
            c.slope, c.correlation
        )),
        (AltitudeSource::LowPass(fc), _) => notes.note(format!(
            "altitude of the vertical-gradient term: `alt` low-passed at {fc} Hz{}",
            if vd.is_none() {
                " (no `vd` column to blend with)"
            } else {
                ""
            }
        )),
        _ => {}
    }
    let Some(lever) = lever else {
        return Ok((clean, how));
    };
    let [_, _, sensor_alt] = sensor_track_at(flight, &clean, lever.arm_m)?;
    Ok((sensor_alt, how))
}

/// Ground speed (m/s) from `vn`, `ve` when present, else from the positions.
pub(crate) fn ground_speed(flight: &Flight) -> Result<Vec<f64>> {
    Ok(match (flight.column("vn"), flight.column("ve")) {
        (Some(vn), Some(ve)) => ground_speed_from_velocity(vn, ve),
        _ => {
            let why = "the position (deg), whose ground speed sets how fast the external field changes (or vn, ve)";
            ground_speed_from_positions(
                flight.require("time")?,
                kalman_needs(flight, "lat", why)?,
                kalman_needs(flight, "lon", why)?,
            )
        }
    })
}

/// The column `name` the Kalman method (and `observability`, which runs
/// it) needs, for `why`: a flight without it was told only "required
/// column 'alt' is missing" (MagNav's TL test arrays have no positions),
/// now what it is for and that `--method ls` fits without it.
fn kalman_needs<'f>(flight: &'f Flight, name: &str, why: &str) -> Result<&'f [f64]> {
    if flight.resolve(name).is_none() {
        return Err(Error::bad_file(
            flight.label(),
            format!(
                "has no `{name}` column: the Kalman method (which `observability` runs too) needs {why}; \
                 map it with --columns {name}=NAME, or fit with --method ls, which does not"
            ),
        ));
    }
    Ok(flight.require(name)?)
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
