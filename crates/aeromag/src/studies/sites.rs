//! The same aircraft calibrated at three sites of different inclination:
//! the share of the permanent, induced and eddy-current parts of its
//! interference per manoeuvre (the thesis' table of contributions, seed
//! `003`, which compares Elista, Brazil and Yakutia).
//!
//! The default calibration box is flown at a mid-latitude site (Elista,
//! 46.3° N 44.3° E), a low-latitude site (the Brazilian interior, 10° S
//! 45° W) and a high-latitude one (Yakutsk, 62.0° N 129.7° E) with the same
//! aircraft and seed; each flight is calibrated by band-pass least squares
//! and [`Contributions`] splits the model's interference by part and
//! manoeuvre, next to the simulator's own parts (truth). The permanent
//! part turns with the heading whatever the site; the induced part follows
//! the field's direction, large where the field is steep and small where it
//! is horizontal; the eddy part follows the field's strength and the
//! manoeuvres' rates.

use super::{PrintedFigure, PrintedSummary, Study, StudyOutcome, StudySize, fixed};
use crate::error::Result;
use crate::observer::{Observer, Silent};
use crate::simulate::{ScenarioKind, simulate_flight};
use crate::tolles_lawson::{CalibrateOptions, Contributions, PartsRms, calibrate};
use aeromag_core::field::igrf::igrf_geodetic;
use aeromag_core::frames::Geodetic;
use aeromag_report::{Block, ReportSection, Table};
use serde::Serialize;

/// The three sites: name, latitude, longitude (degrees).
pub const SITES: [(&str, f64, f64); 3] = [
    ("mid latitude (Elista)", 46.3, 44.3),
    ("low latitude (Brazil)", -10.0, -45.0),
    ("high latitude (Yakutsk)", 62.0, 129.7),
];

/// The study: the demo's calibration box at [`SITES`] with seed `seed`.
#[derive(Debug, Clone, Copy)]
pub struct SitesStudy {
    /// Seed of the simulated flights.
    pub seed: u64,
}

/// One site's figures.
#[derive(Debug, Clone, Serialize)]
pub struct SiteContributions {
    /// The site.
    pub site: String,
    /// Latitude, longitude, degrees.
    pub lat_deg: f64,
    /// Longitude, degrees.
    pub lon_deg: f64,
    /// IGRF inclination at the site, degrees.
    pub inclination_deg: f64,
    /// IGRF total field, nT.
    pub total_field_nt: f64,
    /// The fitted model's parts per manoeuvre.
    pub model: Vec<PartsRms>,
    /// The simulator's parts per manoeuvre (truth).
    pub truth: Vec<PartsRms>,
}

/// `sites` in `summary.json`: per site (`mid`, `low`, `high` latitude)
/// the inclination and the fitted model's parts over the manoeuvres (nT,
/// RMS about each manoeuvre's mean); the tables per manoeuvre, with the
/// truth, are in the report.
#[derive(Debug, Clone, Serialize)]
pub struct SitesSummary {
    /// Inclination at the mid-latitude site, degrees.
    pub inclination_mid_deg: f64,
    /// Inclination at the low-latitude site, degrees.
    pub inclination_low_deg: f64,
    /// Inclination at the high-latitude site, degrees.
    pub inclination_high_deg: f64,
    /// Permanent part at each site (mid, low, high), nT.
    pub permanent_nt: [f64; 3],
    /// Induced part at the mid-latitude site, nT.
    pub induced_mid_nt: f64,
    /// Induced part at the low-latitude site, nT.
    pub induced_low_nt: f64,
    /// Induced part at the high-latitude site, nT.
    pub induced_high_nt: f64,
    /// Eddy part at each site (mid, low, high), nT.
    pub eddy_nt: [f64; 3],
}

/// What the study computed.
pub struct SitesOutcome {
    sites: Vec<SiteContributions>,
    summary: SitesSummary,
}

impl SitesOutcome {
    /// Per site, the parts per manoeuvre (model and truth).
    pub fn sites(&self) -> &[SiteContributions] {
        &self.sites
    }
}

/// The fitted model's `manoeuvres` group of a site.
fn manoeuvres(site: &SiteContributions) -> Option<&PartsRms> {
    site.model.iter().find(|g| g.group == "manoeuvres")
}

impl Study for SitesStudy {
    type Outcome = SitesOutcome;

    fn run(&self, size: StudySize, observer: &mut dyn Observer) -> Result<SitesOutcome> {
        let mut sites = Vec::new();
        for (name, lat, lon) in SITES {
            observer.stage(&format!("sites: {name}"));
            let mut config = format!("[flight]\norigin_lat_deg = {lat}\norigin_lon_deg = {lon}\n");
            if size == StudySize::Quick {
                config.push_str("[pattern]\ncycles = 2\n");
            }
            let flight =
                simulate_flight(ScenarioKind::Calibration, Some(&config), Some(self.seed))?;
            let cal = calibrate(&flight, &CalibrateOptions::default(), &mut Silent)?;
            let model = cal.contributions(&flight)?;
            let truth = Contributions::from_series(
                [
                    flight.require("true_interf_perm")?,
                    flight.require("true_interf_induced")?,
                    flight.require("true_interf_eddy")?,
                    flight.require("true_interf_current")?,
                ],
                flight.column("manoeuvre"),
            );
            let date = aeromag_core::time::Date::parse("2025-06-15")?.decimal_year();
            let f = igrf_geodetic(&Geodetic::new(lat, lon, 3000.0), date)?;
            sites.push(SiteContributions {
                site: name.to_string(),
                lat_deg: lat,
                lon_deg: lon,
                inclination_deg: f.inclination_deg(),
                total_field_nt: f.f_nt(),
                model: model.groups,
                truth: truth.groups,
            });
        }
        let part =
            |k: usize, f: &dyn Fn(&PartsRms) -> f64| manoeuvres(&sites[k]).map_or(f64::NAN, f);
        let summary = SitesSummary {
            inclination_mid_deg: sites[0].inclination_deg,
            inclination_low_deg: sites[1].inclination_deg,
            inclination_high_deg: sites[2].inclination_deg,
            permanent_nt: [0, 1, 2].map(|k| part(k, &|p| p.permanent_nt)),
            induced_mid_nt: part(0, &|p| p.induced_nt),
            induced_low_nt: part(1, &|p| p.induced_nt),
            induced_high_nt: part(2, &|p| p.induced_nt),
            eddy_nt: [0, 1, 2].map(|k| part(k, &|p| p.eddy_nt)),
        };
        Ok(SitesOutcome { sites, summary })
    }
}

impl StudyOutcome for SitesOutcome {
    type Summary = SitesSummary;

    fn summary(&self) -> SitesSummary {
        self.summary.clone()
    }

    fn section(&self) -> Result<ReportSection> {
        let mut sec = ReportSection::new("Contributions of the interference at three sites");
        sec.blocks.push(Block::Paragraph(
            "The same aircraft flies the calibration box at a mid-, a low- and a high-latitude site (the thesis \
             compares Elista, Brazil and Yakutia). Each flight is calibrated by band-pass least squares; the table \
             splits the fitted model's interference into its permanent, induced and eddy-current parts, as the RMS \
             of each part about its mean over each manoeuvre (nT; what the part adds to the manoeuvre), with the \
             simulator's own parts in brackets. The induced part follows the direction of the field: the same \
             manoeuvre induces more where the field is steep. `aeromag calibrate` prints the same table for any \
             calibration flight."
                .into(),
        ));
        let mut rows = Vec::new();
        for s in &self.sites {
            for (m, t) in s.model.iter().zip(&s.truth) {
                if m.group == "between" {
                    continue;
                }
                let cell = |a: f64, b: f64| format!("{a:.3} ({b:.3})");
                rows.push(vec![
                    s.site.clone(),
                    format!("{:.1}°", s.inclination_deg),
                    m.group.clone(),
                    cell(m.permanent_nt, t.permanent_nt),
                    cell(m.induced_nt, t.induced_nt),
                    cell(m.eddy_nt, t.eddy_nt),
                    cell(m.total_nt, t.total_nt),
                ]);
            }
        }
        sec.blocks.push(Block::Table(Table::new(
            [
                "site",
                "inclination",
                "manoeuvre",
                "permanent (nT)",
                "induced (nT)",
                "eddy (nT)",
                "total (nT)",
            ]
            .map(String::from)
            .to_vec(),
            rows,
            "Interference by part and manoeuvre: fitted model (truth).",
        )));
        Ok(sec)
    }
}

impl PrintedSummary for SitesSummary {
    fn printed(&self) -> Vec<PrintedFigure> {
        [
            ("mid", self.induced_mid_nt),
            ("low", self.induced_low_nt),
            ("high", self.induced_high_nt),
        ]
        .into_iter()
        .map(|(k, v)| PrintedFigure::new(format!("sites.induced_{k}_nt"), fixed(Some(v), 3)))
        .collect()
    }
}
