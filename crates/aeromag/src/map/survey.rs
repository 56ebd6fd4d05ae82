//! A flight's lines in projected coordinates.
//!
//! Latitude and longitude (degrees, WGS 84) are projected to UTM in the
//! zone of the data (the zone of the median longitude, the hemisphere of
//! the median latitude; [`UtmZone::for_points`]) or in a zone given. Each
//! line's direction is the principal axis of its points; the survey
//! direction is the length-weighted circular mean of those axes (angles
//! doubled, as axes have no sense), and lines within 30° of it are the
//! traverse lines (the others, tie lines or turns, do not count for the
//! spacing). The line spacing is the median gap between successive
//! traverse lines across the survey direction, gaps below a tenth of the
//! median (re-flown parts such as 1003.01 beside 1003) left out.
//!
//! A flight whose positions are already projected (a Geosoft XYZ's `X` and
//! `Y`, eastings and northings in metres, without latitude and longitude)
//! is taken as it is ([`ProjectedColumns`], [`ProjectedSurvey::of_columns`]):
//! its coordinate system is the UTM zone given, or none.
//!
//! Rows whose position jumps off the track faster than anything flies
//! ([`position_glitches`]; a GPS dropout written as 0) are not projected:
//! their easting and northing are NaN, as for a missing position, and
//! [`ProjectedSurvey::off_track`] lists them.

use crate::error::{Error, Result};
use crate::flight::Flight;
use crate::flight::{LineLabels, position_glitches, sensor_track};
use aeromag_core::error::shown;
use aeromag_grid::projection::{Utm, UtmZone};

/// A flight's rows in UTM (m) and its lines' geometry.
#[derive(Debug, Clone)]
pub struct ProjectedSurvey {
    /// The UTM zone; `None` for projected columns of a coordinate system
    /// not given ([`ProjectedSurvey::of_columns`]).
    pub zone: Option<UtmZone>,
    /// The flight's columns the positions come from: `lat` and `lon`, or
    /// the projected columns.
    pub position_columns: [String; 2],
    /// Easting of every row, m (NaN where latitude or longitude is missing).
    pub x: Vec<f64>,
    /// Northing of every row, m.
    pub y: Vec<f64>,
    /// Rows (0-based, ascending) whose position is off the track
    /// ([`position_glitches`]; needs a `time` column): not projected.
    pub off_track: Vec<usize>,
    /// Per row the id of its line (0: on no line), when the flight has a
    /// `line` column.
    pub line_ids: Option<Vec<f64>>,
    /// The warning for rows without a line label
    /// ([`LineLabels::missing_warning`]).
    pub missing_labels: Option<String>,
    /// The lines' geometry, when there are lines.
    pub lines: Option<LineGeometry>,
}

/// The columns of a flight's projected positions: easting and northing, m.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ProjectedColumns {
    /// The easting column (`X` of a Geosoft XYZ file).
    pub easting: String,
    /// The northing column.
    pub northing: String,
}

/// The column pairs [`ProjectedColumns::found_in`] takes, in this order,
/// in any case.
pub const PROJECTED_NAMES: [[&str; 2]; 5] = [
    ["x", "y"],
    ["easting", "northing"],
    ["utm_x", "utm_y"],
    ["utm-x", "utm-y"],
    ["utm_easting", "utm_northing"],
];

impl ProjectedColumns {
    /// The columns `easting` and `northing`.
    pub fn new(easting: impl Into<String>, northing: impl Into<String>) -> Self {
        Self {
            easting: easting.into(),
            northing: northing.into(),
        }
    }

    /// The columns a command takes its positions from: `given`, else those
    /// of a flight without latitude and longitude ([`Self::found_in`]),
    /// with a note of where they come from for `notes`; `None`: latitude
    /// and longitude. A lever arm is refused with projected columns: it
    /// moves the positions by the attitude on the Earth.
    pub(crate) fn chosen(
        flight: &Flight,
        given: Option<&Self>,
        lever_arm: bool,
        notes: &mut crate::observer::Notes,
    ) -> Result<Option<Self>> {
        let columns = match given {
            Some(c) => c.clone(),
            None => match Self::found_in(flight, "--xy")? {
                Some(c) => {
                    notes.note(format!(
                        "positions from the projected columns {} (easting) and {} (northing), m: the file has no lat/lon (name others with --xy)",
                        c.easting, c.northing
                    ));
                    c
                }
                None => return Ok(None),
            },
        };
        if lever_arm {
            return Err(Error::bad_input(format!(
                "a lever arm moves the positions by the attitude on the Earth (lat, lon, alt, roll, pitch, yaw): it is not applied to the projected {} and {}; leave it out",
                columns.easting, columns.northing
            )));
        }
        Ok(Some(columns))
    }

    /// Latitudes and longitudes (degrees) of `flight`'s positions in these
    /// columns, UTM coordinates of `zone` (checked as
    /// [`ProjectedSurvey::of_columns`] checks them, rows off the track
    /// aside); missing where either is.
    pub fn geodetic(&self, flight: &Flight, zone: UtmZone) -> Result<(Vec<f64>, Vec<f64>)> {
        let ([x, y], _) = self.read(flight, Some(zone))?;
        let utm = Utm::new(zone);
        Ok(x.iter()
            .zip(y)
            .map(|(&e, &n)| match e.is_finite() && n.is_finite() {
                true => utm.inverse(e, n),
                false => (f64::NAN, f64::NAN),
            })
            .unzip())
    }

    /// The two columns of `flight` and its rows off the track
    /// ([`aeromag_io::projected_position_glitches`]; none without `time`),
    /// checked against `zone` when given ([`Self::check_in`]).
    fn read<'f>(
        &self,
        flight: &'f Flight,
        zone: Option<UtmZone>,
    ) -> Result<([&'f [f64]; 2], Vec<usize>)> {
        let (x, y) = (
            flight.require(&self.easting)?,
            flight.require(&self.northing)?,
        );
        let off_track = flight.column("time").map_or_else(Vec::new, |t| {
            aeromag_io::projected_position_glitches(t, x, y)
        });
        if let Some(z) = zone {
            self.check_in(flight, [x, y], z, &off_track)?;
        }
        Ok(([x, y], off_track))
    }

    /// Bad input naming the first row, not among `off_track` (ascending),
    /// whose easting or northing (`values` of these columns) is not one of
    /// `zone`'s: eastings within 100–900 km, where a zone's are, northings
    /// within 0–10 000 km. (A dropout written as 0, 0 is off the track.)
    fn check_in(
        &self,
        flight: &Flight,
        values: [&[f64]; 2],
        zone: UtmZone,
        off_track: &[usize],
    ) -> Result<()> {
        let names = [self.easting.as_str(), self.northing.as_str()];
        let what = ["easting", "northing"];
        let ranges = [(100_000.0, 900_000.0), (0.0, 10_000_000.0)];
        for k in 0..2 {
            let (v, (lo, hi)) = (values[k], ranges[k]);
            let outside = |r: usize| {
                v[r].is_finite()
                    && !(lo..=hi).contains(&v[r])
                    && off_track.binary_search(&r).is_err()
            };
            if let Some(r) = (0..v.len()).find(|&r| outside(r)) {
                return Err(flight.bad_value(
                    r,
                    flight.resolve(names[k]).unwrap_or(names[k]),
                    format!(
                        "{} m is not a UTM {} (a zone's are from {} to {} km): are these coordinates in {zone}, and in metres?",
                        shown(v[r]),
                        what[k],
                        lo / 1000.0,
                        hi / 1000.0
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The projected columns of a flight without latitude and longitude:
    /// the first pair of [`PROJECTED_NAMES`] it has, in any case (as the
    /// file spells them); `None` when it has latitude and longitude or no
    /// such pair. `flag` is the option naming them, for the error of two
    /// columns differing only in case.
    pub fn found_in(flight: &Flight, flag: &str) -> Result<Option<Self>> {
        if flight.column("lat").is_some() && flight.column("lon").is_some() {
            return Ok(None);
        }
        for [e, n] in PROJECTED_NAMES {
            let e = crate::flight::find_column(flight, e, flag)?;
            let n = crate::flight::find_column(flight, n, flag)?;
            if let (Some(e), Some(n)) = (e, n) {
                return Ok(Some(Self::new(e, n)));
            }
        }
        Ok(None)
    }
}

/// Direction and spacing of a survey's traverse lines ([`ProjectedSurvey`]).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LineGeometry {
    /// Direction of the traverse lines, degrees clockwise from grid north,
    /// 0–180.
    pub direction_deg: f64,
    /// Median spacing of the traverse lines, m.
    pub spacing_m: f64,
    /// Lines counted as traverse lines.
    pub traverse_lines: usize,
    /// Other lines (ties, turns).
    pub other_lines: usize,
    /// The ids ([`LineLabels`] ids) of the traverse lines, ascending (left
    /// out of the reports' JSON; empty when read back from it).
    #[serde(skip_serializing, default)]
    pub traverse_ids: Vec<i64>,
}

impl ProjectedSurvey {
    /// Project `flight`'s `lat`/`lon` (degrees) to UTM in `zone`, or in the
    /// zone of the data when `None`, and find its lines' geometry. With a
    /// lever arm (body frame, m, from the navigation point), the sensor's
    /// positions are projected instead (attitude and `alt` needed).
    pub fn of(
        flight: &Flight,
        zone: Option<UtmZone>,
        lever_arm_m: Option<[f64; 3]>,
    ) -> Result<Self> {
        let track = lever_arm_m
            .map(|arm| sensor_track(flight, arm))
            .transpose()?;
        let (lat, lon) = match &track {
            Some([la, lo, _]) => (la.as_slice(), lo.as_slice()),
            None => (flight.require("lat")?, flight.require("lon")?),
        };
        let off_track = flight
            .column("time")
            .map_or_else(Vec::new, |t| position_glitches(t, lat, lon));
        let on_track = |k: usize| off_track.binary_search(&k).is_err();
        let zone_given = zone.is_some();
        let zone = match zone {
            Some(z) => Ok(z),
            None if off_track.is_empty() => UtmZone::for_points(lat, lon),
            None => {
                let kept = |v: &[f64]| -> Vec<f64> {
                    (0..v.len())
                        .filter(|&k| on_track(k))
                        .map(|k| v[k])
                        .collect()
                };
                UtmZone::for_points(&kept(lat), &kept(lon))
            }
        }
        .map_err(|e| Error::bad_file(flight.label(), e.to_string()))?;
        let utm = Utm::new(zone);
        let (mut x, mut y) = (Vec::with_capacity(lat.len()), Vec::with_capacity(lat.len()));
        for (k, (&la, &lo)) in lat.iter().zip(lon).enumerate() {
            if !(la.is_finite() && lo.is_finite() && on_track(k)) {
                x.push(f64::NAN);
                y.push(f64::NAN);
                continue;
            }
            let (e, n) = utm.forward(la, lo).map_err(|e| {
                // Within UTM's latitudes the longitude is refused: far from
                // the zone, which a zone given by `--utm-zone` explains.
                use aeromag_grid::projection::utm::{FORWARD_LAT_MAX_DEG, FORWARD_LAT_MIN_DEG};
                let column = match (FORWARD_LAT_MIN_DEG..=FORWARD_LAT_MAX_DEG).contains(&la) {
                    true => "lon",
                    false => "lat",
                };
                let given = match (zone_given, column) {
                    (true, "lon") => " (the zone given with --utm-zone is not the data's: leave it out to take theirs)",
                    _ => "",
                };
                flight.bad_value(k, column, format!("{e}{given}"))
            })?;
            x.push(e);
            y.push(n);
        }
        Self::with_lines(
            flight,
            Some(zone),
            ["lat".into(), "lon".into()],
            (x, y),
            off_track,
        )
    }

    /// `flight`'s positions as they are in the columns `columns` (easting
    /// and northing, m), in the UTM zone `zone` when given (checked: the
    /// eastings within 100–900 km, where a zone's are, and the northings
    /// within 0–10 000 km), in a coordinate system not given otherwise;
    /// and its lines' geometry. Missing values are missing positions; rows off
    /// the track are found as for latitude and longitude
    /// ([`aeromag_io::projected_position_glitches`]).
    pub fn of_columns(
        flight: &Flight,
        columns: &ProjectedColumns,
        zone: Option<UtmZone>,
    ) -> Result<Self> {
        let names = [columns.easting.as_str(), columns.northing.as_str()];
        let ([x, y], off_track) = columns.read(flight, zone)?;
        let (mut x, mut y) = (x.to_vec(), y.to_vec());
        for &k in &off_track {
            x[k] = f64::NAN;
            y[k] = f64::NAN;
        }
        Self::with_lines(
            flight,
            zone,
            names.map(|c| flight.resolve(c).unwrap_or(c).to_string()),
            (x, y),
            off_track,
        )
    }

    /// The survey of positions `x`, `y` (m) from `position_columns`, with
    /// the lines of `flight`'s `line` column.
    fn with_lines(
        flight: &Flight,
        zone: Option<UtmZone>,
        position_columns: [String; 2],
        (x, y): (Vec<f64>, Vec<f64>),
        off_track: Vec<usize>,
    ) -> Result<Self> {
        let labels = flight
            .get("line")
            .map(|_| LineLabels::of(flight, &[]))
            .transpose()?;
        let missing_labels = labels.as_ref().and_then(|l| l.missing_warning(flight));
        let line_ids = labels.map(|l| l.ids);
        let lines = line_ids
            .as_deref()
            .and_then(|ids| LineGeometry::of(&x, &y, ids));
        Ok(Self {
            zone,
            position_columns,
            x,
            y,
            off_track,
            line_ids,
            missing_labels,
            lines,
        })
    }

    /// The warning for the rows off the track (`None` when there are
    /// none): how many, and the first few with their file rows, lines and
    /// positions, named `[position-glitch]`.
    pub fn off_track_warning(&self, flight: &Flight) -> Option<String> {
        let [a, b] = &self.position_columns;
        off_track_warning(flight, &self.off_track, [a, b])
    }

    /// Whether row `k` is survey data: on a line when there are lines
    /// (label ≠ 0), every row otherwise.
    pub fn on_line(&self, k: usize) -> bool {
        self.line_ids.as_ref().is_none_or(|ids| ids[k] != 0.0)
    }
}

/// The warning for the rows `off_track` (ascending, 0-based) of `flight`
/// whose position is off the track (`None` when there are none): how
/// many, and the first few with their file rows, lines and positions (the
/// columns `position`: `lat` and `lon`, or projected ones), named
/// `[position-glitch]`; `grid`, `microlevel` and `level` leave them out.
pub(crate) fn off_track_warning(
    flight: &Flight,
    off_track: &[usize],
    position: [&str; 2],
) -> Option<String> {
    const SHOWN: usize = 5;
    let n = off_track.len();
    if n == 0 {
        return None;
    }
    let [c0, c1] = position.map(|c| flight.column(c));
    let rows: Vec<String> = off_track[..n.min(SHOWN)]
        .iter()
        .map(|&k| {
            let line = flight
                .line_of_row(k)
                .map_or(String::new(), |l| format!(" (line {l})"));
            let at = |c: Option<&[f64]>| shown(c.map_or(f64::NAN, |c| c[k]));
            format!(
                "data row {}{line}: {} {}, {} {}",
                flight.file_row(k) + 1,
                position[0],
                at(c0),
                position[1],
                at(c1)
            )
        })
        .collect();
    let more = if n > SHOWN {
        format!(" and {} more", n - SHOWN)
    } else {
        String::new()
    };
    Some(format!(
        "{n} {} off the track (the position jumps away and back faster than {} m/s: a GPS dropout or a corrupted cell?) and {} left out: {}{more} [position-glitch]",
        if n == 1 { "row is" } else { "rows are" },
        crate::flight::MAX_GROUND_SPEED_M_S,
        if n == 1 { "is" } else { "are" },
        rows.join("; ")
    ))
}

impl LineGeometry {
    /// The geometry of the lines `ids` (per row, 0 = no line) through the
    /// points `x`, `y`; `None` with fewer than two traverse lines.
    pub fn of(x: &[f64], y: &[f64], ids: &[f64]) -> Option<Self> {
        // Per line: sums for the centroid and the 2 × 2 covariance.
        let mut acc: std::collections::BTreeMap<i64, [f64; 6]> = Default::default();
        for k in 0..ids.len() {
            if ids[k] == 0.0 || !(x[k].is_finite() && y[k].is_finite()) {
                continue;
            }
            let a = acc.entry(ids[k] as i64).or_default();
            a[0] += 1.0;
            a[1] += x[k];
            a[2] += y[k];
            a[3] += x[k] * x[k];
            a[4] += y[k] * y[k];
            a[5] += x[k] * y[k];
        }
        // (id, centroid, axis angle θ from east (rad), length ~ 2√(3λ₁)).
        let lines: Vec<(i64, [f64; 2], f64, f64)> = acc
            .iter()
            .filter(|(_, a)| a[0] >= 2.0)
            .map(|(&id, a)| {
                let n = a[0];
                let (mx, my) = (a[1] / n, a[2] / n);
                let sxx = a[3] / n - mx * mx;
                let syy = a[4] / n - my * my;
                let sxy = a[5] / n - mx * my;
                let theta = 0.5 * (2.0 * sxy).atan2(sxx - syy);
                let l1 = 0.5 * (sxx + syy) + (0.25 * (sxx - syy).powi(2) + sxy * sxy).sqrt();
                (id, [mx, my], theta, (12.0 * l1.max(0.0)).sqrt())
            })
            .collect();
        let (c, s) = lines.iter().fold((0.0, 0.0), |(c, s), l| {
            (c + l.3 * (2.0 * l.2).cos(), s + l.3 * (2.0 * l.2).sin())
        });
        let theta = 0.5 * s.atan2(c);
        let (ux, uy) = (theta.cos(), theta.sin());
        let (mut offsets, mut traverse_ids) = (Vec::new(), Vec::new());
        for l in &lines {
            if (l.2 - theta).cos().abs() >= 30f64.to_radians().cos() {
                offsets.push(-l.1[0] * uy + l.1[1] * ux);
                traverse_ids.push(l.0);
            }
        }
        if offsets.len() < 2 {
            return None;
        }
        offsets.sort_by(f64::total_cmp);
        let mut gaps: Vec<f64> = offsets.windows(2).map(|w| w[1] - w[0]).collect();
        gaps.sort_by(f64::total_cmp);
        let median = gaps[gaps.len() / 2];
        let mut wide: Vec<f64> = gaps.into_iter().filter(|&g| g >= 0.1 * median).collect();
        if wide.is_empty() {
            return None;
        }
        wide.sort_by(f64::total_cmp);
        let spacing = wide[wide.len() / 2];
        let direction = (90.0 - theta.to_degrees()).rem_euclid(180.0);
        (spacing > 0.0).then_some(Self {
            direction_deg: direction,
            spacing_m: spacing,
            traverse_lines: offsets.len(),
            other_lines: lines.len() - offsets.len(),
            traverse_ids,
        })
    }

    /// The default cell of a grid of these lines: a quarter of the line
    /// spacing, rounded down to 1, 2, 2.5 or 5 × 10ᵏ m (a spacing measured
    /// 2 % short of a round number, 499 m for 500, still gives 125 m).
    pub fn default_cell_m(&self) -> f64 {
        nice_below(self.spacing_m / 4.0 * 1.02)
    }
}

/// The largest of 1, 2, 2.5, 5 × 10ᵏ not above `v` (> 0).
pub fn nice_below(v: f64) -> f64 {
    let p = 10f64.powf(v.log10().floor());
    let m = v / p;
    let step = [5.0, 2.5, 2.0, 1.0]
        .into_iter()
        .find(|&s| m >= s - 1e-9)
        .unwrap_or(1.0);
    step * p
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each pair of [`PROJECTED_NAMES`] is found in any case (SGL's export
    /// writes `UTM-X`, `UTM-Y`), the first pair first, and none beside
    /// latitude and longitude; two columns differing only in case (and
    /// none exactly) are an error naming the flag.
    #[test]
    fn projected_columns_are_found_by_name_in_any_case() {
        let flight = |names: &[&str]| {
            let mut t = aeromag_io::FlightTable::new();
            for n in names {
                t.add_column(n, vec![1.0, 2.0, 3.0]).unwrap();
            }
            Flight::from_table(t).unwrap()
        };
        for [e, n] in PROJECTED_NAMES {
            let upper = [e.to_uppercase(), n.to_uppercase()];
            let f = flight(&["time", &upper[0], &upper[1]]);
            let found = ProjectedColumns::found_in(&f, "--xy").unwrap();
            assert_eq!(found, Some(ProjectedColumns::new(&upper[0], &upper[1])));
        }
        let f = flight(&["time", "UTM-X", "UTM-Y", "x", "y"]);
        let found = ProjectedColumns::found_in(&f, "--xy").unwrap().unwrap();
        assert_eq!(found.easting, "x");
        let f = flight(&["time", "lat", "lon", "x", "y"]);
        assert_eq!(ProjectedColumns::found_in(&f, "--xy").unwrap(), None);
        let f = flight(&["time", "Easting", "EASTING", "northing"]);
        let e = ProjectedColumns::found_in(&f, "--xy").unwrap_err();
        assert!(e.is_bad_input() && e.to_string().contains("--xy"), "{e}");
    }

    #[test]
    fn spacing_and_direction_of_lines_with_ties_and_a_reflight() {
        // Lines at 30° from north, 400 m apart; two ties across them; line
        // 3 re-flown 15 m beside itself.
        let (mut x, mut y, mut ids) = (vec![], vec![], vec![]);
        let th = 30f64.to_radians();
        let (along, across) = ((th.sin(), th.cos()), (th.cos(), -th.sin()));
        let mut push = |id: f64, off: f64, dir: (f64, f64), nrm: (f64, f64)| {
            for k in 0..200 {
                let s = k as f64 * 25.0 - 2500.0;
                x.push(s * dir.0 + off * nrm.0);
                y.push(s * dir.1 + off * nrm.1);
                ids.push(id);
            }
        };
        for l in 0..10 {
            push(l as f64 + 1.0, 400.0 * l as f64, along, across);
        }
        push(11.0, 3.0 * 400.0 + 15.0, along, across);
        push(20.0, -1000.0, across, along);
        push(21.0, 1500.0, across, along);
        let g = LineGeometry::of(&x, &y, &ids).unwrap();
        assert!((g.direction_deg - 30.0).abs() < 1e-6, "{g:?}");
        assert!((g.spacing_m - 400.0).abs() < 1e-6, "{g:?}");
        assert_eq!((g.traverse_lines, g.other_lines), (11, 2));
        assert_eq!(g.default_cell_m(), 100.0);
    }

    #[test]
    fn nice_cells() {
        for (v, n) in [
            (125.0, 100.0),
            (62.5, 50.0),
            (30.0, 25.0),
            (24.0, 20.0),
            (9.9, 5.0),
            (1.0, 1.0),
        ] {
            assert_eq!(nice_below(v), n, "{v}");
        }
    }
}
