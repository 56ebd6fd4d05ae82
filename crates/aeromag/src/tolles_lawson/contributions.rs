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
            let runs = [(0.0, 0..n)];
            let moments = run_moments(&runs, parts);
            return Self {
                groups: vec![Self::group("all", &[0], &runs, &moments)],
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
        // Each run's moments once (a group pools those of its runs, and
        // `manoeuvres` reuses those of roll, pitch and yaw), the runs and
        // parts on the cores.
        let moments = run_moments(&runs, parts);
        let groups = GROUPS
            .iter()
            .filter_map(|(name, of)| {
                let rs: Vec<usize> = (0..runs.len())
                    .filter(|&r| of.contains(&runs[r].0))
                    .collect();
                (!rs.is_empty()).then(|| Self::group(name, &rs, &runs, &moments))
            })
            .collect();
        Self { groups }
    }

    /// The RMS of each part's deviation from its mean over each of the
    /// runs `rs`, pooled (`moments`: those of every run).
    fn group(
        name: &str,
        rs: &[usize],
        runs: &[(f64, std::ops::Range<usize>)],
        moments: &[[Moments; PARTS]],
    ) -> PartsRms {
        let rms = |p: usize| {
            let (mut ss, mut n) = (0.0, 0usize);
            for &r in rs {
                let m = moments[r][p];
                if m.count > 0 {
                    ss += m.ss;
                    n += m.count;
                }
            }
            if n == 0 {
                f64::NAN
            } else {
                (ss / n as f64).sqrt()
            }
        };
        PartsRms {
            group: name.to_string(),
            rows: rs.iter().map(|&r| runs[r].1.len()).sum(),
            permanent_nt: rms(0),
            induced_nt: rms(1),
            eddy_nt: rms(2),
            currents_nt: rms(3),
            total_nt: rms(4),
        }
    }
}

/// The parts measured: permanent, induced, eddy, currents, their sum.
const PARTS: usize = 5;

/// The finite values of one part over one run: how many, and the sum of
/// their squared deviations from their mean.
#[derive(Debug, Clone, Copy)]
struct Moments {
    count: usize,
    ss: f64,
}

impl Moments {
    /// Two passes over the run's finite values of `f` (no copy).
    fn of(r: &std::ops::Range<usize>, f: impl Fn(usize) -> f64) -> Self {
        let v = || r.clone().map(&f).filter(|x| x.is_finite());
        let count = v().count();
        if count == 0 {
            return Self { count, ss: 0.0 };
        }
        let m = v().sum::<f64>() / count as f64;
        Self {
            count,
            ss: v().map(|x| (x - m).powi(2)).sum::<f64>(),
        }
    }
}

/// [`Moments`] of every part over every run, each on its own (the same
/// bits on any number of cores).
fn run_moments(
    runs: &[(f64, std::ops::Range<usize>)],
    parts: [&[f64]; 4],
) -> Vec<[Moments; PARTS]> {
    let zero_if_nan = |x: f64| if x.is_nan() { 0.0 } else { x };
    let one = |i: usize| {
        let r = &runs[i / PARTS].1;
        match i % PARTS {
            0 => Moments::of(r, |k| parts[0][k]),
            1 => Moments::of(r, |k| parts[1][k]),
            2 => Moments::of(r, |k| parts[2][k]),
            3 => Moments::of(r, |k| zero_if_nan(parts[3][k])),
            _ => Moments::of(r, |k| {
                parts[0][k] + parts[1][k] + parts[2][k] + zero_if_nan(parts[3][k])
            }),
        }
    };
    let rows = parts[0].len();
    let threads = if rows >= 1 << 16 {
        aeromag_core::parallel::threads()
    } else {
        1
    };
    let flat = aeromag_core::parallel::parallel_map(runs.len() * PARTS, threads, one);
    flat.chunks_exact(PARTS)
        .map(|c| std::array::from_fn(|p| c[p]))
        .collect()
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
