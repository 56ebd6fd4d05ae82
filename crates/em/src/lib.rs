//! # aeromag-em
//!
//! Relative positioning of a towed receiver bird in the low-frequency field of
//! a three-dipole transmitter (spec `em-positioning.md`, seed `001_…`,
//! Volkovitsky, Karshakov, Pavlov: "Positioning of moving objects in a
//! low-frequency electromagnetic field", parts I–II).
//!
//! ## Model
//!
//! The transmitter is three co-located point dipoles with linearly independent
//! moments `M_i` (A·m², the columns of `M`) at three frequencies `ω_i`. The
//! receiver at `r` (m, transmitter frame) with axes turned by the rotation `R`
//! (transmitter-frame vectors → receiver axes) measures, quasi-statically,
//!
//! ```text
//! H = R Ω(r) M,   Ω(r) = μ0/(4π|r|³) (3 e eᵀ − I),   e = r/|r|     [T]
//! ```
//!
//! (columns of `H` = the three dipoles' fields in receiver axes; we work in
//! flux density `B`, so `Ω` is [`aeromag_core::field::dipole::dipole_matrix`]).
//!
//! ## Modules
//!
//! | module | contents |
//! |---|---|
//! | [`positioning`] | Gram matrix, closed-form range/direction/attitude, SO(3) projection, LM polish |
//! | [`detection`] | FIR-weighted synchronous detection, its frequency response, pilot correction, polarisation ellipse |
//! | [`calibration`] | three-stage calibration (polarisation, transmitter geometry, attitude), JSON, run-time application |
//! | [`sim`] | the `em` scenario: ADC-level three-channel coil voltages with all distortions, binary raw format |
//! | [`error`] | [`EmError`], with `is_bad_input()` |
//! | [`study`] | the full-chain flight study (simulation → detection → calibration → positioning) shared by tests, CLI and demo; error curves versus range and noise |
//!
//! ## Pipeline (what `aeromag em simulate|detect|calibrate|locate` wires together)
//!
//! 1. `sim::synthesize(&EmScenario::new(cfg)?)` → interleaved f32 volts
//!    (`sim::write_raw` / `sim::read_raw` for the binary file, whose header
//!    carries the instrument constants [`detection::EmSystem`], never truth;
//!    `sim::truth_csv` / `sim::known_csv` write the truth and the
//!    calibration information apart).
//! 2. `EmSystem::chain(rate, N, window, use_pilot)?.process(samples, start_index)?`
//!    → `FieldEpoch`s (complex fields, T); `sim::detected_csv` writes them.
//! 3. `calibration::Calibration::fit(epochs, &KnownPoints, &M, &hemisphere)`:
//!    stage 1 on all epochs, stage 2 from known positions, stage 3 from
//!    known attitudes; `calibration::CalibrationFile` is the versioned JSON.
//! 4. `Calibration::locate(&epoch.h, &M, &mut Hemisphere::new(n))` per epoch
//!    → pose, range, Euler angles (`Pose::attitude`), polarisation ratios,
//!    residual, hemisphere flag. `positioning::error_study` gives the
//!    closed-form errors versus range/noise on ideal fields,
//!    `study::error_curves` those of the whole calibrated chain.

pub mod calibration;
pub mod detection;
pub mod error;
pub mod positioning;
pub mod sim;
pub mod study;

pub use error::EmError;

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, EmError>;

/// `true` for a finite, strictly positive number (NaN-safe domain check).
pub(crate) fn positive_finite(x: f64) -> bool {
    x.is_finite() && x > 0.0
}
