//! Simulator scenario `gradiometer` (spec `simulator.md`, `gradiometry.md`
//! "Simulation mock-up"; seed `004_…`, sect. 5).
//!
//! Local flat north-east-down frame around a reference WGS84 point. Two
//! kinds of pass:
//!
//! - [`SystemMotion::Stationary`]: the gradiometer stands at the origin
//!   with a fixed attitude; the object drives along north, `p_o(t) =
//!   (−L/2 + v t, y₀, z₀)`, yawing at a constant rate;
//! - [`SystemMotion::Mobile`]: the object stands at `(0, y₀, z₀)`; the
//!   system moves along north, `p_s(t) = (−L/2 + v t, 0, 0)`, with a fixed
//!   (known) attitude.
//!
//! Truth (richer than the estimator's model):
//!
//! - Earth's field `B_e` and gradient `G_e` from IGRF-14 at the system
//!   (the geodetic position of the local point); each sensor sees
//!   `B_e + G_e C_nb δr_i`;
//! - natural variations `d(t)` common to all sensors: three sinusoids of
//!   periods 60, 45, 80 s with random phases and amplitude `A`;
//! - the object's moment `M = C_no (M_perm + K C_on B_e(p_o))`: a permanent
//!   part fixed in the object and an induced part with an anisotropic
//!   susceptibility `K = diag(k_x, k_y, k_z)` (A·m²/nT) in the object's
//!   axes, so `M` changes with the object's heading in a way the
//!   estimators' models do not describe exactly (the tensor system turns
//!   the whole moment with the object; the scalar system separates a
//!   permanent part turning with it and an induced part fixed with the
//!   Earth's field, [`crate::motion::motion_mv_induced`], which leaves the
//!   anisotropic residue `C_no (K − k̄ I) C_on B_e` out). The truth
//!   columns hold the total `M`, body frame;
//! - vector sensors (body frame): `C_bn (B_e + G_e C_nb δr_i + d + B_dip) +
//!   b_i + n`, scalar sensors `|B_e + G_e C_nb δr_i + d + B_dip| + b_i + n`,
//!   with a fixed bias `b_i ~ N(0, σ_b²)` per sensor and white noise
//!   `n ~ N(0, σ²)`, `σ`, `σ_b` per sensor type.
//!
//! Randomness: the streams of [`aeromag_core::random`] of `seed`, one per
//! purpose (biases, noise, variations). Geodetic positions of local points:
//! WGS84 flat-earth offsets about the origin ([`Geodetic::offset_by`]).

use crate::decorrelate::{contrasts_scalar, contrasts_vector};
use crate::error::{GradiometryError, Result, in_range, positive};
use crate::forward::{Background, Forward, ScalarForward, TensorForward};
use crate::geometry::Geometry;
use crate::motion::{Motion, MotionNoise, motion_mt, motion_mv_induced};
use crate::pass::PassEpoch;
use aeromag_core::NT_PER_T;
use aeromag_core::field::dipole::dipole_field;
use aeromag_core::field::igrf::IgrfModel;
use aeromag_core::frames::Attitude;
use aeromag_core::frames::geodetic::Geodetic;
use aeromag_core::random::{self, ChaCha8Rng, normal};
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};
use rand::RngExt;
use std::borrow::Borrow;

/// Which body moves (`"stationary"`, `"mobile"` in scenario files).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SystemMotion {
    /// Fixed gradiometer, moving object.
    Stationary,
    /// Moving gradiometer, fixed object.
    Mobile,
}

/// Which gradiometer (`"tensor"`, `"scalar"` in scenario files).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Gradiometer {
    /// Four vector sensors: 9 contrasts, state `(r, M)`.
    Tensor,
    /// Four scalar sensors: 3 contrasts of the moduli, state `M` (position known).
    Scalar,
}

/// Noise and bias of one sensor type, nT.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorSpec {
    /// White noise σ per sample (per axis for vector sensors), nT.
    pub noise_nt: f64,
    /// σ of the fixed per-sensor bias (per axis), nT.
    pub bias_sigma_nt: f64,
}

/// The `gradiometer` scenario; [`Scenario::new`] documents the defaults.
#[derive(Debug, Clone, PartialEq)]
pub struct Scenario {
    /// Which body moves.
    pub motion: SystemMotion,
    /// Sensor layout (the same for vector and scalar sensors).
    pub geometry: Geometry,
    /// Vector (fluxgate) sensors.
    pub vector_sensor: SensorSpec,
    /// Scalar (optically pumped) sensors.
    pub scalar_sensor: SensorSpec,
    /// Sample interval, s.
    pub dt_s: f64,
    /// Number of epochs.
    pub epochs: usize,
    /// Speed of the moving body along north, m/s.
    pub speed_m_s: f64,
    /// East and down offsets `(y₀, z₀)` of the pass line, m.
    pub offset_east_down_m: (f64, f64),
    /// Permanent moment in the object's axes, A·m².
    pub permanent_moment_am2: Vector3<f64>,
    /// Induced susceptibility diagonal in the object's axes, A·m²/nT.
    pub induced_am2_per_nt: Vector3<f64>,
    /// Initial heading of the object, rad.
    pub object_yaw_rad: f64,
    /// Object yaw rate, rad/s.
    pub object_yaw_rate_rad_s: f64,
    /// Attitude of the system (fixed during the pass).
    pub system_attitude: Attitude,
    /// Amplitude of the natural variations, nT.
    pub variation_nt: f64,
    /// Reference point of the local frame.
    pub origin: Geodetic,
    /// Epoch of the IGRF, decimal year.
    pub decimal_year: f64,
    /// Random seed.
    pub seed: u64,
}

/// Most epochs of one simulated pass: a million samples (28 h at 10 Hz,
/// where a pass by one object lasts minutes) take about 0.5 GB; a hundred
/// times more did not fit in memory.
pub const MAX_EPOCHS: usize = 1_000_000;

/// Sample-interval range of a pass, s: 1 µs (a 1 MHz ADC, faster than any
/// magnetometer) to one hour.
pub const DT_RANGE_S: (f64, f64) = (1e-6, 3600.0);

impl Scenario {
    /// Defaults: tetrahedron 1 m; fluxgates 0.5 nT noise, 5 nT bias;
    /// scalar 0.02 nT noise, 0.5 nT bias; 10 Hz for 30 s; 2 m/s; pass line
    /// 6 m east and 2 m down; permanent moment (800, −300, 200) A·m²;
    /// induced (0.02, 0.008, 0.008) A·m²/nT (≈ 1000/400/400 A·m² in
    /// 50 µT); object yaw 0 rad, rate 0.02 rad/s; system level, yaw 0;
    /// variations 5 nT; 55° N 37° E, 150 m, 2025.5; seed 1.
    pub fn new(motion: SystemMotion, geometry: Geometry) -> Self {
        Self {
            motion,
            geometry,
            vector_sensor: SensorSpec {
                noise_nt: 0.5,
                bias_sigma_nt: 5.0,
            },
            scalar_sensor: SensorSpec {
                noise_nt: 0.02,
                bias_sigma_nt: 0.5,
            },
            dt_s: 0.1,
            epochs: 300,
            speed_m_s: 2.0,
            offset_east_down_m: (6.0, 2.0),
            permanent_moment_am2: Vector3::new(800.0, -300.0, 200.0),
            induced_am2_per_nt: Vector3::new(0.02, 0.008, 0.008),
            object_yaw_rad: 0.0,
            object_yaw_rate_rad_s: 0.02,
            system_attitude: Attitude::new(0.0, 0.0, 0.0),
            variation_nt: 5.0,
            origin: Geodetic {
                lat_deg: 55.0,
                lon_deg: 37.0,
                alt_m: 150.0,
            },
            decimal_year: 2025.5,
            seed: 1,
        }
    }

    /// Check the values: step within [`DT_RANGE_S`], positive speed, 1 to
    /// [`MAX_EPOCHS`] epochs; non-negative noise, bias and variation
    /// amplitudes.
    pub fn validate(&self) -> Result<()> {
        in_range("dt_s", self.dt_s, DT_RANGE_S.0, DT_RANGE_S.1)?;
        if self.epochs > MAX_EPOCHS {
            return Err(GradiometryError::OutOfRange {
                name: "epochs",
                value: self.epochs as f64,
                min: 1.0,
                max: MAX_EPOCHS as f64,
            });
        }
        positive("speed_m_s", self.speed_m_s)?;
        for (name, v) in [
            ("vector noise_nt", self.vector_sensor.noise_nt),
            ("scalar noise_nt", self.scalar_sensor.noise_nt),
            ("vector bias_sigma_nt", self.vector_sensor.bias_sigma_nt),
            ("scalar bias_sigma_nt", self.scalar_sensor.bias_sigma_nt),
            ("variation_nt", self.variation_nt),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(GradiometryError::NotPositive { name, value: v });
            }
        }
        if self.epochs == 0 {
            return Err(GradiometryError::NotPositive {
                name: "epochs",
                value: 0.0,
            });
        }
        Ok(())
    }
}

/// One measured epoch of a pass (system body frame unless stated): the
/// readings and what navigation and the object's known track give — what
/// a pass file holds. The estimators read nothing else.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Epoch {
    /// Time, s.
    pub t_s: f64,
    /// Vector sensor readings, body frame, nT.
    pub vector_nt: [Vector3<f64>; 4],
    /// Scalar sensor readings, nT.
    pub scalar_nt: [f64; 4],
    /// Known Earth field and gradient at the centre (IGRF), body frame.
    pub background: Background,
    /// Known motion over the step into this epoch (body frame).
    pub motion: Motion,
    /// System position in the local NED frame, m (navigation).
    pub system_position_ned_m: Vector3<f64>,
    /// System position, WGS84 (navigation).
    pub system_geodetic: Geodetic,
    /// System attitude (navigation).
    pub system_attitude: Attitude,
    /// Object position in the local NED frame, m (its known track).
    pub object_position_ned_m: Vector3<f64>,
    /// Object heading, rad (its known track).
    pub object_yaw_rad: f64,
}

/// One simulated epoch: the measured [`Epoch`] and the truth. It
/// dereferences to the measured epoch, so `e.t_s`, `e.vector_nt`, … read
/// the same on both.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimEpoch {
    /// What the instruments and the navigation record.
    pub measured: Epoch,
    /// True object position relative to the measuring centre, body, m.
    pub true_position_m: Vector3<f64>,
    /// True moment, body frame, A·m².
    pub true_moment_am2: Vector3<f64>,
}

impl std::ops::Deref for SimEpoch {
    type Target = Epoch;
    fn deref(&self) -> &Epoch {
        &self.measured
    }
}

impl std::borrow::Borrow<Epoch> for SimEpoch {
    fn borrow(&self) -> &Epoch {
        &self.measured
    }
}

/// Geodetic position of a local NED point (m) about `origin`: the WGS84
/// flat-earth relation of [`Geodetic::offset_by`] (radii of curvature at
/// the origin), the same as every other simulator of aeromag.
fn local_to_geodetic(origin: &Geodetic, p_ned: &Vector3<f64>) -> Geodetic {
    origin.offset_by(p_ned.x, p_ned.y, origin.alt_m - p_ned.z)
}

/// The random streams of a gradiometer scenario (numbers fixed: never
/// renumber), drawn with the scheme of [`aeromag_core::random`].
#[derive(Debug, Clone, Copy)]
#[repr(u64)]
enum Stream {
    /// Sensor biases.
    Bias = 1,
    /// Sensor noise.
    Noise = 2,
    /// Geomagnetic variations.
    Variation = 3,
}

fn rng(seed: u64, stream: Stream) -> ChaCha8Rng {
    random::stream(seed, stream as u64)
}

/// Simulate the scenario (deterministic for a given `seed`).
pub fn simulate(s: &Scenario) -> Result<Vec<SimEpoch>> {
    s.validate()?;
    let igrf = IgrfModel::new(s.decimal_year)
        .map_err(|e| GradiometryError::config(format!("decimal_year: {e}")))?;
    let mut bias_rng = rng(s.seed, Stream::Bias);
    let mut noise_rng = rng(s.seed, Stream::Noise);
    let mut var_rng = rng(s.seed, Stream::Variation);
    let bias_v: [Vector3<f64>; 4] = std::array::from_fn(|_| {
        Vector3::new(
            normal(&mut bias_rng),
            normal(&mut bias_rng),
            normal(&mut bias_rng),
        ) * s.vector_sensor.bias_sigma_nt
    });
    let bias_s: [f64; 4] =
        std::array::from_fn(|_| normal(&mut bias_rng) * s.scalar_sensor.bias_sigma_nt);
    let phases: [f64; 3] = std::array::from_fn(|_| var_rng.random::<f64>() * std::f64::consts::TAU);
    let periods = [60.0, 45.0, 80.0];
    let c_nb = s.system_attitude.c_nb();
    let c_bn = c_nb.transpose();
    let half = 0.5 * s.speed_m_s * s.dt_s * (s.epochs - 1) as f64;
    let (y0, z0) = s.offset_east_down_m;
    let v_ned = Vector3::new(s.speed_m_s, 0.0, 0.0);
    let (v_o, v_s) = match s.motion {
        SystemMotion::Stationary => (v_ned, Vector3::zeros()),
        SystemMotion::Mobile => (Vector3::zeros(), v_ned),
    };
    let mut out = Vec::with_capacity(s.epochs);
    for j in 0..s.epochs {
        let t = j as f64 * s.dt_s;
        let along = -half + s.speed_m_s * t;
        let (p_s, p_o) = match s.motion {
            SystemMotion::Stationary => (Vector3::zeros(), Vector3::new(along, y0, z0)),
            SystemMotion::Mobile => (Vector3::new(along, 0.0, 0.0), Vector3::new(0.0, y0, z0)),
        };
        let geo_s = local_to_geodetic(&s.origin, &p_s);
        let b_e = igrf.field_geodetic(&geo_s).ned_nt();
        let g_e = igrf.gradient_ned_nt_per_m(&geo_s);
        // the same as `Background::from_igrf`, which the estimator uses
        let background = Background::from_ned(&b_e, &g_e, &s.system_attitude);
        let b_at_object = igrf
            .field_geodetic(&local_to_geodetic(&s.origin, &p_o))
            .ned_nt();
        let yaw = s.object_yaw_rad + s.object_yaw_rate_rad_s * t;
        let c_no = Attitude::new(0.0, 0.0, yaw).c_nb();
        let m_obj = s.permanent_moment_am2
            + Matrix3::from_diagonal(&s.induced_am2_per_nt) * (c_no.transpose() * b_at_object);
        let m_ned = c_no * m_obj;
        let d = Vector3::from_fn(|k, _| {
            s.variation_nt * (std::f64::consts::TAU * t / periods[k] + phases[k]).sin()
        });
        let mut vector_nt = [Vector3::zeros(); 4];
        let mut scalar_nt = [0.0; 4];
        for (i, off) in s.geometry.offsets_m().iter().enumerate() {
            let dn = c_nb * off;
            let b = b_e + g_e * dn + d + dipole_field(&m_ned, &(p_s + dn - p_o)) * NT_PER_T;
            let nv = Vector3::new(
                normal(&mut noise_rng),
                normal(&mut noise_rng),
                normal(&mut noise_rng),
            );
            vector_nt[i] = c_bn * b + bias_v[i] + nv * s.vector_sensor.noise_nt;
            scalar_nt[i] = b.norm() + bias_s[i] + normal(&mut noise_rng) * s.scalar_sensor.noise_nt;
        }
        let measured = Epoch {
            t_s: t,
            vector_nt,
            scalar_nt,
            background,
            motion: Motion {
                v_object: c_bn * v_o,
                v_system: c_bn * v_s,
                w_object: c_bn * Vector3::new(0.0, 0.0, s.object_yaw_rate_rad_s),
                w_system: Vector3::zeros(),
                dt_s: if j == 0 { 0.0 } else { s.dt_s },
            },
            system_position_ned_m: p_s,
            system_geodetic: geo_s,
            system_attitude: s.system_attitude,
            object_position_ned_m: p_o,
            object_yaw_rad: yaw,
        };
        out.push(SimEpoch {
            measured,
            true_position_m: c_bn * (p_o - p_s),
            true_moment_am2: c_bn * m_ned,
        });
    }
    Ok(out)
}

/// How the processing treats sensor biases and the background.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Processing {
    /// Subtract the mean contrasts of the first `quiet_epochs` epochs
    /// (object far away: removes per-sensor biases and the Earth-gradient
    /// contrasts; the forward model then omits the background gradient).
    /// 0 = use the IGRF background in the forward model, no bias removal.
    pub quiet_epochs: usize,
    /// Model noise of the motion model.
    pub noise: MotionNoise,
    /// Characteristic moment for the induced term of `S_Q` (and the scalar
    /// system's offset prior, [`scalar_epochs`]), A·m².
    pub moment_scale_am2: f64,
}

fn quiet_mean<const K: usize>(
    vals: impl Iterator<Item = SVector<f64, K>>,
    n: usize,
) -> SVector<f64, K> {
    if n == 0 {
        return SVector::zeros();
    }
    vals.take(n).sum::<SVector<f64, K>>() / n as f64
}

/// Tensor-system filter input (state `(r, M)`, body frame).
pub fn tensor_epochs<E: Borrow<Epoch>>(
    sim: &[E],
    geometry: &Geometry,
    p: &Processing,
) -> Vec<PassEpoch<6, 9, TensorForward>> {
    let q = p.quiet_epochs.min(sim.len());
    let z0 = quiet_mean(
        sim.iter().map(|e| contrasts_vector(&e.borrow().vector_nt)),
        q,
    );
    sim.iter()
        .map(|e| {
            let e: &Epoch = e.borrow();
            let (f, u, s_q) = motion_mt(
                &e.motion,
                &p.noise,
                &Vector3::new(p.moment_scale_am2, 0.0, 0.0),
            );
            let background = if q > 0 {
                Background::zero()
            } else {
                e.background
            };
            PassEpoch {
                transition: f,
                offset: u,
                s_q,
                model: TensorForward {
                    geometry: *geometry,
                    background,
                },
                z: contrasts_vector(&e.vector_nt) - z0,
            }
        })
        .collect()
}

/// Scalar-system filter input, position known (`positions_m[j]`, e.g. the
/// true or a navigated relative position): state `x = (M, M_i, b)`, the
/// total moment the sensors see and its induced part in the body frame
/// (A·m², moving as in [`motion_mv_induced`]) and a constant offset `b` of
/// the three contrasts (nT, `F = I`, no process noise).
///
/// The offset is what the bias removal leaves: the mean of the first
/// `Q = quiet_epochs` contrasts holds, besides the sensor biases, the
/// object's own contrasts there, `z̄_Q = b_s + (1/Q) Σ_{q<Q} h_q(M_q) + v̄`,
/// which at the scalar sensors' noise (0.02 nT against some 0.05 nT from
/// 1500 A·m² at 50 m) biased every epoch by about 2σ. Its prior enters as
/// the first epoch's process noise (the pass's prior covers the moment
/// only): per contrast `k`,
///
/// ```text
/// σ_b,k = √((|M| ‖row_k(H̄_Q)‖)² + σ²/Q),   H̄_Q = (1/Q) Σ_{q<Q} ∂h_q/∂M (M = 0),
/// ```
///
/// `|M|` the characteristic moment `moment_scale_am2`, `σ` the sensor
/// noise `noise_nt` (nT). Without bias removal (`Q = 0`) the offset is 0.
pub fn scalar_epochs<E: Borrow<Epoch>>(
    sim: &[E],
    geometry: &Geometry,
    positions_m: &[Vector3<f64>],
    p: &Processing,
    noise_nt: f64,
) -> Result<Vec<PassEpoch<9, 3, ScalarForward>>> {
    if positions_m.len() != sim.len() {
        return Err(GradiometryError::LengthMismatch {
            what: "positions_m",
            got: positions_m.len(),
            expected: sim.len(),
        });
    }
    let q = p.quiet_epochs.min(sim.len());
    let z0 = quiet_mean(
        sim.iter().map(|e| contrasts_scalar(&e.borrow().scalar_nt)),
        q,
    );
    let mut epochs: Vec<PassEpoch<9, 3, ScalarForward>> = sim
        .iter()
        .zip(positions_m)
        .map(|(e, r)| {
            let e: &Epoch = e.borrow();
            let (f6, _, q6) = motion_mv_induced(
                &e.motion,
                &p.noise,
                &Vector3::new(p.moment_scale_am2, 0.0, 0.0),
            );
            let mut transition = SMatrix::<f64, 9, 9>::identity();
            transition.fixed_view_mut::<6, 6>(0, 0).copy_from(&f6);
            let mut s_q = SVector::<f64, 9>::zeros();
            s_q.fixed_rows_mut::<6>(0).copy_from(&q6);
            let mut background = e.background;
            if q > 0 {
                background.gradient_nt_per_m = Matrix3::zeros();
            }
            PassEpoch {
                transition,
                offset: SVector::zeros(),
                s_q,
                model: ScalarForward {
                    geometry: *geometry,
                    background,
                    position_m: *r,
                },
                z: contrasts_scalar(&e.scalar_nt) - z0,
            }
        })
        .collect();
    if q > 0 {
        let h_mean = epochs[..q]
            .iter()
            .map(|e| Forward::<3, 3>::eval(&e.model, &Vector3::zeros()).1)
            .sum::<Matrix3<f64>>()
            / q as f64;
        let noise2 = noise_nt * noise_nt / q as f64;
        let sigma_b = Vector3::from_fn(|k, _| {
            ((p.moment_scale_am2 * h_mean.row(k).norm()).powi(2) + noise2).sqrt()
        });
        epochs[0].s_q.fixed_rows_mut::<3>(6).copy_from(&sigma_b);
    }
    Ok(epochs)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Layout;

    #[test]
    fn simulation_is_deterministic_and_variations_cancel_in_contrasts() {
        let g = Geometry::new(Layout::Tetrahedron, 1.0).unwrap();
        let mut s = Scenario::new(SystemMotion::Mobile, g);
        s.epochs = 50;
        let a = simulate(&s).unwrap();
        assert_eq!(a, simulate(&s).unwrap());
        // Without noise and bias, the vector contrasts do not depend on the variations.
        s.vector_sensor = SensorSpec {
            noise_nt: 0.0,
            bias_sigma_nt: 0.0,
        };
        let quiet = simulate(&Scenario {
            variation_nt: 0.0,
            ..s.clone()
        })
        .unwrap();
        let loud = simulate(&Scenario {
            variation_nt: 50.0,
            ..s
        })
        .unwrap();
        for (q, l) in quiet.iter().zip(&loud) {
            let dz = contrasts_vector(&q.vector_nt) - contrasts_vector(&l.vector_nt);
            assert!(dz.norm() < 1e-9, "{}", dz.norm());
            assert!((q.vector_nt[0] - l.vector_nt[0]).norm() > 1.0 || q.t_s == 0.0);
        }
    }

    #[test]
    fn bad_scenario_is_an_error() {
        let g = Geometry::new(Layout::Cross, 1.0).unwrap();
        let s = Scenario {
            dt_s: -1.0,
            ..Scenario::new(SystemMotion::Stationary, g)
        };
        assert!(simulate(&s).is_err());
    }
}
