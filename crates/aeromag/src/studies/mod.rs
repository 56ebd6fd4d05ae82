//! Studies: each subsystem's demonstration on simulated data with known
//! truth, run at a size, giving a typed summary (its group of the demo's
//! `summary.json`, and its rows of the printed table) and a report section.
//!
//! `aeromag demo` runs every study ([`Demo`]); the `study` subcommands
//! (`aeromag rotor study`, `aeromag em study`) run one.
//!
//! A study implements [`Study`]; its result implements [`StudyOutcome`].

use crate::error::Result;
use crate::observer::Observer;
use aeromag_report::ReportSection;
use serde::Serialize;

mod demo;
mod em;
mod fixed_wing;
mod gradiometry;
mod maps;
mod multi_sensor;
mod pod;
mod rotor;
mod sites;
mod stream;

pub use demo::{Demo, DemoOutcome, DemoSummary, MAX_DEMO_SEED};
pub use em::{EmOutcome, EmStudy, EmSummary};
pub use fixed_wing::{
    CompensationSummary, FixedWingOutcome, FixedWingStudy, FixedWingSummary, GeologySummary,
    LevellingSummary, PlanningSummary,
};
pub use gradiometry::{GradiometryOutcome, GradiometryStudy, GradiometrySummary};
pub use maps::{MapsOutcome, MapsStudy, MapsSummary};
pub use multi_sensor::{
    CALIBRATION_CYCLES, MultiSensorOutcome, MultiSensorStudy, MultiSensorSummary, SGL_CURRENTS,
    SensorFigures, compensated, line_error_rms, oracle,
};
pub use pod::{MethodRates, PodOutcome, PodStudy, PodSummary};
pub use rotor::{RotorOutcome, RotorStudyRun, RotorSummary, pct};
pub use sites::{SITES, SiteContributions, SitesOutcome, SitesStudy, SitesSummary};
pub use stream::{
    CREEP_AM2_PER_H, CREEP_CLEARANCE_M, CREEP_LINES, StreamOutcome, StreamStudy, StreamSummary,
    WINDOW_S, creeping_scenario,
};

/// How much work a study does: the demo's `--quick` or the full run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum StudySize {
    /// Fewer trials, epochs or grid points; same steps.
    Quick,
    /// The documented figures.
    #[default]
    Full,
}

impl StudySize {
    /// `Quick` when `quick` holds.
    pub fn quick_if(quick: bool) -> Self {
        if quick { Self::Quick } else { Self::Full }
    }
}

/// A demonstration of one subsystem on simulated data.
///
/// ```
/// use aeromag::studies::{PrintedSummary, RotorStudyRun, Study, StudyOutcome, StudySize};
/// use aeromag::Silent;
/// let outcome = RotorStudyRun::default().run(StudySize::Quick, &mut Silent)?;
/// let summary = outcome.summary();
/// // The printed table comes from the same typed summary as summary.json.
/// for row in summary.printed() {
///     println!("{:<40} {:>12}", row.key, row.value);
/// }
/// assert!(summary.residual_model_nt < summary.rotor_rms_nt);
/// # Ok::<(), aeromag::Error>(())
/// ```
pub trait Study {
    /// What a run produces: the full result, with the series its report
    /// section draws.
    type Outcome: StudyOutcome;

    /// Run the study. Progress goes to `observer`.
    fn run(&self, size: StudySize, observer: &mut dyn Observer) -> Result<Self::Outcome>;
}

/// The result of a [`Study`].
pub trait StudyOutcome {
    /// The figures of the study: its group of `summary.json` (units in the
    /// field names).
    type Summary: Serialize + Clone + std::fmt::Debug;

    /// The figures.
    fn summary(&self) -> Self::Summary;

    /// The main report section (text, tables, figures).
    fn section(&self) -> Result<ReportSection>;

    /// Every report section of the study, the main one first (a study with
    /// one section need not implement it).
    fn sections(&self) -> Result<Vec<ReportSection>> {
        Ok(vec![self.section()?])
    }
}

/// One row of a printed summary table: the figure's key in
/// `summary.json` (dotted) and its value as printed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PrintedFigure {
    /// Dotted key, e.g. `rotor.residual_model_nt`.
    pub key: String,
    /// Formatted value.
    pub value: String,
}

impl PrintedFigure {
    /// A row.
    pub fn new(key: impl Into<String>, value: impl Into<String>) -> Self {
        Self {
            key: key.into(),
            value: value.into(),
        }
    }
}

/// A summary that contributes rows to the demo's printed table, read from
/// its typed fields.
pub trait PrintedSummary {
    /// The rows, in order.
    fn printed(&self) -> Vec<PrintedFigure>;
}

/// RMS about the mean of the finite values of `v` (0 without any), the
/// scoring of a residual against the truth, whose mean (a datum no
/// compensation or levelling fixes) does not count.
pub(crate) fn rms_about_mean(v: &[f64]) -> f64 {
    let finite = || v.iter().copied().filter(|x| x.is_finite());
    let n = finite().count().max(1) as f64;
    let m = finite().sum::<f64>() / n;
    (finite().map(|x| (x - m).powi(2)).sum::<f64>() / n).sqrt()
}

/// A number with `digits` decimals, or `—` when there is none (a figure
/// that cannot be computed on this flight).
pub fn fixed(v: Option<f64>, digits: usize) -> String {
    v.map_or("—".into(), |x| format!("{x:.digits$}"))
}

/// A small number in scientific notation with 3 decimals.
pub fn sci(v: f64) -> String {
    format!("{v:.3e}")
}
