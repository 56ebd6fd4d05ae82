//! `aeromag demo`: the whole chain on built-in simulated data.

use crate::analysis::{Figures, add_to_report, figures};
use crate::commands::calibrate::{EddyLag, FitOptions, fit_model, fit_model_kalman};
use crate::commands::compensate::compensate_table;
use crate::commands::level::level_table;
use crate::input::load;
use crate::kalman_report::{KalmanRows, kalman_section};
use aeromag_compensation::kalman::KalmanConfig;
use aeromag_compensation::levelling::LevellingConfig;
use aeromag_compensation::model_file::TlModel;
use aeromag_compensation::observability::{Observability, observability};
use aeromag_compensation::reference_field::LeverArm;
use aeromag_compensation::tolles_lawson::fit_ls::LsConfig;
use aeromag_io::FlightTable;
use aeromag_report::Report;
use aeromag_sim::{ScenarioKind, simulate};
use serde_json::json;
use std::path::PathBuf;
use std::time::Instant;

/// Run aeromag end to end on simulated data with known truth.
///
/// Simulates a calibration box (four headings with roll, pitch and yaw
/// manoeuvres) over a quiet area and over realistic geology, and an
/// independent survey flight with the same aircraft; fits the Tolles-Lawson
/// model on each calibration flight by band-pass least squares and by the
/// Kalman method, compensates the survey, scores the result
/// against the simulator's truth, prints a summary table, and writes
/// DIR/summary.json, DIR/index.html (single-file report, plots inline), the
/// model file and the simulated and compensated data.
///
/// Example: `aeromag demo --out demo-out`
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct Args {
    /// Output folder.
    #[arg(long, default_value = "demo-out", value_name = "DIR")]
    out: PathBuf,
    /// Seed of the simulated flights (the survey uses seed + 1).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Smaller, faster run (same steps).
    #[arg(long)]
    quick: bool,
}

/// A calibration box flown over geology instead of the quiet default area,
/// scored on the same independent survey.
struct GeologyArea {
    /// Group of `summary.json` (`data-formats.md`).
    key: &'static str,
    /// Folder of its data under `DIR/data`.
    dir: &'static str,
    /// Row label in the report.
    label: &'static str,
    /// Scenario overrides of the `calibration` scenario.
    toml: &'static str,
}

/// The calibrations over geology. At the default 3000 m the anomaly field is
/// continued up so far that nothing of it is left in the 0.1–0.9 Hz
/// calibration band and both methods see a quiet area, so the box is flown
/// lower:
///
/// - `compensation_gradient`, the spec's "calibration area with realistic
///   anomaly gradients": 300 m over geology of 10 nT/100 m at 100 m above
///   ground, 8.8 nT/100 m expected at the box's height (the spec calls
///   1–10 nT/100 m realistic). Here the geology costs LS about 0.04 nT,
///   well above the 0.011 nT sensor noise, and the Kalman method's survey
///   residual is at most half of LS's (seeds 1–10: ratio 0.20–0.44).
/// - `compensation_gradient_mild`: 1000 m over the simulator's preset
///   realistic area (3 nT/100 m at 100 m, 1.0 nT/100 m at the box). LS
///   loses only a few 10⁻³ nT to the geology; the Kalman method's
///   interference model is still better, but both survey residuals sit on
///   the sensor noise (ratio 0.65–0.99 on seeds 1–5).
const GEOLOGY_AREAS: [GeologyArea; 2] = [
    GeologyArea {
        key: "compensation_gradient",
        dir: "gradient_area",
        label: "realistic gradients",
        toml: "[pattern]\naltitude_m = 300.0\n[anomaly]\narea = \"realistic\"\ngradient_rms_nt_per_100m = 10.0\n",
    },
    GeologyArea {
        key: "compensation_gradient_mild",
        dir: "gradient_area_mild",
        label: "mild gradients",
        toml: "[pattern]\naltitude_m = 1000.0\n[anomaly]\narea = \"realistic\"\n",
    },
];

/// One calibration over geology, fitted by both methods and scored.
struct GeologyResult {
    /// The calibration flight as read back.
    table: FlightTable,
    ls: TlModel,
    kalman: TlModel,
    rows: KalmanRows,
    /// Survey residual (LS, Kalman), nT.
    residual: [Option<f64>; 2],
    /// Interference-model error on the survey (LS, Kalman), nT.
    interference: [Option<f64>; 2],
    /// Altitude of the box, m above ground, and the expected RMS horizontal
    /// anomaly gradient there, nT/100 m (from the truth file; a description
    /// of the scenario, never read by the estimators).
    altitude_m: Option<f64>,
    gradient_nt_per_100m: Option<f64>,
}

/// `pattern.altitude_m` of a written scenario and the truth file's
/// `anomaly.expected_gradient_nt_per_100m_at_flight_height`.
fn box_geology(files: &aeromag_sim::WrittenFiles) -> anyhow::Result<(Option<f64>, Option<f64>)> {
    let alt = scenario_toml(&files.scenario)?
        .get("pattern")
        .and_then(|p| p.get("altitude_m"))
        .and_then(|x| x.as_float());
    let truth: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&files.truth)?)?;
    Ok((
        alt,
        truth["anomaly"]["expected_gradient_nt_per_100m_at_flight_height"].as_f64(),
    ))
}

/// A small number from a JSON object, in scientific notation.
fn sci(v: &serde_json::Value, key: &str) -> String {
    v[key].as_f64().map_or("—".into(), |x| format!("{x:.3e}"))
}

fn fmt(v: Option<f64>, digits: usize) -> String {
    v.map_or("—".into(), |x| format!("{x:.digits$}"))
}

/// A written scenario file, parsed.
fn scenario_toml(scenario: &std::path::Path) -> anyhow::Result<toml::Value> {
    Ok(toml::from_str(&std::fs::read_to_string(scenario)?)?)
}

/// The scalar sensor's lever arm (`scalar.position_m`, body frame, m) and
/// the flight date (`flight.date`) from a scenario file.
fn installation(scenario: &std::path::Path) -> anyhow::Result<LeverArm> {
    let v = scenario_toml(scenario)?;
    let arm = v
        .get("scalar")
        .and_then(|s| s.get("position_m"))
        .and_then(|p| p.as_array())
        .and_then(|a| a.iter().map(|x| x.as_float()).collect::<Option<Vec<f64>>>())
        .and_then(|a| <[f64; 3]>::try_from(a).ok())
        .ok_or_else(|| anyhow::anyhow!("{}: no scalar.position_m", scenario.display()))?;
    let date = v
        .get("flight")
        .and_then(|f| f.get("date"))
        .and_then(|d| d.as_str())
        .ok_or_else(|| anyhow::anyhow!("{}: no flight.date", scenario.display()))?;
    Ok(LeverArm {
        arm_m: arm,
        decimal_year: aeromag_core::time::Date::parse(date)?.decimal_year(),
    })
}

/// The scalar sensor's lag (s) of a written survey scenario: the truth of
/// the levelling's k (`k = −lag`). Read for scoring only.
fn survey_lag_s(scenario: &std::path::Path) -> anyhow::Result<f64> {
    scenario_toml(scenario)?
        .get("scalar")
        .and_then(|s| s.get("lag_s"))
        .and_then(|x| x.as_float())
        .ok_or_else(|| anyhow::anyhow!("{}: no scalar.lag_s", scenario.display()))
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let start = Instant::now();
    let data = a.out.join("data");
    std::fs::create_dir_all(&data)?;
    let bar = crate::progress::bar(6, "demo");
    if a.quick {
        eprintln!("--quick: the truncated calibration pattern is used");
    }

    // 1. Simulate: a quiet calibration area (the default), the same aircraft
    //    calibrated over realistic geology, and an independent survey.
    bar.set_message("simulating");
    let cal_kind = if a.quick {
        ScenarioKind::CalibrationTruncated
    } else {
        ScenarioKind::Calibration
    };
    let cal_files = simulate(cal_kind, None, Some(a.seed))?.write_to_dir(&data)?;
    let geology_files = GEOLOGY_AREAS
        .iter()
        .map(|g| {
            Ok(simulate(cal_kind, Some(g.toml), Some(a.seed))?.write_to_dir(&data.join(g.dir))?)
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let survey_files =
        simulate(ScenarioKind::Survey, None, Some(a.seed + 1))?.write_to_dir(&data)?;
    bar.inc(1);

    // 2. Calibrate by both methods (reading the files back, as a user would).
    bar.set_message("calibrating");
    // The installation, as the user knows it: the scalar sensor's lever arm
    // from the navigation point and the flight date (scenario file).
    let opts = FitOptions {
        lever_arm: Some(installation(&cal_files.scenario)?),
        ..FitOptions::auto()
    };
    let fit_both =
        |path: &std::path::Path| -> anyhow::Result<(FlightTable, TlModel, TlModel, KalmanRows)> {
            // The fits' notes (lag choice, altitude cleaning) follow this line.
            eprintln!("fitting {}", path.display());
            let t = load(path, None)?;
            let ls = fit_model(&t, &LsConfig::default(), &opts)?;
            // The Kalman method as `calibrate --method kalman` runs it: its own
            // lag choice (after a first pass has removed the field) and noise
            // intensities tuned by maximum likelihood.
            let mut kf_cfg = KalmanConfig::default();
            kf_cfg.tuning.enabled = true;
            let (kf, fit, rows) = fit_model_kalman(&t, &kf_cfg, &opts)?;
            Ok((t, ls, kf, KalmanRows { fit, rows }))
        };
    let (mut cal, model, model_kf, _) = fit_both(&cal_files.csv)?;
    let geology_fits = geology_files
        .iter()
        .map(|f| fit_both(&f.csv))
        .collect::<anyhow::Result<Vec<_>>>()?;
    std::fs::write(a.out.join("model_ls.json"), model.to_json()?)?;
    std::fs::write(a.out.join("model_kalman.json"), model_kf.to_json()?)?;
    bar.inc(1);

    // 3. Compensate.
    bar.set_message("compensating");
    let survey_raw = load(&survey_files.csv, None)?;
    let compensated = |m: &TlModel| -> anyhow::Result<FlightTable> {
        let mut t = survey_raw.clone();
        compensate_table(m, &mut t)?;
        Ok(t)
    };
    compensate_table(&model, &mut cal)?;
    let survey = compensated(&model)?;
    aeromag_io::write_csv(&cal, &a.out.join("calibration_comp.csv"))?;
    aeromag_io::write_csv(&survey, &a.out.join("survey_comp.csv"))?;
    bar.inc(1);

    // 4. Score.
    bar.set_message("scoring");
    let fc: Figures = figures(&cal, &model.reference, model.lever_arm.as_ref())?;
    let fsv: Figures = figures(&survey, &model.reference, model.lever_arm.as_ref())?;
    // The survey residual and the interference-model error of a model.
    let scores = |m: &TlModel| -> anyhow::Result<[Option<f64>; 2]> {
        let f = figures(&compensated(m)?, &m.reference, m.lever_arm.as_ref())?;
        Ok([f.residual_rms_nt, f.interference_rms_nt])
    };
    let residual = |m: &TlModel| -> anyhow::Result<Option<f64>> { Ok(scores(m)?[0]) };
    let [res_kf, int_kf] = scores(&model_kf)?;

    // Calibration planning (thesis fig. 2): the truncated pattern against the
    // full one — flight time, estimability of every coefficient, and the
    // residual each leaves on the independent survey.
    let plan = if a.quick {
        None
    } else {
        let trunc_files = simulate(ScenarioKind::CalibrationTruncated, None, Some(a.seed))?
            .write_to_dir(&data)?;
        let (trunc, trunc_ls, trunc_kf, _) = fit_both(&trunc_files.csv)?;
        let cfg = KalmanConfig {
            compute_series: false,
            ..KalmanConfig::default()
        };
        let obs = |t: &FlightTable, pattern: &str| -> anyhow::Result<Observability> {
            eprintln!("estimability of the {pattern} pattern");
            let (_, f, _) = fit_model_kalman(
                t,
                &cfg,
                &FitOptions {
                    eddy_lag: EddyLag::None,
                    ..opts.clone()
                },
            )?;
            Ok(observability(
                &f.names,
                &f.prior_covariance,
                &f.posterior_covariance,
                1e6,
            )?)
        };
        let duration = |t: &FlightTable| -> anyhow::Result<f64> {
            let time = t.require("time")?;
            Ok(time.last().copied().unwrap_or(0.0) - time.first().copied().unwrap_or(0.0))
        };
        let full_table = load(&cal_files.csv, None)?;
        Some((
            [duration(&full_table)?, duration(&trunc)?],
            [obs(&full_table, "full")?, obs(&trunc, "truncated")?],
            [fsv.residual_rms_nt, residual(&trunc_ls)?],
            [res_kf, residual(&trunc_kf)?],
        ))
    };
    let quiet_box = box_geology(&cal_files)?;
    let geology = geology_fits
        .into_iter()
        .zip(&geology_files)
        .map(|((table, ls, kalman, rows), files)| {
            let ([res_ls, int_ls], [res_kf, int_kf]) = (scores(&ls)?, scores(&kalman)?);
            let (altitude_m, gradient_nt_per_100m) = box_geology(files)?;
            Ok(GeologyResult {
                table,
                ls,
                kalman,
                rows,
                residual: [res_ls, res_kf],
                interference: [int_ls, int_kf],
                altitude_m,
                gradient_nt_per_100m,
            })
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    // Levelling of the compensated survey at its crossovers (`aeromag level
    // --lever-arm … --reference auto`, and without the base station).
    let lever = opts.lever_arm.as_ref().map(|l| l.arm_m);
    let level_cfg = LevellingConfig::default();
    let lev = level_table(&survey, "mag_comp", None, lever, "auto", &level_cfg)?.levelling;
    let lev_none = level_table(&survey, "mag_comp", None, lever, "none", &level_cfg)?.levelling;
    let survey_lag = survey_lag_s(&survey_files.scenario)?;
    bar.inc(1);

    // Helicopter rotor and EM bird positioning.
    bar.set_message("rotor, pod, EM and gradiometry studies");
    let (rotor_keys, rotor_section) = crate::commands::rotor::demo_rotor(a.quick)?;
    let (em_keys, em_section) = crate::commands::em::demo_em(a.quick)?;
    let (grad_keys, grad_section) = crate::commands::dipole::demo_gradiometry(a.quick)?;
    let (pod_keys, pod_section) = crate::commands::pod::demo_pod(a.quick)?;
    bar.inc(1);

    // 5. Report.
    bar.set_message("writing report");
    let mut summary = json!({
        "compensation": {
            "residual_rms_ls_nt": fsv.residual_rms_nt,
            "residual_rms_kalman_nt": res_kf,
            "interference_rms_ls_nt": fsv.interference_rms_nt,
            "interference_rms_kalman_nt": int_kf,
            "noise_floor_nt": fsv.noise_floor_nt,
            "fom_before_nt": fc.fom_before_nt,
            "fom_after_nt": fc.fom_after_nt,
            "ir": fc.ir,
            "fom_windows": fc.fom_windows,
            "calibration_residual_rms_ls_nt": fc.residual_rms_nt,
            "survey_ir": fsv.ir,
        },
        "planning": plan.as_ref().map(|(d, o, ls, kf)| json!({
            "duration_full_s": d[0],
            "duration_truncated_s": d[1],
            "residual_rms_ls_full_nt": ls[0],
            "residual_rms_ls_truncated_nt": ls[1],
            "residual_rms_kalman_full_nt": kf[0],
            "residual_rms_kalman_truncated_nt": kf[1],
            "estimability_full": o[0].estimability,
            "estimability_truncated": o[1].estimability,
        })),
        "levelling": {
            "crossovers": lev.crossovers.crossovers.len(),
            "k_s": lev.fit.k_s,
            "k_std_s": lev.fit.k_std_s,
            "k_true_s": -survey_lag,
            "rms_before_nt": lev.fit.rms_before_nt,
            "rms_after_nt": lev.fit.rms_after_nt,
            "downweighted": lev.fit.downweighted,
            "rms_before_no_base_station_nt": lev_none.fit.rms_before_nt,
            "rms_after_no_base_station_nt": lev_none.fit.rms_after_nt,
        },
        "rotor": rotor_keys,
        "pod": pod_keys,
        "em": em_keys,
        "gradiometry": grad_keys,
        "seed": a.seed,
        "software_version": env!("CARGO_PKG_VERSION"),
    });
    for (area, g) in GEOLOGY_AREAS.iter().zip(&geology) {
        summary[area.key] = json!({
            "residual_rms_ls_nt": g.residual[0],
            "residual_rms_kalman_nt": g.residual[1],
            "interference_rms_ls_nt": g.interference[0],
            "interference_rms_kalman_nt": g.interference[1],
            "noise_floor_nt": fsv.noise_floor_nt,
            "calibration_altitude_m": g.altitude_m,
            "expected_gradient_nt_per_100m": g.gradient_nt_per_100m,
        });
    }
    std::fs::write(
        a.out.join("summary.json"),
        serde_json::to_string_pretty(&summary)?,
    )?;
    let mut r = Report::new("aeromag demo — simulated calibration and survey");
    r.section("Summary").paragraph(format!(
        "A simulated aircraft (magnetised and conducting parts, exact dipole fields) flies a {} and an \
         independent survey (seed {}). The Tolles-Lawson model ({} terms) is fitted on the calibration flight \
         by band-pass least squares (LS) and by the Kalman filter and smoother with a stochastic field model, \
         and applied to the survey. Residuals are scored against the simulator's truth (per survey line, mean \
         removed). The same aircraft is also calibrated lower, over geology: at 300 m over an area of \
         realistic anomaly gradients (the gradient area), and at 1000 m over a milder one. The Kalman method \
         pays off where the geology costs LS well more than the sensor noise.",
        if a.quick { "truncated calibration box" } else { "four-heading calibration box" },
        a.seed,
        model.terms
    ));
    let area_row = |label: &str,
                    (alt, grad): (Option<f64>, Option<f64>),
                    res: [Option<f64>; 2],
                    int: [Option<f64>; 2]| {
        vec![
            label.to_string(),
            fmt(alt, 0),
            fmt(grad, 2),
            fmt(res[0], 4),
            fmt(res[1], 4),
            fmt(res[0].zip(res[1]).map(|(l, k)| k / l), 2),
            fmt(fsv.noise_floor_nt, 4),
            fmt(int[0], 4),
            fmt(int[1], 4),
        ]
    };
    let mut area_rows = vec![area_row(
        "quiet",
        quiet_box,
        [fsv.residual_rms_nt, res_kf],
        [fsv.interference_rms_nt, int_kf],
    )];
    area_rows.extend(GEOLOGY_AREAS.iter().zip(&geology).map(|(area, g)| {
        area_row(
            area.label,
            (g.altitude_m, g.gradient_nt_per_100m),
            g.residual,
            g.interference,
        )
    }));
    r.table(aeromag_report::Table::new(
        [
            "calibration area",
            "box altitude (m)",
            "anomaly gradient at the box (nT/100 m)",
            "LS residual (nT)",
            "Kalman residual (nT)",
            "Kalman / LS",
            "noise floor (nT)",
            "LS model error (nT)",
            "Kalman model error (nT)",
        ]
        .map(String::from)
        .to_vec(),
        area_rows,
        "Residual versus truth on the independent survey (compensated − true external field, which holds \
         the sensor noise), and the error of the interference model alone (true − modelled interference), \
         per survey line with the mean removed. The gradient is the expected RMS horizontal gradient of the \
         anomaly at the calibration box's height (simulator truth). No estimator's residual goes below the \
         noise floor, so the Kalman / LS ratio of the residuals can only be small where LS's model error is \
         well above it.",
    ));
    r.key_values(vec![
        (
            "FOM before / after (nT)".into(),
            format!("{} / {}", fmt(fc.fom_before_nt, 3), fmt(fc.fom_after_nt, 3)),
        ),
        ("improvement ratio (calibration)".into(), fmt(fc.ir, 1)),
    ]);
    if let Some((d, o, ls, kf)) = &plan {
        r.section("Calibration planning: full and truncated patterns");
        r.paragraph(format!(
            "The truncated pattern takes {:.0} s against {:.0} s ({:.0} % less flight time). The estimability \
             measure μ = sqrt(P_post/P_prior) of each coefficient (0: determined by the flight, 1: not) and the \
             residual each calibration leaves on the independent survey show what the shorter flight costs.",
            d[1],
            d[0],
            100.0 * (1.0 - d[1] / d[0])
        ));
        r.table(aeromag_report::Table::new(
            [
                "pattern",
                "duration (s)",
                "LS residual (nT)",
                "Kalman residual (nT)",
                "max μ",
                "information rank",
            ]
            .map(String::from)
            .to_vec(),
            (0..2)
                .map(|k| {
                    vec![
                        ["full", "truncated"][k].to_string(),
                        format!("{:.0}", d[k]),
                        fmt(ls[k], 4),
                        fmt(kf[k], 4),
                        format!(
                            "{:.2e}",
                            o[k].estimability.iter().cloned().fold(0.0, f64::max)
                        ),
                        format!("{} of {}", o[k].rank, o[k].names.len()),
                    ]
                })
                .collect(),
            "Full versus truncated calibration pattern.",
        ));
        let x: Vec<f64> = (0..o[0].names.len()).map(|i| i as f64).collect();
        let svg = aeromag_report::LinePlot::new(
            "Estimability per coefficient (index in p3, i5, e8 order)",
            "coefficient index",
            "μ",
        )
        .with_series(aeromag_report::Series::points(
            "full pattern",
            x.clone(),
            o[0].estimability.clone(),
        ))
        .with_series(aeromag_report::Series::points(
            "truncated pattern",
            x,
            o[1].estimability.clone(),
        ))
        .to_svg()?;
        r.figure(
            svg,
            format!(
                "Estimability measures, coefficients {}.",
                o[0].names.join(", ")
            ),
        );
    }
    add_to_report(
        &mut r,
        "Calibration flight (LS model)",
        &cal,
        &fc,
        Some(&model),
    )?;
    let g = &geology[0];
    kalman_section(
        &format!(
            "Kalman method over realistic geology (gradient area, {} m): smoothed field, innovations, uncertainties",
            fmt(g.altitude_m, 0)
        ),
        &g.table,
        &g.ls,
        &g.kalman,
        &g.rows,
    )?
    .append_to(&mut r);
    add_to_report(
        &mut r,
        "Survey flight (independent, LS model)",
        &survey,
        &fsv,
        None,
    )?;
    r.section("Survey levelling at crossovers");
    r.paragraph(format!(
        "The LS-compensated survey is levelled at its {} line/tie-line crossovers (`aeromag level`): per-line \
         offsets, the coefficient k of the k·d|B0|/dt term (the scalar sensor's lag; truth −{} s) and the \
         crossovers' height differences times the vertical gradient from the two crossing profiles, fitted \
         with Huber weights ({} crossovers down-weighted). With the base station and IGRF removed \
         (`--reference auto`) k = {:.4} ± {:.4} s.",
        lev.crossovers.crossovers.len(),
        survey_lag,
        lev.fit.downweighted,
        lev.fit.k_s,
        lev.fit.k_std_s
    ));
    r.table(aeromag_report::Table::new(
        [
            "reference removed",
            "crossover RMS before (nT)",
            "model residual after (nT)",
            "reduction",
        ]
        .map(String::from)
        .to_vec(),
        [
            ("base station and IGRF", &lev),
            ("none (classic levelling)", &lev_none),
        ]
        .iter()
        .map(|(name, l)| {
            vec![
                name.to_string(),
                format!("{:.4}", l.fit.rms_before_nt),
                format!("{:.4}", l.fit.rms_after_nt),
                format!("{:.1}×", l.fit.rms_before_nt / l.fit.rms_after_nt),
            ]
        })
        .collect(),
        "Crossover differences before and after levelling.",
    ));
    for section in [rotor_section, pod_section, em_section, grad_section]
        .into_iter()
        .flatten()
    {
        section.append_to(&mut r);
    }
    r.write_html(a.out.join("index.html"))?;
    bar.inc(1);
    bar.finish_and_clear();

    println!(
        "aeromag demo (seed {}, {:.1} s)",
        a.seed,
        start.elapsed().as_secs_f64()
    );
    println!("{:<56} {:>12}", "figure", "value");
    let mut rows: Vec<(String, String)> = [
        (
            "compensation.residual_rms_ls_nt",
            fmt(fsv.residual_rms_nt, 4),
        ),
        ("compensation.residual_rms_kalman_nt", fmt(res_kf, 4)),
        ("compensation.noise_floor_nt", fmt(fsv.noise_floor_nt, 4)),
        ("compensation.fom_before_nt", fmt(fc.fom_before_nt, 3)),
        ("compensation.fom_after_nt", fmt(fc.fom_after_nt, 3)),
        ("compensation.ir", fmt(fc.ir, 1)),
    ]
    .map(|(k, v)| (k.to_string(), v))
    .to_vec();
    for (area, g) in GEOLOGY_AREAS.iter().zip(&geology) {
        rows.extend([
            (
                format!("{}.residual_rms_ls_nt", area.key),
                fmt(g.residual[0], 4),
            ),
            (
                format!("{}.residual_rms_kalman_nt", area.key),
                fmt(g.residual[1], 4),
            ),
            (
                format!("{}.interference_rms ls / kalman", area.key),
                format!(
                    "{} / {}",
                    fmt(g.interference[0], 4),
                    fmt(g.interference[1], 4)
                ),
            ),
        ]);
    }
    rows.extend(
        [
            ("levelling.k_s", format!("{:.4}", lev.fit.k_s)),
            (
                "levelling.rms_before_nt / after",
                format!("{:.3} / {:.3}", lev.fit.rms_before_nt, lev.fit.rms_after_nt),
            ),
            (
                "rotor.rotor_rms_nt",
                fmt(rotor_keys["rotor_rms_nt"].as_f64(), 3),
            ),
            (
                "rotor.residual_model_nt",
                fmt(rotor_keys["residual_model_nt"].as_f64(), 4),
            ),
            (
                "rotor.residual_best_filter_nt",
                fmt(rotor_keys["residual_best_filter_nt"].as_f64(), 4),
            ),
            (
                "pod.rate_train (fraction)",
                fmt(pod_keys["rate_train"].as_f64(), 4),
            ),
            (
                "pod.rate_test (fraction)",
                fmt(pod_keys["rate_test"].as_f64(), 4),
            ),
            ("em.range_err_rel", sci(&em_keys, "range_err_rel")),
            ("em.angle_err_deg", sci(&em_keys, "angle_err_deg")),
            (
                "em.polarization_ratio_before",
                sci(&em_keys, "polarization_ratio_before"),
            ),
            (
                "em.polarization_ratio_after",
                sci(&em_keys, "polarization_ratio_after"),
            ),
            (
                "gradiometry.efficiency_tensor",
                fmt(grad_keys["efficiency_tensor"].as_f64(), 3),
            ),
            (
                "gradiometry.efficiency_scalar",
                fmt(grad_keys["efficiency_scalar"].as_f64(), 3),
            ),
            (
                "gradiometry.convergence_fraction",
                fmt(grad_keys["convergence_fraction"].as_f64(), 4),
            ),
        ]
        .map(|(k, v)| (k.to_string(), v)),
    );
    for (k, v) in rows {
        println!("{k:<56} {v:>12}");
    }
    println!("results in {}/ (summary.json, index.html)", a.out.display());
    Ok(())
}
