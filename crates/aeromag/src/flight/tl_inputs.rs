//! The columns of a Tolles-Lawson fit or compensation.

use super::{Flight, SegmentRule, Segments};
use crate::error::Result;
use aeromag_compensation::tolles_lawson::ExtraTerm;
use aeromag_compensation::tolles_lawson::design::Channels;
use aeromag_compensation::tolles_lawson::fit_ls::Segment;
use aeromag_compensation::tolles_lawson::segments::median_step;

/// `time` (s), `flux_x/y/z` (nT, body frame), `mag` (nT), `line`
/// ([`Flight::line_numbers`]) and the channels of the extra regressors of a flight: what the
/// Tolles-Lawson model reads.
#[derive(Debug, Clone)]
pub struct TlInputs<'a> {
    /// Time, s.
    pub time: &'a [f64],
    /// Vector magnetometer, body frame, nT.
    pub flux: [&'a [f64]; 3],
    /// Scalar reading, nT (possibly reduced by reference channels).
    pub mag: &'a [f64],
    /// Line labels, when the flight has them.
    pub line: Option<&'a [f64]>,
    /// The channels of the extra regressors, in the terms' order
    /// ([`TlInputs::with_extras`]).
    pub channels: Vec<&'a [f64]>,
    /// The flight whose `time` this is, for its median step
    /// ([`Flight::median_step_s`]; `None`: worked out from `time`).
    pub flight: Option<&'a Flight>,
}

/// The columns of one scalar magnetometer and the vector magnetometer its
/// model reads (a flight may carry several of each: SGL's aircraft has five
/// scalars and four fluxgates).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SensorColumns {
    /// The scalar magnetometer.
    pub mag: String,
    /// The vector magnetometer's x, y, z (body frame).
    pub flux: [String; 3],
}

impl Default for SensorColumns {
    /// The canonical `mag` and `flux_x/y/z` (whatever the flight's column
    /// map or sensor choice made them).
    fn default() -> Self {
        Self {
            mag: "mag".into(),
            flux: ["flux_x".into(), "flux_y".into(), "flux_z".into()],
        }
    }
}

impl SensorColumns {
    /// The scalar magnetometer `mag` and the vector magnetometer of prefix
    /// `vector` (`flux_b` → `flux_b_x/y/z`; `None`: the flight's
    /// `flux_x/y/z`), found in `flight` by the rules of `--mag` and
    /// `--vector` (SGL HDF5 and Geosoft XYZ names of one sensor, without
    /// regard to case). A sensor the flight lacks is bad input naming the
    /// file and the sensor.
    ///
    /// An SGL sensor is kept under its MagNav name (`UNCOMPMAG3` →
    /// `mag_3_uc`, `FLUXB_X` → `flux_b_x`; [`aeromag_io::magnav_name`]),
    /// which finds it in a flight of either naming: a model fitted on the
    /// XYZ export applies to the HDF5 layout and back.
    pub fn find(flight: &Flight, mag: &str, vector: Option<&str>) -> Result<Self> {
        let names = flight.column_names();
        let find = |name: &str| -> Option<String> {
            aeromag_io::sensor_names(name).iter().find_map(|n| {
                names
                    .iter()
                    .find(|h| h.eq_ignore_ascii_case(n))
                    .map(|h| aeromag_io::magnav_name(h))
            })
        };
        let absent = |what: &str, name: &str| {
            crate::Error::bad_file(
                flight.label(),
                format!(
                    "has no {what} `{name}`; columns present: {}",
                    flight.table().present_columns()
                ),
            )
        };
        let mag = find(mag).ok_or_else(|| absent("scalar magnetometer", mag))?;
        let flux = match vector {
            None => Self::default().flux,
            Some(p) => {
                let axis = |a: &str| {
                    find(&format!("{p}_{a}")).ok_or_else(|| absent("vector magnetometer", p))
                };
                [axis("x")?, axis("y")?, axis("z")?]
            }
        };
        // The canonical `mag` and `flux_x/y/z` were checked when the
        // flight was read; another sensor's columns are checked here.
        let canonical = Self::default();
        if mag != canonical.mag || flux != canonical.flux {
            let [x, y, z] = flux.each_ref().map(String::as_str);
            aeromag_io::check_sensor_units(flight.table(), &mag, [x, y, z])?;
        }
        Ok(Self { mag, flux })
    }

    /// The sensors `mags` of `flight` with their vector magnetometers:
    /// `vectors` gives none (the flight's `flux_x/y/z` for all), one prefix
    /// for all, or one per sensor (`--mag A,B,… --vector P,Q,…`). Bad input
    /// for no sensor or a vector list of another length.
    pub fn list(flight: &Flight, mags: &[String], vectors: &[String]) -> Result<Vec<Self>> {
        if mags.is_empty() {
            return Err(crate::Error::bad_input(
                "give the scalar sensors (--mag A,B,…)",
            ));
        }
        if vectors.len() > 1 && vectors.len() != mags.len() {
            return Err(crate::Error::bad_input(format!(
                "--vector names {} vector magnetometers for {} scalar sensors: give one for all or one per sensor",
                vectors.len(),
                mags.len()
            )));
        }
        mags.iter()
            .enumerate()
            .map(|(k, m)| {
                let v = vectors.get(k).or(vectors.first()).map(String::as_str);
                Self::find(flight, m, v)
            })
            .collect()
    }

    /// Stem of the sensor's output columns: `mag_3_uc` → `mag_3`,
    /// `UNCOMPMAG3` → `mag_3`, any other name as it is.
    pub fn stem(&self) -> String {
        // The sensor's SGL HDF5 name (the XYZ export's `UNCOMPMAG3` is
        // `mag_3_uc`), without `_uc`.
        let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
        aeromag_io::sensor_names(&self.mag)
            .iter()
            .map(|n| n.to_ascii_lowercase())
            .find_map(|n| {
                let stem = n.strip_suffix("_uc")?;
                stem.strip_prefix("mag_")
                    .is_some_and(digits)
                    .then(|| stem.to_string())
            })
            .unwrap_or_else(|| self.mag.clone())
    }
}

impl<'a> TlInputs<'a> {
    /// The columns of `flight`; a missing one is bad input naming the file.
    pub fn of(flight: &'a Flight) -> Result<Self> {
        Self::of_sensor(flight, &SensorColumns::default())
    }

    /// The columns of `flight` with the scalar and vector magnetometers of
    /// `sensor`.
    pub fn of_sensor(flight: &'a Flight, sensor: &SensorColumns) -> Result<Self> {
        Ok(Self {
            time: flight.require("time")?,
            flux: [
                flight.measured(&sensor.flux[0])?,
                flight.measured(&sensor.flux[1])?,
                flight.measured(&sensor.flux[2])?,
            ],
            mag: flight.measured(&sensor.mag)?,
            line: flight.line_numbers(),
            channels: Vec::new(),
            flight: Some(flight),
        })
    }

    /// These columns with the channels of the extra regressors `extras`
    /// (a missing channel is bad input naming the file and the column).
    pub fn with_extras(self, flight: &'a Flight, extras: &[ExtraTerm]) -> Result<Self> {
        let channels = extras
            .iter()
            .map(|x| flight.measured(&x.channel))
            .collect::<Result<_>>()?;
        Ok(Self { channels, ..self })
    }

    /// The same columns with another scalar series (same length).
    pub fn with_mag<'b>(&self, mag: &'b [f64]) -> TlInputs<'b>
    where
        'a: 'b,
    {
        TlInputs {
            mag,
            ..self.clone()
        }
    }

    /// The usable-row rule: time, `mag`, the three flux components and the
    /// extra channels finite, and the flux not exactly zero (a dropped-out
    /// fluxgate).
    pub fn usable(&self) -> Vec<bool> {
        // Column by column with `&` (no early exit), so each pass
        // vectorises; parts of the rows on the cores (a pass over five
        // flight-long columns is bound by memory, which two cores read
        // faster than one). Each row's flag is its own, whatever the parts.
        let [x, y, z] = self.flux;
        let (time, mag, channels) = (self.time, self.mag, &self.channels);
        let mut ok = vec![false; time.len()];
        let threads = aeromag_core::parallel::threads();
        aeromag_core::parallel::for_each_part_mut(&mut ok, threads, 1 << 16, |a, part| {
            let r = a..a + part.len();
            let (t, m, x, y, z) = (
                &time[r.clone()],
                &mag[r.clone()],
                &x[r.clone()],
                &y[r.clone()],
                &z[r.clone()],
            );
            for (i, o) in part.iter_mut().enumerate() {
                let finite = t[i].is_finite()
                    & m[i].is_finite()
                    & x[i].is_finite()
                    & y[i].is_finite()
                    & z[i].is_finite();
                *o = finite & ((x[i] != 0.0) | (y[i] != 0.0) | (z[i] != 0.0));
            }
            for c in channels {
                for (o, v) in part.iter_mut().zip(c.get(a..).unwrap_or(&[])) {
                    *o &= v.is_finite();
                }
            }
        });
        ok
    }

    /// The segments of usable rows under `rule`.
    pub fn segments(&self, rule: &SegmentRule) -> Segments {
        let usable = self.usable();
        // The flight's median step, worked out once for all its splits,
        // and only when the rule needs it.
        let median = || match self.flight.map(Flight::median_step_s) {
            Some(Ok(step)) => step,
            _ => median_step(self.time),
        };
        rule.split_with(self.time, self.line, &usable, median)
    }

    /// All rows as one fitting segment, to be sliced into legs.
    pub fn whole(&self) -> Segment<'_> {
        Segment {
            time: self.time,
            flux: self.flux,
            mag: self.mag,
            channels: Channels::new(&self.channels),
            direction: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use aeromag_io::FlightTable;

    #[test]
    fn sensor_stems_are_the_sgl_names_without_uc() {
        let stem = |mag: &str| {
            SensorColumns {
                mag: mag.into(),
                ..SensorColumns::default()
            }
            .stem()
        };
        assert_eq!(stem("mag_3_uc"), "mag_3");
        assert_eq!(stem("UNCOMPMAG4"), "mag_4");
        assert_eq!(stem("MAG_2_UC"), "mag_2");
        assert_eq!(stem("mag_x_uc"), "mag_x_uc");
        assert_eq!(stem("mag_2"), "mag_2");
        assert_eq!(stem("mag"), "mag");
    }

    /// A flight's segments, with its median step worked out once, are
    /// those of the time column's own median under every rule (a gap, a
    /// step just under the gap rule, a line change, a missing value), and
    /// its median step is the time steps' median.
    #[test]
    fn the_flights_median_step_splits_as_the_time_columns() {
        let n = 400;
        let mut time: Vec<f64> = (0..n).map(|k| k as f64 * 0.1).collect();
        for (from, by) in [(100, 0.04), (250, 0.3)] {
            for t in &mut time[from..] {
                *t += by;
            }
        }
        let line: Vec<f64> = (0..n).map(|k| if k < 300 { 7.0 } else { 8.0 }).collect();
        let mut mag = vec![50_000.0; n];
        mag[180] = f64::NAN;
        let mut t = FlightTable::new();
        t.add_column("time", time.clone()).unwrap();
        t.add_column("line", line.clone()).unwrap();
        t.add_column("mag", mag).unwrap();
        for (c, v) in [
            ("flux_x", 20_000.0),
            ("flux_y", 1_000.0),
            ("flux_z", 45_000.0),
        ] {
            t.add_column(c, vec![v; n]).unwrap();
        }
        let flight = Flight::from_table(t).unwrap();
        let step = median_step(&time);
        assert_eq!(flight.median_step_s().unwrap().to_bits(), step.to_bits());
        assert_eq!(flight.median_step_s().unwrap().to_bits(), step.to_bits());
        let inputs = TlInputs::of_sensor(&flight, &SensorColumns::default()).unwrap();
        let alone = TlInputs {
            flight: None,
            ..inputs.clone()
        };
        for rule in [
            SegmentRule::default(),
            SegmentRule::ignoring_lines(),
            SegmentRule::default().min_len(120),
            SegmentRule {
                gap_factor: f64::INFINITY,
                ..SegmentRule::default()
            },
        ] {
            let ours = inputs.segments(&rule);
            assert_eq!(ours, alone.segments(&rule));
            assert_eq!(ours, rule.split(&time, Some(&line), &inputs.usable()));
        }
        assert_eq!(
            inputs.segments(&SegmentRule::default()).kept,
            vec![0..180, 181..250, 250..300, 300..400]
        );
    }

    /// Text line labels (`L7`, `L8`: the labels `--lines` shows) split
    /// the flight into legs as numbers do; before, a text `line` column
    /// was not seen and the flight was one leg.
    #[test]
    fn text_line_labels_split_legs_as_numbers_do() {
        let n = 400;
        let columns = |line: std::result::Result<Vec<f64>, Vec<String>>| {
            let mut t = FlightTable::new();
            t.add_column("time", (0..n).map(|k| k as f64 * 0.1).collect())
                .unwrap();
            match line {
                Ok(v) => t.add_column("line", v).unwrap(),
                Err(s) => t.add_text_column("line", s).unwrap(),
            }
            t.add_column("mag", vec![50_000.0; n]).unwrap();
            for (c, v) in [("flux_x", 2e4), ("flux_y", 1e3), ("flux_z", 4.5e4)] {
                t.add_column(c, vec![v; n]).unwrap();
            }
            Flight::from_table(t).unwrap()
        };
        let at = |k: usize| {
            if k < 150 {
                7
            } else if k < 300 {
                8
            } else {
                7
            }
        };
        let numbers = columns(Ok((0..n).map(|k| at(k) as f64).collect()));
        let text = columns(Err((0..n).map(|k| format!("L{}", at(k))).collect()));
        let legs = |f: &Flight| {
            TlInputs::of_sensor(f, &SensorColumns::default())
                .unwrap()
                .segments(&SegmentRule::default())
                .kept
        };
        assert_eq!(legs(&text), vec![0..150, 150..300, 300..400]);
        assert_eq!(legs(&text), legs(&numbers));
    }

    #[test]
    fn a_row_is_usable_with_every_input_finite_and_a_live_fluxgate() {
        let mut t = FlightTable::new();
        t.add_column("time", vec![0.0, 0.1, 0.2, 0.3]).unwrap();
        t.add_column("mag", vec![50_000.0, f64::NAN, 50_000.0, 50_000.0])
            .unwrap();
        t.add_column("flux_x", vec![20_000.0, 20_000.0, 0.0, 20_000.0])
            .unwrap();
        t.add_column("flux_y", vec![1_000.0, 1_000.0, 0.0, 1_000.0])
            .unwrap();
        t.add_column("flux_z", vec![45_000.0, 45_000.0, 0.0, 45_000.0])
            .unwrap();
        let f = Flight::from_table(t).unwrap();
        let cols = TlInputs::of(&f).unwrap();
        assert_eq!(cols.usable(), [true, false, false, true]);
        let mut bare = FlightTable::new();
        bare.add_column("time", vec![0.0]).unwrap();
        let e = TlInputs::of(&Flight::from_table(bare).unwrap()).unwrap_err();
        assert!(e.is_bad_input() && e.to_string().contains("flux_x"), "{e}");
    }

    /// A long flight's flags, worked out on the cores by parts, are each
    /// row's own: a missing value in any input or channel, or a dead
    /// fluxgate, on either side of every part boundary.
    #[test]
    fn usable_rows_of_a_long_flight_are_each_rows_own() {
        let n = 5 * (1 << 16) + 123;
        let bad =
            |k: usize, col: usize| (k * 7 + col * 13).is_multiple_of(101) || (k % (1 << 16)) == col;
        let series = |col: usize, v: f64| -> Vec<f64> {
            (0..n)
                .map(|k| if bad(k, col) { f64::NAN } else { v + k as f64 })
                .collect()
        };
        let time = series(0, 0.0);
        let mag = series(1, 50_000.0);
        let (mut x, mut y, mut z) = (series(2, 20_000.0), series(3, 1_000.0), series(4, 45_000.0));
        let channel = series(5, 3.0);
        // Dead fluxgates (all three components zero) and one live one with
        // x alone zero.
        for k in [0, 65_535, 65_536, 65_537, 200_000, n - 1] {
            x[k] = 0.0;
            y[k] = 0.0;
            z[k] = 0.0;
        }
        x[131_122] = 0.0;
        let inputs = TlInputs {
            time: &time,
            flux: [&x, &y, &z],
            mag: &mag,
            line: None,
            channels: vec![&channel],
            flight: None,
        };
        let expected: Vec<bool> = (0..n)
            .map(|k| {
                [time[k], mag[k], x[k], y[k], z[k], channel[k]]
                    .iter()
                    .all(|v| v.is_finite())
                    && (x[k], y[k], z[k]) != (0.0, 0.0, 0.0)
            })
            .collect();
        let usable = inputs.usable();
        assert_eq!(usable, expected);
        assert!(usable[131_122] && !usable[65_536]);
        assert!(expected.iter().filter(|u| !**u).count() > 1000);
    }
}
