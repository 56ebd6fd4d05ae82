//! The report section of the Kalman method: the smoothed external field, the
//! innovations and the coefficients with their uncertainties next to the
//! band-pass LS fit (spec `compensation.md`, Method 2, "Outputs").

use super::kalman::KalmanOutcome;
use crate::error::Result;
use crate::flight::Flight;
use aeromag_compensation::model_file::TlModel;
use aeromag_report::{Block, LinePlot, ReportSection, Series, Table};

impl KalmanOutcome {
    /// The report section of this fit on the calibration flight `table`
    /// (the one it was fitted on), with the band-pass LS model `ls` of the same
    /// flight for comparison and `kalman`, the model of this fit: noise
    /// intensities and innovation statistics, the smoothed field (against
    /// `true_anomaly` when the flight is simulated; the estimators never read
    /// it), the innovations with their ±σ, and both coefficient sets. The
    /// series plots need [`KalmanOptions::series`](super::KalmanOptions::series).
    pub fn section(
        &self,
        heading: &str,
        table: &Flight,
        ls: &TlModel,
        kalman: &TlModel,
    ) -> Result<ReportSection> {
        let mut s = ReportSection::new(heading);
        let f = &self.fit;
        s.blocks.push(Block::Paragraph(format!(
        "Field model of order {} (B^h the {}-th integral of white noise). Noise intensities {}: q1 = {:.2e} {}, \
         q2 = {:.2e} nT²/m⁵, r = {:.2e} nT². Eddy-current lags: {}. \
         Normalised innovation variance {:.2} (1 when the noise model fits), innovation RMS {:.4} nT over {} samples \
         in {} runs.",
        f.field_order,
        f.field_order,
        if f.tuning.is_some() {
            "tuned by maximum likelihood"
        } else if f.noise == aeromag_compensation::kalman::NoiseModel::calibration_default_for(f.field_order) {
            "(defaults)"
        } else {
            "(as given)"
        },
        f.noise.q1,
        aeromag_compensation::kalman::q1_unit(f.field_order),
        f.noise.q2_nt2_per_m5,
        f.noise.r_nt2,
        if kalman.design.terms.eddy_lags_s().is_empty() {
            "none".to_string()
        } else {
            format!("{:?} s", kalman.design.terms.eddy_lags_s())
        },
        f.normalized_innovation_variance,
        f.innovation_rms_nt,
        f.rows,
        f.runs
    )));
        if let Some(series) = &self.series {
            let rows = series.columns();
            let time = table.require("time")?;
            let t0 = time.iter().copied().find(|t| t.is_finite()).unwrap_or(0.0);
            let used: Vec<usize> = (0..time.len())
                .filter(|&i| rows[2][i].is_finite())
                .collect();
            let tt: Vec<f64> = used.iter().map(|&i| time[i] - t0).collect();
            let centred = |col: &[f64]| -> Vec<f64> {
                let m = used.iter().map(|&i| col[i]).sum::<f64>() / used.len().max(1) as f64;
                used.iter().map(|&i| col[i] - m).collect()
            };
            let field = centred(rows[2]);
            let mut plot = LinePlot::new(
                "Smoothed external field (mean removed)",
                "time since start (s)",
                "field (nT)",
            )
            .with_series(Series::line(
                "Kalman smoothed field",
                tt.clone(),
                field.clone(),
            ));
            let truth = table.column("true_anomaly").map(centred);
            if let Some(truth) = &truth {
                plot = plot.with_series(Series::line(
                    "true anomaly (simulation)",
                    tt.clone(),
                    truth.clone(),
                ));
            }
            s.blocks.push(Block::Figure {
            svg: plot.to_svg()?,
            caption: "The field the Kalman smoother separates from the interference, on the calibration flight.".into(),
        });
            if let Some(truth) = &truth {
                // The smoothed field also holds the diurnal and IGRF residuals
                // the reference channels leave, so the difference is not zero.
                let diff: Vec<f64> = field.iter().zip(truth).map(|(a, b)| a - b).collect();
                let plot = LinePlot::new(
                    "Smoothed field minus the true anomaly",
                    "time since start (s)",
                    "nT",
                )
                .with_series(Series::line(
                    "smoothed − true anomaly",
                    tt.clone(),
                    diff,
                ));
                s.blocks.push(Block::Figure {
                svg: plot.to_svg()?,
                caption: "What the smoother gets wrong, plus the reference channels' own errors (base station, IGRF at the \
                          recorded position)."
                    .into(),
            });
            }
            let sel = |c: usize| used.iter().map(|&i| rows[c][i]).collect::<Vec<f64>>();
            let sd = sel(4);
            // The first samples of each run have the diffuse prior's σ; scale
            // the view to the typical σ.
            let mut sorted = sd.clone();
            sorted.sort_by(f64::total_cmp);
            let typical = sorted.get(sorted.len() / 2).copied().unwrap_or(1.0);
            let mut plot = LinePlot::new(
                "Innovations and their predicted ±1σ",
                "time since start (s)",
                "nT",
            )
            .with_series(Series::line("innovation ν", tt.clone(), sel(3)))
            .with_series(Series::line("+σ", tt.clone(), sd.clone()))
            .with_series(Series::line("−σ", tt, sd.iter().map(|v| -v).collect()));
            plot.y_range = Some((-6.0 * typical, 6.0 * typical));
            s.blocks.push(Block::Figure {
            svg: plot.to_svg()?,
            caption: "Pass-1 innovations; a noise model that fits keeps about two thirds of them within ±σ.".into(),
        });
        }
        let rows = kalman
            .coefficients
            .iter()
            .map(|c| {
                // Lagged terms carry the fit's own τ: compare only the others.
                let lagged = c.name.starts_with('l');
                let l = ls.coefficients.iter().find(|x| x.name == c.name && !lagged);
                vec![
                    c.name.clone(),
                    l.map_or("—".into(), |l| format!("{:.4} ± {:.2e}", l.value, l.std)),
                    format!("{:.4} ± {:.2e}", c.value, c.std),
                ]
            })
            .collect();
        s.blocks.push(Block::Table(Table::new(
        ["coefficient", "band-pass LS (± 1σ)", "Kalman (± 1σ)"].map(String::from).to_vec(),
        rows,
        "Coefficients and their standard deviations (nT, nT·s for eddy terms; the LS σ assumes white band-passed \
         residuals). Lagged eddy terms (l…) are listed for the Kalman fit only: the two fits may choose different lags.",
    )));
        Ok(s)
    }
}
