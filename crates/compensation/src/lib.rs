//! # aeromag-compensation
//!
//! Magnetic interference of the platform, on arrays: the fixed-wing
//! Tolles-Lawson model and its two fits, the helicopter rotor and towed-pod
//! models, levelling at crossovers, and the figures that judge them (spec
//! `compensation.md` and `helicopter.md`; seed `000_…` chapters 1–3, seed
//! `002_…`). Every function takes plain slices in documented units (nT,
//! s, m, degrees or radians as named); the flight-level workflows (columns,
//! segments, reference channels, notes, model files on disk) are in the
//! `aeromag` crate.
//!
//! | module | contents |
//! |---|---|
//! | [`tolles_lawson`] | the Tolles-Lawson/Leliak terms (with lagged eddy currents), the design matrix, band-pass least squares, the eddy-lag search, segments; online application sample by sample (fixed, or adapting with RLS) |
//! | [`kalman`] | Method 2: the joint Kalman filter and smoother with a stochastic model of the field along the track, noise tuning, altitude cleaning; the forward filter online (adaptive coefficients) |
//! | [`observability`] | rank, weak combinations and estimability μ = √(P_post/P_prior) of the coefficients |
//! | [`metrics`] | manoeuvre detection, figure of merit, improvement ratio, residual per line |
//! | [`model_file`] | the Tolles-Lawson model file and the header check shared by every model file |
//! | [`reference_field`] | the main-field reference moved from the navigation point to the sensor (lever arm) |
//! | [`levelling`] | crossovers of lines and ties, the `k·d|B0|/dt` term, line levels, the altitude term |
//! | [`rotor`] | helicopter main-rotor model (blades, coning, phase), filter baselines, the rotor study |
//! | [`pod`] | towed pod: direction cosines, pod trajectory, small-signal, joint and dipole-array solves |
//! | [`error`] | [`CompError`] |
//!
//! A Tolles-Lawson fit on arrays, and the model's interference:
//!
//! ```
//! use aeromag_compensation::tolles_lawson::fit_ls::{LsConfig, Segment, fit_band_pass_ls};
//! use aeromag_compensation::tolles_lawson::{Design, TermSet};
//!
//! // A 10 Hz flight swinging about two axes (0.3 and 0.2 Hz) in a constant
//! // 50 000 nT field, with an aircraft whose permanent field adds
//! // 3·e_x − 2·e_z nT (e = B/|B|, the field's direction in the body frame).
//! let n = 3000;
//! let time: Vec<f64> = (0..n).map(|k| k as f64 * 0.1).collect();
//! let a: Vec<f64> = time.iter().map(|t| 0.4 * (1.9 * t).sin()).collect();
//! let b: Vec<f64> = time.iter().map(|t| 0.3 * (1.3 * t + 1.0).sin()).collect();
//! let fx: Vec<f64> = (0..n).map(|k| 50_000.0 * a[k].cos() * b[k].cos()).collect();
//! let fy: Vec<f64> = (0..n).map(|k| 50_000.0 * a[k].sin() * b[k].cos()).collect();
//! let fz: Vec<f64> = (0..n).map(|k| 50_000.0 * b[k].sin()).collect();
//! let mag: Vec<f64> = (0..n)
//!     .map(|k| 50_000.0 + (3.0 * fx[k] - 2.0 * fz[k]) / 50_000.0)
//!     .collect();
//! let cfg = LsConfig { design: Design::new(TermSet::parse("p3")?), ..LsConfig::default() };
//! let seg = Segment::new(&time, [&fx, &fy, &fz], &mag);
//! let fit = fit_band_pass_ls(&[seg], &cfg)?;
//! assert!((fit.coef[0] - 3.0).abs() < 1e-6 && (fit.coef[2] + 2.0).abs() < 1e-6);
//! let model = cfg.design.interference(&fit.coef, &time, [&fx, &fy, &fz]);
//! assert!((model[10] - (mag[10] - 50_000.0)).abs() < 1e-6);
//! # Ok::<(), aeromag_compensation::CompError>(())
//! ```

pub mod error;
pub mod kalman;
pub mod levelling;
pub mod metrics;
pub mod model_file;
pub mod observability;
pub mod pod;
pub mod reference_field;
pub mod rotor;
pub mod tolles_lawson;

pub use error::{CompError, Result};
