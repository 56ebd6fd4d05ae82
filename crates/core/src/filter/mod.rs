//! Digital filters: Butterworth design, zero-phase filtering, FIR windows.
//!
//! Everything here reproduces SciPy's `scipy.signal` results (the tests in
//! `tests/filter_reference.rs` compare against stored SciPy output), with
//! errors instead of exceptions and without panics on bad input.
//!
//! ## IIR filters
//!
//! * [`butter`] designs a digital Butterworth filter (analog prototype →
//!   frequency transform → bilinear transform → second-order sections,
//!   [`butterworth`], [`zpk`], [`zpk2sos`](mod@zpk2sos)) and returns [`Sos`], SciPy's
//!   `butter(N, Wn, btype, fs=fs, output='sos')`.
//! * [`sosfilt`] / [`lfilter`] filter one way (causal, zero initial state).
//! * [`sosfiltfilt`] / [`filtfilt()`] filter forward and backward (zero phase,
//!   response `|H|²`) with SciPy's odd padding and steady-state initial
//!   conditions ([`filtfilt`](mod@filtfilt) module docs give the convention).
//! * [`BandPass`] is the designed-once band-pass that the compensation
//!   ("Method 1" of `spec/compensation.md`) applies to every column.
//!
//! ## FIR filters and windows
//!
//! * [`Window`] with [`Symmetry`]: Hann, Hamming, Blackman, Blackman–Harris,
//!   Nuttall (cosine sums, [`window`]), Dolph–Chebyshev ([`chebwin`](mod@chebwin)),
//!   Kaiser ([`kaiser`](mod@kaiser)), rectangular.
//! * [`firwin_lowpass`]: windowed-sinc low-pass taps (SciPy `firwin`).
//!
//! Frequencies are in hertz throughout, with the sampling rate `fs_hz`
//! given explicitly.
//!
//! References: SciPy reference guide (`scipy.signal`: `butter`, `zpk2sos`,
//! `sosfilt`, `sosfilt_zi`, `sosfiltfilt`, `filtfilt`, `lfilter_zi`,
//! `firwin`, `get_window`); Harris, F. J. (1978), "On the use of windows for
//! harmonic analysis with the discrete Fourier transform", Proc. IEEE 66(1);
//! Gustafsson, F. (1996), "Determining the initial states in
//! forward-backward filtering", IEEE Trans. Signal Processing 44(4).

mod complex;
pub(crate) mod validate;

pub mod bandpass;
pub mod butterworth;
pub mod chebwin;
pub mod filtfilt;
pub mod firwin;
pub mod kaiser;
pub mod sos;
pub mod transfer;
pub mod window;
pub mod zpk;
pub mod zpk2sos;

pub use bandpass::BandPass;
pub use butterworth::{Band, MAX_ORDER, buttap, butter, butter_zpk};
pub use chebwin::chebwin;
pub use filtfilt::{
    FILTER_LANES, filtfilt, sosfiltfilt, sosfiltfilt_columns_in_place,
    sosfiltfilt_columns_propagating_with, sosfiltfilt_columns_with, sosfiltfilt_in_place,
};
pub use firwin::firwin_lowpass;
pub use kaiser::{bessel_i0, kaiser};
pub use sos::{Sos, sosfilt};
pub use transfer::{TransferFunction, lfilter, lfilter_zi};
pub use window::{Symmetry, Window, cosine_sum};
pub use zpk::Zpk;
pub use zpk2sos::zpk2sos;
