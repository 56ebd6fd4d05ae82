//! Sensor models: what the instruments record given the true fields and
//! motion (spec `simulator.md`, "Sensors").
//!
//! * [`scalar`] — caesium/potassium total-field magnetometer: heading error,
//!   optional first-order lag, white noise.
//! * [`fluxgate`] — three-axis vector magnetometer: misalignment,
//!   non-orthogonality, scale errors, bias, noise.
//! * [`nav`] — GNSS/INS position, velocity and attitude errors.
//! * [`base_station`] — the ground magnetometer that records the diurnal
//!   variation.
//!
//! White-noise levels are given as one-sided noise densities `ρ` (unit/√Hz);
//! sampled at `f_s` the RMS is `σ = ρ √(f_s/2)` (the noise occupies the band
//! 0…f_s/2).

pub mod base_station;
pub mod fluxgate;
pub mod nav;
pub mod scalar;

/// RMS of white noise of one-sided density `density` (unit/√Hz) sampled at
/// `rate_hz`: `σ = ρ √(f_s/2)`.
pub fn white_rms(density: f64, rate_hz: f64) -> f64 {
    density * (0.5 * rate_hz).sqrt()
}
