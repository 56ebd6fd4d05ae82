//! Small numerical building blocks of the simulator.
//!
//! * [`fft2`] — 2-D real FFT (rows real-to-complex, columns complex) for the
//!   anomaly grid.
//! * [`interp`] — Catmull–Rom cubic interpolation weights (1-D, used as a
//!   tensor product in 2-D/3-D).
//! * [`lag`] — exact discretisations of the first-order lag `τ ẏ + y = u`.
//! * [`quadrature`] — adaptive Simpson integration.

pub mod fft2;
pub mod interp;
pub mod lag;
pub mod quadrature;

/// Smallest `m ≥ n` of the form `2^a 3^b 5^c` (fast FFT length).
pub fn next_fast_len(n: usize) -> usize {
    let mut m = n.max(1);
    loop {
        let mut r = m;
        for p in [2, 3, 5] {
            while r.is_multiple_of(p) {
                r /= p;
            }
        }
        if r == 1 {
            return m;
        }
        m += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fast_lengths() {
        assert_eq!(next_fast_len(1), 1);
        assert_eq!(next_fast_len(7), 8);
        assert_eq!(next_fast_len(97), 100);
        assert_eq!(next_fast_len(1001), 1024);
        assert_eq!(next_fast_len(121), 125);
    }
}
