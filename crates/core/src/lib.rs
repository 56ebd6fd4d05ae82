//! # aeromag-core
//!
//! The physics and signal-processing base of aeromag.
//!
//! ## Frames and conventions (used by every crate)
//!
//! * **Navigation frame NED**: x north, y east, z down.
//! * **Body frame**: x forward (nose), y right wing, z down.
//! * **Euler angles** yaw ψ, pitch θ, roll φ, applied in the aerospace Z-Y-X
//!   order; `C_nb` ([`frames::Attitude::c_nb`]) rotates body vectors into NED:
//!   `v_n = C_nb · v_b`.
//! * **Units**: SI inside the code (tesla, metre, second, radian, A·m²);
//!   files use nT and degrees. Every public function names its units.
//!
//! ## Modules
//!
//! | module | contents |
//! |---|---|
//! | [`frames`] | rotations, Euler angles, WGS84 geodetic ↔ geocentric |
//! | [`estimability`] | the estimability convention μ = σ⁺/σ⁰ (0 = determined) |
//! | [`field`] | magnetic dipole field and gradients; IGRF-14 main field |
//! | [`filter`] | Butterworth design, zero-phase filtering, FIR windows |
//! | [`spectrum`] | Welch power spectral density |
//! | [`random`] | seeded random streams (ChaCha8, one stream per purpose) |
//! | [`time`] | calendar dates and decimal years |
//! | [`median`] | the median of a sample (one definition for every crate) |
//! | [`quadrature`] | composite Simpson's rule (reference integrals in tests) |
//! | [`simd`] | kernels compiled with and without AVX, chosen at run time |
//! | [`memory`] | the memory this process can still take (refusing work sized beyond it) |
//! | [`output_target`] | where an output goes: a regular file (written atomically) or a device, FIFO or socket |
//! | [`cancel`] | stopping a long computation between its steps ([`cancel::Cancelled`]) |
//! | [`error`] | [`CoreError`], with `is_bad_input()` |

pub mod cancel;
pub mod error;
pub mod estimability;
pub mod field;
pub mod file_name;
pub mod filter;
pub mod frames;
pub mod median;
pub mod memory;
pub mod output_target;
pub mod parallel;
pub mod quadrature;
pub mod random;
pub mod simd;
pub mod spectrum;
pub mod time;

pub use error::CoreError;

/// μ0/(4π) in T·m/A (exactly 1e-7 to the precision used here).
pub const MU0_OVER_4PI: f64 = 1e-7;
/// Tesla per nanotesla.
pub const T_PER_NT: f64 = 1e-9;
/// Nanotesla per tesla.
pub const NT_PER_T: f64 = 1e9;
