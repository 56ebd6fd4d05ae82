//! Estimability measures (seed `MeasureS`, tables 1–2), in the project's
//! one convention ([`aeromag_core::estimability`]).
//!
//! For each state component `k`, compare the posterior standard deviation
//! `σ⁺_k = ‖row_k(S⁺)‖` with the one the filter would have without any
//! measurement, `σ⁰_k = ‖row_k(S⁰⁻)‖` (the prior propagated by
//! `PrognosisFK` alone):
//!
//! ```text
//! μ_k = σ⁺_k / σ⁰_k  ∈ [0, 1]
//! ```
//!
//! `μ → 0`: the component is determined by the measurements, independently
//! of the prior; `μ = 1`: the measurements taught nothing about it. (The
//! seed reports `1 − μ`; aeromag uses one direction everywhere, the
//! compensation's `√(P⁺/P⁰)`.)

use crate::sr_iekf::SrState;
use aeromag_core::estimability::estimability;
use nalgebra::SVector;

/// `MeasureS`: `μ_k = σ⁺_k/σ⁰_k` per component (1 when `σ⁰_k = 0`).
pub fn measure_s<const N: usize>(
    posterior: &SrState<N>,
    no_measurements: &SrState<N>,
) -> SVector<f64, N> {
    SVector::from_fn(|k, _| {
        estimability(
            posterior.s.row(k).norm_squared(),
            no_measurements.s.row(k).norm_squared(),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sr_iekf::processing;

    #[test]
    fn measured_component_is_estimable_and_unmeasured_is_not() {
        let prior = SrState::diagonal(
            SVector::<f64, 2>::zeros(),
            &SVector::<f64, 2>::new(10.0, 10.0),
        );
        let mut post = prior;
        processing(&mut post, &SVector::<f64, 2>::new(1.0, 0.0), 0.0, 1.0).unwrap();
        let mu = measure_s(&post, &prior);
        assert!((mu[0] - (1.0f64 / 101.0).sqrt()).abs() < 1e-12);
        assert_eq!(mu[1], 1.0);
    }
}
