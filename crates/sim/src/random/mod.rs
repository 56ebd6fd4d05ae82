//! Seeded randomness: one ChaCha stream per physical component, and the
//! coloured-noise generators built on it.
//!
//! Every random draw of the simulator comes from a [`ChaCha8Rng`] seeded with
//! the scenario seed and switched to a component-specific *stream*
//! ([`Stream`]), the scheme of [`aeromag_core::random`]. Streams are independent, so that adding a component or
//! changing the length of one process does not change the draws of another:
//! the anomaly of a survey area stays the same when the diurnal settings
//! change. The same seed gives bit-identical output on the same build and
//! machine (spec `README.md`, "Conventions").
//!
//! * [`gauss_markov`] — first-order Gauss–Markov process, exact discretisation.
//! * [`spectral`] — stationary Gaussian processes of any power spectral
//!   density by FFT synthesis (turbulence, diurnal variation,
//!   micropulsations).

pub mod gauss_markov;
pub mod spectral;

pub use aeromag_core::random::{normal, normals};
use rand_chacha::ChaCha8Rng;

/// The independent random streams of the simulator (the discriminant is the
/// ChaCha stream number; never renumber an existing entry).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u64)]
pub enum Stream {
    /// Crustal anomaly grid.
    Anomaly = 1,
    /// Diurnal variation and micropulsations.
    Diurnal = 2,
    /// Atmospheric turbulence of the trajectory.
    Turbulence = 3,
    /// Scalar magnetometer noise.
    ScalarNoise = 4,
    /// Fluxgate noise.
    FluxgateNoise = 5,
    /// GNSS/INS errors.
    Navigation = 6,
    /// Base-station magnetometer noise.
    BaseStation = 7,
    /// On-board electric currents.
    Currents = 8,
    /// Helicopter rotor speed and initial phase.
    HelicopterRotor = 16,
    /// Noise of the recorded rotor phase.
    HelicopterRotorPhase = 17,
    /// Wind forcing of the towed pod's swing.
    PodWind = 18,
    /// Altitude and speed wander of the towed-pod flight.
    PodTrack = 19,
    /// Pod magnetometer and cable-angle noise.
    PodNoise = 20,
}

/// A generator for `stream` of the scenario `seed`.
pub fn rng_for(seed: u64, stream: Stream) -> ChaCha8Rng {
    aeromag_core::random::stream(seed, stream as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_are_reproducible_and_distinct() {
        let a = normals(&mut rng_for(7, Stream::Anomaly), 8);
        let b = normals(&mut rng_for(7, Stream::Anomaly), 8);
        let c = normals(&mut rng_for(7, Stream::Diurnal), 8);
        let d = normals(&mut rng_for(8, Stream::Anomaly), 8);
        assert_eq!(a, b);
        assert_ne!(a, c);
        assert_ne!(a, d);
    }
}
