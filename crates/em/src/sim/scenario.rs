//! Configuration, drawn distortions and the bird's truth motion of the `em`
//! scenario (see [`super`] for the signal model).

use crate::detection::{Complex64, EmSystem};
use crate::positioning::Pose;
use crate::{EmError, Result};
use aeromag_core::frames::Attitude;
use nalgebra::{Matrix3, Vector3};
use rand::RngExt;
use rand_chacha::ChaCha8Rng;
use std::f64::consts::TAU;

/// Complex 3×3 matrix.
pub type CMatrix3 = Matrix3<Complex64>;

/// User configuration of the `em` scenario (units in the names).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EmSimConfig {
    /// ChaCha seed of every random draw.
    pub seed: u64,
    /// ADC rate, Hz.
    pub sample_rate_hz: f64,
    /// Length of the record, s.
    pub duration_s: f64,
    /// Flight time of the first sample, s (drifts are functions of it).
    pub start_time_s: f64,
    /// Working frequencies, Hz (multiples of the detector bin).
    pub frequencies_hz: [f64; 3],
    /// Pilot offset `δ`, Hz (pilots at `f ± δ`).
    pub pilot_offset_hz: f64,
    /// Transmitter moments (columns = dipoles), A·m²; in TOML a flat
    /// column-major list of 9 (dipole 1's x, y, z, then dipole 2's, …).
    pub moments_am2: Matrix3<f64>,
    /// Coil gain `g`, V per (T/s).
    pub coil_gain_v_per_t_s: f64,
    /// Pilot field amplitude in bird axes, T.
    pub pilot_field_t: Vector3<f64>,
    /// Mean direction of the bird from the transmitter (transmitter frame).
    pub mean_direction: Vector3<f64>,
    /// Range swept sinusoidally between these bounds, m.
    pub range_min_m: f64,
    /// Upper range bound, m.
    pub range_max_m: f64,
    /// Period of the range sweep, s.
    pub range_period_s: f64,
    /// Lateral/vertical swing amplitude, m.
    pub swing_amplitude_m: f64,
    /// Swing period, s.
    pub swing_period_s: f64,
    /// Roll/pitch oscillation amplitude, deg.
    pub attitude_amplitude_deg: f64,
    /// Steady rotation rate of the bird about its vertical, deg/s.
    pub rotation_rate_deg_s: f64,
    /// Cross-coupling magnitude range `[min, max]` of off-diagonal `χ`.
    pub cross_coupling: [f64; 2],
    /// Channel gain drift amplitude (fraction, e.g. 0.05).
    pub gain_drift: f64,
    /// Channel phase drift amplitude, deg.
    pub phase_drift_deg: f64,
    /// Drift period, s (a five-hour flight sees a full cycle).
    pub drift_period_s: f64,
    /// Maximum magnitude of the complex transmitter distortion `k_ij`.
    pub transmitter_distortion: f64,
    /// Channel group delay bound `τ`, s.
    pub group_delay_s: f64,
    /// White coil noise, V RMS per sample.
    pub coil_noise_v: f64,
    /// 400 Hz fundamental amplitude, V (odd harmonics fall as 1/h).
    pub power_line_v: f64,
    /// Mean sferic rate, 1/s (0 to [`MAX_SFERIC_RATE_HZ`]).
    pub sferic_rate_hz: f64,
    /// Median sferic peak amplitude, V.
    pub sferic_amplitude_v: f64,
}

/// The largest noise or interference amplitude simulated
/// (`coil_noise_v`, `power_line_v`, `sferic_amplitude_v`), V. Measured on
/// the default flight (`em simulate` → `detect` → `calibrate` → `locate`)
/// with `power_line_v` raised: up to 10⁴ V the 400 Hz harmonics are
/// rejected (polarisation ratio after calibration 2.31–2.42·10⁻⁵, largest
/// position error 0.011 m, as at the default 10⁻² V); at 10⁶ V the f32
/// record's rounding gives 5.9·10⁻⁴ and 0.12 m, and at 10³⁰ V every epoch
/// carried the same field (calibrate: "singular matrix", exit 1).
pub const MAX_INTERFERENCE_V: f64 = 1e4;

/// The highest sferic rate simulated, 1/s: every sferic is a waveform of
/// its own, so 10⁸/s (a mutated scenario file) ran for minutes on a
/// 10-second record; lightning gives tens to hundreds per second.
pub const MAX_SFERIC_RATE_HZ: f64 = 1000.0;

impl Default for EmSimConfig {
    fn default() -> Self {
        Self {
            seed: 1,
            sample_rate_hz: 100_000.0,
            duration_s: 2.56,
            start_time_s: 0.0,
            frequencies_hz: [1025.0, 2075.0, 3125.0],
            pilot_offset_hz: 25.0,
            moments_am2: Matrix3::new(
                2.0e4, 1.0e3, -5.0e2, 4.0e2, 1.8e4, 8.0e2, -6.0e2, 5.0e2, 2.2e4,
            ),
            coil_gain_v_per_t_s: 1.0e4,
            pilot_field_t: Vector3::new(2.0e-9, 2.0e-9, 2.0e-9),
            mean_direction: Vector3::new(-0.8, 0.0, 0.6),
            range_min_m: 30.0,
            range_max_m: 100.0,
            range_period_s: 600.0,
            swing_amplitude_m: 5.0,
            swing_period_s: 8.0,
            attitude_amplitude_deg: 20.0,
            rotation_rate_deg_s: 3.0,
            cross_coupling: [0.03, 0.05],
            gain_drift: 0.05,
            phase_drift_deg: 3.0,
            drift_period_s: 5.0 * 3600.0,
            transmitter_distortion: 0.05,
            group_delay_s: 5e-6,
            coil_noise_v: 1e-4,
            power_line_v: 1e-2,
            sferic_rate_hz: 20.0,
            sferic_amplitude_v: 5e-3,
        }
    }
}

/// The scenario: configuration plus everything drawn from the seed.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EmScenario {
    /// The configuration.
    pub config: EmSimConfig,
    /// Cross-coupling `χ_i` per working frequency (unit diagonal).
    pub chi: [CMatrix3; 3],
    /// Transmitter distortion `D` (complex, `Re D` symmetric):
    /// `M' = (I + D) M`, i.e. `k = M⁻¹ D M` in `M'_i = M_i + Σ_j k_ji M_j`.
    pub distortion: CMatrix3,
    /// Drift phases `ψ_c`, `ψ'_c` per channel, rad.
    pub drift_phase_rad: [[f64; 2]; 3],
    /// Group delay `τ_c` per channel, s.
    pub group_delay_s: [f64; 3],
    /// Swing and attitude oscillation phases, rad.
    pub motion_phase_rad: [f64; 5],
}

fn random_phase_complex(rng: &mut ChaCha8Rng, lo: f64, hi: f64) -> Complex64 {
    Complex64::from_polar(rng.random_range(lo..hi), rng.random_range(0.0..TAU))
}

/// The unit mean direction `e`, the swing direction `side = (0, 1, 0)`
/// and `up = e × side` (normalised) of the simulated motion; NaN when
/// `mean_direction` is along `side` or too small to normalise.
fn swing_frame(mean_direction: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
    let e = mean_direction.normalize();
    let side = Vector3::new(0.0, 1.0, 0.0);
    let up = e.cross(&side).normalize();
    (e, side, up)
}

impl EmScenario {
    /// Draw the scenario from the configuration's seed.
    ///
    /// Errors ([`EmError::InvalidArgument`], naming the field) for
    /// non-positive rate, duration or ranges, a minimum above its maximum
    /// (ranges, cross-coupling), a period of 0, a mean direction that is 0,
    /// along the swing axis y or too small to normalise, noise and
    /// interference levels outside 0 … [`MAX_INTERFERENCE_V`], or
    /// frequencies (with pilots) outside `(0, f_s/2)`.
    pub fn new(config: EmSimConfig) -> Result<Self> {
        let c = &config;
        let invalid = |reason: String| Err(EmError::InvalidArgument { reason });
        let shown = aeromag_core::error::shown;
        for (name, v) in [
            ("sample_rate_hz", c.sample_rate_hz),
            ("duration_s", c.duration_s),
            ("range_min_m", c.range_min_m),
        ] {
            if v.is_nan() || v <= 0.0 {
                return invalid(format!("field '{name}' is {}, must be positive", shown(v)));
            }
        }
        if c.range_max_m.is_nan() || c.range_max_m < c.range_min_m {
            return invalid(format!(
                "field 'range_min_m' {} m is above 'range_max_m' {} m: the range sweeps from the minimum to the maximum",
                shown(c.range_min_m),
                shown(c.range_max_m)
            ));
        }
        // The motion and the drift divide flight time by these: 0 gave
        // positions of NaN m ("0 m from the transmitter") or NaN samples.
        for (name, v) in [
            ("range_period_s", c.range_period_s),
            ("swing_period_s", c.swing_period_s),
            ("drift_period_s", c.drift_period_s),
        ] {
            if v == 0.0 {
                return invalid(format!(
                    "field '{name}' is 0 s: a period must not be 0 (the simulation divides flight time by it)"
                ));
            }
        }
        let [lo, hi] = c.cross_coupling;
        if lo.is_nan() || hi.is_nan() || lo > hi {
            return invalid(format!(
                "field 'cross_coupling' is [{}, {}]: the minimum is above the maximum (expected [min, max])",
                shown(lo),
                shown(hi)
            ));
        }
        let (_, _, up) = swing_frame(&c.mean_direction);
        if c.mean_direction != Vector3::zeros() && !up.iter().all(|v| v.is_finite()) {
            let d = c.mean_direction;
            return invalid(if d.normalize().iter().all(|v| v.is_finite()) {
                format!(
                    "field 'mean_direction' {}, {}, {} lies along the y axis, the bird's swing direction (the vertical swing is along mean_direction × y, which is then 0): give a direction with an x or z component",
                    shown(d.x),
                    shown(d.y),
                    shown(d.z)
                )
            } else {
                format!(
                    "field 'mean_direction' {}, {}, {} is too small to normalise (its length underflows to 0): give a direction such as -0.8, 0, 0.6",
                    shown(d.x),
                    shown(d.y),
                    shown(d.z)
                )
            });
        }
        if !(c.sferic_rate_hz >= 0.0 && c.sferic_rate_hz <= MAX_SFERIC_RATE_HZ) {
            return Err(EmError::InvalidArgument {
                reason: format!(
                    "sferic_rate_hz {} must be from 0 to {MAX_SFERIC_RATE_HZ} /s (sferics arrive at tens to hundreds per second)",
                    aeromag_core::error::shown(c.sferic_rate_hz)
                ),
            });
        }
        // The noise and interference levels are amplitudes: the noise is
        // `coil_noise_v · N(0, 1)`, so a negative level (−1 V in a mutated
        // scenario file) was taken as its magnitude and buried the signal
        // under 1 V of broadband noise; 0 turns a source off.
        for (name, v) in [
            ("coil_noise_v", c.coil_noise_v),
            ("power_line_v", c.power_line_v),
            ("sferic_amplitude_v", c.sferic_amplitude_v),
        ] {
            if !(v.is_finite() && (0.0..=MAX_INTERFERENCE_V).contains(&v)) {
                return Err(EmError::InvalidArgument {
                    reason: format!(
                        "{name} {} V must be from 0 to {MAX_INTERFERENCE_V:e} V (an amplitude; 0 turns it off; larger levels drown the signal in the f32 record's rounding)",
                        aeromag_core::error::shown(v)
                    ),
                });
            }
        }
        if c.mean_direction == Vector3::zeros() {
            return invalid("field 'mean_direction' is 0, 0, 0: the bird needs a direction from the transmitter".into());
        }
        for f in c.frequencies_hz {
            if !(f - c.pilot_offset_hz > 0.0 && f + c.pilot_offset_hz < c.sample_rate_hz / 2.0) {
                return Err(EmError::InvalidArgument {
                    reason: format!("frequency {f} Hz with pilots outside (0, fs/2)"),
                });
            }
        }
        // Stream 0 of the seed: the system's couplings and distortions.
        let mut rng = aeromag_core::random::stream(c.seed, 0);
        let [lo, hi] = c.cross_coupling;
        let hi = hi.max(lo + 1e-12);
        let chi = [0, 1, 2].map(|_| {
            Matrix3::from_fn(|r, col| {
                if r == col {
                    Complex64::new(1.0, 0.0)
                } else {
                    random_phase_complex(&mut rng, lo, hi)
                }
            })
        });
        let td = c.transmitter_distortion.max(1e-12);
        // An antisymmetric real part would only turn the transmitter frame,
        // which the effective moments themselves define (seed, stage 2).
        let raw = Matrix3::from_fn(|_, _| random_phase_complex(&mut rng, 0.0, td));
        let distortion = Matrix3::from_fn(|r, c| {
            Complex64::new(0.5 * (raw[(r, c)].re + raw[(c, r)].re), raw[(r, c)].im)
        });
        let drift_phase_rad =
            [0, 1, 2].map(|_| [rng.random_range(0.0..TAU), rng.random_range(0.0..TAU)]);
        let gd = c.group_delay_s.max(1e-15);
        let group_delay_s = [0, 1, 2].map(|_| rng.random_range(-gd..gd));
        let motion_phase_rad = [0, 1, 2, 3, 4].map(|_| rng.random_range(0.0..TAU));
        Ok(Self {
            config,
            chi,
            distortion,
            drift_phase_rad,
            group_delay_s,
            motion_phase_rad,
        })
    }

    /// Truth pose at flight time `t_s` (s): range sweep along the mean
    /// direction, swing across it, roll/pitch oscillation, steady yaw rotation.
    pub fn pose_at(&self, t_s: f64) -> Pose {
        let c = &self.config;
        let ph = &self.motion_phase_rad;
        let (e, side, up) = swing_frame(&c.mean_direction);
        let mid = 0.5 * (c.range_min_m + c.range_max_m);
        let half = 0.5 * (c.range_max_m - c.range_min_m);
        let range = mid + half * (TAU * t_s / c.range_period_s + ph[0]).sin();
        let w = TAU / c.swing_period_s;
        let pos = e * range
            + side * (c.swing_amplitude_m * (w * t_s + ph[1]).sin())
            + up * (0.5 * c.swing_amplitude_m * (2.0 * w * t_s + ph[2]).sin());
        let a = c.attitude_amplitude_deg.to_radians();
        let roll = a * (w * t_s + ph[3]).sin();
        let pitch = 0.5 * a * (1.3 * w * t_s + ph[4]).sin();
        let yaw = (c.rotation_rate_deg_s * t_s).to_radians();
        let c_nb = Attitude::new(roll, pitch, yaw).c_nb();
        Pose {
            position_m: pos,
            rotation: c_nb.transpose(),
        }
    }

    /// The instrument constants a crew would know: frequency plan, coil
    /// gain, pilot field, the cross-coupling `χ` (as if measured exactly on
    /// the bench) and the nominal moments.
    pub fn system(&self) -> EmSystem {
        let c = &self.config;
        EmSystem {
            frequencies_hz: c.frequencies_hz,
            pilot_offset_hz: c.pilot_offset_hz,
            coil_gain_v_per_t_s: c.coil_gain_v_per_t_s,
            pilot_field_t: c.pilot_field_t,
            chi: self.chi,
            moments_am2: c.moments_am2,
        }
    }

    /// Effective complex moments `M' = (I + D) M` (columns), A·m².
    pub fn effective_moments(&self) -> CMatrix3 {
        let m = self.config.moments_am2.map(|v| Complex64::new(v, 0.0));
        m + self.distortion * m
    }

    /// Channel sensitivity `ξ_c(ω, t)` (dimensionless, complex).
    pub fn sensitivity(&self, channel: usize, f_hz: f64, t_s: f64) -> Complex64 {
        let c = &self.config;
        let [p1, p2] = self.drift_phase_rad[channel % 3];
        let x = TAU * t_s / c.drift_period_s;
        let amp = 1.0 + c.gain_drift * (x + p1).sin();
        let phase = c.phase_drift_deg.to_radians() * (x + p2).sin()
            + TAU * f_hz * self.group_delay_s[channel % 3];
        Complex64::from_polar(amp, phase)
    }
}
