//! Magnetic fields: point dipoles and the IGRF-14 main field.

pub mod dipole;
pub mod igrf;
