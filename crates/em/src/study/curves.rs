//! Positioning errors of the full chain versus range and versus noise level
//! (spec `em-positioning.md`, "What to show": "report how they grow with
//! range and noise"; issue 6, "curves of error versus range and noise").
//!
//! Unlike [`crate::positioning::error_study()`] (white noise added to ideal
//! field matrices), every point here goes through the whole chain: ADC-level
//! synthesis with all distortions → synchronous detection with pilot
//! correction → a given [`Calibration`] → positioning. Per point the bird is
//! held at one range (`range_min_m = range_max_m = L`; it still swings and
//! turns) and `epochs_per_point` blocks are taken at times spread over the
//! flight; the RMS errors are those of [`super::run_flight_study`].
//!
//! Noise level: the white coil noise is `s · σ₀` (`σ₀` the scenario's
//! `coil_noise_v`, `s` the scale); 400 Hz harmonics and sferics stay as
//! configured (the detector plan rejects them). The signal-to-noise ratio
//! reported per point is the per-sample input SNR
//!
//! ```text
//! SNR = 20 log10( a_rms / σ ),   a_rms² = (1/9) Σ_{i,c} |2π f_i g B_ic|² / 2      [dB]
//! ```
//!
//! with `B_ic` the true field of dipole `i` on channel `c` (T) averaged over
//! the point's epochs, `g` the coil gain (V per T/s), `σ = s σ₀` (V RMS per
//! sample). Detection over `N` samples gains about `10 log10(N/2)` dB
//! (≈ 39 dB for `N` = 16 000) before the fields are used.
//!
//! Two noise paths reach the pose: the noise of the detected working tones,
//! relative to a field that falls as `L⁻³` (so its share of the error grows
//! as `L³`), and the noise of the pilot-measured sensitivity `ξ` (eq. 4),
//! whose tones have a fixed amplitude: a relative gain error of the three
//! channels that does not depend on the range. With the default pilot
//! (2 nT) the second path is the floor of the curves at the default noise.

use super::{epochs_at, rms};
use crate::calibration::Calibration;
use crate::positioning::{Hemisphere, angle_between, field_matrix, rotation_angle_between};
use crate::sim::EmSimConfig;
use crate::{EmError, Result};
use nalgebra::Vector3;
use std::f64::consts::TAU;

/// Sizes of the curves.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveConfig {
    /// Ranges of the range curves, m.
    pub ranges_m: Vec<f64>,
    /// Coil-noise scales at which the range curves are taken (one curve
    /// each; 1 = the scenario's noise).
    pub range_noise_scales: Vec<f64>,
    /// Range at which the noise curve is taken, m.
    pub noise_range_m: f64,
    /// Coil-noise scales `s` of the noise curve (> 0).
    pub noise_scales: Vec<f64>,
    /// Detector blocks per point (≥ 1).
    pub epochs_per_point: usize,
    /// Flight length over which each point's blocks are spread, s.
    pub flight_s: f64,
}

impl Default for CurveConfig {
    /// Ranges 30–130 m at noise ×1 and ×100, noise ×1–×1000 at 100 m,
    /// 8 blocks per point over 5 h.
    fn default() -> Self {
        Self {
            ranges_m: vec![30.0, 50.0, 70.0, 100.0, 130.0],
            range_noise_scales: vec![1.0, 100.0],
            noise_range_m: 100.0,
            noise_scales: vec![1.0, 10.0, 100.0, 1000.0],
            epochs_per_point: 8,
            flight_s: 5.0 * 3600.0,
        }
    }
}

impl CurveConfig {
    /// Fewer points and blocks (ranges 30/65/100 m at noise ×1/×100, noise
    /// ×1/×100/×1000 at 100 m, 3 blocks) for quick demos.
    pub fn quick() -> Self {
        Self {
            ranges_m: vec![30.0, 65.0, 100.0],
            range_noise_scales: vec![1.0, 100.0],
            noise_scales: vec![1.0, 100.0, 1000.0],
            epochs_per_point: 3,
            ..Self::default()
        }
    }
}

/// RMS errors at one point of a curve.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CurvePoint {
    /// Range of the bird, m.
    pub range_m: f64,
    /// Coil-noise scale `s` (dimensionless).
    pub noise_scale: f64,
    /// Per-sample input SNR (module docs), dB.
    pub snr_db: f64,
    /// RMS relative range error (dimensionless).
    pub range_err_rel: f64,
    /// RMS direction error, deg.
    pub angle_err_deg: f64,
    /// RMS attitude error, deg.
    pub attitude_err_deg: f64,
}

/// The two curves.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ErrorCurves {
    /// Errors versus range: for each of `range_noise_scales` (outer) every
    /// range (inner).
    pub versus_range: Vec<CurvePoint>,
    /// Errors versus noise scale at `CurveConfig::noise_range_m`.
    pub versus_noise: Vec<CurvePoint>,
}

/// One point: blocks at range `range_m` with coil noise scaled by `scale`.
fn point(
    base: &EmSimConfig,
    cal: &Calibration,
    hemisphere: &Hemisphere,
    cfg: &CurveConfig,
    range_m: f64,
    scale: f64,
) -> Result<CurvePoint> {
    let sim = EmSimConfig {
        range_min_m: range_m,
        range_max_m: range_m,
        coil_noise_v: base.coil_noise_v * scale,
        ..base.clone()
    };
    let n = cfg.epochs_per_point;
    let times: Vec<f64> = (0..n)
        .map(|k| cfg.flight_s * (k as f64 + 0.53) / n as f64)
        .collect();
    let (sc, epochs) = epochs_at(&sim, &times, true)?;
    let m = sc.config.moments_am2;
    let m_eff = sc.effective_moments().map(|v| v.re);
    let g = sc.config.coil_gain_v_per_t_s;
    let mut errs = [Vec::new(), Vec::new(), Vec::new()];
    let mut power = 0.0;
    for e in &epochs {
        let l = cal.locate(&e.h, &m, &mut hemisphere.clone())?;
        let t = sc.pose_at(e.time_s);
        errs[0].push((l.pose.range_m() - t.range_m()) / t.range_m());
        errs[1].push(angle_between(&l.pose.position_m, &t.position_m).to_degrees());
        errs[2].push(rotation_angle_between(&l.pose.rotation, &t.rotation).to_degrees());
        let b = field_matrix(&t.position_m, &t.rotation, &m_eff);
        for (i, f) in sc.config.frequencies_hz.iter().enumerate() {
            let a: Vector3<f64> = b.column(i) * (TAU * f * g);
            power += a.norm_squared() / 2.0;
        }
    }
    let a_rms = (power / (9 * epochs.len()).max(1) as f64).sqrt();
    Ok(CurvePoint {
        range_m,
        noise_scale: scale,
        snr_db: 20.0 * (a_rms / sim.coil_noise_v).log10(),
        range_err_rel: rms(&errs[0]),
        angle_err_deg: rms(&errs[1]),
        attitude_err_deg: rms(&errs[2]),
    })
}

/// Errors of the calibrated chain versus range and versus coil-noise scale
/// (module docs) for the scenario `base` (its seed draws the distortions the
/// calibration `cal` was fitted for), locating with the prior half-space of
/// `hemisphere`.
///
/// Errors: no point, `epochs_per_point == 0`, non-positive ranges, scales,
/// coil noise or flight length, or a failing chain.
pub fn error_curves(
    base: &EmSimConfig,
    cal: &Calibration,
    hemisphere: &Hemisphere,
    cfg: &CurveConfig,
) -> Result<ErrorCurves> {
    let ok = |v: &[f64]| v.iter().all(|&x| crate::positive_finite(x));
    if cfg.epochs_per_point == 0
        || cfg.ranges_m.is_empty()
        || cfg.noise_scales.is_empty()
        || !ok(&cfg.ranges_m)
        || !ok(&cfg.noise_scales)
        || !ok(&cfg.range_noise_scales)
        || !crate::positive_finite(cfg.noise_range_m)
        || !crate::positive_finite(cfg.flight_s)
        || !crate::positive_finite(base.coil_noise_v)
    {
        return Err(EmError::InvalidArgument {
            reason: format!(
                "error curves need positive ranges, scales, flight and coil noise: {cfg:?}"
            ),
        });
    }
    let hemi = Hemisphere {
        previous: None,
        ..*hemisphere
    };
    let versus_range: Vec<CurvePoint> = cfg
        .range_noise_scales
        .iter()
        .flat_map(|&s| cfg.ranges_m.iter().map(move |&r| (r, s)))
        .map(|(r, s)| point(base, cal, &hemi, cfg, r, s))
        .collect::<Result<_>>()?;
    // A (range, scale) pair already on a range curve is the same simulation
    // (same seed and times): reuse it.
    let versus_noise = cfg
        .noise_scales
        .iter()
        .map(|&s| {
            match versus_range
                .iter()
                .find(|p: &&CurvePoint| p.range_m == cfg.noise_range_m && p.noise_scale == s)
            {
                Some(p) => Ok(*p),
                None => point(base, cal, &hemi, cfg, cfg.noise_range_m, s),
            }
        })
        .collect::<Result<_>>()?;
    Ok(ErrorCurves {
        versus_range,
        versus_noise,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::{FlightStudyConfig, run_flight_study};

    #[test]
    fn errors_grow_with_range_and_noise_and_meet_the_figures_at_default_snr() {
        let base = EmSimConfig::default();
        let st = run_flight_study(&base, &FlightStudyConfig::quick()).unwrap();
        let hemi = Hemisphere::new(Vector3::new(-1.0, 0.0, 1.0));
        let cfg = CurveConfig {
            ranges_m: vec![30.0, 100.0],
            range_noise_scales: vec![1.0, 100.0],
            noise_range_m: 100.0,
            noise_scales: vec![1.0, 100.0, 1000.0],
            epochs_per_point: 24,
            ..CurveConfig::default()
        };
        let c = error_curves(&base, &st.calibration, &hemi, &cfg).unwrap();
        for p in c.versus_range.iter().chain(&c.versus_noise) {
            eprintln!("{p:?}");
        }
        let (near, far) = (c.versus_range[0], c.versus_range[1]);
        // SNR falls as L⁻³: 60·log10(100/30) ≈ 31.4 dB between the points.
        assert!(
            ((near.snr_db - far.snr_db) - 60.0 * (100.0f64 / 30.0).log10()).abs() < 3.0,
            "{near:?} {far:?}"
        );
        // At noise ×100 the errors grow with range (the field's share as L³;
        // the range-independent pilot floor of the module docs keeps the
        // total ratio well below 37: 1.5 for the range and 2.2 for the
        // angle over 24 epochs). An RMS of 24 epochs scatters by about
        // 1/√48 ≈ 14 %, so only the growth itself is asserted (a factor 2
        // held for one noise draw of 6 epochs, not for another).
        let (near100, far100) = (c.versus_range[2], c.versus_range[3]);
        assert_eq!((near100.noise_scale, far100.range_m), (100.0, 100.0));
        assert!(
            far100.range_err_rel > near100.range_err_rel,
            "{near100:?} {far100:?}"
        );
        assert!(
            far100.angle_err_deg > near100.angle_err_deg,
            "{near100:?} {far100:?}"
        );
        // The default SNR meets the issue's figures over 30–100 m.
        for p in &c.versus_range[..2] {
            assert!(
                p.range_err_rel <= 1e-3 && p.angle_err_deg <= 0.1 && p.attitude_err_deg <= 0.1,
                "{p:?}"
            );
        }
        // Noise ×1000 (−60 dB): the noise dominates and the errors grow.
        let (n1, n1000) = (c.versus_noise[0], c.versus_noise[2]);
        assert!((n1.snr_db - n1000.snr_db - 60.0).abs() < 1e-9);
        assert!(
            n1000.range_err_rel > 10.0 * n1.range_err_rel,
            "{n1:?} {n1000:?}"
        );
        assert!(
            n1000.angle_err_deg > 10.0 * n1.angle_err_deg,
            "{n1:?} {n1000:?}"
        );
        assert!(
            n1000.attitude_err_deg > 10.0 * n1.attitude_err_deg,
            "{n1:?} {n1000:?}"
        );
        // Monotone in the noise.
        assert!(c.versus_noise[1].range_err_rel < n1000.range_err_rel);
        let bad = CurveConfig {
            noise_scales: vec![0.0],
            ..cfg
        };
        assert!(error_curves(&base, &st.calibration, &hemi, &bad).is_err());
    }
}
