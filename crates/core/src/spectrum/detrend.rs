//! Removing a constant or a straight line from a segment before its
//! periodogram is taken (SciPy's `signal.detrend`, `type='constant'` /
//! `'linear'`).
//!
//! * constant: `x[n] − x̄`;
//! * linear: `x[n] − (x̄ + b (n − n̄))` with the least-squares slope
//!   `b = Σ (n − n̄)(x[n] − x̄) / Σ (n − n̄)²`, `n̄ = (L − 1)/2`.
//!
//! Without detrending, the mean (or a drift) of a segment leaks through the
//! window's sidelobes into the low-frequency bins of a spectrum.

use serde::{Deserialize, Serialize};

/// What to remove from every segment before windowing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Detrend {
    /// Nothing (SciPy `detrend=False`).
    None,
    /// The segment mean (SciPy `'constant'`, the `welch` default).
    Constant,
    /// The least-squares straight line (SciPy `'linear'`).
    Linear,
}

/// Removes the trend `kind` from `x` in place.
pub fn detrend_in_place(x: &mut [f64], kind: Detrend) {
    let len = x.len();
    if len == 0 || kind == Detrend::None {
        return;
    }
    let mean = x.iter().sum::<f64>() / len as f64;
    match kind {
        Detrend::None => {}
        Detrend::Constant => x.iter_mut().for_each(|v| *v -= mean),
        Detrend::Linear => {
            let centre = (len as f64 - 1.0) / 2.0;
            let (mut sxy, mut sxx) = (0.0, 0.0);
            for (n, v) in x.iter().enumerate() {
                let t = n as f64 - centre;
                sxy += t * (v - mean);
                sxx += t * t;
            }
            let slope = if sxx > 0.0 { sxy / sxx } else { 0.0 };
            for (n, v) in x.iter_mut().enumerate() {
                *v -= mean + slope * (n as f64 - centre);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn removes_lines_exactly() {
        let mut x: Vec<f64> = (0..11).map(|n| 3.0 - 0.25 * n as f64).collect();
        detrend_in_place(&mut x, Detrend::Linear);
        assert!(x.iter().all(|v| v.abs() < 1e-14));
        let mut y = vec![2.0, 4.0, 6.0];
        detrend_in_place(&mut y, Detrend::Constant);
        assert_eq!(y, vec![-2.0, 0.0, 2.0]);
        let mut z = vec![1.0, 5.0];
        detrend_in_place(&mut z, Detrend::None);
        assert_eq!(z, vec![1.0, 5.0]);
        let mut one = vec![7.0];
        detrend_in_place(&mut one, Detrend::Linear);
        assert_eq!(one, vec![0.0]);
    }

    #[test]
    fn linear_residual_is_orthogonal_to_line() {
        let mut x: Vec<f64> = (0..20)
            .map(|n| ((n * n) % 7) as f64 + 0.3 * n as f64)
            .collect();
        detrend_in_place(&mut x, Detrend::Linear);
        let s0: f64 = x.iter().sum();
        let s1: f64 = x.iter().enumerate().map(|(n, v)| n as f64 * v).sum();
        assert!(s0.abs() < 1e-12 && s1.abs() < 1e-11);
    }
}
