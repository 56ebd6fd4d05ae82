//! Conversion of a digital ZPK filter into cascaded second-order sections
//! with SciPy's `zpk2sos(..., pairing='nearest')` pole–zero pairing, so that
//! the sections come out in the same order as SciPy's.
//!
//! A section is `[b0, b1, b2, 1, a1, a2]`, the biquad
//!
//! ```text
//! H_s(z) = (b0 + b1 z⁻¹ + b2 z⁻²) / (1 + a1 z⁻¹ + a2 z⁻²)
//! ```
//!
//! Pairing rules (SciPy reference guide, `scipy.signal.zpk2sos`):
//!
//! 1. If the number of poles is odd, a pole and a zero at the origin are added.
//! 2. Roots are split into real ones and one representative of each
//!    conjugate pair (tolerance `100 ε |r|` on the imaginary part; pairs are
//!    averaged).
//! 3. Sections are built from the last to the first. Each step takes the
//!    remaining pole closest to the unit circle (the "worst" pole), pairs it
//!    with its conjugate or with the next-worst real pole, and gives it the
//!    nearest zero(s) (a conjugate pair, or the nearest real zeros), with two
//!    special cases that keep real poles/zeros matched.
//! 4. The overall gain `k` multiplies the numerator of the first section.
//!
//! So the poles nearest the unit circle (the most resonant) sit in the last
//! sections, which limits the peak gain of intermediate results.

use super::complex::{C64, is_real};
use super::validate::invalid;
use super::zpk::Zpk;
use crate::error::Result;

/// Which roots [`nearest`] may return.
#[derive(Clone, Copy, PartialEq)]
enum Which {
    Real,
    Complex,
    Any,
}

/// Second-order sections (`[b0, b1, b2, 1, a1, a2]` each) of a digital ZPK
/// filter, sections ordered like SciPy's `zpk2sos(z, p, k)`.
///
/// Errors (`InvalidArgument`) when a complex root has no conjugate partner or
/// the pairing cannot find a required real zero (both impossible for a
/// Butterworth design).
pub fn zpk2sos(zpk: &Zpk) -> Result<Vec<[f64; 6]>> {
    let k = zpk.gain;
    if zpk.zeros.is_empty() && zpk.poles.is_empty() {
        return Ok(vec![[k, 0.0, 0.0, 1.0, 0.0, 0.0]]);
    }
    let origin = C64::new(0.0, 0.0);
    let mut z = zpk.zeros.clone();
    let mut p = zpk.poles.clone();
    let n = z.len().max(p.len());
    p.resize(n, origin);
    z.resize(n, origin);
    let n_sections = n.div_ceil(2);
    if n % 2 == 1 {
        p.push(origin);
        z.push(origin);
    }
    let mut z = cplxreal(&z)?;
    let mut p = cplxreal(&p)?;

    let mut sos = vec![[0.0; 6]; n_sections];
    for si in (0..n_sections).rev() {
        let p1 = p.remove(idx_worst(&p));
        let n_real_p = p.iter().filter(|&&r| is_real(r)).count();
        sos[si] = if is_real(p1) && n_real_p == 0 {
            // Special case 1: the last remaining real pole.
            let z1 = take(&mut z, p1, Which::Real)?;
            single_section(&[z1, origin], &[p1, origin])
        } else if p.len() + 1 == z.len()
            && !is_real(p1)
            && n_real_p == 1
            && z.iter().filter(|&&r| is_real(r)).count() == 1
        {
            // Special case 2: one real pole and one real zero left; the
            // complex pole must take a complex zero.
            let z1 = take(&mut z, p1, Which::Complex)?;
            single_section(&[z1, z1.conj()], &[p1, p1.conj()])
        } else {
            let p2 = if is_real(p1) {
                let real_idx: Vec<usize> = (0..p.len()).filter(|&i| is_real(p[i])).collect();
                let reals: Vec<C64> = real_idx.iter().map(|&i| p[i]).collect();
                p.remove(real_idx[idx_worst(&reals)])
            } else {
                p1.conj()
            };
            if z.is_empty() {
                single_section(&[], &[p1, p2])
            } else {
                let z1 = take(&mut z, p1, Which::Any)?;
                if !is_real(z1) {
                    single_section(&[z1, z1.conj()], &[p1, p2])
                } else if z.is_empty() {
                    single_section(&[z1], &[p1, p2])
                } else {
                    let z2 = take(&mut z, p1, Which::Real)?;
                    single_section(&[z1, z2], &[p1, p2])
                }
            }
        };
    }
    for c in &mut sos[0][..3] {
        *c *= k;
    }
    Ok(sos)
}

/// Index of the root closest to the unit circle, `argmin |1 − |p||` (first
/// of equals). `p` is never empty here: poles are consumed in step with the
/// section count.
fn idx_worst(p: &[C64]) -> usize {
    let mut best = 0;
    let mut best_d = f64::INFINITY;
    for (i, r) in p.iter().enumerate() {
        let d = (1.0 - r.norm()).abs();
        if d < best_d {
            best = i;
            best_d = d;
        }
    }
    best
}

/// Removes and returns the root of `roots` nearest to `to` among the allowed kind.
fn take(roots: &mut Vec<C64>, to: C64, which: Which) -> Result<C64> {
    let mut order: Vec<usize> = (0..roots.len()).collect();
    order.sort_by(|&a, &b| (roots[a] - to).norm().total_cmp(&(roots[b] - to).norm()));
    let idx = order
        .into_iter()
        .find(|&i| match which {
            Which::Any => true,
            Which::Real => is_real(roots[i]),
            Which::Complex => !is_real(roots[i]),
        })
        .ok_or_else(|| invalid("zpk", "pole-zero pairing found no matching zero"))?;
    Ok(roots.remove(idx))
}

/// The section `[b0 b1 b2 a0 a1 a2]` of unit gain with the given (at most two)
/// zeros and poles; shorter polynomials are right-aligned as in SciPy.
fn single_section(z: &[C64], p: &[C64]) -> [f64; 6] {
    let mut s = [0.0; 6];
    let b = poly(z);
    let a = poly(p);
    s[3 - b.len()..3].copy_from_slice(&b);
    s[6 - a.len()..6].copy_from_slice(&a);
    s
}

/// Real coefficients of `Π (x − r)`, highest power first (NumPy `poly`).
fn poly(roots: &[C64]) -> Vec<f64> {
    let mut c = vec![C64::new(1.0, 0.0)];
    for &r in roots {
        let mut next = c.clone();
        next.push(C64::new(0.0, 0.0));
        for j in 1..next.len() {
            next[j] += c[j - 1] * (-r);
        }
        c = next;
    }
    c.into_iter().map(|v| v.re).collect()
}

/// SciPy's `_cplxreal` followed by concatenation: one representative (positive
/// imaginary part, averaged with its partner) of each conjugate pair, sorted
/// by real part then |imaginary part|, followed by the real roots sorted.
fn cplxreal(z: &[C64]) -> Result<Vec<C64>> {
    let tol = 100.0 * f64::EPSILON;
    let mut z = z.to_vec();
    z.sort_by(|a, b| {
        a.re.total_cmp(&b.re)
            .then(a.im.abs().total_cmp(&b.im.abs()))
    });
    let (real, cplx): (Vec<C64>, Vec<C64>) =
        z.into_iter().partition(|r| r.im.abs() <= tol * r.norm());
    let mut zp: Vec<C64> = cplx.iter().copied().filter(|r| r.im > 0.0).collect();
    let mut zn: Vec<C64> = cplx.iter().copied().filter(|r| r.im < 0.0).collect();
    if zp.len() != zn.len() {
        return Err(invalid("zpk", "complex root without a matching conjugate"));
    }
    // Runs of (approximately) equal real part are re-sorted by |imag|.
    let mut start = 0;
    while start < zp.len() {
        let mut stop = start + 1;
        while stop < zp.len() && zp[stop].re - zp[stop - 1].re <= tol * zp[stop - 1].norm() {
            stop += 1;
        }
        if stop - start > 1 {
            zp[start..stop].sort_by(|a, b| a.im.abs().total_cmp(&b.im.abs()));
            zn[start..stop].sort_by(|a, b| a.im.abs().total_cmp(&b.im.abs()));
        }
        start = stop;
    }
    let mut out = Vec::with_capacity(zp.len() + real.len());
    for (a, b) in zp.iter().zip(&zn) {
        if (a - b.conj()).norm() > tol * b.norm() {
            return Err(invalid("zpk", "complex root without a matching conjugate"));
        }
        out.push((a + b.conj()) / 2.0);
    }
    out.extend(real.into_iter().map(|r| C64::new(r.re, 0.0)));
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_filter_is_a_gain() {
        let zpk = Zpk {
            zeros: vec![],
            poles: vec![],
            gain: 2.5,
        };
        assert_eq!(zpk2sos(&zpk).unwrap(), vec![[2.5, 0.0, 0.0, 1.0, 0.0, 0.0]]);
    }

    #[test]
    fn unmatched_conjugate_is_an_error() {
        let zpk = Zpk {
            zeros: vec![C64::new(0.5, 0.5)],
            poles: vec![C64::new(0.1, 0.0)],
            gain: 1.0,
        };
        assert!(zpk2sos(&zpk).is_err());
    }

    #[test]
    fn sections_reproduce_polynomial_product() {
        // poles 0.9e^{±0.3i}, 0.5e^{±1.2i}, zeros −1 (×2), 1 (×2)
        let pol = |r: f64, t: f64| C64::new(r * t.cos(), r * t.sin());
        let zpk = Zpk {
            zeros: vec![
                C64::new(-1.0, 0.0),
                C64::new(-1.0, 0.0),
                C64::new(1.0, 0.0),
                C64::new(1.0, 0.0),
            ],
            poles: vec![pol(0.9, 0.3), pol(0.9, -0.3), pol(0.5, 1.2), pol(0.5, -1.2)],
            gain: 0.3,
        };
        let sos = zpk2sos(&zpk).unwrap();
        assert_eq!(sos.len(), 2);
        // the worst pole (radius 0.9) is in the last section
        let a2_last = sos[1][5];
        assert!((a2_last - 0.81).abs() < 1e-15);
        for s in &sos {
            assert_eq!(s[3], 1.0);
        }
    }
}
