//! The towed-pod study (seed 002): every solve fitted on the seed's
//! learning headings and applied to an independent heading set, the
//! compensation rate per heading (the demo's `pod` group).

use super::{PrintedFigure, PrintedSummary, Study, StudyOutcome, StudySize, fixed};
use crate::error::Result;
use crate::flight::Flight;
use crate::observer::{Observer, Silent};
use crate::pod::{HeadingRate, PodApplied, PodMethod, PodSetup, apply_pod, fit_pod};
use crate::simulate::{ScenarioKind, simulate_flight};
use aeromag_compensation::pod::detrend;
use aeromag_report::{Block, LinePlot, ReportSection, Series, Table};
use aeromag_sim::scenario::pod::{PodConfig, TEST_HEADINGS_DEG};
use serde::Serialize;

/// The pod study: the seed's stated conditions (`PodConfig::seed_002`:
/// the default scenario with the swing a 5° sinusoid; learning headings,
/// seed 1) and the independent heading set (seed 1001) simulated in
/// memory, every method fitted and applied. It has one size.
#[derive(Debug, Clone, Copy, Default)]
pub struct PodStudy;

/// The rates of one solve (fractions, not %): the worst and the mean
/// heading of the learning and of the test set, and the test set pooled.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MethodRates {
    /// Worst learning heading.
    pub train: f64,
    /// Worst test heading.
    pub test: f64,
    /// Mean over the learning headings.
    pub train_mean: f64,
    /// Mean over the test headings.
    pub test_mean: f64,
    /// Over all test samples.
    pub test_pooled: f64,
}

/// The `pod` group of the demo's `summary.json`: `rate_train` and
/// `rate_test` are the worst heading of the dipole-array solve (the
/// improved method); `…_two_step` the seed's solve, `…_joint` the joint
/// one; `…_mean` the mean over headings, `rate_test…_pooled` the test set's
/// samples pooled. Fractions.
#[derive(Debug, Clone, Serialize)]
pub struct PodSummary {
    /// Dipole array, worst learning heading.
    pub rate_train: f64,
    /// Dipole array, worst test heading.
    pub rate_test: f64,
    /// Dipole array, mean learning heading.
    pub rate_train_mean: f64,
    /// Dipole array, mean test heading.
    pub rate_test_mean: f64,
    /// Dipole array, test samples pooled.
    pub rate_test_pooled: f64,
    /// Two-step (seed), worst learning heading.
    pub rate_train_two_step: f64,
    /// Two-step, worst test heading.
    pub rate_test_two_step: f64,
    /// Two-step, mean learning heading.
    pub rate_train_two_step_mean: f64,
    /// Two-step, mean test heading.
    pub rate_test_two_step_mean: f64,
    /// Two-step, test samples pooled.
    pub rate_test_two_step_pooled: f64,
    /// Joint, worst learning heading.
    pub rate_train_joint: f64,
    /// Joint, worst test heading.
    pub rate_test_joint: f64,
    /// Joint, mean learning heading.
    pub rate_train_joint_mean: f64,
    /// Joint, mean test heading.
    pub rate_test_joint_mean: f64,
    /// Joint, test samples pooled.
    pub rate_test_joint_pooled: f64,
    /// Two-step, worst test heading, at 0° inclination (level flight at
    /// the magnetic equator, where the axes are reordered).
    pub rate_test_inclination_0: f64,
    /// Two-step, worst test heading at each of [`INCLINATIONS_DEG`]:
    /// `(inclination °, rate)`.
    pub rate_test_by_inclination: Vec<(f64, f64)>,
    /// Always `fraction`.
    pub rate_unit: &'static str,
}

/// The inclinations of the equator sweep, degrees.
pub const INCLINATIONS_DEG: [f64; 5] = [0.0, 5.0, 30.0, 60.0, 85.0];

/// The study's result: each solve's learning rates and its application to
/// the test flight.
pub struct PodOutcome {
    results: Vec<MethodRun>,
    test: Flight,
    /// Two-step worst test-heading rate per inclination.
    by_inclination: Vec<(f64, f64)>,
}

impl PodOutcome {
    /// The rates of `method`.
    pub fn rates(&self, method: PodMethod) -> Option<MethodRates> {
        let worst = |v: &[HeadingRate]| v.iter().map(|h| h.rate).fold(f64::INFINITY, f64::min);
        let mean =
            |v: &[HeadingRate]| v.iter().map(|h| h.rate).sum::<f64>() / v.len().max(1) as f64;
        self.results
            .iter()
            .find(|(m, _, _)| *m == method)
            .map(|(_, train, applied)| MethodRates {
                train: worst(train),
                test: worst(&applied.per_heading),
                train_mean: mean(train),
                test_mean: mean(&applied.per_heading),
                test_pooled: applied.pooled,
            })
    }
}

impl Study for PodStudy {
    type Outcome = PodOutcome;

    fn run(&self, _size: StudySize, observer: &mut dyn Observer) -> Result<PodOutcome> {
        observer.stage("pod study");
        let cfg = PodConfig::seed_002();
        let setup = PodSetup {
            cable_length_m: cfg.cable_m,
            attach_m: cfg.attach_m,
            inclination_deg: cfg.inclination_deg,
            declination_deg: cfg.declination_deg,
            grad_north_nt_per_km: cfg.grad_north_nt_per_km,
            grad_up_nt_per_km: cfg.grad_up_nt_per_km,
        };
        let train_toml = cfg.to_toml()?;
        let test_toml = PodConfig {
            headings_deg: TEST_HEADINGS_DEG.to_vec(),
            ..cfg.clone()
        }
        .to_toml()?;
        let train = simulate_flight(ScenarioKind::Pod, Some(&train_toml), Some(cfg.seed))?;
        let test = simulate_flight(ScenarioKind::Pod, Some(&test_toml), Some(cfg.seed + 1000))?;
        // The seed's solve from the magnetic equator to the pole: the same
        // scenario at each inclination.
        let mut by_inclination = Vec::new();
        for inclination in INCLINATIONS_DEG {
            observer.stage(&format!("pod study: inclination {inclination}°"));
            let c = PodConfig {
                inclination_deg: inclination,
                ..cfg.clone()
            };
            let tr = simulate_flight(ScenarioKind::Pod, Some(&c.to_toml()?), Some(c.seed))?;
            let te_toml = PodConfig {
                headings_deg: TEST_HEADINGS_DEG.to_vec(),
                ..c.clone()
            }
            .to_toml()?;
            let te = simulate_flight(ScenarioKind::Pod, Some(&te_toml), Some(c.seed + 1000))?;
            let s = PodSetup {
                inclination_deg: inclination,
                ..setup
            };
            let model = fit_pod(&tr, &s, PodMethod::TwoStep, None, &mut Silent)?.model;
            let applied = apply_pod(&model, &te)?;
            let worst = applied
                .per_heading
                .iter()
                .map(|h| h.rate)
                .fold(f64::INFINITY, f64::min);
            by_inclination.push((inclination, worst));
        }
        let results = PodMethod::ALL
            .into_iter()
            .map(|m| {
                let model = fit_pod(&train, &setup, m, None, &mut Silent)?.model;
                let applied = apply_pod(&model, &test)?;
                Ok((m, model.learning, applied))
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(PodOutcome {
            results,
            test,
            by_inclination,
        })
    }
}

impl StudyOutcome for PodOutcome {
    type Summary = PodSummary;

    fn summary(&self) -> PodSummary {
        let r = |m| {
            self.rates(m).unwrap_or(MethodRates {
                train: f64::NAN,
                test: f64::NAN,
                train_mean: f64::NAN,
                test_mean: f64::NAN,
                test_pooled: f64::NAN,
            })
        };
        let (d, t, j) = (
            r(PodMethod::DipoleArray),
            r(PodMethod::TwoStep),
            r(PodMethod::Joint),
        );
        PodSummary {
            rate_train: d.train,
            rate_test: d.test,
            rate_train_mean: d.train_mean,
            rate_test_mean: d.test_mean,
            rate_test_pooled: d.test_pooled,
            rate_train_two_step: t.train,
            rate_test_two_step: t.test,
            rate_train_two_step_mean: t.train_mean,
            rate_test_two_step_mean: t.test_mean,
            rate_test_two_step_pooled: t.test_pooled,
            rate_train_joint: j.train,
            rate_test_joint: j.test,
            rate_train_joint_mean: j.train_mean,
            rate_test_joint_mean: j.test_mean,
            rate_test_joint_pooled: j.test_pooled,
            rate_test_inclination_0: self
                .by_inclination
                .iter()
                .find(|(i, _)| *i == 0.0)
                .map_or(f64::NAN, |(_, r)| *r),
            rate_test_by_inclination: self.by_inclination.clone(),
            rate_unit: "fraction",
        }
    }

    fn section(&self) -> Result<ReportSection> {
        let mut sec = pod_section(&self.results, &self.test)?;
        sec.blocks.push(Block::Paragraph(
            "Near the magnetic equator the field is nearly horizontal in level flight and the seed's elimination \
             of the third direction cosine (division by U3) fails; as the seed prescribes for that case, the axes \
             are reordered: the component of U with the largest magnitude is eliminated. The seed's two-step \
             solve on the same scenario at each inclination (worst independent test heading):"
                .into(),
        ));
        sec.blocks.push(Block::Table(Table::new(
            vec!["inclination (°)".into(), "worst test rate (%)".into()],
            self.by_inclination
                .iter()
                .map(|(i, r)| vec![format!("{i:.0}"), format!("{:.2}", 100.0 * r)])
                .collect(),
            "Two-step solve from the equator to the pole.",
        )));
        Ok(sec)
    }
}

impl PrintedSummary for PodSummary {
    fn printed(&self) -> Vec<PrintedFigure> {
        vec![
            PrintedFigure::new("pod.rate_train (fraction)", fixed(Some(self.rate_train), 4)),
            PrintedFigure::new("pod.rate_test (fraction)", fixed(Some(self.rate_test), 4)),
            PrintedFigure::new(
                "pod.rate_test_inclination_0 (fraction)",
                fixed(Some(self.rate_test_inclination_0), 4),
            ),
        ]
    }
}

/// One solve of the demo: method, learning rates, result on the test set.
type MethodRun = (PodMethod, Vec<HeadingRate>, PodApplied);

fn pod_section(results: &[MethodRun], test: &Flight) -> Result<ReportSection> {
    let mut sec = ReportSection::new("Towed pod: compensation rate per heading (seed 002)");
    sec.blocks.push(Block::Paragraph(
        "The seed's simulation (|B| = 55 000 nT, inclination 45°, gradients 5.91 / −25.91 nT/km, 100 m/s, \
         pitch, roll and yaw manoeuvres of 5° at 0.1 Hz, 20 Hz, 40 m cable at 70°, swing a 5° sinusoid at the \
         pendulum frequency; `PodConfig::seed_002`): learned on the \
         headings 0, 90, 180, 270, 45, 135, 225, 315° (seed 1), compensated on the independent set 30, 120, \
         210, 300, 70, 160, 250, 340° (seed 1001). Rate = 1 − RMS(after)/RMS(before), both detrended per \
         heading, after the known gradient term; the pooled rate takes RMS over all samples of the test set. \
         Two-step: the seed's solve with its pod trajectory (eqs. 7–8); joint: the large-signal model with the \
         gradient of the eddy-current field that the seed's eqs. 10–12 omit (67 parameters) in one fit with the \
         exact trajectory; dipole array: equivalent dipoles whose field is evaluated exactly at the swinging \
         pod. The seed's solve reaches its \"above 90 %\" on the test set as a whole, but not on every heading: \
         a 5° manoeuvre moves the pod by metres in the body frame, and its first-order heading coefficients \
         cannot carry the resulting second-order terms. The degradation with noise, swing, eddy currents and \
         heading count is tabulated in the library docs of `aeromag_compensation::pod`."
            .into(),
    ));
    let mut rows = Vec::new();
    for (m, train, applied) in results {
        for (set, r, pooled) in [
            ("learning", train, None),
            ("test", &applied.per_heading, Some(applied.pooled)),
        ] {
            let mut row = vec![m.name().to_string(), set.to_string()];
            let worst = r.iter().map(|h| h.rate).fold(f64::INFINITY, f64::min);
            row.push(format!("{:.2}", 100.0 * worst));
            row.push(pooled.map_or("–".into(), |p| format!("{:.2}", 100.0 * p)));
            row.push(
                r.iter()
                    .map(|h| format!("{:.0}°: {:.1}", h.heading_deg, 100.0 * h.rate))
                    .collect::<Vec<_>>()
                    .join(", "),
            );
            rows.push(row);
        }
    }
    sec.blocks.push(Block::Table(Table::new(
        [
            "method",
            "heading set",
            "worst rate (%)",
            "pooled rate (%)",
            "rate per heading (%)",
        ]
        .map(String::from)
        .to_vec(),
        rows,
        "Compensation rate per heading for each solve.",
    )));
    let mut plot = LinePlot::new("Compensation rate per heading", "heading (deg)", "rate (%)");
    for (m, train, applied) in results {
        for (set, r) in [("learning", train), ("test", &applied.per_heading)] {
            plot = plot.with_series(Series::points(
                format!("{} ({set})", m.name()),
                r.iter().map(|h| h.heading_deg).collect(),
                r.iter().map(|h| 100.0 * h.rate).collect(),
            ));
        }
    }
    sec.blocks.push(Block::Figure {
        svg: plot.to_svg()?,
        caption: "Rate per heading: learning headings and the independent test headings.".into(),
    });
    // Waveforms on the first test heading: detrended field minus the
    // gradient term before, and what each solve leaves.
    if let (Some(first), Ok(mag), Ok(ext), Ok(time)) = (
        results.first().and_then(|r| r.2.per_heading.first()),
        test.require("mag"),
        test.require("true_external"),
        test.require("time"),
    ) {
        let r = first.rows[0]..first.rows[1];
        let before = detrend(&r.clone().map(|k| mag[k] - ext[k]).collect::<Vec<_>>());
        let t: Vec<f64> = time[r.clone()].iter().map(|x| x - time[r.start]).collect();
        let mut p = LinePlot::new(
            format!(
                "Test heading {:.0}°: pod interference before and after",
                first.heading_deg
            ),
            "time (s)",
            "nT (detrended)",
        )
        .with_series(Series::line("before", t.clone(), before));
        for (m, _, applied) in results {
            let after = detrend(
                &r.clone()
                    .map(|k| mag[k] - ext[k] - applied.interf_nt[k])
                    .collect::<Vec<_>>(),
            );
            p = p.with_series(Series::line(
                format!("after {}", m.name()),
                t.clone(),
                after,
            ));
        }
        sec.blocks.push(Block::Figure {
            svg: p.to_svg()?,
            caption: "Pod reading minus the Earth field (truth, scoring only), detrended, before and after each \
                      solve."
                .into(),
        });
    }
    Ok(sec)
}
