//! Towed magnetometer pod under a helicopter: small-signal compensation
//! (spec `helicopter.md` part B, seed `002_…`).
//!
//! The background at the pod = (1) the helicopter's field at the pod's
//! equilibrium position (Tolles–Lawson in the direction cosines `u`),
//! (2) its change when the pod swings (gradient × displacement), (3) the
//! Earth's gradients along the pod's wandering track (`s3 = k_x x_N + k_h h`,
//! known gradients, removed before fitting).
//!
//! | file | contents |
//! |---|---|
//! | [`trajectory`] | pod position from cable length, inclination, azimuth and attitude (seed eqs. 7–8 and the exact form), direction cosines |
//! | [`model`] | parameters `θ` (sd1…sd5, and sd6 the eddy-current gradient of the joint solve), heading coefficients `W(U)` (corrected eq. 6, eqs. 10–12), large-signal regressors |
//! | [`dipole_array`] | the joint equivalent-dipole-array solve (exact field at the swinging pod) |
//! | [`fit`] | the seed's two-step solve, the joint solve, predictions, compensation rate per heading |
//!
//! ## Results on the simulated seed scenario
//!
//! `aeromag-sim`'s `scenario::pod` with the seed's parameters, learning on
//! headings 0, 90, …, 315°, evaluated on the independent set 30, 120, 210,
//! 300, 70, 160, 250, 340° (test `crates/compensation/tests/pod_sim.rs`,
//! the numbers are printed by `pod_degradation_table`; the table below is
//! its output, minimum rate over the 8 test headings):
//!
//! Trajectory: the two-step solve uses the seed's eq. 7–8 pod position
//! ([`pod_position_seed`]), the joint solves the exact one. Rates are
//! `1 − RMS(after)/RMS(before)` per test heading (high-passed by removing
//! each heading's straight line), minimum and mean over the 8 test
//! headings, and pooled over all their samples
//! ([`compensation_rate_pooled`]: the seed states one rate for its whole
//! independent set, Fig. 7, and defines neither the rate nor the high-pass
//! band); sim seed 1 for learning, 1001 for test; defaults: sensor noise
//! 0.002 nT, swing 5°, 8 learning headings. "Joint θ" is the large-signal
//! model with the eddy-current gradient ([`model::N_JOINT`] = 67
//! parameters, displacements about the mean pod position of the learning
//! flight). `seed_002()` is `PodConfig::seed_002` of `aeromag-sim` (the
//! seed's stated conditions: the defaults with the swing a 5° sinusoid).
//! The simulated helicopter's eddy currents have the seed's Table 1 ratio
//! `rms(W3, W4)/rms(W1, W2)` = 0.25 s (ours 0.252 s, test
//! `seed_002_conditions_two_step_reaches_90_percent_on_the_independent_set`);
//! "eddy currents × 37" is the earlier, unphysically strong default kept as
//! a hard case.
//!
//! | case | two-step min / mean / pooled % | joint θ min / mean / pooled % | dipole array min / mean / pooled % |
//! |---|---|---|---|
//! | sensor noise 0.002 nT | 78.3 / 91.5 / 93.5 | 96.0 / 97.7 / 98.0 | 98.9 / 99.5 / 99.6 |
//! | sensor noise 0.01 nT | 77.7 / 91.0 / 93.2 | 93.2 / 96.5 / 97.2 | 94.7 / 97.4 / 98.0 |
//! | sensor noise 0.03 nT | 73.5 / 88.2 / 91.2 | 83.4 / 91.7 / 93.6 | 84.3 / 92.1 / 93.9 |
//! | sensor noise 0.1 nT | 49.6 / 73.5 / 79.2 | 52.6 / 74.7 / 80.0 | 53.3 / 74.9 / 80.2 |
//! | swing 2° | 80.5 / 90.9 / 92.4 | 97.4 / 98.3 / 98.4 | 98.0 / 98.9 / 99.1 |
//! | swing 5° | 78.3 / 91.5 / 93.5 | 96.0 / 97.7 / 98.0 | 98.9 / 99.5 / 99.6 |
//! | swing 10° | 78.2 / 91.0 / 92.8 | 94.3 / 96.4 / 96.8 | 99.4 / 99.7 / 99.8 |
//! | no eddy currents in the helicopter | 77.2 / 91.3 / 93.5 | 95.6 / 97.7 / 98.0 | 98.8 / 99.5 / 99.6 |
//! | `seed_002()` (sine swing) | 88.3 / 93.8 / 95.4 | 97.8 / 98.4 / 98.4 | 99.0 / 99.5 / 99.6 |
//! | `seed_002()`, eddy currents × 37 | 87.4 / 90.0 / 89.8 | 99.3 / 99.5 / 99.5 | 99.9 / 99.9 / 99.9 |
//! | 4 learning headings (0, 90, 180, 270°) | 73.4 / 88.2 / 90.9 | 86.3 / 94.7 / 95.7 | 98.8 / 99.4 / 99.6 |
//! | 5 learning headings | 75.4 / 90.9 / 93.1 | 94.8 / 97.4 / 97.5 | 98.9 / 99.5 / 99.6 |
//! | 6 learning headings | 77.2 / 91.0 / 93.2 | 96.6 / 97.4 / 97.6 | 98.9 / 99.5 / 99.6 |
//! | 8 learning headings | 78.3 / 91.5 / 93.5 | 96.0 / 97.7 / 98.0 | 98.9 / 99.5 / 99.6 |
//!
//! The interference at the pod is a few tenths of a nT after the
//! high-pass (the seed's Table 1 scale), so sensor noise of 0.01 nT and
//! more costs every solve; the dipole array is limited by noise only.
//!
//! ### The seed's two-step solve: ≥ 90 % on the set, not on every heading
//!
//! Under the seed's stated conditions (`seed_002()`) the two-step solve
//! compensates 95.4 % of the independent set (pooled, the spec's
//! `1 − std(after)/std(before)` over the test set; 93.8 % mean over the
//! headings), the seed's "above 90 %". Its worst heading is 88.3 %:
//!
//! * **Not an implementation error.** On data that are exactly the
//!   small-signal model both steps are exact: heading coefficients to
//!   1e-6, the mapped parameters reproduce the true coefficients on the
//!   independent headings and compensate > 99.99 % (unit test
//!   `two_step_is_exact_on_small_signal_data` in [`fit`]).
//! * **The limit is the first-order heading model itself**: fitted on one
//!   learning heading and applied to that same heading it already leaves
//!   more than 10 % on the worst one (88.4 %), so no second step can do
//!   better on new headings. A 5° manoeuvre moves the pod itself by
//!   ≈ 3.5 m in the body frame (40 m cable), so `δp` and `v` are coherent
//!   and their product is second order in one manoeuvre angle, not a
//!   product of two independent small quantities. An exploratory
//!   per-heading fit (not kept) with the products `δp_i v_j`, `v_i v_j`,
//!   `δp_i δp_j` and `δp_i v_j'` added to the 7 columns reached 98.7 %
//!   on the worst learning heading; the joint solves below carry these
//!   terms through the instantaneous `u`.
//! * With the wind-driven (random) swing of the default scenario the
//!   worst heading falls to 78 % (pooled 93.5 %): the swing is then not one
//!   sinusoid the per-heading coefficients can partly absorb.
//! * **Sensitivity to the unstated high-pass**: a 0.05 Hz zero-phase
//!   Butterworth high-pass of `before` and `after`, instead of removing the
//!   straight line, raised the worst two-step heading by 2–2.5 points in an
//!   exploratory run (not kept): it removes the 0.02 Hz beat of the
//!   residual products (manoeuvre 0.1 Hz, swing 0.079 Hz). The spec's
//!   definition is kept.
//!
//! With eddy currents 37× stronger (an eddy moment of ≈ 1800 A·m² in a
//! 5° manoeuvre at 0.1 Hz), the seed's eqs. 10–12 also miss the gradient of
//! the eddy-current field (`δp × u'`): the two-step solve falls to 89.8 %
//! pooled, and the joint solve needs its 24 eddy-gradient parameters
//! ([`model`]: 97.1 % → 99.1 % on the truth in the earlier diagnosis). The
//! joint solve with the eddy gradient and the equivalent dipole array
//! ([`dipole_array`], 3 points × 21 moments, limited by sensor noise only)
//! reach ≥ 97 % in both cases. Heading count hardly matters to the dipole
//! array at one site (level flights see few independent functions of the
//! heading); the joint θ needs 6 or more.

pub mod dipole_array;
pub mod fit;
pub mod model;
pub mod model_file;
pub mod trajectory;

pub use dipole_array::{
    DipoleArrayModel, MAX_SOURCE_M, MAX_SOURCE_POINTS, PER_SOURCE, check_source_points,
    default_source_points, fit_dipole_array, predict_dipole_array, predict_dipole_array_raw,
};
pub use fit::{
    JointFit, PodHeading, TwoStepFit, compensation_rate, compensation_rate_pooled, detrend,
    fit_heading_coefficients, fit_joint, fit_two_step, predict_joint, predict_joint_raw,
    predict_small_signal, predict_small_signal_raw,
};
pub use model::{
    N_HEADING, N_JOINT, N_PARAMS, free_axes, heading_coefficients, heading_design, large_signal_row,
};
pub use trajectory::{
    Cable, direction_cosines, pod_offset_ned, pod_position_exact, pod_position_seed,
};
