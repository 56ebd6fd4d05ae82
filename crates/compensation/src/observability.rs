//! Observability and estimability of the interference coefficients
//! (spec `compensation.md`, "Observability and estimability"; seed `000_…`
//! §10 (deterministic) and §12 (stochastic, estimability measures)).
//!
//! Input: the prior covariance `P⁰` of the coefficients `X1` and their
//! posterior covariance `P` after the Kalman filter has processed a flight
//! (the field states `X2` are marginalised by the filter itself).
//!
//! * **Information** of the flight about `X1`: `J = P⁻¹ − (P⁰)⁻¹`. It is
//!   scaled by the prior standard deviations, `S = D J D`,
//!   `D = diag(√P⁰_ii)`, so that an eigenvalue of `S` says how many times the
//!   prior variance the flight resolves in that direction. Its **rank**
//!   (eigenvalues above `ε_rank · λ_max`) and **condition number** are the
//!   deterministic observability of §10; the eigenvectors of the smallest
//!   eigenvalues are the combinations of coefficients the flight cannot
//!   separate, spelled out by name.
//! * **Estimability** (§12): `μ_i = √(P_ii / P⁰_ii)` — near 0 the flight
//!   determines coefficient `i`, near 1 it leaves it at its prior (the
//!   project's one convention, [`aeromag_core::estimability`]).

use crate::error::{CompError, Result};
use aeromag_core::estimability::estimability;
use nalgebra::{DMatrix, SymmetricEigen};
use serde::{Deserialize, Serialize};

/// Observability and estimability of a flight.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Observability {
    /// Coefficient names.
    pub names: Vec<String>,
    /// Rank of the scaled information matrix.
    pub rank: usize,
    /// Condition number of the scaled information matrix (∞ if singular).
    pub condition: f64,
    /// Eigenvalues of the scaled information, ascending.
    pub eigenvalues: Vec<f64>,
    /// Estimability measure per coefficient, `√(P_ii/P⁰_ii)`.
    pub estimability: Vec<f64>,
    /// The poorly determined combinations, in words.
    pub weak_combinations: Vec<String>,
}

/// Relative eigenvalue below which a direction counts as unobservable.
pub const RANK_TOLERANCE: f64 = 1e-9;

/// Observability from prior and posterior covariances (same order as
/// `names`). `weak_ratio`: directions whose information is below
/// `λ_max / weak_ratio` are listed as poorly determined (e.g. 1e6).
pub fn observability(
    names: &[String],
    prior: &DMatrix<f64>,
    posterior: &DMatrix<f64>,
    weak_ratio: f64,
) -> Result<Observability> {
    let n = names.len();
    if prior.shape() != (n, n) || posterior.shape() != (n, n) {
        return Err(CompError::setting(format!("covariances must be {n}×{n}")));
    }
    let inv = |m: &DMatrix<f64>| m.clone().cholesky().map(|c| c.inverse());
    let (p0i, pi) = match (inv(prior), inv(posterior)) {
        (Some(a), Some(b)) => (a, b),
        _ => {
            return Err(CompError::Singular {
                reason: "a covariance matrix is not positive definite".into(),
            });
        }
    };
    let d: Vec<f64> = (0..n).map(|i| prior[(i, i)].sqrt()).collect();
    let mut s = DMatrix::from_fn(n, n, |i, j| (pi[(i, j)] - p0i[(i, j)]) * d[i] * d[j]);
    s = (&s + s.transpose()) * 0.5;
    let eig = SymmetricEigen::new(s);
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
    let w: Vec<f64> = order.iter().map(|&k| eig.eigenvalues[k].max(0.0)).collect();
    let wmax = w.last().copied().unwrap_or(0.0);
    let rank = w.iter().filter(|&&v| v > RANK_TOLERANCE * wmax).count();
    let condition = if w[0] > 0.0 {
        wmax / w[0]
    } else {
        f64::INFINITY
    };
    let mut weak = Vec::new();
    for (pos, &k) in order.iter().enumerate() {
        if w[pos].partial_cmp(&(wmax / weak_ratio)) != Some(std::cmp::Ordering::Less) {
            break;
        }
        let v = eig.eigenvectors.column(k);
        let mut idx: Vec<usize> = (0..n).collect();
        idx.sort_by(|&a, &b| v[b].abs().total_cmp(&v[a].abs()));
        let terms: Vec<String> = idx
            .iter()
            .take(4)
            .filter(|&&j| v[j].abs() > 0.1)
            .map(|&j| format!("{:+.2}·{}", v[j], names[j]))
            .collect();
        let how = if w[pos] <= RANK_TOLERANCE * wmax {
            "not observable"
        } else {
            "poorly determined"
        };
        weak.push(format!(
            "{how}: {} (information {:.1e} of the best direction)",
            terms.join(" "),
            w[pos] / wmax.max(f64::MIN_POSITIVE)
        ));
    }
    let estimability = (0..n)
        .map(|i| estimability(posterior[(i, i)], prior[(i, i)]))
        .collect();
    Ok(Observability {
        names: names.to_vec(),
        rank,
        condition,
        eigenvalues: w,
        estimability,
        weak_combinations: weak,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_unmeasured_combination_is_found_and_named() {
        // Prior: unit variances. The data measure a and b + c, never b − c.
        let names: Vec<String> = ["a", "b", "c"].iter().map(|s| s.to_string()).collect();
        let prior = DMatrix::identity(3, 3);
        let h = DMatrix::from_row_slice(2, 3, &[1.0, 0.0, 0.0, 0.0, 1.0, 1.0]);
        let info = h.transpose() * &h * 100.0; // σ = 0.1
        let post = (DMatrix::identity(3, 3) + info).try_inverse().unwrap();
        let o = observability(&names, &prior, &post, 1e6).unwrap();
        assert_eq!(o.rank, 2);
        assert!(o.condition.is_infinite() || o.condition > 1e12);
        assert_eq!(o.weak_combinations.len(), 1);
        let text = &o.weak_combinations[0];
        assert!(
            text.contains("not observable")
                && text.contains("b")
                && text.contains("c")
                && !text.contains("a "),
            "{text}"
        );
        // μ: a well estimated, b and c only half (b + c known, b − c not).
        assert!(o.estimability[0] < 0.11);
        assert!((o.estimability[1] - (0.5f64 + 0.5 / 201.0).sqrt()).abs() < 1e-9);
    }

    #[test]
    fn bad_shapes_are_errors() {
        let names = vec!["a".to_string()];
        assert!(
            observability(
                &names,
                &DMatrix::identity(2, 2),
                &DMatrix::identity(1, 1),
                1e6
            )
            .is_err()
        );
        assert!(
            observability(&names, &DMatrix::zeros(1, 1), &DMatrix::identity(1, 1), 1e6).is_err()
        );
    }
}
