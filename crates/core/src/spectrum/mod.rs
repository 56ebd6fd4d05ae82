//! Spectral estimation.
