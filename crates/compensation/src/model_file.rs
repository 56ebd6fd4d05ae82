//! The compensation model file (`spec/data-formats.md`, "Model files").
//!
//! JSON, versioned by `"format": "aeromag-model/1"`. It records everything
//! needed to rebuild the design matrix on new data (terms, derivative
//! convention, `bt_scale`), how the model was fitted (method, band, trim, λ),
//! the coefficients with names and standard deviations, fit statistics, the
//! input columns used, and the software version.

use crate::error::{CompError, Result};
use crate::tolles_lawson::{Convention, TermSet};
use serde::{Deserialize, Serialize};

/// The format tag of this version of the model file.
pub const MODEL_FORMAT: &str = "aeromag-model/1";

/// `kind` of a Tolles-Lawson model (both fitting methods).
pub const TL_KIND: &str = "tolles-lawson";

/// Parse a model file and check its `format` ([`MODEL_FORMAT`]) and `kind`
/// (`writer` names the command that writes that kind, for the message).
/// Every model file of aeromag (Tolles-Lawson, rotor, pod) goes through here.
pub fn parse_model_json(
    text: &str,
    origin: &str,
    kind: &str,
    writer: &str,
) -> Result<serde_json::Value> {
    let v: serde_json::Value = serde_json::from_str(text)
        .map_err(|e| CompError::BadData(format!("{origin}: not a JSON model file ({e})")))?;
    match v.get("format").and_then(|f| f.as_str()) {
        Some(MODEL_FORMAT) => {}
        Some(other) => {
            return Err(CompError::BadData(format!(
                "{origin}: model format `{other}` is not supported (expected `{MODEL_FORMAT}`)"
            )));
        }
        None => {
            return Err(CompError::BadData(format!(
                "{origin}: no \"format\" key; not an aeromag model file"
            )));
        }
    }
    match v.get("kind").and_then(|k| k.as_str()) {
        Some(k) if k == kind => Ok(v),
        found => Err(CompError::BadData(format!(
            "{origin}: model kind `{}` is not a `{kind}` model (written by `{writer}`)",
            found.unwrap_or("missing")
        ))),
    }
}

/// A model file of `kind` parsed into `T` after the header check of
/// [`parse_model_json`]; errors name `origin`.
pub fn parse_model<T: serde::de::DeserializeOwned>(
    text: &str,
    origin: &str,
    kind: &str,
    writer: &str,
) -> Result<T> {
    let v = parse_model_json(text, origin, kind, writer)?;
    serde_json::from_value(v)
        .map_err(|e| CompError::BadData(format!("{origin}: invalid `{kind}` model: {e}")))
}

/// One named coefficient.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Coefficient {
    /// Column name, e.g. `p_x`, `i_xy`, `e_zy`.
    pub name: String,
    /// Value.
    pub value: f64,
    /// Standard deviation (NaN when unknown).
    pub std: f64,
}

/// Fit statistics recorded in the model file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct FitStats {
    /// Rows used by the fit.
    pub rows: usize,
    /// Segments used.
    pub segments: usize,
    /// Scaled condition number (∞ for a singular fit: written as JSON `null`,
    /// which JSON numbers cannot express, and read back as ∞).
    #[serde(deserialize_with = "null_as_infinity")]
    pub condition: f64,
    /// RMS fit residual (filtered for `ls`), nT.
    pub residual_rms_nt: f64,
    /// Warnings raised while fitting.
    pub warnings: Vec<String>,
    /// How `--eddy-lag auto` chose the lags: every candidate with its
    /// likelihood-ratio statistic and threshold (absent otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub eddy_lag_selection: Option<crate::tolles_lawson::lag_select::LagSelection>,
}

/// JSON has no ∞: `serde_json` writes it as `null`; read `null` back as ∞.
fn null_as_infinity<'de, D: serde::Deserializer<'de>>(d: D) -> std::result::Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::INFINITY))
}

/// A Tolles-Lawson compensation model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TlModel {
    /// Always [`MODEL_FORMAT`].
    pub format: String,
    /// Model kind, `"tolles-lawson"`.
    pub kind: String,
    /// Fitting method: `"ls"` or `"kalman"`.
    pub method: String,
    /// Term groups.
    pub terms: TermSet,
    /// Derivative convention.
    pub convention: Convention,
    /// Scale of the induced and eddy columns, nT.
    pub bt_scale_nt: f64,
    /// Pass band used by the fit, Hz (`null` when unfiltered).
    pub band_hz: Option<(f64, f64)>,
    /// Filter order.
    pub filter_order: usize,
    /// Samples trimmed per segment end.
    pub trim: usize,
    /// Ridge parameter.
    pub lambda: f64,
    /// Coefficients in column order.
    pub coefficients: Vec<Coefficient>,
    /// Fit statistics.
    pub fit: FitStats,
    /// Known external-field channels subtracted from `mag` before the fit
    /// (e.g. `diurnal`, `igrf`); empty when the raw reading was fitted.
    #[serde(default)]
    pub reference: Vec<String>,
    /// Lever arm of the scalar sensor from the navigation point: when set,
    /// the `igrf` reference channel is moved to the sensor
    /// ([`crate::reference_field`]) before the fit and before scoring.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lever_arm: Option<crate::reference_field::LeverArm>,
    /// Input columns used (canonical name → file column name).
    pub columns: std::collections::BTreeMap<String, String>,
    /// Version of aeromag that wrote the file.
    pub software_version: String,
}

impl TlModel {
    /// Coefficient values in column order.
    pub fn coef(&self) -> Vec<f64> {
        self.coefficients.iter().map(|c| c.value).collect()
    }

    /// Serialize to pretty JSON.
    pub fn to_json(&self) -> Result<String> {
        serde_json::to_string_pretty(self)
            .map_err(|e| CompError::BadData(format!("cannot serialise model: {e}")))
    }

    /// Parse and check a model file's text; `origin` names the file in errors.
    pub fn from_json(text: &str, origin: &str) -> Result<Self> {
        let v = parse_model_json(text, origin, TL_KIND, "aeromag calibrate")?;
        let m: TlModel = serde_json::from_value(v)
            .map_err(|e| CompError::BadData(format!("{origin}: invalid model file: {e}")))?;
        m.terms
            .validate()
            .map_err(|e| CompError::BadData(format!("{origin}: {e}")))?;
        let expect = m.terms.column_names();
        let got: Vec<&str> = m.coefficients.iter().map(|c| c.name.as_str()).collect();
        if expect.iter().map(|s| s.as_str()).ne(got.iter().copied()) {
            return Err(CompError::BadData(format!(
                "{origin}: coefficient names {got:?} do not match terms `{}` ({expect:?})",
                m.terms
            )));
        }
        if m.coefficients.iter().any(|c| !c.value.is_finite()) {
            return Err(CompError::BadData(format!(
                "{origin}: a coefficient is not finite"
            )));
        }
        Ok(m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> TlModel {
        let terms = TermSet::parse("p3,bias").unwrap();
        TlModel {
            format: MODEL_FORMAT.into(),
            kind: "tolles-lawson".into(),
            method: "ls".into(),
            coefficients: terms
                .column_names()
                .into_iter()
                .enumerate()
                .map(|(k, name)| Coefficient {
                    name,
                    value: k as f64 + 0.5,
                    std: 0.1,
                })
                .collect(),
            terms,
            convention: Convention::Physical,
            bt_scale_nt: 50_000.0,
            band_hz: Some((0.1, 0.9)),
            filter_order: 4,
            trim: 20,
            lambda: 0.0,
            fit: FitStats::default(),
            columns: Default::default(),
            reference: vec![],
            lever_arm: None,
            software_version: "test".into(),
        }
    }

    #[test]
    fn format_and_kind_are_checked() {
        let rotor = r#"{"format":"aeromag-model/1","kind":"helicopter-rotor"}"#;
        let e = TlModel::from_json(rotor, "r.json").unwrap_err().to_string();
        assert!(
            e.contains("r.json")
                && e.contains("helicopter-rotor")
                && e.contains("aeromag calibrate"),
            "{e}"
        );
        assert!(parse_model_json(rotor, "r.json", "helicopter-rotor", "aeromag rotor fit").is_ok());
        let e = parse_model_json(r#"{"format":"aeromag-model/9","kind":"x"}"#, "m", "x", "w")
            .unwrap_err()
            .to_string();
        assert!(e.contains("aeromag-model/9"), "{e}");
        assert!(parse_model_json(r#"{"kind":"x"}"#, "m", "x", "w").is_err());
        assert!(parse_model_json("not json", "m", "x", "w").is_err());
        let e = parse_model_json(r#"{"format":"aeromag-model/1"}"#, "m", "x", "w")
            .unwrap_err()
            .to_string();
        assert!(e.contains("missing"), "{e}");
    }

    #[test]
    fn round_trip() {
        let m = sample();
        let back = TlModel::from_json(&m.to_json().unwrap(), "m.json").unwrap();
        assert_eq!(m, back);
    }

    #[test]
    fn an_infinite_condition_number_survives_the_round_trip() {
        let mut m = sample();
        m.fit.condition = f64::INFINITY;
        let back = TlModel::from_json(&m.to_json().unwrap(), "m.json").unwrap();
        assert_eq!(back.fit.condition, f64::INFINITY);
    }

    #[test]
    fn wrong_format_and_names_are_rejected() {
        let mut m = sample();
        m.format = "other/9".into();
        let e = TlModel::from_json(&serde_json::to_string(&m).unwrap(), "m.json").unwrap_err();
        assert!(e.to_string().contains("m.json") && e.to_string().contains("other/9"));
        let mut m = sample();
        m.coefficients[0].name = "q".into();
        assert!(TlModel::from_json(&serde_json::to_string(&m).unwrap(), "m.json").is_err());
        assert!(TlModel::from_json("{", "m.json").is_err());
    }
}
