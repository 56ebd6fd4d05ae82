//! The interference by part and manoeuvre: how much of it is permanent,
//! induced and eddy-current (the thesis' table of contributions, seed
//! `003`, which compares the same aircraft over Elista, Brazil and Yakutia:
//! the induced part follows the field's direction, the eddy part its
//! strength, so the shares change with the site's inclination).
//!
//! Each part is the model with the other groups' coefficients set to zero
//! ([`InterferenceParts`]). Its size during a manoeuvre is the RMS of its
//! deviation from its mean over that manoeuvre (nT): what the part adds to
//! the manoeuvre, the level of each heading left aside. Rows are grouped by
//! the `manoeuvre` column when the flight has one (0 none, 1 roll, 2 pitch,
//! 3 yaw, as the simulator writes it): each run of one code is a
//! manoeuvre, and a group (`roll`, `pitch`, `yaw`, `manoeuvres` for the
//! three, `between` for the legs and turns between them) pools the
//! deviations of its runs. Without the column the whole flight is one
//! group, `all`, about its mean.

use super::compensate::InterferenceParts;
use crate::error::Result;
use crate::flight::{Flight, SensorColumns};
use aeromag_compensation::model_file::TlModel;
use serde::Serialize;

/// The size of each part over one group of rows (nT, RMS about the mean).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PartsRms {
    /// The group: `roll`, `pitch`, `yaw`, `manoeuvres`, `between` or `all`.
    pub group: String,
    /// Rows in the group.
    pub rows: usize,
    /// Permanent magnetization.
    pub permanent_nt: f64,
    /// Induced magnetization.
    pub induced_nt: f64,
    /// Eddy currents.
    pub eddy_nt: f64,
    /// The extra regressors (currents).
    pub currents_nt: f64,
    /// The sum of the parts.
    pub total_nt: f64,
}

/// [`PartsRms`] per manoeuvre of a flight under a model.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Contributions {
    /// One entry per manoeuvre present, then `all`.
    pub groups: Vec<PartsRms>,
}

/// The groups of the simulator's manoeuvre codes.
const GROUPS: [(&str, &[f64]); 5] = [
    ("roll", &[1.0]),
    ("pitch", &[2.0]),
    ("yaw", &[3.0]),
    ("manoeuvres", &[1.0, 2.0, 3.0]),
    ("between", &[0.0]),
];

impl Contributions {
    /// The parts of `model`'s interference on `flight` (its default sensor)
    /// per manoeuvre (module docs).
    pub fn of(model: &TlModel, flight: &Flight) -> Result<Self> {
        let p = InterferenceParts::of(model, flight, &SensorColumns::default())?;
        Ok(Self::from_series(
            [&p.permanent, &p.induced, &p.eddy, &p.currents],
            flight.column("manoeuvre"),
        ))
    }

    /// The same from given part series (permanent, induced, eddy,
    /// currents; e.g. the simulator's truth) and manoeuvre codes.
    pub fn from_series(parts: [&[f64]; 4], manoeuvre: Option<&[f64]>) -> Self {
        let n = parts[0].len();
        let Some(codes) = manoeuvre else {
            return Self {
                groups: vec![Self::group("all", std::slice::from_ref(&(0..n)), parts)],
            };
        };
        // Runs of one code.
        let mut runs: Vec<(f64, std::ops::Range<usize>)> = Vec::new();
        let mut start = 0;
        for k in 1..=n {
            if k == n || codes[k] != codes[start] {
                runs.push((codes[start], start..k));
                start = k;
            }
        }
        let groups = GROUPS
            .iter()
            .filter_map(|(name, of)| {
                let rs: Vec<std::ops::Range<usize>> = runs
                    .iter()
                    .filter(|(c, _)| of.contains(c))
                    .map(|(_, r)| r.clone())
                    .collect();
                (!rs.is_empty()).then(|| Self::group(name, &rs, parts))
            })
            .collect();
        Self { groups }
    }

    /// The RMS of each part's deviation from its mean over each run, pooled.
    fn group(name: &str, runs: &[std::ops::Range<usize>], parts: [&[f64]; 4]) -> PartsRms {
        let rms = |f: &dyn Fn(usize) -> f64| {
            let (mut ss, mut n) = (0.0, 0usize);
            for r in runs {
                // Two passes over the run's finite values (no copy).
                let v = || r.clone().map(f).filter(|x| x.is_finite());
                let count = v().count();
                if count == 0 {
                    continue;
                }
                let m = v().sum::<f64>() / count as f64;
                ss += v().map(|x| (x - m).powi(2)).sum::<f64>();
                n += count;
            }
            if n == 0 {
                f64::NAN
            } else {
                (ss / n as f64).sqrt()
            }
        };
        let rows = runs.iter().map(|r| r.len()).sum();
        let zero_if_nan = |x: f64| if x.is_nan() { 0.0 } else { x };
        PartsRms {
            group: name.to_string(),
            rows,
            permanent_nt: rms(&|k| parts[0][k]),
            induced_nt: rms(&|k| parts[1][k]),
            eddy_nt: rms(&|k| parts[2][k]),
            currents_nt: rms(&|k| zero_if_nan(parts[3][k])),
            total_nt: rms(&|k| parts[0][k] + parts[1][k] + parts[2][k] + zero_if_nan(parts[3][k])),
        }
    }
}

impl super::Calibration {
    /// The fitted model's interference on `flight` (normally the
    /// calibration flight) by part and manoeuvre.
    pub fn contributions(&self, flight: &Flight) -> Result<Contributions> {
        Contributions::of(&self.model, flight)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_manoeuvre_is_measured_about_its_own_mean() {
        // Two roll runs at different levels (headings), one pitch run.
        let perm = [1.0, 3.0, 0.0, 0.0, 5.0, 5.0, 11.0, 13.0];
        let ind = [0.0, 0.0, 2.0, -2.0, 0.0, 0.0, 0.0, 0.0];
        let zero = [0.0; 8];
        let codes = [1.0, 1.0, 2.0, 2.0, 0.0, 0.0, 1.0, 1.0];
        let c = Contributions::from_series([&perm, &ind, &zero, &zero], Some(&codes));
        let names: Vec<&str> = c.groups.iter().map(|g| g.group.as_str()).collect();
        assert_eq!(names, ["roll", "pitch", "manoeuvres", "between"]);
        // Rolls: ±1 about 2 and about 12, not about their common mean.
        assert_eq!(c.groups[0].permanent_nt, 1.0);
        assert_eq!(c.groups[0].rows, 4);
        assert_eq!(c.groups[1].induced_nt, 2.0);
        assert_eq!(c.groups[3].total_nt, 0.0);
        assert_eq!(c.groups[2].rows, 6);
        let whole = Contributions::from_series([&perm, &ind, &zero, &zero], None);
        assert_eq!(whole.groups.len(), 1);
        assert_eq!(whole.groups[0].group, "all");
    }
}
