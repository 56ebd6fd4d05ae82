//! One backward step of the Rauch–Tung–Striebel smoother in square-root
//! form.
//!
//! With the filtered estimate `(x_k, P_k = S_k S_kᵀ)`, the transition to the
//! next step `(Φ, G)` (`Q = G Gᵀ`), the predicted `(x⁻_{k+1} = Φ x_k,
//! P⁻_{k+1} = S⁻ S⁻ᵀ)` and the smoothed `(x^s_{k+1}, S^s_{k+1})`:
//!
//! ```text
//! C   = P_k Φᵀ (P⁻_{k+1})⁻¹                         smoother gain
//! x^s_k = x_k + C (x^s_{k+1} − x⁻_{k+1})
//! S^s_k = tri([C G,  C S^s_{k+1},  (I − CΦ) S_k])
//! ```
//!
//! The gain needs no inverse: `Cᵀ = S⁻⁻ᵀ S⁻⁻¹ (Φ S_k S_kᵀ)`, two triangular
//! solves with the predicted factor. The factor update is the square-root
//! form of the Joseph-like identity
//!
//! ```text
//! P^s_k = (I − CΦ) P_k (I − CΦ)ᵀ + C Q Cᵀ + C P^s_{k+1} Cᵀ
//!       = P_k + C (P^s_{k+1} − P⁻_{k+1}) Cᵀ
//! ```
//!
//! (expand and use `C P⁻_{k+1} = P_k Φᵀ`), a sum of three positive
//! semi-definite terms, so the smoothed covariance stays symmetric positive
//! semi-definite whatever the round-off, unlike the textbook difference
//! form. It is re-triangularised by [`super::triangularize`]. References:
//! Rauch, Tung & Striebel (1965); P. Park & T. Kailath, "New square-root
//! smoothing algorithms", *IEEE TAC* 41 (1996) 727–732; Grewal & Andrews
//! (2015) §6.4.

use super::triangularize::triangularize_upper;
use crate::error::{EstError, Result};
use nalgebra::DMatrix;

/// Workspace for square-root RTS steps of dimension `n` (no allocation per
/// step once the largest noise dimension has been seen).
#[derive(Debug, Clone)]
pub struct SqrtRts {
    n: usize,
    a: Vec<f64>,
    b: Vec<f64>,
    d: Vec<f64>,
    wide: Vec<f64>,
    v: Vec<f64>,
}

impl SqrtRts {
    /// Workspace for `n` states.
    pub fn new(n: usize) -> Self {
        Self {
            n,
            a: vec![0.0; n * n],
            b: vec![0.0; n * n],
            d: vec![0.0; n * n],
            wide: vec![0.0; n * 3 * n.max(1)],
            v: vec![0.0; 3 * n.max(1)],
        }
    }

    /// The smoother gain `C = P_k Φᵀ (P⁻_{k+1})⁻¹` into `c` (`n × n`) from the
    /// filtered factor `s_f`, `Φ` and the predicted factor `s_p` (both upper
    /// triangular). Error if `s_p` is singular (a zero diagonal entry).
    pub fn gain(
        &mut self,
        s_f: &DMatrix<f64>,
        phi: &DMatrix<f64>,
        s_p: &DMatrix<f64>,
        c: &mut DMatrix<f64>,
    ) -> Result<()> {
        let n = self.n;
        check(n, &[s_f, phi, s_p, c])?;
        let (sf, ph, sp) = (s_f.as_slice(), phi.as_slice(), s_p.as_slice());
        for i in 0..n {
            let dii = sp[i + i * n];
            if dii == 0.0 || !dii.is_finite() {
                return Err(EstError::Singular(format!(
                    "predicted covariance factor has diagonal {dii} at state {i}"
                )));
            }
        }
        // The same code, specialised by the compiler for the field models of
        // orders 3, 4 and 6 (5, 6 and 8 states).
        let (a, b, d, c) = (&mut self.a, &mut self.b, &mut self.d, c.as_mut_slice());
        match n {
            5 => gain_impl(5, sf, ph, sp, a, b, d, c),
            6 => gain_impl(6, sf, ph, sp, a, b, d, c),
            8 => gain_impl(8, sf, ph, sp, a, b, d, c),
            _ => gain_impl(n, sf, ph, sp, a, b, d, c),
        }
        Ok(())
    }

    /// The smoothed mean `x_f + C (x_s_next − x_p)` into `out`.
    pub fn mean(
        &self,
        x_f: &[f64],
        c: &DMatrix<f64>,
        x_s_next: &[f64],
        x_p: &[f64],
        out: &mut [f64],
    ) {
        let n = self.n;
        let cs = c.as_slice();
        out[..n].copy_from_slice(&x_f[..n]);
        for j in 0..n {
            let dj = x_s_next[j] - x_p[j];
            for (o, cij) in out[..n].iter_mut().zip(&cs[j * n..(j + 1) * n]) {
                *o += cij * dj;
            }
        }
    }

    /// The smoothed factor `tri([C G, C S^s_{k+1}, (I − CΦ) S_f])` into
    /// `out` (`n × n`, upper triangular).
    #[allow(clippy::too_many_arguments)]
    pub fn factor(
        &mut self,
        s_f: &DMatrix<f64>,
        c: &DMatrix<f64>,
        phi: &DMatrix<f64>,
        g: &DMatrix<f64>,
        s_s_next: &DMatrix<f64>,
        out: &mut DMatrix<f64>,
    ) -> Result<()> {
        let n = self.n;
        check(n, &[s_f, c, phi, s_s_next, out])?;
        if g.nrows() != n {
            return Err(EstError::Dimension(format!(
                "noise factor has {} rows for {n} states",
                g.nrows()
            )));
        }
        let q = g.ncols();
        let cols = q + 2 * n;
        if self.wide.len() < n * cols {
            self.wide.resize(n * cols, 0.0);
        }
        if self.v.len() < cols {
            self.v.resize(cols, 0.0);
        }
        let (cm, ph, sf, sn, gs) = (
            c.as_slice(),
            phi.as_slice(),
            s_f.as_slice(),
            s_s_next.as_slice(),
            g.as_slice(),
        );
        // d = I − CΦ (column-major).
        let d = &mut self.d;
        for j in 0..n {
            for i in 0..n {
                let mut acc = if i == j { 1.0 } else { 0.0 };
                for l in 0..n {
                    acc -= cm[i + l * n] * ph[l + j * n];
                }
                d[i + j * n] = acc;
            }
        }
        // Row-major wide = [C G | C S^s_{k+1} | (I − CΦ) S_f].
        let w = &mut self.wide[..n * cols];
        for i in 0..n {
            let row = &mut w[i * cols..(i + 1) * cols];
            for j in 0..q {
                let mut acc = 0.0;
                for l in 0..n {
                    acc += cm[i + l * n] * gs[l + j * n];
                }
                row[j] = acc;
            }
            for j in 0..n {
                let (mut acc, mut acc2) = (0.0, 0.0);
                for l in 0..=j {
                    acc += cm[i + l * n] * sn[l + j * n];
                    acc2 += d[i + l * n] * sf[l + j * n];
                }
                row[q + j] = acc;
                row[q + n + j] = acc2;
            }
        }
        triangularize_upper(w, n, cols, &mut self.v);
        let o = out.as_mut_slice();
        for j in 0..n {
            for i in 0..n {
                o[i + j * n] = w[i * cols + q + n + j];
            }
        }
        Ok(())
    }
}

/// The body of [`SqrtRts::gain`] (inlined so that fixed sizes specialise).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn gain_impl(
    n: usize,
    sf: &[f64],
    ph: &[f64],
    sp: &[f64],
    a: &mut [f64],
    b: &mut [f64],
    d: &mut [f64],
    cs: &mut [f64],
) {
    let nn = n * n;
    let (sf, ph, sp, a, b, d, cs) = (
        &sf[..nn],
        &ph[..nn],
        &sp[..nn],
        &mut a[..nn],
        &mut b[..nn],
        &mut d[..n],
        &mut cs[..nn],
    );
    // a = Φ S_f (column-major; S_f upper: column j uses rows 0..=j), over
    // the non-zeros of Φ.
    a.fill(0.0);
    for (idx, &p) in ph.iter().enumerate() {
        if p != 0.0 {
            let (i, l) = (idx % n, idx / n);
            for j in l..n {
                a[i + j * n] += p * sf[l + j * n];
            }
        }
    }
    // b = a S_fᵀ = Φ P_f:  b[:, j] = Σ_{l ≥ j} a[:, l] S_f[j, l].
    b.fill(0.0);
    for j in 0..n {
        for l in j..n {
            let sjl = sf[j + l * n];
            if sjl != 0.0 {
                let (bj, al) = (j * n, l * n);
                for i in 0..n {
                    b[bj + i] += a[al + i] * sjl;
                }
            }
        }
    }
    // Solve S_p W = b (back substitution), then S_pᵀ Z = W (forward): Z = Cᵀ.
    let inv = d;
    for i in 0..n {
        inv[i] = 1.0 / sp[i + i * n];
    }
    for col in 0..n {
        let bc = &mut b[col * n..(col + 1) * n];
        for i in (0..n).rev() {
            let mut acc = bc[i];
            for l in i + 1..n {
                acc -= sp[i + l * n] * bc[l];
            }
            bc[i] = acc * inv[i];
        }
        for i in 0..n {
            let mut acc = bc[i];
            for (l, s) in sp[i * n..i * n + i].iter().enumerate() {
                acc -= s * bc[l];
            }
            bc[i] = acc * inv[i];
        }
        for i in 0..n {
            cs[col + i * n] = bc[i];
        }
    }
}

fn check(n: usize, ms: &[&DMatrix<f64>]) -> Result<()> {
    if ms.iter().any(|m| m.nrows() != n || m.ncols() != n) {
        return Err(EstError::Dimension(format!(
            "RTS step: every matrix must be {n}×{n}"
        )));
    }
    Ok(())
}
