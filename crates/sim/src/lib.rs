//! # aeromag-sim — the physical flight simulator
//!
//! Real flight data with known truth does not exist publicly, so every
//! method of aeromag is proved on simulated data first (spec
//! `simulator.md`). This crate flies a kinematic aircraft through a
//! realistic magnetic environment and records what its instruments would
//! record, together with the truth. The truth is deliberately richer than
//! the estimators' models (no "inverse crime"): the aircraft interference is
//! a set of magnetised and conducting parts evaluated with the exact dipole
//! formula and the exact field modulus, not the Tolles–Lawson formula.
//!
//! ## Entry points
//!
//! ```no_run
//! use aeromag_sim::{ScenarioKind, simulate};
//! let sim = simulate(ScenarioKind::Calibration, None, Some(42))?;
//! let mag = sim.column("mag").unwrap();
//! sim.write_to_dir(std::path::Path::new("out"))?;
//! # Ok::<(), aeromag_sim::SimError>(())
//! ```
//!
//! * [`simulate`]`(kind, config_toml, seed)` → [`Simulation`] (columns, the
//!   scenario file with every default filled in, truth JSON);
//! * [`Simulation::write_to_dir`] writes `<scenario>.csv`, `<scenario>.toml`,
//!   `<scenario>.truth.json`;
//! * [`default_config_toml`] gives the full default scenario file;
//! * [`Simulation::to_flight_table`] hands the columns to `aeromag-io`.
//!
//! `cargo run --release -p aeromag-sim --example sim_summary -- survey 7`
//! prints the statistics of every column of a run.
//!
//! Scenarios ([`ScenarioKind`]): `calibration` (four-heading box at 3000 m
//! with roll/pitch/yaw manoeuvres), `calibration_truncated` (the thesis'
//! truncated pattern, ≈ 73 % of the time), `survey` (20 lines + 5 ties at
//! 100 m above ground with turbulence), `helicopter` (the box at 40 m/s and
//! 100 Hz with a fuselage and a main rotor of magnetised, conducting blades
//! with coning and tip-path-plane tilt, [`scenario::helicopter`],
//! [`platform::rotor`]), `pod` (a magnetometer pod towed on a 40 m cable
//! under a dipole-array helicopter, seed `002_…`'s parameters, 20 Hz,
//! [`scenario::pod`]). Scenario files are TOML; every field
//! has a documented default (see the `*Config` types and
//! [`scenario::config`]); unknown fields are errors.
//!
//! ## Physics (one model per file)
//!
//! | family | files |
//! |---|---|
//! | [`trajectory`] | kinematic aircraft, L1 guidance, manoeuvres, turbulence |
//! | [`environment`] | IGRF-14 main field, random anomaly continued upward by FFT + dipoles, diurnal + micropulsations |
//! | [`platform`] | aircraft parts: permanent, induced (full matrix), eddy-current loops (first-order lags), on-board currents |
//! | [`sensor`] | scalar (exact modulus, heading error, lag, noise), fluxgate (misalignment, non-orthogonality, scale, bias, noise), GNSS/INS, base station |
//! | [`output`] | a simulation's result: named columns, scenario file, truth metadata, writing them |
//! | [`error`] | `SimError`, with `is_bad_input()` |
//! | [`random`], [`numerics`] | seeded ChaCha streams, coloured noise, 2-D FFT, interpolation, exact lag discretisation |
//!
//! ## Default magnitudes (documented on each model)
//!
//! * Scalar sensor noise 0.005 nT/√Hz → **0.011 nT RMS at 10 Hz**; heading
//!   error 0.05 nT cos θ + 0.02 nT cos 2θ; lag 0 s (calibration), 0.1 s
//!   (survey).
//! * Aircraft interference at the stinger ≈ 32 nT (vector), −20…+2 nT on
//!   the total field depending on heading, 0.4–8 nT peak to peak in the
//!   manoeuvres (uncompensated FOM ≈ 44 nT), eddy part ≤ 0.6 nT; ≈ 560 nT at
//!   the fluxgate (see [`platform::aircraft`]).
//! * Fluxgate noise 0.11 nT RMS at 10 Hz, bias ~10 nT, scale errors ~10⁻³,
//!   non-orthogonality and misalignment 0.05–0.5°.
//! * Anomaly: RMS horizontal gradient 3 nT/100 m at 100 m above ground
//!   (realistic) or 0.3 nT/100 m (quiet, calibration default); ≈ 10× smaller
//!   at 3000 m. Diurnal 20 nT/hour RMS change + 0.3 nT micropulsations.
//! * GNSS 0.5 m (horizontal), 1 m (vertical) correlated errors; attitude
//!   0.03° (roll, pitch), 0.1° (yaw).
//!
//! ## Output columns
//!
//! All channels are sampled at `flight.sample_rate_hz` (default 10 Hz).
//! Canonical names and units follow `data-formats.md`; `true_…` columns are
//! the truth.
//!
//! | column | unit | meaning |
//! |---|---|---|
//! | `time` | s | seconds after 00:00 UTC of the flight date |
//! | `lat`, `lon` | deg | recorded (GNSS/INS) position of the navigation reference point, WGS84 |
//! | `alt` | m | recorded WGS84 ellipsoidal height of the reference point |
//! | `vn`, `ve`, `vd` | m/s | recorded velocity north, east, down |
//! | `roll`, `pitch`, `yaw` | deg | recorded attitude (yaw in (−180, 180]) |
//! | `mag` | nT | scalar magnetometer, uncompensated |
//! | `flux_x`, `flux_y`, `flux_z` | nT | fluxgate, body axes, with its errors |
//! | `line` | – | calibration leg 1…n / survey line label (1001…) / tie label (2001…); 0 in turns |
//! | `manoeuvre` | – | 0 none, 1 roll, 2 pitch, 3 yaw |
//! | `diurnal` | nT | base-station record of the diurnal variation (relative to take-off) |
//! | `igrf` | nT | IGRF-14 total field at the recorded position |
//! | `cur_<name>` | A | recorded current of an on-board loop (only if configured) |
//! | `true_lat`, `true_lon` | deg | true position of the reference point |
//! | `true_alt` | m | true height of the reference point |
//! | `true_sensor_alt` | m | true height of the scalar sensor |
//! | `true_vn`, `true_ve`, `true_vd` | m/s | true velocity |
//! | `true_roll`, `true_pitch`, `true_yaw` | deg | true attitude |
//! | `true_external` | nT | \|B_ext\| at the scalar sensor — what a perfect compensation yields |
//! | `true_interf` | nT | \|B_ext + ΔB\| − \|B_ext\| (exact, not first order) |
//! | `true_igrf` | nT | \|B_IGRF\| at the scalar sensor |
//! | `true_anomaly` | nT | \|B_IGRF + B_anom\| − \|B_IGRF\| |
//! | `true_diurnal` | nT | \|B_ext\| − \|B_IGRF + B_anom\| (so igrf + anomaly + diurnal = external exactly) |
//! | `true_heading_error` | nT | heading error of the scalar sensor |
//! | `true_lag` | nT | exact lag contribution `y − x` (≈ −τ d\|B\|/dt: the `k·d|B0|/dt` term) |
//! | `true_mag_noise` | nT | scalar sensor noise; `mag = true_external + true_interf + true_heading_error + true_lag + true_mag_noise` |
//! | `true_interf_perm`, `true_interf_induced`, `true_interf_eddy`, `true_interf_current` | nT | projections on `B_ext/|B_ext|` of each kind of aircraft field |
//! | `true_ext_x`, `true_ext_y`, `true_ext_z` | nT | external field at the scalar sensor, body axes |
//! | `true_interf_x`, `true_interf_y`, `true_interf_z` | nT | aircraft field ΔB at the scalar sensor, body axes |
//! | `true_flux_x`, `true_flux_y`, `true_flux_z` | nT | true total field at the fluxgate, body axes, before sensor errors |
//! | `true_cur_<name>` | A | true current of an on-board loop |
//!
//! Optional extra sensors (`[[extra_scalars]]`, `[[extra_fluxgates]]` in the
//! scenario file, none by default; see [`scenario::fixed_wing`], "Extra
//! sensors"; `k` = 2, 3, …, `j` = b, c, d, …):
//!
//! | column | unit | meaning |
//! |---|---|---|
//! | `mag_<k>` | nT | extra scalar magnetometer k, uncompensated (after `flux_z`) |
//! | `flux_<j>_x`, `flux_<j>_y`, `flux_<j>_z` | nT | extra fluxgate j, body axes, with its errors |
//! | `true_interf_<k>` | nT | \|B_ext + ΔB\| − \|B_ext\| at extra scalar sensor k (exact) |
//! | `true_external_<k>` | nT | \|B_ext\| at extra scalar sensor k |
//! | `true_flux_<j>_x`, `true_flux_<j>_y`, `true_flux_<j>_z` | nT | true total field at extra fluxgate j, body axes, before sensor errors |
//!
//! With `installation = "sgl"` (an SGL-like installation: a stinger and
//! four cabin scalar sensors, four fluxgates, 14 current loops; see
//! [`scenario::installation`]) the columns follow the SGL HDF5 layout:
//! `mag_1_uc` … `mag_5_uc`, `flux_a_x` … `flux_d_z`, `cur_<name>`, and per
//! scalar sensor `k` = 1 … 5 `true_interf_<k>`, `true_external_<k>` and
//! `true_interf_current_<k>` (nT: the currents' part of the interference,
//! projected on the external field).
//!
//! The `helicopter` scenario adds `rotor_phase` (deg, recorded),
//! `true_rotor_phase` (deg), `true_rotor_hz` (Hz), `true_coning`,
//! `true_tilt_lon`, `true_tilt_lat` (deg), `true_rotor`, `true_fuselage`
//! and `true_rotor_x`, `true_rotor_y`, `true_rotor_z` (nT); there
//! `true_interf = true_fuselage + true_rotor` (see [`scenario::helicopter`]).
//! The `pod` scenario has its own columns (`cable_inclination`,
//! `cable_azimuth` in deg, `true_interf` at the pod, `true_pod_x/y/z` …,
//! listed on [`scenario::pod::run`]).
//!
//! ## Determinism and speed
//!
//! Every random process draws from its own ChaCha8 stream of the scenario
//! seed ([`random`]); the same seed and configuration give bit-identical
//! output on the same build and machine. A one-hour 10 Hz survey runs in well
//! under a second in release (bench `benches/flight.rs`).

pub mod environment;
pub mod error;
pub mod numerics;
pub mod output;
pub mod platform;
pub mod random;
pub mod scenario;
pub mod sensor;
pub mod trajectory;

pub use error::SimError;
pub use output::{Column, Simulation, WrittenFiles};
pub use scenario::{ScenarioKind, default_config_toml, simulate};
