//! Kaiser window (Kaiser & Schafer 1980; Harris 1978, §V-F), equal to
//! SciPy's `windows.kaiser(M, beta, sym)`:
//!
//! ```text
//! w[n] = I0(β √(1 − ((n − α)/α)²)) / I0(β),   α = (M − 1)/2,  n = 0 … M−1
//! ```
//!
//! `I0` is the modified Bessel function of the first kind, order 0,
//! evaluated by its everywhere-convergent power series
//! `I0(x) = Σ_k ((x/2)^k / k!)²` (all terms positive, so the sum is accurate
//! to a few ulp). β trades main-lobe width for sidelobe level (β = 0:
//! rectangular; β ≈ 8.6: close to Blackman).

use super::validate::invalid;
use super::window::{Symmetry, extended_len};
use crate::error::Result;

/// Largest accepted β (the window underflows to a spike long before).
pub const MAX_BETA: f64 = 700.0;

/// Modified Bessel function of the first kind of order 0, `I0(x)`.
pub fn bessel_i0(x: f64) -> f64 {
    let q = 0.25 * x * x;
    let mut term = 1.0;
    let mut sum = 1.0;
    let mut k = 1.0;
    while term > f64::EPSILON * 0.25 * sum {
        term *= q / (k * k);
        sum += term;
        k += 1.0;
    }
    sum
}

/// Kaiser window of `len` samples with shape parameter `beta`.
///
/// Errors (`InvalidArgument`) when `beta` is not finite or outside `0…700`.
pub fn kaiser(len: usize, beta: f64, symmetry: Symmetry) -> Result<Vec<f64>> {
    if !(beta.is_finite() && (0.0..=MAX_BETA).contains(&beta)) {
        return Err(invalid(
            "beta",
            format!("must be finite in 0..={MAX_BETA}, got {beta}"),
        ));
    }
    if len <= 1 {
        return Ok(vec![1.0; len]);
    }
    let m = extended_len(len, symmetry);
    let alpha = (m as f64 - 1.0) / 2.0;
    let norm = bessel_i0(beta);
    Ok((0..len)
        .map(|n| {
            let r = (n as f64 - alpha) / alpha;
            bessel_i0(beta * (1.0 - r * r).sqrt()) / norm
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn i0_known_values() {
        // Abramowitz & Stegun table 9.8 / exact series values
        assert_eq!(bessel_i0(0.0), 1.0);
        assert!((bessel_i0(1.0) - 1.266_065_877_752_008_4).abs() < 1e-15);
        assert!((bessel_i0(5.0) - 27.239_871_823_604_442).abs() < 1e-13);
        assert!((bessel_i0(-2.0) - bessel_i0(2.0)).abs() == 0.0);
    }

    #[test]
    fn beta_zero_is_rectangular() {
        assert_eq!(kaiser(6, 0.0, Symmetry::Symmetric).unwrap(), vec![1.0; 6]);
        assert!(kaiser(6, -1.0, Symmetry::Symmetric).is_err());
        assert!(kaiser(6, f64::NAN, Symmetry::Periodic).is_err());
    }
}
