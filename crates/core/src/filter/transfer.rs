//! Transfer-function (`b`, `a`) filters: one-way filtering and the
//! steady-state initial conditions.
//!
//! ```text
//! H(z) = (b0 + b1 z⁻¹ + … + bM z⁻ᴹ) / (a0 + a1 z⁻¹ + … + aN z⁻ᴺ)
//! ```
//!
//! After normalising by `a0` and padding `b`, `a` with zeros to a common
//! length `n`, the filter runs in transposed direct form II with `n − 1`
//! state values (SciPy's `lfilter`):
//!
//! ```text
//! y[k]    = b0 x[k] + z_0
//! z_i     ← z_{i+1} + b_{i+1} x[k] − a_{i+1} y[k],   i = 0 … n−3
//! z_{n−2} ← b_{n−1} x[k] − a_{n−1} y[k]
//! ```
//!
//! **Steady state** (SciPy's `lfilter_zi`): the state that a unit step input
//! reaches after infinite time solves `zi = A zi + B` with `A` the transposed
//! companion matrix of `a` and `B_i = b_{i+1} − a_{i+1} b0`, i.e.
//! `(I − Aᵀ_companion) zi = B`, solved here by LU with partial pivoting.
//! The zero-phase filters start from `zi · x[0]` to suppress the start-up
//! transient.

use super::validate::{check_finite, check_len, invalid};
use crate::error::Result;
use nalgebra::{DMatrix, DVector};

/// What the zero-phase machinery needs from a linear time-invariant filter.
pub(crate) trait LinearFilter {
    /// SciPy's default pad length for `filtfilt` / `sosfiltfilt`.
    fn padlen(&self) -> usize;
    /// Steady-state state for a unit step, flattened.
    fn steady_state(&self) -> Result<Vec<f64>>;
    /// Filters `x` in place, first to last (last to first when
    /// `reverse`), starting from and updating `state` (layout of
    /// [`LinearFilter::steady_state`]).
    fn run(&self, x: &mut [f64], state: &mut [f64], reverse: bool);
}

/// A rational transfer function `B(z)/A(z)` (SciPy's `b`, `a` arrays).
#[derive(Debug, Clone, PartialEq)]
pub struct TransferFunction {
    b: Vec<f64>,
    a: Vec<f64>,
    /// `b/a0` padded with zeros to the common length.
    bn: Vec<f64>,
    /// `a/a0` padded with zeros to the common length.
    an: Vec<f64>,
}

impl TransferFunction {
    /// Numerator `b` and denominator `a`, highest power of `z⁻¹` last.
    ///
    /// Errors (`InvalidArgument`): empty `b` or `a`, non-finite coefficients,
    /// `a[0] = 0`.
    pub fn new(b: Vec<f64>, a: Vec<f64>) -> Result<Self> {
        if b.is_empty() || a.is_empty() {
            return Err(invalid("b, a", "coefficient arrays must not be empty"));
        }
        if b.iter().chain(&a).any(|c| !c.is_finite()) {
            return Err(invalid("b, a", "coefficients must be finite"));
        }
        if a[0] == 0.0 {
            return Err(invalid("a", "a[0] must be non-zero"));
        }
        let n = a.len().max(b.len());
        let mut bn = vec![0.0; n];
        let mut an = vec![0.0; n];
        for (d, s) in bn.iter_mut().zip(&b) {
            *d = s / a[0];
        }
        for (d, s) in an.iter_mut().zip(&a) {
            *d = s / a[0];
        }
        Ok(TransferFunction { b, a, bn, an })
    }

    /// Numerator coefficients as given.
    pub fn b(&self) -> &[f64] {
        &self.b
    }

    /// Denominator coefficients as given.
    pub fn a(&self) -> &[f64] {
        &self.a
    }

    /// SciPy's default `filtfilt` pad length `3·max(len(a), len(b))`.
    pub fn padlen(&self) -> usize {
        3 * self.bn.len()
    }

    /// Steady-state initial conditions for a unit step (SciPy `lfilter_zi`),
    /// `max(len a, len b) − 1` values.
    ///
    /// Errors (`InvalidArgument`) when `A(1) = 0` (a pole at `z = 1`).
    pub fn zi(&self) -> Result<Vec<f64>> {
        let (b, a) = (&self.bn, &self.an);
        let m = b.len() - 1;
        if m == 0 {
            return Ok(vec![]);
        }
        // I − companion(a)ᵀ: first column 1 + a1, a2, …; superdiagonal −1.
        let mut lhs = DMatrix::<f64>::identity(m, m);
        for i in 0..m {
            lhs[(i, 0)] += a[i + 1];
            if i + 1 < m {
                lhs[(i, i + 1)] -= 1.0;
            }
        }
        let rhs = DVector::from_iterator(m, (0..m).map(|i| b[i + 1] - a[i + 1] * b[0]));
        let zi = lhs
            .lu()
            .solve(&rhs)
            .ok_or_else(|| invalid("a", "A(1) = 0: the filter has no steady state"))?;
        Ok(zi.iter().copied().collect())
    }
}

impl LinearFilter for TransferFunction {
    fn padlen(&self) -> usize {
        TransferFunction::padlen(self)
    }

    fn steady_state(&self) -> Result<Vec<f64>> {
        self.zi()
    }

    fn run(&self, x: &mut [f64], z: &mut [f64], reverse: bool) {
        if reverse {
            self.run_in_order(x.iter_mut().rev(), z)
        } else {
            self.run_in_order(x.iter_mut(), z)
        }
    }
}

impl TransferFunction {
    /// [`LinearFilter::run`] over `samples` in iteration order.
    fn run_in_order<'a>(&self, samples: impl Iterator<Item = &'a mut f64>, z: &mut [f64]) {
        let (b, a) = (&self.bn, &self.an);
        let n = b.len();
        for v in samples {
            let x = *v;
            if n == 1 {
                *v = b[0] * x;
                continue;
            }
            let y = z[0] + b[0] * x;
            for i in 0..n - 2 {
                z[i] = z[i + 1] + x * b[i + 1] - y * a[i + 1];
            }
            z[n - 2] = x * b[n - 1] - y * a[n - 1];
            *v = y;
        }
    }
}

/// Steady-state initial conditions of `B(z)/A(z)` for a unit step, equal to
/// SciPy's `lfilter_zi(b, a)`. Errors as [`TransferFunction::new`] and
/// [`TransferFunction::zi`].
pub fn lfilter_zi(b: &[f64], a: &[f64]) -> Result<Vec<f64>> {
    TransferFunction::new(b.to_vec(), a.to_vec())?.zi()
}

/// One-way (causal) filtering from zero initial state, equal to SciPy's
/// `lfilter(b, a, x)`.
///
/// Errors: `TooShort` for an empty `x`, `NonFinite` naming the first
/// non-finite sample.
pub fn lfilter(tf: &TransferFunction, x: &[f64]) -> Result<Vec<f64>> {
    check_len("x", x.len(), 1)?;
    check_finite("x", x)?;
    let mut y = x.to_vec();
    let mut state = vec![0.0; tf.bn.len() - 1];
    tf.run(&mut y, &mut state, false);
    Ok(y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn difference_equation() {
        // y[n] = 0.5 x[n] + 0.25 x[n−1] + 0.3 y[n−1] − 0.1 y[n−2], scaled by a0 = 2
        let tf = TransferFunction::new(vec![1.0, 0.5], vec![2.0, -0.6, 0.2]).unwrap();
        let x = [1.0, -2.0, 0.5, 3.0, 0.0, 1.0];
        let y = lfilter(&tf, &x).unwrap();
        let mut expect = vec![0.0; x.len()];
        for n in 0..x.len() {
            let xm1 = if n >= 1 { x[n - 1] } else { 0.0 };
            let ym1 = if n >= 1 { expect[n - 1] } else { 0.0 };
            let ym2 = if n >= 2 { expect[n - 2] } else { 0.0 };
            expect[n] = 0.5 * x[n] + 0.25 * xm1 + 0.3 * ym1 - 0.1 * ym2;
        }
        for (u, v) in y.iter().zip(&expect) {
            assert!((u - v).abs() < 1e-15);
        }
    }

    #[test]
    fn zi_gives_constant_step_response() {
        let tf =
            TransferFunction::new(vec![0.1, 0.3, 0.3, 0.1], vec![1.0, -0.5, 0.3, -0.05]).unwrap();
        let mut z = tf.zi().unwrap();
        let dc = 0.8 / (1.0 - 0.5 + 0.3 - 0.05);
        let mut x = vec![1.0; 10];
        tf.run(&mut x, &mut z, false);
        for v in x {
            assert!((v - dc).abs() < 1e-14);
        }
    }

    #[test]
    fn invalid_inputs() {
        assert!(TransferFunction::new(vec![], vec![1.0]).is_err());
        assert!(TransferFunction::new(vec![1.0], vec![0.0, 1.0]).is_err());
        assert!(TransferFunction::new(vec![f64::NAN], vec![1.0]).is_err());
        // pole at z = 1: A(1) = 0
        assert!(lfilter_zi(&[1.0, 0.0], &[1.0, -1.0]).is_err());
        let tf = TransferFunction::new(vec![2.0], vec![4.0]).unwrap();
        assert_eq!(tf.zi().unwrap(), Vec::<f64>::new());
        assert_eq!(lfilter(&tf, &[1.0, 2.0]).unwrap(), vec![0.5, 1.0]);
    }
}
