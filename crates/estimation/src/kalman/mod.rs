//! Square-root Kalman filtering and Rauch–Tung–Striebel smoothing.
//!
//! Spec `README.md` (crate `estimation`: "square-root Kalman filter with
//! scalar sequential updates, RTS smoother") and `compensation.md`
//! ("Method 2"); seed `000_…` §11 and appendices §21–22 (Kalman filter and
//! smoothing).
//!
//! ## The problem
//!
//! ```text
//! x_k = Φ_k x_{k−1} + G_k w_k,   w_k ~ N(0, I)      (Q_k = G_k G_kᵀ, exact discretisation by the caller)
//! y_k = h_kᵀ x_k + v_k,          v_k ~ N(0, r_k)    (scalar measurements, processed one at a time)
//! ```
//!
//! The filter gives `E[x_k | y_1..y_k]` and its covariance; the smoother
//! `E[x_k | y_1..y_N]`. The innovations `ν_k = y_k − h_kᵀ x⁻_k` with variance
//! `σ_k² = h_kᵀ P⁻_k h_k + r_k` give the log-likelihood used to tune noise
//! intensities.
//!
//! ## Why square roots
//!
//! The covariance is never formed: it is carried as an upper-triangular
//! factor `S`, `P = S Sᵀ`. The condition number of `S` is the square root of
//! that of `P`, so the filter keeps twice the significant digits and `P`
//! stays symmetric positive semi-definite by construction — which matters
//! for the compensation problem, where parameter variances shrink from
//! diffuse (10⁶) to tiny (10⁻⁴) over a flight (Bierman 1977, ch. I and VII;
//! P. Kaminski, A. Bryson, S. Schmidt, "Discrete square root filtering: a
//! survey of current techniques", *IEEE TAC* 16 (1971) 727–736).
//!
//! ## One algorithm per file
//!
//! | file | algorithm |
//! |---|---|
//! | [`carlson`] | Carlson's triangular scalar measurement update, `O(n²)` |
//! | [`triangularize`] | Householder RQ re-triangularisation of a wide factor (time updates, smoother) |
//! | [`filter`] | [`SqrtKalmanFilter`]: the filter; cheap time update when constant parameters are ordered last |
//! | [`rts`] | one square-root RTS backward step ([`SqrtRts`]) |
//! | [`mbf`] | the modified Bryson–Frazier smoother: smoothed means by an adjoint recursion, no gain |
//! | [`fixed_interval`] | forward filter + backward smoother over a record, with checkpointing (`O(√N n²)` memory) |
//! | [`lanes`] | four filters of 5, 6 or 8 states stepped together in SIMD lanes, bit for bit each filter alone: augmented ([`AugmentedLanes`], the likelihood and the field filter's groups) and plain ([`FilterLanes`], the smoother's block re-runs) |
//! | [`innovation`] | innovations and their Gaussian log-likelihood |
//! | [`augmented`] | the likelihood with constant regression coefficients integrated out, from a filter of the dynamic states alone ([`AugmentedFilter`]) |
//! | [`conventional`] | the Joseph-form filter and textbook RTS smoother: the test reference |
//!
//! References: G. J. Bierman, *Factorization Methods for Discrete Sequential
//! Estimation* (Academic Press 1977); M. S. Grewal & A. P. Andrews, *Kalman
//! Filtering: Theory and Practice* (4th ed., Wiley 2015); C. L. Thornton,
//! *Triangular Covariance Factorizations for Kalman Filtering* (UCLA 1976).

pub mod augmented;
pub mod carlson;
pub mod conventional;
pub mod filter;
pub mod fixed_interval;
pub mod innovation;
pub mod lanes;
pub mod mbf;
pub mod rts;
pub mod triangularize;

pub use augmented::{AugmentedFilter, AugmentedSolution};
pub use conventional::{ConventionalKalmanFilter, rts_step_conventional};
pub use filter::{LeadingConditional, SqrtKalmanFilter, upper_cholesky};
pub use fixed_interval::{
    Checkpoint, SmootherOptions, StateSpaceModel, default_block_len, filter_checkpoints,
    fixed_interval_smooth, smooth_from_checkpoints,
};
pub use innovation::Innovation;
pub use lanes::{AugmentedLanes, FILTER_LANES, FilterLanes, FilterStep, LaneStep, Reading};
pub use mbf::{MbfAdjoint, MbfUpdate};
pub use rts::SqrtRts;

#[cfg(test)]
mod tests;
