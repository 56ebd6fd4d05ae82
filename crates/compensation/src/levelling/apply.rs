//! Applying a levelling fit to every row, and the one-call survey levelling
//! (spec `compensation.md`, "Survey altitude"; seed `000_…` §9).
//!
//! ```text
//! corrected_i = m_i − k·Ḃ_i − (o_L + s_L (t_i − t_L)/h_L)        (nT)
//! ```
//!
//! Every input row is kept (spec: nothing is silently dropped); each gets a
//! [`RowFlag`]. Rows off lines (label 0 or NaN: turns, transits) keep their
//! value: the derivative term is a property of the sensor and would apply
//! there too, but a turn has no level and mixing corrected and uncorrected
//! samples in one channel would hide that. Rows of a line without any
//! crossover get the `k·Ḃ` correction only (its level is unknown, taken as 0).

use super::crossovers::{CrossoverSet, find_crossovers};
use super::fit::{LevellingConfig, LevellingFit, fit_levelling};
use super::tracks::{SurveyTracks, TrackConfig, bad, track_derivative};
use super::vertical_gradient::profile_gradient;
use crate::error::Result;
use serde::{Deserialize, Serialize};

/// What happened to a row.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum RowFlag {
    /// Corrected for `k·Ḃ` and the line's level.
    Levelled,
    /// On a line without crossovers: corrected for `k·Ḃ` only.
    NoCrossovers,
    /// Not on a line (label 0 or NaN): value unchanged.
    NotOnLine,
    /// Non-finite value, or (when `k ≠ 0`) no derivative: value unchanged.
    Missing,
}

/// The levelled series.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Levelled {
    /// The corrected value of every input row, nT.
    pub value_nt: Vec<f64>,
    /// The flag of every input row.
    pub flag: Vec<RowFlag>,
}

/// Everything [`level_survey`] computed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SurveyLevelling {
    /// Along-track derivative `Ḃ` of the sensed reading (else the input
    /// value), nT/s (one per row).
    pub derivative_nt_per_s: Vec<f64>,
    /// The crossovers and the skipped crossings.
    pub crossovers: CrossoverSet,
    /// The fit (k, levels, residuals before/after).
    pub fit: LevellingFit,
    /// The corrected series.
    pub levelled: Levelled,
}

/// Apply `fit` to every row of `tracks` (module docs). `derivative` is the
/// along-track derivative used for the fit (nT/s, one per row).
pub fn apply_levelling(
    fit: &LevellingFit,
    tracks: &SurveyTracks,
    derivative: &[f64],
) -> Result<Levelled> {
    tracks.validate()?;
    if derivative.len() != tracks.len() {
        return Err(bad(format!(
            "derivative has {} rows, the tracks {}",
            derivative.len(),
            tracks.len()
        )));
    }
    let n = tracks.len();
    let mut out = Levelled {
        value_nt: tracks.value.to_vec(),
        flag: vec![RowFlag::NotOnLine; n],
    };
    for (i, &bdot) in derivative.iter().enumerate() {
        let Some(label) = tracks.label(i) else {
            continue;
        };
        let m = tracks.value[i];
        let kb = if fit.k_s == 0.0 { 0.0 } else { fit.k_s * bdot };
        let level = fit.line(label).map(|l| l.level_nt(tracks.time[i]));
        let corrected = m - kb - level.unwrap_or(0.0);
        if !corrected.is_finite() {
            out.flag[i] = RowFlag::Missing;
            continue;
        }
        out.value_nt[i] = corrected;
        out.flag[i] = if level.is_some() {
            RowFlag::Levelled
        } else {
            RowFlag::NoCrossovers
        };
    }
    Ok(out)
}

/// Level a survey in one call: derivative, crossovers, fit, corrected series.
pub fn level_survey(
    tracks: &SurveyTracks,
    track: &TrackConfig,
    fit: &LevellingConfig,
) -> Result<SurveyLevelling> {
    let derivative_nt_per_s = track_derivative(tracks, track)?;
    let gradient = if fit.altitude_term {
        Some(profile_gradient(tracks, track)?)
    } else {
        None
    };
    let crossovers = find_crossovers(tracks, &derivative_nt_per_s, gradient.as_deref(), track)?;
    let fit = fit_levelling(&crossovers.crossovers, fit)?;
    let levelled = apply_levelling(&fit, tracks, &derivative_nt_per_s)?;
    Ok(SurveyLevelling {
        derivative_nt_per_s,
        crossovers,
        fit,
        levelled,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::levelling::crossovers::tests::block;
    use proptest::prelude::*;

    /// The synthetic block with per-line offsets `o(L)` and a lag-like term
    /// `k·dv/dt` added to a curved field; returns the block.
    fn levelled_block(k: f64) -> (crate::levelling::crossovers::tests::Block, Vec<f64>) {
        let mut b = block(9, 4, 150.0, 7.0);
        // A non-linear field so that Ḃ differs between crossovers.
        let o = aeromag_core::frames::Geodetic::new(50.0, 10.0, 0.0);
        let field = |lat: f64, lon: f64| {
            let [n, e, _] = o.ned_offset_to(&aeromag_core::frames::Geodetic::new(lat, lon, 0.0));
            20.0 * (n / 90.0).sin() * (e / 130.0).cos() + 0.01 * e
        };
        let offset = |l: f64| {
            if l > 0.0 {
                ((l as i64 * 13) % 7) as f64 - 3.0
            } else {
                0.0
            }
        };
        let truth: Vec<f64> = (0..b.t.len()).map(|i| field(b.lat[i], b.lon[i])).collect();
        let zeros = vec![0.0; truth.len()];
        let tr = SurveyTracks {
            value: &truth,
            sensed: None,
            alt: &zeros,
            ..b.tracks()
        };
        let bdot = track_derivative(&tr, &TrackConfig::default()).unwrap();
        for i in 0..b.t.len() {
            b.v[i] = truth[i]
                + offset(b.line[i])
                + if bdot[i].is_finite() {
                    k * bdot[i]
                } else {
                    0.0
                };
        }
        (b, truth)
    }

    #[test]
    fn levelling_restores_the_field_on_lines_and_keeps_turns() {
        let (mut b, truth) = levelled_block(-0.1);
        b.v[5] = f64::NAN;
        let r = level_survey(
            &b.tracks(),
            &TrackConfig::default(),
            &LevellingConfig::default(),
        )
        .unwrap();
        assert_eq!(r.crossovers.crossovers.len(), 36);
        assert!((r.fit.k_s + 0.1).abs() < 0.01, "k = {}", r.fit.k_s);
        assert!(
            r.fit.rms_after_nt < r.fit.rms_before_nt / 10.0,
            "{} → {}",
            r.fit.rms_before_nt,
            r.fit.rms_after_nt
        );
        assert_eq!(r.levelled.value_nt.len(), b.t.len());
        // On lines: corrected − truth is one common constant (the datum).
        let on: Vec<usize> = (0..b.t.len())
            .filter(|&i| r.levelled.flag[i] == RowFlag::Levelled)
            .collect();
        let c = r.levelled.value_nt[on[0]] - truth[on[0]];
        let worst = on
            .iter()
            .map(|&i| (r.levelled.value_nt[i] - truth[i] - c).abs())
            .fold(0.0, f64::max);
        assert!(worst < 0.15, "worst {worst}");
        for i in 0..b.t.len() {
            match r.levelled.flag[i] {
                RowFlag::NotOnLine => assert_eq!(b.line[i], 0.0),
                RowFlag::Missing => assert_eq!(i, 5),
                _ => {}
            }
            if b.line[i] == 0.0 {
                assert_eq!(r.levelled.value_nt[i].to_bits(), b.v[i].to_bits());
            }
        }
        assert!(r.levelled.value_nt[5].is_nan());
    }

    #[test]
    fn a_line_without_crossovers_gets_only_the_k_term() {
        let (mut b, _) = levelled_block(0.0);
        // Relabel part of tie 101 beyond the block as line 77: no crossings.
        let rows: Vec<usize> = (0..b.t.len()).filter(|&i| b.line[i] == 101.0).collect();
        for &i in &rows[..5] {
            b.line[i] = 77.0;
        }
        let r = level_survey(
            &b.tracks(),
            &TrackConfig::default(),
            &LevellingConfig::default(),
        )
        .unwrap();
        assert!(r.fit.line(77).is_none());
        for &i in &rows[..5] {
            assert_eq!(r.levelled.flag[i], RowFlag::NoCrossovers);
            let expect = b.v[i] - r.fit.k_s * r.derivative_nt_per_s[i];
            assert!((r.levelled.value_nt[i] - expect).abs() < 1e-12);
        }
    }

    /// The lag acts on the total the sensor saw: with an interference-like
    /// series `q` in the reading, compensated away but not its lag, the
    /// regressor must be the derivative of the uncompensated `v + q`.
    #[test]
    fn the_regressor_is_the_derivative_of_the_sensed_series() {
        let (b0, truth) = levelled_block(0.0);
        let q: Vec<f64> =
            b0.t.iter()
                .map(|t| 3.0 * (std::f64::consts::TAU * t / 9.3).sin())
                .collect();
        let total: Vec<f64> = b0.v.iter().zip(&q).map(|(v, q)| v + q).collect();
        let zeros = vec![0.0; truth.len()];
        let bdot = track_derivative(
            &SurveyTracks {
                value: &total,
                alt: &zeros,
                ..b0.tracks()
            },
            &TrackConfig::default(),
        )
        .unwrap();
        // Compensated value: offsets, field and the lag of the total.
        let value: Vec<f64> = (0..truth.len())
            .map(|i| b0.v[i] - 0.1 * if bdot[i].is_finite() { bdot[i] } else { 0.0 })
            .collect();
        let cfg = LevellingConfig {
            robust: false,
            lambda: 0.0,
            ..LevellingConfig::default()
        };
        let with = |sensed: Option<&[f64]>| {
            let tr = SurveyTracks {
                value: &value,
                sensed,
                ..b0.tracks()
            };
            level_survey(&tr, &TrackConfig::default(), &cfg)
                .unwrap()
                .fit
        };
        // A missing sensed reading on a line costs that row only.
        let mut gappy = total.clone();
        let gap = (0..gappy.len())
            .find(|&i| b0.line[i] == 3.0 && b0.line[i - 3] == 3.0 && b0.line[i + 3] == 3.0)
            .unwrap();
        gappy[gap] = f64::NAN;
        let tr = SurveyTracks {
            value: &value,
            sensed: Some(&gappy),
            ..b0.tracks()
        };
        let r = level_survey(&tr, &TrackConfig::default(), &cfg).unwrap();
        for i in gap - 3..=gap + 3 {
            let want = if i == gap {
                RowFlag::Missing
            } else {
                RowFlag::Levelled
            };
            assert_eq!(r.levelled.flag[i], want, "row {i} (gap at {gap})");
        }
        let right = with(Some(&total));
        let wrong = with(None);
        // Up to the linear interpolation of the curved field along two edges
        // (≈ 0.002 nT here) the model is exact.
        assert!(
            (right.k_s + 0.1).abs() < 0.002 && right.rms_after_nt < 0.005,
            "k = {}, residual {} nT",
            right.k_s,
            right.rms_after_nt
        );
        assert!(
            wrong.rms_after_nt > 10.0 * right.rms_after_nt,
            "derivative of the compensated value: k = {}, residual {} nT",
            wrong.k_s,
            wrong.rms_after_nt
        );
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        /// Adding a constant to every value changes no crossover difference:
        /// the fit and the corrected series (up to that constant) are unchanged;
        /// every row is kept.
        #[test]
        fn invariant_to_a_common_constant(c in -1.0e4f64..1.0e4) {
            let (b, _) = levelled_block(-0.05);
            let r0 = level_survey(&b.tracks(), &TrackConfig::default(), &LevellingConfig::default()).unwrap();
            let shifted: Vec<f64> = b.v.iter().map(|v| v + c).collect();
            let tr = SurveyTracks { value: &shifted, ..b.tracks() };
            let r1 = level_survey(&tr, &TrackConfig::default(), &LevellingConfig::default()).unwrap();
            prop_assert_eq!(r1.levelled.value_nt.len(), b.t.len());
            prop_assert!((r0.fit.k_s - r1.fit.k_s).abs() < 1e-9);
            for i in 0..b.t.len() {
                let d = r1.levelled.value_nt[i] - r0.levelled.value_nt[i] - c;
                prop_assert!(d.abs() < 1e-6 * (1.0 + c.abs()), "row {}: {}", i, d);
            }
        }
    }
}
