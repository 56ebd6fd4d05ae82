//! Catmull–Rom cubic interpolation (Keys' cubic convolution with `a = −½`).
//!
//! For a sample sequence `f_j` on a uniform grid and a point at fractional
//! offset `t ∈ [0, 1)` after node `j`:
//!
//! ```text
//! f(t) = w₋₁ f_{j−1} + w₀ f_j + w₁ f_{j+1} + w₂ f_{j+2}
//! w₋₁ = (−t³ + 2t² − t)/2     w₀ = (3t³ − 5t² + 2)/2
//! w₁  = (−3t³ + 4t² + t)/2    w₂ = (t³ − t²)/2
//! ```
//!
//! The interpolant passes through the samples, reproduces quadratics, has a
//! continuous first derivative (so the field seen along a flight path has a
//! continuous rate of change) and a third-order error `O(h³ f‴)` (Keys 1981,
//! *IEEE Trans. ASSP* 29:1153). Used horizontally (bicubic) and vertically on
//! the continued anomaly grids.

/// The four Catmull–Rom weights for nodes `j−1, j, j+1, j+2` at offset `t`.
#[inline]
pub fn catmull_rom_weights(t: f64) -> [f64; 4] {
    let t2 = t * t;
    let t3 = t2 * t;
    [
        0.5 * (-t3 + 2.0 * t2 - t),
        0.5 * (3.0 * t3 - 5.0 * t2 + 2.0),
        0.5 * (-3.0 * t3 + 4.0 * t2 + t),
        0.5 * (t3 - t2),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reproduces_quadratics_and_sums_to_one() {
        let f = |x: f64| 2.0 - 0.5 * x + 0.25 * x * x;
        for i in 0..=10 {
            let t = i as f64 / 10.0;
            let w = catmull_rom_weights(t);
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-15);
            let v: f64 = (0..4).map(|m| w[m] * f(m as f64 - 1.0)).sum();
            assert!((v - f(t)).abs() < 1e-13);
        }
    }
}
