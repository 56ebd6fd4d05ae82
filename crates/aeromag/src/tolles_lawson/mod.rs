//! Fixed-wing interference compensation on flights: calibrate a
//! Tolles-Lawson model by either method, apply it, and ask what a
//! calibration flight determines.
//!
//! | item | what |
//! |---|---|
//! | [`CalibrateSettings`] | the choices as the CLI's flags and Python's keyword options state them → [`CalibrateOptions`] |
//! | [`calibrate`] | fit a [`TlModel`] on a calibration flight ([`CalibrateOptions`], [`Method`]) → [`Calibration`] |
//! | [`Compensator`](crate::Compensator) for [`TlModel`] | the modelled interference of every row of a flight, and the compensated reading |
//! | [`Contributions`] | the interference by part (permanent, induced, eddy, currents) and manoeuvre |
//! | [`observability`] | rank, weak combinations and estimability of the coefficients on a flight |
//! | [`calibrate_sensors`] | one model per scalar sensor ([`SensorSet`], reference-sensor mode) → [`SensorsModel`]; [`CompensateSensors`] applies it |
//!
//! The algorithms are in [`aeromag_compensation::tolles_lawson`] (band-pass
//! least squares, the eddy-lag search) and
//! [`aeromag_compensation::kalman`] (the thesis' Kalman filter and
//! smoother); this module applies them to flights: columns, segments,
//! reference channels, the sensor's lever arm, notes and the model file.

mod calibrate;
mod compensate;
mod contributions;
mod kalman;
mod kalman_section;
mod lags;
mod observability;
mod sensors;
mod settings;

pub(crate) use calibrate::calibrate_against;
pub use calibrate::{
    CalibrateOptions, Calibration, EddyLag, ExtraSelection, Method, SECOND_ORDER_NOTE_NT, calibrate,
};
pub(crate) use compensate::check_time_unit;
pub use compensate::{InterferenceParts, MAX_STEP_RATIO, TL_OUTPUT, second_order_range_nt};
pub use contributions::{Contributions, PartsRms};
pub(crate) use kalman::ground_speed;
pub use kalman::{KALMAN_SERIES, KalmanOptions, KalmanOutcome, KalmanSeriesColumns};
pub use observability::{CoefficientVerdict, FlightObservability, Verdict, observability};
pub use sensors::{
    CompensateSensors, SensorSet, SensorsCalibration, SensorsCompensated, calibrate_sensors,
};
pub use settings::{CalibrateSettings, DEFAULT_DECIMAL_YEAR};

pub use aeromag_compensation::model_file::{SensorModel, SensorsModel, TlModel};
