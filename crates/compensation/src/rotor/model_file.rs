//! The rotor model file (`aeromag-model/1`, kind `helicopter-rotor`): what
//! `aeromag rotor fit` writes and `rotor apply` reads, so that library
//! callers can read and write the same files.

use super::blade::{FlapAngles, MAX_FLAP_RAD, RotorGeometry};
use super::coning::SlowAngleOptions;
use super::linear::{RotorFit, RotorFitOptions};
use super::tail::TailRotor;
use crate::error::{CompError, Result};
#[cfg(test)]
use crate::model_file::MODEL_FORMAT;
use crate::model_file::parse_model;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// `kind` of a rotor model file.
pub const ROTOR_KIND: &str = "helicopter-rotor";

/// Where the rotor phase comes from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PhaseSource {
    /// Phase channel (canonical name in the fitted file), or `null` when
    /// the phase is estimated from the scalar data.
    pub column: Option<String>,
    /// Search band of the rotor frequency for the estimate, Hz.
    pub rotor_hz_range: [f64; 2],
}

/// A tail rotor in a model file: its geometry and gear, the phase offset
/// found on the fitted record and its parameters (fitted jointly with the
/// main rotor's; [`super::tail`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TailModel {
    /// Geometry, gear ratio and cone.
    pub rotor: TailRotor,
    /// Phase offset `φ_0` of `ψ_t = k ψ + φ_0`, rad (fixed by the gearbox
    /// for a given phase channel).
    pub offset_rad: f64,
    /// Its parameters.
    pub model: RotorFit,
}

/// Most slowly-varying-angle alternations a model file may ask for
/// (default 3; each refits every window of the flight: 2⁶³ kept
/// `rotor apply` running for ever).
pub const MAX_SLOW_ITERATIONS: usize = 100;

/// The rotor model file (versioned JSON).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RotorModelFile {
    /// Always [`crate::model_file::MODEL_FORMAT`].
    pub format: String,
    /// Always [`ROTOR_KIND`].
    pub kind: String,
    /// Rotor and sensor geometry.
    pub geometry: RotorGeometry,
    /// The tail rotor, when modelled (absent in files without one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tail: Option<TailModel>,
    /// Nominal cone angles (start of the slowly varying estimate), rad.
    pub nominal_angles: FlapAngles,
    /// Blade terms, parameters (regressor order of
    /// `aeromag_compensation::rotor::regressors`) and the RMS of the
    /// high-passed fit residual (nT).
    pub model: RotorFit,
    /// High-pass and edge options of the fit.
    pub fit_options: RotorFitOptions,
    /// Options of the slowly varying angles (of the final fit, and of the
    /// tracking on new data, where a phase estimated from the data is also
    /// corrected slowly).
    pub slow_angles: SlowAngleOptions,
    /// Phase channel or estimate.
    pub phase: PhaseSource,
    /// Sample rate of the fitted record, Hz.
    pub sample_rate_hz: f64,
    /// Mean rotor frequency of the fitted record, Hz.
    pub rotor_hz: f64,
    /// Mean estimated coning of the fitted record, deg.
    pub coning_mean_deg: f64,
    /// Rows fitted.
    pub rows: usize,
    /// Input columns used (canonical name → file column name).
    pub columns: BTreeMap<String, String>,
    /// Version of aeromag that wrote the file.
    pub software_version: String,
}

impl RotorModelFile {
    /// Read a model file's text (`origin` names it in errors): header,
    /// fields and [`Self::validate`].
    pub fn from_json(text: &str, origin: &str) -> Result<Self> {
        let m: Self = parse_model(text, origin, ROTOR_KIND, "aeromag rotor fit")?;
        m.validate()
            .map_err(|e| CompError::model_file(origin, e.to_string()))?;
        Ok(m)
    }

    /// Check the content: geometry, `blades × per-blade` finite
    /// parameters, and the options `rotor apply` runs with (finite, in
    /// range; at most [`MAX_SLOW_ITERATIONS`] alternations).
    pub fn validate(&self) -> Result<()> {
        self.geometry.validate()?;
        let shown = aeromag_core::error::shown;
        let (so, fo) = (&self.slow_angles, &self.fit_options);
        if !(1..=MAX_SLOW_ITERATIONS).contains(&so.iterations) {
            return Err(CompError::data(format!(
                "slow_angles.iterations = {} must be 1 to {MAX_SLOW_ITERATIONS}",
                so.iterations
            )));
        }
        let a = &self.nominal_angles;
        let [lo, hi] = self.phase.rotor_hz_range;
        for (name, v, ok) in [
            ("slow_angles.window_s", so.window_s, so.window_s > 0.0),
            (
                "fit_options.highpass_hz",
                fo.highpass_hz,
                fo.highpass_hz > 0.0,
            ),
            ("fit_options.edge_s", fo.edge_s, fo.edge_s >= 0.0),
            ("fit_options.ridge", fo.ridge, fo.ridge >= 0.0),
            ("phase.rotor_hz_range", lo, lo > 0.0 && hi > lo),
            ("phase.rotor_hz_range", hi, hi > lo),
            (
                "sample_rate_hz",
                self.sample_rate_hz,
                self.sample_rate_hz > 0.0,
            ),
            // An edited coning of 100 rad was applied: 281 331 nT of
            // "interference" with exit 0.
            (
                "nominal_angles.coning_rad",
                a.coning_rad,
                a.coning_rad.abs() <= MAX_FLAP_RAD,
            ),
            (
                "nominal_angles.tilt_lon_rad",
                a.tilt_lon_rad,
                a.tilt_lon_rad.abs() <= MAX_FLAP_RAD,
            ),
            (
                "nominal_angles.tilt_lat_rad",
                a.tilt_lat_rad,
                a.tilt_lat_rad.abs() <= MAX_FLAP_RAD,
            ),
        ] {
            if !(ok && v.is_finite()) {
                return Err(CompError::data(format!(
                    "{name} = {} is not a finite value in range",
                    shown(v)
                )));
            }
        }
        let expect = self.geometry.blades * self.model.terms.per_blade();
        if self.model.params.len() != expect || self.model.params.iter().any(|p| !p.is_finite()) {
            return Err(CompError::data(format!(
                "expected {expect} finite rotor parameters, got {}",
                self.model.params.len()
            )));
        }
        if let Some(t) = &self.tail {
            t.rotor.validate()?;
            let expect = t.rotor.geometry.blades * t.model.terms.per_blade();
            if t.model.params.len() != expect
                || t.model.params.iter().any(|p| !p.is_finite())
                || !t.offset_rad.is_finite()
            {
                return Err(CompError::data(format!(
                    "expected {expect} finite tail rotor parameters and a finite offset, got {}",
                    t.model.params.len()
                )));
            }
            if self.phase.column.is_none() {
                return Err(CompError::data(
                    "a tail rotor is modelled with a phase channel only",
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotor::linear::BladeTerms;
    use crate::rotor::study::{nominal_angles, scenario_geometry};

    fn model() -> RotorModelFile {
        let geometry = scenario_geometry();
        let n = geometry.blades * BladeTerms::Full.per_blade();
        RotorModelFile {
            format: MODEL_FORMAT.into(),
            kind: ROTOR_KIND.into(),
            geometry,
            tail: None,
            nominal_angles: nominal_angles(),
            model: RotorFit {
                terms: BladeTerms::Full,
                params: vec![0.5; n],
                residual_rms_nt: 0.1,
            },
            fit_options: RotorFitOptions::default(),
            slow_angles: SlowAngleOptions::default(),
            phase: PhaseSource {
                column: None,
                rotor_hz_range: [4.0, 6.0],
            },
            sample_rate_hz: 100.0,
            rotor_hz: 4.8,
            coning_mean_deg: 4.0,
            rows: 1000,
            columns: BTreeMap::new(),
            software_version: "test".into(),
        }
    }

    #[test]
    fn round_trips_and_rejects_what_is_not_a_rotor_model() {
        let m = model();
        m.validate().unwrap();
        let back: RotorModelFile =
            serde_json::from_str(&serde_json::to_string(&m).unwrap()).unwrap();
        assert_eq!(back, m);
        let mut wrong = m.clone();
        wrong.kind = "towed-pod".into();
        let e = RotorModelFile::from_json(&serde_json::to_string(&wrong).unwrap(), "x.json")
            .unwrap_err();
        assert!(e.to_string().contains("towed-pod"), "{e}");
        assert_eq!(
            RotorModelFile::from_json(&serde_json::to_string(&m).unwrap(), "x.json").unwrap(),
            m
        );
        let mut short = m.clone();
        short.model.params.pop();
        assert!(
            short
                .validate()
                .unwrap_err()
                .to_string()
                .contains("finite rotor parameters")
        );
        let mut nan = m.clone();
        nan.model.params[0] = f64::NAN;
        assert!(nan.validate().is_err());
        // The options apply runs with: 2⁶³ alternations kept `rotor
        // apply` running for ever; the others were not checked either.
        type Edit = fn(&mut RotorModelFile);
        let edits: [(&str, Edit); 8] = [
            ("slow_angles.iterations", |m| {
                m.slow_angles.iterations = 1 << 63
            }),
            ("slow_angles.iterations", |m| m.slow_angles.iterations = 0),
            ("slow_angles.window_s", |m| m.slow_angles.window_s = -1.0),
            ("fit_options.highpass_hz", |m| {
                m.fit_options.highpass_hz = f64::INFINITY
            }),
            ("phase.rotor_hz_range", |m| {
                m.phase.rotor_hz_range = [6.0, 4.0]
            }),
            ("nominal_angles.coning_rad", |m| {
                m.nominal_angles.coning_rad = f64::NAN
            }),
            // Applied before: 281 331 nT of interference.
            ("nominal_angles.coning_rad", |m| {
                m.nominal_angles.coning_rad = 100.0
            }),
            ("nominal_angles.tilt_lat_rad", |m| {
                m.nominal_angles.tilt_lat_rad = -0.6
            }),
        ];
        for (name, edit) in edits {
            let mut bad = m.clone();
            edit(&mut bad);
            let e = bad.validate().unwrap_err().to_string();
            assert!(e.contains(name), "{name}: {e}");
        }
        // With a tail rotor: round trip, its parameter count, and it needs
        // a phase channel.
        let mut tail = m;
        let rotor = crate::rotor::study::scenario_tail_rotor([5.0, 0.0, 0.6]);
        tail.tail = Some(TailModel {
            model: RotorFit {
                params: vec![0.1; rotor.geometry.blades * 7],
                ..tail.model.clone()
            },
            rotor,
            offset_rad: 0.6,
        });
        tail.phase.column = Some("rotor_phase".into());
        tail.validate().unwrap();
        let text = serde_json::to_string(&tail).unwrap();
        assert_eq!(RotorModelFile::from_json(&text, "t.json").unwrap(), tail);
        let mut no_channel = tail.clone();
        no_channel.phase.column = None;
        assert!(no_channel.validate().is_err());
        let mut short = tail;
        short.tail.as_mut().unwrap().model.params.pop();
        assert!(short.validate().is_err());
    }
}
