//! The square-root covariance Kalman filter: state `x`, upper-triangular
//! factor `S` with `P = S Sᵀ`, scalar sequential measurement updates
//! (Carlson) and time updates by re-triangularisation (Householder RQ).
//!
//! ## Model
//!
//! ```text
//! x_k = Φ_k x_{k−1} + G_k w_k,      w_k ~ N(0, I_q)       (Q_k = G_k G_kᵀ)
//! y_k = h_kᵀ x_k + v_k,             v_k ~ N(0, r_k)       (one or more scalars per step)
//! ```
//!
//! `Φ_k` and `G_k` come from the caller's exact discretisation of the
//! continuous model (e.g. `Φ = e^{AΔ}`, `Q = ∫₀^Δ e^{As} B Bᵀ e^{Aᵀs} ds`, and
//! `G` any factor of `Q`, such as its Cholesky factor). Correlated vector
//! measurements are decorrelated by the caller (or processed as scalars when
//! their noises are independent), so only scalar updates are needed: no
//! matrix is ever inverted (Bierman 1977, ch. V).
//!
//! ## Steps
//!
//! * [`SqrtKalmanFilter::update`]: Carlson's triangular update
//!   ([`super::carlson`]), `O(n²)`.
//! * [`SqrtKalmanFilter::predict`]: `x ← Φx`, `S ← tri([G, ΦS])`
//!   ([`super::triangularize`]), `O(n³)`. When `Φ` and `G` (`n × n`) are
//!   both upper triangular, as for chains of integrators with the upper
//!   factor of `Q`, `[G, ΦS]` is a pair of triangles and the cheaper
//!   [`super::triangularize::triangularize_upper_pair`] is used (detected
//!   from the matrices; same result up to round-off); for 5, 6 or 8
//!   states (the field models) the same operations run as the lanes'
//!   kernel one lane wide ([`super::lanes`]), the same bits.
//! * [`SqrtKalmanFilter::predict_leading`]: when only the first `k` states
//!   evolve and the others are constant parameters (`Φ = diag(Φ_a, I)`,
//!   `G = [G_a; 0]`), the time update is exact and cheap *because the constant
//!   states are ordered last*: with `S = [[U_a, U_b], [0, U_c]]`,
//!
//!   ```text
//!   [G, Φ S] = [[G_a, Φ_a U_a, Φ_a U_b], [0, 0, U_c]]  →  S⁺ = [[tri([G_a, Φ_a U_a]), Φ_a U_b], [0, U_c]]
//!   ```
//!
//!   since the columns `[G_a, Φ_a U_a]` are zero in the rows of the constant
//!   states, rotating them among themselves leaves those rows alone. Cost
//!   `O(k²(n − k) + k³)` instead of `O(n³)` (Bierman 1977, §VI.4, "bias"
//!   states last). The covariance of the trailing constant block is
//!   `U_c U_cᵀ` ([`SqrtKalmanFilter::trailing_covariance`]).
//! * [`SqrtKalmanFilter::reset_leading`]: replace the leading states by a
//!   fresh prior independent of everything else (set `U_a`, zero `U_b`); the
//!   marginal of the trailing block is unchanged.
//!
//! Work buffers are allocated on construction (and grown once if a larger
//! noise dimension appears); steps do not allocate.

use super::carlson::carlson_update;
use super::innovation::Innovation;
use super::lanes::Predict;
use super::triangularize::{triangularize_upper, triangularize_upper_pair};
use crate::error::{EstError, Result};
use nalgebra::{DMatrix, DVector};

/// A square-root covariance Kalman filter (see the module docs).
#[derive(Debug, Clone)]
pub struct SqrtKalmanFilter {
    x: DVector<f64>,
    s: DMatrix<f64>,
    gain: Vec<f64>,
    work: Vec<f64>,
    wide: Vec<f64>,
    v: Vec<f64>,
    tmp: Vec<f64>,
    nz: Vec<(usize, usize, f64)>,
    /// Whether every entry of `nz` is on or above the diagonal.
    nz_upper: bool,
    phi_upper: Vec<f64>,
}

impl SqrtKalmanFilter {
    /// A filter with prior mean `x0` and upper-triangular factor `s0`
    /// (`P0 = S0 S0ᵀ`; the strictly lower part of `s0` is ignored).
    pub fn new(x0: &[f64], s0: &DMatrix<f64>) -> Result<Self> {
        let n = x0.len();
        if s0.nrows() != n || s0.ncols() != n {
            return Err(EstError::Dimension(format!(
                "prior factor {}×{} for {n} states",
                s0.nrows(),
                s0.ncols()
            )));
        }
        if x0.iter().any(|v| !v.is_finite()) || s0.iter().any(|v| !v.is_finite()) {
            return Err(EstError::NonFinite {
                what: "prior mean or factor",
            });
        }
        let s = DMatrix::from_fn(n, n, |i, j| if i <= j { s0[(i, j)] } else { 0.0 });
        Ok(Self {
            x: DVector::from_column_slice(x0),
            s,
            gain: vec![0.0; n],
            work: vec![0.0; 3 * n],
            wide: vec![0.0; n * 2 * n.max(1)],
            v: vec![0.0; 2 * n.max(1)],
            tmp: vec![0.0; n],
            nz: Vec::with_capacity(n * n),
            nz_upper: true,
            phi_upper: Vec::with_capacity(n * n),
        })
    }

    /// A filter with prior mean `x0` and covariance `p0` (symmetric positive
    /// definite; factored with [`upper_cholesky`]).
    pub fn from_covariance(x0: &[f64], p0: &DMatrix<f64>) -> Result<Self> {
        Self::new(x0, &upper_cholesky(p0)?)
    }

    /// Number of states `n`.
    pub fn dim(&self) -> usize {
        self.x.len()
    }

    /// The state estimate.
    pub fn state(&self) -> &DVector<f64> {
        &self.x
    }

    /// The upper-triangular factor `S` (`P = S Sᵀ`).
    pub fn factor(&self) -> &DMatrix<f64> {
        &self.s
    }

    /// The covariance `P = S Sᵀ` (allocates).
    pub fn covariance(&self) -> DMatrix<f64> {
        &self.s * self.s.transpose()
    }

    /// The variance `P_ii = Σ_{j ≥ i} S_ij²`.
    pub fn variance(&self, i: usize) -> f64 {
        (i..self.dim())
            .map(|j| self.s[(i, j)] * self.s[(i, j)])
            .sum()
    }

    /// The covariance of the trailing states `from..n`, `U_c U_cᵀ` (exact:
    /// those rows of `S` vanish left of column `from`).
    pub fn trailing_covariance(&self, from: usize) -> DMatrix<f64> {
        let u = self
            .s
            .view((from, from), (self.dim() - from, self.dim() - from));
        u * u.transpose()
    }

    /// Replace the state and factor (same dimension; lower part ignored).
    pub fn set(&mut self, x: &[f64], s: &DMatrix<f64>) -> Result<()> {
        let n = self.dim();
        if x.len() != n || s.nrows() != n || s.ncols() != n {
            return Err(EstError::Dimension(
                "set: state or factor of another size".into(),
            ));
        }
        self.x.copy_from_slice(x);
        for j in 0..n {
            for i in 0..n {
                self.s[(i, j)] = if i <= j { s[(i, j)] } else { 0.0 };
            }
        }
        Ok(())
    }

    /// Scalar measurement update with row `h`, value `y` and noise variance
    /// `r > 0` (Carlson). Returns the innovation; on error nothing changes.
    pub fn update(&mut self, h: &[f64], y: f64, r: f64) -> Result<Innovation> {
        carlson_update(
            self.s.as_mut_slice(),
            self.x.as_mut_slice(),
            h,
            y,
            r,
            &mut self.gain,
            &mut self.work,
        )
    }

    /// The innovation that [`update`](Self::update) with row `h`, value
    /// `y` and noise variance `r` would have, `ν = y − hᵀx`,
    /// `σ² = |Sᵀh|² + r`, without updating: for a caller that leaves out an
    /// outlier before it enters the estimate.
    pub fn innovation(&self, h: &[f64], y: f64, r: f64) -> Result<Innovation> {
        let n = self.dim();
        if h.len() != n {
            return Err(EstError::Dimension("measurement row length".into()));
        }
        let mut variance = r;
        for j in 0..n {
            let f: f64 = (0..=j).map(|i| self.s[(i, j)] * h[i]).sum();
            variance += f * f;
        }
        let predicted: f64 = h.iter().zip(self.x.iter()).map(|(a, b)| a * b).sum();
        Ok(Innovation {
            value: y - predicted,
            variance,
        })
    }

    /// The Kalman gain `P⁻h/α` of the last [`update`](Self::update).
    pub fn last_gain(&self) -> &[f64] {
        &self.gain
    }

    /// Time update with transition `Φ` (`n × n`) and noise factor `G`
    /// (`n × q`, `Q = G Gᵀ`, `q` may be 0): `x ← Φx`, `S ← tri([G, ΦS])`.
    pub fn predict(&mut self, phi: &DMatrix<f64>, g: &DMatrix<f64>) -> Result<()> {
        let n = self.dim();
        if phi.nrows() != n || phi.ncols() != n || g.nrows() != n {
            return Err(EstError::Dimension(format!(
                "predict: Φ {}×{}, G {}×{} for {n} states",
                phi.nrows(),
                phi.ncols(),
                g.nrows(),
                g.ncols()
            )));
        }
        self.collect_nonzeros(phi);
        self.propagate_block(n, g);
        Ok(())
    }

    /// Time update when only the first `k` states evolve (`Φ_a`, `k × k`;
    /// `G_a`, `k × q`) and the states `k..n` are constant (module docs).
    pub fn predict_leading(&mut self, phi_a: &DMatrix<f64>, g_a: &DMatrix<f64>) -> Result<()> {
        let n = self.dim();
        let k = phi_a.nrows();
        if k > n || phi_a.ncols() != k || g_a.nrows() != k {
            return Err(EstError::Dimension(format!(
                "predict_leading: Φ_a {}×{}, G_a {}×{} for {n} states",
                phi_a.nrows(),
                phi_a.ncols(),
                g_a.nrows(),
                g_a.ncols()
            )));
        }
        self.collect_nonzeros(phi_a);
        // U_b ← Φ_a U_b, column by column (each column of U_b is contiguous
        // in the column-major factor).
        let s = self.s.as_mut_slice();
        if self.nz_upper {
            // Φ_a upper triangular: dense row-major copy of its upper part,
            // then in place, rows ascending, each from rows not yet updated:
            // col_i ← Σ_{l ≥ i} Φ_il col_l.
            let dense = &mut self.phi_upper;
            dense.clear();
            dense.resize(k * k, 0.0);
            for &(i, l, p) in &self.nz {
                dense[i * k + l] = p;
            }
            match k {
                5 => aeromag_core::simd::run(UpperTimesColumns::<5> { phi: dense, s, n }),
                6 => aeromag_core::simd::run(UpperTimesColumns::<6> { phi: dense, s, n }),
                8 => aeromag_core::simd::run(UpperTimesColumns::<8> { phi: dense, s, n }),
                _ => {
                    // Workspace in `wide`, which propagate_block refills next.
                    if self.wide.len() < k * k + 2 * k {
                        self.wide.resize(k * k + 2 * k, 0.0);
                    }
                    let (by_col, rest) = self.wide.split_at_mut(k * k);
                    let (c, out) = rest.split_at_mut(k);
                    upper_times_columns(k, dense, s, n, by_col, c, out);
                }
            }
        } else {
            let tmp = &mut self.tmp[..k];
            for j in k..n {
                let col = &mut s[j * n..j * n + k];
                tmp.fill(0.0);
                for &(i, l, p) in &self.nz {
                    tmp[i] += p * col[l];
                }
                col.copy_from_slice(tmp);
            }
        }
        self.propagate_block(k, g_a);
        Ok(())
    }

    /// The non-zero entries `(i, l, Φ_il)` of `phi` into `self.nz`, and
    /// whether `phi` is upper triangular into `self.nz_upper`.
    fn collect_nonzeros(&mut self, phi: &DMatrix<f64>) {
        self.nz.clear();
        self.nz_upper = true;
        let k = phi.nrows();
        for (l, col) in phi.as_slice().chunks_exact(k).enumerate() {
            for (i, &p) in col.iter().enumerate() {
                if p != 0.0 {
                    self.nz_upper &= i <= l;
                    self.nz.push((i, l, p));
                }
            }
        }
    }

    /// `x_a ← Φ_a x_a`, `U_a ← tri([G_a, Φ_a U_a])` on the leading `k`
    /// states, with `Φ_a` given by its non-zeros in `self.nz`.
    fn propagate_block(&mut self, k: usize, g: &DMatrix<f64>) {
        let c = g.ncols() + k;
        if self.wide.len() < k * c {
            self.wide.resize(k * c, 0.0);
        }
        if self.v.len() < c {
            self.v.resize(c, 0.0);
        }
        // The field models of orders 3, 4 and 6 (5, 6 and 8 states, Φ and
        // G upper triangular): the factor by the lanes' kernel, one lane
        // wide; otherwise the same code specialised by the compiler.
        let pair = self.upper_pair(k, g.ncols(), g.as_slice());
        match (k, g.ncols()) {
            (5, 5) if pair => self.propagate_fixed::<5>(g.as_slice()),
            (6, 6) if pair => self.propagate_fixed::<6>(g.as_slice()),
            (8, 8) if pair => self.propagate_fixed::<8>(g.as_slice()),
            (5, 5) => self.propagate_impl(5, 5, g.as_slice()),
            (6, 6) => self.propagate_impl(6, 6, g.as_slice()),
            (8, 8) => self.propagate_impl(8, 8, g.as_slice()),
            _ => self.propagate_impl(k, g.ncols(), g.as_slice()),
        }
    }

    /// `x_a ← Φ_a x_a` on the leading `k` states, `Φ_a` by its non-zeros
    /// in `self.nz` (each entry summed from +0 in their order).
    fn advance_mean(&mut self, k: usize) {
        let tmp = &mut self.tmp[..k];
        tmp.fill(0.0);
        let x = self.x.as_mut_slice();
        for &(i, l, p) in &self.nz {
            tmp[i] += p * x[l];
        }
        x[..k].copy_from_slice(tmp);
    }

    /// Whether `[G_a, Φ_a U_a]` is a pair of triangles: `G_a` (`k × q`,
    /// column-major in `g`) square and upper triangular, `Φ_a` (in
    /// `self.nz`) upper triangular.
    fn upper_pair(&self, k: usize, q: usize, g: &[f64]) -> bool {
        q == k
            && self.nz_upper
            && (0..k).all(|j| g[j * k + j + 1..(j + 1) * k].iter().all(|x| *x == 0.0))
    }

    /// [`Self::propagate_impl`] for `K` leading states with `Φ_a` (in
    /// `self.nz`) and `G_a` (`K × K`) both upper triangular: `x_a ← Φ_a
    /// x_a` as there, `U_a ← tri([G_a, Φ_a U_a])` by the lanes' kernel one
    /// lane wide ([`super::lanes`]: the operations of the pair
    /// triangularisation in their order, the same bits; with the products
    /// of a zero block between two chains left out). Test
    /// `the_fixed_time_update_is_the_general_one_bit_for_bit`.
    fn propagate_fixed<const K: usize>(&mut self, g: &[f64]) {
        let n = self.dim();
        self.advance_mean(K);
        let mut phi = [[[0.0; 1]; K]; K];
        for &(i, l, p) in &self.nz {
            phi[i][l][0] = p;
        }
        let s = self.s.as_mut_slice();
        let mut u = [[[0.0; 1]; K]; K];
        let mut gl = [[[0.0; 1]; K]; K];
        for j in 0..K {
            for i in 0..=j {
                u[j][i][0] = s[i + j * n];
                gl[i][j][0] = g[i + j * K];
            }
        }
        // Two chains: Φ zero between states 0..K−2 and K−2..K.
        let two = K > 2 && (0..K - 2).all(|i| (K - 2..K).all(|j| phi[i][j][0] == 0.0));
        // One lane: nothing for AVX to widen (and its dispatch measured
        // slower).
        use aeromag_core::simd::Kernel;
        if two {
            Predict::<K, 1, true> {
                u: &mut u,
                phi: &phi,
                g: &mut gl,
                moving: [true],
            }
            .run()
        } else {
            Predict::<K, 1, false> {
                u: &mut u,
                phi: &phi,
                g: &mut gl,
                moving: [true],
            }
            .run()
        }
        for j in 0..K {
            for i in 0..K {
                s[i + j * n] = if i <= j { u[j][i][0] } else { 0.0 };
            }
        }
    }

    #[inline(always)]
    fn propagate_impl(&mut self, k: usize, q: usize, g: &[f64]) {
        let n = self.dim();
        let c = q + k;
        // Φ and G both upper triangular (and U_a always is): the cheaper
        // kernel for two triangular halves.
        let pair = self.upper_pair(k, q, g);
        self.advance_mean(k);
        // wide (row-major k × (q+k)) = [G, Φ U_a]; U_a upper triangular.
        let w = &mut self.wide[..k * c];
        w.fill(0.0);
        let g = &g[..k * q];
        for i in 0..k {
            for j in 0..q {
                w[i * c + j] = g[i + j * k];
            }
        }
        let s = self.s.as_mut_slice();
        for &(i, l, p) in &self.nz {
            for j in l..k {
                w[i * c + q + j] += p * s[l + j * n];
            }
        }
        if pair {
            triangularize_upper_pair(w, k, &mut self.v[..c]);
        } else {
            triangularize_upper(w, k, c, &mut self.v[..c]);
        }
        for j in 0..k {
            for i in 0..=j {
                s[i + j * n] = w[i * c + q + j];
            }
            for i in j + 1..k {
                s[i + j * n] = 0.0;
            }
        }
    }

    /// Replace the first `k = x_a.len()` states by a fresh prior (mean
    /// `x_a`, upper factor `s_a`, lower part ignored) independent of the
    /// other states: `U_a ← s_a`, `U_b ← 0`. The trailing block's marginal
    /// is unchanged.
    pub fn reset_leading(&mut self, x_a: &[f64], s_a: &DMatrix<f64>) -> Result<()> {
        let n = self.dim();
        let k = x_a.len();
        if k > n || s_a.nrows() != k || s_a.ncols() != k {
            return Err(EstError::Dimension(format!(
                "reset_leading: {k} states, factor {}×{}",
                s_a.nrows(),
                s_a.ncols()
            )));
        }
        if x_a.iter().any(|v| !v.is_finite()) || s_a.iter().any(|v| !v.is_finite()) {
            return Err(EstError::NonFinite {
                what: "reset prior",
            });
        }
        self.x.as_mut_slice()[..k].copy_from_slice(x_a);
        for j in 0..n {
            for i in 0..k {
                self.s[(i, j)] = if j < k && i <= j { s_a[(i, j)] } else { 0.0 };
            }
        }
        Ok(())
    }
}

/// `U_b ← Φ U_b` for an upper-triangular `Φ` (`k × k`, row-major in
/// `phi`) on the columns `k..n` of the column-major `n × n` factor `s`.
/// Each column's new entries are formed together, `out[..=l] += Φ[..=l, l]
/// c_l` for `l` ascending (runs of rows in SIMD lanes), each entry summed
/// as `Σ_{l ≥ i} Φ_il c_l` from 0 in ascending `l`. `by_col` (`k²`), `c`
/// and `out` (`k` each) are workspace.
#[inline(always)]
fn upper_times_columns(
    k: usize,
    phi: &[f64],
    s: &mut [f64],
    n: usize,
    by_col: &mut [f64],
    c: &mut [f64],
    out: &mut [f64],
) {
    // Φ by columns: by_col[l k + i] = Φ_il (i ≤ l; the rest is not read).
    for (i, row) in phi[..k * k].chunks_exact(k).enumerate() {
        for l in i..k {
            by_col[l * k + i] = row[l];
        }
    }
    let (c, out) = (&mut c[..k], &mut out[..k]);
    for j in k..n {
        let col = &mut s[j * n..j * n + k];
        c.copy_from_slice(col);
        out.fill(0.0);
        for l in 0..k {
            let cl = c[l];
            for (o, p) in out[..=l].iter_mut().zip(&by_col[l * k..=l * k + l]) {
                *o += p * cl;
            }
        }
        col.copy_from_slice(out);
    }
}

/// [`upper_times_columns`] for `K` leading states (the field models of
/// orders 3, 4 and 6), its workspace on the stack, as a
/// [`aeromag_core::simd::Kernel`] (AVX where the processor has it).
struct UpperTimesColumns<'a, const K: usize> {
    phi: &'a [f64],
    s: &'a mut [f64],
    n: usize,
}

impl<const K: usize> aeromag_core::simd::Kernel for UpperTimesColumns<'_, K> {
    type Output = ();
    #[inline(always)]
    fn run(self) {
        let mut by_col = [[0.0f64; K]; K];
        let (mut c, mut out) = ([0.0f64; K], [0.0f64; K]);
        upper_times_columns(
            K,
            self.phi,
            self.s,
            self.n,
            by_col.as_flattened_mut(),
            &mut c,
            &mut out,
        );
    }
}

/// The distribution of the leading `k` states given the trailing ones
/// (module docs of [`SqrtKalmanFilter::leading_conditional`]).
#[derive(Debug, Clone, PartialEq)]
pub struct LeadingConditional {
    /// `x̂_a`, the current estimate of the leading states.
    pub mean: Vec<f64>,
    /// `U_a`: `Cov(x_a | x_b) = U_a U_aᵀ` (upper triangular, `k × k`).
    pub factor: DMatrix<f64>,
    /// `W = U_b U_c⁻¹` (`k × (n−k)`).
    pub weight: DMatrix<f64>,
    /// `x̂_b`, the current estimate of the trailing states.
    pub trailing_mean: Vec<f64>,
}

impl LeadingConditional {
    /// `E[x_a | x_b] = x̂_a + W (x_b − x̂_b)`.
    pub fn mean_given(&self, x_b: &[f64]) -> Vec<f64> {
        let mut m = self.mean.clone();
        for (j, (xb, mb)) in x_b.iter().zip(&self.trailing_mean).enumerate() {
            let d = xb - mb;
            for (i, mi) in m.iter_mut().enumerate() {
                *mi += self.weight[(i, j)] * d;
            }
        }
        m
    }
}

impl SqrtKalmanFilter {
    /// The conditional distribution of the first `k` states given the others.
    ///
    /// With `S = [[U_a, U_b], [0, U_c]]`: `Cov(x_a, x_b) = U_b U_cᵀ`,
    /// `Cov(x_b) = U_c U_cᵀ`, so
    ///
    /// ```text
    /// E[x_a | x_b] = x̂_a + U_b U_c⁻¹ (x_b − x̂_b),    Cov(x_a | x_b) = U_a U_aᵀ
    /// ```
    ///
    /// (the Schur complement is the leading block of the triangular factor).
    /// When the trailing states are constant parameters, this is what a
    /// filter of the leading states alone would give if the parameters were
    /// known — a restart point ([`super::Checkpoint`]) for smoothing the
    /// leading states once the parameters are estimated. Error if `U_c` is
    /// singular.
    pub fn leading_conditional(&self, k: usize) -> Result<LeadingConditional> {
        let n = self.dim();
        if k > n {
            return Err(EstError::Dimension(format!(
                "leading_conditional: {k} of {n} states"
            )));
        }
        let u_b = self.s.view((0, k), (k, n - k));
        let u_c = self.s.view((k, k), (n - k, n - k)).into_owned();
        // W U_c = U_b  ⇔  U_cᵀ Wᵀ = U_bᵀ.
        let wt = u_c
            .tr_solve_upper_triangular(&u_b.transpose())
            .ok_or_else(|| EstError::Singular("trailing covariance factor is singular".into()))?;
        Ok(LeadingConditional {
            mean: self.x.as_slice()[..k].to_vec(),
            factor: self.s.view((0, 0), (k, k)).into_owned(),
            weight: wt.transpose(),
            trailing_mean: self.x.as_slice()[k..].to_vec(),
        })
    }
}

/// The upper-triangular factor `U` of a symmetric positive definite `P`,
/// `P = U Uᵀ` (the "reverse" Cholesky factor: Cholesky of `P` with rows and
/// columns in reverse order, then reversed back).
pub fn upper_cholesky(p: &DMatrix<f64>) -> Result<DMatrix<f64>> {
    let n = p.nrows();
    if p.ncols() != n {
        return Err(EstError::Dimension(format!(
            "covariance {}×{} is not square",
            n,
            p.ncols()
        )));
    }
    if p.iter().any(|v| !v.is_finite()) {
        return Err(EstError::NonFinite { what: "covariance" });
    }
    let rev = DMatrix::from_fn(n, n, |i, j| {
        0.5 * (p[(n - 1 - i, n - 1 - j)] + p[(n - 1 - j, n - 1 - i)])
    });
    let l = rev
        .cholesky()
        .ok_or_else(|| EstError::Singular("covariance is not positive definite".into()))?
        .unpack();
    Ok(DMatrix::from_fn(n, n, |i, j| l[(n - 1 - i, n - 1 - j)]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn upper_cholesky_factors() {
        let p = DMatrix::from_row_slice(3, 3, &[4.0, 1.0, 0.5, 1.0, 3.0, -0.2, 0.5, -0.2, 2.0]);
        let u = upper_cholesky(&p).unwrap();
        assert!((&u * u.transpose() - &p).abs().max() < 1e-14);
        assert_eq!(u[(1, 0)], 0.0);
        assert_eq!(u[(2, 1)], 0.0);
        assert!(upper_cholesky(&DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0])).is_err());
    }

    #[test]
    fn leading_prediction_equals_the_full_one() {
        let p0 = DMatrix::from_fn(5, 5, |i, j| {
            if i == j {
                2.0 + i as f64
            } else {
                0.3 / (1.0 + (i + j) as f64)
            }
        });
        let x0 = [1.0, -2.0, 0.5, 3.0, -1.0];
        let mut a = SqrtKalmanFilter::from_covariance(&x0, &p0).unwrap();
        let mut b = a.clone();
        a.update(&[1.0, 0.2, 0.0, -0.4, 0.7], 0.3, 0.5).unwrap();
        b.update(&[1.0, 0.2, 0.0, -0.4, 0.7], 0.3, 0.5).unwrap();
        let phi_a = DMatrix::from_row_slice(2, 2, &[1.0, 0.5, 0.0, 1.0]);
        let g_a = DMatrix::from_row_slice(2, 2, &[0.1, 0.0, 0.05, 0.2]);
        a.predict_leading(&phi_a, &g_a).unwrap();
        let mut phi = DMatrix::identity(5, 5);
        phi.view_mut((0, 0), (2, 2)).copy_from(&phi_a);
        let mut g = DMatrix::zeros(5, 2);
        g.view_mut((0, 0), (2, 2)).copy_from(&g_a);
        b.predict(&phi, &g).unwrap();
        assert!((a.covariance() - b.covariance()).abs().max() < 1e-13);
        assert!((a.state() - b.state()).abs().max() < 1e-15);
        assert!(
            (a.trailing_covariance(2) - b.covariance().view((2, 2), (3, 3)))
                .abs()
                .max()
                < 1e-13
        );
    }

    /// The time update of 5, 6 and 8 leading states with `Φ` and `G` upper
    /// triangular (the lanes' kernel one lane wide) is the general code's
    /// (`propagate_impl` with the pair triangularisation) to the bit: dense
    /// and two-chain transitions, zero steps (`Φ = I`, `G = 0`), alone and
    /// as the leading block of a larger filter.
    #[test]
    fn the_fixed_time_update_is_the_general_one_bit_for_bit() {
        fn check<const K: usize>(extra: usize, two: bool, seed: u64) {
            let mut seed = seed;
            let mut rnd = move || {
                seed = seed
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
            };
            let n = K + extra;
            let cross = |i: usize, j: usize| two && i < K - 2 && j >= K - 2;
            let s0 = DMatrix::from_fn(n, n, |i, j| {
                if i <= j {
                    0.3 + (i + 2 * j) as f64 * 0.1
                } else {
                    0.0
                }
            });
            let x0: Vec<f64> = (0..n).map(|i| i as f64 - 2.0).collect();
            let mut a = SqrtKalmanFilter::new(&x0, &s0).unwrap();
            let mut h = vec![0.0; n];
            for step in 0..200 {
                let d = if step % 13 == 4 { 0.0 } else { 0.5 + rnd() };
                let phi = DMatrix::from_fn(K, K, |i, j| {
                    if i == j {
                        1.0
                    } else if i < j && !cross(i, j) {
                        d.powi((j - i) as i32)
                    } else {
                        0.0
                    }
                });
                let g = DMatrix::from_fn(K, K, |i, j| {
                    if i <= j && !cross(i, j) {
                        0.1 * d * (1.0 + rnd())
                    } else {
                        0.0
                    }
                });
                let mut b = a.clone();
                a.collect_nonzeros(&phi);
                a.propagate_fixed::<K>(g.as_slice());
                b.collect_nonzeros(&phi);
                b.propagate_impl(K, K, g.as_slice());
                let bits = |f: &SqrtKalmanFilter| {
                    f.state()
                        .iter()
                        .chain(f.factor().iter())
                        .map(|v| v.to_bits())
                        .collect::<Vec<_>>()
                };
                assert_eq!(
                    bits(&a),
                    bits(&b),
                    "K {K}, extra {extra}, two {two}, step {step}"
                );
                for (i, v) in h.iter_mut().enumerate() {
                    *v = if i == 0 || i == K - 2 || i >= K {
                        1.0 + rnd()
                    } else {
                        0.0
                    };
                }
                a.update(&h, rnd(), 0.05).unwrap();
            }
        }
        for two in [false, true] {
            check::<5>(0, two, 1);
            check::<6>(0, two, 2);
            check::<8>(0, two, 3);
            check::<8>(16, two, 4);
        }
    }

    #[test]
    fn reset_leading_keeps_the_trailing_marginal() {
        let p0 = DMatrix::from_fn(4, 4, |i, j| if i == j { 1.0 } else { 0.4 });
        let mut f = SqrtKalmanFilter::from_covariance(&[0.0; 4], &p0).unwrap();
        f.update(&[1.0, 1.0, 0.5, 0.2], 1.0, 0.1).unwrap();
        let before = f.trailing_covariance(2);
        f.reset_leading(&[5.0, 6.0], &DMatrix::from_diagonal_element(2, 2, 10.0))
            .unwrap();
        let p = f.covariance();
        assert!((p.view((2, 2), (2, 2)) - &before).abs().max() < 1e-15);
        assert_eq!(p.view((0, 2), (2, 2)).abs().max(), 0.0);
        assert!((p[(0, 0)] - 100.0).abs() < 1e-12);
        assert_eq!(f.state()[1], 6.0);
    }
}
