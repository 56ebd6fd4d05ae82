//! Levelling at line/tie-line crossovers and the survey-altitude `k·d|B0|/dt`
//! term (spec `compensation.md`, "Survey altitude: the d|B0|/dt term and
//! levelling"; seed `000_…` §9).
//!
//! ## Why
//!
//! Seed §9: at survey altitude (~100 m) the horizontal gradients of the
//! anomalous field are large, and the scalar measurement model acquires an
//! extra term of order ε⁶ proportional to the time derivative of the field
//! modulus, `k·d|B0|/dt`. It is too small to be estimated on the calibration
//! flight (~1000 m and more), so the thesis estimates it on the survey itself
//! by re-adjustment (переуравнивание) at crossovers of survey lines and tie
//! lines. Physically the same term is produced by any time lag of the
//! scalar channel: a first-order lag `τ` reads `B(t − τ) ≈ B − τ·dB/dt`, so
//! `k = −τ` (s).
//!
//! ## The model (units: nT, s)
//!
//! For a sample at time `t` on line `L` the compensated reading is
//!
//! ```text
//! m(t) = B(x(t)) + k·Ḃ(t) + o_L + s_L·(t − t_L)/h_L + noise
//! ```
//!
//! * `B(x)` the true field at the position `x` (the same for every pass);
//! * `Ḃ` the along-track time derivative of the field the sensor saw (the
//!   uncompensated reading when given, [`SurveyTracks::sensed`]; else the
//!   levelled series), nT/s, estimated from the data themselves
//!   ([`track_derivative`]);
//! * `k` (s) the coefficient of the derivative term;
//! * `o_L` (nT) the level offset of line `L`, and optionally a linear drift
//!   `s_L` (nT at the ends of the line's crossover time span, `t_L` its
//!   middle and `h_L` its half-length, s).
//!
//! At a crossover of lines `a` and `b` (`a` the smaller label) the field
//! `B` cancels:
//!
//! ```text
//! d = m_a − m_b = k (Ḃ_a − Ḃ_b) + (o_a − o_b) + (s_a τ_a − s_b τ_b) + noise,   τ = (t − t_L)/h_L
//! ```
//!
//! plus, when the two passes are flown at different heights, the altitude
//! term `c·g_x` of [`fit`] (the true field differs by the vertical gradient
//! times the height difference; the gradient comes from the two crossing
//! profiles, [`vertical_gradient`]),
//! and `k`, `o`, `s` (and `c`) are found by regularised least squares ([`fit_levelling`]):
//! the offsets are only determined up to a common constant (the datum: their
//! mean is zero, or one line is held fixed) and a ridge `λ` keeps lines
//! without enough crossovers at zero. With `k` fixed at 0 and no drift this
//! is ordinary tie-line levelling. The corrected series is
//! `m − k·Ḃ − o_L − s_L τ` ([`apply_levelling`]); rows outside lines keep
//! their value and are flagged.
//!
//! Positions must be those of the scalar sensor, not of the navigation
//! reference point: a lever arm along the track acts like a time shift and
//! would be absorbed in `k` ([`sensor_positions`] converts them).
//!
//! ## Files
//!
//! | file | algorithm |
//! |---|---|
//! | [`tracks`] | the survey samples, sensor positions, track segmentation, along-track derivative |
//! | [`crossovers`] | intersections of tracks of different lines (grid buckets, `O(N log N)`) |
//! | [`vertical_gradient`] | the profile operator behind the crossovers' altitude term |
//! | [`fit`] | the joint least-squares fit of `k`, offsets, drifts and the altitude term |
//! | [`apply`] | the corrected series, row flags, and the one-call [`level_survey`] |

pub mod apply;
pub mod crossovers;
pub mod fit;
pub mod tracks;
pub mod vertical_gradient;

pub use apply::{Levelled, RowFlag, SurveyLevelling, apply_levelling, level_survey};
pub use crossovers::{Crossover, CrossoverSet, CrossoverSide, find_crossovers};
pub use fit::{Datum, HUBER_K, LevellingConfig, LevellingFit, LineLevel, fit_levelling};
pub use tracks::{Pairing, SurveyTracks, TrackConfig, sensor_positions, track_derivative};
pub use vertical_gradient::profile_gradient;
