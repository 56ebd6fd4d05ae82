//! The Nelder–Mead simplex method for minimising a function of a few
//! variables without derivatives.
//!
//! A simplex of `d + 1` points moves downhill by reflecting its worst point
//! through the centroid `c` of the others, expanding, contracting, or
//! shrinking towards the best point. With the standard coefficients
//! (reflection ρ = 1, expansion χ = 2, contraction γ = ½, shrink σ = ½):
//!
//! ```text
//! x_r = c + ρ (c − x_worst)                       reflect
//! x_e = c + χ (x_r − c)        if f(x_r) < f_best   expand
//! x_c = c + γ (x_r − c)        if f(x_r) < f_worst  outside contraction
//! x_cc = c − γ (c − x_worst)   otherwise           inside contraction
//! x_i ← x_best + σ (x_i − x_best)                  shrink (if contraction fails)
//! ```
//!
//! Ties are broken by the order of insertion, so the method is
//! deterministic. It stops when the spread of function values *and* the
//! size of the simplex are below the tolerances, or after the evaluation
//! budget. Non-finite function values are treated as `+∞` (the point is
//! rejected). References: J. A. Nelder & R. Mead, *Comput. J.* 7 (1965)
//! 308–313; J. C. Lagarias, J. A. Reeds, M. H. Wright, P. E. Wright,
//! "Convergence properties of the Nelder–Mead simplex method in low
//! dimensions", *SIAM J. Optim.* 9 (1998) 112–147 (the variant implemented).

use crate::error::{EstError, Result};

/// Settings of [`nelder_mead`].
#[derive(Debug, Clone, PartialEq)]
pub struct NelderMeadOptions {
    /// Initial step along each coordinate (the simplex is `x0` and
    /// `x0 + step_i e_i`); length `d`, non-zero.
    pub initial_step: Vec<f64>,
    /// Stop when `max |f_i − f_best| ≤ f_tol` …
    pub f_tol: f64,
    /// … and `max_i ‖x_i − x_best‖_∞ ≤ x_tol`.
    pub x_tol: f64,
    /// Evaluation budget.
    pub max_evaluations: usize,
}

/// The outcome of [`nelder_mead`].
#[derive(Debug, Clone, PartialEq)]
pub struct NelderMeadResult {
    /// The best point found.
    pub x: Vec<f64>,
    /// The function value there.
    pub f: f64,
    /// Function evaluations used.
    pub evaluations: usize,
    /// Whether the tolerances were met (otherwise the budget ran out).
    pub converged: bool,
}

/// Minimise `f` from `x0` (module docs).
pub fn nelder_mead(
    mut f: impl FnMut(&[f64]) -> f64,
    x0: &[f64],
    opts: &NelderMeadOptions,
) -> Result<NelderMeadResult> {
    let d = x0.len();
    if d == 0 || opts.initial_step.len() != d {
        return Err(EstError::Dimension(format!(
            "Nelder–Mead: {d} variables, {} steps",
            opts.initial_step.len()
        )));
    }
    if x0.iter().chain(&opts.initial_step).any(|v| !v.is_finite())
        || opts.initial_step.contains(&0.0)
    {
        return Err(EstError::NonFinite {
            what: "Nelder–Mead start point or step (steps must be non-zero)",
        });
    }
    let mut evals = 0usize;
    let mut eval = |x: &[f64], evals: &mut usize| {
        *evals += 1;
        let v = f(x);
        if v.is_finite() { v } else { f64::INFINITY }
    };
    let mut pts: Vec<Vec<f64>> = Vec::with_capacity(d + 1);
    let mut fs: Vec<f64> = Vec::with_capacity(d + 1);
    pts.push(x0.to_vec());
    fs.push(eval(x0, &mut evals));
    for i in 0..d {
        let mut p = x0.to_vec();
        p[i] += opts.initial_step[i];
        fs.push(eval(&p, &mut evals));
        pts.push(p);
    }
    let mut order: Vec<usize> = (0..=d).collect();
    let mut converged = false;
    let mut c = vec![0.0; d];
    let mut xr = vec![0.0; d];
    let mut xe = vec![0.0; d];
    loop {
        // Stable sort: ties keep their previous order.
        order.sort_by(|&a, &b| fs[a].total_cmp(&fs[b]));
        let best = order[0];
        let worst = order[d];
        let f_spread = order
            .iter()
            .map(|&i| (fs[i] - fs[best]).abs())
            .fold(0.0, f64::max);
        let x_spread = order
            .iter()
            .map(|&i| {
                pts[i]
                    .iter()
                    .zip(&pts[best])
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max)
            })
            .fold(0.0, f64::max);
        if f_spread <= opts.f_tol && x_spread <= opts.x_tol {
            converged = true;
            break;
        }
        if evals >= opts.max_evaluations {
            break;
        }
        c.fill(0.0);
        for &i in &order[..d] {
            for (cj, pj) in c.iter_mut().zip(&pts[i]) {
                *cj += pj / d as f64;
            }
        }
        let f_best = fs[best];
        let f_second_worst = fs[order[d - 1]];
        let f_worst = fs[worst];
        for j in 0..d {
            xr[j] = 2.0 * c[j] - pts[worst][j];
        }
        let fr = eval(&xr, &mut evals);
        if fr < f_best {
            for j in 0..d {
                xe[j] = c[j] + 2.0 * (xr[j] - c[j]);
            }
            let fe = eval(&xe, &mut evals);
            if fe < fr {
                pts[worst].copy_from_slice(&xe);
                fs[worst] = fe;
            } else {
                pts[worst].copy_from_slice(&xr);
                fs[worst] = fr;
            }
            continue;
        }
        if fr < f_second_worst {
            pts[worst].copy_from_slice(&xr);
            fs[worst] = fr;
            continue;
        }
        // Contraction: outside if the reflection improved on the worst point.
        let outside = fr < f_worst;
        for j in 0..d {
            xe[j] = if outside {
                c[j] + 0.5 * (xr[j] - c[j])
            } else {
                c[j] + 0.5 * (pts[worst][j] - c[j])
            };
        }
        let fc = eval(&xe, &mut evals);
        if (outside && fc <= fr) || (!outside && fc < f_worst) {
            pts[worst].copy_from_slice(&xe);
            fs[worst] = fc;
            continue;
        }
        // Shrink towards the best point.
        let xb = pts[best].clone();
        for &i in &order[1..] {
            for j in 0..d {
                pts[i][j] = xb[j] + 0.5 * (pts[i][j] - xb[j]);
            }
            fs[i] = eval(&pts[i].clone(), &mut evals);
        }
    }
    let best = order
        .iter()
        .copied()
        .min_by(|&a, &b| fs[a].total_cmp(&fs[b]))
        .unwrap_or(0);
    Ok(NelderMeadResult {
        x: pts[best].clone(),
        f: fs[best],
        evaluations: evals,
        converged,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn opts(d: usize) -> NelderMeadOptions {
        NelderMeadOptions {
            initial_step: vec![0.5; d],
            f_tol: 1e-12,
            x_tol: 1e-7,
            max_evaluations: 5000,
        }
    }

    #[test]
    fn finds_the_minimum_of_the_rosenbrock_function() {
        let rosen = |x: &[f64]| 100.0 * (x[1] - x[0] * x[0]).powi(2) + (1.0 - x[0]).powi(2);
        let r = nelder_mead(rosen, &[-1.2, 1.0], &opts(2)).unwrap();
        assert!(r.converged);
        assert!(
            (r.x[0] - 1.0).abs() < 1e-5 && (r.x[1] - 1.0).abs() < 1e-5,
            "{:?}",
            r.x
        );
    }

    #[test]
    fn minimises_a_shifted_quadratic_in_three_dimensions_and_rejects_nan() {
        let q = |x: &[f64]| {
            if x[2] > 10.0 {
                return f64::NAN;
            }
            (x[0] - 1.0).powi(2)
                + 4.0 * (x[1] + 2.0).powi(2)
                + 0.25 * (x[2] - 3.0).powi(2)
                + 0.5 * x[0] * x[1]
        };
        let r = nelder_mead(q, &[0.0, 0.0, 9.5], &opts(3)).unwrap();
        // Stationary point of the quadratic (solve the 3×3 gradient system).
        // ∂/∂x0: 2(x0−1) + 0.5 x1 = 0; ∂/∂x1: 8(x1+2) + 0.5 x0 = 0; x2 = 3.
        let x1 = (-16.0 - 0.5) / (8.0 - 0.125);
        let x0 = 1.0 - 0.25 * x1;
        assert!(
            (r.x[0] - x0).abs() < 1e-5 && (r.x[1] - x1).abs() < 1e-5 && (r.x[2] - 3.0).abs() < 1e-4,
            "{:?}",
            r.x
        );
    }

    #[test]
    fn budget_and_bad_input() {
        let r = nelder_mead(
            |x| x[0] * x[0],
            &[5.0],
            &NelderMeadOptions {
                max_evaluations: 4,
                ..opts(1)
            },
        )
        .unwrap();
        assert!(!r.converged && r.evaluations <= 6);
        assert!(nelder_mead(|x| x[0], &[], &opts(0)).is_err());
        assert!(
            nelder_mead(
                |x| x[0],
                &[1.0],
                &NelderMeadOptions {
                    initial_step: vec![0.0],
                    ..opts(1)
                }
            )
            .is_err()
        );
    }
}
