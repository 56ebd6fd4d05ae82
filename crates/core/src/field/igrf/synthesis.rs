//! Spherical-harmonic synthesis of an internal potential field in geocentric
//! spherical coordinates, with Schmidt semi-normalised associated Legendre
//! functions computed by recursion.
//!
//! ## Potential and field
//!
//! With reference radius `a = 6371.2 km`, geocentric radius `r`, colatitude
//! `θ`, longitude `φ` and Gauss coefficients `g_n^m`, `h_n^m` (nT):
//!
//! ```text
//! V(r,θ,φ) = a Σ_{n=1..N} (a/r)^{n+1} Σ_{m=0..n} (g_n^m cos mφ + h_n^m sin mφ) P_n^m(cos θ)
//!
//! B = −∇V:
//! B_r = −∂V/∂r          =  Σ_n (n+1) (a/r)^{n+2} Σ_m (g cos mφ + h sin mφ) P_n^m
//! B_θ = −(1/r) ∂V/∂θ    = −Σ_n (a/r)^{n+2} Σ_m (g cos mφ + h sin mφ) dP_n^m/dθ
//! B_φ = −∂V/∂φ/(r sinθ) =  Σ_n (a/r)^{n+2} Σ_m m (g sin mφ − h cos mφ) P_n^m / sin θ
//! ```
//!
//! `B_θ` points south (increasing colatitude), `B_φ` east, `B_r` up; all in nT.
//!
//! ## Legendre recursion (Schmidt semi-normalised, no Condon–Shortley phase)
//!
//! ```text
//! P_0^0 = 1,   P_1^1 = sin θ,   P_m^m = √((2m−1)/(2m)) sin θ P_{m−1}^{m−1}   (m ≥ 2)
//! P_n^m = [(2n−1) cos θ P_{n−1}^m − √((n−1)² − m²) P_{n−2}^m] / √(n² − m²)    (n > m)
//! dP_m^m/dθ = m cos θ P_m^m / sin θ
//! dP_n^m/dθ = [(2n−1)(cos θ dP_{n−1}^m/dθ − sin θ P_{n−1}^m) − √((n−1)² − m²) dP_{n−2}^m/dθ] / √(n² − m²)
//! ```
//!
//! **Poles.** For `m ≥ 1` every `P_n^m` carries a factor `sin θ`, so the
//! recursion is run on `Q_n^m = P_n^m / sin θ` (same three-term recursion,
//! seed `Q_m^m = √((2m−1)/(2m)) P_{m−1}^{m−1}`, `Q_1^1 = 1`), and
//! `P_n^m = sin θ Q_n^m`. `B_φ` uses `Q` directly, which is the exact limit at
//! `θ = 0, π`: no division by `sin θ` happens anywhere and the poles give the
//! finite, direction-consistent horizontal field.

use super::coefficients::{GaussCoefficients, MAX_DEGREE, N_COEF, index};
use std::sync::OnceLock;

/// IGRF reference radius `a`, m (6371.2 km, not the mean Earth radius).
pub const IGRF_REFERENCE_RADIUS_M: f64 = 6_371_200.0;

/// θ-independent factors of the Legendre recursion.
#[derive(Debug)]
pub(crate) struct Recursion {
    /// `(2n−1)/√(n²−m²)` at `index(n, m)`, `n > m`.
    alpha: [f64; N_COEF],
    /// `√((n−1)²−m²)/√(n²−m²)` at `index(n, m)`, `n > m`.
    beta: [f64; N_COEF],
    /// Sectoral factor `√((2m−1)/(2m))` for `m ≥ 2`, 1 for `m = 1`.
    sectoral: [f64; MAX_DEGREE + 1],
}

/// The recursion factors, computed on first use.
pub(crate) fn recursion() -> &'static Recursion {
    static REC: OnceLock<Recursion> = OnceLock::new();
    REC.get_or_init(|| {
        let mut alpha = [0.0; N_COEF];
        let mut beta = [0.0; N_COEF];
        let mut sectoral = [1.0; MAX_DEGREE + 1];
        for n in 1..=MAX_DEGREE {
            for m in 0..n {
                let (nf, mf) = (n as f64, m as f64);
                let den = (nf * nf - mf * mf).sqrt();
                alpha[index(n, m)] = (2.0 * nf - 1.0) / den;
                beta[index(n, m)] = ((nf - 1.0) * (nf - 1.0) - mf * mf).max(0.0).sqrt() / den;
            }
        }
        for (m, s) in sectoral.iter_mut().enumerate().skip(2) {
            let mf = m as f64;
            *s = ((2.0 * mf - 1.0) / (2.0 * mf)).sqrt();
        }
        Recursion {
            alpha,
            beta,
            sectoral,
        }
    })
}

/// Geocentric field `[B_r, B_θ, B_φ]` (nT; up, south, east) of the expansion
/// `c` truncated at degree `n_max` (≤ 13), at radius `r_m` (m), colatitude
/// `colat_rad` and longitude `lon_rad`. Allocation-free; O(n_max²).
pub(crate) fn synthesize(
    c: &GaussCoefficients,
    n_max: usize,
    rec: &Recursion,
    r_m: f64,
    colat_rad: f64,
    lon_rad: f64,
) -> [f64; 3] {
    let n_max = n_max.min(MAX_DEGREE);
    let (st, ct) = colat_rad.sin_cos();
    let (sp, cp) = lon_rad.sin_cos();
    let ratio = IGRF_REFERENCE_RADIUS_M / r_m;

    // cos mφ, sin mφ by the angle-addition recursion.
    let mut cos_m = [1.0; MAX_DEGREE + 1];
    let mut sin_m = [0.0; MAX_DEGREE + 1];
    for m in 1..=n_max {
        cos_m[m] = cos_m[m - 1] * cp - sin_m[m - 1] * sp;
        sin_m[m] = sin_m[m - 1] * cp + cos_m[m - 1] * sp;
    }

    // Row-wise recursion over n (independent across m within a row). `q`
    // holds P_n^0 for m = 0 and Q_n^m = P_n^m / sin θ for m ≥ 1; `dp` holds
    // dP_n^m/dθ. Rows n−1 and n−2 are kept in the triangular arrays.
    let mut q = [0.0; N_COEF];
    let mut dp = [0.0; N_COEF];
    q[0] = 1.0;
    let mut p_sect = 1.0; // P_{n−1}^{n−1}
    let mut rho = ratio * ratio; // (a/r)^(n+2)
    let (mut br, mut bt, mut bp) = (0.0, 0.0, 0.0);
    for n in 1..=n_max {
        rho *= ratio;
        let row = index(n, 0);
        let prev = index(n - 1, 0);
        // Zonal and tesseral terms, m < n.
        for m in 0..n {
            let k = row + m;
            let (al, be) = (rec.alpha[k], rec.beta[k]);
            let s = if m == 0 { 1.0 } else { st };
            let (q1, dp1) = (q[prev + m], dp[prev + m]);
            let (q2, dp2) = if m + 1 < n {
                let pp = index(n - 2, m);
                (q[pp], dp[pp])
            } else {
                (0.0, 0.0)
            };
            q[k] = al * ct * q1 - be * q2;
            dp[k] = al * (ct * dp1 - st * s * q1) - be * dp2;
        }
        // Sectoral term, m = n.
        let k = row + n;
        q[k] = rec.sectoral[n] * p_sect;
        dp[k] = n as f64 * ct * q[k];
        p_sect = st * q[k];

        let (mut sr, mut stt, mut sp_) = (0.0, 0.0, 0.0);
        for m in 0..=n {
            let k = row + m;
            let a = c.g[k] * cos_m[m] + c.h[k] * sin_m[m];
            let s = if m == 0 { 1.0 } else { st };
            sr += a * s * q[k];
            stt += a * dp[k];
            sp_ += m as f64 * (c.g[k] * sin_m[m] - c.h[k] * cos_m[m]) * q[k];
        }
        br += (n + 1) as f64 * rho * sr;
        bt -= rho * stt;
        bp += rho * sp_;
    }
    [br, bt, bp]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Schmidt semi-normalised P_n^m(cos θ) and dP/dθ from the closed forms of
    /// low degrees (independent of the recursion).
    fn closed_form(n: usize, m: usize, t: f64) -> (f64, f64) {
        let (s, c) = t.sin_cos();
        let r3 = 3.0_f64.sqrt();
        match (n, m) {
            (1, 0) => (c, -s),
            (1, 1) => (s, c),
            (2, 0) => (1.5 * c * c - 0.5, -3.0 * c * s),
            (2, 1) => (r3 * s * c, r3 * (c * c - s * s)),
            (2, 2) => (0.5 * r3 * s * s, r3 * s * c),
            (3, 0) => (
                0.5 * (5.0 * c * c * c - 3.0 * c),
                0.5 * (-15.0 * c * c * s + 3.0 * s),
            ),
            (3, 3) => {
                let k = (5.0_f64 / 8.0).sqrt();
                (k * s * s * s, 3.0 * k * s * s * c)
            }
            _ => unreachable!(),
        }
    }

    /// A single unit coefficient isolates one Legendre function in B_r and B_θ.
    #[test]
    fn legendre_matches_closed_forms() {
        let rec = recursion();
        for &(n, m) in &[(1, 0), (1, 1), (2, 0), (2, 1), (2, 2), (3, 0), (3, 3)] {
            let mut c = GaussCoefficients {
                g: [0.0; N_COEF],
                h: [0.0; N_COEF],
            };
            c.g[index(n, m)] = 1.0;
            for t in [
                0.0,
                0.3,
                1.0,
                std::f64::consts::FRAC_PI_2,
                2.5,
                std::f64::consts::PI,
            ] {
                let [br, bt, _] = synthesize(&c, 13, rec, IGRF_REFERENCE_RADIUS_M, t, 0.0);
                let (p, dp) = closed_form(n, m, t);
                assert!((br - (n as f64 + 1.0) * p).abs() < 1e-14, "({n},{m}) θ={t}");
                assert!((bt + dp).abs() < 1e-14, "({n},{m}) θ={t}");
            }
        }
    }

    /// B_φ equals −(1/sinθ)∂V/∂φ: compare with a finite difference of V in φ
    /// (V from B_r/(n+1) of a single degree).
    #[test]
    fn bphi_is_the_longitude_derivative() {
        let rec = recursion();
        let mut c = GaussCoefficients {
            g: [0.0; N_COEF],
            h: [0.0; N_COEF],
        };
        c.g[index(4, 3)] = 2.0;
        c.h[index(4, 3)] = -1.5;
        let (t, p, d) = (1.1, 0.7, 1e-6);
        let v = |phi: f64| synthesize(&c, 13, rec, IGRF_REFERENCE_RADIUS_M, t, phi)[0] / 5.0;
        let [_, _, bp] = synthesize(&c, 13, rec, IGRF_REFERENCE_RADIUS_M, t, p);
        let fd = -(v(p + d) - v(p - d)) / (2.0 * d) / t.sin();
        assert!((bp - fd).abs() < 1e-7, "{bp} vs {fd}");
    }
}
