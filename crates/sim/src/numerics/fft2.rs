//! 2-D FFT of a real grid: real-to-complex along rows, complex along columns.
//!
//! A real grid of `n0` rows × `n1` columns (row-major, row index = north,
//! column index = east) has the half spectrum `F(k0, k1)`, `k0 = 0…n0−1`,
//! `k1 = 0…n1/2`, stored column-major in `k1` (`h1 = n1/2 + 1` blocks of
//! `n0` contiguous values) so that every column transform works on
//! contiguous memory. Forward transforms are unnormalised; the inverse
//! divides by `n0·n1`, so `inverse(forward(x)) = x`.
//!
//! A spectral multiplier `H(k)` gives a real result only if it is Hermitian,
//! `H(−k) = conj H(k)`; odd multipliers such as `i k_x` are not at a Nyquist
//! index, where callers must set them to zero. The imaginary parts of the
//! `k1 = 0` and `k1 = n1/2` rows are cleared before the real inverse.

use std::sync::Arc;

use realfft::num_complex::Complex;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};
use rustfft::{Fft, FftPlanner};

use crate::error::{Result, SimError};

/// Planned 2-D real FFT for one grid shape.
pub struct RealFft2 {
    n0: usize,
    n1: usize,
    row_fwd: Arc<dyn RealToComplex<f64>>,
    row_inv: Arc<dyn ComplexToReal<f64>>,
    col_fwd: Arc<dyn Fft<f64>>,
    col_inv: Arc<dyn Fft<f64>>,
}

impl std::fmt::Debug for RealFft2 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "RealFft2 {{ n0: {}, n1: {} }}", self.n0, self.n1)
    }
}

fn numerics(e: impl std::fmt::Display) -> SimError {
    SimError::Numerics(e.to_string())
}

impl RealFft2 {
    /// Plans for an `n0 × n1` grid (both ≥ 2).
    pub fn new(n0: usize, n1: usize) -> Result<Self> {
        if n0 < 2 || n1 < 2 {
            return Err(SimError::Numerics(format!(
                "grid {n0}×{n1} is too small for a 2-D FFT"
            )));
        }
        let mut rp = RealFftPlanner::<f64>::new();
        let mut cp = FftPlanner::<f64>::new();
        Ok(Self {
            n0,
            n1,
            row_fwd: rp.plan_fft_forward(n1),
            row_inv: rp.plan_fft_inverse(n1),
            col_fwd: cp.plan_fft_forward(n0),
            col_inv: cp.plan_fft_inverse(n0),
        })
    }

    /// Number of rows `n0`.
    pub fn n0(&self) -> usize {
        self.n0
    }

    /// Number of columns `n1`.
    pub fn n1(&self) -> usize {
        self.n1
    }

    /// Number of half-spectrum columns `h1 = n1/2 + 1`.
    pub fn h1(&self) -> usize {
        self.n1 / 2 + 1
    }

    /// Half spectrum (layout in the module docs) of a real row-major grid.
    pub fn forward(&self, grid: &[f64]) -> Result<Vec<Complex<f64>>> {
        let (n0, n1, h1) = (self.n0, self.n1, self.h1());
        if grid.len() != n0 * n1 {
            return Err(SimError::Numerics(format!(
                "grid has {} values, expected {}",
                grid.len(),
                n0 * n1
            )));
        }
        let mut row_in = vec![0.0; n1];
        let mut row_out = vec![Complex::new(0.0, 0.0); h1];
        let mut scratch = self.row_fwd.make_scratch_vec();
        let mut spec = vec![Complex::new(0.0, 0.0); h1 * n0];
        for r in 0..n0 {
            row_in.copy_from_slice(&grid[r * n1..(r + 1) * n1]);
            self.row_fwd
                .process_with_scratch(&mut row_in, &mut row_out, &mut scratch)
                .map_err(numerics)?;
            for (c, v) in row_out.iter().enumerate() {
                spec[c * n0 + r] = *v;
            }
        }
        self.col_fwd.process(&mut spec);
        Ok(spec)
    }

    /// Real grid (row-major) of a half spectrum; normalised so that
    /// `inverse(forward(x)) = x`. The spectrum is used as scratch space.
    pub fn inverse(&self, spec: &mut [Complex<f64>]) -> Result<Vec<f64>> {
        let (n0, n1, h1) = (self.n0, self.n1, self.h1());
        if spec.len() != n0 * h1 {
            return Err(SimError::Numerics(format!(
                "spectrum has {} values, expected {}",
                spec.len(),
                n0 * h1
            )));
        }
        self.col_inv.process(spec);
        let norm = 1.0 / (n0 * n1) as f64;
        let mut row_in = vec![Complex::new(0.0, 0.0); h1];
        let mut row_out = vec![0.0; n1];
        let mut scratch = self.row_inv.make_scratch_vec();
        let mut grid = vec![0.0; n0 * n1];
        for r in 0..n0 {
            for (c, v) in row_in.iter_mut().enumerate() {
                *v = spec[c * n0 + r];
            }
            row_in[0].im = 0.0;
            if n1.is_multiple_of(2) {
                row_in[h1 - 1].im = 0.0;
            }
            self.row_inv
                .process_with_scratch(&mut row_in, &mut row_out, &mut scratch)
                .map_err(numerics)?;
            for (g, v) in grid[r * n1..(r + 1) * n1].iter_mut().zip(&row_out) {
                *g = v * norm;
            }
        }
        Ok(grid)
    }
}

/// Signed integer frequency of FFT index `i` of length `n`
/// (`0, 1, …, ⌈n/2⌉−1, −⌊n/2⌋, …, −1`) and whether it is the Nyquist index.
#[inline]
pub fn signed_index(i: usize, n: usize) -> (f64, bool) {
    let nyq = n.is_multiple_of(2) && i == n / 2;
    let s = if i <= n / 2 {
        i as f64
    } else {
        i as f64 - n as f64
    };
    (s, nyq)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_a_single_mode() {
        let (n0, n1) = (6, 10);
        let f = RealFft2::new(n0, n1).unwrap();
        let g: Vec<f64> = (0..n0 * n1).map(|i| ((i * 37 % 11) as f64).sin()).collect();
        let mut s = f.forward(&g).unwrap();
        let back = f.inverse(&mut s).unwrap();
        for (a, b) in g.iter().zip(&back) {
            assert!((a - b).abs() < 1e-13);
        }
        // cos(2π(2 r/n0 + 3 c/n1)) has energy only at (k0, k1) = (2, 3).
        let m: Vec<f64> = (0..n0 * n1)
            .map(|i| {
                let (r, c) = ((i / n1) as f64, (i % n1) as f64);
                (std::f64::consts::TAU * (2.0 * r / n0 as f64 + 3.0 * c / n1 as f64)).cos()
            })
            .collect();
        let s = f.forward(&m).unwrap();
        for c in 0..f.h1() {
            for r in 0..n0 {
                let v = s[c * n0 + r].norm();
                let expect = if (r, c) == (2, 3) {
                    (n0 * n1) as f64 / 2.0
                } else {
                    0.0
                };
                assert!((v - expect).abs() < 1e-10, "({r},{c}) {v}");
            }
        }
    }
}
