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

/// Stream numbers of the extra scalar magnetometers start here (the
/// sensor's index is added), far above the fixed entries.
pub const EXTRA_SCALAR_STREAM_BASE: u64 = 1 << 32;
/// Stream numbers of the extra fluxgates start here.
pub const EXTRA_FLUXGATE_STREAM_BASE: u64 = 2 << 32;

/// The independent random streams of the simulator ([`Stream::id`] is the
/// ChaCha stream number; never renumber an existing entry).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stream {
    /// Crustal anomaly grid (stream 1).
    Anomaly,
    /// Diurnal variation and micropulsations (2).
    Diurnal,
    /// Atmospheric turbulence of the trajectory (3).
    Turbulence,
    /// Scalar magnetometer noise (4).
    ScalarNoise,
    /// Fluxgate noise (5).
    FluxgateNoise,
    /// GNSS/INS errors (6).
    Navigation,
    /// Base-station magnetometer noise (7).
    BaseStation,
    /// On-board electric currents (8).
    Currents,
    /// Helicopter rotor speed and initial phase (16).
    HelicopterRotor,
    /// Noise of the recorded rotor phase (17).
    HelicopterRotorPhase,
    /// Wind forcing of the towed pod's swing (18).
    PodWind,
    /// Altitude and speed wander of the towed-pod flight (19).
    PodTrack,
    /// Pod magnetometer and cable-angle noise (20).
    PodNoise,
    /// Noise of the extra scalar magnetometer whose column is `mag_<k>`
    /// (k = 2, 3, …): stream [`EXTRA_SCALAR_STREAM_BASE`]` + k`.
    ExtraScalarNoise(u32),
    /// Noise of the extra fluxgate number `j` (j = 1 for `flux_b`, 2 for
    /// `flux_c`, …): stream [`EXTRA_FLUXGATE_STREAM_BASE`]` + j`.
    ExtraFluxgateNoise(u32),
}

impl Stream {
    /// The ChaCha stream number.
    pub fn id(self) -> u64 {
        match self {
            Self::Anomaly => 1,
            Self::Diurnal => 2,
            Self::Turbulence => 3,
            Self::ScalarNoise => 4,
            Self::FluxgateNoise => 5,
            Self::Navigation => 6,
            Self::BaseStation => 7,
            Self::Currents => 8,
            Self::HelicopterRotor => 16,
            Self::HelicopterRotorPhase => 17,
            Self::PodWind => 18,
            Self::PodTrack => 19,
            Self::PodNoise => 20,
            Self::ExtraScalarNoise(k) => EXTRA_SCALAR_STREAM_BASE + u64::from(k),
            Self::ExtraFluxgateNoise(j) => EXTRA_FLUXGATE_STREAM_BASE + u64::from(j),
        }
    }
}

/// A generator for `stream` of the scenario `seed`.
pub fn rng_for(seed: u64, stream: Stream) -> ChaCha8Rng {
    aeromag_core::random::stream(seed, stream.id())
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

    #[test]
    fn stream_numbers_are_stable_and_extra_sensors_get_their_own() {
        use Stream::*;
        let fixed = [
            (Anomaly, 1),
            (Diurnal, 2),
            (Turbulence, 3),
            (ScalarNoise, 4),
            (FluxgateNoise, 5),
            (Navigation, 6),
            (BaseStation, 7),
            (Currents, 8),
            (HelicopterRotor, 16),
            (HelicopterRotorPhase, 17),
            (PodWind, 18),
            (PodTrack, 19),
            (PodNoise, 20),
        ];
        for (s, id) in fixed {
            assert_eq!(s.id(), id, "{s:?}");
        }
        // The same generator as the number it always had.
        let a = normals(&mut rng_for(3, ScalarNoise), 4);
        let b = normals(&mut aeromag_core::random::stream(3, 4), 4);
        assert_eq!(a, b);
        let mut ids: Vec<u64> = fixed.iter().map(|(s, _)| s.id()).collect();
        ids.extend((2..40).map(|k| ExtraScalarNoise(k).id()));
        ids.extend((1..26).map(|j| ExtraFluxgateNoise(j).id()));
        let n = ids.len();
        ids.sort_unstable();
        ids.dedup();
        assert_eq!(ids.len(), n);
        assert_ne!(
            normals(&mut rng_for(3, ExtraScalarNoise(2)), 4),
            normals(&mut rng_for(3, ExtraScalarNoise(3)), 4)
        );
    }
}
