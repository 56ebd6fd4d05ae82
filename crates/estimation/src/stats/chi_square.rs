//! The chi-square distribution with an integer number of degrees of freedom.
//!
//! `F(x; k) = P(k/2, x/2)`, the regularised lower incomplete gamma function,
//! summed by its power series
//!
//! ```text
//! P(a, y) = e^{−y} y^a / Γ(a) · Σ_{n≥0} y^n / (a (a+1) … (a+n))
//! ```
//!
//! which converges for every `y` (terms shrink once `n > y`); `ln Γ(a)` is
//! exact for the integer and half-integer `a = k/2` (sums of logarithms).
//! The quantile inverts `F` by bisection to a relative 1e-13. Used by the
//! likelihood-ratio test of the lagged eddy-current terms
//! (`aeromag_compensation::tolles_lawson::lag_select`); checked against
//! SciPy's `chi2.cdf` / `chi2.ppf`.

use crate::error::{EstError, Result};

/// `ln Γ(k/2)` for an integer `k ≥ 1`, exact up to rounding.
fn ln_gamma_half(k: u32) -> f64 {
    if k.is_multiple_of(2) {
        // Γ(m) = (m − 1)!
        (1..k / 2).map(|i| (i as f64).ln()).sum()
    } else {
        // Γ(m + ½) = √π · Π_{i=1..m} (i − ½)
        0.5 * std::f64::consts::PI.ln() + (1..=(k / 2)).map(|i| (i as f64 - 0.5).ln()).sum::<f64>()
    }
}

/// Chi-square distribution function `P(X ≤ x)` with `dof ≥ 1` degrees of
/// freedom. Errors for `dof = 0` or a non-finite `x`.
pub fn chi_square_cdf(x: f64, dof: u32) -> Result<f64> {
    if dof == 0 {
        return Err(EstError::Dimension(
            "chi-square with 0 degrees of freedom".into(),
        ));
    }
    if !x.is_finite() {
        return Err(EstError::NonFinite {
            what: "chi-square argument",
        });
    }
    if x <= 0.0 {
        return Ok(0.0);
    }
    let (a, y) = (dof as f64 / 2.0, x / 2.0);
    let (mut term, mut sum, mut n) = (1.0 / a, 1.0 / a, 0.0);
    while term > sum * 1e-17 && n < 100_000.0 {
        n += 1.0;
        term *= y / (a + n);
        sum += term;
    }
    let p = (a * y.ln() - y - ln_gamma_half(dof) + sum.ln()).exp();
    Ok(p.min(1.0))
}

/// The `p`-quantile (0 < p < 1) of the chi-square distribution with `dof ≥ 1`
/// degrees of freedom: the `x` with `P(X ≤ x) = p`.
pub fn chi_square_quantile(p: f64, dof: u32) -> Result<f64> {
    if !(p > 0.0 && p < 1.0) {
        return Err(EstError::Dimension(format!(
            "probability {p} outside (0, 1)"
        )));
    }
    let k = dof as f64;
    let (mut lo, mut hi) = (0.0, k.max(1.0));
    while chi_square_cdf(hi, dof)? < p {
        lo = hi;
        hi *= 2.0;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if chi_square_cdf(mid, dof)? < p {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-13 * hi {
            break;
        }
    }
    Ok(0.5 * (lo + hi))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// SciPy 1.17 `scipy.stats.chi2.ppf(p, k)` and `chi2.cdf(x, k)`.
    #[test]
    fn matches_scipy() {
        for (k, p, x) in [
            (9, 1.0 - 0.01 / 9.0, 27.602611945680085),
            (9, 0.999, 27.877164871256568),
            (18, 1.0 - 0.01 / 9.0, 41.985360769764455),
            (1, 0.95, 3.841458820694124),
            (9, 0.95, 16.918977604620448),
        ] {
            let q = chi_square_quantile(p, k).unwrap();
            assert!((q - x).abs() < 1e-10 * x, "k {k} p {p}: {q} vs {x}");
            assert!(
                (chi_square_cdf(x, k).unwrap() - p).abs() < 1e-12,
                "cdf k {k}"
            );
        }
    }

    #[test]
    fn limits_and_errors() {
        assert_eq!(chi_square_cdf(0.0, 3).unwrap(), 0.0);
        assert!((chi_square_cdf(1e4, 9).unwrap() - 1.0).abs() < 1e-15);
        // k = 2 is the exponential distribution: F = 1 − e^{−x/2}.
        for x in [0.1, 1.0, 7.5, 30.0] {
            assert!((chi_square_cdf(x, 2).unwrap() - (1.0 - (-x / 2.0_f64).exp())).abs() < 1e-14);
        }
        assert!(chi_square_cdf(1.0, 0).is_err());
        assert!(chi_square_cdf(f64::NAN, 3).is_err());
        assert!(chi_square_quantile(1.0, 3).is_err());
        assert!(chi_square_quantile(0.0, 3).is_err());
    }
}
