//! Checks that every command runs on its input table.
//!
//! - [`check_time`]: `time` (s) must be strictly increasing and never missing
//!   (spec `data-formats.md`: "a duplicate or a step back is an error that
//!   names the row"), and within ±[`MAX_TIME_S`].
//! - [`check_units`]: plausibility of units. Errors for values that cannot
//!   be in the expected unit, [`Warning`]s for values that are merely
//!   suspicious. Statistics use the finite values only; medians are taken
//!   over at most [`MEDIAN_SAMPLES`] evenly strided samples (deterministic).
//!
//! Rules of [`check_units`] (Earth's total field is about 22 000–67 000 nT).
//! Every warning is named by its [`WarningKind`], printed after the message
//! (`[field-range]`):
//!
//! | columns | error | warning |
//! |---|---|---|
//! | `mag`, `igrf` | median \|B\| < 1 (tesla 1e-6–1e-3, gauss 0.05–1, else "wrong units") or > 1e6 (pT?); median \|B\| in [`EARTH_FIELD_UT`] (microtesla; for `mag` only when every value lies within half and twice the median, as a total field does and an anomaly does not) | median \|B\| outside 15 000–75 000 nT (`field-range`) |
//! | `mag` | when its median \|B\| is at least 15 000 nT (a total field, not an anomaly): any value below [`MIN_READING_NT`] (a dropout value, a negated reading), naming the first row | — |
//! | `mag`, `igrf`, `flux_x/y/z`, `diurnal` | once the units pass: any \|value\| > [`MAX_FIELD_NT`] (a corrupted cell, a numeric dummy such as −1e32), naming the first row | — |
//! | `flux_x/y/z` | one component: max \|B\| < 1e-3 or median \|B\| > 1e6; all three: median of the vector magnitude as for `mag` | magnitude outside 15 000–75 000 nT; median relative difference from `mag` above 10 % (`vector-vs-scalar`) |
//! | `diurnal` | 0 < max \|B\| < 1e-3 (tesla), median \|B\| > 1e6 | — |
//! | `lat` | \|lat\| > 90 | all \|lat\| ≤ π/2 and \|lon\| ≤ π (radians?) |
//! | `lon` | \|lon\| > 360 | (see `lat`) |
//! | `lat`, `lon` derived from `ins_lat`, `ins_lon` | as `lat`, `lon`, naming the file's field | taken as degrees because a value cannot be radians (`ins-degrees`; [`crate::derive`]) |
//! | `roll`, `pitch` | \|roll\| > 180, \|pitch\| > 90 | |
//! | `yaw` | — | outside ±360 |
//! | `roll`, `pitch`, `yaw` | — | radians: \|roll\|, \|pitch\| ≤ π/2 while yaw stays in [−π, 2π] and spans more than π (a turn of over 180° in radians; in degrees that would be a heading range of 3–9° without a single roll above 1.6°) |
//! | `alt` | any \|value\| > [`MAX_ALT_M`], naming the first row | median > 20 000 m (feet or km?) |
//! | [`FINITE_COLUMNS`] (`time`, position, velocity, attitude, fields, `line`) | an infinite value (`inf` in a cell), naming the first row | — |
//!
//! A single flux component is tested by its maximum rather than its median,
//! because one body-frame component can legitimately stay near zero (e.g. the
//! vertical component at the magnetic equator).

use std::fmt;

use serde::Serialize;

use crate::columns::MAGNETIC_COLUMNS;
use crate::derive::Conversion;
use crate::error::{IoError, Result};
use crate::table::FlightTable;
use aeromag_core::error::{figure, shown};

/// Columns in which an infinite value is an error ([`check_units`]): the
/// canonical navigation, attitude, field and line columns, whose
/// infinities would otherwise pass every range rule (those test finite
/// values) and come out of a command as `inf` or NaN.
pub const FINITE_COLUMNS: [&str; 17] = [
    "time", "lat", "lon", "alt", "vn", "ve", "vd", "roll", "pitch", "yaw", "mag", "igrf", "flux_x",
    "flux_y", "flux_z", "diurnal", "line",
];

/// Medians are computed over at most this many samples.
pub const MEDIAN_SAMPLES: usize = 100_000;

/// A suspicion about the input that does not stop a command.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Warning {
    /// Which check raised it.
    pub kind: WarningKind,
    /// File (or `"<in-memory table>"`).
    pub file: String,
    /// Column concerned, if one.
    pub column: Option<String>,
    /// 0-based data row concerned, if one.
    pub row: Option<usize>,
    /// 1-based file line of that row, when known.
    pub line: Option<u64>,
    /// What looks wrong.
    pub message: String,
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "'{}'", self.file)?;
        if let Some(c) = &self.column {
            write!(f, ": column '{c}'")?;
        }
        if let Some(r) = self.row {
            write!(f, " at data row {}", r + 1)?;
        }
        if let Some(l) = self.line {
            write!(f, " (line {l})")?;
        }
        write!(f, ": {} [{}]", self.message, self.kind.name())
    }
}

/// The named checks that raise [`Warning`]s.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum WarningKind {
    /// A total field outside Earth's (15 000–75 000 nT): anomaly, corrected
    /// data or another unit.
    FieldRange,
    /// The vector magnetometer's magnitude disagrees with the scalar
    /// magnetometer by more than [`VECTOR_SCALAR_TOLERANCE`].
    VectorVsScalar,
    /// Angles that look like radians in a degree column.
    Radians,
    /// A yaw outside ±360°.
    YawRange,
    /// An altitude that looks like feet or km.
    AltitudeUnit,
    /// A median ground speed no aircraft flies: time in minutes or hours
    /// (or positions in another unit).
    TimeUnit,
    /// `ins_lat`/`ins_lon`, which the SGL layout records in radians, taken
    /// as degrees because their values cannot be radians
    /// ([`crate::derive::ins_position_unit`]).
    InsDegrees,
}

impl WarningKind {
    /// The name printed after the message (`field-range`).
    pub fn name(self) -> &'static str {
        match self {
            WarningKind::FieldRange => "field-range",
            WarningKind::VectorVsScalar => "vector-vs-scalar",
            WarningKind::Radians => "radians",
            WarningKind::YawRange => "yaw-range",
            WarningKind::AltitudeUnit => "altitude-unit",
            WarningKind::TimeUnit => "time-unit",
            WarningKind::InsDegrees => "ins-degrees",
        }
    }
}

/// Relative difference (median over rows) between the vector
/// magnetometer's magnitude and the scalar reading above which
/// [`check_units`] warns. Uncalibrated fluxgates differ from the scalar by a
/// few per cent: on the SGL sample `Flt1003_sample.xyz` the four fluxgates
/// differ from the five scalar magnetometers by 0.2–9.5 % (FLUXC vs
/// UNCOMPMAG2 the most); a wrong column, a component in another unit or a
/// total channel mapped as a component gives tens of per cent or more.
pub const VECTOR_SCALAR_TOLERANCE: f64 = 0.10;

pub use aeromag_core::field::{MAX_ALT_M, MAX_FIELD_NT, MIN_READING_NT};

/// The largest median ground speed taken as a flight's, m/s: an airliner
/// cruises at 250 m/s and a fast jet at 700; above, the time is in
/// minutes or hours (a 60 m/s survey with its time in minutes moves at
/// 3 600 m/s), and [`check_units`] warns.
pub const MAX_MEDIAN_GROUND_SPEED_M_S: f64 = aeromag_core::field::MAX_GROUND_SPEED_M_S;

/// Below this median ground speed (m/s), a platform that moves at least
/// [`MIN_MOVING_STEP_M`] between rows has its time in milliseconds: a
/// 2 Hz survey at 70 m/s with its time in ms moves at 0.07 m/s, 35 m per
/// row (levelling then fitted k = 505 s for 0.505 s). A base station does
/// not move; a boat or a walker moving 5 m per row at under 1 m/s samples
/// every 5 s or more.
pub const MIN_MOVING_SPEED_M_S: f64 = 1.0;

/// The distance between two nearby positions `[lat, lon]` (degrees), m:
/// equirectangular on a 6 371 km sphere, at the first one's latitude (for
/// the step between consecutive samples, not for long distances).
pub fn step_distance_m(a: [f64; 2], b: [f64; 2]) -> f64 {
    const EARTH_RADIUS_M: f64 = 6_371_000.0;
    let dlat = (b[0] - a[0]).to_radians();
    let dlon = (b[1] - a[1]).to_radians() * a[0].to_radians().cos();
    EARTH_RADIUS_M * dlat.hypot(dlon)
}

/// The median distance between rows (m) from which [`MIN_MOVING_SPEED_M_S`]
/// applies.
pub const MIN_MOVING_STEP_M: f64 = 5.0;

/// Earth's total field, nT: a `mag` median outside is warned about.
pub const EARTH_FIELD_NT: (f64, f64) = (15_000.0, 75_000.0);

/// Earth's total field in microtesla ([`EARTH_FIELD_NT`] / 1000): a total
/// field whose median lies here is in µT, 1000 times too small for nT (a
/// fit on it gave a model with exit 0).
pub const EARTH_FIELD_UT: (f64, f64) = (15.0, 75.0);

/// Checks that `time` exists, has no missing value and strictly increases.
///
/// Errors: [`IoError::MissingColumn`], [`IoError::MissingValue`] (a NaN time,
/// naming the row and line), [`IoError::NotIncreasing`] (a repeat or a step
/// back, naming both rows, their lines and values), [`IoError::Units`] (a
/// time beyond ±[`MAX_TIME_S`]).
pub fn check_time(table: &FlightTable) -> Result<()> {
    let t = table.require("time")?;
    // Blocks that increase throughout (`x < y` is false when either is
    // NaN) pass in one pass that vectorises; the first that does not is
    // searched row by row for its first error, the file's first (earlier
    // blocks have none). 10⁷ rows: about 3× faster than row by row.
    for start in (0..t.len()).step_by(TIME_BLOCK) {
        let end = (start + TIME_BLOCK).min(t.len());
        let from = start.saturating_sub(1);
        let (a, b) = (&t[from..end - 1], &t[from + 1..end]);
        let increasing = a.iter().zip(b).fold(true, |ok, (x, y)| ok & (x < y));
        if !increasing || t[start].is_nan() {
            return first_time_error(table, t, start..end);
        }
    }
    // Increasing: the first and last times are the extremes.
    for i in [0, t.len().saturating_sub(1)] {
        let Some(&v) = t.get(i) else { continue };
        if v.is_infinite() {
            return Err(infinite_time(table, i, v));
        }
        if v.abs() > MAX_TIME_S {
            return Err(IoError::Units {
                file: table.file_label(),
                column: "time".into(),
                message: format!(
                    "time {} s at {} is beyond ±{} s (3 000 years): milliseconds, microseconds or \
                     nanoseconds, or a corrupted cell? expected seconds",
                    shown(v),
                    data_row(table, i),
                    shown(MAX_TIME_S)
                ),
            });
        }
    }
    check_time_steps(table, t)
}

/// A time step below this fraction of the flight's median step is a
/// duplicated or corrupted time, refused like time going backwards: the
/// eddy-current terms divide by the step (two rows 1e-9 s apart in a 10 Hz
/// flight gave an interference of −177 747 nT, 1e-6 s apart one 177 nT
/// off, written as compensated). Sampling jitter is a few per cent of the
/// step.
pub const MIN_TIME_STEP_FRACTION: f64 = 0.01;

/// Checks (on increasing times) that no step is below
/// [`MIN_TIME_STEP_FRACTION`] of the median step. The median is worked out
/// only when the shortest step is below that fraction of the mean step.
fn check_time_steps(table: &FlightTable, t: &[f64]) -> Result<()> {
    let n = t.len();
    if n < 3 {
        return Ok(());
    }
    let step = |i: usize| t[i] - t[i - 1];
    let shortest = (1..n).map(step).fold(f64::INFINITY, f64::min);
    let mean = (t[n - 1] - t[0]) / (n - 1) as f64;
    if shortest >= MIN_TIME_STEP_FRACTION * mean {
        return Ok(());
    }
    let mut steps: Vec<f64> = (1..n).map(step).collect();
    let Some(median) = median_in_place(&mut steps) else {
        return Ok(());
    };
    let limit = MIN_TIME_STEP_FRACTION * median;
    match (1..n).find(|&i| step(i) < limit) {
        None => Ok(()),
        Some(i) => Err(IoError::Units {
            file: table.file_label(),
            column: "time".into(),
            message: format!(
                "{} has time {} s, {} s after {} ({} s): below {} % of the median step ({} s); \
                 a duplicated or corrupted time? (the eddy-current terms divide by the step)",
                data_row(table, i),
                shown(t[i]),
                figure(step(i)),
                data_row(table, i - 1),
                shown(t[i - 1]),
                shown(100.0 * MIN_TIME_STEP_FRACTION),
                figure(median)
            ),
        }),
    }
}

/// An infinite time at row `i` (it was reported as time going backwards,
/// at the row after it).
fn infinite_time(table: &FlightTable, i: usize, v: f64) -> IoError {
    IoError::Units {
        file: table.file_label(),
        column: "time".into(),
        message: format!("time {v} at {} is no time", data_row(table, i)),
    }
}

/// The largest time taken as one in seconds (10¹¹ s, 3 000 years; Unix
/// time is 1.8·10⁹ s): beyond, the clock counts milliseconds (Unix time
/// in ms is 1.8·10¹²) or smaller units, which every command would take
/// for a flight sampled a thousand times too slowly, or a cell is
/// corrupted (a time from −10³⁰⁸ to 10³⁰⁸ s gave `inspect` an infinite
/// duration with exit 0).
pub const MAX_TIME_S: f64 = 1e11;

/// Rows per block of [`check_time`].
const TIME_BLOCK: usize = 4096;

/// The first missing time or step that does not increase among `rows` of
/// `t` (with the step into the first of them); `Ok` when there is none.
fn first_time_error(table: &FlightTable, t: &[f64], rows: std::ops::Range<usize>) -> Result<()> {
    for i in rows {
        let v = t[i];
        if v.is_infinite() {
            return Err(infinite_time(table, i, v));
        }
        if v.is_nan() {
            return Err(IoError::MissingValue {
                file: table.file_label(),
                column: "time".into(),
                row: table.file_row(i),
                line: table.line_of_row(i),
            });
        }
        if i > 0 && v <= t[i - 1] {
            return Err(IoError::NotIncreasing {
                file: table.file_label(),
                column: "time".into(),
                row_a: table.file_row(i - 1),
                line_a: table.line_of_row(i - 1),
                value_a: t[i - 1],
                row_b: table.file_row(i),
                line_b: table.line_of_row(i),
                value_b: v,
            });
        }
    }
    Ok(())
}

/// Checks the units of magnetic, position and attitude columns (rules in
/// the module docs). Absent columns are skipped.
pub fn check_units(table: &FlightTable) -> Result<Vec<Warning>> {
    let mut warnings = Vec::new();
    let ctx = Ctx { table };
    ctx.no_infinity()?;
    let stats = Stats::of(table);
    for (name, m, max) in [
        ("mag", stats.mag, stats.mag_max),
        ("igrf", stats.igrf, stats.igrf_max),
    ] {
        if table.column(name).is_some() {
            let range = (name == "mag").then_some((stats.mag_min, stats.mag_max));
            ctx.total_field(name, m, range, &mut warnings)?;
            ctx.within_field(name, max)?;
        }
    }
    ctx.readings("mag", stats.mag, stats.mag_min)?;
    for (name, c) in ["flux_x", "flux_y", "flux_z", "diurnal"]
        .into_iter()
        .zip(stats.components)
    {
        if table.column(name).is_some() {
            ctx.component(name, c)?;
            ctx.within_field(name, c.0)?;
        }
    }
    if let Some((norm, vs_mag)) = stats.vector {
        ctx.total_field("flux_x/flux_y/flux_z", norm, None, &mut warnings)?;
        if let Some(d) = vs_mag
            && d.abs() > VECTOR_SCALAR_TOLERANCE
        {
            let names = |c: &str| table.resolve(c).unwrap_or(c).to_string();
            warnings.push(ctx.warn(
                WarningKind::VectorVsScalar,
                "flux_x/flux_y/flux_z",
                None,
                format!(
                    "the vector magnetometer's magnitude ({}, {}, {}) differs from the scalar magnetometer ({}) by {:+.1} % (median); expected within {:.0} %: another sensor's or a total channel mapped as a component, or another unit?",
                    names("flux_x"),
                    names("flux_y"),
                    names("flux_z"),
                    names("mag"),
                    100.0 * d,
                    100.0 * VECTOR_SCALAR_TOLERANCE
                ),
            ));
        }
    }
    ctx.position(&mut warnings)?;
    ctx.attitude(&mut warnings)?;
    if let Some(alt) = table.column("alt")
        && let Some((i, v)) = first_where(alt, |v| v.abs() > MAX_ALT_M)
    {
        return Err(ctx.units(
            "alt",
            format!(
                "height {} m at {} is outside ±{} m: a corrupted cell, or a number standing for a missing value? leave the cell empty (`*` in an XYZ file) for a missing value",
                shown(v),
                data_row(table, i),
                shown(MAX_ALT_M)
            ),
        ));
    }
    if let Some(m) = stats.alt
        && m > 20_000.0
    {
        warnings.push(ctx.warn(
            WarningKind::AltitudeUnit,
            "alt",
            None,
            format!(
                "median altitude {} m is above 20 km: feet or another unit? expected m",
                shown(m)
            ),
        ));
    }
    Ok(warnings)
}

/// The unit checks [`check_units`] runs on `mag` and `flux_x/y/z`, for
/// another sensor of the flight: the scalar column `mag` (a total field:
/// tesla, gauss, microtesla and picotesla refused, readings below
/// [`MIN_READING_NT`] and beyond [`MAX_FIELD_NT`] refused) and the vector
/// magnetometer's components `flux` (tesla, picotesla refused) and
/// magnitude. File column names or canonical names ([`FlightTable::resolve`]);
/// a column the table lacks is not checked. Before, `calibrate --mag
/// mag_1_uc,mag_4_uc` fitted a `mag_4_uc` in µT or T with exit 0 (and a
/// model in pT, which `compensate` then said "does not fit").
pub fn check_sensor_units(table: &FlightTable, mag: &str, flux: [&str; 3]) -> Result<()> {
    let ctx = Ctx { table };
    let column = |n: &str| {
        table
            .resolve(n)
            .and_then(|c| table.column(c).map(|v| (c, v)))
    };
    if let Some((name, v)) = column(mag) {
        let (median, min, max) = column_spread(v);
        ctx.total_field(name, median, Some((min, max)), &mut Vec::new())?;
        ctx.within_field(name, max)?;
        ctx.readings(name, median, min)?;
    }
    let components = flux.map(column);
    for (name, v) in components.iter().flatten() {
        let max = max_abs(v);
        ctx.component(name, (max, sampled_median(v.len(), |i| v[i].abs())))?;
        ctx.within_field(name, max)?;
    }
    if let [Some((x_name, x)), Some((y_name, y)), Some((z_name, z))] = components {
        let norm = sampled_median(x.len(), |i| {
            (x[i] * x[i] + y[i] * y[i] + z[i] * z[i]).sqrt()
        });
        ctx.total_field(
            &format!("{x_name}/{y_name}/{z_name}"),
            norm,
            None,
            &mut Vec::new(),
        )?;
    }
    Ok(())
}

/// Multiplies the magnetic columns present (`mag`, `flux_*`, `diurnal`,
/// `igrf`) by 1e9, converting tesla to nT. Returns the
/// names converted.
pub fn convert_tesla_to_nt(table: &mut FlightTable) -> Vec<String> {
    MAGNETIC_COLUMNS
        .iter()
        .filter(|n| table.scale_column(n, 1e9))
        .map(|n| n.to_string())
        .collect()
}

/// The medians and maxima the rules of [`check_units`] test, each a pass
/// over a flight-long column (or [`MEDIAN_SAMPLES`] of its rows), worked
/// out side by side on the cores before the rules are tested in their
/// order (the same values, errors and warnings as one after the other;
/// 12.5 → 8.3–9.5 ms for both checks of a 10⁶-row flight).
struct Stats {
    /// Median |value| of `mag` and of `igrf`.
    mag: Option<f64>,
    igrf: Option<f64>,
    /// Maximum |value| of `mag` and of `igrf`.
    mag_max: Option<f64>,
    /// Smallest value of `mag`.
    mag_min: Option<f64>,
    igrf_max: Option<f64>,
    /// Maximum and median |value| of `flux_x`, `flux_y`, `flux_z`, `diurnal`.
    components: [(Option<f64>, Option<f64>); 4],
    /// With all three flux components: the median vector magnitude, and
    /// the median relative difference from `mag` (with `mag`).
    vector: Option<(Option<f64>, Option<f64>)>,
    /// Median `alt`.
    alt: Option<f64>,
}

impl Stats {
    fn of(table: &FlightTable) -> Self {
        type Job<'a> = Box<dyn Fn() -> Option<f64> + Sync + 'a>;
        let median_abs = |v: &'static str| -> Option<Job<'_>> {
            let v = table.column(v)?;
            Some(Box::new(move || sampled_median(v.len(), |i| v[i].abs())))
        };
        let flux: Option<[&[f64]; 3]> =
            match ["flux_x", "flux_y", "flux_z"].map(|n| table.column(n)) {
                [Some(x), Some(y), Some(z)] => Some([x, y, z]),
                _ => None,
            };
        let norm = move |[x, y, z]: [&[f64]; 3], i: usize| {
            (x[i] * x[i] + y[i] * y[i] + z[i] * z[i]).sqrt()
        };
        let mut jobs: Vec<Option<Job<'_>>> = vec![median_abs("mag"), median_abs("igrf")];
        for name in ["flux_x", "flux_y", "flux_z", "diurnal"] {
            let max: Option<Job<'_>> = table
                .column(name)
                .map(|v| Box::new(move || max_abs(v)) as Job<'_>);
            jobs.extend([max, median_abs(name)]);
        }
        jobs.push(
            flux.map(|f| {
                Box::new(move || sampled_median(table.n_rows(), |i| norm(f, i))) as Job<'_>
            }),
        );
        jobs.push(flux.zip(table.column("mag")).map(|(f, mag)| {
            Box::new(move || sampled_median(table.n_rows(), |i| (norm(f, i) - mag[i]) / mag[i]))
                as Job<'_>
        }));
        jobs.push(
            table
                .column("alt")
                .map(|alt| Box::new(move || sampled_median(alt.len(), |i| alt[i])) as Job<'_>),
        );
        for name in ["mag", "igrf"] {
            jobs.push(
                table
                    .column(name)
                    .map(|v| Box::new(move || max_abs(v)) as Job<'_>),
            );
        }
        jobs.push(
            table
                .column("mag")
                .map(|v| Box::new(move || min_value(v)) as Job<'_>),
        );
        let v = crate::parts::each_on_cores(&jobs, |job| job.as_ref().and_then(|f| f()));
        Self {
            mag: v[0],
            igrf: v[1],
            components: [(v[2], v[3]), (v[4], v[5]), (v[6], v[7]), (v[8], v[9])],
            vector: flux.map(|_| (v[10], v[11])),
            alt: v[12],
            mag_max: v[13],
            igrf_max: v[14],
            mag_min: v[15],
        }
    }
}

/// Whether a column of median |value| `m` reads as Earth's total field in
/// microtesla: `m` within [`EARTH_FIELD_UT`] and, when `range` gives the
/// column's smallest and largest value (a column that may be an anomaly),
/// every value within half and twice `m`. A total field varies by a few
/// per cent; an anomaly of this median would be all of one sign and
/// within a factor of 2 of it.
pub fn reads_as_microtesla(m: f64, range: Option<(Option<f64>, Option<f64>)>) -> bool {
    let total = range.is_none_or(|(lo, hi)| {
        lo.is_some_and(|lo| lo >= m / 2.0) && hi.is_some_and(|hi| hi <= 2.0 * m)
    });
    (EARTH_FIELD_UT.0..=EARTH_FIELD_UT.1).contains(&m) && total
}

/// The median |value|, smallest value and largest |value| of a column
/// (finite values), as the unit checks use them.
pub fn column_spread(v: &[f64]) -> (Option<f64>, Option<f64>, Option<f64>) {
    (
        sampled_median(v.len(), |i| v[i].abs()),
        min_value(v),
        max_abs(v),
    )
}

struct Ctx<'a> {
    table: &'a FlightTable,
}

impl Ctx<'_> {
    fn units(&self, column: &str, message: String) -> IoError {
        IoError::Units {
            file: self.table.file_label(),
            column: column.to_string(),
            message,
        }
    }

    fn warn(
        &self,
        kind: WarningKind,
        column: &str,
        row: Option<usize>,
        message: String,
    ) -> Warning {
        Warning {
            kind,
            file: self.table.file_label(),
            column: Some(column.to_string()),
            row: row.map(|r| self.table.file_row(r)),
            line: row.and_then(|r| self.table.line_of_row(r)),
            message,
        }
    }

    /// A total-field magnitude (nT): errors for tesla/gauss/pT-like medians, warning outside Earth's range.
    /// `range`: the column's smallest and largest value when it could be
    /// an anomaly rather than a total field (`mag`), `None` for a column
    /// that is a total field whatever its values (`igrf`, the vector
    /// magnitude).
    fn total_field(
        &self,
        name: &str,
        median_abs: Option<f64>,
        range: Option<(Option<f64>, Option<f64>)>,
        w: &mut Vec<Warning>,
    ) -> Result<()> {
        let Some(m) = median_abs else { return Ok(()) };
        let fix = "expected nT";
        if reads_as_microtesla(m, range) {
            return Err(self.units(
                name,
                format!("median |value| = {} looks like microtesla (Earth's field is 22 to 67 µT), {fix} (multiply by 1000)", shown(m)),
            ));
        }
        if m < 1.0 {
            let guess = if (1e-6..1e-3).contains(&m) {
                format!(
                    "looks like tesla (Earth's field is 2e-5 to 7e-5 T), {fix} (multiply by 1e9)"
                )
            } else if (0.05..1.0).contains(&m) {
                format!("looks like gauss (Earth's field is 0.2 to 0.7 G), {fix} (multiply by 1e5)")
            } else {
                format!("is far below Earth's field (22 000 to 67 000 nT): wrong units? {fix}")
            };
            return Err(self.units(name, format!("median |value| = {m:e}: {guess}")));
        }
        if m > 1e6 {
            return Err(self.units(
                name,
                format!("median |value| = {m:e} is far above Earth's field in nT (22 000 to 67 000 nT): picotesla? {fix} (divide by 1000)"),
            ));
        }
        let (lo, hi) = EARTH_FIELD_NT;
        if !(lo..=hi).contains(&m) {
            w.push(self.warn(
                WarningKind::FieldRange,
                name,
                None,
                format!("median |value| = {} nT is outside Earth's total field (22 000 to 67 000 nT): anomaly or corrected data, or other units?", shown(m)),
            ));
        }
        Ok(())
    }

    /// One field component (nT), which may be small: tested by its maximum
    /// (then its median), `c` ([`Stats::components`]).
    fn component(&self, name: &str, c: (Option<f64>, Option<f64>)) -> Result<()> {
        let (Some(max), median) = c else {
            return Ok(());
        };
        if max > 0.0 && max < 1e-3 {
            return Err(self.units(
                name,
                format!("all values are below 1e-3 in magnitude (max |value| = {max:e}): looks like tesla, expected nT (multiply by 1e9)"),
            ));
        }
        if let Some(m) = median
            && m > 1e6
        {
            return Err(self.units(
                    name,
                    format!("median |value| = {m:e} is far too large for nT: picotesla? expected nT (divide by 1000)"),
                ));
        }
        Ok(())
    }

    /// A total-field reading (a column whose median `median_abs` is at
    /// least [`EARTH_FIELD_NT`]'s lower end) has no value below [`MIN_READING_NT`] (`min`:
    /// its smallest), or bad input naming the first row that has one: a
    /// dropout value (0, −99999), a negated reading. A column of an anomaly
    /// or another unit is not tested (its median is warned about).
    fn readings(&self, name: &str, median_abs: Option<f64>, min: Option<f64>) -> Result<()> {
        let total_field = median_abs.is_some_and(|m| m >= EARTH_FIELD_NT.0);
        if !total_field || min.is_none_or(|m| m >= MIN_READING_NT) {
            return Ok(());
        }
        let Some((i, v)) = self
            .table
            .column(name)
            .and_then(|c| first_where(c, |v| v < MIN_READING_NT))
        else {
            return Ok(());
        };
        let what = if v < 0.0 {
            "a total field is never negative: a negated column, or a number standing for a missing value?"
        } else {
            "a dropout value, or a number standing for a missing value?"
        };
        Err(self.units(
            name,
            format!(
                "{} nT at {} is no reading of Earth's total field (at least {} nT; the column's median is {:.0} nT): {what} leave the cell empty (`*` in an XYZ file) for a missing value",
                shown(v),
                data_row(self.table, i),
                shown(MIN_READING_NT),
                median_abs.unwrap_or(f64::NAN)
            ),
        ))
    }

    /// No `|value|` of `name` above [`MAX_FIELD_NT`] (`max`: its largest),
    /// or bad input naming the first row that has one.
    fn within_field(&self, name: &str, max: Option<f64>) -> Result<()> {
        if max.is_none_or(|m| m <= MAX_FIELD_NT) {
            return Ok(());
        }
        let Some((i, v)) = self
            .table
            .column(name)
            .and_then(|c| first_where(c, |v| v.abs() > MAX_FIELD_NT))
        else {
            return Ok(());
        };
        Err(self.units(
            name,
            format!(
                "{v:e} at {} is no magnetic field reading in nT (at most {MAX_FIELD_NT:e} nT in magnitude): a corrupted cell, or a number standing for a missing value? leave the cell empty (`*` in an XYZ file) for a missing value",
                data_row(self.table, i)
            ),
        ))
    }

    /// The [`WarningKind::TimeUnit`] rule: the median ground speed between
    /// consecutive rows ([`MEDIAN_SAMPLES`] pairs at most; equirectangular
    /// distance on a 6 371 km sphere, degrees) above
    /// [`MAX_MEDIAN_GROUND_SPEED_M_S`], or below [`MIN_MOVING_SPEED_M_S`]
    /// while the median distance between rows is at least
    /// [`MIN_MOVING_STEP_M`] (time in milliseconds).
    fn ground_speed(&self, lat: &[f64], lon: &[f64], w: &mut Vec<Warning>) {
        let Some(t) = self.table.column("time") else {
            return;
        };
        let step = |i: usize| t[i + 1] - t[i];
        let distance = |i: usize| step_distance_m([lat[i], lon[i]], [lat[i + 1], lon[i + 1]]);
        // Over steps forward in time only (NaN is left out of a median).
        let forward = |i: usize, v: f64| if step(i) > 0.0 { v } else { f64::NAN };
        let speed = |i: usize| forward(i, distance(i) / step(i));
        let moved = |i: usize| forward(i, distance(i));
        let pairs = t.len().saturating_sub(1);
        let Some(v) = sampled_median(pairs, speed) else {
            return;
        };
        if v < MIN_MOVING_SPEED_M_S
            && let (Some(d), Some(dt)) = (sampled_median(pairs, moved), sampled_median(pairs, step))
            && d >= MIN_MOVING_STEP_M
        {
            w.push(self.warn(
                WarningKind::TimeUnit,
                "time",
                None,
                format!(
                    "the platform moves a median {} m from row to row but a row comes every {} s \
                     ({} m/s): time in milliseconds? expected seconds",
                    shown((d * 10.0).round() / 10.0),
                    shown(dt),
                    shown((v * 1000.0).round() / 1000.0)
                ),
            ));
        }
        if v > MAX_MEDIAN_GROUND_SPEED_M_S {
            w.push(self.warn(
                WarningKind::TimeUnit,
                "time",
                None,
                format!(
                    "the median ground speed is {} m/s, more than any aircraft flies \
                     ({} m/s): time in minutes or hours? expected seconds",
                    shown(v.round()),
                    shown(MAX_MEDIAN_GROUND_SPEED_M_S)
                ),
            ));
        }
    }

    /// No infinite value in a column of [`FINITE_COLUMNS`] (`inf` is a
    /// number to the cell parser, but no position, height, field, attitude
    /// or line number): bad input naming the first row that has one.
    fn no_infinity(&self) -> Result<()> {
        let columns: Vec<(&str, &[f64])> = FINITE_COLUMNS
            .iter()
            .filter_map(|&n| Some((n, self.table.column(n)?)))
            .collect();
        let any = crate::parts::each_on_cores(&columns, |(_, v)| {
            crate::parts::on_parts(v, |p| p.iter().fold(false, |a, x| a | x.is_infinite()))
                .contains(&true)
        });
        let Some((name, v)) = columns.iter().zip(any).find_map(|(c, a)| a.then_some(c)) else {
            return Ok(());
        };
        let Some(i) = v.iter().position(|x| x.is_infinite()) else {
            return Ok(());
        };
        Err(self.units(
            name,
            format!(
                "{} at {} is no number this column can hold: a corrupted cell? leave the cell empty (`*` in an XYZ file) for a missing value",
                v[i],
                data_row(self.table, i)
            ),
        ))
    }

    /// The column a message about canonical `name` names, and what it adds:
    /// the file's field a derived `lat`/`lon` comes from (`INS_LAT`, not a
    /// `lat` the file does not have), with the unit it was read in.
    fn source_of(&self, name: &str) -> (String, String) {
        match self.table.derived().iter().find(|d| d.canonical == name) {
            Some(d) => (
                d.from.clone(),
                format!(
                    " (read as {name}, {})",
                    match d.conversion {
                        Conversion::RadiansToDegrees => "radians converted to degrees",
                        _ => "degrees as recorded",
                    }
                ),
            ),
            None => (name.to_string(), String::new()),
        }
    }

    fn position(&self, w: &mut Vec<Warning>) -> Result<()> {
        let lat = self.table.column("lat");
        let lon = self.table.column("lon");
        if let Some(d) = self
            .table
            .derived()
            .iter()
            .find(|d| d.conversion == Conversion::DegreesAsRecorded)
            && let Some((_, evidence)) = crate::derive::ins_position_unit(self.table)
        {
            let taken: Vec<String> = self
                .table
                .derived()
                .iter()
                .filter(|d| d.conversion == Conversion::DegreesAsRecorded)
                .map(|d| format!("{} = {}", d.canonical, d.from))
                .collect();
            w.push(self.warn(
                WarningKind::InsDegrees,
                &d.from,
                None,
                format!(
                    "taken as degrees, not radians as the SGL layout records it: {evidence} is beyond ±π/2 (latitude) or ±π (longitude), which no position in radians reaches (MagNav's XYZ0 layout records degrees); {} as recorded",
                    taken.join(", ")
                ),
            ));
        }
        if let Some(lat) = lat
            && let Some((i, v)) = first_where(lat, |v| v.abs() > 90.0)
        {
            let (column, read) = self.source_of("lat");
            return Err(self.units(
                    &column,
                    format!("latitude {}{read} at {} is outside ±90°: lat/lon swapped, or projected coordinates? expected degrees", shown(v), data_row(self.table, i)),
                ));
        }
        if let Some(lon) = lon
            && let Some((i, v)) = first_where(lon, |v| v.abs() > 360.0)
        {
            let (column, read) = self.source_of("lon");
            return Err(self.units(
                &column,
                format!(
                    "longitude {}{read} at {} is outside ±360°: projected coordinates? expected degrees",
                    shown(v),
                    data_row(self.table, i)
                ),
            ));
        }
        if let (Some(lat), Some(lon)) = (lat, lon) {
            self.ground_speed(lat, lon, w);
            let (Some(a), Some(o)) = (max_abs(lat), max_abs(lon)) else {
                return Ok(());
            };
            if a <= std::f64::consts::FRAC_PI_2 && o <= std::f64::consts::PI && (a > 0.0 || o > 0.0)
            {
                w.push(self.warn(
                    WarningKind::Radians,
                    "lat",
                    None,
                    format!(
                        "all |lat| ≤ π/2 and |lon| ≤ π (max {a}, {o}): radians? expected degrees"
                    ),
                ));
            }
        }
        Ok(())
    }

    fn attitude(&self, w: &mut Vec<Warning>) -> Result<()> {
        let t = self.table;
        for (name, limit) in [("roll", 180.0), ("pitch", 90.0)] {
            if let Some(v) = t.column(name)
                && let Some((i, x)) = first_where(v, |x| x.abs() > limit)
            {
                return Err(self.units(
                    name,
                    format!(
                        "{name} {} at {} is outside ±{limit}°: expected degrees",
                        shown(x),
                        data_row(t, i)
                    ),
                ));
            }
        }
        if let Some(yaw) = t.column("yaw")
            && let Some((i, x)) = first_where(yaw, |x| x.abs() > 360.0)
        {
            w.push(self.warn(
                WarningKind::YawRange,
                "yaw",
                Some(i),
                format!("yaw {} is outside ±360°: expected degrees", shown(x)),
            ));
        }
        let (Some(roll), Some(pitch), Some(yaw)) =
            (t.column("roll"), t.column("pitch"), t.column("yaw"))
        else {
            return Ok(());
        };
        use std::f64::consts::{FRAC_PI_2, PI};
        let (Some(r), Some(p)) = (max_abs(roll), max_abs(pitch)) else {
            return Ok(());
        };
        let finite = || yaw.iter().copied().filter(|x| x.is_finite());
        let (lo, hi) = finite().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
            (lo.min(x), hi.max(x))
        });
        let eps = 1e-9;
        if r <= FRAC_PI_2
            && p <= FRAC_PI_2
            && lo >= -PI - eps
            && hi <= 2.0 * PI + eps
            && hi - lo > PI
        {
            w.push(self.warn(
                WarningKind::Radians,
                "yaw",
                None,
                format!(
                    "attitude looks like radians: yaw spans {lo}..{hi} (more than π) while |roll| ≤ {r} and |pitch| ≤ {p}; expected degrees"
                ),
            ));
        }
        Ok(())
    }
}

/// "data row R (line L)" for a row of a table: the file's data row, and
/// its line when the table was read from a text file.
fn data_row(table: &FlightTable, row: usize) -> String {
    let line = table
        .line_of_row(row)
        .map(|l| format!(" (line {l})"))
        .unwrap_or_default();
    format!("data row {}{line}", table.file_row(row) + 1)
}

fn first_where(v: &[f64], pred: impl Fn(f64) -> bool) -> Option<(usize, f64)> {
    v.iter()
        .copied()
        .enumerate()
        .find(|(_, x)| x.is_finite() && pred(*x))
}

/// The largest finite `|value|` of `v` (`None` when there is none); a
/// long column in parts on the cores ([`crate::parts`]), the parts'
/// maxima then compared: the same value either way.
fn max_abs(v: &[f64]) -> Option<f64> {
    max_key(v, f64::abs)
}

/// The smallest finite value of `v` (`None` when there is none), as
/// [`max_abs`].
fn min_value(v: &[f64]) -> Option<f64> {
    max_key(v, |x| -x).map(|m| -m)
}

/// The largest `key(x)` over the finite values `x` of `v`, in parts on the
/// cores.
fn max_key(v: &[f64], key: impl Fn(f64) -> f64 + Sync + Copy) -> Option<f64> {
    crate::parts::on_parts(v, |part| max_key_serial(part, key))
        .into_iter()
        .flatten()
        .reduce(f64::max)
}

/// [`max_key`] in one pass on the calling thread.
#[inline(always)]
fn max_key_serial(v: &[f64], key: impl Fn(f64) -> f64) -> Option<f64> {
    // Four independent running maxima with selects (no NaN-aware `max`,
    // no branch), so the pass over a long column vectorises; a non-finite
    // value counts as −∞, below every finite key.
    let lane = |x: f64| {
        if x.is_finite() {
            key(x)
        } else {
            f64::NEG_INFINITY
        }
    };
    let pick = |m: f64, a: f64| if a > m { a } else { m };
    let mut m = [f64::NEG_INFINITY; 4];
    let chunks = v.chunks_exact(4);
    let rest = chunks.remainder();
    for c in chunks {
        for l in 0..4 {
            m[l] = pick(m[l], lane(c[l]));
        }
    }
    let max = rest
        .iter()
        .fold(m.into_iter().fold(f64::NEG_INFINITY, pick), |m, &x| {
            pick(m, lane(x))
        });
    (max > f64::NEG_INFINITY).then_some(max)
}

/// Median of the finite values among at most [`MEDIAN_SAMPLES`] evenly
/// strided samples `value(0), value(s), value(2s), …` of `n` rows; `None`
/// when there is none. Only the sampled rows are evaluated (a 10⁷-row
/// column is neither copied nor passed over whole).
pub fn sampled_median(n: usize, value: impl Fn(usize) -> f64) -> Option<f64> {
    let stride = n.div_ceil(MEDIAN_SAMPLES).max(1);
    let mut v: Vec<f64> = (0..n)
        .step_by(stride)
        .map(value)
        .filter(|x| x.is_finite())
        .collect();
    median_in_place(&mut v)
}

pub use aeromag_core::median::median_in_place;

#[cfg(test)]
mod tests {
    use super::*;

    /// An INS position in degrees is taken as degrees with a named
    /// warning; a bad one names the file's field (`ins_lat`), not a `lat`
    /// the file does not have; radians raise nothing.
    #[test]
    fn ins_positions_name_their_unit_and_their_field() {
        let checked = |lat: f64, lon: f64| {
            let mut t = FlightTable::new();
            t.set_source("f.csv");
            t.add_column("ins_lat", vec![lat, lat]).unwrap();
            t.add_column("ins_lon", vec![lon, lon]).unwrap();
            crate::derive_columns(&mut t).unwrap();
            check_units(&t)
        };
        let w = checked(39.1607, -95.5207).unwrap();
        assert_eq!(w.len(), 1, "{w:?}");
        assert_eq!(w[0].kind, WarningKind::InsDegrees);
        let s = w[0].to_string();
        assert!(
            s.contains("column 'ins_lat'")
                && s.contains("ins_lat = 39.1607 is beyond ±π/2")
                && s.contains("lat = ins_lat, lon = ins_lon as recorded")
                && s.ends_with("[ins-degrees]"),
            "{s}"
        );
        assert!(checked(0.6835, -1.6672).unwrap().is_empty());
        let e = checked(2243.74, -95.5).unwrap_err().to_string();
        assert!(
            e.contains("column 'ins_lat': latitude 2243.74 (read as lat, degrees as recorded)"),
            "{e}"
        );
    }

    /// A time from −10³⁰⁸ to 10³⁰⁸ s gave `inspect` an infinite duration
    /// with exit 0, and Unix time in milliseconds a flight sampled a
    /// thousand times too slowly: times beyond ±10¹¹ s are refused,
    /// naming the row; Unix time in seconds passes.
    /// A second sensor's scalar and vector columns are checked as `mag`
    /// and `flux_x/y/z` are (µT, T and pT were fitted with exit 0), in
    /// either naming; nT passes.
    #[test]
    fn another_sensors_columns_have_the_unit_checks_of_mag_and_flux() {
        let n = 200;
        let wobble = |base: f64, k: usize| base * (1.0 + 1e-4 * (k as f64).sin());
        let table = |scale: f64, flux_scale: f64| {
            let mut t = FlightTable::new();
            t.add_column(
                "UNCOMPMAG4",
                (0..n).map(|k| wobble(52_000.0, k) * scale).collect(),
            )
            .unwrap();
            for (c, v) in [
                ("flux_d_x", 20_000.0),
                ("flux_d_y", 3_000.0),
                ("flux_d_z", 48_000.0),
            ] {
                t.add_column(c, (0..n).map(|k| wobble(v, k) * flux_scale).collect())
                    .unwrap();
            }
            t
        };
        let flux = ["flux_d_x", "flux_d_y", "flux_d_z"];
        assert!(check_sensor_units(&table(1.0, 1.0), "mag_4_uc", flux).is_ok());
        for (scale, flux_scale, column, says) in [
            (1e-3, 1.0, "UNCOMPMAG4", "microtesla"),
            (1e-9, 1.0, "UNCOMPMAG4", "tesla"),
            (1e3, 1.0, "UNCOMPMAG4", "picotesla"),
            (1.0, 1e-9, "flux_d_x", "tesla"),
            (1.0, 1e3, "flux_d_x", "picotesla"),
        ] {
            let e = check_sensor_units(&table(scale, flux_scale), "mag_4_uc", flux).unwrap_err();
            let text = e.to_string();
            assert!(text.contains(column) && text.contains(says), "{text}");
        }
    }

    #[test]
    fn times_beyond_any_clock_in_seconds_are_refused() {
        let check = |t: Vec<f64>| {
            let mut table = FlightTable::new();
            table.add_column("time", t).unwrap();
            check_time(&table)
        };
        assert!(check(vec![1.764e9, 1.764e9 + 0.1]).is_ok());
        assert!(check(vec![-1e11, 1e11]).is_ok());
        for (t, row, needle) in [
            (
                vec![0.0, f64::INFINITY, 1.0],
                "data row 2",
                "time inf at data row 2 is no time",
            ),
            (
                vec![0.0, 1.0, f64::INFINITY],
                "data row 3",
                "time inf at data row 3 is no time",
            ),
        ] {
            let e = check(t).unwrap_err();
            assert!(
                e.is_bad_input() && e.to_string().contains(needle),
                "{e} ({row})"
            );
        }
        for (t, row, shown) in [
            (vec![-1e308, 1e308], "data row 1", "-1e308"),
            (
                vec![1.764e12, 1.764e12 + 100.0],
                "data row 1",
                "1764000000000",
            ),
            (vec![0.0, 0.1, 2e11], "data row 3", "200000000000"),
        ] {
            let e = check(t).unwrap_err();
            let msg = e.to_string();
            assert!(e.is_bad_input(), "{msg}");
            assert!(
                msg.contains(&format!("time {shown} s at {row}")) && msg.contains("milliseconds"),
                "{msg}"
            );
        }
    }

    /// The block-wise check finds the error that a row-by-row pass over
    /// the whole column finds (the first one), wherever it falls against
    /// the blocks, for a missing time, a repeat and a step back.
    #[test]
    fn time_errors_are_the_row_by_row_first_across_blocks() {
        let n = 3 * TIME_BLOCK + 7;
        let good: Vec<f64> = (0..n).map(|i| i as f64 * 0.1).collect();
        let mut places = vec![0, 1, 2, n - 1];
        for k in 1..=3 {
            places.extend([k * TIME_BLOCK - 1, k * TIME_BLOCK, k * TIME_BLOCK + 1]);
        }
        let run = |t: Vec<f64>| {
            let mut table = FlightTable::new();
            table.add_column("time", t.clone()).unwrap();
            let blocks = check_time(&table).map_err(|e| e.to_string());
            let rows = first_time_error(&table, &t, 0..t.len()).map_err(|e| e.to_string());
            (blocks, rows)
        };
        let (ok, _) = run(good.clone());
        assert!(ok.is_ok());
        for &i in &places {
            for fault in 0..3 {
                let mut t = good.clone();
                match fault {
                    0 => t[i] = f64::NAN,
                    1 if i > 0 => t[i] = t[i - 1],
                    2 if i > 0 => t[i] = t[i - 1] - 1.0,
                    _ => t[i] = f64::NAN,
                }
                // A second fault later: only the first is reported.
                t[n - 1] = if i == n - 1 { t[n - 1] } else { 0.0 };
                let (blocks, rows) = run(t);
                assert!(blocks.is_err(), "fault {fault} at {i}");
                assert_eq!(blocks, rows, "fault {fault} at {i}");
            }
        }
        let (one, _) = run(vec![f64::NAN]);
        assert!(one.is_err());
        let (empty, _) = run(Vec::new());
        assert!(empty.is_ok());
    }

    proptest::proptest! {
        /// The vectorised maximum is the plain one over the finite values.
        #[test]
        fn max_abs_is_the_largest_finite_magnitude(
            v in proptest::collection::vec(
                proptest::prop_oneof![
                    -1e9f64..1e9,
                    proptest::strategy::Just(f64::NAN),
                    proptest::strategy::Just(f64::INFINITY),
                    proptest::strategy::Just(f64::NEG_INFINITY),
                ],
                0..23,
            )
        ) {
            let plain = v
                .iter()
                .filter(|x| x.is_finite())
                .map(|x| x.abs())
                .fold(None, |m: Option<f64>, x| Some(m.map_or(x, |m| m.max(x))));
            proptest::prop_assert_eq!(max_abs(&v), plain);
        }
    }

    /// A long column's maximum, found in parts on the cores, is the one
    /// pass's, wherever the largest value falls against the parts.
    #[test]
    fn max_abs_of_a_long_column_is_the_one_pass_maximum() {
        let n = 3 * (1 << 20) + 5;
        let base: Vec<f64> = (0..n)
            .map(|k| {
                if k % 97 == 0 {
                    f64::NAN
                } else {
                    ((k * 7919) % 1000) as f64 - 500.0
                }
            })
            .collect();
        for at in [0, 1 << 20, (1 << 20) + 1, n / 2, n - 1] {
            let mut v = base.clone();
            v[at] = -1e6;
            v[(at + 1) % n] = f64::INFINITY;
            assert_eq!(max_abs(&v), Some(1e6));
            assert_eq!(max_abs(&v), max_key_serial(&v, f64::abs));
            assert_eq!(min_value(&v), Some(-1e6));
            v[at] = 1e6;
            assert_eq!(min_value(&v), Some(-500.0));
        }
        assert_eq!(max_abs(&vec![f64::NAN; n]), None);
        assert_eq!(min_value(&vec![f64::NAN; n]), None);
    }

    #[test]
    fn sampled_median_skips_what_is_not_finite() {
        assert_eq!(
            sampled_median(3, |i| [f64::NAN, 5.0, f64::INFINITY][i]),
            Some(5.0)
        );
    }

    #[test]
    fn warning_display_names_everything() {
        let w = Warning {
            kind: WarningKind::YawRange,
            file: "f.csv".into(),
            column: Some("yaw".into()),
            row: Some(4),
            line: Some(7),
            message: "odd".into(),
        };
        assert_eq!(
            w.to_string(),
            "'f.csv': column 'yaw' at data row 5 (line 7): odd [yaw-range]"
        );
    }
}
