//! Seeded random streams: the one scheme every simulator and study of
//! aeromag draws from.
//!
//! A generator is ChaCha8 (`rand_chacha`) seeded with the scenario seed
//! (`seed_from_u64`, which expands the 64-bit seed with PCG32) and switched
//! to a **stream number** (`set_stream`). Streams of one seed are
//! independent sequences of 2⁶⁸ words each, so a component that draws more
//! or fewer numbers never shifts the draws of another: each simulator keeps
//! a registry of its stream numbers (e.g. `aeromag_sim::random::Stream`) and
//! never renumbers an entry. Stream 0 is `seed_from_u64(seed)` itself.
//!
//! Same seed and stream ⇒ bit-identical draws on every machine and thread
//! count (the draws depend on nothing else).
//!
//! ```
//! use aeromag_core::random::{normals, stream};
//! let a = normals(&mut stream(7, 3), 4);
//! assert_eq!(a, normals(&mut stream(7, 3), 4)); // reproducible
//! assert_ne!(a, normals(&mut stream(7, 4), 4)); // another stream
//! assert_ne!(a, normals(&mut stream(8, 3), 4)); // another seed
//! ```

use rand::{RngExt, SeedableRng};
pub use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

/// The generator of stream `stream` of `seed`.
pub fn stream(seed: u64, stream: u64) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(stream);
    rng
}

/// One standard normal draw (ziggurat, `rand_distr::StandardNormal`).
#[inline]
pub fn normal(rng: &mut ChaCha8Rng) -> f64 {
    rng.sample(StandardNormal)
}

/// `n` independent standard normal draws.
pub fn normals(rng: &mut ChaCha8Rng, n: usize) -> Vec<f64> {
    (0..n).map(|_| normal(rng)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stream_zero_is_the_plain_seeded_generator() {
        let mut a = stream(11, 0);
        let mut b = ChaCha8Rng::seed_from_u64(11);
        assert_eq!(normals(&mut a, 16), normals(&mut b, 16));
    }

    #[test]
    fn streams_do_not_shift_each_other() {
        // Drawing more from stream 1 leaves stream 2 untouched.
        let mut one = stream(5, 1);
        let _ = normals(&mut one, 1000);
        assert_eq!(normals(&mut stream(5, 2), 8), normals(&mut stream(5, 2), 8));
        assert_ne!(normals(&mut stream(5, 1), 8), normals(&mut stream(5, 2), 8));
    }
}
