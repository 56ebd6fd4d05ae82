//! Complex arithmetic helpers used by the filter design.
//!
//! The design code reproduces SciPy's floating-point path closely, so the two
//! operations whose textbook formulas lose accuracy are written out here:
//!
//! * division uses Smith's (1962) algorithm, the one NumPy uses for complex
//!   division, instead of `(a·c̄)/|c|²` (which overflows and loses digits);
//! * the square root uses the principal branch computed from `|z|` without
//!   trigonometric functions, `√z = t + i·y/(2t)` with `t = √((|x|+|z|)/2)`
//!   (C99 `csqrt`), honouring the sign of a zero imaginary part so that the
//!   branch cut `(−∞, 0]` is handled as NumPy does.

use nalgebra::Complex;

/// Shorthand for a double-precision complex number.
pub(crate) type C64 = Complex<f64>;

/// `a / b` by Smith's algorithm (NumPy's complex division).
pub(crate) fn cdiv(a: C64, b: C64) -> C64 {
    if b.re.abs() >= b.im.abs() {
        if b.re == 0.0 && b.im == 0.0 {
            return C64::new(a.re / b.re.abs(), a.im / b.re.abs());
        }
        let rat = b.im / b.re;
        let scl = 1.0 / (b.re + b.im * rat);
        C64::new((a.re + a.im * rat) * scl, (a.im - a.re * rat) * scl)
    } else {
        let rat = b.re / b.im;
        let scl = 1.0 / (b.im + b.re * rat);
        C64::new((a.re * rat + a.im) * scl, (a.im * rat - a.re) * scl)
    }
}

/// Principal square root (branch cut on the negative real axis; the sign of
/// the result's imaginary part follows the sign of `z.im`, also for `±0`).
pub(crate) fn csqrt(z: C64) -> C64 {
    let (x, y) = (z.re, z.im);
    if x == 0.0 && y == 0.0 {
        return C64::new(0.0, y);
    }
    let r = x.hypot(y);
    if x >= 0.0 {
        let t = ((x + r) * 0.5).sqrt();
        C64::new(t, y / (2.0 * t))
    } else {
        let t = ((-x + r) * 0.5).sqrt();
        C64::new(y.abs() / (2.0 * t), t.copysign(y))
    }
}

/// `true` when the imaginary part is exactly zero (NumPy's `isreal`).
pub(crate) fn is_real(z: C64) -> bool {
    z.im == 0.0
}

/// Product of all elements, left to right (NumPy's `prod` order); 1 when empty.
pub(crate) fn cprod(v: &[C64]) -> C64 {
    v.iter().fold(C64::new(1.0, 0.0), |acc, &z| acc * z)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn division_matches_definition() {
        let a = C64::new(1.5, -2.0);
        let b = C64::new(-0.25, 3.0);
        let q = cdiv(a, b);
        let back = q * b;
        assert!((back - a).norm() < 1e-15);
        let q2 = cdiv(a, C64::new(4.0, -0.5));
        assert!((q2 * C64::new(4.0, -0.5) - a).norm() < 1e-15);
    }

    #[test]
    fn sqrt_branches() {
        for z in [
            C64::new(4.0, 0.0),
            C64::new(-4.0, 0.0),
            C64::new(-4.0, -0.0),
            C64::new(3.0, -4.0),
            C64::new(-3.0, 4.0),
            C64::new(-3.0, -4.0),
        ] {
            let s = csqrt(z);
            assert!((s * s - z).norm() < 1e-14, "{z}");
            assert!(s.re >= 0.0);
            assert_eq!(s.im.is_sign_negative(), z.im.is_sign_negative());
        }
        assert_eq!(csqrt(C64::new(-4.0, 0.0)), C64::new(0.0, 2.0));
        assert_eq!(csqrt(C64::new(-4.0, -0.0)), C64::new(0.0, -2.0));
    }
}
