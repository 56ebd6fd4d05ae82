//! Levelling a survey at its line/tie-line crossovers with the
//! `k·d|B0|/dt` term and the crossovers' height differences
//! (algorithms: [`aeromag_compensation::levelling`]).

use crate::error::{Error, InFile, Result};
use crate::flight::{Flight, LineLabels, ReferenceChannels, reduced, reference_sum, sensor_track};
use crate::observer::{Note, Notes, Observer};
use aeromag_compensation::levelling::{
    Crossover, LevellingConfig, RowFlag, SurveyLevelling, SurveyTracks, TrackConfig, level_survey,
};
use aeromag_io::FlightTable;

/// What to level and how.
#[derive(Debug, Clone, PartialEq)]
pub struct LevelOptions {
    /// Column to level; `None`: the compensated reading (`mag_comp`, else
    /// the first `mag_<k>_comp`, any case), else `mag` with the warning
    /// `[uncompensated-default]` ([`crate::flight::default_column`]).
    pub value: Option<String>,
    /// Column whose along-track derivative is the regressor of the
    /// `d|B0|/dt` term, as recorded; `None`: `mag` (the uncompensated
    /// reading) when the flight has it, else the levelled column. A lag of
    /// the scalar channel acts on everything the sensor sees, the aircraft's
    /// own interference included.
    pub rate_of: Option<String>,
    /// Sensor lever arm from the navigation point (body frame: x forward,
    /// y right, z down; m): crossovers are found at the sensor's position.
    pub lever_arm_m: Option<[f64; 3]>,
    /// Positions already projected (easting and northing, m) in place of
    /// `lat`/`lon`, as [`crate::map::GridOptions::projected`] (found in a
    /// flight without lat/lon when `None`); they need their UTM zone,
    /// `zone`, which turns them into latitudes and longitudes.
    pub projected: Option<crate::map::ProjectedColumns>,
    /// The UTM zone of the projected positions.
    pub zone: Option<aeromag_grid::projection::UtmZone>,
    /// Known external-field channels subtracted from the value first
    /// (default none: classic levelling; `calibrate`'s default is `auto`).
    pub reference: ReferenceChannels,
    /// Note when `reference` is none and the flight has reference channels
    /// (`diurnal`, `igrf`) that `auto` would subtract: for a caller whose
    /// `none` is the default rather than a choice (`aeromag level` without
    /// `--reference`). On the simulated survey the crossover RMS after
    /// levelling is 0.786 nT as recorded against 0.155 nT with `auto`; the
    /// default stays `none`, which levelled outputs already rely on.
    pub note_unused_reference: bool,
    /// Crossover finding (gap rule, derivative window, minimum angle).
    pub tracks: TrackConfig,
    /// The fit (k, drift, ridge λ, altitude term, robust weights).
    pub fit: LevellingConfig,
    /// Labels of the tie lines, when neither a `line_type` column nor the
    /// labels (`L…`/`T…`) tell ([`LineLabels`]). Empty: not declared.
    pub ties: Vec<String>,
}

impl Default for LevelOptions {
    fn default() -> Self {
        Self {
            value: None,
            rate_of: None,
            lever_arm_m: None,
            projected: None,
            zone: None,
            reference: ReferenceChannels::None,
            note_unused_reference: false,
            tracks: TrackConfig::default(),
            fit: LevellingConfig::default(),
            ties: Vec::new(),
        }
    }
}

/// The levelling fit as a user states it: the `aeromag level` flags and
/// the keywords of Python's `aeromag.level`, turned into the library's
/// [`LevellingConfig`] by one rule.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LevelFitChoices {
    /// Classic tie-line levelling: no `k·d|B0|/dt` term, no altitude term.
    pub tie_only: bool,
    /// A linear drift per line besides its level.
    pub drift: bool,
    /// Leave out the altitude (vertical-gradient) term.
    pub no_altitude_term: bool,
    /// Least squares without the Huber weights.
    pub no_robust: bool,
    /// Ridge parameter λ ≥ 0 of the line levels.
    pub ridge_lambda: f64,
}

impl Default for LevelFitChoices {
    fn default() -> Self {
        Self {
            tie_only: false,
            drift: false,
            no_altitude_term: false,
            no_robust: false,
            ridge_lambda: LevellingConfig::default().lambda,
        }
    }
}

impl LevelFitChoices {
    /// The fit configuration these choices mean.
    pub fn config(&self) -> LevellingConfig {
        LevellingConfig {
            estimate_k: !self.tie_only,
            drift: self.drift,
            lambda: self.ridge_lambda,
            altitude_term: !(self.tie_only || self.no_altitude_term),
            robust: !self.no_robust,
            ..LevellingConfig::default()
        }
    }
}

/// A levelled survey ([`level`]).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Levelled {
    /// Crossovers, the fit (k, line levels, residuals) and the corrected
    /// series.
    pub levelling: SurveyLevelling,
    /// The column levelled.
    pub value_column: String,
    /// The reference channels subtracted from it.
    pub reference_columns: Vec<String>,
    /// The column whose derivative is the `d|B0|/dt` regressor.
    pub rate_column: String,
    /// The line labels: the fit's and the crossovers' `label`s are their ids.
    pub lines: LineLabels,
    /// Notes and warnings.
    pub notes: Vec<Note>,
}

/// The flag column `level` adds.
pub const LEVEL_FLAG: &str = "level_flag";

impl Levelled {
    /// Name of the levelled column: `<value>_level`.
    pub fn output_column(&self) -> String {
        format!("{}_level", self.value_column)
    }

    /// The flag of every row as written: 0 levelled, 1 on a line without
    /// crossovers, 2 not on a line, 3 missing value.
    pub fn flags(&self) -> Vec<f64> {
        self.levelling
            .levelled
            .flag
            .iter()
            .map(|fl| match fl {
                RowFlag::Levelled => 0.0,
                RowFlag::NoCrossovers => 1.0,
                RowFlag::NotOnLine => 2.0,
                RowFlag::Missing => 3.0,
            })
            .collect()
    }

    /// Add `<value>_level` and [`LEVEL_FLAG`] to `table`.
    pub fn add_to(&self, table: &mut FlightTable) -> Result<()> {
        table.add_column(
            &self.output_column(),
            self.levelling.levelled.value_nt.clone(),
        )?;
        table.add_integer_column(LEVEL_FLAG, self.flags())?;
        Ok(())
    }

    /// The crossover table: one row per crossover with both lines,
    /// position, times, altitudes, values, `d|B0|/dt`, profile gradients,
    /// the difference, what the fitted model leaves of it and its weight
    /// (units in the column names). The lines are `line_a` and `line_b`,
    /// numbers when the labels are, text when a label's later pass is
    /// named (`1003 (pass 2)`).
    pub fn crossover_table(&self) -> Result<FlightTable> {
        let xs = &self.levelling.crossovers.crossovers;
        let fit = &self.levelling.fit;
        let col = |f: &dyn Fn(&Crossover) -> f64| -> Vec<f64> { xs.iter().map(f).collect() };
        let mut t = FlightTable::new();
        // The labels as numbers, unless a label flown twice needs its
        // passes named (`1003 (pass 2)`).
        if self.lines.numbers.is_some() && self.lines.repeated.is_empty() {
            t.add_column("line_a", col(&|x| self.lines.number(x.a.label)))?;
            t.add_column("line_b", col(&|x| self.lines.number(x.b.label)))?;
        } else {
            let text = |id: &dyn Fn(&Crossover) -> i64| -> Vec<String> {
                xs.iter()
                    .map(|x| self.lines.label(id(x)).unwrap_or("").to_string())
                    .collect()
            };
            t.add_text_column("line_a", text(&|x| x.a.label))?;
            t.add_text_column("line_b", text(&|x| x.b.label))?;
        }
        let columns: Vec<(&str, Vec<f64>)> = vec![
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
        Ok(t)
    }
}

/// Level a (compensated) survey: find the crossovers of lines and tie lines
/// (label 0 = not on a line) at the sensor's position, fit `k` of the
/// `k·d|B0|/dt` term jointly with a level per line (and the altitude term,
/// robust weights: [`LevellingConfig`]), and correct every row.
///
/// Reads `time`, `lat`, `lon`, `alt` (without it, the altitude term is
/// left out, with a note), `line`, the value and rate columns,
/// the reference channels, and the attitude with a lever arm. Bad input if
/// the flight already has the output columns.
///
/// ```
/// use aeromag::level::{LevelOptions, level};
/// use aeromag::simulate::{ScenarioKind, simulate_flight};
/// use aeromag::Silent;
/// // A small simulated survey: five lines and three ties, levelled as recorded.
/// let pattern = "[pattern]\nline_count = 5\nline_length_m = 5000.0\ntie_count = 3\n";
/// let survey = simulate_flight(ScenarioKind::Survey, Some(pattern), Some(7))?;
/// let lev = level(&survey, &LevelOptions::default(), &mut Silent)?;
/// let fit = &lev.levelling.fit;
/// assert!(!lev.levelling.crossovers.crossovers.is_empty());
/// assert!(fit.rms_after_nt <= fit.rms_before_nt);
/// println!("k = {:.3} ± {:.3} s", fit.k_s, fit.k_std_s);
/// # Ok::<(), aeromag::Error>(())
/// ```
pub fn level(
    flight: &Flight,
    opts: &LevelOptions,
    observer: &mut dyn Observer,
) -> Result<Levelled> {
    let mut notes = Notes::new(observer);
    let value_column = match &opts.value {
        Some(v) => v.clone(),
        None => {
            let d = crate::flight::default_column(flight, &[""], "--value")?;
            if let Some(w) = d.warning {
                notes.warn(w);
            }
            d.name
        }
    };
    let out_name = format!("{value_column}_level");
    if flight.get(&out_name).is_some() || flight.get(LEVEL_FLAG).is_some() {
        return Err(Error::bad_file(
            flight.label(),
            format!("already has `{out_name}` or `{LEVEL_FLAG}`"),
        ));
    }
    if !(opts.fit.lambda >= 0.0 && opts.fit.lambda.is_finite()) {
        return Err(Error::bad_input(format!(
            "levelling λ {} must be ≥ 0",
            opts.fit.lambda
        )));
    }
    notes.stage("levelling");
    notes.check_cancelled()?;
    let projected = crate::map::ProjectedColumns::chosen(
        flight,
        opts.projected.as_ref(),
        opts.lever_arm_m.is_some(),
        &mut notes,
    )?;
    let positions = opts
        .lever_arm_m
        .map(|arm| sensor_track(flight, arm))
        .transpose()?;
    let from_projected = match &projected {
        Some(c) => {
            let zone = opts.zone.ok_or_else(|| {
                Error::bad_input(format!(
                    "levelling finds the crossovers on the Earth: give the UTM zone of {} and {} (--utm-zone), which turns them into latitudes and longitudes",
                    c.easting, c.northing
                ))
            })?;
            Some(c.geodetic(flight, zone)?)
        }
        None => None,
    };
    // The height is needed only by the altitude term: a file without
    // `alt` (an XYZ of X, Y and the field) is levelled without it, saying
    // so (it was refused: "required column 'alt' is missing").
    let no_height;
    let recorded = flight.column("alt");
    let has_alt = recorded.is_some();
    let recorded_alt = match recorded {
        Some(a) => a,
        None => {
            if opts.fit.altitude_term {
                notes.note(
                    "the file has no `alt` column: the altitude term is left out (map a height onto it with --columns alt=NAME to fit it)",
                );
            }
            no_height = vec![f64::NAN; flight.n_rows()];
            &no_height
        }
    };
    let (lat, lon, alt) = match (&positions, &from_projected) {
        (Some([la, lo, al]), _) => (la.as_slice(), lo.as_slice(), al.as_slice()),
        (None, Some((la, lo))) => (la.as_slice(), lo.as_slice(), recorded_alt),
        (None, None) => (flight.require("lat")?, flight.require("lon")?, recorded_alt),
    };
    let fit_config = LevellingConfig {
        altitude_term: opts.fit.altitude_term && has_alt,
        ..opts.fit.clone()
    };
    let position_columns = projected.as_ref().map_or(["lat", "lon"], |c| {
        [c.easting.as_str(), c.northing.as_str()]
    });
    // Rows off the track (a GPS dropout written as 0, 0) made crossovers
    // of their own: 10 on a survey, a line shifted by 55 nT. They are left
    // out as `grid` and `microlevel` leave them out.
    let time = flight.require("time")?;
    let off_track = aeromag_io::position_glitches(time, lat, lon);
    let on_track_positions = (!off_track.is_empty()).then(|| {
        let mut la = lat.to_vec();
        let mut lo = lon.to_vec();
        for &k in &off_track {
            la[k] = f64::NAN;
            lo[k] = f64::NAN;
        }
        (la, lo)
    });
    if let Some(w) = crate::map::survey::off_track_warning(flight, &off_track, position_columns) {
        notes.warn(w);
    }
    let (lat, lon) = match &on_track_positions {
        Some((la, lo)) => (la.as_slice(), lo.as_slice()),
        None => (lat, lon),
    };
    let reference_columns = opts.reference.resolve(flight)?;
    if opts.note_unused_reference && opts.reference == ReferenceChannels::None {
        let present = ReferenceChannels::Auto.resolve(flight)?;
        if !present.is_empty() {
            notes.note(format!(
                "the file has the reference channel{} {}, not subtracted (--reference none is the default); --reference auto subtracts {} before the crossovers are formed, which usually levels better (simulated survey: crossover RMS 0.155 against 0.786 nT)",
                if present.len() > 1 { "s" } else { "" },
                present.join(" and "),
                if present.len() > 1 { "them" } else { "it" },
            ));
        }
    }
    let sum = reference_sum(flight, &reference_columns, None)?;
    let value = reduced(flight.field_values(&value_column)?, &sum);
    let rate_column = match &opts.rate_of {
        Some(c) => c.clone(),
        None if flight.column("mag").is_some() => "mag".into(),
        None => value_column.clone(),
    };
    // `--rate-of time` failed as a "singular system" (exit 1).
    if crate::flight::NOT_FIELDS.contains(&rate_column.as_str()) {
        return Err(Error::bad_input(format!(
            "the rate of `{rate_column}` is no d|B0|/dt: give a magnetic column (the reading as recorded, `mag` by default)"
        )));
    }
    // The column as recorded (the sensor lags the reference fields too);
    // not needed, and its gaps not imposed, without the k term.
    let sensed = opts
        .fit
        .estimate_k
        .then(|| flight.require(&rate_column))
        .transpose()?;
    let lines = LineLabels::per_pass(flight, &opts.ties)?;
    for w in [
        lines.missing_warning(flight),
        lines.repeated_warning(flight),
    ]
    .into_iter()
    .flatten()
    {
        notes.warn(w);
    }
    let tracks = SurveyTracks {
        time,
        lat,
        lon,
        alt,
        line: &lines.ids,
        value: &value,
        sensed,
    };
    let track_config = TrackConfig {
        pairing: lines.pairing(),
        ..opts.tracks.clone()
    };
    let levelling = level_survey(&tracks, &track_config, &fit_config).in_file(&flight.label())?;
    let f = &levelling.fit;
    if fit_config.altitude_term && !f.altitude_term_used {
        notes.warn(
            "no crossover has heights and profiles on both sides; the altitude term is left out",
        );
    }
    if f.components > 1 {
        notes.warn(format!(
            "the lines form {} groups that never cross; their relative levels rest on the penalty, not the data",
            f.components
        ));
    }
    Ok(Levelled {
        levelling,
        value_column,
        reference_columns,
        rate_column,
        lines,
        notes: notes.into_notes(),
    })
}
