//! The `em` simulator scenario (spec `em-positioning.md`, "What to show";
//! issue 6 item 1): a three-dipole transmitter on the aircraft, a towed bird
//! 30–100 m away that swings and rotates, and ADC-level induction-coil
//! voltages with every distortion of the seed (`001_…` eqs. 3–5).
//!
//! Signal of channel `c` (V), with `b(t) = Re(B e^{−iωt})` conventions:
//!
//! ```text
//! u_c(t) = Σ_i Re[ ξ_c(ω_i,t) (χ_i (−iω_i g) B_i(t))_c e^{−iω_i t} ]           working
//!        + Σ_i Σ_± Re[ ξ_c(ω_i±δ,t) (χ_i (−i(ω_i±δ) g) P)_c e^{−i(ω_i±δ) t} ]   pilot
//!        + n_coil + n_400Hz + n_sferics
//! B_i(t) = R(t) Ω(r(t)) M'_i,   M' = (I + D) M  (D complex, |D_ij| ≤ 5 %, Re D symmetric)
//! ξ_c(ω,t) = (1 + a sin(2πt/T + ψ_c)) e^{i φ sin(2πt/T + ψ'_c)} e^{iωτ_c}
//! ```
//!
//! `g` is the coil gain (V per T/s, the voltage ∝ dB/dt), `χ_i` the complex
//! cross-coupling (unit diagonal, off-diagonal 3–5 %), `P` the pilot field in
//! bird axes (T), `a = ±5 %`, `φ = ±3°`, `T` the drift period (5 h).
//! Everything random is drawn from one ChaCha seed.

pub mod detected_csv;
pub mod raw_format;
pub mod scenario;
pub mod synthesis;
pub mod truth_csv;

pub use detected_csv::{detected_csv, field_epoch_from_values, value_columns};
pub use raw_format::{MAX_CHANNELS, RawHeader, RawReader, read_raw, write_raw};
pub use scenario::{EmScenario, EmSimConfig};
pub use synthesis::{EmRecording, synthesize};
pub use truth_csv::{known_csv, truth_csv};

#[cfg(test)]
mod tests;
