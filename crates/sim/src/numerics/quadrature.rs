//! Adaptive Simpson quadrature.
//!
//! On `[a, b]` with midpoint `m`, Simpson's rule `S(a, b) = (b − a)/6 ·
//! (f(a) + 4 f(m) + f(b))` is compared with the sum of the two halves
//! `S(a, m) + S(m, b)`; the interval is accepted when they differ by less
//! than `15 ε` (Richardson: the halves' error is ≈ 1/15 of the difference)
//! and the extrapolated value `S₂ + (S₂ − S₁)/15` is returned, else both
//! halves are refined with `ε/2` (Lyness 1969). Used for the radial spectral
//! moments of the anomaly model (smooth integrands with features at very
//! different scales).

/// `∫_a^b f` to absolute tolerance `eps` (recursion depth at most 48).
pub fn adaptive_simpson(f: &impl Fn(f64) -> f64, a: f64, b: f64, eps: f64) -> f64 {
    let (fa, fm, fb) = (f(a), f(0.5 * (a + b)), f(b));
    let whole = (b - a) / 6.0 * (fa + 4.0 * fm + fb);
    refine(f, a, b, fa, fm, fb, whole, eps, 48)
}

#[allow(clippy::too_many_arguments)]
fn refine(
    f: &impl Fn(f64) -> f64,
    a: f64,
    b: f64,
    fa: f64,
    fm: f64,
    fb: f64,
    whole: f64,
    eps: f64,
    depth: u32,
) -> f64 {
    let m = 0.5 * (a + b);
    let (lm, rm) = (0.5 * (a + m), 0.5 * (m + b));
    let (flm, frm) = (f(lm), f(rm));
    let left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
    let right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
    let delta = left + right - whole;
    if depth == 0 || delta.abs() <= 15.0 * eps {
        return left + right + delta / 15.0;
    }
    refine(f, a, m, fa, flm, fm, left, 0.5 * eps, depth - 1)
        + refine(f, m, b, fm, frm, fb, right, 0.5 * eps, depth - 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_integrals() {
        let v = adaptive_simpson(&|x: f64| x.powi(3) * (-x).exp(), 0.0, 60.0, 1e-13);
        assert!((v - 6.0).abs() < 1e-10, "{v}");
        let v = adaptive_simpson(&|x: f64| 1.0 / (1.0 + x * x), 0.0, 1.0, 1e-14);
        assert!((v - std::f64::consts::FRAC_PI_4).abs() < 1e-12, "{v}");
    }
}
