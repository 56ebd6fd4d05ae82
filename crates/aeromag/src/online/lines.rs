//! The line protocol of `aeromag stream`: comma-separated lines in, each
//! line out with `mag_interf`, `mag_comp` and `comp_flag` appended.

use super::CausalTl;
use super::adaptive::{Adapt, AdaptOptions, OnlineEngine};
use crate::error::{Error, Result};
use crate::observer::Note;
use aeromag_compensation::model_file::TlModel;
use aeromag_compensation::tolles_lawson::adaptive::Navigation;
use aeromag_compensation::tolles_lawson::online::{OnlineSample, SampleStatus};
use aeromag_core::error::shown;
use aeromag_io::ColumnMap;

/// The columns a stream's lines gain.
pub const STREAM_OUTPUT: [&str; 3] = ["mag_interf", "mag_comp", "comp_flag"];

/// The largest ground speed `--speed` may give, m/s: three times a jet
/// survey's; beyond it the along-track field model's arithmetic fails.
pub const MAX_GROUND_SPEED_M_S: f64 = 1000.0;

/// The stretch of a stream, s, over which its positions' ground speed is
/// measured against `--speed` ([`StreamIssues::speed`]): long enough that
/// the position noise of a GNSS receiver (metres) is a small part of the
/// path (hundreds of metres at survey speeds).
pub const SPEED_STRETCH_S: f64 = 10.0;

/// The longest time step, s, within a stretch of [`SPEED_STRETCH_S`]: a
/// gap restarts the stretch (the path across it is unknown).
pub const SPEED_STRETCH_GAP_S: f64 = 2.0;

/// Whether a ground speed measured from positions, `measured_m_s`,
/// disagrees with the one given, `given_m_s`: by more than 5 m/s and by
/// more than half the larger of the two (0 given at 70 m/s does; 60 given
/// at 70 does not).
pub fn speed_disagrees(measured_m_s: f64, given_m_s: f64) -> bool {
    (measured_m_s - given_m_s).abs() > f64::max(5.0, 0.5 * measured_m_s.max(given_m_s))
}

/// The ground speed a stream's positions give over stretches of
/// [`SPEED_STRETCH_S`] (path length over time).
#[derive(Debug, Clone, Default)]
struct SpeedCheck {
    /// The stretch's start time, s, and its path so far, m.
    start_s: f64,
    path_m: f64,
    /// The last line's time, s, and position `[lat, lon]`, degrees.
    last: Option<(f64, [f64; 2])>,
}

impl SpeedCheck {
    /// Take a line's time and position; the stretch's speed, m/s, and
    /// length, s, when it is complete (a new one then starts).
    fn push(&mut self, time_s: f64, position: [f64; 2]) -> Option<(f64, f64)> {
        match self.last {
            Some((t, p)) if time_s > t && time_s - t <= SPEED_STRETCH_GAP_S => {
                self.path_m += aeromag_io::step_distance_m(p, position);
            }
            _ => (self.start_s, self.path_m) = (time_s, 0.0),
        }
        self.last = Some((time_s, position));
        let span = time_s - self.start_s;
        (span >= SPEED_STRETCH_S).then(|| {
            let v = self.path_m / span;
            (self.start_s, self.path_m) = (time_s, 0.0);
            (v, span)
        })
    }
}

/// `comp_flag` of an output line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum StreamFlag {
    /// 0: compensated.
    Compensated = 0,
    /// 1: not compensated, an input is missing (empty, `NaN`), `mag` or
    /// the vector magnitude is below a reading of Earth's field
    /// ([`aeromag_core::field::MIN_READING_NT`]: a dropout value such as 0,
    /// tesla), or the interference the model gives is beyond any
    /// magnetic field ([`aeromag_io::MAX_FIELD_NT`]: a model file that does
    /// not fit, or a time step too short for the derivative); its values
    /// are left empty.
    Missing = 1,
    /// 2: compensated, the first sample of a run (the stream's first, after
    /// a gap or after a sample that could not be used): derivative 0, lags
    /// restarted.
    Started = 2,
    /// 3: not compensated, its time does not increase (ignored: the stream
    /// goes on as if it had not arrived).
    TimeBackwards = 3,
    /// 4: not compensated, the line is malformed (wrong number of fields,
    /// text where a number is needed, a `mag` or `flux_*` value beyond any
    /// magnetic field: a corrupted cell).
    Malformed = 4,
}

impl From<SampleStatus> for StreamFlag {
    fn from(s: SampleStatus) -> Self {
        match s {
            SampleStatus::Compensated => StreamFlag::Compensated,
            SampleStatus::Started => StreamFlag::Started,
            SampleStatus::Missing => StreamFlag::Missing,
            SampleStatus::TimeBackwards => StreamFlag::TimeBackwards,
        }
    }
}

/// Lines of a stream by what became of them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct StreamCounts {
    /// Data lines read.
    pub lines: u64,
    /// Compensated (flags 0 and 2).
    pub compensated: u64,
    /// Runs started after the first (gaps, or samples that could not be
    /// used, in between).
    pub restarts: u64,
    /// Flag 1.
    pub missing: u64,
    /// Flag 3.
    pub time_backwards: u64,
    /// Flag 4.
    pub malformed: u64,
}

impl StreamCounts {
    fn add(&mut self, flag: StreamFlag) {
        self.lines += 1;
        match flag {
            StreamFlag::Compensated => self.compensated += 1,
            StreamFlag::Started => {
                if self.compensated > 0 {
                    self.restarts += 1;
                }
                self.compensated += 1;
            }
            StreamFlag::Missing => self.missing += 1,
            StreamFlag::TimeBackwards => self.time_backwards += 1,
            StreamFlag::Malformed => self.malformed += 1,
        }
    }
}

impl std::fmt::Display for StreamCounts {
    /// One line: `N lines: C compensated (R restarts), M missing, B time
    /// going back, X malformed`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} lines: {} compensated ({} runs restarted), {} with missing values, {} with time going back, {} malformed",
            self.lines,
            self.compensated,
            self.restarts,
            self.missing,
            self.time_backwards,
            self.malformed
        )
    }
}

/// Lines of one kind that a stream could not compensate: how many, and
/// the first (its data line, counted from 1 since the header, and what
/// was wrong with it).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LineIssue {
    /// Lines of this kind.
    pub count: u64,
    /// The first one: data line and detail (empty when the kind says it
    /// all).
    pub first: Option<(u64, String)>,
}

impl LineIssue {
    fn add(&mut self, line: u64, detail: String) {
        self.count += 1;
        if self.first.is_none() {
            self.first = Some((line, detail));
        }
    }

    /// `self` and then `later` (a later connection's).
    fn then(&self, later: &LineIssue) -> LineIssue {
        LineIssue {
            count: self.count + later.count,
            first: self.first.clone().or_else(|| later.first.clone()),
        }
    }

    /// `N line(s) … (the first: data line L, detail)`, `None` without lines.
    fn told(&self, what: &str, then: &str) -> Option<Note> {
        let (line, detail) = self.first.as_ref()?;
        let detail = if detail.is_empty() {
            String::new()
        } else {
            format!(": {detail}")
        };
        Some(Note::warning(format!(
            "{} {} {what} (the first: data line {line}{detail}){then}",
            self.count,
            if self.count == 1 { "line" } else { "lines" },
        )))
    }
}

/// Why lines of a stream were not compensated, for the user (the flags
/// say which lines; these say why): malformed lines (flag 4), readings
/// below a reading of Earth's field and interference beyond any field
/// (both flag 1).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StreamIssues {
    /// Malformed lines (flag 4): a wrong number of cells, text where a
    /// number is needed, a value beyond any magnetic field, a line too
    /// long.
    pub malformed: LineIssue,
    /// Lines whose `mag` or vector magnitude is below
    /// [`aeromag_core::field::MIN_READING_NT`] (flag 1).
    pub not_reading: LineIssue,
    /// Lines whose modelled interference is beyond any magnetic field
    /// (flag 1; a model file that does not fit the stream).
    pub beyond_field: LineIssue,
    /// Lines ending a stretch of [`SPEED_STRETCH_S`] whose positions give a
    /// ground speed far from `--speed` ([`speed_disagrees`]; the Kalman
    /// filter's field model then runs along the track at the wrong pace).
    pub speed: LineIssue,
}

impl StreamIssues {
    /// `self` and then `later` (a later connection's).
    fn then(&self, later: &StreamIssues) -> StreamIssues {
        StreamIssues {
            malformed: self.malformed.then(&later.malformed),
            not_reading: self.not_reading.then(&later.not_reading),
            beyond_field: self.beyond_field.then(&later.beyond_field),
            speed: self.speed.then(&later.speed),
        }
    }

    /// One warning per kind of line seen, with its first line.
    pub fn warnings(&self) -> Vec<Note> {
        [
            self.malformed.told("malformed", ""),
            self.not_reading.told(
                &format!(
                    "with a reading below {} nT, no reading of Earth's field",
                    aeromag_core::error::shown(aeromag_core::field::MIN_READING_NT)
                ),
                ": a dropout value, a negated reading, or another unit (the stream wants nT, not tesla, gauss or µT)? not compensated (comp_flag 1)",
            ),
            self.beyond_field.told(
                "whose modelled interference is beyond any magnetic field",
                ": the model file does not fit this stream (an edited coefficient, another aircraft's model?); not compensated (comp_flag 1)",
            ),
            self.speed.told(
                &format!("ending {} s stretches whose positions give a ground speed far from --speed", shown(SPEED_STRETCH_S)),
                ": the adaptive Kalman filter's field model runs along the track at the speed given; give the stream's ground speed (--speed) or map its velocity (--columns vn=NAME,ve=NAME)",
            ),
        ]
        .into_iter()
        .flatten()
        .collect()
    }
}

/// How a stream's columns are found.
#[derive(Debug, Clone, Default)]
pub struct StreamOptions {
    /// Canonical name → stream column (`--columns mag=mag_1_uc,…`).
    pub columns: ColumnMap,
    /// The sample rate, Hz, when the model does not record it (or to
    /// override it): the gap rule ([`CausalTl::new`]).
    pub sample_rate_hz: Option<f64>,
    /// Adapt the coefficients as the samples arrive (`--adapt`); `None`:
    /// the model's coefficients, the values of `compensate --causal`.
    pub adapt: Option<Adapt>,
    /// The adaptive estimators' settings.
    pub adapt_options: AdaptOptions,
    /// Ground speed, m/s, when the stream has no `vn`, `ve` columns (the
    /// Kalman filter's field model runs along the track).
    pub speed_m_s: Option<f64>,
}

/// Where the inputs are in a line.
#[derive(Debug, Clone)]
struct Fields {
    time: usize,
    flux: [usize; 3],
    mag: usize,
    channels: Vec<usize>,
    /// `vn`, `ve`, `alt`, `lat`, `lon` (adaptive mode, when present).
    nav: [Option<usize>; 5],
    /// The last input's position.
    last: usize,
    /// Cells per line.
    count: usize,
}

/// A model compensating a stream of CSV lines ([module docs](super)).
#[derive(Debug, Clone)]
pub struct LineCompensator {
    engine: OnlineEngine,
    /// Ground speed when the stream has no velocity, m/s (NaN: none).
    speed_m_s: f64,
    fields: Fields,
    header: String,
    /// The header's names, trimmed (for messages).
    names: Vec<String>,
    counts: StreamCounts,
    issues: StreamIssues,
    channels: Vec<f64>,
    /// `vn`, `ve`, `alt`, `lat`, `lon` of the current line (NaN when
    /// absent).
    nav: [f64; 5],
    /// The positions' ground speed, when the speed is `--speed`'s.
    speed_check: SpeedCheck,
}

impl LineCompensator {
    /// `model` on lines laid out as `header` (comma-separated names). Each
    /// input is found by, in order: the user's mapping (`opts.columns`),
    /// its canonical name (`time`, `flux_x`, …, `mag`; case ignored), the
    /// file column the model was fitted on (`model.columns`); an extra
    /// regressor by its channel name. An input not found is bad input, as
    /// is a model without its sample interval and no rate given. With
    /// [`StreamOptions::adapt`], `vn`, `ve` and `alt` are read when present;
    /// the Kalman filter needs the ground speed: `vn` and `ve`, or
    /// [`StreamOptions::speed_m_s`].
    pub fn new(model: &TlModel, header: &str, opts: &StreamOptions) -> Result<Self> {
        let causal = CausalTl::new(model, opts.sample_rate_hz)?;
        // A byte-order mark (a file saved by a Windows editor) is no part
        // of the first name: `time` was not found.
        let header = header.strip_prefix('\u{feff}').unwrap_or(header);
        let names: Vec<&str> = header.split(',').map(str::trim).collect();
        if let Some(c) = header.chars().find(|c| c.is_control() && *c != '\t') {
            return Err(Error::bad_input(format!(
                "the header line holds the control character {c:?}{}: {}",
                if c == '\r' {
                    " (lines must end in \\n or \\r\\n, not \\r alone)"
                } else {
                    ""
                },
                listed(&names)
            )));
        }
        let mut seen = std::collections::HashSet::with_capacity(names.len());
        if let Some(n) = names.iter().find(|n| !seen.insert(n.to_ascii_lowercase())) {
            return Err(Error::bad_input(format!(
                "the header names the column {:?} twice: {}",
                clipped(n),
                listed(&names)
            )));
        }
        // A mapping onto a column the stream lacks (a typo) fell back on
        // the canonical column silently, switching sensors.
        for (canonical, name) in opts.columns.pairs() {
            if !names.iter().any(|h| h.eq_ignore_ascii_case(name)) {
                return Err(Error::bad_input(format!(
                    "the column map sends `{canonical}` to column {:?}, which the stream does not have; \
                     its columns: {}",
                    clipped(name),
                    listed(&names)
                )));
            }
        }
        let lookup = |canonical: &str| -> Option<usize> {
            // An SGL field in either naming (`cur_com_1` = `CUR_COM1`).
            let by = |n: &str| {
                aeromag_io::sensor_names(n)
                    .iter()
                    .find_map(|s| names.iter().position(|h| h.eq_ignore_ascii_case(s)))
            };
            opts.columns
                .get(canonical)
                .and_then(by)
                .or_else(|| by(canonical))
                .or_else(|| model.columns.get(canonical).and_then(|n| by(n)))
        };
        let find = |canonical: &str| -> Result<usize> {
            lookup(canonical).ok_or_else(|| {
                    Error::bad_input(format!(
                        "the stream has no column for `{canonical}`{}; its columns: {} (map one with --columns {canonical}=NAME)",
                        model
                            .columns
                            .get(canonical)
                            .map(|n| format!(" (the model was fitted on `{n}`)"))
                            .unwrap_or_default(),
                        listed(&names)
                    ))
                })
        };
        let mut nav = match opts.adapt {
            Some(_) => ["vn", "ve", "alt", "lat", "lon"].map(lookup),
            None => [None; 5],
        };
        // The position is read only to check `--speed` (the Kalman filter
        // without `vn`, `ve`).
        if opts.adapt != Some(Adapt::Kalman) || (nav[0].is_some() && nav[1].is_some()) {
            (nav[3], nav[4]) = (None, None);
        }
        let speed_m_s = match opts.speed_m_s {
            Some(v) if !(0.0..=MAX_GROUND_SPEED_M_S).contains(&v) => {
                return Err(Error::bad_input(format!(
                    "ground speed {} m/s: must be from 0 to {MAX_GROUND_SPEED_M_S}",
                    aeromag_core::error::shown(v)
                )));
            }
            Some(v) => v,
            None => f64::NAN,
        };
        if opts.adapt == Some(Adapt::Kalman) && speed_m_s.is_nan() && nav[..2].contains(&None) {
            return Err(Error::bad_input(format!(
                "the adaptive Kalman filter needs the ground speed: the stream has no `vn` and `ve` \
                 columns (its columns: {}); map them with --columns vn=NAME,ve=NAME or give --speed M/S",
                names.join(", ")
            )));
        }
        let engine = causal.engine(opts.adapt, &opts.adapt_options)?;
        let fields = Fields {
            time: find("time")?,
            flux: [find("flux_x")?, find("flux_y")?, find("flux_z")?],
            mag: find("mag")?,
            channels: model
                .design
                .terms
                .extras()
                .iter()
                .map(|x| find(&x.channel))
                .collect::<Result<_>>()?,
            nav,
            count: names.len(),
            last: 0,
        };
        // One stream column in two roles (`--columns mag=flux_x`): every
        // line was flagged malformed without a reason.
        let roles: Vec<(&str, usize)> = [("time", fields.time), ("mag", fields.mag)]
            .into_iter()
            .chain(["flux_x", "flux_y", "flux_z"].into_iter().zip(fields.flux))
            .collect();
        for (k, (a, i)) in roles.iter().enumerate() {
            if let Some((b, _)) = roles[..k].iter().find(|(_, j)| j == i) {
                return Err(Error::bad_input(format!(
                    "the stream column {:?} would be read as both `{b}` and `{a}`; its columns: {} \
                     (map each with --columns {a}=NAME)",
                    clipped(names[*i]),
                    listed(&names)
                )));
            }
        }
        let mut fields = fields;
        fields.last = [fields.time, fields.mag]
            .into_iter()
            .chain(fields.flux)
            .chain(fields.channels.iter().copied())
            .chain(fields.nav.iter().flatten().copied())
            .max()
            .unwrap_or(0);
        for out in STREAM_OUTPUT {
            if names.iter().any(|n| n.eq_ignore_ascii_case(out)) {
                return Err(Error::bad_input(format!(
                    "the stream already has a column `{out}`; drop or rename it first"
                )));
            }
        }
        Ok(Self {
            channels: vec![0.0; fields.channels.len()],
            nav: [f64::NAN; 5],
            speed_check: SpeedCheck::default(),
            engine,
            speed_m_s,
            fields,
            header: normalised(header),
            names: names.iter().map(|n| n.to_string()).collect(),
            counts: StreamCounts::default(),
            issues: StreamIssues::default(),
        })
    }

    /// The output header: the input's names and [`STREAM_OUTPUT`].
    pub fn header(&self) -> String {
        format!("{},{}", self.header, STREAM_OUTPUT.join(","))
    }

    /// Compensate one data line (without its line end) and append it to
    /// `out` with the three values and a newline. Numbers are written as
    /// the CSV writer writes them (shortest round trip; missing as an empty
    /// cell). A line not compensated for a reason the user must see is
    /// counted in [`LineCompensator::issues`].
    pub fn line(&mut self, line: &str, out: &mut String) -> StreamFlag {
        let line = line.trim_end_matches(['\r', '\n']);
        let at = self.counts.lines + 1;
        let (interf, comp, flag) = match self.parse(line) {
            Err(why) => {
                self.issues.malformed.add(at, why);
                (f64::NAN, f64::NAN, StreamFlag::Malformed)
            }
            Ok((time_s, flux_nt, mag_nt)) => {
                let sample = OnlineSample {
                    time_s,
                    flux_nt,
                    mag_nt,
                    channels: &self.channels,
                };
                let [vn, ve, alt, lat, lon] = self.nav;
                let speed_m_s = if self.fields.nav[0].is_some() && self.fields.nav[1].is_some() {
                    vn.hypot(ve)
                } else {
                    // `--speed`, against the positions when there are any.
                    if !self.speed_m_s.is_nan()
                        && lat.is_finite()
                        && lon.is_finite()
                        && let Some((v, span)) = self.speed_check.push(time_s, [lat, lon])
                        && speed_disagrees(v, self.speed_m_s)
                    {
                        self.issues.speed.add(
                            at,
                            format!(
                                "{} m/s over {} s against --speed {}",
                                shown((v * 10.0).round() / 10.0),
                                shown((span * 10.0).round() / 10.0),
                                shown(self.speed_m_s)
                            ),
                        );
                    }
                    self.speed_m_s
                };
                let (o, beyond) = self.engine.push_told(
                    &sample,
                    Navigation {
                        speed_m_s,
                        alt_m: alt,
                    },
                );
                if beyond {
                    self.issues.beyond_field.add(at, String::new());
                }
                if o.status == SampleStatus::Missing
                    && let Some((what, v)) = sample.below_reading()
                {
                    // 5.3e-5 (tesla), not 0.00005310232207072217.
                    let v = if v == 0.0 || v.abs() >= 1e-3 {
                        aeromag_core::error::shown(v)
                    } else {
                        format!("{v:.3e}")
                    };
                    self.issues.not_reading.add(at, format!("{what} = {v} nT"));
                }
                (
                    o.interference_nt,
                    o.compensated_nt,
                    StreamFlag::from(o.status),
                )
            }
        };
        self.counts.add(flag);
        out.push_str(line);
        let mut text = aeromag_io::NumberText::new();
        for v in [interf, comp] {
            out.push(',');
            if v.is_finite() {
                out.push_str(text.format(v));
            }
        }
        out.push(',');
        out.push(char::from(b'0' + flag as u8));
        out.push('\n');
        flag
    }

    /// A line too long to read: flagged malformed, written as an empty
    /// line with the three values.
    fn malformed(&mut self, out: &mut String) {
        let at = self.counts.lines + 1;
        self.issues
            .malformed
            .add(at, format!("longer than {} bytes", MAX_STREAM_LINE_BYTES));
        self.counts.add(StreamFlag::Malformed);
        out.push_str(",,,4\n");
    }

    /// The lines not compensated for a reason the user must see, so far.
    pub fn issues(&self) -> &StreamIssues {
        &self.issues
    }

    /// The inputs of a line (channels into `self.channels`), or why the
    /// line is malformed. Empty cells and `NaN` are missing values.
    fn parse(&mut self, line: &str) -> std::result::Result<(f64, [f64; 3], f64), String> {
        let f = &self.fields;
        let names = &self.names;
        // Binary data in any cell, used or not (`compensate` refuses the
        // file; the stream took the line and echoed the NUL).
        if let Some(at) = memchr::memchr(0, line.as_bytes()) {
            let k = memchr::memchr_iter(b',', &line.as_bytes()[..at]).count();
            return Err(match names.get(k) {
                Some(name) => format!("column {:?}: a NUL byte (binary data)", clipped(name)),
                None => format!("a NUL byte (binary data) in cell {}", k + 1),
            });
        }
        let (mut time, mut flux, mut mag) = (f64::NAN, [f64::NAN; 3], f64::NAN);
        let mut cell = |k: usize, text: &str| -> std::result::Result<(), String> {
            let slot = if k == f.time {
                &mut time
            } else if k == f.mag {
                &mut mag
            } else if let Some(a) = f.flux.iter().position(|&i| i == k) {
                &mut flux[a]
            } else if let Some(c) = f.channels.iter().position(|&i| i == k) {
                &mut self.channels[c]
            } else if let Some(c) = f.nav.iter().position(|&i| i == Some(k)) {
                &mut self.nav[c]
            } else {
                return Ok(());
            };
            *slot = number(text).ok_or_else(|| {
                format!(
                    "column {:?}: {} is not a number",
                    clipped(&names[k]),
                    aeromag_core::error::shown_text(text)
                )
            })?;
            Ok(())
        };
        // The cells up to the last input, then only the commas counted.
        let bytes = line.as_bytes();
        let (mut start, mut k) = (0, 0);
        let mut commas = memchr::memchr_iter(b',', bytes);
        let cells = |n: usize| format!("{n} cells where the header has {}", f.count);
        while k < f.last {
            let end = commas.next().unwrap_or(bytes.len());
            cell(k, &line[start..end.min(bytes.len())])?;
            if end >= bytes.len() {
                return Err(cells(k + 1));
            }
            (start, k) = (end + 1, k + 1);
        }
        let rest = &bytes[start..];
        let end = memchr::memchr(b',', rest).map_or(bytes.len(), |i| start + i);
        cell(k, &line[start..end])?;
        let n = k + 1 + memchr::memchr_iter(b',', &bytes[end.min(bytes.len())..]).count();
        if n != f.count {
            return Err(cells(n));
        }
        // Beyond any magnetic field: a corrupted cell (NaN is missing).
        let beyond = [
            (f.mag, mag),
            (f.flux[0], flux[0]),
            (f.flux[1], flux[1]),
            (f.flux[2], flux[2]),
        ]
        .into_iter()
        .find(|(_, v)| v.abs() > aeromag_io::MAX_FIELD_NT);
        if let Some((k, v)) = beyond {
            return Err(format!(
                "column {:?}: {} is beyond any magnetic field ({} nT)",
                clipped(&names[k]),
                aeromag_core::error::shown(v),
                aeromag_core::error::shown(aeromag_io::MAX_FIELD_NT)
            ));
        }
        Ok((time, flux, mag))
    }

    /// What became of the lines so far.
    pub fn counts(&self) -> &StreamCounts {
        &self.counts
    }

    /// Forget the stream's state (a new connection): the next line starts
    /// a run whatever its time. The counts are kept.
    pub fn reset(&mut self) {
        self.engine.reset();
    }

    /// The current coefficients and their standard deviations (column
    /// order) when adapting, `None` with the model's fixed coefficients.
    pub fn coefficients(&self) -> Option<(&[f64], Vec<f64>)> {
        self.engine.coefficients()
    }

    /// When adapting, the samples not learnt from as outliers
    /// ([`OnlineEngine::outliers`]).
    pub fn outliers(&self) -> Option<u64> {
        self.engine.outliers()
    }
}

/// Whether a line is a comment (`#` first), as in a CSV file.
fn is_comment(line: &[u8]) -> bool {
    line.first() == Some(&b'#')
}

/// The longest line read, bytes: a longer one is malformed (and skipped to
/// its end), so a hostile peer cannot make the stream hold unbounded text.
pub const MAX_STREAM_LINE_BYTES: usize = 1 << 20;

/// A stream of lines through one model, over one or several connections
/// (`aeromag stream`): each connection's first line is its header unless
/// the columns were named ([`LineStream::new`]); a connection with the same
/// header as the last continues its state (the gap rule decides whether
/// the run goes on), another header starts afresh. The counts add up over
/// connections.
///
/// Comment lines (`#` first, as in a CSV file: the `# units:` lines that
/// `aeromag simulate` writes) are written back as they are, in their
/// place, and are not data lines; so are blank lines before the header.
#[derive(Debug, Clone)]
pub struct LineStream {
    model: TlModel,
    opts: StreamOptions,
    columns_in: Option<String>,
    comp: Option<LineCompensator>,
    before: StreamCounts,
    issues_before: StreamIssues,
}

impl LineStream {
    /// `model` on streams laid out as `columns_in` (comma-separated names;
    /// `None`: each connection's first line). Bad input as
    /// [`LineCompensator::new`], checked now when the columns are named.
    pub fn new(model: &TlModel, opts: &StreamOptions, columns_in: Option<&str>) -> Result<Self> {
        let comp = columns_in
            .map(|h| LineCompensator::new(model, h, opts))
            .transpose()?;
        Ok(Self {
            model: model.clone(),
            opts: opts.clone(),
            columns_in: columns_in.map(str::to_string),
            comp,
            before: StreamCounts::default(),
            issues_before: StreamIssues::default(),
        })
    }

    /// Serve one connection: [`LineStream::start`], then
    /// [`LineStream::lines`] until `input` ends.
    pub fn serve(
        &mut self,
        mut input: impl std::io::BufRead,
        mut output: impl std::io::Write,
        peer: &str,
    ) -> Result<()> {
        if self.start(&mut input, &mut output, peer)? {
            self.lines(input, output, peer)?;
        }
        Ok(())
    }

    /// Start a connection: read its header (unless the columns were named)
    /// and write the output header, flushed. `false` when `input` ended
    /// before a header. `peer` names the connection in errors; a header
    /// that does not name the model's inputs is bad input.
    pub fn start(
        &mut self,
        input: &mut impl std::io::BufRead,
        output: &mut impl std::io::Write,
        peer: &str,
    ) -> Result<bool> {
        if self.columns_in.is_none() {
            let mut buf = Vec::new();
            let header = loop {
                if !read_line(input, &mut buf, &mut false, peer, || Ok(()))? {
                    return Ok(false);
                }
                let line = String::from_utf8_lossy(&buf);
                let line = line.trim_end_matches(['\r', '\n']);
                if !(is_comment(&buf) || line.trim().is_empty()) {
                    break line.to_string();
                }
                // A comment or blank line before the header, written back
                // at once (however many come, none is held).
                write_flushed(output, &format!("{line}\n"), peer)?;
            };
            let header = header.as_str();
            if self
                .comp
                .as_ref()
                .is_none_or(|c| c.header != normalised(header))
            {
                let next = LineCompensator::new(&self.model, header, &self.opts)?;
                if let Some(old) = self.comp.replace(next) {
                    self.before = self.before.plus(old.counts());
                    self.issues_before = self.issues_before.then(old.issues());
                }
            }
        }
        let comp = self.comp.as_ref().expect("a header");
        let out = format!("{}\n", comp.header());
        write_flushed(output, &out, peer)?;
        Ok(true)
    }

    /// Every line of `input` compensated into `output`, each flushed, until
    /// `input` ends (after [`LineStream::start`]; a datagram's lines).
    /// Reading or writing failing ends it with [`Error::Read`] /
    /// [`Error::Write`].
    pub fn lines(
        &mut self,
        mut input: impl std::io::BufRead,
        mut output: impl std::io::Write,
        peer: &str,
    ) -> Result<()> {
        let Some(comp) = self.comp.as_mut() else {
            return Err(Error::bad_input(format!(
                "{peer}: data before a header line"
            )));
        };
        let (mut buf, mut out, mut drained) = (Vec::new(), String::new(), true);
        loop {
            // Before a read may wait for input, everything compensated so
            // far goes out, flushed: no line is held back by one that has
            // not arrived, and lines that arrived together go out together.
            let got = read_line(&mut input, &mut buf, &mut drained, peer, || {
                write_flushed(&mut output, &out, peer)?;
                out.clear();
                Ok(())
            })?;
            if !got {
                return write_flushed(&mut output, &out, peer);
            }
            if buf.len() > MAX_STREAM_LINE_BYTES {
                comp.malformed(&mut out);
            } else if is_comment(&buf) || buf.iter().all(u8::is_ascii_whitespace) {
                // A comment or a blank line (which a file reader skips),
                // written back as it is; no data line.
                out.push_str(String::from_utf8_lossy(&buf).trim_end_matches(['\r', '\n']));
                out.push('\n');
            } else {
                match std::str::from_utf8(&buf) {
                    Ok(text) => comp.line(text, &mut out),
                    Err(_) => comp.line(&String::from_utf8_lossy(&buf), &mut out),
                };
            }
        }
    }

    /// What became of the lines so far, over every connection.
    pub fn counts(&self) -> StreamCounts {
        self.comp
            .as_ref()
            .map_or(self.before, |c| self.before.plus(c.counts()))
    }

    /// Why lines were not compensated so far, over every connection (data
    /// lines are counted from each header that changed the columns).
    pub fn issues(&self) -> StreamIssues {
        self.comp.as_ref().map_or_else(
            || self.issues_before.clone(),
            |c| self.issues_before.then(c.issues()),
        )
    }

    /// When adapting, the samples not learnt from as outliers
    /// ([`OnlineEngine::outliers`]; `None` otherwise, or before the first
    /// header).
    pub fn outliers(&self) -> Option<u64> {
        self.comp.as_ref().and_then(|c| c.outliers())
    }

    /// When adapting: each coefficient's name, current value and standard
    /// deviation (empty otherwise, or before the first header).
    pub fn coefficients(&self) -> Vec<(String, f64, f64)> {
        let Some((values, std)) = self.comp.as_ref().and_then(|c| c.coefficients()) else {
            return Vec::new();
        };
        self.model
            .design
            .column_names()
            .into_iter()
            .zip(values.iter().zip(std))
            .map(|(n, (v, s))| (n, *v, s))
            .collect()
    }
}

impl StreamCounts {
    fn plus(&self, o: &StreamCounts) -> StreamCounts {
        StreamCounts {
            lines: self.lines + o.lines,
            compensated: self.compensated + o.compensated,
            restarts: self.restarts + o.restarts,
            missing: self.missing + o.missing,
            time_backwards: self.time_backwards + o.time_backwards,
            malformed: self.malformed + o.malformed,
        }
    }
}

fn read_error(peer: &str, source: std::io::Error) -> Error {
    Error::Read {
        path: peer.into(),
        source,
    }
}

/// Write `text` and flush.
fn write_flushed(output: &mut impl std::io::Write, text: &str, peer: &str) -> Result<()> {
    output
        .write_all(text.as_bytes())
        .and_then(|()| output.flush())
        .map_err(|source| Error::Write {
            path: peer.into(),
            source,
        })
}

/// A cell's number: empty is missing (NaN); text that is not a number is
/// `None` (a malformed line).
fn number(cell: &str) -> Option<f64> {
    let c = cell.trim();
    // Quoted, as a CSV writer may quote any cell (`"49302"`), and as the
    // file reader takes it.
    let c = c
        .strip_prefix('"')
        .and_then(|c| c.strip_suffix('"'))
        .map_or(c, str::trim);
    if c.is_empty() {
        Some(f64::NAN)
    } else {
        c.parse::<f64>().ok()
    }
}

/// At most 40 characters of a name, for messages.
fn clipped(name: &str) -> String {
    match name.char_indices().nth(40) {
        Some((i, _)) => format!("{}…", &name[..i]),
        None => name.to_string(),
    }
}

/// A header's names for a message: the first 30, each clipped, control
/// characters escaped.
fn listed(names: &[&str]) -> String {
    let mut shown: Vec<String> = names
        .iter()
        .take(30)
        .map(|n| clipped(n).escape_default().to_string())
        .collect();
    if names.len() > 30 {
        shown.push(format!("… ({} columns)", names.len()));
    }
    shown.join(", ")
}

/// A header's names, trimmed, joined by commas (a byte-order mark dropped).
fn normalised(header: &str) -> String {
    header
        .strip_prefix('\u{feff}')
        .unwrap_or(header)
        .split(',')
        .map(str::trim)
        .collect::<Vec<_>>()
        .join(",")
}

/// One line of `input` into `buf` (its end included), at most
/// [`MAX_STREAM_LINE_BYTES`] + 1 bytes kept (the rest read and dropped);
/// `false` at the end of the input. `before_wait` runs before the reader
/// refills an empty buffer (which may wait for input); `drained` carries
/// whether the buffer is empty from one call to the next (`true` at the
/// start). `peer` names the input in errors.
fn read_line(
    input: &mut impl std::io::BufRead,
    buf: &mut Vec<u8>,
    drained: &mut bool,
    peer: &str,
    mut before_wait: impl FnMut() -> Result<()>,
) -> Result<bool> {
    buf.clear();
    let mut any = false;
    loop {
        if *drained {
            before_wait()?;
        }
        let chunk = input.fill_buf().map_err(|e| read_error(peer, e))?;
        if chunk.is_empty() {
            return Ok(any);
        }
        any = true;
        let (take, done) = match memchr::memchr(b'\n', chunk) {
            Some(k) => (k + 1, true),
            None => (chunk.len(), false),
        };
        let room = (MAX_STREAM_LINE_BYTES + 1).saturating_sub(buf.len());
        buf.extend_from_slice(&chunk[..take.min(room)]);
        *drained = take == chunk.len();
        input.consume(take);
        if done {
            return Ok(true);
        }
    }
}
