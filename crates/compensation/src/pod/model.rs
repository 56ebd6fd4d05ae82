//! The small-signal model of the pod's background interference and its
//! large-signal counterpart (spec `helicopter.md` part B "Model (derivation
//! corrected)", seed `002_…` eqs. 2–12).
//!
//! Parameters `θ` ([`N_PARAMS`] = 43, all in nT per unit direction cosine,
//! per unit direction cosine rate (s), or per metre):
//!
//! | block | entries | meaning |
//! |---|---|---|
//! | `sd1` (0..8) | `P1 P2 P3 a11 a12 a13 a22 a23` | permanent and induced (`a` symmetric, `a33 = 0`: `Σu² = 1` makes it redundant) |
//! | `sd2` (8..16) | `b11 b12 b13 b21 b22 b23 b31 b32` | eddy (`b33 = 0`: `b + κI` is unobservable) |
//! | `sd3..5` (16..43) | `∂P1..3, ∂a11 ∂a12 ∂a13 ∂a22 ∂a23, g0` per axis x, y, z | field gradient at the pod |
//! | `sd6` (43..67, joint solve only) | `∂b11 … ∂b32` per axis x, y, z | gradient of the eddy-current field |
//!
//! Correction to the seed: the gradient blocks carry a ninth term `g0`
//! (a heading-independent gradient, the `∂a33` term that `Σu² = 1` turns
//! into a constant); with `a33 = 0` and no constant, eqs. 10–12 cannot
//! represent a field gradient that does not change with the heading.
//!
//! Second correction (found on the simulated seed scenario): eqs. 10–12
//! differentiate only the permanent and induced parts in the pod position.
//! The eddy-current part changes with the pod position too, by
//! `δp_k Σ_ij ∂b_ij,k u_j u_i'`; in the small-signal view this is a product
//! of two small quantities (`δp`, `v'`) and is dropped, but during a 5°
//! manoeuvre at 0.1 Hz the field rate is ≈ 3000 nT/s, the eddy moments are
//! as large as the permanent ones and the pod moves by metres, so the
//! product is not small. The joint solve carries these 24 terms
//! ([`N_JOINT`] parameters); the two-step solve, whose heading coefficients
//! are first order, cannot.
//!
//! Large signal (the interference up to a constant per heading):
//! `ΔB = P·u + uᵀAu + Σ_ij b_ij u_j u_i' + Σ_k δp_k (∂P_k·u + uᵀ∂A_k u + g0_k
//! + Σ_ij ∂b_ij,k u_j u_i')`.
//!
//! Small signal on a heading with steady direction cosines `U` (seed eq. 4,
//! corrected eq. 6): `c = P + 2AU`, `d = bU`; the perturbation `v ⊥ U`
//! has one dependent component, eliminated by `U·v = 0`. The seed
//! eliminates `v3` (`W1 = c1 − c3 U1/U3`, `W2 = c2 − c3 U2/U3`,
//! `W3 = d1 − d3 U1/U3`, `W4 = d2 − d3 U2/U3`), which fails where `U3 = 0`:
//! level flight at the magnetic equator. As the seed says for that case,
//! the axes are reordered: the component `e` with the largest `|U_e|` is
//! eliminated and `(a, b)` are the other two in order ([`free_axes`]):
//! `W1 = c_a − c_e U_a/U_e`, `W2 = c_b − c_e U_b/U_e`, `W3 = d_a − d_e U_a/U_e`,
//! `W4 = d_b − d_e U_b/U_e`, `W5..7 = ∂P_k·U + Uᵀ∂A_k U + g0_k`, and
//! `s = W1 v_a + W2 v_b + W3 v_a' + W4 v_b' + W5 x + W6 y + W7 z`
//! (`|U_e| ≥ 1/√3` always; for `|U3|` largest this is the seed's form).

use crate::{CompError, Result};

/// Number of model parameters of the small-signal model (8 + 8 + 3 × 9).
pub const N_PARAMS: usize = 43;
/// Number of parameters of the large-signal model of the joint solve:
/// [`N_PARAMS`] plus the eddy-current gradient (3 × 8).
pub const N_JOINT: usize = N_PARAMS + 24;
/// Number of heading coefficients `W1..W7`.
pub const N_HEADING: usize = 7;
/// The axes of the small-signal model for steady direction cosines `u0`:
/// `(a, b, e)`, `e` the component of largest `|U_e|` (eliminated), `a < b`
/// the other two (module docs).
pub fn free_axes(u0: &[f64; 3]) -> (usize, usize, usize) {
    let e = (0..3)
        .max_by(|&i, &j| u0[i].abs().total_cmp(&u0[j].abs()))
        .unwrap_or(2);
    match e {
        0 => (1, 2, 0),
        1 => (0, 2, 1),
        _ => (0, 1, 2),
    }
}

/// Symmetric `A` from `(a11, a12, a13, a22, a23)`, `a33 = 0`.
fn sym(a: &[f64]) -> [[f64; 3]; 3] {
    [[a[0], a[1], a[2]], [a[1], a[3], a[4]], [a[2], a[4], 0.0]]
}

/// `b` from `(b11 b12 b13 b21 b22 b23 b31 b32)`, `b33 = 0`.
fn eddy(b: &[f64]) -> [[f64; 3]; 3] {
    [[b[0], b[1], b[2]], [b[3], b[4], b[5]], [b[6], b[7], 0.0]]
}

fn quad(a: &[[f64; 3]; 3], u: &[f64; 3], w: &[f64; 3]) -> f64 {
    (0..3)
        .map(|i| (0..3).map(|j| a[i][j] * u[i] * w[j]).sum::<f64>())
        .sum()
}

/// Gradient-block value `∂P·U + Uᵀ∂A U + g0` for one axis (9 entries).
fn gradient_block(g: &[f64], u: &[f64; 3]) -> f64 {
    g[0] * u[0] + g[1] * u[1] + g[2] * u[2] + quad(&sym(&g[3..8]), u, u) + g[8]
}

/// Heading coefficients `W1..W7` of parameters `theta` for steady direction
/// cosines `u0` (corrected seed eq. 6 and eqs. 10–12, the axes of
/// [`free_axes`]). Errors: wrong length, `u0` not a direction.
pub fn heading_coefficients(theta: &[f64], u0: &[f64; 3]) -> Result<[f64; N_HEADING]> {
    if theta.len() != N_PARAMS {
        return Err(CompError::data(format!(
            "pod model needs {N_PARAMS} parameters, got {}",
            theta.len()
        )));
    }
    let norm = (u0[0] * u0[0] + u0[1] * u0[1] + u0[2] * u0[2]).sqrt();
    if !(norm > 0.5 && norm < 2.0) {
        return Err(CompError::data(format!(
            "steady direction cosines {u0:?} are not a unit vector"
        )));
    }
    let (ia, ib, ie) = free_axes(u0);
    let a = sym(&theta[3..8]);
    let b = eddy(&theta[8..16]);
    let c: Vec<f64> = (0..3)
        .map(|i| theta[i] + 2.0 * (0..3).map(|j| a[i][j] * u0[j]).sum::<f64>())
        .collect();
    let d: Vec<f64> = (0..3)
        .map(|i| (0..3).map(|j| b[i][j] * u0[j]).sum())
        .collect();
    let r = [u0[ia] / u0[ie], u0[ib] / u0[ie]];
    Ok([
        c[ia] - c[ie] * r[0],
        c[ib] - c[ie] * r[1],
        d[ia] - d[ie] * r[0],
        d[ib] - d[ie] * r[1],
        gradient_block(&theta[16..25], u0),
        gradient_block(&theta[25..34], u0),
        gradient_block(&theta[34..43], u0),
    ])
}

/// The 7 × 43 matrix `M(U)` with `W = M(U) θ` (the heading coefficients are
/// linear in the parameters).
pub fn heading_design(u0: &[f64; 3]) -> Result<Vec<[f64; N_HEADING]>> {
    (0..N_PARAMS)
        .map(|k| {
            let mut e = [0.0; N_PARAMS];
            e[k] = 1.0;
            heading_coefficients(&e, u0)
        })
        .collect()
}

/// Large-signal regressors of one sample: the [`N_JOINT`] functions
/// multiplying `θ` in `ΔB(u, u', δp)` (module docs), for direction cosines
/// `u`, their rate `du` (1/s) and pod displacement `dp` (m, body frame).
/// The first [`N_PARAMS`] are those of the seed's parameters.
pub fn large_signal_row(u: &[f64; 3], du: &[f64; 3], dp: &[f64; 3]) -> [f64; N_JOINT] {
    let mut r = [0.0; N_JOINT];
    let g = gradient_functions(u);
    r[..8].copy_from_slice(&g[..8]);
    let pairs = [
        (0, 0),
        (0, 1),
        (0, 2),
        (1, 0),
        (1, 1),
        (1, 2),
        (2, 0),
        (2, 1),
    ];
    for (k, (i, j)) in pairs.iter().enumerate() {
        r[8 + k] = u[*j] * du[*i];
    }
    for (axis, d) in dp.iter().enumerate() {
        let o = 16 + 9 * axis;
        for k in 0..9 {
            r[o + k] = d * g[k];
        }
        for k in 0..8 {
            r[N_PARAMS + 8 * axis + k] = d * r[8 + k];
        }
    }
    r
}

/// The 9 functions of `u` of a gradient block: `(u1, u2, u3, u1², 2u1u2,
/// 2u1u3, u2², 2u2u3, 1)` (the first 8 are also the `sd1` regressors).
fn gradient_functions(u: &[f64; 3]) -> [f64; 9] {
    [
        u[0],
        u[1],
        u[2],
        u[0] * u[0],
        2.0 * u[0] * u[1],
        2.0 * u[0] * u[2],
        u[1] * u[1],
        2.0 * u[1] * u[2],
        1.0,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The small-signal coefficients are the derivatives of the large-signal
    /// model: `ΔB(U+εv) − ΔB(U) ≈ ε (W1 v1 + W2 v2)` for `v ⊥ U`, and the
    /// position terms are `W5..7`.
    #[test]
    fn small_signal_is_the_derivative_of_the_large_signal_model() {
        // The seed's case (U3 largest) and level flight at the magnetic
        // equator heading north-east (U3 = 0: U1 or U2 eliminated).
        let h = 0.5f64.sqrt();
        for u0 in [[0.5, -0.5, h], [h, h * 0.999, 0.0], [0.2, -0.97, 0.1397]] {
            check_derivatives(u0);
        }
    }

    fn check_derivatives(u0: [f64; 3]) {
        let n = (u0[0] * u0[0] + u0[1] * u0[1] + u0[2] * u0[2]).sqrt();
        let u0 = u0.map(|x| x / n);
        let (ia, ib, ie) = free_axes(&u0);
        let theta: Vec<f64> = (0..N_PARAMS)
            .map(|k| ((k * 37 % 11) as f64 - 5.0) * 0.1)
            .collect();
        let w = heading_coefficients(&theta, &u0).unwrap();
        let f = |u: &[f64; 3], du: &[f64; 3], dp: &[f64; 3]| -> f64 {
            large_signal_row(u, du, dp)
                .iter()
                .zip(&theta)
                .map(|(a, b)| a * b)
                .sum()
        };
        let z = [0.0; 3];
        // v with v_e = −(U_a v_a + U_b v_b)/U_e.
        let (v1, v2) = (0.3, -0.2);
        let mut v = [0.0; 3];
        v[ia] = v1;
        v[ib] = v2;
        v[ie] = -(u0[ia] * v1 + u0[ib] * v2) / u0[ie];
        let eps = 1e-6;
        let up = [u0[0] + eps * v[0], u0[1] + eps * v[1], u0[2] + eps * v[2]];
        let num = (f(&up, &z, &z) - f(&u0, &z, &z)) / eps;
        assert!((num - (w[0] * v1 + w[1] * v2)).abs() < 1e-5, "{num}");
        // Eddy: ΔB is linear in u'; at u = U it equals W3 v1' + W4 v2'.
        let e = f(&u0, &v, &z) - f(&u0, &z, &z);
        assert!((e - (w[2] * v1 + w[3] * v2)).abs() < 1e-12, "{e}");
        for axis in 0..3 {
            let mut dp = [0.0; 3];
            dp[axis] = 1.0;
            let g = f(&u0, &z, &dp) - f(&u0, &z, &z);
            assert!((g - w[4 + axis]).abs() < 1e-12);
        }
    }

    #[test]
    fn bad_inputs_are_errors_and_the_equator_is_not() {
        assert!(heading_coefficients(&[0.0; 3], &[0.0, 0.0, 1.0]).is_err());
        assert!(heading_coefficients(&[0.0; N_PARAMS], &[0.0, 0.0, 0.0]).is_err());
        assert!(heading_coefficients(&[0.0; N_PARAMS], &[1.0, 0.0, 0.0]).is_ok());
        assert_eq!(free_axes(&[1.0, 0.0, 0.0]), (1, 2, 0));
        assert_eq!(free_axes(&[0.1, -0.9, 0.3]), (0, 2, 1));
        assert_eq!(free_axes(&[0.6, 0.0, 0.8]), (0, 1, 2));
        assert_eq!(heading_design(&[0.6, 0.0, 0.8]).unwrap().len(), N_PARAMS);
    }
}
