//! The modified Bryson–Frazier (MBF) smoother: smoothed means from a
//! backward recursion of an adjoint vector, with no smoother gain.
//!
//! The RTS step ([`super::rts`]) needs the gain `C = P_k Φᵀ (P⁻_{k+1})⁻¹`
//! at every step: two products and two triangular solves, `O(n³)`. When only
//! the smoothed **means** are wanted, the adjoint form avoids it. With the
//! filter's update at step `k` (row `h_k`, gain `K_k = P⁻_k h_k/α_k`,
//! innovation `ν_k`, variance `α_k`) and the filtered `(x_k, P_k = S_k S_kᵀ)`:
//!
//! ```text
//! λ̃_k   = Φ_{k+1}ᵀ λ_{k+1}                      (λ̃_{N−1} = 0)
//! x^s_k = x_k + P_k λ̃_k = x_k + S_k (S_kᵀ λ̃_k)
//! λ_k   = λ̃_k − h_k (K_kᵀ λ̃_k) + h_k ν_k/α_k    (λ_k = λ̃_k without a measurement)
//! ```
//!
//! Derivation: the RTS mean `x^s_k = x_k + C (x^s_{k+1} − x⁻_{k+1})` with
//! `x^s_{k+1} − x⁻_{k+1} = P⁻_{k+1} λ_{k+1}` gives the second line, since
//! `C P⁻_{k+1} = P_k Φᵀ`; writing `x^s_k = x⁻_k + P⁻_k λ_k` and substituting
//! `x_k = x⁻_k + K_k ν_k`, `P_k = (I − K_k h_kᵀ) P⁻_k` gives the third. Cost
//! per step `O(n²)` (three matrix–vector products) against `O(n³)` for the
//! RTS gain; the result equals the RTS means up to round-off (tested).
//!
//! References: G. J. Bierman, *Factorization Methods for Discrete Sequential
//! Estimation* (Academic Press 1977), §X.2 ("modified Bryson–Frazier
//! smoother"); A. E. Bryson & M. Frazier, "Smoothing for linear and
//! nonlinear dynamic systems", ASD-TDR-63-119 (1963); Grewal & Andrews
//! (2015) §6.4.

/// The measurement update of one step as the MBF recursion needs it.
#[derive(Debug, Clone, Copy)]
pub struct MbfUpdate<'a> {
    /// The measurement row `h_k` (length `n`).
    pub row: &'a [f64],
    /// The Kalman gain `K_k = P⁻_k h_k/α_k` (length `n`).
    pub gain: &'a [f64],
    /// `ν_k/α_k`: the innovation divided by its variance.
    pub weighted_innovation: f64,
}

/// The adjoint `λ` of the MBF recursion and its workspace.
#[derive(Debug, Clone)]
pub struct MbfAdjoint {
    lambda: Vec<f64>,
    tilde: Vec<f64>,
    t: Vec<f64>,
}

impl MbfAdjoint {
    /// The adjoint after the last step (`λ_N = 0`) for `n` states.
    pub fn new(n: usize) -> Self {
        Self {
            lambda: vec![0.0; n],
            tilde: vec![0.0; n],
            t: vec![0.0; n],
        }
    }

    /// The current adjoint `λ_k` (after [`step`](Self::step) at `k`).
    pub fn adjoint(&self) -> &[f64] {
        &self.lambda
    }

    /// One backward step at `k`, with `λ_{k+1}` held: `phi_next` is
    /// `Φ_{k+1}` (column-major `n × n`; `None` at the last step), `x_f` and
    /// `s_f` (column-major, upper triangular) the filtered estimate at `k`,
    /// `update` the measurement update at `k` (if any). Writes `x^s_k` into
    /// `out` and keeps `λ_k`. Panics on inconsistent lengths (a programming
    /// error).
    pub fn step(
        &mut self,
        phi_next: Option<&[f64]>,
        x_f: &[f64],
        s_f: &[f64],
        update: Option<MbfUpdate<'_>>,
        out: &mut [f64],
    ) {
        let n = self.lambda.len();
        assert!(
            x_f.len() == n && s_f.len() == n * n && out.len() == n,
            "MBF step: inconsistent sizes"
        );
        match n {
            5 => self.step_impl(5, phi_next, x_f, s_f, update, out),
            6 => self.step_impl(6, phi_next, x_f, s_f, update, out),
            8 => self.step_impl(8, phi_next, x_f, s_f, update, out),
            _ => self.step_impl(n, phi_next, x_f, s_f, update, out),
        }
    }

    #[inline(always)]
    fn step_impl(
        &mut self,
        n: usize,
        phi_next: Option<&[f64]>,
        x_f: &[f64],
        s_f: &[f64],
        update: Option<MbfUpdate<'_>>,
        out: &mut [f64],
    ) {
        let (lambda, tilde, t) = (
            &mut self.lambda[..n],
            &mut self.tilde[..n],
            &mut self.t[..n],
        );
        // λ̃ = Φᵀ λ: column j of Φ dotted with λ.
        match phi_next {
            Some(phi) => {
                for (j, tj) in tilde.iter_mut().enumerate() {
                    let mut acc = 0.0;
                    for (p, l) in phi[j * n..(j + 1) * n].iter().zip(lambda.iter()) {
                        acc += p * l;
                    }
                    *tj = acc;
                }
            }
            None => tilde.fill(0.0),
        }
        // t = Sᵀ λ̃ (column j of S has rows 0..=j), out = x + S t.
        for (j, tj) in t.iter_mut().enumerate() {
            let mut acc = 0.0;
            for (s, l) in s_f[j * n..j * n + j + 1].iter().zip(tilde.iter()) {
                acc += s * l;
            }
            *tj = acc;
        }
        out[..n].copy_from_slice(&x_f[..n]);
        for (j, tj) in t.iter().enumerate() {
            for (o, s) in out[..=j].iter_mut().zip(&s_f[j * n..j * n + j + 1]) {
                *o += s * tj;
            }
        }
        // λ = λ̃ − h (Kᵀ λ̃) + h ν/α.
        lambda.copy_from_slice(tilde);
        if let Some(u) = update {
            let mut k_l = 0.0;
            for (k, l) in u.gain[..n].iter().zip(tilde.iter()) {
                k_l += k * l;
            }
            let c = u.weighted_innovation - k_l;
            for (l, h) in lambda.iter_mut().zip(&u.row[..n]) {
                *l += h * c;
            }
        }
    }
}
