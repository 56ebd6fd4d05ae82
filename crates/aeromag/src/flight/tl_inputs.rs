//! The columns of a Tolles-Lawson fit or compensation.

use super::{Flight, SegmentRule, Segments};
use crate::error::Result;
use aeromag_compensation::tolles_lawson::fit_ls::Segment;

/// `time` (s), `flux_x/y/z` (nT, body frame), `mag` (nT) and `line` (when
/// numeric) of a flight: what the Tolles-Lawson model reads.
#[derive(Debug, Clone, Copy)]
pub struct TlInputs<'a> {
    /// Time, s.
    pub time: &'a [f64],
    /// Vector magnetometer, body frame, nT.
    pub flux: [&'a [f64]; 3],
    /// Scalar reading, nT (possibly reduced by reference channels).
    pub mag: &'a [f64],
    /// Line labels, when the flight has them.
    pub line: Option<&'a [f64]>,
}

impl<'a> TlInputs<'a> {
    /// The columns of `flight`; a missing one is bad input naming the file.
    pub fn of(flight: &'a Flight) -> Result<Self> {
        Ok(Self {
            time: flight.require("time")?,
            flux: [
                flight.require("flux_x")?,
                flight.require("flux_y")?,
                flight.require("flux_z")?,
            ],
            mag: flight.require("mag")?,
            line: flight.column("line"),
        })
    }

    /// The same columns with another scalar series (same length).
    pub fn with_mag<'b>(&self, mag: &'b [f64]) -> TlInputs<'b>
    where
        'a: 'b,
    {
        TlInputs { mag, ..*self }
    }

    /// The usable-row rule: time, `mag` and the three flux components
    /// finite, and the flux not exactly zero (a dropped-out fluxgate).
    pub fn usable(&self) -> Vec<bool> {
        (0..self.time.len())
            .map(|i| {
                self.time[i].is_finite()
                    && self.mag[i].is_finite()
                    && self.flux.iter().all(|f| f[i].is_finite())
                    && (self.flux[0][i] != 0.0 || self.flux[1][i] != 0.0 || self.flux[2][i] != 0.0)
            })
            .collect()
    }

    /// The segments of usable rows under `rule`.
    pub fn segments(&self, rule: &SegmentRule) -> Segments {
        rule.split(self.time, self.line, &self.usable())
    }

    /// All rows as one fitting segment, to be sliced into legs.
    pub fn whole(&self) -> Segment<'a> {
        Segment {
            time: self.time,
            flux: self.flux,
            mag: self.mag,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use aeromag_io::FlightTable;

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
}
