//! The demo: every study on built-in simulated data, one typed summary
//! (`summary.json`) and one report.

use super::{
    EmStudy, EmSummary, FixedWingStudy, FixedWingSummary, GradiometryStudy, GradiometrySummary,
    MapsStudy, MapsSummary, MultiSensorStudy, MultiSensorSummary, PodStudy, PodSummary,
    PrintedFigure, PrintedSummary, RotorStudyRun, RotorSummary, SitesStudy, SitesSummary,
    StreamStudy, StreamSummary, Study, StudyOutcome, StudySize,
};
use crate::error::Result;
use crate::observer::Observer;
use aeromag_report::{Report, ReportSection};
use serde::Serialize;
use std::path::PathBuf;

/// The largest seed [`Demo`] takes: 2⁶³ − 2, so that the survey's
/// `seed + 1` is a scenario seed (TOML integers are signed 64-bit). A seed
/// of 2⁶⁴ − 1 wrapped the survey's to 0 in a release build.
pub const MAX_DEMO_SEED: u64 = i64::MAX as u64 - 1;

/// The whole demo: the fixed-wing chain (seed `seed`, survey `seed + 1`;
/// files under `out`), the rotor, pod, EM and gradiometry studies (seed at
/// most [`MAX_DEMO_SEED`]).
#[derive(Debug, Clone)]
pub struct Demo {
    /// Seed of the simulated fixed-wing flights.
    pub seed: u64,
    /// Folder of the fixed-wing study's files.
    pub out: PathBuf,
}

/// `summary.json`: one group per study (keys in `spec/data-formats.md`),
/// the seed and the software version.
#[derive(Debug, Clone, Serialize)]
pub struct DemoSummary {
    /// The fixed-wing groups (`compensation`, `compensation_gradient`,
    /// `compensation_gradient_mild`, `planning`, `levelling`).
    #[serde(flatten)]
    pub fixed_wing: FixedWingSummary,
    /// Helicopter rotor.
    pub rotor: RotorSummary,
    /// Towed pod.
    pub pod: PodSummary,
    /// EM positioning.
    pub em: EmSummary,
    /// Gradiometry.
    pub gradiometry: GradiometrySummary,
    /// Several sensors and the aircraft's currents (SGL-like installation).
    pub multi_sensor: MultiSensorSummary,
    /// On board: causal and adaptive compensation.
    pub stream: StreamSummary,
    /// Maps of the survey.
    pub maps: MapsSummary,
    /// The interference by part at three sites.
    pub sites: SitesSummary,
    /// Seed of the fixed-wing flights.
    pub seed: u64,
    /// Version of aeromag.
    pub software_version: &'static str,
}

impl DemoSummary {
    /// The summary as written to `summary.json`: pretty JSON with the keys
    /// of every object in alphabetical order.
    pub fn to_json(&self) -> Result<String> {
        // A `serde_json::Value` keeps its objects' keys sorted.
        Ok(serde_json::to_string_pretty(&serde_json::to_value(self)?)?)
    }
}

impl PrintedSummary for DemoSummary {
    fn printed(&self) -> Vec<PrintedFigure> {
        let mut rows = self.fixed_wing.printed();
        rows.extend(self.rotor.printed());
        rows.extend(self.pod.printed());
        rows.extend(self.em.printed());
        rows.extend(self.gradiometry.printed());
        rows.extend(self.multi_sensor.printed());
        rows.extend(self.stream.printed());
        rows.extend(self.maps.printed());
        rows.extend(self.sites.printed());
        rows
    }
}

/// What the demo produced: the summary and the report's sections.
pub struct DemoOutcome {
    /// The figures.
    pub summary: DemoSummary,
    /// The report's sections, in order.
    pub sections: Vec<ReportSection>,
}

impl StudyOutcome for DemoOutcome {
    type Summary = DemoSummary;

    fn summary(&self) -> DemoSummary {
        self.summary.clone()
    }

    /// The first section (the fixed-wing summary).
    fn section(&self) -> Result<ReportSection> {
        Ok(self.sections.first().cloned().unwrap_or_default())
    }

    fn sections(&self) -> Result<Vec<ReportSection>> {
        Ok(self.sections.clone())
    }
}

impl Demo {
    /// Every file a run at `size` writes in `out`, relative to it: the
    /// fixed-wing study's simulated flights, models and compensated
    /// flights, and the maps (the command adds its summary and report),
    /// for checking them all before minutes of work.
    pub fn outputs(size: StudySize) -> Vec<PathBuf> {
        let mut files = FixedWingStudy::outputs(size);
        files.extend(MapsStudy::outputs());
        files
    }
}

impl DemoOutcome {
    /// The single-file HTML report.
    pub fn report(&self) -> Report {
        let mut r = Report::new("aeromag demo — simulated calibration and survey");
        for s in &self.sections {
            s.clone().append_to(&mut r);
        }
        r
    }
}

impl Study for Demo {
    type Outcome = DemoOutcome;

    /// Run every study at `size` (quick: the truncated calibration pattern,
    /// fewer trials and grid points).
    fn run(&self, size: StudySize, observer: &mut dyn Observer) -> Result<DemoOutcome> {
        // Checked before minutes of work: the survey's seed `seed + 1`
        // must be a scenario seed too (below 2⁶³), and must not wrap.
        if self.seed > MAX_DEMO_SEED {
            return Err(crate::error::Error::bad_input(format!(
                "demo seed {} is too large: at most {MAX_DEMO_SEED} (the survey uses seed + 1, \
                 and scenario seeds are below 2^63)",
                self.seed
            )));
        }
        let fixed_wing = FixedWingStudy {
            seed: self.seed,
            out: self.out.clone(),
        }
        .run(size, observer)?;
        let rotor = RotorStudyRun::default().run(size, observer)?;
        let em = EmStudy::default().run(size, observer)?;
        let gradiometry = GradiometryStudy.run(size, observer)?;
        let pod = PodStudy.run(size, observer)?;
        let multi_sensor = MultiSensorStudy { seed: self.seed }.run(size, observer)?;
        let stream = StreamStudy { seed: self.seed }.run(size, observer)?;
        let maps = MapsStudy::of(&fixed_wing, Some(self.out.clone()))?.run(size, observer)?;
        let sites = SitesStudy { seed: self.seed }.run(size, observer)?;
        let mut sections = fixed_wing.sections()?;
        sections.extend(rotor.sections()?);
        sections.extend(pod.sections()?);
        sections.extend(em.sections()?);
        sections.extend(gradiometry.sections()?);
        sections.extend(multi_sensor.sections()?);
        sections.extend(stream.sections()?);
        sections.extend(maps.sections()?);
        sections.extend(sites.sections()?);
        Ok(DemoOutcome {
            summary: DemoSummary {
                fixed_wing: fixed_wing.summary(),
                rotor: rotor.summary(),
                pod: pod.summary(),
                em: em.summary(),
                gradiometry: gradiometry.summary(),
                multi_sensor: multi_sensor.summary(),
                stream: stream.summary(),
                maps: maps.summary(),
                sites: sites.summary(),
                seed: self.seed,
                software_version: env!("CARGO_PKG_VERSION"),
            },
            sections,
        })
    }
}
