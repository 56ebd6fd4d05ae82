//! Estimability measures (seed `MeasureS`, tables 1–2).
//!
//! For each state component `k`, compare the posterior standard deviation
//! `σ⁺_k = ‖row_k(S⁺)‖` with the one the filter would have without any
//! measurement, `σ⁰_k = ‖row_k(S⁰⁻)‖` (the prior propagated by
//! `PrognosisFK` alone):
//!
//! ```text
//! μ_k = 1 − σ⁺_k / σ⁰_k  ∈ [0, 1]
//! ```
//!
//! `μ = 0`: the measurements taught nothing about the component; `μ → 1`:
//! it is determined by the measurements, independently of the prior.

use crate::sr_iekf::SrState;
use nalgebra::SVector;

/// `MeasureS`: `μ_k = 1 − σ⁺_k/σ⁰_k` per component (0 when `σ⁰_k = 0`).
pub fn measure_s<const N: usize>(
    posterior: &SrState<N>,
    no_measurements: &SrState<N>,
) -> SVector<f64, N> {
    let sp = posterior.sigma();
    let s0 = no_measurements.sigma();
    SVector::from_fn(|k, _| {
        if s0[k] > 0.0 {
            (1.0 - sp[k] / s0[k]).clamp(0.0, 1.0)
        } else {
            0.0
        }
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
        processing(&mut post, &SVector::<f64, 2>::new(1.0, 0.0), 0.0, 1.0);
        let mu = measure_s(&post, &prior);
        assert!((mu[0] - (1.0 - (1.0f64 / 101.0).sqrt() * 10.0 / 10.0)).abs() < 1e-12);
        assert_eq!(mu[1], 0.0);
    }
}
