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
//! seed's stated conditions: the defaults with the swing a 5° sinusoid);
//! "eddy × 0.027" scales its eddy currents so that the step-1
//! coefficients have the seed's Table 1 ratio `rms(W3, W4)/rms(W1, W2)`
//! = 0.25 s (ours 9.2 s).
//!
//! | case | two-step min / mean / pooled % | joint θ min / mean / pooled % | dipole array min / mean / pooled % |
//! |---|---|---|---|
//! | sensor noise 0.002 nT | 83.6 / 89.4 / 88.8 | 99.1 / 99.4 / 99.4 | 99.9 / 99.9 / 99.9 |
//! | sensor noise 0.01 nT | 83.6 / 89.4 / 88.8 | 99.0 / 99.3 / 99.3 | 99.5 / 99.5 / 99.5 |
//! | sensor noise 0.03 nT | 83.5 / 89.3 / 88.7 | 98.2 / 98.4 / 98.4 | 98.4 / 98.5 / 98.6 |
//! | sensor noise 0.1 nT | 82.9 / 88.2 / 87.8 | 94.7 / 95.1 / 95.1 | 94.8 / 95.2 / 95.2 |
//! | swing 2° | 90.8 / 93.4 / 93.2 | 99.6 / 99.8 / 99.8 | 99.9 / 99.9 / 99.9 |
//! | swing 5° | 83.6 / 89.4 / 88.8 | 99.1 / 99.4 / 99.4 | 99.9 / 99.9 / 99.9 |
//! | swing 10° | 71.9 / 82.3 / 81.2 | 97.7 / 98.5 / 98.4 | 99.9 / 99.9 / 99.9 |
//! | no eddy currents in the helicopter | 77.2 / 91.3 / 93.5 | 95.6 / 97.7 / 98.0 | 98.8 / 99.5 / 99.6 |
//! | `seed_002()` (sine swing) | 87.3 / 90.0 / 89.8 | 99.3 / 99.5 / 99.5 | 99.9 / 99.9 / 99.9 |
//! | `seed_002()`, eddy × 0.027 (Table 1 ratio) | 88.3 / 93.8 / 95.4 | 97.8 / 98.4 / 98.4 | 99.0 / 99.5 / 99.6 |
//! | 4 learning headings (0, 90, 180, 270°) | 82.8 / 89.1 / 88.4 | 98.4 / 99.0 / 98.9 | 99.9 / 99.9 / 99.9 |
//! | 5 learning headings | 81.2 / 88.6 / 87.8 | 99.0 / 99.3 / 99.3 | 99.9 / 99.9 / 99.9 |
//! | 6 learning headings | 82.6 / 89.0 / 88.4 | 99.0 / 99.4 / 99.4 | 99.9 / 99.9 / 99.9 |
//! | 8 learning headings | 83.6 / 89.4 / 88.8 | 99.1 / 99.4 / 99.4 | 99.9 / 99.9 / 99.9 |
//!
//! ### Why the seed's two-step solve stays below 90 % on its worst heading
//!
//! * **Not an implementation error.** On data that are exactly the
//!   small-signal model both steps are exact: heading coefficients to
//!   1e-6, the mapped parameters reproduce the true coefficients on the
//!   independent headings and compensate > 99.99 % (unit test
//!   `two_step_is_exact_on_small_signal_data` in [`fit`]).
//! * **The simulator follows every condition the seed states**; the one
//!   difference of wording, the swing ("5° at the swing's main frequency"),
//!   is `PodConfig::seed_002` (87.3 % worst). The seed does not give its
//!   dipole array (its refs. 11–12). Its Table 1 has
//!   `rms(W3, W4)/rms(W1, W2)` = 0.25 s and `rms(W5..7)/rms(W1, W2)` =
//!   0.077 /m; our helicopter 9.2 s and 0.020 /m: its eddy currents are
//!   37× stronger relative to the attitude term, and its swing (gradient)
//!   term 4× weaker, than in the seed's simulation. With the eddy currents
//!   scaled to the seed's ratio the two-step solve gives 88.3 % worst,
//!   93.8 % mean, 95.4 % pooled: the seed's "above 90 %" for the whole set
//!   is met in the mean and pooled sense, not on every heading.
//! * **The limit is the first-order heading model itself** (test
//!   `seed_002_conditions_two_step_is_limited_by_the_first_order_heading_model`):
//!   fitted on one learning heading and applied to that same heading it
//!   already leaves more than 10 % on the worst one (86.9 % for
//!   `seed_002()`, 88.4 % with the scaled eddy currents), so no second step
//!   can do better on new headings. A 5° manoeuvre moves the pod itself by
//!   ≈ 3.5 m in the body frame (40 m cable), so `δp` and `v` are coherent
//!   and their product is second order in one manoeuvre angle, not a
//!   product of two independent small quantities. An exploratory
//!   per-heading fit (not kept) with the products `δp_i v_j`, `v_i v_j`,
//!   `δp_i δp_j` and `δp_i v_j'` added to the 7 columns reached 98.7 %
//!   (`seed_002()`, eddy × 0.02) and 99.8 % (`seed_002()`, no eddy) on the
//!   worst learning heading; the
//!   joint solves below carry these terms through the instantaneous `u`.
//! * **Sensitivity to the unstated high-pass**: a 0.05 Hz zero-phase
//!   Butterworth high-pass of `before` and `after`, instead of removing the
//!   straight line, raises the worst two-step heading by 2–2.5 points
//!   (86.1 % default, 89.2 % `seed_002()`, 90.6 % with the scaled eddy
//!   currents; exploratory, not kept): it removes the 0.02 Hz beat of the
//!   residual products (manoeuvre 0.1 Hz, swing 0.079 Hz). The spec's
//!   definition is kept.
//!
//! Earlier diagnosis on the default scenario, measured with the
//! same joint least-squares machinery on the truth `true_interf` (no noise,
//! no track term: 82.8 % worst test heading, so neither noise nor the
//! gradient term is the cause):
//!
//! * the seed's 43 parameters, exact trajectory: 82.8 %; adding all
//!   second-order displacement terms (`δp_i δp_j` × the 9 functions of `u`,
//!   97 parameters): 82.2 % — the linearisation in the displacement is
//!   **not** the limit;
//! * the same scenario without eddy currents: 97.1 % with the 43
//!   parameters, 99.9 % with the second-order terms;
//! * adding the eddy-current gradient (24 parameters, [`model`]): 99.1 %.
//!
//! So the seed's eqs. 10–12 omit the gradient of the eddy-current field:
//! with this helicopter's eddy moments (up to ≈ 1800 A·m² at the 3000 nT/s
//! of a 5° manoeuvre at 0.1 Hz, as large as the permanent ones) and metres
//! of pod motion, `δp × u'` is not negligible. The two-step solve cannot
//! carry it (its heading coefficients are first order); it also loses to
//! the second-order terms in `v` and `δp` (77 % without eddy currents). The
//! joint solve with the eddy gradient and the equivalent dipole array
//! ([`dipole_array`], 3 points × 21 moments, limited by sensor noise only)
//! reach ≥ 97 %. Heading count hardly matters at one site (level flights
//! see few independent functions of the heading).

pub mod dipole_array;
pub mod fit;
pub mod model;
pub mod model_file;
pub mod trajectory;

pub use dipole_array::{
    DipoleArrayModel, PER_SOURCE, default_source_points, fit_dipole_array, predict_dipole_array,
    predict_dipole_array_raw,
};
pub use fit::{
    JointFit, PodHeading, TwoStepFit, compensation_rate, compensation_rate_pooled, detrend,
    fit_heading_coefficients, fit_joint, fit_two_step, predict_joint, predict_joint_raw,
    predict_small_signal, predict_small_signal_raw,
};
pub use model::{
    N_HEADING, N_JOINT, N_PARAMS, heading_coefficients, heading_design, large_signal_row,
};
pub use trajectory::{
    Cable, direction_cosines, pod_offset_ned, pod_position_exact, pod_position_seed,
};
