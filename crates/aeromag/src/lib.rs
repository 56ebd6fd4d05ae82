//! # aeromag
//!
//! Processing of magnetic and low-frequency EM measurements from moving
//! platforms, as a library: everything the `aeromag` command does is a
//! function here, and the command only parses arguments, calls one of them,
//! writes files and prints.
//!
//! ## A first calibration
//!
//! ```no_run
//! use aeromag::prelude::*;
//!
//! // A calibration flight and a survey (CSV or Geosoft XYZ; MagNav names are
//! // recognised, others mapped with a ColumnMap).
//! let cal = Flight::read("cal/calibration.csv")?;
//! let survey = Flight::read("survey/survey.csv")?;
//!
//! // Fit the Tolles-Lawson model by the Kalman method (band-pass least
//! // squares is CalibrateOptions::default()).
//! let fit = calibrate(&cal, &CalibrateOptions::kalman(), &mut Silent)?;
//! for note in &fit.notes {
//!     eprintln!("{note}");
//! }
//! std::fs::write("model.json", fit.model.to_json()?).unwrap();
//!
//! // The model applies itself: interference (nT) and compensated reading.
//! let out = fit.model.compensate(&survey)?;
//! println!("{} of {} rows compensated", survey.n_rows() - out.missing, survey.n_rows());
//! # Ok::<(), aeromag::Error>(())
//! ```
//!
//! ## What is where
//!
//! | module | workflows on flights |
//! |---|---|
//! | [`flight`] | [`Flight`] (a table read and checked), [`TlInputs`], [`SegmentRule`] and the gap rule, [`ReferenceChannels`], [`LeverArm`] |
//! | [`tolles_lawson`] | [`calibrate`] (band-pass LS or Kalman) → [`Calibration`]; [`TlModel`] as a [`Compensator`]; [`observability`] |
//! | [`compensate`] | the [`Compensator`] trait every model implements, [`Compensated`] |
//! | [`model_file`] | [`ModelFile`]: reading and writing the model files of every kind |
//! | [`studies`] | [`Study`](studies::Study): each subsystem's demonstration on simulated data, typed summary and report section; the demo |
//! | [`simulate`] | simulated flights with truth, in memory |
//! | [`rotor`] | helicopter main-rotor model: [`rotor::fit_rotor`] on a flight, [`rotor::RotorModelFile`] as a [`Compensator`] |
//! | [`pod`] | towed pod: [`pod::fit_pod`] by three solves, [`pod::apply_pod`] with the rates per heading |
//! | [`gradiometry`] | gradiometer passes on files: [`gradiometry::read_pass`], [`gradiometry::locate_pass`], [`gradiometry::crlb()`], convergence maps |
//! | [`em`] | EM positioning on files: [`em::detect`], [`em::calibrate`], [`em::locate`], [`em::simulate_to_dir`] |
//! | [`level`] | levelling at crossovers ([`level::level`]) |
//! | [`map`] | from lines to the map: [`map::grid_flight`] (UTM, minimum curvature, blanking) → [`map::SurveyGrid`] |
//! | [`score`] | FOM, IR and residual against truth of a compensated flight, and its report section |
//! | [`observer`] | [`Observer`] (stages, progress, notes as they happen), [`Note`], [`Silent`] |
//! | [`error`] | [`Error`] with [`Error::is_bad_input`] |
//!
//! The algorithms live in the sub-crates, re-exported here:
//!
//! | crate | holds |
//! |---|---|
//! | [`core`] (`aeromag-core`) | frames and rotations, dipole fields, IGRF-14, filters, spectra |
//! | [`io`] (`aeromag-io`) | flight tables: CSV, Geosoft XYZ and HDF5, column maps, validation, CSV writing |
//! | [`sim`] (`aeromag-sim`) | the physical simulator (truth in `true_` columns) |
//! | [`estimation`] (`aeromag-estimation`) | least squares, square-root Kalman filters and smoothers |
//! | [`compensation`] (`aeromag-compensation`) | Tolles-Lawson terms and fits, the Kalman method, levelling, rotor and pod models, metrics |
//! | [`grid`] (`aeromag-grid`) | UTM projection, minimum-curvature gridding, blanking, GeoTIFF / ESRI ASCII / netCDF / GXF grid files |
//! | [`aeromag_em`] | EM bird positioning (its file workflows are [`em`]) |
//! | [`aeromag_gradiometry`] | dipole parameters from gradiometers (its flight-level workflows are [`gradiometry`]) |
//! | [`report`] (`aeromag-report`) | plots and the single-file HTML report |
//!
//! Units: nT, m, s, degrees in files; NED and body frames (x forward,
//! y right, z down). Estimators never read `true_` columns.

pub mod compensate;
pub mod em;
pub mod error;
pub mod flight;
pub mod gradiometry;
pub mod level;
pub mod map;
pub mod model_file;
pub mod observer;
pub mod online;
pub mod pod;
pub mod rotor;
pub mod score;
pub mod simulate;
pub mod studies;
pub mod tolles_lawson;

pub use aeromag_compensation as compensation;
pub use aeromag_core as core;
pub use aeromag_estimation as estimation;
pub use aeromag_grid as grid;
pub use aeromag_io as io;
pub use aeromag_report as report;
pub use aeromag_sim as sim;

pub use aeromag_io::Location;
pub use aeromag_io::{ColumnMap, Fields, FlightTable, ReadOptions, RowSelection, Sensors};
pub use compensate::{Compensated, Compensator, OutputColumns};
pub use error::{Error, InFile, Result};
pub use flight::{
    Flight, LeverArm, LineLabels, ReferenceChannels, SegmentRule, SensorColumns, TlInputs,
};
pub use model_file::ModelFile;
pub use observer::{Note, NoteLevel, Observer, Silent};
pub use tolles_lawson::{
    CalibrateOptions, CalibrateSettings, Calibration, CompensateSensors, EddyLag, ExtraSelection,
    KalmanOptions, Method, SensorSet, SensorsCalibration, SensorsCompensated, SensorsModel,
    TlModel, calibrate, calibrate_sensors, observability,
};

/// The names most programs need: `use aeromag::prelude::*;`.
pub mod prelude {
    pub use crate::{
        CalibrateOptions, Calibration, Compensator, EddyLag, Error, Flight, LeverArm, Method,
        ModelFile, Observer, ReferenceChannels, Silent, TlModel, calibrate,
    };
}
