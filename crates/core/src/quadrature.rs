//! Composite Simpson's rule, for reference integrals in tests.
//!
//! ```text
//! ∫_a^b f(x) dx ≈ h Σ_{i=0}^{m} w_i f(a + i h),   h = (b − a)/m,   m even,
//! w = (1, 4, 2, 4, …, 2, 4, 1)/3
//! ```
//!
//! exact for cubics, error `O(h⁴)` (Press et al., *Numerical Recipes*,
//! 3rd ed., §4.1).

/// The weight `w_i` of node `i` of `m` intervals (`m` even, `i ≤ m`).
pub fn simpson_weight(i: usize, m: usize) -> f64 {
    debug_assert!(
        m.is_multiple_of(2) && i <= m,
        "Simpson: node {i} of {m} intervals"
    );
    if i == 0 || i == m {
        1.0 / 3.0
    } else if i % 2 == 1 {
        4.0 / 3.0
    } else {
        2.0 / 3.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_for_a_cubic() {
        // ∫_0^2 (x³ − 2x + 1) dx = 4 − 4 + 2 = 2.
        let (m, h) = (4, 0.5);
        let sum: f64 = (0..=m)
            .map(|i| {
                let x = i as f64 * h;
                h * simpson_weight(i, m) * (x * x * x - 2.0 * x + 1.0)
            })
            .sum();
        assert!((sum - 2.0).abs() < 1e-14, "{sum}");
    }
}
