//! Parsers of option values shared by several commands (clap value
//! parsers: a bad value is a usage error, exit code 2, naming the flag),
//! and the flag groups several commands flatten into theirs.

use std::fmt;
use std::str::FromStr;

/// `n` comma-separated finite numbers.
pub fn numbers(s: &str, n: usize) -> Result<Vec<f64>, String> {
    let bad = || format!("expected {n} comma-separated finite numbers");
    let v: Vec<f64> = s
        .split(',')
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad())?;
    if v.len() != n || v.iter().any(|x| !x.is_finite()) {
        return Err(bad());
    }
    Ok(v)
}

/// Three numbers `X,Y,Z` (a position or vector, m, body frame).
pub fn xyz(s: &str) -> Result<[f64; 3], String> {
    let v = numbers(s, 3)?;
    Ok([v[0], v[1], v[2]])
}

/// Two numbers `A,B`.
pub fn pair(s: &str) -> Result<[f64; 2], String> {
    let v = numbers(s, 2)?;
    Ok([v[0], v[1]])
}

/// A `YYYY-MM-DD` date as a decimal year.
pub fn decimal_year(s: &str) -> Result<f64, String> {
    aeromag::core::time::Date::parse(s)
        .map(|d| d.decimal_year())
        .map_err(|e| e.to_string())
}

/// The minimum-curvature flags of `grid` and `microlevel` (which grids
/// the column it corrects): GMT `surface`'s `-T`, `-N` and `-C`.
#[derive(Debug, Clone, clap::Args)]
pub struct MinCurvatureArgs {
    /// Tension, 0 (minimum curvature) to 1 (harmonic).
    #[arg(long, default_value_t = 0.25)]
    pub tension: f64,
    /// Most sweeps of each of minimum curvature's relaxations on the final
    /// grid (two: between the coarser grid's nodes, then with the data),
    /// 1 to 100000 (GMT `surface -N`; the coarser grids before it get
    /// more in proportion to their spacing). A solve stopped by it is
    /// warned of, with how far the grid may be from the converged one.
    #[arg(long, value_name = "N", default_value_t = 500)]
    pub max_sweeps: usize,
    /// Convergence limit of minimum curvature: the largest change of a
    /// sweep, in the column's unit (GMT `surface -C`; default 10⁻⁴ × the
    /// data's RMS about their plane).
    #[arg(long, value_name = "NT", value_parser = positive)]
    pub convergence: Option<f64>,
}

impl MinCurvatureArgs {
    /// The library's settings (checked there: tension 0–1, sweeps 1 to
    /// 100 000).
    pub fn settings(&self) -> aeromag::grid::gridding::MinCurvature {
        aeromag::grid::gridding::MinCurvature {
            tension: self.tension,
            max_iterations: self.max_sweeps,
            convergence: self.convergence,
            ..Default::default()
        }
    }
}

/// A finite number ≥ 0.
pub fn non_negative(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err("must be a finite number ≥ 0".into()),
    }
}

/// A finite number > 0.
pub fn positive(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err("must be a finite number > 0".into()),
    }
}

/// A pass band `LO,HI` in Hz, or `none`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Band(pub Option<(f64, f64)>);

impl FromStr for Band {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        if s.trim().eq_ignore_ascii_case("none") {
            return Ok(Band(None));
        }
        let [lo, hi] = pair(s)?;
        if !(lo > 0.0 && hi > lo) {
            return Err(format!("need 0 < LO < HI, got {lo},{hi}"));
        }
        Ok(Band(Some((lo, hi))))
    }
}

impl fmt::Display for Band {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            Some((lo, hi)) => write!(f, "{lo},{hi}"),
            None => f.write_str("none"),
        }
    }
}

/// A UTM zone: `37N`, `56S`, `EPSG:32637` or `32737`.
pub fn utm_zone(s: &str) -> Result<aeromag::grid::projection::UtmZone, String> {
    aeromag::grid::projection::UtmZone::parse(s).map_err(|e| e.to_string())
}

/// Two column names `EASTING,NORTHING` of projected positions (m).
pub fn projected_columns(s: &str) -> Result<aeromag::map::ProjectedColumns, String> {
    match s.split(',').map(str::trim).collect::<Vec<_>>()[..] {
        [e, n] if !e.is_empty() && !n.is_empty() && e != n => {
            Ok(aeromag::map::ProjectedColumns::new(e, n))
        }
        _ => Err("expected two different column names EASTING,NORTHING, e.g. `X,Y`".into()),
    }
}

/// A value parser from a library type's `FromStr` whose error is
/// [`aeromag::Error`].
pub fn parsed<T: FromStr<Err = aeromag::Error>>(s: &str) -> Result<T, String> {
    s.parse().map_err(|e: aeromag::Error| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_and_bands() {
        assert_eq!(numbers("1, 2,3", 3).unwrap(), vec![1.0, 2.0, 3.0]);
        assert!(numbers("1,2", 3).is_err());
        assert!(numbers("1,nan,2", 3).is_err());
        assert_eq!("0.1,0.9".parse::<Band>().unwrap(), Band(Some((0.1, 0.9))));
        assert_eq!("none".parse::<Band>().unwrap(), Band(None));
        assert!("0.9,0.1".parse::<Band>().is_err());
        assert_eq!(Band(Some((0.1, 0.9))).to_string(), "0.1,0.9");
    }
}
