//! `calibrate`: fit a Tolles-Lawson model on a calibration flight by band-pass
//! least squares or by the Kalman method.

use super::kalman::{KalmanOptions, KalmanOutcome, fit_kalman_flight};
use super::lags::{TermChoice, choose_terms, test_extra_channels};
use crate::error::{Error, InFile, Result};
use crate::flight::{Flight, LeverArm, ReferenceChannels, SegmentRule, SensorColumns, TlInputs};
use crate::flight::{reduced, reference_sum};
use crate::observer::{Note, Notes, Observer};
use aeromag_compensation::model_file::{
    Coefficient, FitStats, LsSettings, MODEL_FORMAT, MethodSettings, TL_KIND, TlModel,
};
use aeromag_compensation::tolles_lawson::extra_select::ChannelSelection;
use aeromag_compensation::tolles_lawson::fit_ls::{LsConfig, Segment, fit_band_pass_ls};
use aeromag_compensation::tolles_lawson::lag_select::{
    DEFAULT_SELECTION_BLOCK, LagSelection, within_budget,
};
use aeromag_compensation::tolles_lawson::{Convention, ExtraRequest, ExtraTerm};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// How the coefficients are estimated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Method {
    /// Band-pass least squares (Butterworth, zero-phase, legs trimmed): the
    /// industry and MagNav.jl baseline (spec `compensation.md`, Method 1).
    #[default]
    Ls,
    /// The Kalman filter and smoother with a stochastic model of the
    /// external field along the track (the thesis' method, Method 2).
    Kalman,
}

impl Method {
    /// `ls` or `kalman`, as in the model file and the command line.
    pub fn name(self) -> &'static str {
        match self {
            Method::Ls => "ls",
            Method::Kalman => "kalman",
        }
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Method {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s.trim() {
            "ls" => Ok(Method::Ls),
            "kalman" => Ok(Method::Kalman),
            m => Err(Error::bad_input(format!(
                "method `{m}`: use `ls` or `kalman`"
            ))),
        }
    }
}

/// How the lagged eddy-current terms (`l9`) are chosen.
///
/// ```
/// use aeromag::EddyLag;
/// assert_eq!("auto".parse::<EddyLag>()?, EddyLag::Auto);
/// assert_eq!("0.3,0.8".parse::<EddyLag>()?, EddyLag::Fixed(vec![0.3, 0.8]));
/// assert!("-1".parse::<EddyLag>().is_err());
/// assert!("".parse::<EddyLag>().is_err());
/// # Ok::<(), aeromag::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum EddyLag {
    /// The classical model, no lagged terms.
    None,
    /// Up to two lags of
    /// [`DEFAULT_LAG_GRID_S`](aeromag_compensation::tolles_lawson::lag_select::DEFAULT_LAG_GRID_S),
    /// kept when a likelihood-ratio test finds them significant.
    Auto,
    /// These lags, s.
    Fixed(Vec<f64>),
}

impl EddyLag {
    /// The default for a derivative convention: `none` with MagNav's (its
    /// model exactly), `auto` otherwise.
    pub fn default_for(convention: Convention) -> Self {
        match convention {
            Convention::MagNav => EddyLag::None,
            _ => EddyLag::Auto,
        }
    }
}

impl FromStr for EddyLag {
    type Err = Error;
    /// `auto`, `none` or lags in seconds such as `0.3,0.8`. Empty is bad
    /// input (an unset shell variable, `--eddy-lag=$LAG`, meant `none`).
    fn from_str(s: &str) -> Result<Self> {
        match s.trim() {
            "auto" => Ok(EddyLag::Auto),
            "none" => Ok(EddyLag::None),
            "" => Err(Error::bad_input(
                "eddy lag is empty: give auto, none or lags in seconds such as 0.3,0.8",
            )),
            list => list
                .split(',')
                .map(|t| match t.trim().parse::<f64>() {
                    Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
                    _ => Err(Error::bad_input(format!(
                        "eddy lag `{s}`: expected auto, none or lags in seconds > 0 such as 0.3,0.8"
                    ))),
                })
                .collect::<Result<Vec<f64>>>()
                .map(EddyLag::Fixed),
        }
    }
}

/// Whether the extra regressors asked for are tested.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum ExtraSelection {
    /// Keep the channels the flight shows to matter: backward elimination
    /// by the likelihood-ratio test
    /// ([`aeromag_compensation::tolles_lawson::extra_select`]); the others
    /// are dropped with a note.
    #[default]
    Test,
    /// Keep every channel asked for.
    All,
}

impl FromStr for ExtraSelection {
    type Err = Error;
    /// `test` or `all`.
    fn from_str(s: &str) -> Result<Self> {
        match s.trim() {
            "test" => Ok(ExtraSelection::Test),
            "all" => Ok(ExtraSelection::All),
            m => Err(Error::bad_input(format!(
                "extra selection `{m}`: use `test` or `all`"
            ))),
        }
    }
}

/// Everything `calibrate` is told besides the flight.
#[derive(Debug, Clone, PartialEq)]
pub struct CalibrateOptions {
    /// Band-pass LS or the Kalman method.
    pub method: Method,
    /// Terms, derivative convention and `bt_scale` of both methods, and the
    /// band-pass settings of the LS method (band, order, trim, ridge λ).
    pub ls: LsConfig,
    /// Settings of the Kalman method.
    pub kalman: KalmanOptions,
    /// The lagged eddy-current terms.
    pub eddy_lag: EddyLag,
    /// Split the flight into legs at changes of `line`.
    pub split_lines: bool,
    /// Known external-field channels subtracted from `mag` first.
    pub reference: ReferenceChannels,
    /// The scalar sensor's lever arm from the navigation point: moves the
    /// `igrf` reference to the sensor and, for the Kalman method, the
    /// altitude of the vertical-gradient term.
    pub lever_arm: Option<LeverArm>,
    /// Extra regressors (`--extra cur_strb,cur_flap:lag`): recorded
    /// channels times the direction cosines, with a lag chosen on the
    /// flight for those asked with `:lag`
    /// ([`aeromag_compensation::tolles_lawson::terms`]).
    pub extra: Vec<ExtraRequest>,
    /// Whether [`Self::extra`] is tested channel by channel.
    pub extra_selection: ExtraSelection,
    /// The scalar and vector magnetometers fitted (default: the canonical
    /// `mag` and `flux_x/y/z`).
    pub sensor: SensorColumns,
}

impl Default for CalibrateOptions {
    /// Band-pass LS with the 16 observable terms (`p3,i5,e8`), the physical
    /// convention, 0.1–0.9 Hz, lags `auto`, references `auto`, legs split
    /// at lines, no lever arm.
    fn default() -> Self {
        Self {
            method: Method::Ls,
            ls: LsConfig::default(),
            kalman: KalmanOptions::default(),
            eddy_lag: EddyLag::Auto,
            split_lines: true,
            reference: ReferenceChannels::Auto,
            lever_arm: None,
            extra: Vec::new(),
            extra_selection: ExtraSelection::Test,
            sensor: SensorColumns::default(),
        }
    }
}

impl CalibrateOptions {
    /// The Kalman method with its defaults.
    pub fn kalman() -> Self {
        Self {
            method: Method::Kalman,
            ..Self::default()
        }
    }

    /// The LS settings with the extra regressors of [`Self::extra`] in the
    /// terms, without lags (the lags are chosen on the flight); without
    /// requests, the terms' own extra regressors (with their lags) stay.
    pub(super) fn ls_with_extras(&self) -> Result<LsConfig> {
        if self.extra.is_empty() {
            return Ok(self.ls.clone());
        }
        let extras: Vec<ExtraTerm> = self
            .extra
            .iter()
            .map(|r| ExtraTerm::new(r.channel.clone()))
            .collect();
        let terms = self
            .ls
            .design
            .terms
            .with_extras(&extras)
            .map_err(|e| Error::bad_input(format!("extra regressors: {e}")))?;
        Ok(LsConfig {
            design: self.ls.design.with_terms(terms),
            ..self.ls.clone()
        })
    }
}

/// The result of [`calibrate`]: the model and what the fit found on the way.
#[derive(Debug, Clone)]
pub struct Calibration {
    /// The model (what `aeromag calibrate` writes as the model file).
    pub model: TlModel,
    /// How `auto` chose the eddy-current lags (also in the model file).
    pub lag_selection: Option<LagSelection>,
    /// The Kalman method's fit details (noise intensities, tuning,
    /// likelihood, series), with that method.
    pub kalman: Option<KalmanOutcome>,
    /// Notes and warnings raised while fitting, in order.
    pub notes: Vec<Note>,
}

/// Fit a Tolles-Lawson model on a calibration flight.
///
/// Reads `time`, `flux_x/y/z`, `mag` (and `line`, the reference channels,
/// and for the Kalman method `alt`, ground speed from `vn`, `ve` or the
/// positions, `vd` when recorded); never a `true_` column. Progress and notes
/// go to `observer`; the notes are also kept in the result.
///
/// ```
/// use aeromag::simulate::{ScenarioKind, simulate_flight};
/// use aeromag::{CalibrateOptions, ModelFile, Silent, calibrate};
/// // A flight from a file is `Flight::read("cal/calibration.csv")?`.
/// let flight = simulate_flight(ScenarioKind::Calibration, None, Some(1))?;
/// let cal = calibrate(&flight, &CalibrateOptions::kalman(), &mut Silent)?;
/// assert_eq!(cal.model.method.name(), "kalman");
/// for note in &cal.notes {
///     println!("{note}"); // warnings are data, the library prints nothing
/// }
/// let path = std::env::temp_dir().join(format!("aeromag-doc-model-{}.json", std::process::id()));
/// cal.model.write(&path)?; // the file `aeromag calibrate --method kalman` writes
/// # std::fs::remove_file(&path).ok();
/// # Ok::<(), aeromag::Error>(())
/// ```
pub fn calibrate(
    flight: &Flight,
    opts: &CalibrateOptions,
    observer: &mut dyn Observer,
) -> Result<Calibration> {
    let mut notes = Notes::new(observer);
    calibrate_with(flight, opts, None, &mut notes)
}

/// [`calibrate`] with the series `reference_nt` (nT) subtracted from the
/// scalar reading besides the reference channels: the studies' oracle
/// fits, which subtract the simulation's true external field to give the
/// best a model family can do (a bound, not an estimator; truth columns
/// are refused as inputs, [`Flight::measured`]).
pub(crate) fn calibrate_against(
    flight: &Flight,
    opts: &CalibrateOptions,
    reference_nt: &[f64],
    observer: &mut dyn Observer,
) -> Result<Calibration> {
    let mut notes = Notes::new(observer);
    calibrate_with(flight, opts, Some(reference_nt), &mut notes)
}

/// [`calibrate`] with `reference_nt` (a series subtracted from the scalar
/// reading besides the reference channels: the compensated reading of a
/// reference sensor), notes into `notes`.
pub(super) fn calibrate_with(
    flight: &Flight,
    opts: &CalibrateOptions,
    reference_nt: Option<&[f64]>,
    notes: &mut Notes,
) -> Result<Calibration> {
    let before = notes.len();
    let tested;
    let (opts, chosen) = match opts.extra_selection {
        ExtraSelection::Test if !opts.extra.is_empty() => {
            // The lags are chosen and the channels tested once; the fit
            // takes the kept channels with their lags as fixed terms.
            let (choice, sel) = select_channels(flight, opts, reference_nt, notes)?;
            let all = choice.terms.extras();
            let kept: Vec<ExtraTerm> = sel.kept.iter().map(|&k| all[k].clone()).collect();
            let terms = choice
                .terms
                .with_extras(&kept)
                .map_err(|e| Error::bad_input(format!("extra regressors: {e}")))?;
            tested = CalibrateOptions {
                extra: Vec::new(),
                eddy_lag: EddyLag::Fixed(terms.eddy_lags_s().to_vec()),
                ls: LsConfig {
                    design: opts.ls.design.with_terms(terms),
                    ..opts.ls.clone()
                },
                ..opts.clone()
            };
            let extras = choice
                .extras
                .into_iter()
                .filter(|x| kept.iter().any(|k| k.channel == x.channel))
                .collect();
            (&tested, Some((choice.eddy, extras, sel)))
        }
        _ => (opts, None),
    };
    let (mut model, mut lag_selection, kalman) = match opts.method {
        Method::Ls => {
            let (model, sel) = fit_ls_flight(flight, opts, reference_nt, notes)?;
            (model, sel, None)
        }
        Method::Kalman => {
            let (model, sel, outcome) = fit_kalman_flight(flight, opts, reference_nt, notes)?;
            (model, sel, Some(outcome))
        }
    };
    model.fit.sample_interval_s = Some(1.0 / flight.sample_rate_hz()?);
    // With the channels tested, the lags were chosen by that step (the
    // Kalman method then takes them as fixed, without its own searches).
    if let Some((eddy, extras, sel)) = chosen {
        lag_selection = eddy;
        model.fit.eddy_lag_selection = lag_selection.clone();
        model.fit.extra_lag_selection = extras;
        model.fit.extra_channel_selection = Some(sel);
    }
    Ok(Calibration {
        model,
        lag_selection,
        kalman,
        notes: notes.since(before),
    })
}

/// The second-order term above which [`second_order_note`] recommends the
/// exact magnitude, nT (peak to peak over the flight).
pub const SECOND_ORDER_NOTE_NT: f64 = 0.1;

/// Rows [`second_order_note`] evaluates at most: a longer flight is
/// sampled as the lag search samples it (`within_budget`: blocks spread
/// evenly over every segment, or whole short legs spread over the
/// flight), since the remainder needs the interference vector
/// (three evaluations of the design) and follows the attitude and heading,
/// which a tenth of a long flight samples fully. On a 10⁷-row flight the
/// note cost as much as the fit.
pub const SECOND_ORDER_NOTE_ROWS: usize = 200_000;

/// Say when the first-order projection is not enough: the peak-to-peak of
/// its second-order remainder over the flight's rows (at most
/// [`SECOND_ORDER_NOTE_ROWS`] of them), under the fitted coefficients (the
/// vector model they imply), when it exceeds [`SECOND_ORDER_NOTE_NT`].
pub(super) fn second_order_note(
    design: &aeromag_compensation::tolles_lawson::Design,
    coef: &[f64],
    segments: &[Segment],
    notes: &mut Notes,
) {
    use super::compensate::Span;
    use aeromag_compensation::tolles_lawson::Magnitude;
    if design.magnitude != Magnitude::FirstOrder {
        return;
    }
    let sample = within_budget(segments, SECOND_ORDER_NOTE_ROWS, DEFAULT_SELECTION_BLOCK);
    // The sampled blocks on the cores (short blocks take one thread each);
    // their lowest and highest values are the same in any order.
    let span = aeromag_core::parallel::parallel_map(
        sample.len(),
        aeromag_core::parallel::threads(),
        |i| {
            let mut span = Span::default();
            span.add(design, coef, &sample[i]);
            span
        },
    )
    .into_iter()
    .fold(Span::default(), Span::merge);
    if span.range() > SECOND_ORDER_NOTE_NT {
        let rows: usize = segments.iter().map(|s| s.time.len()).sum();
        let over = if rows > SECOND_ORDER_NOTE_ROWS {
            format!("over {SECOND_ORDER_NOTE_ROWS} rows sampled from this flight")
        } else {
            "over this flight".to_string()
        };
        notes.note(format!(
            "the second-order term of the projection varies by {:.2} nT {over} (interference ≳ 1 % of the field): --magnitude exact fits |B + ΔB| − |B|",
            span.range()
        ));
    }
}

/// The reference channels of `opts` and `mag` reduced by their sum and by
/// `reference_nt` when given.
pub(super) fn reduced_mag<'a>(
    flight: &Flight,
    inputs: &TlInputs<'a>,
    opts: &CalibrateOptions,
    reference_nt: Option<&[f64]>,
) -> Result<(Vec<String>, std::borrow::Cow<'a, [f64]>)> {
    check_sensors_vary(flight, inputs, &opts.sensor)?;
    check_calibration_rate(flight)?;
    let ref_cols = opts.reference.resolve(flight)?;
    for c in &ref_cols {
        // `--mag igrf` with the automatic references subtracted the
        // reading from itself: the fit saw the diurnal alone.
        if std::ptr::eq(flight.measured(c)?, inputs.mag) {
            return Err(Error::bad_input(format!(
                "reference channel `{c}` is the scalar reading itself (`mag` is read from `{}`): \
                 subtracted from itself, nothing is left to fit; choose the magnetometer with \
                 --mag, or leave `{c}` out with --reference",
                flight.resolve(c).unwrap_or(c)
            )));
        }
    }
    // The lever arm moves the `igrf` reference to the sensor (and the
    // Kalman method's altitude): with the LS method and no `igrf`
    // reference it changed nothing, without a word.
    if opts.method == Method::Ls
        && opts.lever_arm.is_some()
        && !ref_cols.iter().any(|c| c == "igrf")
    {
        return Err(Error::bad_input(format!(
            "a lever arm moves the `igrf` reference channel to the sensor, and the reference \
             channels ({}) have none: the LS fit would not use it (add `igrf` to --reference, \
             or leave the lever arm out)",
            if ref_cols.is_empty() {
                "none".to_string()
            } else {
                ref_cols.join(", ")
            }
        )));
    }
    if ref_cols.is_empty() && reference_nt.is_none() {
        // Nothing to subtract: the reading itself (`mag − 0` is `mag`, bit
        // for bit), without two copies of the flight's length.
        return Ok((ref_cols, std::borrow::Cow::Borrowed(inputs.mag)));
    }
    let mut sum = reference_sum(flight, &ref_cols, opts.lever_arm.as_ref())?;
    if let Some(r) = reference_nt {
        for (s, v) in sum.iter_mut().zip(r) {
            *s += v;
        }
    }
    Ok((ref_cols, std::borrow::Cow::Owned(reduced(inputs.mag, &sum))))
}

/// The longest median time step of a calibration flight, s: its
/// manoeuvres (periods of 1–10 s, the default pass band 0.1–0.9 Hz) need
/// at least a sample a second. A time in milliseconds (a step of 100 "s")
/// was fitted by the Kalman method with exit 0 and a model 30 times worse,
/// and refused by the LS method as "invalid argument `low_hz`".
pub const MAX_CALIBRATION_STEP_S: f64 = 1.0;

/// Bad input when `flight` is sampled more slowly than
/// [`MAX_CALIBRATION_STEP_S`].
fn check_calibration_rate(flight: &Flight) -> Result<()> {
    let dt = flight.median_step_s()?;
    if dt > MAX_CALIBRATION_STEP_S {
        return Err(Error::bad_file(
            flight.label(),
            format!(
                "the median time step is {} s ({} Hz): a calibration's manoeuvres need at least {} \
                 sample a second; is the time in seconds (milliseconds?)",
                aeromag_core::error::figure(dt),
                aeromag_core::error::figure(1.0 / dt),
                1.0 / MAX_CALIBRATION_STEP_S
            ),
        ));
    }
    Ok(())
}

/// Bad input when the scalar reading or a vector axis of `sensor` holds
/// one value on every row: a stuck magnetometer was fitted to
/// "coefficients" that removed nothing (exit 0), a dead fluxgate axis
/// failed as a "singular system" (exit 1). The scan stops at the first
/// value that differs.
fn check_sensors_vary(flight: &Flight, inputs: &TlInputs, sensor: &SensorColumns) -> Result<()> {
    let columns =
        std::iter::once((&sensor.mag, inputs.mag)).chain(sensor.flux.iter().zip(inputs.flux));
    for (name, v) in columns {
        let mut finite = v.iter().filter(|x| x.is_finite());
        if let Some(first) = finite.next()
            && finite.all(|x| x == first)
        {
            return Err(flight.bad_column(
                name,
                format!(
                    "holds one value, {} nT, on every row: a stuck or dead sensor, or a wrong \
                     column; there is nothing to fit",
                    aeromag_core::error::shown(*first)
                ),
            ));
        }
    }
    Ok(())
}

/// The segment rule of a fit: split at lines unless told not to.
pub(super) fn fit_rule(opts: &CalibrateOptions) -> SegmentRule {
    SegmentRule {
        split_lines: opts.split_lines,
        ..SegmentRule::default()
    }
}

/// Canonical column name → the file's column name for the model file:
/// `base` and the reference channels, with `mag` and `flux_x/y/z` read
/// from `sensor`.
pub(super) fn model_columns(
    flight: &Flight,
    sensor: &SensorColumns,
    base: &[&str],
    ref_cols: &[String],
) -> std::collections::BTreeMap<String, String> {
    let names: Vec<&str> = base
        .iter()
        .copied()
        .chain(ref_cols.iter().map(String::as_str))
        .collect();
    // SGL fields under their MagNav names (`UNCOMPMAG1` → `mag_1_uc`),
    // which find them in either naming.
    let mut map = flight.column_map_of(&names);
    for v in map.values_mut() {
        *v = aeromag_io::magnav_name(v);
    }
    let canonical = SensorColumns::default();
    for (c, s) in std::iter::once((&canonical.mag, &sensor.mag))
        .chain(canonical.flux.iter().zip(&sensor.flux))
        .filter(|(c, s)| c != s)
    {
        map.insert(c.clone(), s.clone());
    }
    map
}

/// The LS inputs of a flight: the settings with the extra regressors, the
/// reference channels used, and the fit's segments (the reduced scalar
/// reading, split by [`fit_rule`]), handed to `f`.
fn with_ls_segments<T>(
    flight: &Flight,
    opts: &CalibrateOptions,
    reference_nt: Option<&[f64]>,
    notes: &mut Notes,
    f: impl FnOnce(&LsConfig, Vec<String>, &[Segment], &mut Notes) -> Result<T>,
) -> Result<T> {
    let ls = opts.ls_with_extras()?;
    let cols =
        TlInputs::of_sensor(flight, &opts.sensor)?.with_extras(flight, ls.design.terms.extras())?;
    let (ref_cols, y) = reduced_mag(flight, &cols, opts, reference_nt)?;
    let cols = cols.with_mag(&y);
    let usable = cols.usable();
    let segs = fit_rule(opts).split(cols.time, cols.line, &usable);
    let left_out = usable.iter().filter(|u| !**u).count();
    if left_out > 0 {
        notes.warn(format!(
            "{} of {} rows have missing values and are not used by the fit",
            left_out,
            flight.n_rows()
        ));
    }
    let segments: Vec<Segment> = segs
        .kept
        .iter()
        .map(|r| cols.whole().slice(r.clone()))
        .collect();
    f(&ls, ref_cols, &segments, notes)
}

/// Choose the lags (eddy and extra regressors) on the flight's band-passed
/// LS inputs and test the extra regressors of `opts` there, with a note
/// for each dropped one.
fn select_channels(
    flight: &Flight,
    opts: &CalibrateOptions,
    reference_nt: Option<&[f64]>,
    notes: &mut Notes,
) -> Result<(TermChoice, ChannelSelection)> {
    let label = flight.label();
    // The missing rows are noted again by the fit that follows.
    let mut silent = crate::observer::Silent;
    let mut quiet = Notes::new(&mut silent);
    with_ls_segments(
        flight,
        opts,
        reference_nt,
        &mut quiet,
        |ls, _, segments, _| {
            let choice = choose_terms(&label, segments, ls, &opts.eddy_lag, &opts.extra, notes)?;
            notes.stage("testing the extra regressors");
            notes.check_cancelled()?;
            // A fit of unfiltered data (the reference-sensor mode) tests its
            // channels in the default band: the test's ν and threshold are
            // those of a band-passed residual, and the unfiltered one is
            // coloured by slow drifts (the difference field, the reference
            // sensor's own error) that slow bus and battery currents then
            // "explain". Measured (demo box, 3-line survey, mag_5_uc):
            // 0.201 nT tested unfiltered, 0.165 band-passed (oracle 0.146);
            // on another cabin (tools/validate, seed 11) 0.305 → 0.181 (oracle
            // 0.167), every cabin sensor within 1.21× its oracle.
            let band_passed;
            let test_ls = match ls.band_hz {
                Some(_) => ls,
                None => {
                    band_passed = LsConfig {
                        band_hz: LsConfig::default().band_hz,
                        trim: LsConfig::default().trim,
                        ..ls.clone()
                    };
                    &band_passed
                }
            };
            let sel = test_extra_channels(&label, segments, test_ls, &choice.terms, notes)?;
            Ok((choice, sel))
        },
    )
}

/// The band-pass LS fit on a flight.
fn fit_ls_flight(
    flight: &Flight,
    opts: &CalibrateOptions,
    reference_nt: Option<&[f64]>,
    notes: &mut Notes,
) -> Result<(TlModel, Option<LagSelection>)> {
    with_ls_segments(
        flight,
        opts,
        reference_nt,
        notes,
        |ls, ref_cols, segments, notes| {
            fit_ls_segments(flight, opts, ls, ref_cols, segments, notes)
        },
    )
}

/// [`fit_ls_flight`] on its segments.
fn fit_ls_segments(
    flight: &Flight,
    opts: &CalibrateOptions,
    ls: &LsConfig,
    ref_cols: Vec<String>,
    segments: &[Segment],
    notes: &mut Notes,
) -> Result<(TlModel, Option<LagSelection>)> {
    let label = flight.label();
    let choice = choose_terms(&label, segments, ls, &opts.eddy_lag, &opts.extra, notes)?;
    let selection = choice.eddy;
    let cfg = &LsConfig {
        design: ls.design.with_terms(choice.terms),
        ..ls.clone()
    };
    notes.stage("fitting");
    notes.check_cancelled()?;
    let fit = fit_band_pass_ls(segments, cfg).in_file(&label)?;
    for w in &fit.warnings {
        notes.warn(w.clone());
    }
    for n in &fit.notes {
        notes.note(n.clone());
    }
    second_order_note(&cfg.design, &fit.coef, segments, notes);
    let model = TlModel {
        format: MODEL_FORMAT.into(),
        kind: TL_KIND.into(),
        design: cfg.design.clone(),
        method: MethodSettings::Ls(LsSettings {
            band_hz: cfg.band_hz,
            filter_order: cfg.filter_order,
            trim: cfg.trim,
            lambda: cfg.lambda,
        }),
        coefficients: Coefficient::list(&fit.names, &fit.coef, &fit.std),
        fit: FitStats {
            rows: fit.rows,
            segments: fit.segments_used,
            condition: fit.condition,
            residual_rms_nt: fit.residual_rms_nt,
            warnings: fit.warnings.clone(),
            eddy_lag_selection: selection.clone(),
            extra_lag_selection: choice.extras,
            extra_channel_selection: None,
            sample_interval_s: None,
        },
        columns: model_columns(
            flight,
            &opts.sensor,
            &["time", "flux_x", "flux_y", "flux_z", "mag"],
            &ref_cols,
        ),
        reference: ref_cols,
        lever_arm: opts.lever_arm,
        software_version: env!("CARGO_PKG_VERSION").into(),
    };
    Ok((model, selection))
}
