//! The compensation model file (`spec/data-formats.md`, "Model files").
//!
//! JSON, versioned by `"format": "aeromag-model/2"`. It records everything
//! needed to rebuild the design matrix on new data (the [`Design`]: terms,
//! derivative convention, `bt_scale`), how the model was fitted
//! ([`MethodSettings`]: `"method": "ls"` with the band, filter order, trim
//! and ridge λ, or `"method": "kalman"` with the field-model order and the
//! noise intensities), the coefficients with names and standard deviations,
//! fit statistics, the input columns used, and the software version.
//!
//! Version history: `aeromag-model/1` recorded `band_hz`, `filter_order`,
//! `trim` and `lambda` for both methods (zeros for the Kalman method) and
//! not the Kalman settings; such files are still read (their Kalman
//! settings are unknown: `None`). Rotor and pod model files share the
//! header and are the same in both versions.

use crate::error::{CompError, Result};
use crate::kalman::NoiseModel;
use crate::tolles_lawson::Design;
use serde::{Deserialize, Serialize};

/// The format tag this version writes.
pub const MODEL_FORMAT: &str = "aeromag-model/2";

/// The format tags this version reads: the current one and its predecessor.
pub const READ_FORMATS: [&str; 2] = [MODEL_FORMAT, "aeromag-model/1"];

/// `kind` of a Tolles-Lawson model (both fitting methods).
pub const TL_KIND: &str = "tolles-lawson";

/// The 1-based line of a JSON parser's error (`None` when it names none:
/// an error found after parsing, such as a missing field of a value).
pub fn json_error_line(e: &serde_json::Error) -> Option<u64> {
    (e.line() > 0).then_some(e.line() as u64)
}

/// Parse a model file and check its `format` (one of [`READ_FORMATS`]) and `kind`
/// (`writer` names the command that writes that kind, for the message).
/// Every model file of aeromag (Tolles-Lawson, rotor, pod) goes through here.
pub fn parse_model_json(
    text: &str,
    origin: &str,
    kind: &str,
    writer: &str,
) -> Result<serde_json::Value> {
    let v: serde_json::Value = serde_json::from_str(text).map_err(|e| CompError::ModelFile {
        origin: origin.to_string(),
        line: json_error_line(&e),
        reason: format!("not a JSON model file ({e})"),
    })?;
    match v.get("format").and_then(|f| f.as_str()) {
        Some(f) if READ_FORMATS.contains(&f) => {}
        Some(other) => {
            return Err(CompError::model_file(
                origin,
                format!(
                    "model format {} is not supported (expected one of {})",
                    aeromag_core::error::shown_text(other),
                    READ_FORMATS.map(|f| format!("`{f}`")).join(", ")
                ),
            ));
        }
        None => {
            return Err(CompError::model_file(
                origin,
                "no \"format\" key; not an aeromag model file",
            ));
        }
    }
    match v.get("kind").and_then(|k| k.as_str()) {
        Some(k) if k == kind => Ok(v),
        found => Err(CompError::model_file(
            origin,
            format!(
                "model kind {} is not a `{kind}` model (written by `{writer}`)",
                found.map_or("missing".to_string(), aeromag_core::error::shown_text)
            ),
        )),
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
    let mut v = parse_model_json(text, origin, kind, writer)?;
    // Read as the current version (the kinds with a layout of their own
    // convert before they come here).
    v["format"] = MODEL_FORMAT.into();
    serde_json::from_value(v)
        .map_err(|e| CompError::model_file(origin, format!("invalid `{kind}` model: {e}")))
}

/// One named coefficient.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Coefficient {
    /// Column name, e.g. `p_x`, `i_xy`, `e_zy`.
    pub name: String,
    /// Value.
    pub value: f64,
    /// Standard deviation (NaN when unknown: JSON `null`, which
    /// `serde_json` writes for NaN).
    #[serde(deserialize_with = "null_as_nan")]
    pub std: f64,
}

/// JSON has no NaN: `serde_json` writes it as `null`; read `null` back as NaN.
fn null_as_nan<'de, D: serde::Deserializer<'de>>(d: D) -> std::result::Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

impl Coefficient {
    /// The named coefficients of a fit: `names`, `values` and standard
    /// deviations `std` in the same (column) order.
    pub fn list(names: &[String], values: &[f64], std: &[f64]) -> Vec<Coefficient> {
        names
            .iter()
            .zip(values.iter().zip(std))
            .map(|(n, (v, s))| Coefficient {
                name: n.clone(),
                value: *v,
                std: *s,
            })
            .collect()
    }
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
    /// How the lags of the extra regressors asked for with `:lag` were
    /// chosen (absent without them).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub extra_lag_selection: Vec<crate::tolles_lawson::lag_select::ExtraLagSelection>,
    /// Which of the extra regressors asked for the flight showed to matter
    /// (absent when every one was kept without a test).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub extra_channel_selection: Option<crate::tolles_lawson::extra_select::ChannelSelection>,
    /// The calibration flight's sample interval (median time step), s: the
    /// online compensator's gap rule (a step over 1.5 × this ends a run;
    /// absent in files written before it was recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sample_interval_s: Option<f64>,
}

/// JSON has no ∞: `serde_json` writes it as `null`; read `null` back as ∞.
fn null_as_infinity<'de, D: serde::Deserializer<'de>>(d: D) -> std::result::Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::INFINITY))
}

/// The band-pass least-squares settings a model was fitted with.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LsSettings {
    /// Pass band, Hz (`null` when unfiltered).
    pub band_hz: Option<(f64, f64)>,
    /// Butterworth order.
    pub filter_order: usize,
    /// Samples trimmed at each end of each segment.
    pub trim: usize,
    /// Ridge parameter λ.
    pub lambda: f64,
}

/// The Kalman-method settings a model was fitted with (`None` in files
/// converted from `aeromag-model/1`, which did not record them).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct KalmanSettings {
    /// Order of the along-track field model.
    pub field_order: Option<usize>,
    /// Noise intensities of the final fit (`q₁` in nT²/m^(2n−1), `q₂` in
    /// nT²/m⁵, `r` in nT²).
    pub noise: Option<NoiseModel>,
}

/// How a model was fitted: the method and its own settings. In the file:
/// `"method": "ls"` or `"method": "kalman"` beside the settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "method", rename_all = "lowercase")]
pub enum MethodSettings {
    /// Band-pass least squares.
    Ls(LsSettings),
    /// The Kalman filter and smoother.
    Kalman(KalmanSettings),
}

impl MethodSettings {
    /// `ls` or `kalman`.
    pub fn name(&self) -> &'static str {
        match self {
            MethodSettings::Ls(_) => "ls",
            MethodSettings::Kalman(_) => "kalman",
        }
    }
}

impl std::fmt::Display for MethodSettings {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A Tolles-Lawson compensation model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TlModel {
    /// Always [`MODEL_FORMAT`] in memory.
    pub format: String,
    /// Model kind, [`TL_KIND`].
    pub kind: String,
    /// Terms, derivative convention and `bt_scale`: how the rows are built.
    #[serde(flatten)]
    pub design: Design,
    /// The method and its settings.
    #[serde(flatten)]
    pub method: MethodSettings,
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
        serde_json::to_string_pretty(self).map_err(|e| CompError::Serialize {
            what: "model",
            reason: e.to_string(),
        })
    }

    /// Parse and check a model file's text (either version,
    /// [`READ_FORMATS`]); `origin` names the file in errors.
    pub fn from_json(text: &str, origin: &str) -> Result<Self> {
        let v = parse_model_json(text, origin, TL_KIND, "aeromag calibrate")?;
        let mut m: TlModel = serde_json::from_value(v)
            .map_err(|e| CompError::model_file(origin, format!("invalid model file: {e}")))?;
        m.format = MODEL_FORMAT.into();
        m.design
            .validate()
            .map_err(|e| CompError::model_file(origin, e.to_string()))?;
        let expect = m.design.column_names();
        let got: Vec<&str> = m.coefficients.iter().map(|c| c.name.as_str()).collect();
        if expect.iter().map(|s| s.as_str()).ne(got.iter().copied()) {
            // The first difference, not both lists (2 KB for 43 terms).
            let k = (0..expect.len().max(got.len()))
                .find(|&k| expect.get(k).map(String::as_str) != got.get(k).copied())
                .unwrap_or_default();
            let named = |name: Option<&str>| name.map_or("none".to_string(), |n| format!("`{n}`"));
            let lags = match m.design.terms.eddy_lags_s().len() {
                0 => String::new(),
                1 => " with 1 eddy lag".to_string(),
                n => format!(" with {n} eddy lags"),
            };
            return Err(CompError::model_file(
                origin,
                format!(
                    "its terms `{}`{lags} take {} coefficients and it names {}: coefficient {} is {} where the terms have {}",
                    m.design.terms,
                    expect.len(),
                    got.len(),
                    k + 1,
                    named(got.get(k).copied()),
                    named(expect.get(k).map(String::as_str)),
                ),
            ));
        }
        if m.coefficients.iter().any(|c| !c.value.is_finite()) {
            return Err(CompError::model_file(origin, "a coefficient is not finite"));
        }
        if let Some(c) = m.coefficients.iter().find(|c| c.std < 0.0) {
            return Err(CompError::model_file(
                origin,
                format!(
                    "coefficient `{}` has a negative standard deviation {}",
                    c.name, c.std
                ),
            ));
        }
        Ok(m)
    }
}

/// `kind` of a model file holding one Tolles-Lawson model per scalar
/// sensor (`aeromag calibrate --mag mag_1_uc,mag_3_uc,…`).
pub const TL_SENSORS_KIND: &str = "tolles-lawson-sensors";

/// One scalar sensor's model in a [`SensorsModel`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorModel {
    /// Stem of the output columns: `<name>_comp`, `<name>_interf`
    /// (`mag_3` for the sensor `mag_3_uc`).
    pub name: String,
    /// The scalar magnetometer's column.
    pub mag: String,
    /// The vector magnetometer's columns (x, y, z).
    pub flux: [String; 3],
    /// The sensor whose compensated reading was the external-field
    /// reference of this fit (reference-sensor mode), if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference_sensor: Option<String>,
    /// The model.
    pub model: TlModel,
}

/// One Tolles-Lawson model per scalar sensor (kind [`TL_SENSORS_KIND`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SensorsModel {
    /// Always [`MODEL_FORMAT`] in memory.
    pub format: String,
    /// [`TL_SENSORS_KIND`].
    pub kind: String,
    /// The sensors, in the order they were given.
    pub sensors: Vec<SensorModel>,
    /// Version of aeromag that wrote the file.
    pub software_version: String,
}

impl SensorsModel {
    /// The file of `sensors`.
    pub fn new(sensors: Vec<SensorModel>) -> Self {
        Self {
            format: MODEL_FORMAT.into(),
            kind: TL_SENSORS_KIND.into(),
            sensors,
            software_version: env!("CARGO_PKG_VERSION").into(),
        }
    }

    /// Serialize to pretty JSON.
    pub fn to_json(&self) -> Result<String> {
        serde_json::to_string_pretty(self).map_err(|e| CompError::Serialize {
            what: "model",
            reason: e.to_string(),
        })
    }

    /// Parse and check the file's text: each sensor's model as
    /// [`TlModel::from_json`] checks it, names unique.
    pub fn from_json(text: &str, origin: &str) -> Result<Self> {
        let v = parse_model_json(
            text,
            origin,
            TL_SENSORS_KIND,
            "aeromag calibrate --mag A,B,…",
        )?;
        let mut m: SensorsModel = serde_json::from_value(v)
            .map_err(|e| CompError::model_file(origin, format!("invalid model file: {e}")))?;
        m.format = MODEL_FORMAT.into();
        if m.sensors.is_empty() {
            return Err(CompError::model_file(origin, "no sensor"));
        }
        for s in m.sensors.iter_mut() {
            let json = serde_json::to_string(&s.model)
                .map_err(|e| CompError::model_file(origin, e.to_string()))?;
            s.model = TlModel::from_json(&json, &format!("{origin}, sensor {}", s.name))?;
        }
        let names: Vec<&str> = m.sensors.iter().map(|s| s.name.as_str()).collect();
        if let Some(d) = names
            .iter()
            .enumerate()
            .find(|(k, n)| names[..*k].contains(n))
        {
            return Err(CompError::model_file(
                origin,
                format!("sensor `{}` appears twice", d.1),
            ));
        }
        Ok(m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tolles_lawson::{Convention, TermSet};

    fn sample() -> TlModel {
        let terms = TermSet::parse("p3,bias").unwrap();
        TlModel {
            format: MODEL_FORMAT.into(),
            kind: "tolles-lawson".into(),
            method: MethodSettings::Ls(LsSettings {
                band_hz: Some((0.1, 0.9)),
                filter_order: 4,
                trim: 20,
                lambda: 0.0,
            }),
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
            design: Design {
                terms,
                convention: Convention::Physical,
                bt_scale_nt: 50_000.0,
                ..Design::default()
            },
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
    fn long_or_binary_format_and_kind_are_not_echoed_whole() {
        // A 100 000-character `kind` (or `format`) was echoed whole in the
        // error; it is cut to its first characters and escaped.
        let long = "x".repeat(100_000);
        for text in [
            format!(r#"{{"format":"aeromag-model/2","kind":"{long}"}}"#),
            format!(r#"{{"format":"{long}","kind":"towed-pod"}}"#),
            r#"{"format":"aeromag-model/2","kind":"pod\u0000\u0001"}"#.to_string(),
        ] {
            let e = parse_model_json(&text, "m.json", "towed-pod", "aeromag pod fit").unwrap_err();
            let msg = e.to_string();
            assert!(e.is_bad_input() && msg.contains("m.json"), "{msg}");
            assert!(msg.len() < 400, "{} characters", msg.len());
            assert!(!msg.contains('\0') && !msg.contains('\u{1}'), "{msg:?}");
        }
    }

    /// The model of a Kalman fit, as `aeromag-model/1` wrote it.
    const KALMAN_V1: &str = r#"{
      "format": "aeromag-model/1", "kind": "tolles-lawson", "method": "kalman",
      "terms": {"groups": ["p3", "bias"]}, "convention": "physical", "bt_scale_nt": 50000.0,
      "band_hz": null, "filter_order": 0, "trim": 0, "lambda": 0.0,
      "coefficients": [
        {"name": "p_x", "value": 1.5, "std": 0.1}, {"name": "p_y", "value": -2.0, "std": 0.1},
        {"name": "p_z", "value": 0.25, "std": 0.1}, {"name": "bias", "value": 3.0, "std": 0.2}],
      "fit": {"rows": 10, "segments": 1, "condition": 5.0, "residual_rms_nt": 0.01, "warnings": []},
      "columns": {}, "software_version": "0.1.0"
    }"#;

    #[test]
    fn version_1_files_are_read_as_the_current_version() {
        let m = TlModel::from_json(KALMAN_V1, "k.json").unwrap();
        assert_eq!(m.format, MODEL_FORMAT);
        assert_eq!(
            m.method,
            MethodSettings::Kalman(KalmanSettings {
                field_order: None,
                noise: None
            })
        );
        assert_eq!(m.coef(), [1.5, -2.0, 0.25, 3.0]);
        let ls_v1 = sample()
            .to_json()
            .unwrap()
            .replace(MODEL_FORMAT, "aeromag-model/1");
        let ls = TlModel::from_json(&ls_v1, "l.json").unwrap();
        assert_eq!(
            ls,
            sample(),
            "an LS model reads the same from either version"
        );
    }

    #[test]
    fn the_method_and_its_settings_are_one_tagged_object() {
        let mut m = sample();
        let v: serde_json::Value = serde_json::from_str(&m.to_json().unwrap()).unwrap();
        assert_eq!(v["method"], "ls");
        assert_eq!(v["trim"], 20);
        assert_eq!(v["terms"], serde_json::json!({"groups": ["p3", "bias"]}));
        m.method = MethodSettings::Kalman(KalmanSettings {
            field_order: Some(6),
            noise: Some(NoiseModel::calibration_default()),
        });
        let text = m.to_json().unwrap();
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(v["method"], "kalman");
        assert_eq!(v["field_order"], 6);
        assert!(
            v["noise"]["r_nt2"].is_number() && v.get("trim").is_none(),
            "{v}"
        );
        assert_eq!(TlModel::from_json(&text, "m.json").unwrap(), m);
    }

    #[test]
    fn round_trip() {
        let m = sample();
        let back = TlModel::from_json(&m.to_json().unwrap(), "m.json").unwrap();
        assert_eq!(m, back);
    }

    /// An unknown standard deviation (NaN, written as JSON `null`) reads
    /// back; a negative one, or a `bt_scale` that is no field magnitude
    /// (which made every row's interference overflow), is a bad file.
    #[test]
    fn unknown_std_reads_back_and_impossible_values_are_refused() {
        let mut m = sample();
        m.coefficients[1].std = f64::NAN;
        let text = m.to_json().unwrap();
        assert!(text.contains("\"std\": null"), "{text}");
        let back = TlModel::from_json(&text, "m.json").unwrap();
        assert!(back.coefficients[1].std.is_nan());
        assert_eq!(back.coef(), m.coef());

        m.coefficients[1].std = -0.5;
        let e = TlModel::from_json(&m.to_json().unwrap(), "m.json").unwrap_err();
        assert!(e.is_bad_input(), "{e}");
        assert!(
            e.to_string()
                .contains("`p_y` has a negative standard deviation"),
            "{e}"
        );

        for (bt, ok) in [
            (1e-308, false),
            (0.5, false),
            (1.0, true),
            (1e6, true),
            (2e6, false),
        ] {
            let mut m = sample();
            m.design.bt_scale_nt = bt;
            let r = TlModel::from_json(&m.to_json().unwrap(), "m.json");
            assert_eq!(r.is_ok(), ok, "{bt}: {r:?}");
            if let Err(e) = r {
                assert!(e.is_bad_input() && e.to_string().contains("m.json"), "{e}");
            }
        }
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
        let e = TlModel::from_json(&serde_json::to_string(&m).unwrap(), "m.json").unwrap_err();
        assert!(
            e.to_string()
                .ends_with("coefficient 1 is `q` where the terms have `p_x`"),
            "{e}"
        );
        assert!(TlModel::from_json("{", "m.json").is_err());
        // One coefficient too many: the counts and the first difference,
        // not both lists (a lag-count mismatch listed 2 KB of names).
        let mut m = sample();
        let mut extra = m.coefficients[0].clone();
        extra.name = "l2_xx".into();
        m.coefficients.push(extra);
        let e = TlModel::from_json(&serde_json::to_string(&m).unwrap(), "m.json")
            .unwrap_err()
            .to_string();
        let n = m.coefficients.len();
        assert!(
            e.contains(&format!("take {} coefficients and it names {n}", n - 1))
                && e.ends_with(&format!(
                    "coefficient {n} is `l2_xx` where the terms have none"
                )),
            "{e}"
        );
        assert!(e.len() < 200, "{e}");
    }
}
