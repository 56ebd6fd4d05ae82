//! Re-triangularisation of a wide square-root factor by Householder
//! reflections applied from the right (an RQ decomposition).
//!
//! Square-root time updates and smoothers produce a *wide* factor: for
//! example the predicted covariance `P⁻ = Φ P Φᵀ + G Gᵀ` equals `M Mᵀ` with
//! `M = [G, Φ S]` (`n × (q+n)`). Any orthogonal `Q` leaves `M Q Qᵀ Mᵀ = M Mᵀ`
//! unchanged, so we look for `Q` with
//!
//! ```text
//! M Q = [0, U],    U upper triangular n × n,  U Uᵀ = M Mᵀ,
//! ```
//!
//! which is the new factor. Rows are processed from the last to the first:
//! for row `i`, one Householder reflection `I − β v vᵀ` acting on the first
//! `p + i + 1` columns (`p = c − n` extra columns, then the square part up to
//! column `i` of `U`) moves the whole norm of that part of row `i` into its
//! last column, the diagonal position of `U`. The rows below `i` are already
//! zero in those columns and stay zero; the columns to the right are final
//! and are not touched again. The diagonal is made non-negative (a sign flip
//! of a column is orthogonal too).
//!
//! The matrix is stored **row-major** with the extra columns first, so the
//! columns a reflection acts on are a contiguous prefix of every row: each
//! step is a set of short dot products and `axpy`s over contiguous memory.
//! Cost about `(4/3) n³ + 2 p n²` flops; no allocation (the caller supplies
//! the workspace).
//!
//! This is the covariance-form counterpart of Thornton's modified weighted
//! Gram–Schmidt time update (C. L. Thornton, *Triangular covariance
//! factorizations for Kalman filtering*, PhD thesis, UCLA 1976; Bierman 1977,
//! ch. VI) and of the QR-based propagation of Kaminski, Bryson & Schmidt
//! (*IEEE TAC* 16, 1971); Householder: Golub & Van Loan, *Matrix
//! Computations* (4th ed.), §5.1.

/// Triangularise `a` (`n × c`, **row-major**, `c ≥ n`; the first `c − n`
/// columns are the extra ones, the last `n` the square part) in place: on
/// return the last `n` columns hold the upper-triangular `U` (row-major,
/// non-negative diagonal, exact zeros below it) with `U Uᵀ = A Aᵀ`, and the
/// first `c − n` columns are zero.
///
/// `v` (length ≥ `c`) is workspace. Panics only on slice lengths
/// inconsistent with `n` and `c` (a programming error, not bad data);
/// non-finite entries propagate to the result.
pub fn triangularize_upper(a: &mut [f64], n: usize, c: usize, v: &mut [f64]) {
    assert!(
        c >= n && a.len() >= n * c && v.len() >= c,
        "triangularize_upper: bad sizes"
    );
    // The same code, specialised by the compiler for the sizes of the
    // field models of orders 3, 4 and 6 (k = 5, 6, 8 states: time update
    // k × 2k, smoother k × 3k).
    match (n, c) {
        (5, 10) => triangularize_impl(&mut a[..50], 5, 10, &mut v[..10]),
        (5, 15) => triangularize_impl(&mut a[..75], 5, 15, &mut v[..15]),
        (6, 12) => triangularize_impl(&mut a[..72], 6, 12, &mut v[..12]),
        (6, 18) => triangularize_impl(&mut a[..108], 6, 18, &mut v[..18]),
        (8, 16) => triangularize_impl(&mut a[..128], 8, 16, &mut v[..16]),
        (8, 24) => triangularize_impl(&mut a[..192], 8, 24, &mut v[..24]),
        _ => triangularize_impl(a, n, c, v),
    }
}

#[inline(always)]
fn triangularize_impl(a: &mut [f64], n: usize, c: usize, v: &mut [f64]) {
    let p = c - n;
    for i in (0..n).rev() {
        let m = p + i + 1; // active prefix; pivot at m − 1
        let (above, rest) = a.split_at_mut(i * c);
        let row_i = &mut rest[..c];
        let w = &row_i[..m];
        let pivot = w[m - 1];
        let mut off2 = 0.0;
        for x in &w[..m - 1] {
            off2 += x * x;
        }
        if off2 > 0.0 {
            let norm = (off2 + pivot * pivot).sqrt();
            // Reflect w onto −sign(w_pivot)·‖w‖ e_pivot (no cancellation in v_pivot).
            let alpha = if pivot >= 0.0 { -norm } else { norm };
            let v = &mut v[..m];
            v.copy_from_slice(w);
            v[m - 1] -= alpha;
            let beta = 2.0 / (off2 + v[m - 1] * v[m - 1]);
            for r in 0..i {
                let row = &mut above[r * c..r * c + m];
                let mut t = 0.0;
                for (x, y) in row.iter().zip(v.iter()) {
                    t += x * y;
                }
                let bt = beta * t;
                for (x, y) in row.iter_mut().zip(v.iter()) {
                    *x -= bt * y;
                }
            }
            row_i[..m - 1].fill(0.0);
            row_i[m - 1] = alpha;
        }
        if row_i[m - 1] < 0.0 {
            // Flip the sign of the pivot column (rows 0..=i; rows below are zero).
            row_i[m - 1] = -row_i[m - 1];
            for r in 0..i {
                above[r * c + m - 1] = -above[r * c + m - 1];
            }
        }
    }
    // Exact zeros below the diagonal of U (row i, square columns < i).
    for i in 0..n {
        a[i * c..i * c + p + i].fill(0.0);
    }
}

/// Triangularise `a = [B, A]` (`n × 2n`, **row-major**) in place when
/// **both** `n × n` halves are upper triangular, as in the time update
/// `[G, Φ S]` of a model whose transition `Φ` and noise factor `G` are upper
/// triangular (chains of integrators with the "upper" factor of `Q`): the
/// result is that of [`triangularize_upper`] (`U` in the last `n` columns,
/// the first `n` zero) at about a third of the cost.
///
/// Why it is cheaper: row `i` of `[B, A]` is non-zero only in the columns
/// `i..n` of `B` and `i..n` of `A`, and the reflections of the rows below
/// `i` (which act on the columns `≥ i + 1` of `B` and on one column of `A`
/// each) keep it so. The reflection of row `i` therefore acts on the
/// `n − i` columns `B[:, i..n]` and the pivot `A[:, i]` only, instead of the
/// whole prefix of `n + i + 1` columns: about `4 Σ i (n − i + 1)` flops
/// (448 for `n = 8`, against 1 568 for the general routine).
///
/// The caller guarantees the structure (entries below either diagonal must
/// be zero; they are not read). `v` (length ≥ `n + 1`) is workspace.
pub fn triangularize_upper_pair(a: &mut [f64], n: usize, v: &mut [f64]) {
    assert!(
        a.len() >= 2 * n * n && v.len() > n,
        "triangularize_upper_pair: bad sizes"
    );
    match n {
        5 => pair_impl(&mut a[..50], 5, &mut v[..6]),
        6 => pair_impl(&mut a[..72], 6, &mut v[..7]),
        8 => pair_impl(&mut a[..128], 8, &mut v[..9]),
        _ => pair_impl(a, n, v),
    }
}

#[inline(always)]
fn pair_impl(a: &mut [f64], n: usize, v: &mut [f64]) {
    let c = 2 * n;
    for i in (0..n).rev() {
        let (above, rest) = a.split_at_mut(i * c);
        let row_i = &mut rest[..c];
        let pivot = row_i[n + i];
        let mut off2 = 0.0;
        for x in &row_i[i..n] {
            off2 += x * x;
        }
        if off2 > 0.0 {
            let norm = (off2 + pivot * pivot).sqrt();
            let alpha = if pivot >= 0.0 { -norm } else { norm };
            // v = (B[i, i..n], A[i, i] − α): the reflection I − β v vᵀ.
            let vb = &mut v[..n - i];
            vb.copy_from_slice(&row_i[i..n]);
            let vp = pivot - alpha;
            let beta = 2.0 / (off2 + vp * vp);
            for r in 0..i {
                let row = &mut above[r * c..(r + 1) * c];
                let mut t = row[n + i] * vp;
                for (x, y) in row[i..n].iter().zip(vb.iter()) {
                    t += x * y;
                }
                let bt = beta * t;
                for (x, y) in row[i..n].iter_mut().zip(vb.iter()) {
                    *x -= bt * y;
                }
                row[n + i] -= bt * vp;
            }
            row_i[i..n].fill(0.0);
            row_i[n + i] = alpha;
        }
        if row_i[n + i] < 0.0 {
            row_i[n + i] = -row_i[n + i];
            for r in 0..i {
                above[r * c + n + i] = -above[r * c + n + i];
            }
        }
    }
    // Exact zeros: all of B, and A below its diagonal.
    for i in 0..n {
        a[i * c..i * c + n + i].fill(0.0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, StandardNormal};

    fn run(m: &DMatrix<f64>) -> DMatrix<f64> {
        let (n, c) = m.shape();
        let mut a: Vec<f64> = (0..n)
            .flat_map(|i| (0..c).map(move |j| (i, j)))
            .map(|(i, j)| m[(i, j)])
            .collect();
        let mut v = vec![0.0; c];
        triangularize_upper(&mut a, n, c, &mut v);
        DMatrix::from_row_slice(n, c, &a)
    }

    #[test]
    fn preserves_the_gram_matrix_and_is_upper_triangular() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for &(n, c) in &[(1, 1), (1, 4), (3, 3), (4, 9), (5, 10), (6, 8), (21, 26)] {
            let m = DMatrix::from_fn(n, c, |_, _| StandardNormal.sample(&mut rng));
            let gram = &m * m.transpose();
            let out = run(&m);
            let u = out.columns(c - n, n).into_owned();
            for i in 0..n {
                assert!(u[(i, i)] >= 0.0);
                for j in 0..i {
                    assert_eq!(u[(i, j)], 0.0);
                }
            }
            assert!(out.columns(0, c - n).iter().all(|x| *x == 0.0));
            let err = (&u * u.transpose() - &gram).abs().max();
            assert!(err < 1e-12 * gram.abs().max(), "n={n} c={c}: {err}");
        }
    }

    #[test]
    fn rank_deficient_rows_are_handled() {
        // A zero row and a row already concentrated in its pivot (negative).
        let m = DMatrix::from_row_slice(
            3,
            4,
            &[1.0, 2.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -3.0],
        );
        let out = run(&m);
        let u = out.columns(1, 3).into_owned();
        assert!((&u * u.transpose() - &m * m.transpose()).abs().max() < 1e-14);
        assert_eq!(u[(2, 2)], 3.0);
        assert_eq!(u[(1, 1)], 0.0);
    }

    #[test]
    fn the_pair_kernel_equals_the_general_one_on_triangular_halves() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        for &n in &[1usize, 2, 5, 6, 7, 8] {
            let upper = |rng: &mut ChaCha8Rng| {
                DMatrix::from_fn(n, n, |i, j| {
                    if i <= j {
                        StandardNormal.sample(rng)
                    } else {
                        0.0
                    }
                })
            };
            let (b, a) = (upper(&mut rng), upper(&mut rng));
            let mut m = DMatrix::zeros(n, 2 * n);
            m.columns_mut(0, n).copy_from(&b);
            m.columns_mut(n, n).copy_from(&a);
            let general = run(&m);
            let mut w: Vec<f64> = (0..n)
                .flat_map(|i| (0..2 * n).map(move |j| (i, j)))
                .map(|(i, j)| m[(i, j)])
                .collect();
            let mut v = vec![0.0; n + 1];
            triangularize_upper_pair(&mut w, n, &mut v);
            let pair = DMatrix::from_row_slice(n, 2 * n, &w);
            assert!(pair.columns(0, n).iter().all(|x| *x == 0.0));
            let u = pair.columns(n, n).into_owned();
            for i in 0..n {
                assert!(u[(i, i)] >= 0.0);
                for j in 0..i {
                    assert_eq!(u[(i, j)], 0.0);
                }
            }
            let gram = &m * m.transpose();
            assert!((&u * u.transpose() - &gram).abs().max() < 1e-12 * gram.abs().max());
            // The upper factor with a non-negative diagonal is unique.
            let diff = (&u - general.columns(n, n)).abs().max();
            assert!(diff < 1e-12 * u.abs().max(), "n={n}: {diff}");
        }
    }
}
