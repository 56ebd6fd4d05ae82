//! The one estimability convention of aeromag (seed `000_…` §12; spec
//! `compensation.md`, "Observability and estimability"; used by the
//! compensation's observability and by the gradiometer's `MeasureS`).
//!
//! For a state component `i` with prior variance `P⁰_ii` (what the filter
//! would know without any measurement) and posterior variance `P⁺_ii`:
//!
//! ```text
//! μ_i = √(P⁺_ii / P⁰_ii) = σ⁺_i / σ⁰_i
//! ```
//!
//! **0: determined by the measurements; 1: left at its prior.** A
//! filter that only adds information has `0 ≤ μ ≤ 1`.
//!
//! ```
//! use aeromag_core::estimability::estimability;
//! assert_eq!(estimability(0.25, 1.0), 0.5);  // σ halved by the measurements
//! assert_eq!(estimability(4.0, 4.0), 1.0);   // nothing learnt
//! ```

/// The convention in words, for reports and file headers.
pub const CONVENTION: &str =
    "μ = σ⁺/σ⁰ = √(P⁺ᵢᵢ/P⁰ᵢᵢ): 0 = determined by the measurements, 1 = left at its prior";

/// `μ = √(P⁺/P⁰)` from the posterior and prior **variances** of one
/// component (any units, the same for both). A prior variance of 0 (the
/// component is fixed) gives 1: the measurements taught nothing. Negative
/// round-off in `P⁺` counts as 0.
pub fn estimability(variance_posterior: f64, variance_prior: f64) -> f64 {
    if variance_prior > 0.0 {
        (variance_posterior / variance_prior).max(0.0).sqrt()
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ratio_of_standard_deviations() {
        assert!((estimability(1.0 / 101.0, 1.0) - (1.0f64 / 101.0).sqrt()).abs() < 1e-15);
        assert_eq!(estimability(-1e-30, 1.0), 0.0);
        assert_eq!(estimability(0.0, 0.0), 1.0);
    }
}
