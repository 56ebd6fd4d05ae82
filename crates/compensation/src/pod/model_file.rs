//! The pod model file (`aeromag-model/1`, kind `towed-pod`): what `aeromag
//! pod fit` writes and `pod apply` reads, so that library callers can read
//! and write the same files.

use crate::error::{CompError, Result};
/// A body-frame point (m) with a coordinate that is NaN or beyond
/// ±[`MAX_SOURCE_M`]: the attachment and reference points' check.
fn beyond_reach(p: &[f64; 3]) -> bool {
    p.iter().any(|x| x.is_nan() || x.abs() > MAX_SOURCE_M)
}

#[cfg(test)]
use crate::model_file::MODEL_FORMAT;
use crate::model_file::parse_model;
use crate::pod::dipole_array::{MAX_SOURCE_M, PER_SOURCE, check_source_points};
use crate::pod::model::{N_JOINT, N_PARAMS};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::str::FromStr;

/// `kind` of a pod model file.
pub const POD_KIND: &str = "towed-pod";

/// The solve of `aeromag pod fit`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum PodMethod {
    /// The seed's two-step solve (heading coefficients, then parameters).
    TwoStep,
    /// One least-squares fit of the large-signal model (43 + 24 eddy
    /// gradient parameters) over all samples.
    Joint,
    /// Equivalent dipole array, exact field at the pod (the default: the
    /// solve that reaches ≥ 97 % on every heading).
    #[default]
    DipoleArray,
}

impl std::fmt::Display for PodMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl PodMethod {
    /// Every method, in report order.
    pub const ALL: [PodMethod; 3] = [Self::TwoStep, Self::Joint, Self::DipoleArray];

    /// Name on the command line and in the model file.
    pub fn name(self) -> &'static str {
        match self {
            Self::TwoStep => "two-step",
            Self::Joint => "joint",
            Self::DipoleArray => "dipole-array",
        }
    }
}

impl FromStr for PodMethod {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| format!("`{s}`: use two-step, joint or dipole-array"))
    }
}

/// Installation and field parameters shared by fit and apply.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PodSetup {
    /// Cable length, m.
    pub cable_length_m: f64,
    /// Attachment point, body axes, m.
    pub attach_m: [f64; 3],
    /// Field inclination, deg.
    pub inclination_deg: f64,
    /// Field declination from the yaw reference, deg.
    pub declination_deg: f64,
    /// North gradient `k_x`, nT/km.
    pub grad_north_nt_per_km: f64,
    /// Upward gradient `k_h`, nT/km.
    pub grad_up_nt_per_km: f64,
}

/// Compensation rate of one heading (fraction).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct HeadingRate {
    /// Mean heading (circular mean of yaw), deg in [0, 360).
    pub heading_deg: f64,
    /// First and one-past-last data row (0-based).
    pub rows: [usize; 2],
    /// `1 − RMS(after)/RMS(before)`, high-passed.
    pub rate: f64,
}

/// The pod model file (versioned JSON).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PodModelFile {
    /// Always [`crate::model_file::MODEL_FORMAT`].
    pub format: String,
    /// Always [`POD_KIND`].
    pub kind: String,
    /// The solve.
    pub method: PodMethod,
    /// Pod trajectory: `seed-eq7-8` (two-step) or `exact`.
    pub trajectory: String,
    /// Installation and field.
    pub setup: PodSetup,
    /// Coefficient names (model parameters `θ`, or per source point
    /// permanent `m`, induced `X` and eddy `E` moments).
    pub coefficient_names: Vec<String>,
    /// Coefficients: nT per direction cosine (and per m, per 1/s) for `θ`,
    /// A·m² per direction cosine (and per 1/s) for the dipole array.
    pub coefficients: Vec<f64>,
    /// Equivalent source points (dipole array only), body axes, m.
    pub sources_m: Vec<[f64; 3]>,
    /// Reference pod position of the joint solve's expansion, body axes, m
    /// (zeros for the other methods).
    pub reference_m: [f64; 3],
    /// Step 1 of the two-step solve: `W1..W7` per learning heading.
    pub heading_coefficients: Vec<[f64; 7]>,
    /// Compensation rate per learning heading.
    pub learning: Vec<HeadingRate>,
    /// Sample rate, Hz.
    pub sample_rate_hz: f64,
    /// Input columns used (canonical name → file column name).
    pub columns: BTreeMap<String, String>,
    /// Version of aeromag that wrote the file.
    pub software_version: String,
}

/// Largest regional field gradient of a pod setup, nT/km (Earth's main
/// field varies by some nT/km; 10 nT/m is far beyond).
pub const MAX_GRADIENT_NT_PER_KM: f64 = 10_000.0;

impl PodSetup {
    /// Check the values: a positive cable length of at most
    /// [`MAX_SOURCE_M`] m, an attachment point within [`MAX_SOURCE_M`] of
    /// the body frame's origin, an inclination in (−90°, 90°), a
    /// declination within ±180° and gradients within
    /// ±[`MAX_GRADIENT_NT_PER_KM`].
    pub fn validate(&self) -> Result<()> {
        use aeromag_core::error::shown;
        let bad = |m: String| Err(CompError::setting(m));
        // The bound of the dipole array's source points, for the same
        // reason: body-frame distances in metres (a cable of 2⁶³ m was
        // fitted to a model of noise with exit 0; 1e308 m made the design
        // NaN).
        if !(self.cable_length_m > 0.0 && self.cable_length_m <= MAX_SOURCE_M) {
            return bad(format!(
                "cable length {} m must be positive and at most {MAX_SOURCE_M} m",
                shown(self.cable_length_m)
            ));
        }
        if beyond_reach(&self.attach_m) {
            return bad(format!(
                "attachment point ({}) m must be within ±{MAX_SOURCE_M} m of the body frame's origin",
                self.attach_m.map(shown).join(", ")
            ));
        }
        if !(self.inclination_deg.is_finite() && self.inclination_deg.abs() < 90.0) {
            return bad(format!(
                "inclination {}° must be in (−90, 90)",
                shown(self.inclination_deg)
            ));
        }
        if self.declination_deg.is_nan() || self.declination_deg.abs() > 180.0 {
            return bad(format!(
                "declination {}° must be within ±180°",
                aeromag_core::error::shown(self.declination_deg)
            ));
        }
        // A regional gradient: Earth's is some nT/km (1e300 gave a
        // compensation rate of −∞ %).
        for (name, g) in [
            ("north", self.grad_north_nt_per_km),
            ("upward", self.grad_up_nt_per_km),
        ] {
            if g.is_nan() || g.abs() > MAX_GRADIENT_NT_PER_KM {
                return bad(format!(
                    "{name} gradient {} nT/km must be within ±{MAX_GRADIENT_NT_PER_KM} nT/km",
                    aeromag_core::error::shown(g)
                ));
            }
        }
        Ok(())
    }
}

impl PodModelFile {
    /// Read a model file's text (`origin` names it in errors): header,
    /// fields and [`Self::validate`].
    pub fn from_json(text: &str, origin: &str) -> Result<Self> {
        let m: Self = parse_model(text, origin, POD_KIND, "aeromag pod fit")?;
        m.validate()
            .map_err(|e| CompError::model_file(origin, e.to_string()))?;
        Ok(m)
    }

    /// Check the content: as many finite coefficients as names, as many as
    /// the method has (43 for `two-step`, 67 for `joint`, 21 per source
    /// point for `dipole-array`, whose points [`check_source_points`]
    /// checks), a reference position within [`MAX_SOURCE_M`], and the
    /// setup.
    pub fn validate(&self) -> Result<()> {
        if self.coefficients.len() != self.coefficient_names.len()
            || self.coefficients.iter().any(|c| !c.is_finite())
        {
            return Err(CompError::data(
                "coefficients and names differ in number or are not finite",
            ));
        }
        let expect = match self.method {
            PodMethod::TwoStep => N_PARAMS,
            PodMethod::Joint => N_JOINT,
            PodMethod::DipoleArray => {
                check_source_points(&self.sources_m)?;
                self.sources_m.len() * PER_SOURCE
            }
        };
        if self.coefficients.len() != expect {
            return Err(CompError::data(format!(
                "a `{}` model has {expect} coefficients, the file {}",
                self.method,
                self.coefficients.len()
            )));
        }
        if beyond_reach(&self.reference_m) {
            return Err(CompError::data(format!(
                "reference position ({}) m must be within ±{MAX_SOURCE_M} m of the body frame's origin",
                self.reference_m.map(aeromag_core::error::shown).join(", ")
            )));
        }
        self.setup.validate()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn methods_parse_by_name_and_models_are_checked() {
        for m in PodMethod::ALL {
            assert_eq!(m.name().parse::<PodMethod>().unwrap(), m);
            assert_eq!(
                serde_json::to_string(&m).unwrap(),
                format!("\"{}\"", m.name())
            );
        }
        assert!("three-step".parse::<PodMethod>().is_err());
        let setup = PodSetup {
            cable_length_m: 40.0,
            attach_m: [0.0, 0.0, 1.2],
            inclination_deg: 45.0,
            declination_deg: 0.0,
            grad_north_nt_per_km: 5.91,
            grad_up_nt_per_km: -25.91,
        };
        let m = PodModelFile {
            format: MODEL_FORMAT.into(),
            kind: POD_KIND.into(),
            method: PodMethod::Joint,
            trajectory: "exact".into(),
            setup,
            coefficient_names: (0..N_JOINT).map(|k| format!("c{k}")).collect(),
            coefficients: (0..N_JOINT).map(|k| k as f64).collect(),
            sources_m: vec![],
            reference_m: [0.0; 3],
            heading_coefficients: vec![],
            learning: vec![],
            sample_rate_hz: 20.0,
            columns: BTreeMap::new(),
            software_version: "test".into(),
        };
        m.validate().unwrap();
        // A declination beyond ±180° or a gradient beyond 10 nT/m (1e300
        // gave a compensation rate of −∞ %) is refused.
        for edit in [
            |s: &mut PodSetup| s.declination_deg = 1e300,
            |s: &mut PodSetup| s.grad_north_nt_per_km = 1e300,
            |s: &mut PodSetup| s.grad_up_nt_per_km = -2e4,
        ] {
            let mut s = setup;
            edit(&mut s);
            assert!(s.validate().unwrap_err().is_bad_input());
        }
        assert_eq!(
            PodModelFile::from_json(&serde_json::to_string(&m).unwrap(), "p.json").unwrap(),
            m
        );
        let back: PodModelFile = serde_json::from_str(&serde_json::to_string(&m).unwrap()).unwrap();
        assert_eq!(back, m);
        let mut bad = m.clone();
        bad.coefficients.push(3.0);
        assert!(bad.validate().is_err());
        // As many coefficients as names, but not as many as the method has.
        let mut bad = m.clone();
        bad.coefficients.pop();
        bad.coefficient_names.pop();
        assert!(
            bad.validate()
                .unwrap_err()
                .to_string()
                .contains("67 coefficients")
        );
        // Body-frame distances beyond 1 km (1e308 m gave NaN rates printed
        // with exit 0, 2⁶³ m a model of noise) and a reference position
        // that is not a position; numbers shown in exponent form.
        for edit in [
            |m: &mut PodModelFile| m.setup.cable_length_m = 1e308,
            |m: &mut PodModelFile| m.setup.cable_length_m = 9.3e18,
            |m: &mut PodModelFile| m.setup.attach_m[0] = 1e308,
            |m: &mut PodModelFile| m.setup.attach_m[2] = -2e3,
            |m: &mut PodModelFile| m.reference_m[1] = 1e300,
            |m: &mut PodModelFile| m.setup.inclination_deg = 1e308,
        ] {
            let mut bad = m.clone();
            edit(&mut bad);
            let e = bad.validate().unwrap_err();
            assert!(e.is_bad_input(), "{e}");
            assert!(e.to_string().len() < 200, "{e}");
        }
        // A dipole array: 21 coefficients per source point, the points
        // within 1 km.
        let mut arr = m.clone();
        arr.method = PodMethod::DipoleArray;
        arr.sources_m = vec![[-6.0, 0.0, -1.0], [2.0, 0.0, -1.0]];
        arr.coefficients = vec![0.5; 2 * PER_SOURCE];
        arr.coefficient_names = (0..2 * PER_SOURCE).map(|k| format!("c{k}")).collect();
        arr.validate().unwrap();
        let mut far = arr.clone();
        far.sources_m[1][0] = 1e308;
        assert!(far.validate().unwrap_err().is_bad_input());
        let mut none = arr;
        none.sources_m.clear();
        assert!(none.validate().is_err());
        let mut bad = m;
        bad.setup.cable_length_m = -1.0;
        assert!(
            bad.validate()
                .unwrap_err()
                .to_string()
                .contains("cable length")
        );
    }
}
