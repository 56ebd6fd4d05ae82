//! The `gradiometer` scenario file (TOML): what `aeromag dipole simulate`
//! simulates and what `aeromag dipole locate|crlb` assume (spec
//! `gradiometry.md`, "Simulation mock-up"; seed `004_…`, sect. 5).
//!
//! Every field has a default (documented on the field; the defaults are
//! those of [`Scenario::new`] and of the realistic-pass estimator settings),
//! so a file may set any subset. Unknown fields are errors (a typo is
//! reported with the TOML parser's line and column). The file written next
//! to simulated data has every default filled in; passing it back with
//! `--config` reproduces the data bit for bit.
//!
//! ```toml
//! seed = 1
//! [system]       # motion = "stationary" | "mobile", gradiometer = "tensor" | "scalar",
//!                # layout = "tetrahedron" | "cross" | "planar", baseline_m, attitude_deg
//! [sensors.vector]  # noise_nt, bias_sigma_nt   (fluxgates of the tensor gradiometer)
//! [sensors.scalar]  # noise_nt, bias_sigma_nt   (scalar sensors)
//! [environment]  # variation_nt, lat_deg, lon_deg, alt_m, decimal_year (IGRF field and gradient)
//! [object]       # permanent_moment_am2, induced_am2_per_nt, yaw_rad, yaw_rate_rad_s
//! [trajectory]   # dt_s, epochs, speed_m_s, offset_east_m, offset_down_m
//! [estimator]    # quiet epochs, motion-model noise, detection, initialisation, passes,
//!                # difference_model = "exact" | "gradient_tensor"
//! ```

use crate::error::{GradiometryError, Result, in_range};
use crate::geometry::{Geometry, Layout};
use crate::locate::LocateConfig;
use crate::motion::MotionNoise;
use crate::sim::{
    DT_RANGE_S, Gradiometer, MAX_EPOCHS, Processing, Scenario, SensorSpec, SystemMotion,
};
use crate::sr_iekf::IekfConfig;
use crate::tensor_approx::DifferenceModel;
use aeromag_core::field::igrf::IgrfModel;
use aeromag_core::frames::Attitude;
use aeromag_core::frames::geodetic::Geodetic;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// The measuring system.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SystemConfig {
    /// Which body moves: `"stationary"` (default; the object drives past)
    /// or `"mobile"` (the system drives past a fixed object).
    pub motion: SystemMotion,
    /// `"tensor"` (default; four vector sensors, state `(r, M)`) or
    /// `"scalar"` (four scalar sensors, state `M`, position from the tracks).
    pub gradiometer: Gradiometer,
    /// Sensor layout. Default `"tetrahedron"`.
    pub layout: Layout,
    /// Distance between neighbouring sensors, m, 0.001…100
    /// ([`crate::geometry::BASELINE_RANGE_M`]). Default 1.
    pub baseline_m: f64,
    /// Roll, pitch, yaw of the system (fixed during the pass), deg, each
    /// within ±360. Default 0, 0, 0.
    pub attitude_deg: [f64; 3],
}

impl Default for SystemConfig {
    fn default() -> Self {
        Self {
            motion: SystemMotion::Stationary,
            gradiometer: Gradiometer::Tensor,
            layout: Layout::Tetrahedron,
            baseline_m: 1.0,
            attitude_deg: [0.0; 3],
        }
    }
}

/// Noise and bias of one sensor type, nT.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorConfig {
    /// White noise σ per sample (per axis for vector sensors), nT; the
    /// estimator's σ of the configured gradiometer must be within
    /// [`NOISE_RANGE_NT`].
    pub noise_nt: f64,
    /// σ of the fixed per-sensor bias (per axis), nT.
    pub bias_sigma_nt: f64,
}

/// Both sensor types. A field not given takes its sensor type's default
/// (`[sensors.vector]` with `noise_nt` alone keeps the vector sensors'
/// 5 nT bias: it was refused, "missing field `bias_sigma_nt`").
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(from = "PartialSensors")]
pub struct SensorsConfig {
    /// Vector (fluxgate) sensors. Default 0.5 nT noise, 5 nT bias.
    pub vector: SensorConfig,
    /// Scalar sensors. Default 0.02 nT noise, 0.5 nT bias.
    pub scalar: SensorConfig,
}

impl Default for SensorsConfig {
    fn default() -> Self {
        Self {
            vector: SensorConfig {
                noise_nt: 0.5,
                bias_sigma_nt: 5.0,
            },
            scalar: SensorConfig {
                noise_nt: 0.02,
                bias_sigma_nt: 0.5,
            },
        }
    }
}

/// [`SensorsConfig`] as written in a scenario file: any field may be left
/// out.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PartialSensors {
    vector: Option<PartialSensor>,
    scalar: Option<PartialSensor>,
}

/// [`SensorConfig`] as written in a scenario file.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PartialSensor {
    noise_nt: Option<f64>,
    bias_sigma_nt: Option<f64>,
}

impl PartialSensor {
    /// The given fields over `default`'s.
    fn over(self, default: SensorConfig) -> SensorConfig {
        SensorConfig {
            noise_nt: self.noise_nt.unwrap_or(default.noise_nt),
            bias_sigma_nt: self.bias_sigma_nt.unwrap_or(default.bias_sigma_nt),
        }
    }
}

impl From<PartialSensors> for SensorsConfig {
    fn from(p: PartialSensors) -> Self {
        let d = Self::default();
        Self {
            vector: p.vector.map_or(d.vector, |v| v.over(d.vector)),
            scalar: p.scalar.map_or(d.scalar, |v| v.over(d.scalar)),
        }
    }
}

/// Place, date and natural field variations.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EnvironmentConfig {
    /// Amplitude of the natural variations common to all sensors, nT. Default 5.
    pub variation_nt: f64,
    /// Latitude of the local origin, deg, −90…90. Default 55.
    pub lat_deg: f64,
    /// Longitude of the local origin, deg, −360…360. Default 37.
    pub lon_deg: f64,
    /// Height of the origin above the ellipsoid, m, −10 000…1 000 000
    /// (deepest mine to low Earth orbit: where the IGRF describes the
    /// field). Default 150.
    pub alt_m: f64,
    /// Epoch of the IGRF (Earth's field and gradient), decimal year, within
    /// the IGRF's years. Default 2025.5.
    pub decimal_year: f64,
}

impl Default for EnvironmentConfig {
    fn default() -> Self {
        Self {
            variation_nt: 5.0,
            lat_deg: 55.0,
            lon_deg: 37.0,
            alt_m: 150.0,
            decimal_year: 2025.5,
        }
    }
}

/// The object: `M = C_no (M_perm + K C_on B_e)` (see [`crate::sim`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ObjectConfig {
    /// Permanent moment in the object's axes, A·m². Default (800, −300, 200).
    pub permanent_moment_am2: [f64; 3],
    /// Induced susceptibility diagonal in the object's axes, A·m²/nT.
    /// Default (0.02, 0.008, 0.008).
    pub induced_am2_per_nt: [f64; 3],
    /// Initial heading, rad. Default 0.
    pub yaw_rad: f64,
    /// Yaw rate, rad/s. Default 0.02.
    pub yaw_rate_rad_s: f64,
}

impl Default for ObjectConfig {
    fn default() -> Self {
        Self {
            permanent_moment_am2: [800.0, -300.0, 200.0],
            induced_am2_per_nt: [0.02, 0.008, 0.008],
            yaw_rad: 0.0,
            yaw_rate_rad_s: 0.02,
        }
    }
}

/// The pass: the moving body drives north along a line offset east and
/// down from the other, centred on the closest approach.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TrajectoryConfig {
    /// Sample interval, s, 10⁻⁶…3600 ([`crate::sim::DT_RANGE_S`]). Default 0.1.
    pub dt_s: f64,
    /// Number of epochs, 2…1 000 000 ([`crate::sim::MAX_EPOCHS`]: a
    /// million samples are 28 h at 10 Hz). Default 600 (a 120 m pass at 2 m/s).
    pub epochs: usize,
    /// Speed of the moving body, m/s. Default 2.
    pub speed_m_s: f64,
    /// East offset of the pass line, m. Default 6.
    pub offset_east_m: f64,
    /// Down offset of the pass line, m. Default 2.
    pub offset_down_m: f64,
}

impl Default for TrajectoryConfig {
    fn default() -> Self {
        Self {
            dt_s: 0.1,
            epochs: 600,
            speed_m_s: 2.0,
            offset_east_m: 6.0,
            offset_down_m: 2.0,
        }
    }
}

/// Settings of `aeromag dipole locate` (see [`crate::locate`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EstimatorConfig {
    /// Subtract the mean contrasts of the first epochs (object far away:
    /// removes sensor biases and the Earth-gradient contrasts; the scalar
    /// system estimates what the object's own contrasts there leave as a
    /// contrast offset, [`crate::sim::scalar_epochs`]); 0 = use the IGRF
    /// background in the model. Default 50.
    pub quiet_epochs: usize,
    /// Position random walk of the motion model, m/√s. Default 0.02.
    pub position_random_walk_m_per_sqrt_s: f64,
    /// Moment random walk, A·m²/√s. Default 2.
    pub moment_random_walk_am2_per_sqrt_s: f64,
    /// Induced-moment coefficient κ of the moment noise, per rad. Default 1.
    pub induced_per_rad: f64,
    /// Characteristic moment |M| for the induced term (and, scalar system,
    /// for the prior of the contrast offset), A·m². Default 1500.
    pub moment_scale_am2: f64,
    /// Detection threshold `k` (tensor): start at the first epoch with
    /// `‖z‖ > k σ √9`. Default 30.
    pub detection_factor: f64,
    /// Multi-start initialisation at the detection epoch (default true);
    /// false = the plain IEKF from `initial_position_m` with zero moment.
    pub multistart: bool,
    /// Epochs of the multi-start window ([`crate::locate::window_multistart`]),
    /// at least 1. Default 30.
    pub multistart_window_epochs: usize,
    /// Start position of the plain IEKF, body frame, m. Default (10, 0, 0).
    pub initial_position_m: [f64; 3],
    /// Prior σ of each position component, m. Default 20.
    pub prior_sigma_position_m: f64,
    /// Prior σ of each moment component, A·m². Default 3000.
    pub prior_sigma_moment_am2: f64,
    /// Passes over the data (1 = filter; more = re-linearised passes,
    /// [`crate::pass::run_pass_relinearised`]), 1…[`MAX_PASSES`]. Default 1.
    pub passes: usize,
    /// Extra position noise per step of the first of several passes, m. Default 0.3.
    pub first_pass_extra_position_m: f64,
    /// Extra moment noise per step of the first of several passes, A·m². Default 30.
    pub first_pass_extra_moment_am2: f64,
    /// Maximum IEKF iterations per epoch, 1…[`MAX_ITERATIONS`]. Default 30.
    pub max_iterations: usize,
    /// `k` of the residual threshold `k σ √Z`. Default 1.5.
    pub residual_factor: f64,
    /// Forward model of the tensor differences: `"exact"` (default, the
    /// seed's) or `"gradient_tensor"` (the linear approximation of
    /// [`crate::tensor_approx`], for comparison).
    pub difference_model: DifferenceModel,
}

impl Default for EstimatorConfig {
    fn default() -> Self {
        Self {
            quiet_epochs: 50,
            position_random_walk_m_per_sqrt_s: 0.02,
            moment_random_walk_am2_per_sqrt_s: 2.0,
            induced_per_rad: 1.0,
            moment_scale_am2: 1500.0,
            detection_factor: 30.0,
            multistart: true,
            multistart_window_epochs: 30,
            initial_position_m: [10.0, 0.0, 0.0],
            prior_sigma_position_m: 20.0,
            prior_sigma_moment_am2: 3000.0,
            passes: 1,
            first_pass_extra_position_m: 0.3,
            first_pass_extra_moment_am2: 30.0,
            max_iterations: 30,
            residual_factor: 1.5,
            difference_model: DifferenceModel::Exact,
        }
    }
}

/// The whole `gradiometer` scenario file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GradiometerConfig {
    /// Seed of the noise, biases and variations (ChaCha8 streams). Default 1; < 2⁶³.
    pub seed: u64,
    /// The measuring system.
    pub system: SystemConfig,
    /// Sensor noise and bias.
    pub sensors: SensorsConfig,
    /// Place, date, natural variations.
    pub environment: EnvironmentConfig,
    /// The object.
    pub object: ObjectConfig,
    /// The pass.
    pub trajectory: TrajectoryConfig,
    /// Estimator settings.
    pub estimator: EstimatorConfig,
}

impl Default for GradiometerConfig {
    fn default() -> Self {
        Self {
            seed: 1,
            system: SystemConfig::default(),
            sensors: SensorsConfig::default(),
            environment: EnvironmentConfig::default(),
            object: ObjectConfig::default(),
            trajectory: TrajectoryConfig::default(),
            estimator: EstimatorConfig::default(),
        }
    }
}

/// Most IEKF iterations per epoch (`estimator.max_iterations`): the iteration converges in a few
/// steps where it converges at all (30 by default); a thousand is ample,
/// and the run time grows linearly with it.
pub const MAX_ITERATIONS: usize = 1000;

/// Most re-linearised passes (`estimator.passes`): each is one
/// Gauss–Newton step; the studies use 10 to 30.
pub const MAX_PASSES: usize = 100;

/// Range of the estimator's sensor noise σ, nT: 1 fT (below any
/// magnetometer) to 10 µT (a fifth of the Earth's field).
pub const NOISE_RANGE_NT: (f64, f64) = (1e-6, 1e4);

fn cfg_err(e: impl std::fmt::Display) -> GradiometryError {
    GradiometryError::config(e.to_string())
}

fn v3(a: [f64; 3]) -> Vector3<f64> {
    Vector3::new(a[0], a[1], a[2])
}

impl GradiometerConfig {
    /// Parse a scenario file (fields not given take the defaults) and
    /// validate it. Errors: [`GradiometryError::Config`] naming the field.
    pub fn from_toml(text: &str) -> Result<Self> {
        let c: Self = toml::from_str(text).map_err(|e| GradiometryError::toml(text, &e))?;
        c.validate()?;
        Ok(c)
    }

    /// The configuration as TOML with every default filled in, after a
    /// comment header.
    pub fn to_toml(&self) -> Result<String> {
        let body = toml::to_string(self).map_err(cfg_err)?;
        Ok(format!(
            "# aeromag `gradiometer` scenario (aeromag-gradiometry {}), every default filled in.\n\
             # `aeromag dipole simulate --config <this file>` reproduces the data;\n\
             # `aeromag dipole locate|crlb --config <this file>` use the same geometry and noise.\n\n{body}",
            env!("CARGO_PKG_VERSION")
        ))
    }

    /// Check every value (through the scenario, the geometry and the
    /// estimator settings). Errors: [`GradiometryError::Config`].
    pub fn validate(&self) -> Result<()> {
        if self.seed > i64::MAX as u64 {
            return Err(cfg_err("seed must be < 2^63"));
        }
        let wrap = |field: &str, e: GradiometryError| cfg_err(format!("{field}: {e}"));
        // Before anything is allocated or simulated, with the keys' names.
        let t = &self.trajectory;
        if !(2..=MAX_EPOCHS).contains(&t.epochs) {
            return Err(cfg_err(format!(
                "trajectory.epochs must be in 2…{MAX_EPOCHS}, got {}",
                t.epochs
            )));
        }
        let env = &self.environment;
        let sys = &self.system;
        let checks = [
            ("trajectory.dt_s", t.dt_s, DT_RANGE_S.0, DT_RANGE_S.1),
            ("environment.lat_deg", env.lat_deg, -90.0, 90.0),
            ("environment.lon_deg", env.lon_deg, -360.0, 360.0),
            ("environment.alt_m", env.alt_m, -1e4, 1e6),
            ("system.attitude_deg[0]", sys.attitude_deg[0], -360.0, 360.0),
            ("system.attitude_deg[1]", sys.attitude_deg[1], -360.0, 360.0),
            ("system.attitude_deg[2]", sys.attitude_deg[2], -360.0, 360.0),
        ];
        for (name, v, lo, hi) in checks {
            in_range(name, v, lo, hi).map_err(cfg_err)?;
        }
        IgrfModel::new(env.decimal_year)
            .map_err(|e| cfg_err(format!("environment.decimal_year: {e}")))?;
        let s = self.scenario().map_err(|e| wrap("system/trajectory", e))?;
        s.validate().map_err(|e| wrap("scenario", e))?;
        if self.estimator.quiet_epochs >= self.trajectory.epochs {
            return Err(cfg_err(
                "estimator.quiet_epochs must be smaller than trajectory.epochs",
            ));
        }
        self.locate_config(None)
            .map_err(|e| wrap("estimator", e))
            .map(|_| ())
    }

    /// The sensor layout.
    pub fn geometry(&self) -> Result<Geometry> {
        Geometry::new(self.system.layout, self.system.baseline_m)
    }

    /// White-noise σ of the configured gradiometer's sensors, nT.
    pub fn sensor_sigma_nt(&self) -> f64 {
        match self.system.gradiometer {
            Gradiometer::Tensor => self.sensors.vector.noise_nt,
            Gradiometer::Scalar => self.sensors.scalar.noise_nt,
        }
    }

    /// The simulator scenario.
    pub fn scenario(&self) -> Result<Scenario> {
        let mut s = Scenario::new(self.system.motion, self.geometry()?);
        let sensor = |c: &SensorConfig| SensorSpec {
            noise_nt: c.noise_nt,
            bias_sigma_nt: c.bias_sigma_nt,
        };
        s.vector_sensor = sensor(&self.sensors.vector);
        s.scalar_sensor = sensor(&self.sensors.scalar);
        s.dt_s = self.trajectory.dt_s;
        s.epochs = self.trajectory.epochs;
        s.speed_m_s = self.trajectory.speed_m_s;
        s.offset_east_down_m = (self.trajectory.offset_east_m, self.trajectory.offset_down_m);
        s.permanent_moment_am2 = v3(self.object.permanent_moment_am2);
        s.induced_am2_per_nt = v3(self.object.induced_am2_per_nt);
        s.object_yaw_rad = self.object.yaw_rad;
        s.object_yaw_rate_rad_s = self.object.yaw_rate_rad_s;
        let [r, p, y] = self.system.attitude_deg;
        s.system_attitude = Attitude::from_degrees(r, p, y);
        s.variation_nt = self.environment.variation_nt;
        s.origin = Geodetic {
            lat_deg: self.environment.lat_deg,
            lon_deg: self.environment.lon_deg,
            alt_m: self.environment.alt_m,
        };
        s.decimal_year = self.environment.decimal_year;
        s.seed = self.seed;
        Ok(s)
    }

    /// How the estimator treats biases and the motion-model noise.
    pub fn processing(&self) -> Processing {
        let e = &self.estimator;
        Processing {
            quiet_epochs: e.quiet_epochs,
            noise: MotionNoise {
                position_m_per_sqrt_s: e.position_random_walk_m_per_sqrt_s,
                moment_am2_per_sqrt_s: e.moment_random_walk_am2_per_sqrt_s,
                induced_per_rad: e.induced_per_rad,
            },
            moment_scale_am2: e.moment_scale_am2,
        }
    }

    /// The estimator settings with sensor noise `sigma_nt` (nT; `None` =
    /// [`Self::sensor_sigma_nt`]).
    pub fn locate_config(&self, sigma_nt: Option<f64>) -> Result<LocateConfig> {
        let e = &self.estimator;
        for (name, v) in [
            (
                "position_random_walk_m_per_sqrt_s",
                e.position_random_walk_m_per_sqrt_s,
            ),
            (
                "moment_random_walk_am2_per_sqrt_s",
                e.moment_random_walk_am2_per_sqrt_s,
            ),
            ("induced_per_rad", e.induced_per_rad),
            ("moment_scale_am2", e.moment_scale_am2),
            ("first_pass_extra_position_m", e.first_pass_extra_position_m),
            ("first_pass_extra_moment_am2", e.first_pass_extra_moment_am2),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(GradiometryError::NotPositive { name, value: v });
            }
        }
        let sigma = in_range(
            "sigma_nt (noise_nt of the configured gradiometer's sensors)",
            sigma_nt.unwrap_or(self.sensor_sigma_nt()),
            NOISE_RANGE_NT.0,
            NOISE_RANGE_NT.1,
        )?;
        for (name, v, max) in [
            ("max_iterations", e.max_iterations, MAX_ITERATIONS),
            (
                "multistart_window_epochs",
                e.multistart_window_epochs,
                MAX_EPOCHS,
            ),
            ("passes", e.passes, MAX_PASSES),
        ] {
            in_range(name, v as f64, 1.0, max as f64)?;
        }
        let mut iekf = IekfConfig::new(sigma)?;
        iekf.max_iterations = e.max_iterations;
        iekf.residual_factor = crate::error::positive("residual_factor", e.residual_factor)?;
        let c = LocateConfig {
            iekf,
            detection_factor: e.detection_factor,
            multistart: e.multistart,
            initial_position_m: v3(e.initial_position_m),
            prior_sigma_position_m: e.prior_sigma_position_m,
            prior_sigma_moment_am2: e.prior_sigma_moment_am2,
            window_epochs: e.multistart_window_epochs,
            passes: e.passes,
            first_pass_extra_position_m: e.first_pass_extra_position_m,
            first_pass_extra_moment_am2: e.first_pass_extra_moment_am2,
            difference_model: e.difference_model,
        };
        c.validate()?;
        Ok(c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_match_the_library_scenario_and_round_trip() {
        let c = GradiometerConfig::from_toml("").unwrap();
        assert_eq!(c.seed, 1);
        let s = c.scenario().unwrap();
        // the file's pass is longer (600 epochs: quiet epochs for the bias removal)
        let lib = Scenario {
            epochs: 600,
            ..Scenario::new(SystemMotion::Stationary, c.geometry().unwrap())
        };
        assert_eq!(s, lib);
        let text = c.to_toml().unwrap();
        assert!(text.contains("[estimator]") && text.contains("layout = \"tetrahedron\""));
        assert_eq!(GradiometerConfig::from_toml(&text).unwrap(), c);
    }

    #[test]
    fn partial_files_override_only_what_they_set() {
        let c = GradiometerConfig::from_toml(
            "seed = 7\n[system]\nmotion = \"mobile\"\ngradiometer = \"scalar\"\nlayout = \"cross\"\n\
             [sensors.scalar]\nnoise_nt = 0.05\nbias_sigma_nt = 0.0\n[trajectory]\nepochs = 200\n",
        )
        .unwrap();
        assert_eq!(c.seed, 7);
        assert_eq!(c.system.motion, SystemMotion::Mobile);
        assert_eq!(c.system.gradiometer, Gradiometer::Scalar);
        assert_eq!(c.system.layout, Layout::Cross);
        assert_eq!(c.sensor_sigma_nt(), 0.05);
        assert_eq!(c.trajectory.epochs, 200);
        assert_eq!(c.trajectory.speed_m_s, 2.0);
        assert_eq!(c.sensors.vector, SensorsConfig::default().vector);
        let text = c.to_toml().unwrap();
        assert_eq!(GradiometerConfig::from_toml(&text).unwrap(), c);
        assert_eq!(
            c.locate_config(None).unwrap().difference_model,
            DifferenceModel::Exact
        );
        // One field of a sensor type: the other keeps that type's default.
        let noise = GradiometerConfig::from_toml("[sensors.vector]\nnoise_nt = 0.3\n").unwrap();
        assert_eq!(noise.sensors.vector.noise_nt, 0.3);
        assert_eq!(noise.sensors.vector.bias_sigma_nt, 5.0);
        assert_eq!(noise.sensors.scalar, SensorsConfig::default().scalar);
        let bias = GradiometerConfig::from_toml("[sensors.scalar]\nbias_sigma_nt = 0.1\n").unwrap();
        assert_eq!(bias.sensors.scalar.noise_nt, 0.02);
        assert!(
            GradiometerConfig::from_toml("[sensors.scalar]\nnoise = 0.1\n")
                .unwrap_err()
                .to_string()
                .contains("noise")
        );
        let approx =
            GradiometerConfig::from_toml("[estimator]\ndifference_model = \"gradient_tensor\"\n")
                .unwrap();
        assert_eq!(
            approx.locate_config(None).unwrap().difference_model,
            DifferenceModel::GradientTensor
        );
    }

    #[test]
    fn bad_files_are_config_errors_naming_the_problem() {
        for (text, needle) in [
            ("[system]\nlayout = \"hexagon\"\n", "hexagon"),
            ("[system]\nbaseline_m = -1.0\n", "baseline_m"),
            ("[trajectory]\nepochs = 1\n", "epochs"),
            ("[trajectory]\nspeeed_m_s = 3.0\n", "speeed_m_s"),
            ("[estimator]\nquiet_epochs = 600\n", "quiet_epochs"),
            (
                "[sensors.vector]\nnoise_nt = 0.0\nbias_sigma_nt = 1.0\n",
                "sigma_nt",
            ),
            ("seed = \"x\"\n", "seed"),
            // 48.8 GB would have been allocated for this one
            ("[trajectory]\nepochs = 100000000\n", "trajectory.epochs"),
            ("[trajectory]\ndt_s = 1e-300\n", "trajectory.dt_s"),
            (
                "[estimator]\nmax_iterations = 1000000000\n",
                "max_iterations",
            ),
            ("[estimator]\nmax_iterations = 0\n", "max_iterations"),
            ("[estimator]\npasses = 0\n", "passes"),
            (
                "[estimator]\nmultistart_window_epochs = 0\n",
                "multistart_window_epochs",
            ),
            ("[environment]\nlat_deg = 91.0\n", "environment.lat_deg"),
            ("[environment]\nlat_deg = 1e308\n", "1e308"),
            ("[environment]\nalt_m = 1e308\n", "environment.alt_m"),
            (
                "[environment]\ndecimal_year = 2100.0\n",
                "environment.decimal_year",
            ),
            (
                "[system]\nattitude_deg = [1e308, 0.0, 0.0]\n",
                "attitude_deg[0]",
            ),
            ("[system]\nbaseline_m = 1e308\n", "baseline_m"),
            (
                "[sensors.vector]\nnoise_nt = 1e-308\nbias_sigma_nt = 1.0\n",
                "noise_nt",
            ),
        ] {
            let e = GradiometerConfig::from_toml(text).unwrap_err();
            assert!(matches!(e, GradiometryError::Config { .. }), "{e:?}");
            assert!(e.to_string().contains(needle), "{text}: {e}");
        }
    }

    #[test]
    fn syntax_errors_carry_their_line() {
        let e = GradiometerConfig::from_toml("seed = 3\n[system\n").unwrap_err();
        assert!(
            matches!(e, GradiometryError::Config { line: Some(2), .. }),
            "{e:?}"
        );
        let e =
            GradiometerConfig::from_toml("seed = 3\n\n[system]\nbaseline_m = \"x\"\n").unwrap_err();
        assert!(
            matches!(e, GradiometryError::Config { line: Some(4), .. }),
            "{e:?}"
        );
    }
}
