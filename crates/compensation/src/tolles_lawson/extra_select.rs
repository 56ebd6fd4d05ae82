//! Which extra regressors (current channels) a sensor needs: backward
//! elimination by the likelihood-ratio test of the eddy lags
//! ([`super::lag_select`]).
//!
//! A flight records channels that do not matter for a given sensor (the
//! battery and bus currents of the SGL aircraft are wired far from every
//! magnetometer), and one current matters for a cabin sensor and hardly for
//! the tail stinger. Each unneeded channel costs three (six with its lag)
//! coefficients that the calibration determines only to its noise, and a
//! slow channel — whose in-band content is small — then projects its
//! coefficient error onto the survey at low frequency, where the band-pass
//! fit never looked. On the simulator's SGL-like installation the four bus
//! and battery channels added 2.6–2.8 nT each to a cabin sensor's survey
//! error when kept.
//!
//! The test: with the model `M` holding the channels still kept, the channel
//! `k` (its `q` columns) is tested by
//!
//! ```text
//! Λ_k = ν ln(RSS_{M∖k} / RSS_M)  ~  χ²_q   if channel k explains nothing,
//! ```
//!
//! `ν` the equivalent number of independent residual samples (the effective
//! degrees of freedom times the residual's in-band spectral flatness, as for
//! the lags). The channel with the smallest `Λ_k` relative to its threshold
//! (`χ²_q` at `1 − α/m`, `m` the channels still in the model: Bonferroni)
//! is dropped if it falls below it, and the test is repeated on the smaller
//! model until every channel left is significant. Every sub-model comes from
//! one band-passed accumulation of the normal equations
//! ([`aeromag_estimation::least_squares::NormalEquations::subset`]), so the cost is one pass over the rows plus
//! one residual pass per elimination step.

use super::fit_ls::{LsConfig, Segment, accumulate, band_passed_residuals};
use super::lag_select::{lag_threshold, spectral_flatness};
use super::terms::Column;
use crate::error::{CompError, Result};
use serde::{Deserialize, Serialize};

/// The test of one extra regressor, as it stood when the channel was
/// dropped or, for a kept channel, in the final model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChannelTest {
    /// The channel (e.g. `cur_strb`).
    pub channel: String,
    /// Its columns in the model (3, or 6 with its lag).
    pub columns: usize,
    /// `Λ` of the module docs.
    pub lr_statistic: f64,
    /// The `χ²` threshold it was tested against.
    pub threshold: f64,
    /// Kept in the model.
    pub kept: bool,
}

/// The outcome of [`select_extra_channels`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChannelSelection {
    /// Indices (into the design's extras) of the channels kept, ascending.
    pub kept: Vec<usize>,
    /// One test per channel, in the design's order.
    pub tests: Vec<ChannelTest>,
    /// Band-passed residual RMS with every channel, nT.
    pub residual_all_nt: f64,
    /// Band-passed residual RMS with the kept channels, nT.
    pub residual_kept_nt: f64,
}

/// Backward elimination of the extra regressors of `cfg`'s design (module
/// docs) at the false-selection probability `alpha` (0 < α < 1). The fit is
/// the first-order band-pass fit of `cfg`; pass
/// [`super::lag_select::within_budget`] segments to bound the cost.
pub fn select_extra_channels(
    segments: &[Segment],
    cfg: &LsConfig,
    alpha: f64,
) -> Result<ChannelSelection> {
    let terms = &cfg.design.terms;
    let n_extra = terms.extras().len();
    // The columns of each extra regressor, and the others.
    let mut of_extra: Vec<Vec<usize>> = vec![Vec::new(); n_extra];
    let mut base = Vec::new();
    let mut j = 0;
    terms.for_each_column(|c| {
        match c {
            Column::Extra { k, .. } => of_extra[k].push(j),
            _ => base.push(j),
        }
        j += 1;
    });
    let acc = accumulate(segments, cfg)?;
    let rows = acc.ne.rows() as f64;
    let solve = |keep: &[usize]| -> Result<(Vec<usize>, Vec<f64>, f64)> {
        let mut cols = base.clone();
        for &k in keep {
            cols.extend(&of_extra[k]);
        }
        cols.sort_unstable();
        let sol = acc
            .ne
            .subset(&cols)
            .and_then(|ne| ne.solve(cfg.lambda))
            .map_err(CompError::estimation("extra-regressor selection"))?;
        Ok((cols, sol.coef.iter().copied().collect(), sol.rss))
    };
    let mut kept: Vec<usize> = (0..n_extra).collect();
    let mut tests: Vec<Option<ChannelTest>> = vec![None; n_extra];
    let (_, _, rss_all) = solve(&kept)?;
    loop {
        let (cols, coef, rss) = solve(&kept)?;
        let flatness = match cfg.band_hz {
            Some(band) => {
                let mut full = vec![0.0; cfg.design.n_columns()];
                for (c, b) in cols.iter().zip(&coef) {
                    full[*c] = *b;
                }
                spectral_flatness(&band_passed_residuals(segments, cfg, &full)?, band)
            }
            None => 1.0,
        };
        let nu = (flatness * acc.effective_dof).max(1.0);
        let mut weakest: Option<(f64, usize)> = None;
        for &k in &kept {
            let without: Vec<usize> = kept.iter().copied().filter(|&x| x != k).collect();
            let (_, _, rss_k) = solve(&without)?;
            let q = of_extra[k].len();
            let lr = nu * (rss_k.max(rss) / rss).ln();
            let threshold = lag_threshold(alpha, kept.len(), q)?;
            tests[k] = Some(ChannelTest {
                channel: terms.extras()[k].channel.clone(),
                columns: q,
                lr_statistic: lr,
                threshold,
                kept: true,
            });
            let margin = lr / threshold;
            if weakest.is_none_or(|(m, _)| margin < m) {
                weakest = Some((margin, k));
            }
        }
        match weakest {
            Some((margin, k)) if margin < 1.0 => {
                if let Some(t) = tests[k].as_mut() {
                    t.kept = false;
                }
                kept.retain(|&x| x != k);
            }
            _ => {
                return Ok(ChannelSelection {
                    kept,
                    tests: tests.into_iter().flatten().collect(),
                    residual_all_nt: (rss_all / rows).sqrt(),
                    residual_kept_nt: (rss / rows).sqrt(),
                });
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tolles_lawson::design::Design;
    use crate::tolles_lawson::fit_ls::tests::coef16;
    use crate::tolles_lawson::lag_select::DEFAULT_ALPHA;
    use crate::tolles_lawson::lag_select::tests::{boxed, with_channels};
    use crate::tolles_lawson::terms::{ExtraTerm, TermSet};

    /// A box flown with the 16-term interference and one switched load
    /// whose field reaches the sensor, and three recorded channels: that
    /// load, a slow bus current and another switched load, both wired far
    /// away. The two that do not matter are dropped, the load is kept.
    #[test]
    fn channels_that_explain_nothing_are_dropped() {
        let mut legs = boxed(&TermSet::observable16(), &coef16());
        let k_nt_per_a = [30.0, -12.0, 20.0];
        let load = |t: f64| 8.0 * f64::from(u8::from(((t / 3.7) as u64).is_multiple_of(2)));
        let bus = |t: f64| {
            20.0 + 2.0 * (2.0 * std::f64::consts::PI * 0.003 * t).sin()
                + 1.3 * (2.0 * std::f64::consts::PI * 0.011 * t + 1.0).sin()
        };
        let far = |t: f64| 4.0 * f64::from(u8::from((t / 7.1) as u64 % 2 == 1));
        let mut chans: Vec<[Vec<f64>; 3]> = Vec::new();
        for (t, f, m) in legs.iter_mut() {
            let mut c: [Vec<f64>; 3] = Default::default();
            for (n, ti) in t.iter().enumerate() {
                let bt = (f[0][n].powi(2) + f[1][n].powi(2) + f[2][n].powi(2)).sqrt();
                m[n] += (0..3)
                    .map(|i| k_nt_per_a[i] * f[i][n] / bt * load(*ti))
                    .sum::<f64>();
                for (x, v) in c.iter_mut().zip([load(*ti), bus(*ti), far(*ti)]) {
                    x.push(v);
                }
            }
            chans.push(c);
        }
        let refs: Vec<[&[f64]; 3]> = chans
            .iter()
            .map(|[a, b, c]| [&a[..], &b[..], &c[..]])
            .collect();
        let segs = with_channels(&legs, &refs);
        let terms = TermSet::observable16()
            .with_extras(&[
                ExtraTerm::new("cur_load"),
                ExtraTerm::new("cur_bus"),
                ExtraTerm::new("cur_far"),
            ])
            .unwrap();
        let cfg = LsConfig {
            design: Design::new(terms),
            ..LsConfig::default()
        };
        let sel = select_extra_channels(&segs, &cfg, DEFAULT_ALPHA).unwrap();
        assert_eq!(sel.kept, vec![0], "{sel:?}");
        let names: Vec<(&str, bool)> = sel.tests.iter().map(|t| (&t.channel[..], t.kept)).collect();
        assert_eq!(
            names,
            [("cur_load", true), ("cur_bus", false), ("cur_far", false)]
        );
        for t in &sel.tests {
            assert_eq!(t.kept, t.lr_statistic > t.threshold, "{t:?}");
            assert_eq!(t.columns, 3);
        }
        // Dropping them costs (almost) nothing; dropping the load would not.
        assert!(sel.residual_kept_nt < 1.05 * sel.residual_all_nt, "{sel:?}");
        let load_test = &sel.tests[0];
        assert!(
            load_test.lr_statistic > 100.0 * load_test.threshold,
            "{load_test:?}"
        );
    }
}
