//! Real-time compensation: a Tolles-Lawson model applied as samples arrive
//! (issue 21).
//!
//! - [`CausalTl`] — a model under the causal convention, applied to a
//!   whole flight (`aeromag compensate --causal`): the eddy columns take
//!   backward differences, so no sample's value depends on a later one;
//!   runs break at time steps over 1.5 × the model's sample interval;
//!   [`CausalSensors`] the same for a multi-sensor model.
//! - [`OnlineTl`] — the same model one sample at a time, latency 0,
//!   bounded memory; it gives [`CausalTl`]'s values bit for bit.
//! - [`LineCompensator`] — the line protocol of `aeromag stream`: CSV lines
//!   in, the same lines with `mag_interf`, `mag_comp` and `comp_flag`
//!   out; bad lines are flagged ([`StreamFlag`]) and counted, never fatal.
//!
//! ```
//! use aeromag::prelude::*;
//! use aeromag::online::{CausalTl, LineCompensator, StreamOptions};
//! use aeromag::simulate::{ScenarioKind, simulate_flight};
//! let cal = simulate_flight(ScenarioKind::Calibration, None, Some(1))?;
//! let model = calibrate(&cal, &CalibrateOptions::default(), &mut Silent)?.model;
//! let mut lines = LineCompensator::new(&model, "time,flux_x,flux_y,flux_z,mag", &StreamOptions::default())?;
//! let mut out = String::new();
//! lines.line("0.0,20000,1000,45000,49300", &mut out);
//! lines.line("0.1,20001,1001,45001,49301", &mut out);
//! lines.line("0.2,oops,1001,45001,49301", &mut out);
//! assert_eq!(lines.counts().malformed, 1);
//! assert!(out.lines().last().unwrap().ends_with(",,,4"));
//! # Ok::<(), aeromag::Error>(())
//! ```

mod adaptive;
mod causal;
mod lines;

pub use adaptive::{Adapt, AdaptOptions, AdaptedFlight, CoefficientSnapshot, OnlineEngine};
pub use aeromag_compensation::kalman::online::OnlineKalmanSettings;
pub use aeromag_compensation::tolles_lawson::adaptive::{AdaptiveTl, Navigation};
pub use aeromag_compensation::tolles_lawson::online::{
    OnlineOutput, OnlineSample, OnlineTl, SampleStatus,
};
pub use aeromag_compensation::tolles_lawson::rls::RlsSettings;
pub use causal::{CausalSensors, CausalTl};
pub use lines::{
    LineCompensator, LineIssue, LineStream, MAX_STREAM_LINE_BYTES, STREAM_OUTPUT, StreamCounts,
    StreamFlag, StreamIssues, StreamOptions,
};
