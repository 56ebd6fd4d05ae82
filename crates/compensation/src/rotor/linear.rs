//! The linear rotor model fitted by least squares (spec `helicopter.md`
//! part A; seed `000_…` §16, "simplified model", extended).
//!
//! With the blade axes `R_j = [r_p e_l e_u]` known from the geometry, the
//! rotor phase `ψ(t)` and the flap angles ([`super::blade`]), the field of
//! blade `j` projected on the field direction `e = B/|B|` is linear in the
//! blade's magnetic parameters:
//!
//! `ΔT_j = eᵀ D_I,j [ λk0_j r_p + (λ_j/μ0) r_p (r_pᵀ B) + γ_j (ω × B) + …]`
//!
//! * [`BladeTerms::Simplified`] — the thesis' model: hard magnetisation
//!   along the blade (`Q_K = k0 I`, parameter `h_∥ = λk0`, A·m), soft
//!   magnetisation along the blade (`χA_∥`, m²), eddy currents
//!   `ΔB_i ≈ γ D_I (ω × B)` (`γ`, A·m per T/s; the thesis writes
//!   `−γ D_I [ω×] B`, the sign is absorbed in `γ`): 3 parameters per blade.
//! * [`BladeTerms::Full`] — adds the hard magnetisation across the blade
//!   (lead and flap directions: a general `Q_K`) and the soft magnetisation
//!   across it (`χA_l e_l e_lᵀ B`, `χA_u e_u e_uᵀ B`; the latter also absorb
//!   the quadrature part of lagging eddy currents): 7 parameters per blade.
//!
//! Per-blade parameters give the once-per-revolution component of
//! dissimilar blades. The fit uses the data and the regressors high-passed
//! by the same zero-phase Butterworth filter (so the slow fuselage
//! interference, the anomaly and the diurnal variation do not enter), and
//! the prediction uses the unfiltered regressors (so the slow part of the
//! rotor field is predicted too).

use aeromag_core::MU0_OVER_4PI;
use aeromag_core::filter::{Band, butter, sosfiltfilt};
use aeromag_estimation::least_squares::NormalEquations;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use super::blade::{FlapAngles, RotorGeometry, blade_axes, dipole_integral};
use crate::error::{CompError, Result};

const MU0: f64 = 4.0 * std::f64::consts::PI * MU0_OVER_4PI;

/// Which blade parameters the model has (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum BladeTerms {
    /// Hard along, soft along, eddy: 3 per blade.
    Simplified,
    /// Plus hard lead/flap and soft lead/flap: 7 per blade.
    Full,
}

impl BladeTerms {
    /// Parameters per blade.
    pub fn per_blade(self) -> usize {
        match self {
            Self::Simplified => 3,
            Self::Full => 7,
        }
    }
}

/// The time series the model needs (all of length `n`).
#[derive(Debug, Clone, Copy)]
pub struct RotorInput<'a> {
    /// External field in body axes (e.g. the fluxgate), nT.
    pub b_body_nt: &'a [Vector3<f64>],
    /// Unwrapped rotor phase (azimuth of blade 0), rad.
    pub phase_rad: &'a [f64],
    /// Rotor angular speed `dψ/dt`, rad/s.
    pub omega_rad_s: &'a [f64],
    /// Flap angles per sample (length `n`), or one set for all (length 1).
    pub angles: &'a [FlapAngles],
}

impl RotorInput<'_> {
    fn len(&self) -> Result<usize> {
        let n = self.b_body_nt.len();
        if self.phase_rad.len() != n
            || self.omega_rad_s.len() != n
            || !(self.angles.len() == n || self.angles.len() == 1)
        {
            return Err(CompError::data("rotor input: series of different lengths"));
        }
        Ok(n)
    }

    fn angles_at(&self, k: usize) -> &FlapAngles {
        &self.angles[if self.angles.len() == 1 { 0 } else { k }]
    }
}

/// Rows of the regressors computed together on one core (a part's columns
/// stay near the caches).
const ROWS_PER_PART: usize = 4096;

/// Regressor columns (nT per unit of each parameter; blade-major order,
/// within a blade: hard along, soft along, eddy, then for
/// [`BladeTerms::Full`] hard lead, hard up, soft lead, soft up).
pub fn regressors(
    geom: &RotorGeometry,
    terms: BladeTerms,
    input: &RotorInput,
) -> Result<Vec<Vec<f64>>> {
    geom.validate()?;
    let n = input.len()?;
    let nb = geom.blades;
    let pb = terms.per_blade();
    // Everything in the hub frame (ω along its z axis); the identity for a
    // main rotor.
    let hub_from_body = geom.body_from_hub()?.transpose();
    let a = hub_from_body * geom.sensor_from_hub();
    let mut cols = vec![vec![0.0; n]; nb * pb];
    // Rows are independent: parts of them on the cores, each part's first
    // failure kept, the earliest of all reported (as one pass would).
    let failures = std::sync::Mutex::new(Vec::new());
    let mut outs: Vec<&mut [f64]> = cols.iter_mut().map(|c| c.as_mut_slice()).collect();
    let threads = aeromag_core::parallel::threads();
    aeromag_core::parallel::for_each_rows_mut(&mut outs, threads, ROWS_PER_PART, |start, parts| {
        for (i, k) in (start..start + parts[0].len()).enumerate() {
            let b = hub_from_body * input.b_body_nt[k] * 1e-9;
            let bn = b.norm();
            if !(bn.is_finite() && bn > 0.0) {
                let e = CompError::data(format!(
                    "rotor input: field at sample {k} is zero or not finite"
                ));
                failures.lock().expect("no panic holds it").push((k, e));
                return;
            }
            let e = b / bn;
            let w = Vector3::new(0.0, 0.0, input.omega_rad_s[k]);
            let wb = w.cross(&b);
            for j in 0..nb {
                let psi = input.phase_rad[k] + std::f64::consts::TAU * j as f64 / nb as f64;
                let r = blade_axes(psi, input.angles_at(k));
                let (rp, el, eu) = (
                    r.column(0).into_owned(),
                    r.column(1).into_owned(),
                    r.column(2).into_owned(),
                );
                let g = match dipole_integral(&a, &rp, geom.root_m, geom.tip_m) {
                    Ok(g) => g.transpose() * e * 1e9,
                    Err(_) => {
                        let e = on_blade_line(geom, j, k, psi);
                        failures.lock().expect("no panic holds it").push((k, e));
                        return;
                    }
                };
                let c = j * pb;
                parts[c][i] = g.dot(&rp);
                parts[c + 1][i] = g.dot(&rp) * rp.dot(&b) / MU0;
                parts[c + 2][i] = g.dot(&wb);
                if terms == BladeTerms::Full {
                    parts[c + 3][i] = g.dot(&el);
                    parts[c + 4][i] = g.dot(&eu);
                    parts[c + 5][i] = g.dot(&el) * el.dot(&b) / MU0;
                    parts[c + 6][i] = g.dot(&eu) * eu.dot(&b) / MU0;
                }
            }
        }
    });
    let failures = failures.into_inner().expect("no panic holds it");
    if let Some((_, e)) = failures.into_iter().min_by_key(|(k, _)| *k) {
        return Err(e);
    }
    Ok(cols)
}

/// The error of a sensor on blade `j`'s line at sample `k` (azimuth
/// `psi_rad`), where the blade model's field is infinite: it names the
/// geometry's settings (`rotor fit --sensor-m/--hub-m`, the model file's
/// `sensor_m`/`hub_m`), not the integral that failed.
fn on_blade_line(geom: &RotorGeometry, j: usize, k: usize, psi_rad: f64) -> CompError {
    use aeromag_core::error::{fixed, shown};
    let p = |v: [f64; 3]| v.map(shown).join(",");
    CompError::setting(format!(
        "rotor geometry: the sensor (sensor_m, --sensor-m {}) lies on the line of blade {} \
         through the hub (hub_m, --hub-m {}) at sample {k} (azimuth {}°), where the blade's \
         field is infinite: move the sensor off the blades' cone",
        p(geom.sensor_m),
        j + 1,
        p(geom.hub_m),
        fixed(psi_rad.to_degrees().rem_euclid(360.0), 1),
    ))
}

/// Options of the least-squares fit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RotorFitOptions {
    /// Cutoff of the 4th-order zero-phase high-pass applied to the data and
    /// the regressors, Hz (below the rotor frequency, above the manoeuvres
    /// and the anomaly). Default 2.
    pub highpass_hz: f64,
    /// Samples within this time of either end are not fitted, s. Default 2.
    pub edge_s: f64,
    /// Ridge parameter of the normal equations. Default 1e-9.
    pub ridge: f64,
}

impl Default for RotorFitOptions {
    fn default() -> Self {
        Self {
            highpass_hz: 2.0,
            edge_s: 2.0,
            ridge: 1e-9,
        }
    }
}

/// A fitted rotor model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RotorFit {
    /// The terms.
    pub terms: BladeTerms,
    /// Parameters in regressor order (units in [`regressors`]).
    pub params: Vec<f64>,
    /// RMS of the high-passed fit residual, nT.
    pub residual_rms_nt: f64,
}

/// Zero-phase high-pass of `x` (4th order Butterworth).
pub fn highpass(x: &[f64], fs_hz: f64, cutoff_hz: f64) -> Result<Vec<f64>> {
    let sos = butter(4, Band::Highpass { cutoff_hz }, fs_hz)?;
    Ok(sosfiltfilt(&sos, x)?)
}

/// Fit the parameters to `mag_nt` (the scalar reading, any slow parts
/// included) sampled at `fs_hz`.
pub fn fit(
    geom: &RotorGeometry,
    terms: BladeTerms,
    input: &RotorInput,
    mag_nt: &[f64],
    fs_hz: f64,
    opts: &RotorFitOptions,
) -> Result<RotorFit> {
    let cols = regressors(geom, terms, input)?;
    fit_columns(&cols, terms, mag_nt, fs_hz, opts)
}

/// Fit given precomputed regressor columns.
pub fn fit_columns(
    cols: &[Vec<f64>],
    terms: BladeTerms,
    mag_nt: &[f64],
    fs_hz: f64,
    opts: &RotorFitOptions,
) -> Result<RotorFit> {
    fit_records(&[(cols, mag_nt)], terms, fs_hz, opts)
}

/// Fit one set of parameters to several records (stretches of a flight
/// between gaps), each given as its regressor columns and reading: every
/// record is high-passed on its own and loses `edge_s` at both ends, and
/// the normal equations of all records are summed. The residual is the RMS
/// over all the rows used.
pub fn fit_records(
    records: &[(&[Vec<f64>], &[f64])],
    terms: BladeTerms,
    fs_hz: f64,
    opts: &RotorFitOptions,
) -> Result<RotorFit> {
    let p = records.first().map_or(0, |r| r.0.len());
    if p == 0 {
        return Err(CompError::data("rotor fit: no regressors"));
    }
    let edge = (opts.edge_s * fs_hz).round() as usize;
    let mut ne = NormalEquations::new(p);
    for (cols, mag_nt) in records {
        let n = mag_nt.len();
        if cols.len() != p || cols.iter().any(|c| c.len() != n) {
            return Err(CompError::data(
                "rotor fit: regressors and data differ in length",
            ));
        }
        if n <= 2 * edge + 10 * p {
            if records.len() == 1 {
                return Err(CompError::data("rotor fit: too few samples"));
            }
            continue;
        }
        let hp: Vec<Vec<f64>> = cols
            .iter()
            .map(|c| highpass(c, fs_hz, opts.highpass_hz))
            .collect::<Result<_>>()?;
        let y = highpass(mag_nt, fs_hz, opts.highpass_hz)?;
        let slices: Vec<&[f64]> = hp.iter().map(|c| &c[edge..n - edge]).collect();
        ne.add_columns(&slices, &y[edge..n - edge])
            .map_err(CompError::estimation("rotor fit"))?;
    }
    if ne.rows() == 0 {
        return Err(CompError::data("rotor fit: too few samples"));
    }
    let sol = ne
        .solve(opts.ridge)
        .map_err(CompError::estimation("rotor fit failed"))?;
    Ok(RotorFit {
        terms,
        params: sol.coef.iter().copied().collect(),
        residual_rms_nt: (sol.rss.max(0.0) / ne.rows() as f64).sqrt(),
    })
}

impl RotorFit {
    /// The rotor interference `Σ params · regressors`, nT.
    pub fn predict(&self, geom: &RotorGeometry, input: &RotorInput) -> Result<Vec<f64>> {
        let cols = regressors(geom, self.terms, input)?;
        self.predict_columns(&cols)
    }

    /// Prediction from precomputed columns.
    pub fn predict_columns(&self, cols: &[Vec<f64>]) -> Result<Vec<f64>> {
        if cols.len() != self.params.len() {
            return Err(CompError::data("rotor model: wrong number of regressors"));
        }
        let n = cols.first().map_or(0, |c| c.len());
        Ok((0..n)
            .map(|k| cols.iter().zip(&self.params).map(|(c, p)| c[k] * p).sum())
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sensor on a blade's line (here in the rotor plane, no coning, at
    /// the azimuth of blade 1 at the first sample) was "dipole integral:
    /// the sensor lies on the blade's line", naming no setting.
    #[test]
    fn a_sensor_on_a_blades_line_names_the_geometry() {
        let geom = RotorGeometry::main_rotor([0.0, 0.0, -2.6], [5.0, 0.0, -2.6], 0.8, 7.5, 4);
        let b = [Vector3::new(20_000.0, 0.0, 45_000.0); 3];
        let flat = [FlapAngles {
            coning_rad: 0.0,
            tilt_lon_rad: 0.0,
            tilt_lat_rad: 0.0,
        }];
        let input = RotorInput {
            b_body_nt: &b,
            phase_rad: &[0.0, 0.1, 0.2],
            omega_rad_s: &[40.0; 3],
            angles: &flat,
        };
        let e = regressors(&geom, BladeTerms::Simplified, &input).unwrap_err();
        let msg = e.to_string();
        assert!(e.is_bad_input(), "{msg}");
        for part in [
            "sensor_m, --sensor-m 5,0,-2.6",
            "hub_m, --hub-m 0,0,-2.6",
            "blade 1 through the hub",
            "at sample 0 (azimuth 0.0°)",
        ] {
            assert!(msg.contains(part), "{part}: {msg}");
        }
        // Off the plane, the same geometry is fine.
        let mut off = geom.clone();
        off.sensor_m[2] = -2.0;
        assert!(regressors(&off, BladeTerms::Simplified, &input).is_ok());
    }

    /// The rows are computed in parts on the cores: the same columns as
    /// row by row, and of two bad samples in different parts the earlier
    /// is named, as one pass names it.
    #[test]
    fn rows_in_parts_give_the_columns_and_the_first_failure_of_one_pass() {
        let geom = RotorGeometry::main_rotor([0.0, 0.0, -2.6], [5.0, 0.0, -2.0], 0.8, 7.5, 4);
        let n = 3 * ROWS_PER_PART + 17;
        let mut b: Vec<Vector3<f64>> = (0..n)
            .map(|k| Vector3::new(20_000.0 + k as f64, -3_000.0, 45_000.0))
            .collect();
        let phase: Vec<f64> = (0..n).map(|k| 0.3 * k as f64).collect();
        let nominal = [FlapAngles {
            coning_rad: 0.05,
            tilt_lon_rad: 0.01,
            tilt_lat_rad: -0.02,
        }];
        let input = |b: &[Vector3<f64>]| -> Result<Vec<Vec<f64>>> {
            let inp = RotorInput {
                b_body_nt: b,
                phase_rad: &phase,
                omega_rad_s: &vec![30.0; n],
                angles: &nominal,
            };
            regressors(&geom, BladeTerms::Full, &inp)
        };
        let all = input(&b).unwrap();
        for k in [0, ROWS_PER_PART + 3, n - 1] {
            let one = RotorInput {
                b_body_nt: &b[k..=k],
                phase_rad: &phase[k..=k],
                omega_rad_s: &[30.0],
                angles: &nominal,
            };
            let row = regressors(&geom, BladeTerms::Full, &one).unwrap();
            for (c, r) in all.iter().zip(&row) {
                assert_eq!(c[k].to_bits(), r[0].to_bits(), "row {k}");
            }
        }
        b[n - 5] = Vector3::zeros();
        b[ROWS_PER_PART + 1] = Vector3::new(f64::NAN, 0.0, 0.0);
        let e = input(&b).unwrap_err().to_string();
        assert!(
            e.contains(&format!("field at sample {} is zero", ROWS_PER_PART + 1)),
            "{e}"
        );
    }
}
