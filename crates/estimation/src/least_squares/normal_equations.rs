//! Streaming ridge least squares by scaled normal equations.
//!
//! Solves `min_c ‖y − A c‖² + λ‖c‖²`, i.e. `(AᵀA + λI) c = Aᵀy`, without ever
//! holding `A`: rows (or blocks of rows) are accumulated into `AᵀA`, `Aᵀy`,
//! `yᵀy`, so memory is `O(n²)` whatever the number of rows `N` and the cost
//! `O(N n²/2)`.
//!
//! **Conditioning.** Before solving, the system is equilibrated with the
//! diagonal `D = diag(sqrt((AᵀA)_jj))`: with `u = D c`,
//! `(D⁻¹AᵀAD⁻¹ + λD⁻²) u = D⁻¹Aᵀy`. The scaled matrix `S = D⁻¹AᵀAD⁻¹` has a
//! unit diagonal, and is solved through its symmetric eigendecomposition,
//! which also gives
//! * the condition number `κ(S)` of the scaled normal equations
//!   (= `κ(A D⁻¹)²`), and the warning threshold in [`LsSolution::is_ill_conditioned`];
//! * the variance inflation factor `VIF_j = (S⁻¹)_jj` of each unknown — how
//!   much its variance is inflated by collinearity with the others (1 for an
//!   orthogonal column); and the near-null directions (eigenvectors of the
//!   smallest eigenvalues), so a caller can say *which* combinations are not
//!   determined.
//!
//! Relative accuracy of the solution is about `κ(S) · ε`; with `κ(S) < 1e8`
//! that is better than 1e-8. Reference: Björck, *Numerical Methods for Least
//! Squares Problems* (SIAM 1996), §2.8 (scaling) and §1.4 (normal equations).
//!
//! **Standard deviations.** `σ̂² = RSS/(N − n)` and
//! `Cov(c) = σ̂² (AᵀA+λI)⁻¹ AᵀA (AᵀA+λI)⁻¹` (which is `σ̂² (AᵀA)⁻¹` for
//! `λ = 0`). These assume independent residuals; when the rows were
//! band-pass filtered the residuals are correlated, and the caller should
//! pass the effective number of independent rows to
//! [`NormalEquations::solve_with_dof`].

use crate::error::{EstError, Result};
use nalgebra::{DMatrix, DVector, SymmetricEigen};

/// Accumulated normal equations of a linear least-squares problem.
#[derive(Debug, Clone)]
pub struct NormalEquations {
    ata: DMatrix<f64>,
    aty: DVector<f64>,
    yty: f64,
    rows: usize,
}

/// The solution of a ridge least-squares problem with diagnostics.
#[derive(Debug, Clone)]
pub struct LsSolution {
    /// The coefficients `c`.
    pub coef: DVector<f64>,
    /// Standard deviation of each coefficient (see module docs).
    pub std: DVector<f64>,
    /// Residual sum of squares `‖y − A c‖²` (from the accumulated moments).
    pub rss: f64,
    /// Residual variance estimate `σ̂²`.
    pub sigma2: f64,
    /// Condition number of the equilibrated normal matrix `S` (without λ).
    pub condition: f64,
    /// Variance inflation factor of each coefficient, `(S⁻¹)_jj` (∞ if singular).
    pub vif: DVector<f64>,
    /// Eigenvalues of `S`, ascending.
    pub eigenvalues: DVector<f64>,
    /// Eigenvectors of `S` (columns, matching `eigenvalues`), in scaled units.
    pub eigenvectors: DMatrix<f64>,
    /// Rows used.
    pub rows: usize,
}

/// Above this scaled condition number a fit is reported as ill-conditioned
/// (relative coefficient error ~ κ·ε ≈ 1e-6 of the largest combination, and
/// noise amplification by √κ ≈ 3000).
pub const ILL_CONDITIONED: f64 = 1e7;

impl NormalEquations {
    /// Empty accumulator for `n` unknowns.
    pub fn new(n: usize) -> Self {
        Self {
            ata: DMatrix::zeros(n, n),
            aty: DVector::zeros(n),
            yty: 0.0,
            rows: 0,
        }
    }

    /// Number of unknowns.
    pub fn n(&self) -> usize {
        self.aty.len()
    }

    /// Rows accumulated so far.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Add one row `a` (length `n`) with observation `y` and weight `w`
    /// (1 for ordinary least squares). Rows with a non-finite value are an error.
    pub fn add_row(&mut self, a: &[f64], y: f64, w: f64) -> Result<()> {
        let n = self.n();
        if a.len() != n {
            return Err(EstError::Dimension(format!(
                "row of length {} for {n} unknowns",
                a.len()
            )));
        }
        if !y.is_finite() || !w.is_finite() || a.iter().any(|v| !v.is_finite()) {
            return Err(EstError::NonFinite {
                what: "least-squares row",
            });
        }
        // Upper triangle only; mirrored in `solve`.
        for i in 0..n {
            let wai = w * a[i];
            self.aty[i] += wai * y;
            for j in i..n {
                self.ata[(i, j)] += wai * a[j];
            }
        }
        self.yty += w * y * y;
        self.rows += 1;
        Ok(())
    }

    /// Add a block of rows stored column-major: `columns[j][k]` is row `k`,
    /// column `j`; `y[k]` the observations. Faster than row by row.
    /// Equivalent to [`Self::add_products`] of [`BlockProducts::of`].
    pub fn add_columns(&mut self, columns: &[&[f64]], y: &[f64]) -> Result<()> {
        let n = self.n();
        if columns.len() != n {
            return Err(EstError::Dimension(format!(
                "{} columns for {n} unknowns",
                columns.len()
            )));
        }
        self.add_products(&BlockProducts::of(columns, y)?)
    }

    /// Add the products of a block formed elsewhere (for example on
    /// another thread): the same bits as [`Self::add_columns`] of that
    /// block, since each sum of a run of rows is added in the same order.
    pub fn add_products(&mut self, p: &BlockProducts) -> Result<()> {
        let n = self.n();
        if p.n != n {
            return Err(EstError::Dimension(format!(
                "products of {} columns for {n} unknowns",
                p.n
            )));
        }
        for run in p.sums.chunks_exact(BlockProducts::per_run(n)) {
            let (aty, rest) = run.split_at(n);
            for (a, v) in self.aty.iter_mut().zip(aty) {
                *a += v;
            }
            let mut k = 0;
            for i in 0..n {
                for j in i..n {
                    self.ata[(i, j)] += rest[k];
                    k += 1;
                }
            }
            self.yty += rest[k];
        }
        self.rows += p.rows;
        Ok(())
    }

    /// Merge another accumulator (e.g. from another segment or thread).
    pub fn merge(&mut self, other: &NormalEquations) -> Result<()> {
        if other.n() != self.n() {
            return Err(EstError::Dimension(
                "merging accumulators of different size".into(),
            ));
        }
        self.ata += &other.ata;
        self.aty += &other.aty;
        self.yty += other.yty;
        self.rows += other.rows;
        Ok(())
    }

    /// The normal equations of the columns `keep` alone (indices into the
    /// unknowns, in the order given): the problem with the other columns
    /// left out, without another pass over the rows. Used to test which
    /// columns a fit needs (the residual of each sub-model is
    /// `yᵀy − cᵀ A_kᵀy`).
    pub fn subset(&self, keep: &[usize]) -> Result<NormalEquations> {
        let n = self.n();
        if let Some(&bad) = keep.iter().find(|&&j| j >= n) {
            return Err(EstError::Dimension(format!("column {bad} of {n} unknowns")));
        }
        let upper = |i: usize, j: usize| self.ata[(i.min(j), i.max(j))];
        let m = keep.len();
        Ok(NormalEquations {
            ata: DMatrix::from_fn(
                m,
                m,
                |a, b| if a <= b { upper(keep[a], keep[b]) } else { 0.0 },
            ),
            aty: DVector::from_fn(m, |a, _| self.aty[keep[a]]),
            yty: self.yty,
            rows: self.rows,
        })
    }

    /// The symmetric `AᵀA` (full matrix).
    pub fn ata(&self) -> DMatrix<f64> {
        let mut m = self.ata.clone();
        m.fill_lower_triangle_with_upper_triangle();
        m
    }

    /// `Aᵀy`.
    pub fn aty(&self) -> &DVector<f64> {
        &self.aty
    }

    /// `yᵀy`.
    pub fn yty(&self) -> f64 {
        self.yty
    }

    /// Solve with ridge parameter `lambda ≥ 0`, taking every row as independent.
    pub fn solve(&self, lambda: f64) -> Result<LsSolution> {
        self.solve_with_dof(lambda, self.rows as f64)
    }

    /// Solve with ridge parameter `lambda ≥ 0`; `effective_rows` is the number
    /// of independent rows used for `σ̂² = RSS/(effective_rows − n)` and the
    /// standard deviations (RSS is rescaled by `effective_rows/rows`).
    pub fn solve_with_dof(&self, lambda: f64, effective_rows: f64) -> Result<LsSolution> {
        let n = self.n();
        if !(lambda >= 0.0 && lambda.is_finite()) {
            return Err(EstError::Dimension(format!(
                "ridge parameter {lambda} must be finite and ≥ 0"
            )));
        }
        if self.rows < n || n == 0 {
            return Err(EstError::Underdetermined {
                rows: self.rows,
                unknowns: n,
            });
        }
        let ata = self.ata();
        // Equilibration; a zero column gets scale 1 (it is then exactly singular).
        let d: DVector<f64> = ata.diagonal().map(|v| if v > 0.0 { v.sqrt() } else { 1.0 });
        let s = DMatrix::from_fn(n, n, |i, j| ata[(i, j)] / (d[i] * d[j]));
        let eig = SymmetricEigen::new(s.clone());
        // Sort ascending.
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
        let w = DVector::from_iterator(n, order.iter().map(|&k| eig.eigenvalues[k]));
        let v = DMatrix::from_fn(n, n, |i, j| eig.eigenvectors[(i, order[j])]);
        let wmax = w[n - 1].max(f64::MIN_POSITIVE);
        let wmin = w[0];
        let condition = if wmin > 0.0 {
            wmax / wmin
        } else {
            f64::INFINITY
        };

        // Ridge in scaled units: S + λ D⁻².
        let ridge = DMatrix::from_diagonal(&d.map(|di| lambda / (di * di)));
        let s_reg = &s + ridge;
        let rhs = DVector::from_fn(n, |i, _| self.aty[i] / d[i]);
        let inv_reg = symmetric_inverse(&s_reg).ok_or_else(|| {
            EstError::Singular(format!(
                "normal matrix is singular (scaled condition number {condition:.3e})"
            ))
        })?;
        let u = &inv_reg * &rhs;
        let coef = DVector::from_fn(n, |i, _| u[i] / d[i]);

        // RSS = yᵀy − 2cᵀAᵀy + cᵀAᵀAc, clamped at 0 against round-off.
        let rss = (self.yty - 2.0 * coef.dot(&self.aty) + coef.dot(&(&ata * &coef))).max(0.0);
        let eff = effective_rows.min(self.rows as f64);
        let dof = (eff - n as f64).max(1.0);
        let sigma2 = rss * (eff / self.rows as f64) / dof;
        // Cov(u) = σ² S_reg⁻¹ S S_reg⁻¹ (scaled), Cov(c)_jj = Cov(u)_jj / d_j².
        let cov_u = &inv_reg * &s * &inv_reg;
        let std = DVector::from_fn(n, |i, _| (sigma2 * cov_u[(i, i)]).max(0.0).sqrt() / d[i]);
        let vif = match symmetric_inverse(&s) {
            Some(si) => si.diagonal(),
            None => DVector::from_element(n, f64::INFINITY),
        };
        Ok(LsSolution {
            coef,
            std,
            rss,
            sigma2,
            condition,
            vif,
            eigenvalues: w,
            eigenvectors: v,
            rows: self.rows,
        })
    }
}

impl LsSolution {
    /// Whether the scaled condition number exceeds [`ILL_CONDITIONED`].
    pub fn is_ill_conditioned(&self) -> bool {
        self.condition.is_nan() || self.condition >= ILL_CONDITIONED
    }

    /// Indices of unknowns whose variance inflation factor exceeds `max_vif`
    /// (e.g. 1e4: the unknown is largely a combination of the others).
    pub fn poorly_determined(&self, max_vif: f64) -> Vec<usize> {
        (0..self.vif.len())
            .filter(|&j| self.vif[j].is_nan() || self.vif[j] > max_vif)
            .collect()
    }

    /// The near-null directions: for each eigenvalue of the scaled normal
    /// matrix below `wmax / max_condition`, the eigenvector's entries (scaled
    /// units, unit norm) — a combination of unknowns the data cannot determine.
    pub fn null_directions(&self, max_condition: f64) -> Vec<Vec<f64>> {
        let n = self.eigenvalues.len();
        let wmax = self.eigenvalues[n - 1];
        (0..n)
            .filter(|&k| self.eigenvalues[k] < wmax / max_condition)
            .map(|k| self.eigenvectors.column(k).iter().copied().collect())
            .collect()
    }
}

/// Inverse of a symmetric positive (semi)definite matrix by Cholesky; `None`
/// when it is not positive definite to working precision.
fn symmetric_inverse(m: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let ch = m.clone().cholesky()?;
    let inv = ch.inverse();
    if inv.iter().all(|v| v.is_finite()) {
        Some(inv)
    } else {
        None
    }
}

/// The products `aᵢ·y`, `aᵢ·aⱼ` (i ≤ j) and `y·y` of a block of rows,
/// summed per run of [`ROW_BLOCK`] rows and not yet added to an
/// accumulator ([`NormalEquations::add_products`]): forming them is the
/// `O(rows × n²)` work, which can then run on several threads while the
/// accumulation keeps its order.
#[derive(Debug, Clone)]
pub struct BlockProducts {
    n: usize,
    rows: usize,
    /// Per run: `n` values of `aᵢ·y`, the upper triangle row by row, `y·y`.
    sums: Vec<f64>,
}

impl BlockProducts {
    fn per_run(n: usize) -> usize {
        n + n * (n + 1) / 2 + 1
    }

    /// The products of the block `columns` (column-major: `columns[j][k]`
    /// is row `k`, column `j`) with observations `y`. Errors: columns of
    /// unequal length, non-finite values.
    ///
    /// Non-finite values are found from the products themselves rather
    /// than in a pass of their own: a column's sum of squares over a run of
    /// rows is finite exactly when each of its values there is finite and
    /// none is so large (`|x| ≳ 10¹⁵⁴`) that its square overflows, which is
    /// an error too.
    pub fn of(columns: &[&[f64]], y: &[f64]) -> Result<BlockProducts> {
        let n = columns.len();
        let m = y.len();
        if columns.iter().any(|c| c.len() != m) {
            return Err(EstError::Dimension("columns of unequal length".into()));
        }
        // Rows in runs that stay in cache while all the products are
        // formed (instead of streaming every pair of columns from memory).
        // Column `n` is `y`; the products are those (i, j) with i ≤ j ≤ n,
        // formed in tiles of two columns against four, the rest four pairs
        // at a time. Each product is summed as [`dot`] sums, whatever the
        // grouping.
        let per = Self::per_run(n);
        let plan = ProductPlan::new(n);
        let mut sums = vec![0.0; m.div_ceil(ROW_BLOCK) * per];
        for (run, out) in sums.chunks_exact_mut(per).enumerate() {
            let (start, end) = (run * ROW_BLOCK, ((run + 1) * ROW_BLOCK).min(m));
            let block: Vec<&[f64]> = columns
                .iter()
                .map(|c| &c[start..end])
                .chain(std::iter::once(&y[start..end]))
                .collect();
            let len = end - start;
            for &(i, j) in &plan.tiles {
                let lanes = aeromag_core::simd::lane_dots(
                    [block[i], block[i + 1]],
                    [block[j], block[j + 1], block[j + 2], block[j + 3]],
                );
                for (r, row) in lanes.iter().enumerate() {
                    for (c, s) in row.iter().enumerate() {
                        out[plan.pos(i + r, j + c)] =
                            finish_dot(s, block[i + r], block[j + c], len);
                    }
                }
            }
            let mut quads = plan.pairs.chunks_exact(4);
            for q in quads.by_ref() {
                let lanes = aeromag_core::simd::lane_dots_pairs(
                    std::array::from_fn(|t| block[q[t].0]),
                    std::array::from_fn(|t| block[q[t].1]),
                );
                for (&(i, j), s) in q.iter().zip(&lanes) {
                    out[plan.pos(i, j)] = finish_dot(s, block[i], block[j], len);
                }
            }
            for &(i, j) in quads.remainder() {
                out[plan.pos(i, j)] = dot(block[i], block[j]);
            }
            if (0..=n).any(|i| !out[plan.pos(i, i)].is_finite()) {
                return Err(EstError::NonFinite {
                    what: "least-squares block",
                });
            }
        }
        Ok(BlockProducts { n, rows: m, sums })
    }

    /// Rows in the block.
    pub fn rows(&self) -> usize {
        self.rows
    }
}

/// Rows of a block of [`NormalEquations::add_columns`]: 20 columns of
/// 512 rows take 80 kB, which stays in a core's L2 cache.
const ROW_BLOCK: usize = 512;

/// Which products [`BlockProducts::of`] forms in tiles and which in
/// pairs, for `n` columns and `y` (column `n`).
struct ProductPlan {
    n: usize,
    /// Tiles: columns `i, i + 1` against `j .. j + 4` (all `≥ i + 1`).
    tiles: Vec<(usize, usize)>,
    /// The products `(i, j)`, `i ≤ j`, that are in no tile.
    pairs: Vec<(usize, usize)>,
}

impl ProductPlan {
    fn new(n: usize) -> Self {
        let (mut tiles, mut pairs) = (Vec::new(), Vec::new());
        let mut i = 0;
        while i + 1 < n {
            // Columns i and i + 1 share j = i + 1 ..= n.
            pairs.push((i, i));
            let mut j = i + 1;
            while j + 3 <= n {
                tiles.push((i, j));
                j += 4;
            }
            for j in j..=n {
                pairs.push((i, j));
                pairs.push((i + 1, j));
            }
            i += 2;
        }
        // The last column when n is odd, and y·y.
        for j in i..=n {
            pairs.push((i, j));
        }
        if i < n {
            pairs.push((n, n));
        }
        Self { n, tiles, pairs }
    }

    /// Where the product of columns `i ≤ j` goes in a run of
    /// [`BlockProducts::sums`]: `aᵢ·y` first, the triangle row by row,
    /// `y·y` last.
    fn pos(&self, i: usize, j: usize) -> usize {
        let n = self.n;
        if i == n {
            n + n * (n + 1) / 2
        } else if j == n {
            i
        } else {
            n + i * n - i * i.saturating_sub(1) / 2 + (j - i)
        }
    }
}

/// A dot product from its four lane sums (`s`, over the whole groups of
/// four of `len` rows) as [`dot`] finishes it: pairwise, then the rows left.
fn finish_dot(s: &[f64; 4], a: &[f64], b: &[f64], len: usize) -> f64 {
    let tail = 4 * (len / 4);
    let mut v = (s[0] + s[1]) + (s[2] + s[3]);
    for (x, y) in a[tail..len].iter().zip(&b[tail..len]) {
        v += x * y;
    }
    v
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    // Four accumulators: vectorises and halves round-off growth.
    let mut s = [0.0f64; 4];
    let chunks = a.len() / 4;
    for k in 0..chunks {
        for l in 0..4 {
            s[l] += a[4 * k + l] * b[4 * k + l];
        }
    }
    let mut t = (s[0] + s[1]) + (s[2] + s[3]);
    for k in 4 * chunks..a.len() {
        t += a[k] * b[k];
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, Normal};

    fn problem(n_rows: usize, seed: u64) -> (Vec<Vec<f64>>, Vec<f64>, Vec<f64>) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let nd = Normal::new(0.0, 1.0).unwrap();
        let truth = vec![1.5, -2.0, 0.25, 1e-3];
        let scales = [1.0, 1e3, 1e-2, 1e4];
        let cols: Vec<Vec<f64>> = (0..4)
            .map(|j| {
                (0..n_rows)
                    .map(|_| nd.sample(&mut rng) * scales[j])
                    .collect()
            })
            .collect();
        let y = (0..n_rows)
            .map(|k| {
                (0..4).map(|j| cols[j][k] * truth[j]).sum::<f64>() + 0.01 * nd.sample(&mut rng)
            })
            .collect();
        (cols, y, truth)
    }

    #[test]
    fn recovers_coefficients_and_their_spread() {
        let (cols, y, truth) = problem(5000, 1);
        let mut ne = NormalEquations::new(4);
        let refs: Vec<&[f64]> = cols.iter().map(|c| c.as_slice()).collect();
        ne.add_columns(&refs, &y).unwrap();
        let s = ne.solve(0.0).unwrap();
        for j in 0..4 {
            let z = (s.coef[j] - truth[j]) / s.std[j];
            assert!(z.abs() < 5.0, "coef {j}: z = {z}");
        }
        assert!((s.sigma2.sqrt() - 0.01).abs() < 0.001);
        // Scaling makes the badly scaled columns harmless.
        assert!(s.condition < 2.0, "condition {}", s.condition);
    }

    #[test]
    fn a_subset_is_the_fit_of_those_columns_alone() {
        let (cols, y, _) = problem(400, 3);
        let refs: Vec<&[f64]> = cols.iter().map(|c| c.as_slice()).collect();
        let mut all = NormalEquations::new(4);
        all.add_columns(&refs, &y).unwrap();
        let keep = [3, 0];
        let mut direct = NormalEquations::new(2);
        direct.add_columns(&[refs[3], refs[0]], &y).unwrap();
        let (a, b) = (
            all.subset(&keep).unwrap().solve(0.0).unwrap(),
            direct.solve(0.0).unwrap(),
        );
        for j in 0..2 {
            assert!(
                (a.coef[j] - b.coef[j]).abs() <= 1e-12 * b.coef[j].abs(),
                "{j}"
            );
        }
        assert!((a.rss - b.rss).abs() <= 1e-9 * b.rss);
        // Leaving out a column the data need raises the residual.
        assert!(a.rss > 10.0 * all.solve(0.0).unwrap().rss);
        assert!(all.subset(&[4]).is_err());
    }

    #[test]
    fn rows_blocks_and_merge_agree() {
        let (cols, y, _) = problem(300, 2);
        let mut a = NormalEquations::new(4);
        for k in 0..300 {
            let row: Vec<f64> = (0..4).map(|j| cols[j][k]).collect();
            a.add_row(&row, y[k], 1.0).unwrap();
        }
        let mut b = NormalEquations::new(4);
        let mut c = NormalEquations::new(4);
        let half = |r: std::ops::Range<usize>| -> Vec<Vec<f64>> {
            cols.iter().map(|cc| cc[r.clone()].to_vec()).collect()
        };
        let h1 = half(0..150);
        let h2 = half(150..300);
        b.add_columns(
            &h1.iter().map(|c| c.as_slice()).collect::<Vec<_>>(),
            &y[..150],
        )
        .unwrap();
        c.add_columns(
            &h2.iter().map(|c| c.as_slice()).collect::<Vec<_>>(),
            &y[150..],
        )
        .unwrap();
        b.merge(&c).unwrap();
        let sa = a.solve(0.5).unwrap();
        let sb = b.solve(0.5).unwrap();
        for j in 0..4 {
            assert!((sa.coef[j] - sb.coef[j]).abs() <= 1e-10 * sa.coef[j].abs().max(1e-12));
        }
    }

    /// Every product of a block, whatever tile or pair forms it, is the
    /// bits of `dot` on each run of rows, the runs added in order; for odd
    /// and even column counts and lengths that leave rows over.
    #[test]
    fn block_products_are_each_products_dot() {
        for n in 1..=10 {
            for len in [1, 3, 4, 7, 64, ROW_BLOCK + 3, 2 * ROW_BLOCK + 5] {
                let cols: Vec<Vec<f64>> = (0..=n)
                    .map(|j| {
                        (0..len)
                            .map(|k| ((k * (j + 2) + j) as f64 * 0.37).sin() * (1.0 + j as f64))
                            .collect()
                    })
                    .collect();
                let refs: Vec<&[f64]> = cols[..n].iter().map(|c| c.as_slice()).collect();
                let p = BlockProducts::of(&refs, &cols[n]).unwrap();
                let mut ne = NormalEquations::new(n);
                ne.add_products(&p).unwrap();
                let sum = |i: usize, j: usize| {
                    (0..len).step_by(ROW_BLOCK).fold(0.0, |acc, s| {
                        let e = (s + ROW_BLOCK).min(len);
                        acc + dot(&cols[i][s..e], &cols[j][s..e])
                    })
                };
                for i in 0..n {
                    assert_eq!(
                        ne.aty[i].to_bits(),
                        sum(i, n).to_bits(),
                        "n {n} len {len} a{i}·y"
                    );
                    for j in i..n {
                        assert_eq!(
                            ne.ata[(i, j)].to_bits(),
                            sum(i, j).to_bits(),
                            "n {n} len {len} a{i}·a{j}"
                        );
                    }
                }
                assert_eq!(ne.yty.to_bits(), sum(n, n).to_bits(), "n {n} len {len} y·y");
            }
        }
    }

    #[test]
    fn ridge_matches_direct_formula() {
        let (cols, y, _) = problem(200, 3);
        let mut ne = NormalEquations::new(4);
        ne.add_columns(&cols.iter().map(|c| c.as_slice()).collect::<Vec<_>>(), &y)
            .unwrap();
        let lambda = 7.0;
        let s = ne.solve(lambda).unwrap();
        let a = DMatrix::from_fn(200, 4, |i, j| cols[j][i]);
        let yv = DVector::from_column_slice(&y);
        let direct = (a.transpose() * &a + DMatrix::identity(4, 4) * lambda)
            .lu()
            .solve(&(a.transpose() * yv))
            .unwrap();
        for j in 0..4 {
            assert!(
                (s.coef[j] - direct[j]).abs() <= 1e-9 * direct[j].abs().max(1e-9),
                "{j}"
            );
        }
    }

    #[test]
    fn collinear_columns_are_reported() {
        let (mut cols, y, _) = problem(400, 4);
        // Column 3 = column 0 + tiny noise: nearly collinear.
        cols[3] = cols[0]
            .iter()
            .enumerate()
            .map(|(k, v)| v + 1e-7 * ((k % 7) as f64 - 3.0))
            .collect();
        let mut ne = NormalEquations::new(4);
        ne.add_columns(&cols.iter().map(|c| c.as_slice()).collect::<Vec<_>>(), &y)
            .unwrap();
        let s = ne.solve(0.0).unwrap();
        assert!(s.is_ill_conditioned());
        let bad = s.poorly_determined(1e4);
        assert_eq!(bad, vec![0, 3]);
        let null = s.null_directions(1e7);
        assert_eq!(null.len(), 1);
        assert!((null[0][0].abs() - std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-3);
    }

    #[test]
    fn bad_input_is_an_error() {
        let mut ne = NormalEquations::new(2);
        assert!(ne.add_row(&[1.0], 1.0, 1.0).is_err());
        assert!(ne.add_row(&[1.0, f64::NAN], 1.0, 1.0).is_err());
        ne.add_row(&[1.0, 2.0], 1.0, 1.0).unwrap();
        assert!(matches!(
            ne.solve(0.0),
            Err(EstError::Underdetermined { .. })
        ));
        assert!(ne.solve(-1.0).is_err());
    }

    /// A block with a NaN, an infinity or a value whose square overflows,
    /// in any column or `y`, at the start, the end, on either side of a
    /// run's boundary, or in the rows after the last whole group of four,
    /// is an error; every finite block that does not overflow is not.
    #[test]
    fn block_products_find_every_non_finite_value() {
        let m = 2 * ROW_BLOCK + 7;
        let cols: Vec<Vec<f64>> = (0..6)
            .map(|j| {
                (0..m)
                    .map(|k| ((k * (j + 2)) as f64 * 0.37).sin() * 1e3)
                    .collect()
            })
            .collect();
        let of = |cols: &[Vec<f64>]| {
            let refs: Vec<&[f64]> = cols[..5].iter().map(|c| c.as_slice()).collect();
            BlockProducts::of(&refs, &cols[5])
        };
        assert!(of(&cols).is_ok());
        for j in 0..6 {
            for k in [0, ROW_BLOCK - 1, ROW_BLOCK, 2 * ROW_BLOCK + 2, m - 1] {
                for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e200] {
                    let mut c = cols.clone();
                    c[j][k] = bad;
                    assert!(
                        matches!(of(&c), Err(EstError::NonFinite { .. })),
                        "column {j}, row {k}, {bad}"
                    );
                }
            }
        }
    }
}
