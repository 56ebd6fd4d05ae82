//! Carlson's triangular square-root update for one scalar measurement.
//!
//! The covariance is carried as an upper-triangular factor `S`, `P = S Sᵀ`
//! (never `P` itself), which doubles the usable precision and keeps `P`
//! symmetric and positive semi-definite by construction. A scalar
//! measurement `y = hᵀx + v`, `v ~ N(0, r)`, `r > 0`, changes
//!
//! ```text
//! P⁺ = P − P h hᵀ P / α = S (I − f fᵀ/α) Sᵀ,    f = Sᵀh,   α = fᵀf + r.
//! ```
//!
//! Carlson (1973) factors the bracket column by column without forming
//! `P`: with `α₀ = r`, `α_j = α_{j−1} + f_j²` and the partial gain
//! `k⁽ʲ⁾ = Σ_{l<j} S_{:,l} f_l`,
//!
//! ```text
//! S⁺_{:,j} = √(α_{j−1}/α_j) · S_{:,j} − f_j/√(α_{j−1} α_j) · k⁽ʲ⁾,
//! k⁽ʲ⁺¹⁾   = k⁽ʲ⁾ + f_j S_{:,j}          (old column j),
//! ```
//!
//! ending with the innovation variance `α = α_n = hᵀPh + r`, the gain
//! `K = k⁽ⁿ⁺¹⁾/α = P h/α` and `x⁺ = x + K (y − hᵀx)`. Because `S` is upper
//! triangular only rows `i ≤ j` of column `j` are touched: `n(n+1)/2`
//! multiply–adds for `f`, about `2n²` for the factor, `n` square roots; no
//! matrix is inverted and no allocation is made.
//!
//! References: N. A. Carlson, "Fast triangular formulation of the square root
//! filter", *AIAA J.* 11 (1973) 1259–1265; G. J. Bierman, *Factorization
//! Methods for Discrete Sequential Estimation* (Academic Press 1977), §V.3;
//! M. S. Grewal & A. P. Andrews, *Kalman Filtering: Theory and Practice*
//! (4th ed., Wiley 2015), §7.5 ("Carlson–Schmidt square-root filtering").

use super::innovation::Innovation;
use crate::error::{EstError, Result};

/// One scalar measurement update of `(x, S)` in place.
///
/// * `s`: the `n × n` upper-triangular factor, column-major (`s[i + j n]`),
///   `P = S Sᵀ`; entries below the diagonal are neither read nor written;
/// * `x`: the state (length `n`); `h`: the measurement row (length `n`);
/// * `y`: the measurement; `r > 0`: its noise variance (units of `y`²);
/// * `gain`: length `n`; on return it holds the Kalman gain `K = P⁻h/α`;
/// * `work`: workspace of length `3n`.
///
/// All `f_j` and then all column coefficients are computed before the
/// columns are touched (they depend only on the old `S`), so the `n` square
/// roots do not form a dependency chain.
///
/// Returns the innovation `ν = y − hᵀx⁻` and its variance `α = hᵀP⁻h + r`.
/// Errors (state untouched): non-finite `y`, `h` or `r`, `r ≤ 0`, wrong lengths.
pub fn carlson_update(
    s: &mut [f64],
    x: &mut [f64],
    h: &[f64],
    y: f64,
    r: f64,
    gain: &mut [f64],
    work: &mut [f64],
) -> Result<Innovation> {
    let n = x.len();
    if s.len() != n * n || h.len() != n || gain.len() != n || work.len() < 3 * n {
        return Err(EstError::Dimension(format!(
            "Carlson update: state {n}, factor {}, row {}, gain {}, workspace {}",
            s.len(),
            h.len(),
            gain.len(),
            work.len()
        )));
    }
    if !(r > 0.0 && r.is_finite()) {
        return Err(EstError::NonFinite {
            what: "measurement noise variance (must be finite and > 0)",
        });
    }
    if !y.is_finite() || h.iter().any(|v| !v.is_finite()) {
        return Err(EstError::NonFinite {
            what: "scalar measurement or its row",
        });
    }
    // The same code, specialised by the compiler for the field models of
    // orders 3, 4 and 6 (5, 6 and 8 states).
    macro_rules! fixed {
        ($k:literal) => {
            Ok(carlson_impl(
                &mut s[..$k * $k],
                &mut x[..$k],
                &h[..$k],
                y,
                r,
                &mut gain[..$k],
                &mut work[..3 * $k],
            ))
        };
    }
    match n {
        5 => fixed!(5),
        6 => fixed!(6),
        8 => fixed!(8),
        // The joint filters of the Kalman method (tens of states): the
        // column loops run four lanes wide with AVX where the processor has
        // it (aeromag_core::simd: the same operations, the same bits).
        _ => Ok(aeromag_core::simd::run(Carlson {
            s,
            x,
            h,
            y,
            r,
            gain,
            work: &mut work[..3 * n],
        })),
    }
}

/// [`carlson_impl`] as a [`aeromag_core::simd::Kernel`].
struct Carlson<'a> {
    s: &'a mut [f64],
    x: &'a mut [f64],
    h: &'a [f64],
    y: f64,
    r: f64,
    gain: &'a mut [f64],
    work: &'a mut [f64],
}

impl aeromag_core::simd::Kernel for Carlson<'_> {
    type Output = Innovation;
    #[inline(always)]
    fn run(self) -> Innovation {
        carlson_impl(self.s, self.x, self.h, self.y, self.r, self.gain, self.work)
    }
}

#[inline(always)]
fn carlson_impl(
    s: &mut [f64],
    x: &mut [f64],
    h: &[f64],
    y: f64,
    r: f64,
    gain: &mut [f64],
    work: &mut [f64],
) -> Innovation {
    let n = x.len();
    let (f, rest) = work.split_at_mut(n);
    let (eta, zeta) = rest.split_at_mut(n);
    let mut innov = y;
    for i in 0..n {
        innov -= h[i] * x[i];
    }
    // f = Sᵀh over the old factor: independent dot products, four columns
    // at a time so that their sums run side by side instead of one long
    // chain of dependent additions; each is still summed over its rows
    // 0..=j in order, so the bits are those of one column at a time.
    let mut j = 0;
    while j + 4 <= n {
        let col = |k: usize| &s[(j + k) * n..(j + k) * n + j + k + 1];
        let (c0, c1, c2, c3) = (col(0), col(1), col(2), col(3));
        let mut a = [0.0f64; 4];
        for ((((s0, s1), s2), s3), hi) in c0.iter().zip(c1).zip(c2).zip(c3).zip(&h[..=j]) {
            a[0] += s0 * hi;
            a[1] += s1 * hi;
            a[2] += s2 * hi;
            a[3] += s3 * hi;
        }
        // The rows below the first column's diagonal.
        a[1] += c1[j + 1] * h[j + 1];
        a[2] += c2[j + 1] * h[j + 1];
        a[3] += c3[j + 1] * h[j + 1];
        a[2] += c2[j + 2] * h[j + 2];
        a[3] += c3[j + 2] * h[j + 2];
        a[3] += c3[j + 3] * h[j + 3];
        f[j..j + 4].copy_from_slice(&a);
        j += 4;
    }
    for j in j..n {
        let mut fj = 0.0;
        for (sij, hi) in s[j * n..j * n + j + 1].iter().zip(&h[..=j]) {
            fj += sij * hi;
        }
        f[j] = fj;
    }
    // α_j = α_{j−1} + f_j² and the column coefficients η_j = √(α_{j−1}/α_j),
    // ζ_j = f_j/√(α_{j−1} α_j).
    let mut alpha = r;
    for j in 0..n {
        let beta = alpha;
        alpha += f[j] * f[j];
        eta[j] = beta;
        zeta[j] = alpha;
    }
    for j in 0..n {
        let (beta, a) = (eta[j], zeta[j]);
        let inv_gamma = 1.0 / (a * beta).sqrt();
        eta[j] = beta * inv_gamma;
        zeta[j] = f[j] * inv_gamma;
    }
    gain.fill(0.0);
    let mut j = 0;
    while j < n {
        if j + 4 <= n && f[j..j + 4].iter().all(|v| *v != 0.0) {
            update_four_columns(s, gain, n, j, &eta[j..j + 4], &zeta[j..j + 4], &f[j..j + 4]);
            j += 4;
            continue;
        }
        if f[j] != 0.0 {
            // (f_j = 0: column unchanged, η = 1, ζ = 0, gain unchanged.)
            let (ej, zj, fj) = (eta[j], zeta[j], f[j]);
            for (sij, ki) in s[j * n..j * n + j + 1]
                .iter_mut()
                .zip(gain[..=j].iter_mut())
            {
                column_step(sij, ki, ej, zj, fj);
            }
        }
        j += 1;
    }
    let inv_alpha = 1.0 / alpha;
    for (g, xi) in gain.iter_mut().zip(x.iter_mut()) {
        *g *= inv_alpha;
        *xi += *g * innov;
    }
    Innovation {
        value: innov,
        variance: alpha,
    }
}

/// One entry of Carlson's column update: `S⁺_ij = η_j S_ij − ζ_j k_i`,
/// then `k_i += f_j S_ij` with the old `S_ij`.
#[inline(always)]
fn column_step(sij: &mut f64, ki: &mut f64, ej: f64, zj: f64, fj: f64) {
    let a = *sij;
    *sij = ej * a - zj * *ki;
    *ki += fj * a;
}

/// Columns `j..j + 4` of the update (all four `f` non-zero), each row's
/// partial gain `k_i` carried through the four in a register instead of
/// stored and reloaded between columns: row `i` sees columns `j`, `j + 1`,
/// … in turn, as one column at a time, so the bits are the same (test
/// `four_columns_at_a_time_are_one_at_a_time`); the rows `0..=j` that all
/// four hold run along the lanes.
#[inline(always)]
fn update_four_columns(
    s: &mut [f64],
    gain: &mut [f64],
    n: usize,
    j: usize,
    eta: &[f64],
    zeta: &[f64],
    f: &[f64],
) {
    let (e, z, f): ([f64; 4], [f64; 4], [f64; 4]) = (
        std::array::from_fn(|c| eta[c]),
        std::array::from_fn(|c| zeta[c]),
        std::array::from_fn(|c| f[c]),
    );
    let (c0, rest) = s[j * n..(j + 4) * n].split_at_mut(n);
    let (c1, rest) = rest.split_at_mut(n);
    let (c2, c3) = rest.split_at_mut(n);
    for ((((s0, s1), s2), s3), ki) in c0[..=j]
        .iter_mut()
        .zip(c1[..=j].iter_mut())
        .zip(c2[..=j].iter_mut())
        .zip(c3[..=j].iter_mut())
        .zip(gain[..=j].iter_mut())
    {
        let mut k = *ki;
        column_step(s0, &mut k, e[0], z[0], f[0]);
        column_step(s1, &mut k, e[1], z[1], f[1]);
        column_step(s2, &mut k, e[2], z[2], f[2]);
        column_step(s3, &mut k, e[3], z[3], f[3]);
        *ki = k;
    }
    // The rows below column j's diagonal: row j + r in columns j + r ….
    let cols = [c1, c2, c3];
    for r in 1..4 {
        let mut k = gain[j + r];
        for c in r..4 {
            column_step(&mut cols[c - 1][j + r], &mut k, e[c], z[c], f[c]);
        }
        gain[j + r] = k;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    #[test]
    fn matches_the_covariance_form_on_a_small_case() {
        let n = 3;
        let s = DMatrix::from_row_slice(3, 3, &[2.0, 0.5, -0.3, 0.0, 1.0, 0.2, 0.0, 0.0, 0.7]);
        let p = &s * s.transpose();
        let h = [0.3, -1.2, 0.8];
        let (y, r) = (1.7, 0.09);
        let mut x = vec![0.1, -0.2, 0.4];
        let hv = DVector::from_column_slice(&h);
        let xv = DVector::from_column_slice(&x);
        let alpha = (hv.transpose() * &p * &hv)[0] + r;
        let k = &p * &hv / alpha;
        let x_ref = &xv + &k * (y - hv.dot(&xv));
        let p_ref = &p - &k * hv.transpose() * &p;

        let mut sf = s.as_slice().to_vec();
        let mut gain = vec![0.0; n];
        let inn = carlson_update(&mut sf, &mut x, &h, y, r, &mut gain, &mut [0.0; 9]).unwrap();
        assert!((inn.variance - alpha).abs() < 1e-14);
        let s2 = DMatrix::from_column_slice(n, n, &sf);
        let p2 = &s2 * s2.transpose();
        assert!((p2 - p_ref).abs().max() < 1e-14);
        for i in 0..n {
            assert!((x[i] - x_ref[i]).abs() < 1e-14);
            assert!((gain[i] - k[i]).abs() < 1e-14);
            assert_eq!(s2[(2, 0)], 0.0);
        }
    }

    /// Every size (four columns at a time, the remainder, the specialised
    /// 5, 6, 8): the covariance form to round-off, and `α = r + Σ f_j²` with
    /// each `f_j` summed one column at a time, bit for bit.
    #[test]
    fn any_size_matches_the_covariance_form_and_sums_f_in_row_order() {
        use rand::SeedableRng;
        use rand_distr::{Distribution, StandardNormal};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for n in [1, 3, 4, 5, 6, 7, 8, 9, 11, 13, 42] {
            let mut s = vec![0.0; n * n];
            for j in 0..n {
                for i in 0..=j {
                    s[i + j * n] = {
                        let v: f64 = StandardNormal.sample(&mut rng);
                        v
                    } + if i == j { 2.0 } else { 0.0 };
                }
            }
            let h: Vec<f64> = (0..n)
                .map(|_| {
                    let v: f64 = StandardNormal.sample(&mut rng);
                    v
                })
                .collect();
            let (y, r) = (0.7, 0.05);
            let mut alpha_ref = r;
            for j in 0..n {
                let mut fj = 0.0;
                for i in 0..=j {
                    fj += s[i + j * n] * h[i];
                }
                alpha_ref += fj * fj;
            }
            let sm = DMatrix::from_column_slice(n, n, &s);
            let p = &sm * sm.transpose();
            let hv = DVector::from_column_slice(&h);
            let k = &p * &hv / alpha_ref;
            let p_ref = &p - &k * hv.transpose() * &p;
            let mut x = vec![0.0; n];
            let mut gain = vec![0.0; n];
            let mut work = vec![0.0; 3 * n];
            let inn = carlson_update(&mut s, &mut x, &h, y, r, &mut gain, &mut work).unwrap();
            assert_eq!(inn.variance.to_bits(), alpha_ref.to_bits(), "n {n}");
            let s2 = DMatrix::from_column_slice(n, n, &s);
            assert!(
                (s2.clone() * s2.transpose() - p_ref).abs().max() < 1e-12,
                "n {n}"
            );
            assert!(
                (DVector::from_column_slice(&gain) - k).abs().max() < 1e-12,
                "n {n}"
            );
        }
    }

    /// The update written one column at a time with plain loops (the
    /// equations of the module docs in their order).
    fn one_column_at_a_time(
        s: &mut [f64],
        x: &mut [f64],
        h: &[f64],
        y: f64,
        r: f64,
        gain: &mut [f64],
    ) -> Innovation {
        let n = x.len();
        let mut innov = y;
        for i in 0..n {
            innov -= h[i] * x[i];
        }
        let f: Vec<f64> = (0..n)
            .map(|j| {
                let mut fj = 0.0;
                for i in 0..=j {
                    fj += s[i + j * n] * h[i];
                }
                fj
            })
            .collect();
        let mut alpha = r;
        gain.fill(0.0);
        for j in 0..n {
            let beta = alpha;
            alpha += f[j] * f[j];
            if f[j] == 0.0 {
                continue;
            }
            let inv_gamma = 1.0 / (alpha * beta).sqrt();
            let (ej, zj) = (beta * inv_gamma, f[j] * inv_gamma);
            for i in 0..=j {
                let a = s[i + j * n];
                s[i + j * n] = ej * a - zj * gain[i];
                gain[i] += f[j] * a;
            }
        }
        for i in 0..n {
            gain[i] *= 1.0 / alpha;
            x[i] += gain[i] * innov;
        }
        Innovation {
            value: innov,
            variance: alpha,
        }
    }

    /// Four columns at a time (registers carrying the partial gain through
    /// them) against one at a time, bit for bit: every size up to 13 and the
    /// Kalman method's tens of states, with zero `f_j` (leading zeros of `h`,
    /// a zero column) that send a block of four back to single columns.
    #[test]
    fn four_columns_at_a_time_are_one_at_a_time() {
        use rand::SeedableRng;
        use rand_distr::{Distribution, StandardNormal};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let mut normal = move || -> f64 { StandardNormal.sample(&mut rng) };
        for n in (1..=13).chain([36, 42]) {
            for case in 0..3 {
                let mut s = vec![0.0; n * n];
                for j in 0..n {
                    for i in 0..=j {
                        s[i + j * n] = normal() + if i == j { 2.0 } else { 0.0 };
                    }
                }
                let mut h: Vec<f64> = (0..n).map(|_| normal()).collect();
                if case == 1 {
                    // f_0 = f_1 = 0.
                    h[..n.min(2)].fill(0.0);
                }
                if case == 2 && n > 9 {
                    // f_9 = 0.
                    s[9 * n..10 * n].fill(0.0);
                }
                let x0: Vec<f64> = (0..n).map(|_| normal()).collect();
                let (mut s_ref, mut x_ref, mut g_ref) = (s.clone(), x0.clone(), vec![0.0; n]);
                let want = one_column_at_a_time(&mut s_ref, &mut x_ref, &h, 0.4, 0.05, &mut g_ref);
                let (mut x, mut gain, mut work) = (x0, vec![0.0; n], vec![0.0; 3 * n]);
                let got =
                    carlson_update(&mut s, &mut x, &h, 0.4, 0.05, &mut gain, &mut work).unwrap();
                let bits = |v: &[f64]| v.iter().map(|a| a.to_bits()).collect::<Vec<_>>();
                assert_eq!(
                    got.value.to_bits(),
                    want.value.to_bits(),
                    "n {n} case {case}"
                );
                assert_eq!(
                    got.variance.to_bits(),
                    want.variance.to_bits(),
                    "n {n} case {case}"
                );
                assert_eq!(bits(&s), bits(&s_ref), "factor, n {n} case {case}");
                assert_eq!(bits(&gain), bits(&g_ref), "gain, n {n} case {case}");
                assert_eq!(bits(&x), bits(&x_ref), "state, n {n} case {case}");
            }
        }
    }

    #[test]
    fn bad_input_leaves_the_state_alone() {
        let mut s = vec![1.0, 0.0, 0.0, 1.0];
        let mut x = vec![0.0, 0.0];
        let mut g = vec![0.0; 2];
        let mut w = vec![0.0; 6];
        assert!(
            carlson_update(&mut s, &mut x, &[1.0, 0.0], f64::NAN, 1.0, &mut g, &mut w).is_err()
        );
        assert!(carlson_update(&mut s, &mut x, &[1.0, 0.0], 1.0, 0.0, &mut g, &mut w).is_err());
        assert!(carlson_update(&mut s, &mut x, &[1.0], 1.0, 1.0, &mut g, &mut w).is_err());
        assert_eq!(s, vec![1.0, 0.0, 0.0, 1.0]);
        assert_eq!(x, vec![0.0, 0.0]);
    }
}
