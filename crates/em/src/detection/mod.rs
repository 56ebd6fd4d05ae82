//! Signal chain from induction-coil voltages to real field vectors (seed
//! `001_…` part II, eqs. 2–4; spec `em-positioning.md`, "Signal chain").
//!
//! 0. [`impulse`]: impulsive samples far outside a block's robust spread
//!    are repaired (and reported) before detection.
//! 1. [`synchronous`]: FIR-weighted synchronous detection (eq. 2) of every
//!    channel at every working and pilot frequency, with the detector's
//!    frequency response (the seed's fig. 1).
//! 2. [`pilot`]: the bi-harmonic pilot at `ω0 ± δ` measures the channel
//!    sensitivity `ξ(ω0) ≈ G (U_R + U_L)/2` (eq. 4) and divides it out.
//! 3. [`chain`]: the whole chain to complex field vectors `χ⁻¹ ξ⁻¹ U0/(−iωg)`.
//! 4. [`system`]: the instrument constants (plan, gain, pilot, bench `χ`,
//!    nominal moments) the chain is built from.
//! 5. [`polarisation`]: the real field vector is the major axis of the
//!    polarisation ellipse; the minor/major ratio is the quality figure.
//!
//! ## Frequency plan
//!
//! With a periodic cosine-sum window of `N` samples at `f_s` (bin width
//! `Δf = f_s/N`), the response `A(Δ) = Σ f[n] e^{iΔ n/f_s}/Σ f[n]` is exactly
//! zero at `Δ = 2π m Δf` for integer `|m| ≥` the number of cosine terms (4 for
//! Blackman–Harris/Nuttall). Placing all working frequencies, pilots and the
//! 400 Hz power harmonics on bins at least 4 apart therefore removes their
//! cross-talk exactly (both the `ω − ω'` and the image `ω + ω'` terms).

pub mod chain;
pub mod impulse;
pub mod pilot;
pub mod polarisation;
pub mod synchronous;
pub mod system;

pub use chain::{FieldChain, FieldEpoch};
pub use impulse::{SPIKE_THRESHOLD, Spike};
pub use pilot::PilotCorrection;
pub use polarisation::{PolarisationEllipse, major_axis};
pub use synchronous::{DetectorConfig, Epoch, SyncDetector, block_centre_time_s};
pub use system::EmSystem;

/// Complex number type used for detected amplitudes.
pub type Complex64 = nalgebra::Complex<f64>;
