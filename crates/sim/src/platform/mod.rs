//! Platforms and their magnetic interference truth.
//!
//! * [`aircraft`] — the fixed-wing aircraft: permanent, induced and
//!   eddy-current parts and on-board current loops, evaluated with the exact
//!   dipole formula at each sensor.
//! * [`currents`] — the time series of the on-board currents (random
//!   switching and fluctuation) and their recorded channels.
//!
//! * [`rotor`] — a helicopter's main rotor: magnetised, conducting thin
//!   blades with coning and tip-path-plane tilt, dipole integral along each
//!   blade (the fuselage of the `helicopter` scenario is an [`aircraft`]).
//! * [`tail_rotor`] — its tail rotor: the same blades in their own plane,
//!   geared to the main rotor.
//!
//! Later platforms (towed pod) belong here, one model per file.

pub mod aircraft;
pub mod currents;
pub mod rotor;
pub mod tail_rotor;
