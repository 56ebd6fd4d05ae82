//! Known external-field channels removed from the scalar reading.

use super::Flight;
use crate::error::{Error, InFile, Result};
use aeromag_compensation::reference_field::{LeverArm, lever_arm_correction_nt};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// Which known external-field channels are subtracted from `mag` before a
/// fit and before scoring (FOM, IR).
///
/// The reduction to the anomaly field keeps the base station's diurnal
/// variation and the main field out of the band-pass fit.
///
/// ```
/// use aeromag::ReferenceChannels;
/// assert_eq!("auto".parse::<ReferenceChannels>()?, ReferenceChannels::Auto);
/// assert_eq!("none".parse::<ReferenceChannels>()?, ReferenceChannels::None);
/// assert!("".parse::<ReferenceChannels>().is_err());
/// assert!(" , ".parse::<ReferenceChannels>().is_err());
/// assert_eq!(
///     "diurnal, igrf".parse::<ReferenceChannels>()?,
///     ReferenceChannels::Columns(vec!["diurnal".into(), "igrf".into()])
/// );
/// # Ok::<(), aeromag::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ReferenceChannels {
    /// `diurnal` (base station) and `igrf` (main field at the recorded
    /// position), those the file has.
    #[default]
    Auto,
    /// `mag` as it is (MagNav.jl's way).
    None,
    /// These columns, each of which must exist.
    Columns(Vec<String>),
}

impl ReferenceChannels {
    /// The channels of `flight` this choice names (bad input if a listed
    /// column is missing).
    pub fn resolve(&self, flight: &Flight) -> Result<Vec<String>> {
        match self {
            ReferenceChannels::Auto => Ok(["diurnal", "igrf"]
                .iter()
                .filter(|c| flight.column(c).is_some())
                .map(|c| c.to_string())
                .collect()),
            ReferenceChannels::None => Ok(Vec::new()),
            ReferenceChannels::Columns(cols) => {
                for c in cols {
                    flight.require(c)?;
                }
                Ok(cols.clone())
            }
        }
    }
}

impl ReferenceChannels {
    /// The channels of `flight` this choice subtracts, for a report:
    /// `diurnal, igrf (derived from DCMAG1 − IGRFMAG1)`, or `none`.
    pub fn describe(&self, flight: &Flight) -> Result<String> {
        let cols = self.resolve(flight)?;
        if cols.is_empty() {
            return Ok("none".into());
        }
        Ok(cols
            .iter()
            .map(
                |c| match flight.derived().iter().find(|d| d.canonical == *c) {
                    Some(d) if d.minus.is_some() => format!("{c} (derived from {})", d.describe()),
                    _ => c.clone(),
                },
            )
            .collect::<Vec<_>>()
            .join(", "))
    }
}

impl FromStr for ReferenceChannels {
    type Err = Error;
    /// `auto`, `none` or a comma-separated list of columns. Empty (or
    /// only commas) is bad input: an unset shell variable
    /// (`--reference=$REF`) meant `none`.
    fn from_str(s: &str) -> Result<Self> {
        Ok(match s.trim() {
            "auto" => ReferenceChannels::Auto,
            "none" => ReferenceChannels::None,
            list => {
                let columns: Vec<String> = list
                    .split(',')
                    .map(|c| c.trim().to_string())
                    .filter(|c| !c.is_empty())
                    .collect();
                if columns.is_empty() {
                    return Err(Error::bad_input(format!(
                        "reference `{s}` names no column: give auto, none or columns such as diurnal,igrf"
                    )));
                }
                ReferenceChannels::Columns(columns)
            }
        })
    }
}

impl fmt::Display for ReferenceChannels {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ReferenceChannels::Auto => f.write_str("auto"),
            ReferenceChannels::None => f.write_str("none"),
            ReferenceChannels::Columns(c) => f.write_str(&c.join(",")),
        }
    }
}

/// Canonical columns that cannot be references: the readings compensated
/// and what compensation writes (subtracting one from itself leaves
/// nothing to fit or score).
const NOT_REFERENCES: [&str; 6] = [
    "mag",
    "mag_comp",
    "mag_interf",
    "flux_x",
    "flux_y",
    "flux_z",
];

/// Canonical columns that are no magnetic field, so no reference.
pub(crate) const NOT_FIELDS: [&str; 11] = [
    "time", "lat", "lon", "alt", "vn", "ve", "vd", "roll", "pitch", "yaw", "line",
];

/// The sum of the named reference channels of `flight` (zeros if none),
/// nT. With a lever arm, the `igrf` channel is moved from the navigation
/// point to the sensor (needs `lat`, `lon`, `alt`, `roll`, `pitch`, `yaw`;
/// [`aeromag_compensation::reference_field`]).
pub fn reference_sum(
    flight: &Flight,
    cols: &[String],
    lever: Option<&LeverArm>,
) -> Result<Vec<f64>> {
    if let Some(c) = cols.iter().find(|c| NOT_REFERENCES.contains(&c.as_str())) {
        return Err(Error::bad_input(format!(
            "reference channel `{c}` is a magnetometer reading or its compensation, not a \
             reference: a reference is a field the aircraft does not make (igrf, diurnal, a base \
             station's record)"
        )));
    }
    if let Some(c) = cols.iter().find(|c| NOT_FIELDS.contains(&c.as_str())) {
        return Err(Error::bad_input(format!(
            "reference channel `{c}` is not a magnetic field (nT): a reference is a field the \
             aircraft does not make (igrf, diurnal, a base station's record)"
        )));
    }
    // Each channel named is subtracted once per naming: found by fuzzing,
    // `diurnal,diurnal` moved the fitted p_z from −12.9 to −15.1 nT silently.
    if let Some((k, c)) = cols
        .iter()
        .enumerate()
        .find(|(k, c)| cols[..*k].contains(c))
    {
        return Err(Error::bad_input(format!(
            "reference channel `{c}` is named twice (channels {} and {} of the list): each is \
             subtracted once",
            cols.iter().position(|x| x == c).map_or(0, |p| p + 1),
            k + 1
        )));
    }
    let mut r = vec![0.0; flight.n_rows()];
    for c in cols {
        for (a, b) in r.iter_mut().zip(flight.require(c)?) {
            *a += b;
        }
    }
    if let (Some(lever), true) = (lever, cols.iter().any(|c| c == "igrf")) {
        let [lat, lon, alt, roll, pitch, yaw] = flight.nav_and_attitude()?;
        let corr = lever_arm_correction_nt(lever, lat, lon, alt, roll, pitch, yaw)
            .in_file(&flight.label())?;
        for (a, c) in r.iter_mut().zip(corr) {
            *a += c;
        }
    }
    Ok(r)
}

/// `values` minus the reference `sum`, element by element.
pub(crate) fn reduced(values: &[f64], sum: &[f64]) -> Vec<f64> {
    values.iter().zip(sum).map(|(v, r)| v - r).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use aeromag_io::FlightTable;

    fn flight() -> Flight {
        let mut t = FlightTable::new();
        t.add_column("time", vec![0.0, 1.0]).unwrap();
        t.add_column("mag", vec![50_010.0, 50_020.0]).unwrap();
        t.add_column("diurnal", vec![10.0, 20.0]).unwrap();
        Flight::from_table(t).unwrap()
    }

    #[test]
    fn choices_resolve_to_the_flights_columns() {
        let f = flight();
        assert_eq!(ReferenceChannels::Auto.resolve(&f).unwrap(), ["diurnal"]);
        assert!(ReferenceChannels::None.resolve(&f).unwrap().is_empty());
        let missing: ReferenceChannels = "diurnal,igrf".parse().unwrap();
        let e = missing.resolve(&f).unwrap_err();
        assert!(e.is_bad_input() && e.to_string().contains("igrf"), "{e}");
        for text in ["auto", "none", "diurnal,igrf"] {
            let r: ReferenceChannels = text.parse().unwrap();
            assert_eq!(r.to_string(), text);
        }
        let sum = reference_sum(&f, &["diurnal".into()], None).unwrap();
        assert_eq!(
            reduced(f.require("mag").unwrap(), &sum),
            [50_000.0, 50_000.0]
        );
        // The reading itself is no reference (all coefficients 0, residual 0).
        for c in ["mag", "mag_comp"] {
            let e = reference_sum(&f, &["diurnal".into(), c.into()], None).unwrap_err();
            assert!(e.is_bad_input() && e.to_string().contains(c), "{e}");
        }
        // Neither is a column that is no field, nor one named twice (it was
        // subtracted twice).
        for (cols, needle) in [
            (vec!["time"], "not a magnetic field"),
            (vec!["diurnal", "diurnal"], "named twice (channels 1 and 2"),
        ] {
            let cols: Vec<String> = cols.into_iter().map(String::from).collect();
            let e = reference_sum(&f, &cols, None).unwrap_err();
            assert!(e.is_bad_input() && e.to_string().contains(needle), "{e}");
        }
    }
}
