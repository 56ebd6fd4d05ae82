//! The external magnetic field: main field, crustal anomaly, diurnal
//! variation (spec `simulator.md`, "Fields").
//!
//! The external field at a point is the vector sum
//!
//! ```text
//! B_ext(p, t) = B_IGRF(p, t) + B_anomaly(p) + d(t) · B_IGRF/|B_IGRF|        nT, NED
//! ```
//!
//! * [`main_field`] — IGRF-14 (from `aeromag-core`).
//! * [`anomaly`] — random crustal field with a power-law spectrum, generated
//!   on a grid and continued upward exactly by FFT, plus
//! * [`sources`] — discrete dipoles (and uniformly magnetised spheres, whose
//!   external field is a dipole's).
//! * [`diurnal`] — the time variation `d(t)`: a smooth random process plus
//!   micropulsations, applied along the main-field direction.

pub mod anomaly;
pub mod diurnal;
pub mod main_field;
pub mod sources;
