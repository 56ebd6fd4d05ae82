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

use super::compensate::{InterferenceParts, tl_interference_blocks};
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
    /// per manoeuvre (module docs). A model whose rows are computed apart
    /// ([`aeromag_compensation::tolles_lawson::Design::rows_apart`]: no
    /// lagged column, the first-order magnitude) is evaluated block by
    /// block into the moments, without the four flight-long series: the
    /// same table, bit for bit. At 10⁶ rows with the MagNav settings
    /// (`calibrate`'s table): 26 → 17.5 ms and 32 MB less (`calibrate`
    /// 187 → 179 ms, peak memory 93 → 80 MB).
    pub fn of(model: &TlModel, flight: &Flight) -> Result<Self> {
        let codes = flight.column("manoeuvre");
        let runs = runs(codes, flight.n_rows());
        let blocks = moment_blocks(&runs);
        let coefs = InterferenceParts::coefficients(model);
        let ranges: Vec<std::ops::Range<usize>> = blocks.iter().map(|(_, r)| r.clone()).collect();
        let moments = tl_interference_blocks(
            model,
            coefs.each_ref().map(|c| &c[..]),
            flight,
            &SensorColumns::default(),
            &ranges,
            |parts| Moments::of_parts(&(0..parts[0].len()), values_of(parts)),
        )?;
        let moments = match moments {
            Some(m) => merged(&runs, &blocks, m),
            None => {
                let p = InterferenceParts::of(model, flight, &SensorColumns::default())?;
                run_moments(&runs, [&p.permanent, &p.induced, &p.eddy, &p.currents])
            }
        };
        Ok(Self::of_runs(&runs, codes.is_some(), &moments))
    }

    /// The same from given part series (permanent, induced, eddy,
    /// currents; e.g. the simulator's truth) and manoeuvre codes.
    pub fn from_series(parts: [&[f64]; 4], manoeuvre: Option<&[f64]>) -> Self {
        let runs = runs(manoeuvre, parts[0].len());
        // Each run's moments once (a group pools those of its runs, and
        // `manoeuvres` reuses those of roll, pitch and yaw), the runs and
        // parts on the cores.
        let moments = run_moments(&runs, parts);
        Self::of_runs(&runs, manoeuvre.is_some(), &moments)
    }

    /// The groups of `runs` (`all` without manoeuvre codes) from each
    /// run's moments.
    fn of_runs(runs: &[Run], coded: bool, moments: &[[Moments; PARTS]]) -> Self {
        if !coded {
            return Self {
                groups: vec![Self::group("all", &[0], runs, moments)],
            };
        }
        let groups = GROUPS
            .iter()
            .filter_map(|(name, of)| {
                let rs: Vec<usize> = (0..runs.len())
                    .filter(|&r| of.contains(&runs[r].0))
                    .collect();
                (!rs.is_empty()).then(|| Self::group(name, &rs, runs, moments))
            })
            .collect();
        Self { groups }
    }

    /// The RMS of each part's deviation from its mean over each of the
    /// runs `rs`, pooled (`moments`: those of every run).
    fn group(name: &str, rs: &[usize], runs: &[Run], moments: &[[Moments; PARTS]]) -> PartsRms {
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

/// The finite values of one part over one run: how many, their mean and
/// the sum of their squared deviations from it.
#[derive(Debug, Clone, Copy)]
struct Moments {
    count: usize,
    mean: f64,
    ss: f64,
}

impl Moments {
    /// The moments of each of the `PARTS` values `f(k)` over the rows `r`,
    /// all parts in each pass (two passes, no copy). Each part's sums are
    /// those of its own values in row order, as `Iterator::sum` adds them.
    fn of_parts(r: &std::ops::Range<usize>, f: impl Fn(usize) -> [f64; PARTS]) -> [Self; PARTS] {
        let (mut count, mut sum) = ([0usize; PARTS], [-0.0; PARTS]);
        for k in r.clone() {
            for (p, x) in f(k).into_iter().enumerate() {
                if x.is_finite() {
                    count[p] += 1;
                    sum[p] += x;
                }
            }
        }
        let mean: [f64; PARTS] = std::array::from_fn(|p| sum[p] / count[p] as f64);
        // The deviations' sum corrects the mean for the merges (the sum's
        // rounding is far larger than the deviations' spread when the
        // values sit far from zero); the squares are about the mean.
        let (mut ss, mut dev) = ([-0.0; PARTS], [0.0; PARTS]);
        if count.iter().any(|&c| c > 0) {
            for k in r.clone() {
                for (p, x) in f(k).into_iter().enumerate() {
                    if x.is_finite() {
                        ss[p] += (x - mean[p]).powi(2);
                        dev[p] += x - mean[p];
                    }
                }
            }
        }
        std::array::from_fn(|p| Self {
            count: count[p],
            mean: mean[p] + dev[p] / count[p] as f64,
            ss: if count[p] == 0 { 0.0 } else { ss[p] },
        })
    }

    /// The moments of the values of both (Chan, Golub and LeVeque's
    /// update: the squared deviations of each about its own mean, plus
    /// those of the means about the pooled one); either alone when the
    /// other has no values, bit for bit.
    fn merge(self, other: Self) -> Self {
        if other.count == 0 {
            return self;
        }
        if self.count == 0 {
            return other;
        }
        let (a, b) = (self.count as f64, other.count as f64);
        let n = a + b;
        let delta = other.mean - self.mean;
        Self {
            count: self.count + other.count,
            mean: self.mean + delta * (b / n),
            ss: self.ss + other.ss + delta * delta * (a * b / n),
        }
    }

    /// No values.
    const NONE: Self = Self {
        count: 0,
        mean: 0.0,
        ss: 0.0,
    };
}

/// Rows per block of [`run_moments`]: a run's moments are its blocks'
/// (each in two passes over rows near the caches) merged in order.
const MOMENT_BLOCK: usize = 1 << 16;

/// A run of one manoeuvre code: the code and its rows.
type Run = (f64, std::ops::Range<usize>);

/// The runs of one code of `codes` over `n` rows; one run (code 0) without
/// codes.
fn runs(codes: Option<&[f64]>, n: usize) -> Vec<Run> {
    let Some(codes) = codes else {
        return vec![(0.0, 0..n)];
    };
    let mut runs = Vec::new();
    let mut start = 0;
    for k in 1..=n {
        if k == n || codes[k] != codes[start] {
            runs.push((codes[start], start..k));
            start = k;
        }
    }
    runs
}

/// Each run's blocks of [`MOMENT_BLOCK`] rows: `(run, rows)`.
fn moment_blocks(runs: &[Run]) -> Vec<(usize, std::ops::Range<usize>)> {
    runs.iter()
        .enumerate()
        .flat_map(|(i, (_, r))| {
            r.clone()
                .step_by(MOMENT_BLOCK)
                .map(move |a| (i, a..(a + MOMENT_BLOCK).min(r.end)))
        })
        .collect()
}

/// The values [`Moments::of_parts`] takes at row `k` of the part series
/// `parts`: each part, the currents' missing values as zero, their sum.
fn values_of(parts: [&[f64]; 4]) -> impl Fn(usize) -> [f64; PARTS] + '_ {
    move |k| {
        let currents = if parts[3][k].is_nan() {
            0.0
        } else {
            parts[3][k]
        };
        [
            parts[0][k],
            parts[1][k],
            parts[2][k],
            currents,
            parts[0][k] + parts[1][k] + parts[2][k] + currents,
        ]
    }
}

/// Each run's moments from its blocks' ([`moment_blocks`]), merged in
/// order ([`Moments::merge`]).
fn merged(
    runs: &[Run],
    blocks: &[(usize, std::ops::Range<usize>)],
    moments: Vec<[Moments; PARTS]>,
) -> Vec<[Moments; PARTS]> {
    let mut out = vec![[Moments::NONE; PARTS]; runs.len()];
    for ((run, _), m) in blocks.iter().zip(moments) {
        for (o, m) in out[*run].iter_mut().zip(m) {
            *o = o.merge(m);
        }
    }
    out
}

/// [`Moments`] of every part over every run: each run's blocks of
/// [`MOMENT_BLOCK`] rows on the cores, merged in order ([`Moments::merge`];
/// the same bits on any number of cores, and a run of one block has its
/// two passes' own). A flight without manoeuvre codes is one run: its
/// moments at 10⁶ rows 8 → 4 ms.
fn run_moments(runs: &[Run], parts: [&[f64]; 4]) -> Vec<[Moments; PARTS]> {
    let rows = parts[0].len();
    let threads = if rows >= 1 << 16 {
        aeromag_core::parallel::threads()
    } else {
        1
    };
    let blocks = moment_blocks(runs);
    let moments = aeromag_core::parallel::parallel_map(blocks.len(), threads, |b| {
        Moments::of_parts(&blocks[b].1, values_of(parts))
    });
    merged(runs, &blocks, moments)
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

    /// All parts in one pass give each part's moments as a pass over that
    /// part alone gives them, bit for bit, with missing values and a run
    /// where a part has none.
    #[test]
    fn moments_of_all_parts_at_once_are_each_parts_own() {
        let n = 3000;
        let wave = |f: f64, every: usize| -> Vec<f64> {
            (0..n)
                .map(|k| {
                    if every > 0 && k % every == 3 {
                        f64::NAN
                    } else {
                        (k as f64 * f).sin() * 17.0 + f
                    }
                })
                .collect()
        };
        let (p0, p1, p2) = (wave(0.1, 0), wave(0.37, 11), wave(1.3, 0));
        let mut p3 = wave(0.05, 7);
        p3[2000..].fill(f64::NAN);
        let runs = [(1.0, 0..1200), (2.0, 1200..2000), (0.0, 2000..n)];
        let moments = run_moments(&runs, [&p0, &p1, &p2, &p3]);
        let zero_if_nan = |x: f64| if x.is_nan() { 0.0 } else { x };
        for (run, (_, r)) in moments.iter().zip(&runs) {
            let series: [Vec<f64>; PARTS] = [
                p0[r.clone()].to_vec(),
                p1[r.clone()].to_vec(),
                p2[r.clone()].to_vec(),
                p3[r.clone()].iter().map(|&x| zero_if_nan(x)).collect(),
                r.clone()
                    .map(|k| p0[k] + p1[k] + p2[k] + zero_if_nan(p3[k]))
                    .collect(),
            ];
            for (m, v) in run.iter().zip(&series) {
                let finite: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
                let mean = finite.iter().sum::<f64>() / finite.len() as f64;
                let ss: f64 = finite.iter().map(|x| (x - mean).powi(2)).sum();
                assert_eq!(m.count, finite.len());
                assert_eq!(m.ss.to_bits(), ss.to_bits());
            }
        }
        // The last run's currents are all missing: counted as zero.
        assert_eq!(moments[2][3].count, n - 2000);
        assert_eq!(moments[2][3].ss, 0.0);
    }

    /// A run longer than a block has its moments from its blocks merged:
    /// the sum of squared deviations within 10⁻¹² of a compensated two-pass
    /// reference, for parts far from zero and near it, with missing values;
    /// a run of one block has the plain two passes' bits.
    #[test]
    fn a_long_runs_blocks_merge_to_its_two_pass_moments() {
        let n = 3 * MOMENT_BLOCK + 1234;
        let part = |f: f64, level: f64| -> Vec<f64> {
            (0..n)
                .map(|k| {
                    if k % 1009 == 5 {
                        f64::NAN
                    } else {
                        level + (k as f64 * f).sin() * 3.0 + k as f64 * 1e-5
                    }
                })
                .collect()
        };
        let (p0, p1, p2) = (part(0.01, 5e4), part(0.1, -20.0), part(0.7, 0.0));
        let p3 = vec![f64::NAN; n];
        let runs = [(0.0, 0..n), (1.0, 0..1000)];
        let moments = run_moments(&runs, [&p0, &p1, &p2, &p3]);
        let two_pass = |v: &[f64]| {
            let f: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
            let mean = f.iter().sum::<f64>() / f.len() as f64;
            (f.len(), f.iter().map(|x| (x - mean).powi(2)).sum::<f64>())
        };
        // The reference: both passes summed with Neumaier's compensation.
        let sum = |v: &mut dyn Iterator<Item = f64>| {
            let (mut s, mut c) = (0.0f64, 0.0f64);
            for x in v {
                let t = s + x;
                c += if s.abs() >= x.abs() {
                    (s - t) + x
                } else {
                    (x - t) + s
                };
                s = t;
            }
            s + c
        };
        for (p, v) in [&p0, &p1, &p2].into_iter().enumerate() {
            let f: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
            let mean = sum(&mut f.iter().copied()) / f.len() as f64;
            let exact = sum(&mut f.iter().map(|x| (x - mean).powi(2)));
            let (count, plain) = two_pass(v);
            let m = moments[0][p];
            assert_eq!(m.count, count);
            // Measured: within 4.3e-13 relative (the plain two passes 1.2e-14;
            // the merges' means are rounded at the values' level, 5e4;
            // without the corrected block means 1.0e-11).
            assert!(
                (m.ss - exact).abs() <= 1e-12 * exact,
                "part {p}: {} vs {exact} (two passes {plain})",
                m.ss
            );
            // One block: the two passes' own bits.
            let (count, ss) = two_pass(&v[..1000]);
            assert_eq!((moments[1][p].count, moments[1][p].ss), (count, ss));
        }
        // Missing currents count as none (zero).
        assert_eq!((moments[0][3].count, moments[0][3].ss), (n, 0.0));
    }

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
