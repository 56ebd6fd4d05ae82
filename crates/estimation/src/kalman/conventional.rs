//! The conventional (covariance-form) Kalman filter with the Joseph update
//! and the textbook Rauch–Tung–Striebel smoother: the reference against
//! which the square-root algorithms are tested.
//!
//! ```text
//! predict:  x⁻ = Φ x,   P⁻ = Φ P Φᵀ + Q
//! update:   α = hᵀP⁻h + r,  K = P⁻h/α,  x = x⁻ + K (y − hᵀx⁻),
//!           P = (I − K hᵀ) P⁻ (I − K hᵀ)ᵀ + r K Kᵀ        (Joseph form)
//! smooth:   C_k = P_k Φ_{k+1}ᵀ (P⁻_{k+1})⁻¹,
//!           x^s_k = x_k + C_k (x^s_{k+1} − x⁻_{k+1}),
//!           P^s_k = P_k + C_k (P^s_{k+1} − P⁻_{k+1}) C_kᵀ
//! ```
//!
//! The Joseph form keeps `P` symmetric positive semi-definite to first order
//! in round-off errors but costs `O(n³)` per scalar update and loses half the
//! digits the square-root form keeps; use [`super::SqrtKalmanFilter`] in
//! production. References: Grewal & Andrews (2015) §5.3 and §4.2 (Joseph);
//! H. E. Rauch, F. Tung, C. T. Striebel, "Maximum likelihood estimates of
//! linear dynamic systems", *AIAA J.* 3 (1965) 1445–1450.

use super::innovation::Innovation;
use crate::error::{EstError, Result};
use nalgebra::{DMatrix, DVector};

/// A covariance-form Kalman filter with Joseph-form scalar updates.
#[derive(Debug, Clone)]
pub struct ConventionalKalmanFilter {
    /// State estimate.
    pub x: DVector<f64>,
    /// Covariance.
    pub p: DMatrix<f64>,
}

impl ConventionalKalmanFilter {
    /// A filter with prior mean `x0` and covariance `p0`.
    pub fn new(x0: DVector<f64>, p0: DMatrix<f64>) -> Result<Self> {
        if p0.nrows() != x0.len() || p0.ncols() != x0.len() {
            return Err(EstError::Dimension(
                "prior covariance does not match the state".into(),
            ));
        }
        Ok(Self { x: x0, p: p0 })
    }

    /// `x ← Φx`, `P ← ΦPΦᵀ + Q`.
    pub fn predict(&mut self, phi: &DMatrix<f64>, q: &DMatrix<f64>) {
        self.x = phi * &self.x;
        self.p = phi * &self.p * phi.transpose() + q;
    }

    /// Joseph-form scalar update; returns the innovation.
    pub fn update(&mut self, h: &[f64], y: f64, r: f64) -> Result<Innovation> {
        let n = self.x.len();
        if h.len() != n {
            return Err(EstError::Dimension("measurement row length".into()));
        }
        if r.is_nan() || r <= 0.0 || !y.is_finite() {
            return Err(EstError::NonFinite {
                what: "measurement",
            });
        }
        let h = DVector::from_column_slice(h);
        let ph = &self.p * &h;
        let alpha = h.dot(&ph) + r;
        let k = ph / alpha;
        let nu = y - h.dot(&self.x);
        self.x += &k * nu;
        let a = DMatrix::identity(n, n) - &k * h.transpose();
        self.p = &a * &self.p * a.transpose() + &k * k.transpose() * r;
        Ok(Innovation {
            value: nu,
            variance: alpha,
        })
    }
}

/// One step of the textbook RTS smoother: from the filtered `(x_k, P_k)`,
/// the predicted `(x⁻_{k+1}, P⁻_{k+1})`, `Φ_{k+1}` and the smoothed
/// `(x^s_{k+1}, P^s_{k+1})`, return `(x^s_k, P^s_k)`.
pub fn rts_step_conventional(
    filtered: (&DVector<f64>, &DMatrix<f64>),
    predicted: (&DVector<f64>, &DMatrix<f64>),
    phi_next: &DMatrix<f64>,
    smoothed_next: (&DVector<f64>, &DMatrix<f64>),
) -> Result<(DVector<f64>, DMatrix<f64>)> {
    let pinv = predicted
        .1
        .clone()
        .try_inverse()
        .ok_or_else(|| EstError::Singular("predicted covariance is singular".into()))?;
    let c = filtered.1 * phi_next.transpose() * pinv;
    let x = filtered.0 + &c * (smoothed_next.0 - predicted.0);
    let p = filtered.1 + &c * (smoothed_next.1 - predicted.1) * c.transpose();
    Ok((x, p))
}
