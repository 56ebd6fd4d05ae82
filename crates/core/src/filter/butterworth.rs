//! Digital Butterworth filter design, returning second-order sections equal
//! to SciPy's `signal.butter(N, Wn, btype, fs=fs, output='sos')`.
//!
//! Steps (SciPy's `iirfilter` path; Butterworth 1930; Oppenheim & Schafer,
//! *Discrete-Time Signal Processing*, §7.1):
//!
//! 1. **Analog prototype** of order `N`, cutoff 1 rad/s, no zeros, unit gain,
//!    poles evenly spaced on the left half of the unit circle:
//!    ```text
//!    p_m = −exp(iπ m/(2N)),   m = −N+1, −N+3, …, N−1        |H(iω)|² = 1/(1 + ω^{2N})
//!    ```
//! 2. **Pre-warping**: a critical frequency `f` (Hz) is normalised to
//!    `W = f/(fs/2)` and warped to the analog frequency that the bilinear
//!    transform (with its sampling rate set to 2) maps back onto `W`:
//!    `ω = 2·2·tan(π W/2)` (rad/s).
//! 3. **Frequency transform** of the prototype ([`super::zpk::Zpk`]): low-pass or
//!    high-pass with `ω`; band-pass or band-stop with centre
//!    `ω0 = √(ω_lo ω_hi)` and width `Δω = ω_hi − ω_lo`.
//! 4. **Bilinear transform** `s = 2·fs'·(z − 1)/(z + 1)` with `fs' = 2`.
//! 5. **Second-order sections** with SciPy's "nearest" pairing
//!    ([`super::zpk2sos`](mod@super::zpk2sos)).
//!
//! Band-pass and band-stop designs have `2N` poles (`N` sections); low-pass
//! and high-pass designs have `N` poles (`⌈N/2⌉` sections).
//!
//! Reference: SciPy reference guide, `scipy.signal.butter`, `iirfilter`.

use super::complex::C64;
use super::sos::Sos;
use super::validate::{check_positive, invalid};
use super::zpk::Zpk;
use super::zpk2sos::zpk2sos;
use crate::error::Result;
use std::f64::consts::PI;

/// Largest accepted filter order (higher orders are numerically pointless
/// for the data of this project and are rejected as a likely mistake).
pub const MAX_ORDER: usize = 20;

/// Pass band of a filter, critical frequencies in hertz (−3 dB points of a
/// Butterworth response).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Band {
    /// Passes `f < cutoff_hz`.
    Lowpass {
        /// Cutoff frequency, Hz.
        cutoff_hz: f64,
    },
    /// Passes `f > cutoff_hz`.
    Highpass {
        /// Cutoff frequency, Hz.
        cutoff_hz: f64,
    },
    /// Passes `low_hz < f < high_hz`.
    Bandpass {
        /// Lower edge, Hz.
        low_hz: f64,
        /// Upper edge, Hz.
        high_hz: f64,
    },
    /// Rejects `low_hz < f < high_hz`.
    Bandstop {
        /// Lower edge, Hz.
        low_hz: f64,
        /// Upper edge, Hz.
        high_hz: f64,
    },
}

/// Analog Butterworth low-pass prototype of order `order` (cutoff 1 rad/s):
/// poles `−exp(iπ m/(2N))`, `m = −N+1, −N+3, …, N−1`, no zeros, gain 1.
pub fn buttap(order: usize) -> Zpk {
    let n = order as f64;
    let poles = (0..order)
        .map(|j| {
            let m = -n + 1.0 + 2.0 * j as f64;
            let theta = PI * m / (2.0 * n);
            // −exp(iθ); for m = 0 the pole is exactly real (imag −0).
            C64::new(-theta.cos(), -theta.sin())
        })
        .collect();
    Zpk {
        zeros: vec![],
        poles,
        gain: 1.0,
    }
}

/// Digital Butterworth filter of order `order` (1…[`MAX_ORDER`]) for the
/// given band at sampling rate `fs_hz`, as second-order sections in the
/// order SciPy returns them.
///
/// Errors (`InvalidArgument`): order 0 or > 20, `fs_hz` not finite and > 0,
/// a critical frequency not finite or outside `(0, fs/2)`, `low_hz ≥ high_hz`.
pub fn butter(order: usize, band: Band, fs_hz: f64) -> Result<Sos> {
    Sos::new(zpk2sos(&butter_zpk(order, band, fs_hz)?)?)
}

/// The digital Butterworth filter as zeros, poles and gain (`z`-plane),
/// equal to SciPy's `butter(..., output='zpk')`. Same errors as [`butter`].
pub fn butter_zpk(order: usize, band: Band, fs_hz: f64) -> Result<Zpk> {
    if order == 0 || order > MAX_ORDER {
        return Err(invalid(
            "order",
            format!("must be 1..={MAX_ORDER}, got {order}"),
        ));
    }
    check_positive("fs_hz", fs_hz)?;
    let nyquist = fs_hz / 2.0;
    // Normalised critical frequency W = f/(fs/2), checked in (0, 1).
    let normalise = |name: &'static str, f: f64| -> Result<f64> {
        let w = f / nyquist;
        if f.is_finite() && w > 0.0 && w < 1.0 {
            Ok(w)
        } else {
            Err(invalid(
                name,
                format!(
                    "must lie strictly between 0 and the Nyquist frequency {nyquist} Hz, got {f}"
                ),
            ))
        }
    };
    // Pre-warp for a bilinear transform at sampling rate 2: ω = 2·2·tan(πW/2).
    let warp = |w: f64| 2.0 * 2.0 * (PI * w / 2.0).tan();
    let proto = buttap(order);
    let analog = match band {
        Band::Lowpass { cutoff_hz } => proto.lp2lp(warp(normalise("cutoff_hz", cutoff_hz)?)),
        Band::Highpass { cutoff_hz } => proto.lp2hp(warp(normalise("cutoff_hz", cutoff_hz)?)),
        Band::Bandpass { low_hz, high_hz } | Band::Bandstop { low_hz, high_hz } => {
            let lo = normalise("low_hz", low_hz)?;
            let hi = normalise("high_hz", high_hz)?;
            if lo >= hi {
                return Err(invalid(
                    "low_hz",
                    format!("must be below high_hz ({low_hz} ≥ {high_hz})"),
                ));
            }
            let (wl, wh) = (warp(lo), warp(hi));
            let (bw, wo) = (wh - wl, (wl * wh).sqrt());
            if matches!(band, Band::Bandpass { .. }) {
                proto.lp2bp(wo, bw)
            } else {
                proto.lp2bs(wo, bw)
            }
        }
    };
    Ok(analog.bilinear(2.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::CoreError;

    #[test]
    fn butterworth_magnitude_law() {
        // |H|² = 1/(1 + (tan(πf/fs)/tan(πfc/fs))^{2N}) for the digital low-pass.
        let (fs, fc) = (10.0, 1.3);
        for order in [1, 2, 5, 8] {
            let sos = butter(order, Band::Lowpass { cutoff_hz: fc }, fs).unwrap();
            for f in [0.0, 0.5, 1.3, 2.0, 4.0] {
                let r = (PI * f / fs).tan() / (PI * fc / fs).tan();
                let expect = 1.0 / (1.0 + r.powi(2 * order as i32)).sqrt();
                assert!((sos.gain(f, fs) - expect).abs() < 1e-12, "N={order} f={f}");
            }
        }
    }

    #[test]
    fn bandpass_edges_are_minus_3db() {
        let sos = butter(
            4,
            Band::Bandpass {
                low_hz: 0.1,
                high_hz: 0.9,
            },
            10.0,
        )
        .unwrap();
        assert_eq!(sos.n_sections(), 4);
        let h = std::f64::consts::FRAC_1_SQRT_2;
        assert!((sos.gain(0.1, 10.0) - h).abs() < 1e-12);
        assert!((sos.gain(0.9, 10.0) - h).abs() < 1e-12);
        assert!(sos.gain(0.0, 10.0) < 1e-12);
        assert!(sos.gain(5.0, 10.0) < 1e-12);
    }

    #[test]
    fn invalid_designs_are_errors() {
        let lp = |f| Band::Lowpass { cutoff_hz: f };
        let bad = [
            butter(0, lp(1.0), 10.0),
            butter(21, lp(1.0), 10.0),
            butter(4, lp(0.0), 10.0),
            butter(4, lp(-1.0), 10.0),
            butter(4, lp(5.0), 10.0),
            butter(4, lp(f64::NAN), 10.0),
            butter(4, lp(1.0), 0.0),
            butter(4, lp(1.0), -10.0),
            butter(4, lp(1.0), f64::INFINITY),
            butter(
                4,
                Band::Bandpass {
                    low_hz: 2.0,
                    high_hz: 1.0,
                },
                10.0,
            ),
            butter(
                4,
                Band::Bandstop {
                    low_hz: 1.0,
                    high_hz: 1.0,
                },
                10.0,
            ),
            butter(
                4,
                Band::Bandpass {
                    low_hz: 1.0,
                    high_hz: 6.0,
                },
                10.0,
            ),
        ];
        for r in bad {
            assert!(matches!(r, Err(CoreError::InvalidArgument { .. })), "{r:?}");
        }
    }
}
