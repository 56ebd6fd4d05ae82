//! The gradiometry study (seed 004): Monte-Carlo efficiency of the
//! square-root IEKF against the Cramér–Rao bound on well-posed passes,
//! estimates ± 2σ and `MeasureS` over the default pass, and the
//! convergence maps of the seed's fig. 2 (the demo's `gradiometry` group).

use super::{PrintedFigure, PrintedSummary, Study, StudyOutcome, StudySize, fixed};
use crate::core::estimability::CONVENTION;
use crate::error::Result;
use crate::gradiometry::{both_maps, locate_pass, map_figures};
use crate::observer::Observer;
use aeromag_gradiometry::config::GradiometerConfig;
use aeromag_gradiometry::convergence::ConvergenceCase;
use aeromag_gradiometry::efficiency::{Efficiency, efficient_locate, monte_carlo, well_posed};
use aeromag_gradiometry::geometry::Layout;
use aeromag_gradiometry::sim::{Gradiometer, SystemMotion, simulate};
use aeromag_report::{Block, LinePlot, ReportSection, Series, Table};
use nalgebra::Vector3;
use serde::Serialize;

/// The gradiometry study. Quick: 12 instead of 40 Monte-Carlo trials per
/// case and a 10³ instead of 16³ convergence map.
#[derive(Debug, Clone, Copy, Default)]
pub struct GradiometryStudy;

/// The `gradiometry` group of the demo's `summary.json`.
#[derive(Debug, Clone, Serialize)]
pub struct GradiometrySummary {
    /// The worst RMS/CRLB of position and moment over the stationary and
    /// mobile tensor systems (goal ≤ 1.2).
    pub efficiency_tensor: f64,
    /// The worst of the moment over both scalar systems.
    pub efficiency_scalar: f64,
    /// Share of the seed's fig. 2 starts from which the multi-start
    /// initialisation converges.
    pub convergence_fraction: f64,
    /// … the plain IEKF.
    pub convergence_fraction_plain: f64,
    /// Monte-Carlo trials per case.
    pub trials: usize,
}

/// The study's figures and its report section.
pub struct GradiometryOutcome {
    summary: GradiometrySummary,
    section: ReportSection,
}

impl Study for GradiometryStudy {
    type Outcome = GradiometryOutcome;

    fn run(&self, size: StudySize, observer: &mut dyn Observer) -> Result<GradiometryOutcome> {
        observer.stage("gradiometry study");
        run_study(size == StudySize::Quick)
    }
}

impl StudyOutcome for GradiometryOutcome {
    type Summary = GradiometrySummary;

    fn summary(&self) -> GradiometrySummary {
        self.summary.clone()
    }

    fn section(&self) -> Result<ReportSection> {
        Ok(self.section.clone())
    }
}

impl PrintedSummary for GradiometrySummary {
    fn printed(&self) -> Vec<PrintedFigure> {
        vec![
            PrintedFigure::new(
                "gradiometry.efficiency_tensor",
                fixed(Some(self.efficiency_tensor), 3),
            ),
            PrintedFigure::new(
                "gradiometry.efficiency_scalar",
                fixed(Some(self.efficiency_scalar), 3),
            ),
            PrintedFigure::new(
                "gradiometry.convergence_fraction",
                fixed(Some(self.convergence_fraction), 4),
            ),
        ]
    }
}

/// Worst block efficiency (position and moment) of a set of runs.
fn worst(runs: &[(String, Efficiency)]) -> f64 {
    runs.iter()
        .flat_map(|(_, e)| e.position.into_iter().chain([e.moment]))
        .fold(0.0, f64::max)
}

fn fmt3(v: Option<f64>) -> String {
    v.map_or("–".into(), |x| format!("{x:.3}"))
}

/// Estimation errors with their ±2σ bands and `MeasureS` over the default
/// pass (tensor, stationary system, realistic: biases, variations, yawing
/// object), from 1 s after the detection on; plots with captions.
fn pass_plots() -> Result<Vec<(LinePlot, String)>> {
    let cfg = GradiometerConfig::default();
    let sim = simulate(&cfg.scenario()?)?;
    let pos: Vec<Vector3<f64>> = sim.iter().map(|e| e.true_position_m).collect();
    let track = locate_pass(&cfg, &sim, &pos)?;
    let from = track.detected.iter().position(|&d| d).map_or(0, |j| j + 10);
    let t: Vec<f64> = sim[from..].iter().map(|e| e.t_s).collect();
    let mut out = Vec::new();
    for (block, unit, title) in [(0, "m", "Position"), (3, "A·m²", "Moment")] {
        let mut p = LinePlot::new(
            format!("{title} error and ±2σ band (body frame)"),
            "time (s)",
            format!("estimate − truth ({unit})"),
        );
        for k in 0..3 {
            let c = aeromag_report::PALETTE[k % aeromag_report::PALETTE.len()];
            let axis = ["x", "y", "z"][k];
            let err: Vec<f64> = (from..sim.len())
                .map(|j| {
                    let truth = if block == 0 {
                        sim[j].true_position_m[k]
                    } else {
                        sim[j].true_moment_am2[k]
                    };
                    track.x[j][block + k] - truth
                })
                .collect();
            let band = |s: f64| -> Vec<f64> {
                track.sd[from..]
                    .iter()
                    .map(|sd| s * 2.0 * sd[block + k])
                    .collect()
            };
            p = p
                .with_series(Series::points(format!("{axis} error"), t.clone(), err).with_color(c))
                .with_series(
                    Series::line(format!("{axis} ±2σ"), t.clone(), band(1.0)).with_color(c),
                )
                .with_series(Series::line("", t.clone(), band(-1.0)).with_color(c));
        }
        out.push((
            p,
            format!(
                "{title} over the default pass (object 6 m east, 2 m below, closest at 30 s): error of \
                 the estimate against the truth (dots) inside the filter's ±2σ band (lines)."
            ),
        ));
    }
    let mut mu = LinePlot::new(
        "Estimability MeasureS over the pass",
        "time (s)",
        "μ = σ⁺/σ⁰",
    );
    for (k, n) in ["x", "y", "z", "Mx", "My", "Mz"].iter().enumerate() {
        mu = mu.with_series(Series::line(
            *n,
            t.clone(),
            track.mu[from..].iter().map(|m| m[k]).collect(),
        ));
    }
    out.push((
        mu,
        format!("Estimability of each component, {CONVENTION} (the convention of the compensation's observability).",),
    ));
    Ok(out)
}

fn pass_figures() -> Result<Vec<Block>> {
    pass_plots()?
        .into_iter()
        .map(|(p, caption)| {
            Ok(Block::Figure {
                svg: p.to_svg()?,
                caption,
            })
        })
        .collect()
}

/// The gradiometry study for `aeromag demo`: the `gradiometry.*` summary
/// object (`efficiency_tensor`: the worst RMS/CRLB of position and moment
/// over the stationary and mobile tensor systems; `efficiency_scalar`: the
/// worst of the moment over both scalar systems; `convergence_fraction`:
/// multi-start share of the seed's fig. 2 starts that converge) and the
/// report section (efficiency table, estimates ± 2σ and `MeasureS` over the
/// default pass, convergence-map slices). `quick`: 12 instead of 40
/// Monte-Carlo trials per case and a 10³ instead of 16³ map.
fn run_study(quick: bool) -> Result<GradiometryOutcome> {
    let (trials, grid) = if quick { (12, 10) } else { (40, 16) };
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get().min(4));
    let mut tensor = Vec::new();
    let mut scalar = Vec::new();
    for motion in [SystemMotion::Stationary, SystemMotion::Mobile] {
        let s = well_posed(motion, Layout::Tetrahedron)?;
        let name = format!("{motion:?}").to_lowercase();
        let lt = efficient_locate(s.vector_sensor.noise_nt)?;
        tensor.push((
            name.clone(),
            monte_carlo(&s, Gradiometer::Tensor, &lt, trials, 1000, threads)?,
        ));
        let ls = efficient_locate(s.scalar_sensor.noise_nt)?;
        scalar.push((
            name,
            monte_carlo(&s, Gradiometer::Scalar, &ls, trials, 2000, threads)?,
        ));
    }
    let case = ConvergenceCase::seed_fig2(grid);
    let maps = both_maps(&case, threads)?;
    let fraction = maps
        .iter()
        .find(|(tag, _, _)| *tag == "multi-start")
        .map_or(f64::NAN, |(_, m, _)| m.converged_fraction());
    let plain = maps
        .iter()
        .find(|(tag, _, _)| *tag == "plain IEKF")
        .map_or(f64::NAN, |(_, m, _)| m.converged_fraction());
    let summary = GradiometrySummary {
        efficiency_tensor: worst(&tensor),
        efficiency_scalar: worst(&scalar),
        convergence_fraction: fraction,
        convergence_fraction_plain: plain,
        trials,
    };
    let mut sec = ReportSection::new("Dipole parameters from gradiometers (seed 004)");
    sec.blocks.push(Block::Paragraph(format!(
        "Monte-Carlo efficiency RMS/CRLB ({trials} trials per case, well-posed 20 m passes, tetrahedron of 1 m) of \
         the square-root IEKF with a windowed multi-start and re-linearised passes: worst {:.3} (tensor), {:.3} \
         (scalar); the goal is ≤ 1.2. Convergence from the seed's fig. 2 starts ({}³ grid): plain IEKF {:.1} %, \
         multi-start {:.1} %.",
        worst(&tensor),
        worst(&scalar),
        grid,
        100.0 * plain,
        100.0 * fraction
    )));
    let rows = tensor
        .iter()
        .map(|r| ("tensor", r))
        .chain(scalar.iter().map(|r| ("scalar", r)))
        .map(|(g, (m, e))| {
            vec![
                g.to_string(),
                m.clone(),
                fmt3(e.position),
                format!("{:.3}", e.moment),
                e.names
                    .iter()
                    .zip(&e.per_parameter)
                    .map(|(n, v)| format!("{n} {v:.2}"))
                    .collect::<Vec<_>>()
                    .join(", "),
            ]
        })
        .collect();
    sec.blocks.push(Block::Table(Table::new(
        [
            "gradiometer",
            "system",
            "position RMS/CRLB",
            "moment RMS/CRLB",
            "per parameter",
        ]
        .map(String::from)
        .to_vec(),
        rows,
        "Efficiency at the end of the pass (1 = efficient).",
    )));
    sec.blocks.extend(pass_figures()?);
    sec.blocks.extend(map_figures(&case, &maps)?);
    Ok(GradiometryOutcome {
        summary,
        section: sec,
    })
}
