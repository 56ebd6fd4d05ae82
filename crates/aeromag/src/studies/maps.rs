//! Maps of the demo survey (issue 22): the survey gridded before and after
//! compensation, levelled and micro-levelled, against the truth.
//!
//! The fixed-wing study's survey (compensated by least squares, levelled
//! with the base station and IGRF subtracted) is gridded by minimum
//! curvature (tension 0.25, a quarter of the line spacing rounded down, at
//! the sensor's positions): the uncompensated and compensated readings
//! (base station and IGRF subtracted the same way), the levelled and the
//! micro-levelled columns, and the simulator's noise-free anomaly along
//! the same lines (`true_anomaly`) on the same nodes — the truth map the
//! data could give at best. Figures:
//!
//! - `grid_rms_vs_truth_nt`: RMS of levelled grid − truth grid about its
//!   mean over the nodes not blanked;
//! - `along_line_residual_nt`: RMS of levelled − truth on the lines about
//!   its mean;
//! - `corrugation_reduction`: the line-parallel corrugation power
//!   ([`corrugation_power`]) of the first vertical derivative of the
//!   uncompensated grid over that of the compensated grid (heading
//!   stripes show on the derivative map; no truth used).

use super::{
    FixedWingOutcome, PrintedFigure, PrintedSummary, Study, StudyOutcome, StudySize, fixed,
    rms_about_mean,
};
use crate::error::{Error, Result};
use crate::flight::{Flight, ReferenceChannels, reference_sum};
use crate::map::picture::{MapPicture, tracks};
use crate::map::{GridOptions, MicrolevelOptions, SurveyGrid, grid_flight, microlevel};
use crate::observer::{Observer, Silent};
use aeromag_grid::Grid;
use aeromag_grid::format::write_grid;
use aeromag_grid::products::{Spectral, apply, corrugation_power};
use aeromag_report::{Block, Colormap, ReportSection, Table};
use serde::Serialize;
use std::path::PathBuf;

/// The maps of a levelled survey with truth (module docs).
pub struct MapsStudy {
    /// The survey: `mag`, `mag_comp`, `mag_comp_level`, `diurnal`, `igrf`,
    /// `true_anomaly`, navigation and attitude.
    pub survey: Flight,
    /// The scalar sensor's lever arm, m.
    pub lever_arm_m: [f64; 3],
    /// Folder for the GeoTIFF grids (`maps/…tif`), if any.
    pub out: Option<PathBuf>,
}

impl MapsStudy {
    /// The maps of the fixed-wing study's survey; grids written under `out`.
    pub fn of(fixed_wing: &FixedWingOutcome, out: Option<PathBuf>) -> Result<Self> {
        Ok(Self {
            survey: fixed_wing.levelled_survey()?,
            lever_arm_m: fixed_wing.lever_arm_m(),
            out,
        })
    }
}

/// `maps` in `summary.json`.
#[derive(Debug, Clone, Serialize)]
pub struct MapsSummary {
    /// Node spacing, m.
    pub cell_m: f64,
    /// Line spacing measured from the data, m.
    pub line_spacing_m: f64,
    /// RMS of the levelled grid − the truth grid about its mean, nT.
    pub grid_rms_vs_truth_nt: f64,
    /// RMS of levelled − truth along the lines about its mean, nT.
    pub along_line_residual_nt: f64,
    /// `grid_rms_vs_truth_nt / along_line_residual_nt` (the figure: ≤ 2).
    pub grid_over_along_line: f64,
    /// Corrugation power of the uncompensated grid's first vertical
    /// derivative, (nT/m)².
    pub corrugation_power_uncompensated: f64,
    /// The same for the compensated grid, (nT/m)².
    pub corrugation_power_compensated: f64,
    /// Their ratio (the figure: ≥ 10).
    pub corrugation_reduction: f64,
    /// The truth grid's own corrugation power on the derivative map (the
    /// geology's share of that band, a floor under the compensated map's),
    /// (nT/m)².
    pub corrugation_power_truth: f64,
    /// The stripes alone: the corrugation power of the derivative of
    /// (uncompensated − truth) over that of (compensated − truth).
    pub stripe_reduction_vs_truth: f64,
    /// RMS of the micro-levelling correction on the lines, nT.
    pub microlevel_correction_rms_nt: f64,
    /// RMS of the micro-levelled grid − the truth grid about its mean, nT.
    pub microlevelled_grid_rms_vs_truth_nt: f64,
    /// RMS of the levelled survey's crossover differences before and after
    /// micro-levelling, nT.
    pub microlevel_crossover_rms_nt: Option<(f64, f64)>,
}

/// A map for the report: the grid, its colour-bar label and colour map.
struct Map {
    title: String,
    grid: Grid,
    label: String,
    colormap: Colormap,
}

/// What the maps study computed.
pub struct MapsOutcome {
    summary: MapsSummary,
    maps: Vec<Map>,
    lines: Vec<Vec<(f64, f64)>>,
    written: Vec<PathBuf>,
}

/// The grid minus the mean of its values (blanks stay blank).
fn minus_mean(g: &Grid) -> Grid {
    let m = g.stats().mean;
    Grid {
        values: g.values.iter().map(|v| v - m).collect(),
        ..g.clone()
    }
}

impl Study for MapsStudy {
    type Outcome = MapsOutcome;

    fn run(&self, _size: StudySize, observer: &mut dyn Observer) -> Result<MapsOutcome> {
        observer.stage("maps: gridding the survey");
        let f = &self.survey;
        let refs = ReferenceChannels::Auto.resolve(f)?;
        let sum = reference_sum(f, &refs, None)?;
        let minus_ref = |c: &str| -> Result<Vec<f64>> {
            Ok(f.require(c)?.iter().zip(&sum).map(|(v, r)| v - r).collect())
        };
        let micro = microlevel(
            f,
            &MicrolevelOptions {
                column: Some("mag_comp_level".into()),
                lever_arm_m: Some(self.lever_arm_m),
                ..MicrolevelOptions::default()
            },
            &mut Silent,
        )?;
        let mut table = f.table().clone();
        table.add_column("map_uncompensated", minus_ref("mag")?)?;
        table.add_column("map_compensated", minus_ref("mag_comp")?)?;
        micro.add_to(&mut table)?;
        let flight = Flight::from_table(table)?;
        let base = GridOptions {
            lever_arm_m: Some(self.lever_arm_m),
            ..GridOptions::default()
        };
        let first = grid_flight(
            &flight,
            &GridOptions {
                column: Some("true_anomaly".into()),
                ..base.clone()
            },
            &mut Silent,
        )?;
        let same_nodes = GridOptions {
            geometry: Some(first.grid.geometry),
            blanking_m: Some(first.blanking_m),
            ..base
        };
        let grid = |c: &str| -> Result<SurveyGrid> {
            grid_flight(
                &flight,
                &GridOptions {
                    column: Some(c.into()),
                    ..same_nodes.clone()
                },
                &mut Silent,
            )
        };
        let truth = first;
        let [unc, comp, lev, mlev] = [
            grid("map_uncompensated")?,
            grid("map_compensated")?,
            grid("mag_comp_level")?,
            grid(&micro.output_column())?,
        ];
        let lines = truth
            .survey
            .lines
            .clone()
            .ok_or_else(|| Error::bad_input("the survey has no lines"))?;
        observer.stage("maps: derivatives and corrugation");
        let err = lev.grid.difference(&truth.grid)?;
        let err_micro = mlev.grid.difference(&truth.grid)?;
        let fvd = |g: &Grid| apply(g, Spectral::VerticalDerivative);
        let [d_unc, d_comp, d_truth] = [fvd(&unc.grid)?, fvd(&comp.grid)?, fvd(&truth.grid)?];
        let power = |g: &Grid| corrugation_power(g, lines.direction_deg, lines.spacing_m);
        let (p_unc, p_comp, p_truth) = (power(&d_unc)?, power(&d_comp)?, power(&d_truth)?);
        let stripes =
            |g: &SurveyGrid| -> Result<f64> { Ok(power(&fvd(&g.grid.difference(&truth.grid)?)?)?) };
        let stripe_reduction = stripes(&unc)? / stripes(&comp)?;
        let level = flight.require("mag_comp_level")?;
        let true_anomaly = flight.require("true_anomaly")?;
        let along_line: Vec<f64> = (0..level.len())
            .filter(|&k| truth.survey.on_line(k))
            .map(|k| level[k] - true_anomaly[k])
            .collect();
        let along = rms_about_mean(&along_line);
        let grid_rms = rms_about_mean(&err.values);
        let summary = MapsSummary {
            cell_m: truth.grid.geometry.cell,
            line_spacing_m: lines.spacing_m,
            grid_rms_vs_truth_nt: grid_rms,
            along_line_residual_nt: along,
            grid_over_along_line: grid_rms / along,
            corrugation_power_uncompensated: p_unc,
            corrugation_power_compensated: p_comp,
            corrugation_reduction: p_unc / p_comp,
            corrugation_power_truth: p_truth,
            stripe_reduction_vs_truth: stripe_reduction,
            microlevel_correction_rms_nt: micro.correction_rms_nt,
            microlevelled_grid_rms_vs_truth_nt: rms_about_mean(&err_micro.values),
            microlevel_crossover_rms_nt: micro.crossover_rms_nt,
        };
        let nt = |t: &str, g: &Grid, label: &str, colormap| Map {
            title: t.into(),
            grid: g.clone(),
            label: label.into(),
            colormap,
        };
        let maps = vec![
            nt(
                "Uncompensated (base station and IGRF removed)",
                &unc.grid,
                "nT",
                Colormap::Viridis,
            ),
            nt("Compensated", &comp.grid, "nT", Colormap::Viridis),
            nt(
                "Compensated and levelled",
                &lev.grid,
                "nT",
                Colormap::Viridis,
            ),
            nt(
                "Truth: the noise-free anomaly along the lines",
                &truth.grid,
                "nT",
                Colormap::Viridis,
            ),
            nt(
                "First vertical derivative, uncompensated",
                &d_unc,
                "nT/m",
                Colormap::Diverging,
            ),
            nt(
                "First vertical derivative, compensated",
                &d_comp,
                "nT/m",
                Colormap::Diverging,
            ),
            nt(
                "Levelled − truth (mean removed)",
                &minus_mean(&err),
                "nT",
                Colormap::Diverging,
            ),
            nt(
                "Micro-levelled − truth (mean removed)",
                &minus_mean(&err_micro),
                "nT",
                Colormap::Diverging,
            ),
        ];
        let mut written = Vec::new();
        if let Some(out) = &self.out {
            let dir = out.join("maps");
            std::fs::create_dir_all(&dir).map_err(|e| Error::Write {
                path: dir.clone(),
                source: e,
            })?;
            let grids = [
                &unc.grid,
                &comp.grid,
                &lev.grid,
                &mlev.grid,
                &truth.grid,
                &err,
            ];
            for (path, g) in Self::outputs().into_iter().zip(grids) {
                let path = out.join(path);
                write_grid(&path, g)?;
                written.push(path);
            }
        }
        Ok(MapsOutcome {
            summary,
            maps,
            // Flight lines for the maps, a point every 10 rows.
            lines: tracks(&truth.survey, 10),
            written,
        })
    }
}

impl MapsStudy {
    /// The GeoTIFF files a run with an output folder writes, relative to
    /// it (for checking them before a run, [`super::Demo::outputs`]).
    pub fn outputs() -> Vec<PathBuf> {
        [
            "uncompensated",
            "compensated",
            "levelled",
            "microlevelled",
            "truth",
            "levelled_minus_truth",
        ]
        .map(|name| PathBuf::from(format!("maps/{name}.tif")))
        .into()
    }
}

impl MapsOutcome {
    /// The GeoTIFF files written.
    pub fn written(&self) -> &[PathBuf] {
        &self.written
    }
}

impl StudyOutcome for MapsOutcome {
    type Summary = MapsSummary;

    fn summary(&self) -> MapsSummary {
        self.summary.clone()
    }

    fn section(&self) -> Result<ReportSection> {
        let s = &self.summary;
        let mut sec = ReportSection::new("Maps: from the lines to the grid");
        sec.blocks.push(Block::Paragraph(format!(
            "The demo's survey gridded by minimum curvature (tension 0.25, cell {:.0} m for a line spacing of {:.0} m, \
             at the sensor's positions, blanked beyond one line spacing from the lines). The compensated, levelled \
             grid differs from the truth grid (the noise-free anomaly along the same lines, gridded the same way) by \
             {:.4} nT RMS, against {:.4} nT along the lines ({:.2}×). Heading stripes show on the first vertical \
             derivative: its line-parallel corrugation power (across-line wavelengths 0.8–2.5 line spacings, along-line \
             longer than 4) falls from {:.3e} to {:.3e} (nT/m)² with compensation ({:.1}× less; the truth's own, the geology in that band, is \
             {:.3e}, a floor under the compensated map's). On the difference from the truth grid, where only the \
             stripes remain, compensation reduces that power {:.0}×. Micro-levelling (Minty's filter, one level per line) corrects by {:.4} nT RMS and leaves {:.4} nT against \
             the truth grid ({}){}",
            s.cell_m,
            s.line_spacing_m,
            s.grid_rms_vs_truth_nt,
            s.along_line_residual_nt,
            s.grid_over_along_line,
            s.corrugation_power_uncompensated,
            s.corrugation_power_compensated,
            s.corrugation_reduction,
            s.corrugation_power_truth,
            s.stripe_reduction_vs_truth,
            s.microlevel_correction_rms_nt,
            s.microlevelled_grid_rms_vs_truth_nt,
            s.microlevel_crossover_rms_nt.map_or("no crossovers".into(), |(b, a)| format!(
                "crossover differences {b:.3} → {a:.3} nT RMS"
            )),
            if s.microlevelled_grid_rms_vs_truth_nt > s.grid_rms_vs_truth_nt {
                ": here it does harm. The lines undersample the geology (an anomaly crossed by one line \
                 only is a stripe along it on the grid, and the lines' mean anomaly differs from line to line), \
                 which no filter can tell from a level error; micro-levelling is for surveys whose corrugation \
                 after levelling exceeds that."
            } else {
                "."
            },
        )));
        sec.blocks.push(Block::Table(Table::new(
            vec!["figure".into(), "value".into()],
            vec![
                vec![
                    "grid − truth (nT)".into(),
                    format!("{:.4}", s.grid_rms_vs_truth_nt),
                ],
                vec![
                    "along-line residual (nT)".into(),
                    format!("{:.4}", s.along_line_residual_nt),
                ],
                vec![
                    "corrugation reduction by compensation".into(),
                    format!("{:.1}", s.corrugation_reduction),
                ],
                vec![
                    "micro-levelling correction RMS (nT)".into(),
                    format!("{:.4}", s.microlevel_correction_rms_nt),
                ],
            ],
            "Map figures.",
        )));
        for m in &self.maps {
            let h = MapPicture {
                title: m.title.clone(),
                label: m.label.clone(),
                colormap: m.colormap,
                shaded: m.colormap == Colormap::Viridis,
                tracks: self.lines.clone(),
            }
            .heatmap(&m.grid);
            sec.blocks.push(Block::Figure {
                svg: h.to_svg()?,
                caption: format!(
                    "{} ({}, UTM coordinates; flight lines in grey).",
                    m.title,
                    m.grid.crs.map_or("no CRS".into(), |c| c.name())
                ),
            });
        }
        Ok(sec)
    }
}

impl PrintedSummary for MapsSummary {
    fn printed(&self) -> Vec<PrintedFigure> {
        vec![
            PrintedFigure::new(
                "maps.grid_rms_vs_truth_nt",
                fixed(Some(self.grid_rms_vs_truth_nt), 4),
            ),
            PrintedFigure::new(
                "maps.along_line_residual_nt",
                fixed(Some(self.along_line_residual_nt), 4),
            ),
            PrintedFigure::new(
                "maps.corrugation_reduction",
                fixed(Some(self.corrugation_reduction), 1),
            ),
        ]
    }
}
