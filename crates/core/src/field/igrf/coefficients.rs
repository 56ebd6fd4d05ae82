//! The IGRF-14 coefficient file (IAGA `.shc` format) and the time
//! interpolation of its Gauss coefficients.
//!
//! ## The `.shc` format
//!
//! Lines starting with `#` are comments. The first other line holds
//! `N_MIN N_MAX N_TIMES SPLINE_ORDER N_STEPS [START END]`; the second the
//! `N_TIMES` epochs in decimal years; every further line `n m c(t_1) … c(t_N)`
//! with `c = g_n^m` for `m ≥ 0` and `c = h_n^|m|` for `m < 0`, in nT
//! (Schmidt semi-normalised). IGRF-14 (IAGA V-MOD, released November 2024;
//! <https://doi.org/10.5281/zenodo.14012302>) has 27 epochs 1900.0, 1905.0, …,
//! 2030.0 and degree 13. The 2030.0 column is the 2025.0 main field plus five
//! years of the predictive secular variation, so linear interpolation between
//! 2025.0 and 2030.0 *is* the IGRF secular-variation extrapolation. Models
//! before 2000.0 stop at degree 10 (their degree 11–13 entries are zero).
//!
//! ## Time interpolation (ppigrf convention)
//!
//! Coefficients are linear in time between consecutive epochs `t_i ≤ t ≤ t_{i+1}`:
//!
//! ```text
//! c(t) = c_i + w (c_{i+1} − c_i),   w = (D(t) − D(t_i)) / (D(t_{i+1}) − D(t_i))
//! ```
//!
//! where `D` counts elapsed **days** (proleptic Gregorian calendar) and a
//! decimal year `y` denotes the instant `floor(y)-01-01 + (y − floor(y))·L`
//! days, `L` = 365 or 366 the length of that year (the convention of
//! [`Date::decimal_year`]). This is what `ppigrf` does (pandas
//! `interpolate(method = "time")` on a datetime index). The IAGA Fortran
//! program interpolates linearly in decimal years instead; the two differ by
//! at most ~0.5 day of secular variation, i.e. ≲ 0.2 nT.

use crate::error::{CoreError, Result};
use crate::time::Date;
use std::sync::OnceLock;

/// Highest spherical-harmonic degree of IGRF-14.
pub const MAX_DEGREE: usize = 13;

/// Number of `(n, m)` slots, `0 ≤ m ≤ n ≤ 13`, in the triangular layout.
pub(crate) const N_COEF: usize = (MAX_DEGREE + 1) * (MAX_DEGREE + 2) / 2;

/// Position of `(n, m)` in the triangular layout `n(n+1)/2 + m`.
#[inline]
pub(crate) const fn index(n: usize, m: usize) -> usize {
    n * (n + 1) / 2 + m
}

/// Schmidt semi-normalised Gauss coefficients `g_n^m`, `h_n^m` (nT) at one
/// instant, in the triangular layout of [`index`] (`h_n^0 = 0`, `n = 0` unused).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct GaussCoefficients {
    pub g: [f64; N_COEF],
    pub h: [f64; N_COEF],
}

impl GaussCoefficients {
    fn zero() -> Self {
        Self {
            g: [0.0; N_COEF],
            h: [0.0; N_COEF],
        }
    }
}

/// A parsed `.shc` file: epochs and the coefficients at each epoch.
#[derive(Debug, Clone)]
pub(crate) struct ShcModel {
    /// Highest degree in the file.
    pub max_degree: usize,
    /// Epochs, decimal years, strictly increasing.
    pub epochs: Vec<f64>,
    /// Epochs on the day axis `D` (days since 1900-01-01).
    epoch_days: Vec<f64>,
    /// Coefficients at each epoch.
    coeffs: Vec<GaussCoefficients>,
}

/// The embedded IGRF-14 coefficient file (copied from the `ppigrf` 2.1.0
/// PyPI package, identical to the IAGA distribution).
static IGRF14_SHC: &str = include_str!("../../../data/IGRF14.shc");

/// The IGRF-14 model, parsed on first use.
pub(crate) fn igrf14() -> Result<&'static ShcModel> {
    static MODEL: OnceLock<Result<ShcModel>> = OnceLock::new();
    MODEL
        .get_or_init(|| parse_shc(IGRF14_SHC))
        .as_ref()
        .map_err(Clone::clone)
}

/// Days since 1900-01-01 00:00 of the instant with decimal year `y`
/// (see the module documentation). Exact for midnights (integer result).
pub(crate) fn days_since_1900(y: f64) -> f64 {
    let year = y.floor();
    // Callers pass validated years (1900–2030 for IGRF); the cast is exact.
    let yi = year as i32;
    let year_length = |yr: i32| {
        Date {
            year: yr,
            month: 12,
            day: 31,
        }
        .day_of_year() as f64
    };
    let whole: f64 = if yi >= 1900 {
        (1900..yi).map(year_length).sum()
    } else {
        -(yi..1900).map(year_length).sum::<f64>()
    };
    whole + (y - year) * year_length(yi)
}

fn parse_err(reason: String) -> CoreError {
    CoreError::Parse {
        what: "IGRF .shc coefficient file",
        reason,
    }
}

fn parse_numbers<T: std::str::FromStr>(line: &str, line_no: usize) -> Result<Vec<T>> {
    line.split_whitespace()
        .map(|tok| {
            tok.parse::<T>()
                .map_err(|_| parse_err(format!("line {line_no}: `{tok}` is not a valid number")))
        })
        .collect()
}

/// Parse an `.shc` file (format in the module documentation).
pub(crate) fn parse_shc(text: &str) -> Result<ShcModel> {
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));

    let (no, header) = lines
        .next()
        .ok_or_else(|| parse_err("no header line".into()))?;
    let head: Vec<f64> = parse_numbers(header, no)?;
    if head.len() < 5 || head[..5].iter().any(|v| v.fract() != 0.0 || *v < 0.0) {
        return Err(parse_err(format!(
            "line {no}: header must start with five non-negative integers N_MIN N_MAX N_TIMES ORDER STEPS"
        )));
    }
    let (n_min, n_max, n_times) = (head[0] as usize, head[1] as usize, head[2] as usize);
    if n_min != 1 || !(1..=MAX_DEGREE).contains(&n_max) {
        return Err(parse_err(format!(
            "line {no}: degrees {n_min}–{n_max} unsupported (need N_MIN = 1, 1 ≤ N_MAX ≤ {MAX_DEGREE})"
        )));
    }
    if n_times < 2 {
        return Err(parse_err(format!(
            "line {no}: need at least 2 epochs, got {n_times}"
        )));
    }

    let (no, epoch_line) = lines
        .next()
        .ok_or_else(|| parse_err("no epoch line".into()))?;
    let epochs: Vec<f64> = parse_numbers(epoch_line, no)?;
    if epochs.len() != n_times {
        return Err(parse_err(format!(
            "line {no}: {} epochs listed, header says {n_times}",
            epochs.len()
        )));
    }
    if epochs.iter().any(|e| !e.is_finite() || e.abs() > 1.0e4)
        || epochs.windows(2).any(|w| w[1] <= w[0])
    {
        return Err(parse_err(format!(
            "line {no}: epochs must be finite and strictly increasing"
        )));
    }

    let mut coeffs = vec![GaussCoefficients::zero(); n_times];
    let mut seen_g = [false; N_COEF];
    let mut seen_h = [false; N_COEF];
    for (no, line) in lines {
        let vals: Vec<f64> = parse_numbers(line, no)?;
        if vals.len() != n_times + 2 {
            return Err(parse_err(format!(
                "line {no}: expected n, m and {n_times} coefficients, found {} numbers",
                vals.len()
            )));
        }
        let (n, m) = (vals[0], vals[1]);
        if n.fract() != 0.0 || m.fract() != 0.0 || n < 1.0 || n > n_max as f64 || m.abs() > n {
            return Err(parse_err(format!(
                "line {no}: invalid degree/order ({n}, {m})"
            )));
        }
        let k = index(n as usize, m.abs() as usize);
        let seen = if m >= 0.0 {
            &mut seen_g[k]
        } else {
            &mut seen_h[k]
        };
        if *seen {
            return Err(parse_err(format!(
                "line {no}: duplicate coefficient ({n}, {m})"
            )));
        }
        *seen = true;
        for (c, &v) in coeffs.iter_mut().zip(&vals[2..]) {
            if !v.is_finite() {
                return Err(parse_err(format!("line {no}: non-finite coefficient")));
            }
            if m >= 0.0 {
                c.g[k] = v;
            } else {
                c.h[k] = v;
            }
        }
    }
    for n in 1..=n_max {
        for m in 0..=n {
            let k = index(n, m);
            if !seen_g[k] || (m > 0 && !seen_h[k]) {
                return Err(parse_err(format!(
                    "coefficient of degree {n}, order {m} is missing"
                )));
            }
        }
    }
    let epoch_days = epochs.iter().map(|&e| days_since_1900(e)).collect();
    Ok(ShcModel {
        max_degree: n_max,
        epochs,
        epoch_days,
        coeffs,
    })
}

impl ShcModel {
    /// First epoch, decimal year.
    pub fn first_year(&self) -> f64 {
        self.epochs[0]
    }

    /// Last epoch, decimal year.
    pub fn last_year(&self) -> f64 {
        self.epochs[self.epochs.len() - 1]
    }

    /// Coefficients at decimal year `y`, linear in elapsed days between the
    /// bracketing epochs (module documentation). `DateOutOfRange` outside
    /// `[first epoch, last epoch]` or for a non-finite `y`.
    pub fn at(&self, y: f64) -> Result<GaussCoefficients> {
        let (first, last) = (self.first_year(), self.last_year());
        if !(first..=last).contains(&y) {
            return Err(CoreError::DateOutOfRange {
                year: y,
                first,
                last,
            });
        }
        let t = days_since_1900(y);
        // Index of the interval [t_i, t_{i+1}] holding t (the last one at t = last).
        let i = self.epoch_days[1..self.epoch_days.len() - 1].partition_point(|&d| d <= t);
        let (d0, d1) = (self.epoch_days[i], self.epoch_days[i + 1]);
        let w = ((t - d0) / (d1 - d0)).clamp(0.0, 1.0);
        let (c0, c1) = (&self.coeffs[i], &self.coeffs[i + 1]);
        let mut out = GaussCoefficients::zero();
        for k in 0..N_COEF {
            out.g[k] = c0.g[k] + w * (c1.g[k] - c0.g[k]);
            out.h[k] = c0.h[k] + w * (c1.h[k] - c0.h[k]);
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn embedded_file_parses() {
        let m = igrf14().expect("embedded IGRF-14 parses");
        assert_eq!(m.max_degree, 13);
        assert_eq!(m.epochs.len(), 27);
        assert_eq!(m.first_year(), 1900.0);
        assert_eq!(m.last_year(), 2030.0);
        // DGRF 2020 g_1^0, g_1^1, h_1^1 (IGRF-14 table; IGRF-13 had -29404.8 as
        // the provisional IGRF 2020 value).
        let c = m.at(2020.0).unwrap();
        assert_eq!(c.g[index(1, 0)], -29403.41);
        assert_eq!(c.g[index(1, 1)], -1451.37);
        assert_eq!(c.h[index(1, 1)], 4653.35);
        // IGRF 2025 and its predictive secular variation (g10 +12.6, g11 +10.0,
        // h11 −21.5 nT/yr) encoded in the 2030 column.
        let c25 = m.at(2025.0).unwrap();
        let c30 = m.at(2030.0).unwrap();
        assert_eq!(c25.g[index(1, 0)], -29350.0);
        assert!(((c30.g[index(1, 0)] - c25.g[index(1, 0)]) / 5.0 - 12.6).abs() < 1e-9);
        assert!(((c30.g[index(1, 1)] - c25.g[index(1, 1)]) / 5.0 - 10.0).abs() < 1e-9);
        assert!(((c30.h[index(1, 1)] - c25.h[index(1, 1)]) / 5.0 + 21.5).abs() < 1e-9);
        // Models before 2000 stop at degree 10; h_n^0 is zero everywhere.
        let c95 = m.at(1995.0).unwrap();
        assert!((11..=13).all(|n| (0..=n).all(|k| c95.g[index(n, k)] == 0.0)));
        assert!(c.g[index(13, 13)] != 0.0 || c.h[index(13, 13)] != 0.0);
        assert!((1..=13).all(|n| c.h[index(n, 0)] == 0.0));
    }

    #[test]
    fn day_axis() {
        assert_eq!(days_since_1900(1900.0), 0.0);
        assert_eq!(days_since_1900(1901.0), 365.0);
        // 1900 is not a leap year, 1904 is: 1900–1905 has 1826 days.
        assert_eq!(days_since_1900(1905.0), 1826.0);
        assert_eq!(days_since_1900(2000.0), 36524.0);
        // 2020-07-02 is day 184 of a leap year.
        let d = Date::parse("2020-07-02").unwrap().decimal_year();
        assert!((days_since_1900(d) - (days_since_1900(2020.0) + 183.0)).abs() < 1e-9);
        assert_eq!(days_since_1900(1899.0), -365.0);
    }

    #[test]
    fn interpolation_is_linear_in_days() {
        let m = igrf14().unwrap();
        // 2021-07-02: 548 days after 2020-01-01; 2020–2025 spans 1827 days.
        let y = Date::parse("2021-07-02").unwrap().decimal_year();
        let c = m.at(y).unwrap();
        let (a, b) = (m.at(2020.0).unwrap(), m.at(2025.0).unwrap());
        let w = 548.0 / 1827.0;
        let k = index(1, 0);
        assert!((c.g[k] - (a.g[k] + w * (b.g[k] - a.g[k]))).abs() < 1e-9);
    }

    #[test]
    fn out_of_range_and_nan_dates() {
        let m = igrf14().unwrap();
        for y in [1899.999, 2030.0001, f64::NAN, f64::INFINITY, -1.0e9] {
            assert!(
                matches!(m.at(y), Err(CoreError::DateOutOfRange { .. })),
                "{y}"
            );
        }
        assert!(m.at(1900.0).is_ok() && m.at(2030.0).is_ok());
    }

    #[test]
    fn malformed_files_are_rejected() {
        let good = "# c\n1 1 2 2 1\n2000.0 2005.0\n1 0 -1 -2\n1 1 3 4\n1 -1 5 6\n";
        let m = parse_shc(good).unwrap();
        assert_eq!(m.at(2005.0).unwrap().h[index(1, 1)], 6.0);
        let bad = [
            "",
            "1 1 2 2\n2000 2005\n",
            "1 1 2 2 1\n2000.0\n1 0 1 2\n1 1 3 4\n1 -1 5 6\n",
            "1 1 2 2 1\n2005.0 2000.0\n1 0 1 2\n1 1 3 4\n1 -1 5 6\n",
            "1 1 2 2 1\n2000.0 2005.0\n1 0 1 2\n1 1 3 4\n",
            "1 1 2 2 1\n2000.0 2005.0\n1 0 1 2\n1 1 3 4\n1 -1 5 6\n1 -1 5 6\n",
            "1 1 2 2 1\n2000.0 2005.0\n1 0 1 x\n1 1 3 4\n1 -1 5 6\n",
            "1 1 2 2 1\n2000.0 2005.0\n1 0 1\n1 1 3 4\n1 -1 5 6\n",
            "1 1 2 2 1\n2000.0 2005.0\n1 2 1 2\n1 1 3 4\n1 -1 5 6\n",
            "1 14 2 2 1\n2000.0 2005.0\n",
            "1 1 2 2 1\n2000.0 2005.0\n1 0 1 NaN\n1 1 3 4\n1 -1 5 6\n",
        ];
        for b in bad {
            assert!(
                matches!(parse_shc(b), Err(CoreError::Parse { .. })),
                "{b:?}"
            );
        }
    }
}
