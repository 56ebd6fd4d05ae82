//! The calibration choices as a user states them: the `aeromag calibrate`
//! flags and the keyword options of Python's `aeromag.TollesLawson` are
//! both turned into [`CalibrateOptions`] here, so that the CLI and Python
//! give the same model from the same choices.
//!
//! Unset values take defaults that may depend on other choices: the
//! eddy-current lags are `auto`, but `none` with the MagNav convention
//! (MagNav.jl's model exactly); the Kalman noise intensities are tuned by
//! maximum likelihood unless they are given.

use super::calibrate::{CalibrateOptions, EddyLag, ExtraSelection, Method};
use super::kalman::KalmanOptions;
use crate::error::{Error, Result};
use crate::flight::{LeverArm, ReferenceChannels};
use aeromag_compensation::kalman::NoiseModel;
use aeromag_compensation::tolles_lawson::fit_ls::LsConfig;
use aeromag_compensation::tolles_lawson::{Convention, Design, ExtraRequest, Magnitude, TermSet};

/// Calibration choices by name, every one optional (`None`: the default).
///
/// ```
/// use aeromag::{CalibrateSettings, EddyLag, Method};
/// use aeromag::compensation::tolles_lawson::Convention;
/// let s = CalibrateSettings {
///     convention: Some(Convention::MagNav),
///     ..CalibrateSettings::default()
/// };
/// let opts = s.options()?;
/// assert_eq!(opts.method, Method::Ls);
/// assert_eq!(opts.eddy_lag, EddyLag::None); // MagNav.jl's model
/// # Ok::<(), aeromag::Error>(())
/// ```
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CalibrateSettings {
    /// `ls` (default) or `kalman`.
    pub method: Method,
    /// Term groups (default `p3,i5,e8`).
    pub terms: Option<TermSet>,
    /// Derivative convention of the eddy terms (default physical, nT/s).
    pub convention: Option<Convention>,
    /// Ridge parameter λ ≥ 0 (default 0).
    pub ridge_lambda: Option<f64>,
    /// Pass band (lo, hi) in Hz; `Some(None)` fits unfiltered data
    /// (default 0.1–0.9 Hz).
    pub band_hz: Option<Option<(f64, f64)>>,
    /// Samples trimmed at each end of each filtered leg (default 20).
    pub trim: Option<usize>,
    /// Scale of the induced and eddy columns, nT (default 50 000).
    pub bt_scale_nt: Option<f64>,
    /// Treat the whole flight as one leg, ignoring `line` (default false).
    pub no_split_lines: bool,
    /// Known external-field channels removed first (default `auto`).
    pub reference: ReferenceChannels,
    /// The lagged eddy-current terms (default `auto`, or `none` with the
    /// MagNav convention).
    pub eddy_lag: Option<EddyLag>,
    /// The scalar sensor's position from the navigation point, m (body
    /// frame: x forward, y right, z down).
    pub lever_arm_m: Option<[f64; 3]>,
    /// Date of the flight as a decimal year, for the main-field gradient
    /// used with the lever arm (default 2025.0).
    pub decimal_year: Option<f64>,
    /// Kalman method: tune the noise intensities (`None`: tune unless
    /// `kalman_noise` is given).
    pub tune: Option<bool>,
    /// Kalman method: noise intensities (default: per field order).
    pub kalman_noise: Option<NoiseModel>,
    /// Kalman method: order of the along-track field model (2–6, default 6).
    pub field_order: Option<usize>,
    /// Kalman method: compute the per-row series.
    pub series: bool,
    /// Extra regressors (`--extra cur_strb,cur_flap:lag`; default none).
    pub extra: Vec<ExtraRequest>,
    /// Test the extra regressors channel by channel and drop those the
    /// flight shows not to matter (`--extra-selection test`, the default),
    /// or keep them all (`all`).
    pub extra_selection: ExtraSelection,
    /// The first-order projection (default) or the exact magnitude
    /// (`--magnitude exact`, either method).
    pub magnitude: Option<Magnitude>,
}

/// The date the lever arm's main-field gradient is taken at by default.
pub const DEFAULT_DECIMAL_YEAR: f64 = 2025.0;

impl CalibrateSettings {
    /// The library's options: defaults filled in, and the Kalman-only
    /// choices refused with the LS method (bad input naming the choice).
    pub fn options(&self) -> Result<CalibrateOptions> {
        if self.method != Method::Kalman {
            for (given, name) in [
                (self.series, "series (--series)"),
                (self.field_order.is_some(), "field_order (--field-order)"),
                (self.kalman_noise.is_some(), "kalman_noise (--kalman-noise)"),
                (self.tune.is_some(), "tune (--tune, --no-tune)"),
            ] {
                if given {
                    return Err(Error::bad_input(format!("{name} needs method kalman")));
                }
            }
        } else {
            // The band-pass LS settings were ignored by the Kalman method
            // without a word (the same coefficients with `--band 0.2,0.5`).
            for (given, name) in [
                (self.ridge_lambda.is_some(), "ridge_lambda (--lambda)"),
                (self.band_hz.is_some(), "band (--band)"),
                (self.trim.is_some(), "trim (--trim)"),
            ] {
                if given {
                    return Err(Error::bad_input(format!(
                        "{name} is a setting of the band-pass LS method; the Kalman method does not filter"
                    )));
                }
            }
        }
        if let Some(l) = self.ridge_lambda
            && !(l.is_finite() && l >= 0.0)
        {
            return Err(Error::bad_input(format!(
                "ridge_lambda (--lambda) must be ≥ 0, got {l}"
            )));
        }
        if let Some(b) = self.bt_scale_nt
            && !(b.is_finite() && b > 0.0)
        {
            return Err(Error::bad_input(format!(
                "bt_scale (--bt-scale) must be > 0 nT, got {b}"
            )));
        }
        if let Some(Some((lo, hi))) = self.band_hz
            && !(lo > 0.0 && hi > lo && hi.is_finite())
        {
            return Err(Error::bad_input(format!(
                "band needs 0 < lo < hi (Hz), got {lo}, {hi}"
            )));
        }
        let ls = LsConfig::default();
        let design = Design::default();
        let convention = self.convention.unwrap_or(design.convention);
        let kalman = KalmanOptions::default();
        Ok(CalibrateOptions {
            method: self.method,
            ls: LsConfig {
                design: Design {
                    terms: self.terms.clone().unwrap_or(design.terms),
                    convention,
                    bt_scale_nt: self.bt_scale_nt.unwrap_or(design.bt_scale_nt),
                    magnitude: self.magnitude.unwrap_or_default(),
                    ..design
                },
                band_hz: self.band_hz.unwrap_or(ls.band_hz),
                trim: self.trim.unwrap_or(ls.trim),
                lambda: self.ridge_lambda.unwrap_or(ls.lambda),
                ..ls
            },
            kalman: KalmanOptions {
                field_order: self.field_order.unwrap_or(kalman.field_order),
                noise: self.kalman_noise,
                tune: self.tune.unwrap_or(self.kalman_noise.is_none()),
                series: self.series,
            },
            eddy_lag: self
                .eddy_lag
                .clone()
                .unwrap_or_else(|| EddyLag::default_for(convention)),
            split_lines: !self.no_split_lines,
            reference: self.reference.clone(),
            lever_arm: self.lever_arm_m.map(|arm_m| LeverArm {
                arm_m,
                decimal_year: self.decimal_year.unwrap_or(DEFAULT_DECIMAL_YEAR),
            }),
            // The model keeps the MagNav name of an SGL channel (`CUR_COM1`
            // → `cur_com_1`), which finds it in either naming.
            extra: self
                .extra
                .iter()
                .map(|r| ExtraRequest {
                    channel: aeromag_io::magnav_name(&r.channel),
                    lag: r.lag,
                })
                .collect(),
            extra_selection: self.extra_selection,
            sensor: Default::default(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_the_library_defaults() {
        let o = CalibrateSettings::default().options().unwrap();
        let d = CalibrateOptions::default();
        assert_eq!(o.ls, d.ls);
        assert_eq!(o.eddy_lag, d.eddy_lag);
        assert_eq!(o.kalman, d.kalman);
        assert_eq!((o.split_lines, &o.reference), (true, &d.reference));
        assert!(o.lever_arm.is_none());
    }

    #[test]
    fn dependent_defaults_and_refusals() {
        let given = NoiseModel {
            q1: 1e-20,
            q2_nt2_per_m5: 1e-15,
            r_nt2: 4e-4,
        };
        let k = CalibrateSettings {
            method: Method::Kalman,
            kalman_noise: Some(given),
            ..CalibrateSettings::default()
        };
        assert!(
            !k.options().unwrap().kalman.tune,
            "given noise is used as is"
        );
        let k = CalibrateSettings {
            tune: Some(true),
            ..k
        };
        assert!(k.options().unwrap().kalman.tune);
        let ls = CalibrateSettings {
            field_order: Some(3),
            ..CalibrateSettings::default()
        };
        let e = ls.options().unwrap_err();
        assert!(
            e.is_bad_input() && e.to_string().contains("field_order"),
            "{e}"
        );
        for bad in [
            CalibrateSettings {
                ridge_lambda: Some(-1.0),
                ..CalibrateSettings::default()
            },
            CalibrateSettings {
                bt_scale_nt: Some(0.0),
                ..CalibrateSettings::default()
            },
            CalibrateSettings {
                band_hz: Some(Some((0.9, 0.1))),
                ..CalibrateSettings::default()
            },
        ] {
            assert!(bad.options().unwrap_err().is_bad_input(), "{bad:?}");
        }
        let arm = CalibrateSettings {
            lever_arm_m: Some([1.0, 0.0, 0.0]),
            ..CalibrateSettings::default()
        };
        assert_eq!(
            arm.options().unwrap().lever_arm.unwrap().decimal_year,
            DEFAULT_DECIMAL_YEAR
        );
    }
}
