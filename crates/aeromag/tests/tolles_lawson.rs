//! Tolles-Lawson calibration and compensation through the library: the
//! eddy-lag policy, rows kept and flagged, flights that do not determine
//! the model, observability, and the Kalman method against band-pass LS
//! over geology and for another aircraft.

use aeromag::prelude::*;
use aeromag::simulate::{ScenarioKind, simulate_flight};
use aeromag::{
    CompensateSensors, FlightTable, KalmanOptions, SensorColumns, SensorSet, SensorsModel,
    calibrate_sensors,
};

/// The classical 16-term LS model of `cal` (no eddy-current lags).
fn classical_model(cal: &Flight) -> TlModel {
    let opts = CalibrateOptions {
        eddy_lag: EddyLag::None,
        ..CalibrateOptions::default()
    };
    calibrate(cal, &opts, &mut Silent).unwrap().model
}

/// A simulated calibration box.
fn calibration(seed: u64) -> Flight {
    simulate_flight(ScenarioKind::Calibration, None, Some(seed)).unwrap()
}

/// The rows of `f` on line 1 without manoeuvres: one straight heading.
fn single_heading(f: &Flight) -> Flight {
    let (line, man) = (f.require("line").unwrap(), f.require("manoeuvre").unwrap());
    let keep: Vec<usize> = (0..f.n_rows())
        .filter(|&i| line[i] == 1.0 && man[i] == 0.0)
        .collect();
    assert!(keep.len() > 300);
    let mut t = FlightTable::new();
    for c in f.columns() {
        let v = c.values().unwrap();
        t.add_column(c.name(), keep.iter().map(|&i| v[i]).collect())
            .unwrap();
    }
    Flight::from_table(t).unwrap()
}

#[test]
fn eddy_lags_are_chosen_when_significant_and_recorded() {
    let cal = calibration(5);
    let fit = calibrate(&cal, &CalibrateOptions::default(), &mut Silent).unwrap();
    let m = &fit.model;
    assert!(
        !fit.notes
            .iter()
            .any(|n| n.message.contains("poorly determined")),
        "{:?}",
        fit.notes
    );
    // The simulated airframe's eddy currents lag (τ 0.15–0.6 s): `auto`
    // adds one or two lagged groups of nine columns to the 16 classical ones.
    let lags = m.design.terms.eddy_lags_s().len();
    assert!((1..=2).contains(&lags), "{}", m.design.terms);
    assert_eq!(m.coefficients.len(), 16 + 9 * lags);
    assert!(
        fit.notes
            .iter()
            .any(|n| n.message.contains("chosen (likelihood-ratio test)")),
        "{:?}",
        fit.notes
    );
    // The model records the search: every candidate with Λ and its threshold.
    let sel = fit.lag_selection.as_ref().expect("lag selection");
    assert_eq!(m.fit.eddy_lag_selection.as_ref(), Some(sel));
    assert!(
        sel.candidates.len() >= 7
            && sel
                .candidates
                .iter()
                .all(|c| c.lr_statistic.is_finite() && c.threshold.is_finite()),
        "{sel:?}"
    );
    assert_eq!(sel.taus_s, m.design.terms.eddy_lags_s());
    // The note says which rows its residuals are over: the search's, no
    // more than the fit's (on short legs fewer; the figures disagreed with
    // the fit's without a word).
    assert!(
        sel.rows > 0 && sel.rows <= m.fit.rows,
        "{} of {}",
        sel.rows,
        m.fit.rows
    );
    let over = format!("over the {} rows every candidate lag can use", sel.rows);
    assert!(
        fit.notes.iter().any(|n| n.message.contains(&over)),
        "{:?}",
        fit.notes
    );
    // `none`: the classical 16 terms, with a larger residual.
    let classical = classical_model(&cal);
    assert_eq!(classical.coefficients.len(), 16);
    assert!(
        m.fit.residual_rms_nt < 0.8 * classical.fit.residual_rms_nt,
        "lagged {} vs classical {}",
        m.fit.residual_rms_nt,
        classical.fit.residual_rms_nt
    );
    // MagNav's convention keeps MagNav's model unless lags are asked for.
    let magnav = aeromag::compensation::tolles_lawson::Convention::MagNav;
    assert_eq!(EddyLag::default_for(magnav), EddyLag::None);
}

#[test]
fn every_row_is_kept_and_rows_with_missing_inputs_are_flagged() {
    let cal = calibration(5);
    let model = classical_model(&cal);
    let mut t = cal.table().clone();
    let mut fx = t.require("flux_x").unwrap().to_vec();
    for row in [100, 101, 2000] {
        fx[row] = f64::NAN;
    }
    t.set_column("flux_x", fx).unwrap();
    let holed = Flight::from_table(t).unwrap();
    let out = model.compensate(&holed).unwrap();
    assert_eq!(out.missing, 3);
    assert_eq!(out.compensated_nt.len(), holed.n_rows());
    let flagged: Vec<usize> = out
        .flags()
        .iter()
        .enumerate()
        .filter(|(_, f)| **f == 1.0)
        .map(|(i, _)| i)
        .collect();
    assert_eq!(flagged, vec![100, 101, 2000]);
    // The interference is the model's A c on every other row.
    let interf = model.interference(&holed).unwrap();
    assert_eq!(
        interf.iter().filter(|v| v.is_finite()).count(),
        holed.n_rows() - 3
    );
    // The compensated reading alone (computed in the interference's place)
    // is the full compensation's, bit for bit, NaN on the same rows.
    let alone = model.compensated(&holed).unwrap();
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&alone), bits(&out.compensated_nt));
    let table = out.into_table(holed).unwrap();
    for c in ["mag_interf", "mag_comp", "comp_flag"] {
        assert!(table.column(c).is_some(), "{c}");
    }
}

/// A model whose interference is beyond any magnetic field on a flight (a
/// corrupted coefficient) is bad input naming the first such row, for
/// every way of applying it; before, the rows were written as compensated
/// with an interference of 10³⁰⁰ nT.
#[test]
fn an_interference_beyond_any_field_is_bad_input_naming_its_row() {
    let cal = calibration(5);
    let mut model = classical_model(&cal);
    let good = model.interference(&cal).unwrap();
    // p_x raised so that the interference passes 10⁶ nT on some rows only.
    let col = model
        .coefficients
        .iter()
        .position(|c| c.name == "p_x")
        .unwrap();
    model.coefficients[col].value += 3e6;
    let expect: Vec<f64> = model.design.interference(
        &model.coef(),
        cal.require("time").unwrap(),
        [
            cal.require("flux_x").unwrap(),
            cal.require("flux_y").unwrap(),
            cal.require("flux_z").unwrap(),
        ],
    );
    let first = expect.iter().position(|v| v.abs() > 1e6).unwrap();
    assert!(first > 0);
    assert!(expect[..first].iter().all(|v| v.is_finite()));
    assert!(good.iter().all(|v| v.abs() < 1e5));
    let want = format!("data row {}", first + 1);
    let errors = [
        model.compensate(&cal).unwrap_err(),
        model.interference(&cal).unwrap_err(),
        model.compensated(&cal).unwrap_err(),
    ];
    for e in errors {
        assert!(e.is_bad_input(), "{e}");
        let msg = e.to_string();
        assert!(
            msg.contains(&want) && msg.contains("beyond any magnetic field"),
            "{msg}"
        );
    }
}

/// Found by fuzzing: a flight whose time is in milliseconds was compensated
/// without a word (the eddy-current derivatives a thousandth of the
/// calibration's, `mag_comp` up to 0.30 nT off), batch and causal alike.
#[test]
fn a_flight_timed_in_other_units_than_the_calibration_is_bad_input() {
    let cal = calibration(5);
    let model = classical_model(&cal);
    let mut t = FlightTable::new();
    for c in cal.table().columns() {
        let v = c.values().unwrap();
        let v = if c.name() == "time" {
            v.iter().map(|x| x * 1e3).collect()
        } else {
            v.to_vec()
        };
        t.add_column(c.name(), v).unwrap();
    }
    let ms = Flight::from_table(t).unwrap();
    let causal = aeromag::online::CausalTl::new(&model, None).unwrap();
    for e in [
        model.compensate(&ms).unwrap_err(),
        causal.compensate(&ms).unwrap_err(),
    ] {
        let msg = e.to_string();
        assert!(
            e.is_bad_input() && msg.contains("milliseconds") && msg.contains("1000 times longer"),
            "{msg}"
        );
    }
    // A tenth of the calibration's rate passes.
    let every_tenth: Vec<usize> = (0..cal.n_rows()).step_by(10).collect();
    let mut t = FlightTable::new();
    for c in cal.table().columns() {
        let v = c.values().unwrap();
        t.add_column(c.name(), every_tenth.iter().map(|&k| v[k]).collect())
            .unwrap();
    }
    assert!(model.compensate(&Flight::from_table(t).unwrap()).is_ok());
}

/// `f` with column `name` replaced by `edit` of it.
fn edited(f: &Flight, name: &str, edit: impl Fn(&[f64]) -> Vec<f64>) -> Flight {
    let mut t = FlightTable::new();
    for c in f.table().columns() {
        let v = c.values().unwrap();
        let v = if c.name() == name {
            edit(v)
        } else {
            v.to_vec()
        };
        t.add_column(c.name(), v).unwrap();
    }
    Flight::from_table(t).unwrap()
}

/// Found by fuzzing `calibrate` (each fitted with exit 0 a model that
/// removed nothing or less, or failed as "singular system" / "invalid
/// argument `low_hz`"): a stuck magnetometer, a dead fluxgate axis, a time
/// in milliseconds, a truth column as an input, the reading as its own
/// reference, a lever arm with nothing to move, LS settings with the
/// Kalman method. Each is bad input saying what is wrong.
#[test]
fn hostile_calibration_flights_and_settings_are_refused() {
    let cal = calibration(1);
    let ls = CalibrateOptions {
        eddy_lag: EddyLag::None,
        ..CalibrateOptions::default()
    };
    let refused = |f: &Flight, opts: &CalibrateOptions, says: &str| {
        let e = calibrate(f, opts, &mut Silent).unwrap_err();
        assert!(
            e.is_bad_input() && e.to_string().contains(says),
            "{says}: {e}"
        );
        e
    };
    let stuck = edited(&cal, "mag", |v| vec![53_100.0; v.len()]);
    let e = refused(&stuck, &ls, "holds one value, 53100 nT, on every row");
    assert_eq!(e.location().column.as_deref(), Some("mag"));
    let dead = edited(&cal, "flux_y", |v| vec![0.0; v.len()]);
    for opts in [&ls, &CalibrateOptions::kalman()] {
        let e = refused(&dead, opts, "holds one value, 0 nT");
        assert_eq!(e.location().column.as_deref(), Some("flux_y"));
    }
    let ms = edited(&cal, "time", |v| v.iter().map(|t| t * 1e3).collect());
    for opts in [&ls, &CalibrateOptions::kalman()] {
        refused(&ms, opts, "median time step is 100.0000 s (0.0100 Hz)");
    }
    let half = edited(&cal, "time", |v| v.iter().map(|t| t * 10.0).collect());
    refused(
        &half,
        &ls,
        "needs a sampling rate above 1.8 Hz, and segment",
    );
    // Truth never goes in: as an extra regressor, a reference channel, a
    // sensor.
    for opts in [
        CalibrateOptions {
            extra: aeromag::compensation::tolles_lawson::ExtraRequest::parse_list("true_interf")
                .unwrap(),
            extra_selection: aeromag::ExtraSelection::All,
            ..ls.clone()
        },
        CalibrateOptions {
            reference: "true_external".parse().unwrap(),
            ..ls.clone()
        },
        CalibrateOptions {
            sensor: SensorColumns {
                mag: "true_external".into(),
                ..SensorColumns::default()
            },
            ..ls.clone()
        },
    ] {
        refused(&cal, &opts, "is a simulation truth column");
    }
    // `mag` read from `igrf` with the automatic references.
    let own = CalibrateOptions {
        sensor: SensorColumns {
            mag: "igrf".into(),
            ..SensorColumns::default()
        },
        ..ls.clone()
    };
    refused(
        &cal,
        &own,
        "reference channel `igrf` is the scalar reading itself",
    );
    let lever = CalibrateOptions {
        reference: "none".parse().unwrap(),
        lever_arm: Some(aeromag::LeverArm {
            arm_m: [10.0, 0.0, 0.0],
            decimal_year: 2025.0,
        }),
        ..ls.clone()
    };
    refused(&cal, &lever, "the LS fit would not use it");
    let band = aeromag::CalibrateSettings {
        method: aeromag::Method::Kalman,
        band_hz: Some(Some((0.2, 0.5))),
        ..Default::default()
    };
    let e = band.options().unwrap_err();
    assert!(
        e.is_bad_input() && e.to_string().contains("band (--band)"),
        "{e}"
    );
}

/// The rows `rows` of every column of `f`, as a flight.
fn rows_of(f: &FlightTable, rows: std::ops::Range<usize>) -> Flight {
    let mut t = FlightTable::new();
    for c in f.columns() {
        t.add_column(c.name(), c.values().unwrap()[rows.clone()].to_vec())
            .unwrap();
    }
    Flight::from_table(t).unwrap()
}

/// A long flight cut by missing values into several stretches is
/// compensated with the stretches shared out over the cores, each as if
/// alone: the interference on each stretch is, bit for bit, that of the
/// stretch's rows compensated as a flight of their own (a model with eddy
/// lags, whose lag filters restart at every stretch).
#[test]
fn stretches_of_a_long_flight_are_each_compensated_as_alone() {
    let cal = calibration(5);
    let model = calibrate(&cal, &CalibrateOptions::default(), &mut Silent)
        .unwrap()
        .model;
    assert!(!model.design.terms.eddy_lags_s().is_empty());
    // Twelve boxes end to end (more than 2¹⁶ rows), time going on.
    let (n, copies) = (cal.n_rows(), 12);
    let time = cal.require("time").unwrap();
    let span = time[n - 1] - time[0] + (time[1] - time[0]);
    let mut long = FlightTable::new();
    for c in cal.columns() {
        let v = c.values().unwrap();
        let col: Vec<f64> = (0..copies)
            .flat_map(|k| {
                v.iter().map(move |x| {
                    if c.name() == "time" {
                        x + k as f64 * span
                    } else {
                        *x
                    }
                })
            })
            .collect();
        long.add_column(c.name(), col).unwrap();
    }
    let holes = [9_000, 30_001, 51_234];
    let mut fx = long.require("flux_x").unwrap().to_vec();
    for h in holes {
        fx[h] = f64::NAN;
    }
    long.set_column("flux_x", fx).unwrap();
    let rows = n * copies;
    assert!(rows > 1 << 16);
    let whole = model
        .interference(&Flight::from_table(long.clone()).unwrap())
        .unwrap();
    let mut start = 0;
    for end in holes.into_iter().chain(std::iter::once(rows)) {
        let alone = model.interference(&rows_of(&long, start..end)).unwrap();
        assert!(
            alone
                .iter()
                .zip(&whole[start..end])
                .all(|(a, b)| a.to_bits() == b.to_bits()),
            "stretch {start}..{end}"
        );
        if end < rows {
            assert!(whole[end].is_nan());
        }
        start = end + 1;
    }
}

#[test]
fn a_single_heading_without_manoeuvres_does_not_determine_the_model() {
    let one = single_heading(&calibration(6));
    match calibrate(&one, &CalibrateOptions::default(), &mut Silent) {
        // Either a warning naming the undetermined terms …
        Ok(fit) => {
            let w: Vec<&str> = fit
                .notes
                .iter()
                .filter(|n| n.is_warning())
                .map(|n| n.message.as_str())
                .collect();
            assert!(
                w.iter().any(|m| m.contains("poorly determined terms")
                    && (m.contains("e_") || m.contains("i_"))),
                "{w:?}"
            );
        }
        // … or a failed fit, which is not the user's bad input.
        Err(e) => assert!(!e.is_bad_input(), "{e}"),
    }
}

/// The straight legs of a box (every heading, no manoeuvre) fitted
/// without a word, with coefficients 17 stated σ from the whole box's:
/// now a `[few-manoeuvres]` warning names the still axes; the whole box
/// has none.
#[test]
fn straight_legs_without_manoeuvres_are_warned_about() {
    let cal = calibration(6);
    let (line, man) = (
        cal.require("line").unwrap(),
        cal.require("manoeuvre").unwrap(),
    );
    let keep: Vec<usize> = (0..cal.n_rows())
        .filter(|&i| line[i] != 0.0 && man[i] == 0.0)
        .collect();
    let mut t = FlightTable::new();
    for c in cal.columns() {
        let v = c.values().unwrap();
        t.add_column(c.name(), keep.iter().map(|&i| v[i]).collect())
            .unwrap();
    }
    let straight = Flight::from_table(t).unwrap();
    let warned = |f: &Flight| {
        let fit = calibrate(f, &CalibrateOptions::default(), &mut Silent).unwrap();
        fit.notes
            .iter()
            .filter(|n| n.is_warning() && n.message.contains("[few-manoeuvres]"))
            .map(|n| n.message.clone())
            .collect::<Vec<_>>()
    };
    let w = warned(&straight);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(w[0].contains("barely manoeuvres"), "{w:?}");
    assert!(warned(&cal).is_empty());
}

/// A noise-free turning flight in a constant field fitted without a
/// band-pass: the induced diagonal equals the bias column times |B|/bt_scale,
/// the normal equations are singular, and that is a failed fit, not bad
/// input.
#[test]
fn a_singular_fit_is_a_failure_not_bad_input() {
    let n = 3000;
    let time: Vec<f64> = (0..n).map(|k| k as f64 * 0.1).collect();
    let mut t = FlightTable::new();
    let f: Vec<[f64; 3]> = time
        .iter()
        .map(|t| {
            let (a, b) = (0.4 * (1.9 * t).sin(), 0.3 * (1.3 * t + 1.0).sin());
            [a.cos() * b.cos(), a.sin() * b.cos(), b.sin()].map(|c| 50_000.0 * c)
        })
        .collect();
    t.add_column("time", time.clone()).unwrap();
    for (k, name) in ["flux_x", "flux_y", "flux_z"].iter().enumerate() {
        t.add_column(name, f.iter().map(|v| v[k]).collect())
            .unwrap();
    }
    t.add_column(
        "mag",
        f.iter().map(|v| 50_000.0 + 3.0 * v[0] / 50_000.0).collect(),
    )
    .unwrap();
    let flight = Flight::from_table(t).unwrap();
    let opts = CalibrateOptions {
        ls: aeromag::compensation::tolles_lawson::fit_ls::LsConfig {
            design: aeromag::compensation::tolles_lawson::Design::new(
                aeromag::compensation::tolles_lawson::TermSet::parse("p3,i6,bias").unwrap(),
            ),
            band_hz: None,
            ..Default::default()
        },
        eddy_lag: EddyLag::None,
        reference: ReferenceChannels::None,
        ..CalibrateOptions::default()
    };
    let e = calibrate(&flight, &opts, &mut Silent).unwrap_err();
    assert!(!e.is_bad_input(), "{e}");
    assert!(e.to_string().contains("singular"), "{e}");
}

#[test]
fn observability_tells_a_full_box_from_a_single_heading() {
    let cal = calibration(8);
    let terms = aeromag::compensation::tolles_lawson::TermSet::observable16();
    let full = aeromag::observability(&cal, &terms, None, &mut Silent).unwrap();
    assert_eq!(full.observability.rank, 16);
    assert!(full.undetermined().is_empty(), "{:?}", full.undetermined());
    // One straight leg: the permanent and induced terms are not determined.
    let one = aeromag::observability(&single_heading(&cal), &terms, None, &mut Silent).unwrap();
    let un = one.undetermined();
    assert!(un.contains(&"p_x") && un.contains(&"i_xx"), "{un:?}");
    assert_eq!(one.observability.estimability.len(), 16);
    // Lagged eddy terms are not assessed: bad input, alone (which left no
    // column and panicked) or with other groups (where they were dropped).
    for spec in ["l9", "p3,i5,e8,l9"] {
        let lagged = aeromag::compensation::tolles_lawson::TermSet::parse(spec).unwrap();
        let e = aeromag::observability(&cal, &lagged, None, &mut Silent).unwrap_err();
        assert!(
            e.is_bad_input() && e.to_string().contains("l9"),
            "{spec}: {e}"
        );
    }
}

/// Current terms in the observability check (issue 20): a strobe switching
/// all through the box is determined; a current that never changes is not
/// (its terms are the permanent terms scaled), though its column is as
/// large.
#[test]
fn observability_rates_current_terms() {
    use aeromag::compensation::tolles_lawson::{ExtraTerm, TermSet};
    let mut cal = calibration(8);
    let t = cal.table().require("time").unwrap().to_vec();
    let strobe: Vec<f64> = t
        .iter()
        .map(|t| if t.rem_euclid(1.2) < 0.15 { 5.0 } else { 0.0 })
        .collect();
    cal.add_column("cur_strb", strobe).unwrap();
    cal.add_column("cur_const", vec![5.0; t.len()]).unwrap();
    let terms = TermSet::observable16()
        .with_extras(&[ExtraTerm::new("cur_strb"), ExtraTerm::new("cur_const")])
        .unwrap();
    let o = aeromag::observability(&cal, &terms, None, &mut Silent).unwrap();
    assert_eq!(o.coefficients.len(), 22);
    let un = o.undetermined();
    for axis in ["x", "y", "z"] {
        assert!(
            un.contains(&format!("cur_const:e_{axis}").as_str()),
            "{un:?}"
        );
        assert!(
            !un.contains(&format!("cur_strb:e_{axis}").as_str()),
            "{un:?}"
        );
    }
}

#[test]
fn the_kalman_series_hold_the_smoothed_field_and_whitened_innovations() {
    let cal = simulate_flight(ScenarioKind::CalibrationTruncated, None, Some(7)).unwrap();
    let opts = CalibrateOptions {
        kalman: KalmanOptions {
            series: true,
            ..KalmanOptions::default()
        },
        ..CalibrateOptions::kalman()
    };
    let fit = calibrate(&cal, &opts, &mut Silent).unwrap();
    let k = fit.kalman.expect("Kalman outcome");
    // Tuned by default.
    assert!(k.fit.tuning.is_some());
    let s = k.series.expect("series asked for");
    for c in s.columns() {
        assert_eq!(c.len(), cal.n_rows());
    }
    let (mut within, mut n) = (0, 0);
    for i in 100..cal.n_rows() {
        let (f, v, sd) = (s.field[i], s.innovation[i], s.innovation_std[i]);
        if f.is_finite() && v.is_finite() && sd.is_finite() {
            assert!(sd > 0.0);
            n += 1;
            within += usize::from(v.abs() <= sd);
        }
    }
    // A noise model that fits keeps about 68 % of the innovations within ±σ.
    assert!(
        n > 1000 && (0.55..0.85).contains(&(within as f64 / n as f64)),
        "{within} of {n} within ±σ"
    );
}

/// Errors of a compensated simulated survey, nT, each the RMS over the
/// survey/tie lines with each line's mean removed (pooled), for scoring
/// only: `[0]` the interference model alone, `true_interf − mag_interf`;
/// `[1]` the survey residual of the spec (`compensation.md`, Metrics),
/// `mag_comp − true_external − true_lag`, which holds the scalar sensor's
/// noise (0.011 nT).
fn survey_errors(f: &FlightTable) -> [f64; 2] {
    let c = |n: &str| f.require(n).unwrap();
    let (ti, mi, mc, te, tl, line) = (
        c("true_interf"),
        c("mag_interf"),
        c("mag_comp"),
        c("true_external"),
        c("true_lag"),
        c("line"),
    );
    let mut by_line: std::collections::BTreeMap<i64, [Vec<f64>; 2]> = Default::default();
    for i in 0..f.n_rows() {
        let x = [ti[i], mi[i], mc[i], te[i], tl[i], line[i]];
        if x.iter().any(|v| !v.is_finite()) {
            continue;
        }
        if x[5] > 0.0 {
            let e = by_line.entry(x[5] as i64).or_default();
            e[0].push(x[0] - x[1]);
            e[1].push(x[2] - x[3] - x[4]);
        }
    }
    let mut out = [0.0; 2];
    for (j, o) in out.iter_mut().enumerate() {
        let (mut ss, mut n) = (0.0, 0usize);
        for e in by_line.values() {
            let e = &e[j];
            let mean = e.iter().sum::<f64>() / e.len() as f64;
            ss += e.iter().map(|x| (x - mean).powi(2)).sum::<f64>();
            n += e.len();
        }
        *o = (ss / n as f64).sqrt();
    }
    out
}

/// Simulate a calibration (`cal_toml`, seed `cal_seed`) and a survey
/// (`survey_toml`; seed `survey_seed`), calibrate with band-pass LS and
/// then with the Kalman method for each field order of `kalman_orders`
/// (`None`: the default), compensate the survey with each model, and
/// return the survey errors of each ([`survey_errors`]), LS first, nT.
fn calibrate_and_compare(
    cal_toml: &str,
    cal_seed: u64,
    survey_toml: Option<&str>,
    survey_seed: u64,
    lever_arm_m: [f64; 3],
    kalman_orders: &[Option<usize>],
) -> Vec<[f64; 2]> {
    let cal = simulate_flight(ScenarioKind::Calibration, Some(cal_toml), Some(cal_seed)).unwrap();
    let survey = simulate_flight(ScenarioKind::Survey, survey_toml, Some(survey_seed)).unwrap();
    let lever_arm = Some(LeverArm {
        arm_m: lever_arm_m,
        decimal_year: aeromag::core::time::Date::parse("2025-01-01")
            .unwrap()
            .decimal_year(),
    });
    let ls = CalibrateOptions {
        lever_arm,
        ..CalibrateOptions::default()
    };
    let runs =
        std::iter::once(ls.clone()).chain(kalman_orders.iter().map(|order| CalibrateOptions {
            method: Method::Kalman,
            kalman: KalmanOptions {
                field_order: order.unwrap_or(KalmanOptions::default().field_order),
                ..KalmanOptions::default()
            },
            ..ls.clone()
        }));
    runs.map(|opts| {
        let model = calibrate(&cal, &opts, &mut Silent).unwrap().model;
        let out = model.compensate(&survey).unwrap();
        survey_errors(&out.into_table(survey.clone()).unwrap())
    })
    .collect()
}

/// Over realistic geology at 600 m the Kalman method (as `calibrate`
/// runs it: two-pass lag choice, tuned noise, the default field model of
/// order 6) leaves at most half the interference-model error of band-pass
/// LS on an independent survey, and less than with the thesis' order-3
/// field model. Measured on the demo surveys, seeds 1–5 (×10⁻³ nT, LS /
/// Kalman order 6): 13.4/3.1, 17.8/2.6, 8.7/2.1, 13.7/2.4, 14.9/6.2 (the
/// module docs of `kalman::tuning` have the other altitudes and stronger
/// geology).
#[test]
fn kalman_halves_the_least_squares_error_over_geology_at_600_m() {
    let err = calibrate_and_compare(
        "[pattern]\naltitude_m = 600.0\n[anomaly]\narea = \"realistic\"\n",
        4,
        None,
        5,
        [-9.5, 0.0, -0.6],
        &[None, Some(3)],
    );
    let e: Vec<f64> = err.iter().map(|e| e[0]).collect();
    eprintln!(
        "interference error LS {:.4} nT, Kalman (order 6) {:.4} nT, order 3 {:.4} nT",
        e[0], e[1], e[2]
    );
    assert!(e[1] <= 0.5 * e[0], "{err:?}");
    assert!(e[1] < e[2], "{err:?}");
}

/// Over strong geology (10 nT/100 m at 100 m above ground, the top of the
/// survey range; ≈ 8 nT/100 m at the calibration height of 300 m) the
/// band-pass LS model leaves several times the sensor noise on the survey,
/// and the Kalman method halves the survey residual of the spec itself
/// (compensated − true external field, noise included), not only the
/// interference-model error. This needs the cleaned altitude of the
/// vertical-gradient term and the multi-start noise tuning: with the raw
/// GNSS altitude (0.2 m white noise) and Nelder–Mead from the defaults,
/// the Kalman error at 600 m over this geology was 2× the LS error (module
/// docs of `aeromag_compensation::kalman::altitude`).
#[test]
fn kalman_halves_the_survey_residual_over_strong_geology() {
    let err = calibrate_and_compare(
        "[pattern]\naltitude_m = 300.0\n[anomaly]\narea = \"realistic\"\ngradient_rms_nt_per_100m = 10.0\n",
        6,
        None,
        7,
        [-9.5, 0.0, -0.6],
        &[None],
    );
    eprintln!(
        "strong geology, LS interference {:.4} residual {:.4} nT; Kalman {:.4} / {:.4} nT",
        err[0][0], err[0][1], err[1][0], err[1][1]
    );
    assert!(err[1][1] <= 0.5 * err[0][1], "{err:?}");
    assert!(err[1][0] <= 0.5 * err[0][0], "{err:?}");
}

/// A different aircraft, not the one the defaults were tuned on: one engine
/// in the nose, a 7 m stinger, other eddy-current circuits (a wing with
/// τ = 0.4 s, between the lags the lag test offers), calibrated at 300 m
/// over realistic geology. Measured (calibration seeds 1–3, surveys 41–43,
/// ×10⁻³ nT, LS / Kalman): 300 m 23.7/6.0, 26.3/8.9, 22.1/5.6; 600 m
/// 10.7/5.9, 16.6/5.8, 8.6/4.5 (before the cleaned altitude and the grid
/// search of the noise tuning: 6.6, 9.3, 12.0; 6.9, 6.2, 4.4). In the
/// quiet box at 3 km both methods gave 5.1–5.5 (not re-measured): what the
/// Tolles-Lawson model itself leaves for this aircraft. On the full survey
/// residual (sensor noise included) the ratio Kalman / LS is 0.49–0.51 at
/// 300 m (the preset geology, 2.6 nT/100 m at the box) and 0.62–0.85 at
/// 600 m.
#[test]
fn kalman_halves_the_least_squares_error_for_another_aircraft_at_300_m() {
    let err = calibrate_and_compare(
        &format!(
            "[pattern]\naltitude_m = 300.0\n[anomaly]\narea = \"realistic\"\n{OTHER_AIRCRAFT}"
        ),
        1,
        Some(OTHER_AIRCRAFT),
        41,
        [-7.0, 0.0, -0.4],
        &[None],
    );
    eprintln!(
        "other aircraft, interference error LS {:.4} nT, Kalman {:.4} nT",
        err[0][0], err[1][0]
    );
    assert!(err[1][0] <= 0.5 * err[0][0], "{err:?}");
}

/// A single-engine aircraft with a short stinger (scenario TOML sections).
const OTHER_AIRCRAFT: &str = include_str!("data/other_aircraft.toml");

/// A cabin installation: a scalar sensor and a fluxgate 1.5 m forward of
/// the navigation point (hundreds of nT of interference), a strobe and a
/// flap motor whose field lags its current by 0.4 s.
const CABIN: &str = r#"
[[extra_scalars]]
position_m = [1.5, 0.0, -0.4]
[[extra_fluxgates]]
position_m = [1.5, 0.3, -0.4]
[[aircraft.currents]]
name = "strb"
position_m = [1.0, 0.5, -0.3]
normal = [0.0, 0.3, 1.0]
area_m2 = 0.05
mean_a = 0.0
switched_a = 6.0
fluctuation_a = 0.05
fluctuation_tau_s = 5.0
channel_noise_a = 0.02
pattern = { kind = "strobe", period_s = 1.3, pulse_s = 0.2 }
[[aircraft.currents]]
name = "flap"
position_m = [2.0, -0.5, -0.2]
normal = [1.0, 0.2, 0.3]
area_m2 = 0.1
mean_a = 0.5
switched_a = 10.0
fluctuation_a = 0.1
fluctuation_tau_s = 10.0
channel_noise_a = 0.05
field_lag_s = 0.4
pattern = { kind = "runs", runs_per_hour = 60.0, run_s = 8.0, ramp_s = 1.0 }
[pattern]
line_count = 6
"#;

/// `CABIN` for the calibration box (its pattern has no `line_count`).
fn cabin_calibration() -> Flight {
    let toml = CABIN.split("[pattern]").next().unwrap();
    simulate_flight(ScenarioKind::Calibration, Some(toml), Some(3)).unwrap()
}

/// RMS about the mean of `comp − true_external<suffix>` on the survey.
fn survey_error(f: &Flight, comp: &[f64], suffix: &str) -> f64 {
    let t = f.require(&format!("true_external{suffix}")).unwrap();
    let d: Vec<f64> = comp.iter().zip(t).map(|(c, t)| c - t).collect();
    let m = d.iter().sum::<f64>() / d.len() as f64;
    (d.iter().map(|v| (v - m).powi(2)).sum::<f64>() / d.len() as f64).sqrt()
}

/// Current terms on a cabin sensor (issue 20): the 16-term model leaves
/// tens of nT of the currents' field, the current terms (the channel times
/// the direction cosines, the flap also through its fitted lag) take it
/// out, on independent survey lines. Measured: 16 terms 143 nT, with the
/// current terms 0.63 nT, τ = 0.402 s (truth 0.4 s); the same model fitted
/// to the survey's own true interference (the oracle) leaves 0.29 nT.
#[test]
fn current_terms_compensate_a_cabin_sensor() {
    use aeromag::compensation::tolles_lawson::ExtraRequest;
    let cal = cabin_calibration();
    let survey = simulate_flight(ScenarioKind::Survey, Some(CABIN), Some(4)).unwrap();
    let cabin = SensorColumns::find(&cal, "mag_2", Some("flux_b")).unwrap();
    let fit = |extra: &str| {
        let opts = CalibrateOptions {
            sensor: cabin.clone(),
            extra: ExtraRequest::parse_list(extra).unwrap(),
            ..CalibrateOptions::default()
        };
        let set = SensorSet {
            sensors: vec![cabin.clone()],
            reference: None,
        };
        let cal = calibrate_sensors(&cal, &set, &opts, &mut Silent).unwrap();
        let comp = cal.model.compensate(&survey).unwrap();
        (cal, survey_error(&survey, &comp.sensors[0].2, "_2"))
    };
    let (_, plain) = fit("");
    let (with, current) = fit("cur_strb,cur_flap:lag");
    let terms = &with.model.sensors[0].model.design.terms;
    let tau = terms.extras()[1].lag_s.unwrap();
    assert!((tau - 0.4).abs() < 0.02, "{terms:?}");
    assert_eq!(terms.extras()[0].lag_s, None);
    assert!(plain > 50.0, "16 terms: {plain} nT");
    assert!(
        current < 1.0 && current * 10.0 < plain,
        "{current} vs {plain} nT"
    );
}

/// Several sensors in one run give each sensor the model it gets alone,
/// bit for bit; `compensate` writes every sensor's columns and the
/// gradient; in reference-sensor mode the cabin sensor, fitted on every
/// row of the flight against the compensated stinger, reaches what the
/// band-passed fit does (measured: 0.70 nT against 0.63 nT).
#[test]
fn several_sensors_and_the_reference_sensor_mode() {
    use aeromag::compensation::tolles_lawson::ExtraRequest;
    let cal = cabin_calibration();
    let survey = simulate_flight(ScenarioKind::Survey, Some(CABIN), Some(4)).unwrap();
    let opts = CalibrateOptions {
        extra: ExtraRequest::parse_list("cur_strb,cur_flap:lag").unwrap(),
        ..CalibrateOptions::default()
    };
    let set = SensorSet {
        sensors: vec![
            SensorColumns::find(&cal, "mag", None).unwrap(),
            SensorColumns::find(&cal, "MAG_2", Some("flux_b")).unwrap(),
        ],
        reference: None,
    };
    let both = calibrate_sensors(&cal, &set, &opts, &mut Silent).unwrap();
    for (k, s) in set.sensors.iter().enumerate() {
        let alone = calibrate(
            &cal,
            &CalibrateOptions {
                sensor: s.clone(),
                ..opts.clone()
            },
            &mut Silent,
        )
        .unwrap();
        assert_eq!(alone.model, both.model.sensors[k].model);
    }
    assert_eq!(both.model.sensors[1].mag, "mag_2");
    assert_eq!(both.model.sensors[1].model.columns["mag"], "mag_2");
    let text = both.model.to_json().unwrap();
    assert_eq!(SensorsModel::parse(&text, "m.json").unwrap(), both.model);
    let comp = both.model.compensate(&survey).unwrap();
    // A corrupted coefficient of the second sensor's model: bad input, not
    // an interference of 10³⁰⁰ nT written as compensated.
    let mut corrupt = both.model.clone();
    corrupt.sensors[1].model.coefficients[0].value = 1e300;
    let e = corrupt.compensate(&survey).unwrap_err();
    assert!(
        e.is_bad_input() && e.to_string().contains("beyond any magnetic field"),
        "{e}"
    );
    let names: Vec<String> = comp.columns().into_iter().map(|c| c.0).collect();
    assert_eq!(
        names,
        [
            "mag_interf",
            "mag_comp",
            "mag_2_interf",
            "mag_2_comp",
            "mag_2_grad"
        ]
    );
    let band_passed = survey_error(&survey, &comp.sensors[1].2, "_2");

    let reference = SensorSet {
        reference: Some("mag".into()),
        ..set.clone()
    };
    let r = calibrate_sensors(&cal, &reference, &opts, &mut Silent).unwrap();
    // The reference sensor alone, filtered through the line changes (its
    // legs end at gaps only): it is not the leg-by-leg fit.
    let through = calibrate(
        &cal,
        &CalibrateOptions {
            sensor: set.sensors[0].clone(),
            split_lines: false,
            ..opts.clone()
        },
        &mut Silent,
    )
    .unwrap();
    assert_eq!(r.model.sensors[0].model, through.model);
    assert_ne!(r.model.sensors[0].model, both.model.sensors[0].model);
    assert_eq!(r.model.sensors[1].reference_sensor.as_deref(), Some("mag"));
    let m = &r.model.sensors[1].model;
    assert!(
        m.reference.is_empty()
            && m.design
                .terms
                .groups()
                .contains(&aeromag::compensation::tolles_lawson::TermGroup::Bias)
    );
    let rc = r.model.compensate(&survey).unwrap();
    let ref_mode = survey_error(&survey, &rc.sensors[1].2, "_2");
    assert!(
        ref_mode < 1.2 * band_passed.max(0.5),
        "{ref_mode} vs {band_passed} nT"
    );
    // A sensor given twice, or absent, is bad input.
    let twice = SensorSet {
        sensors: vec![set.sensors[1].clone(), set.sensors[1].clone()],
        reference: None,
    };
    assert!(
        calibrate_sensors(&cal, &twice, &opts, &mut Silent)
            .unwrap_err()
            .is_bad_input()
    );
    let e = SensorColumns::find(&cal, "mag_7_uc", None).unwrap_err();
    assert!(
        e.is_bad_input() && e.to_string().contains("mag_7_uc"),
        "{e}"
    );
}

/// The SGL-like installation (issue 20): a stinger, four cabin sensors and
/// 14 recorded currents, calibrated on the box and scored on independent
/// survey lines ([`MultiSensorStudy`], the demo's `multi_sensor` group).
/// The issue's figures: the stinger with current terms no worse than
/// today's stinger installation; each cabin sensor more than 10× below its
/// 16-term model and within 1.5× of its oracle; in reference-sensor mode
/// the worst cabin sensor within 1.2× of its oracle. Measured (seed 1):
/// stinger 0.1638 nT (16 terms 0.204; today's
/// installation, which has no currents, 0.1640); cabin 0.724 / 0.102 /
/// 0.226 / 0.186 nT against oracles 0.716 / 0.099 / 0.213 / 0.168 (worst
/// ratio 1.11), 16 terms up to 277 nT; reference mode worst 0.730 nT
/// (1.02×). The figures are printed (`--no-capture`).
#[test]
fn sgl_installation_several_sensors_and_currents() {
    use aeromag::studies::{MultiSensorStudy, Study, StudyOutcome, StudySize};
    let s = MultiSensorStudy { seed: 1 }
        .run(StudySize::Full, &mut Silent)
        .unwrap()
        .summary();
    for f in &s.sensors {
        println!("{f:?}");
    }
    println!(
        "tail {:.3} (16 terms {:.3}); cabin worst {:.3}, oracle {:.3}, worst ratio {:.2}; 16 terms {:.1}; reference mode {:.3} (ratio {:.2})",
        s.tail_residual_nt,
        s.tail_residual_16term_nt,
        s.cabin_residual_worst_nt,
        s.cabin_oracle_worst_nt,
        s.cabin_over_oracle_worst,
        s.cabin_residual_16term_worst_nt,
        s.reference_mode_worst_nt,
        s.reference_mode_over_oracle_worst
    );
    println!(
        "today's stinger installation: {:.3} nT",
        s.tail_residual_stinger_installation_nt
    );
    // Today's installation carries no currents at all; the SGL stinger sees
    // 0.105 nT RMS of them. Its current terms must take them out to within
    // 1 % of the currents-free residual (measured: 0.3 %) and beat its
    // 16-term model.
    assert!(
        s.tail_residual_nt <= 1.01 * s.tail_residual_stinger_installation_nt,
        "{s:?}"
    );
    assert!(s.tail_residual_nt < s.tail_residual_16term_nt, "{s:?}");
    for f in &s.sensors[1..] {
        assert!(f.residual_nt * 10.0 < f.residual_16term_nt, "{f:?}");
        let oracle = f.oracle_nt.unwrap();
        assert!(f.residual_nt <= 1.5 * oracle, "{f:?}");
        // The oracle sits above the sensor noise: the model family does
        // not describe the simulator's richer physics exactly.
        assert!(oracle > 2.0 * f.noise_floor_nt, "{f:?}");
    }
    let worst = s.sensors[1..]
        .iter()
        .max_by(|a, b| {
            a.reference_mode_nt
                .unwrap()
                .total_cmp(&b.reference_mode_nt.unwrap())
        })
        .unwrap();
    assert_eq!(s.reference_mode_worst_nt, worst.reference_mode_nt.unwrap());
    assert!(
        s.reference_mode_worst_nt <= 1.2 * worst.oracle_nt.unwrap(),
        "{worst:?}"
    );
    // The same chain by the Kalman method: no sensor worse than least
    // squares beyond 2 %. The stinger is the sensor the Kalman method fits
    // (measured 0.1648 against 0.1638 nT); the cabin sensors are fitted by
    // least squares against the stinger's least-squares compensation
    // whatever the method, so theirs equal the LS chain's. Against the
    // Kalman-compensated stinger they came out up to 3.3 % higher (mag_3_uc
    // 0.1055 against 0.1022 nT, once the box was filtered through its
    // turns). Before the reference-sensor mode fitted the cabin sensors by
    // least squares, mag_5_uc came out at 3× (0.631 against 0.210 nT on the
    // quick survey).
    println!(
        "Kalman chain: tail {:.3}, cabin worst {:.3}, worst ratio to LS {:.3}",
        s.kalman_tail_residual_nt, s.kalman_cabin_residual_worst_nt, s.kalman_over_ls_worst
    );
    assert!(s.kalman_over_ls_worst <= 1.02, "{s:?}");
}

/// The term searches under the exact magnitude (issue 20): on a cabin
/// sensor whose currents make a second-order term of nT, the searches'
/// first-order fits see the reading corrected by that term. Measured
/// (`cabin_b_calibration.toml`, mag_3): the band-passed residual with
/// every current 3.56 nT before the correction, 0.565 nT with it; the air
/// conditioner (ac_hi, about 15 nT RMS on that cabin's survey) was dropped
/// before (likelihood ratio 14.7 < 15.5) and is kept.
#[test]
fn exact_magnitude_searches_see_currents_beside_the_second_order_term() {
    use aeromag::compensation::tolles_lawson::{ExtraRequest, Magnitude};
    let toml = include_str!("data/cabin_b_calibration.toml");
    let cal = simulate_flight(ScenarioKind::Calibration, Some(toml), Some(7)).unwrap();
    let currents: Vec<&str> = cal
        .column_names()
        .into_iter()
        .filter(|c| c.starts_with("cur_"))
        .collect();
    assert_eq!(currents.len(), 14, "{currents:?}");
    let mut ls = CalibrateOptions::default().ls;
    ls.design.magnitude = Magnitude::Exact;
    let opts = CalibrateOptions {
        sensor: SensorColumns::find(&cal, "mag_3_uc", Some("flux_a")).unwrap(),
        extra: ExtraRequest::parse_list(&currents.join(",")).unwrap(),
        ls,
        ..CalibrateOptions::default()
    };
    let fit = calibrate(&cal, &opts, &mut Silent).unwrap();
    let sel = fit.model.fit.extra_channel_selection.as_ref().unwrap();
    assert!(sel.residual_all_nt < 1.0, "{sel:?}");
    let ac_hi = sel.tests.iter().find(|t| t.channel == "cur_ac_hi").unwrap();
    assert!(ac_hi.kept, "{sel:?}");
}

/// Another cabin (`tools/validate/perturb_installation.py`, seed 23: loops
/// moved, turned and resized, other lags and switching rates, cabin
/// sensors moved), through the recommended chain: every current `:lag`,
/// the stinger as the cabin sensors' reference on the box, exact
/// magnitude. Its `mag_5_uc` has an oracle of 0.027 nT, so the stinger's
/// heading error decides: fitted leg by leg (the `line` changes ending the
/// legs, the turns filtered apart) the stinger left 0.176 nT on the survey
/// and `mag_5_uc` 0.075 nT, 2.74× its oracle, with the stinger's per-line
/// offsets; fitted through the turns (the reference-sensor mode does that
/// now) 0.157 and 0.033 nT, 1.21×.
#[test]
fn a_perturbed_cabin_meets_its_oracle_with_the_stinger_fitted_through_the_turns() {
    use aeromag::compensation::tolles_lawson::{ExtraRequest, Magnitude};
    use aeromag::studies::{compensated, line_error_rms, oracle};
    let cal = simulate_flight(
        ScenarioKind::Calibration,
        Some(include_str!("data/cabin_b_calibration.toml")),
        Some(7),
    )
    .unwrap();
    let survey = simulate_flight(
        ScenarioKind::Survey,
        Some(include_str!("data/cabin_b_survey.toml")),
        Some(8),
    )
    .unwrap();
    let currents: Vec<String> = cal
        .column_names()
        .into_iter()
        .filter(|c| c.starts_with("cur_"))
        .map(|c| format!("{c}:lag"))
        .collect();
    let mut ls = CalibrateOptions::default().ls;
    ls.design.magnitude = Magnitude::Exact;
    let opts = CalibrateOptions {
        extra: ExtraRequest::parse_list(&currents.join(",")).unwrap(),
        ls,
        ..CalibrateOptions::default()
    };
    let set = SensorSet {
        sensors: vec![
            SensorColumns::find(&cal, "mag_1_uc", Some("flux_a")).unwrap(),
            SensorColumns::find(&cal, "mag_5_uc", Some("flux_a")).unwrap(),
        ],
        reference: Some("mag_1_uc".into()),
    };
    let chain = calibrate_sensors(&cal, &set, &opts, &mut Silent).unwrap();
    let comp = chain.model.compensate(&survey).unwrap();
    let stinger = line_error_rms(&survey, &comp.sensors[0].2, 1).unwrap();
    let mag_5 = line_error_rms(&survey, &comp.sensors[1].2, 5).unwrap();
    let mag_5_oracle = oracle(&survey, &set.sensors[1], &chain.model.sensors[1].model, 5).unwrap();
    // The stinger alone, leg by leg (the default of a single-sensor fit).
    let by_legs = calibrate(
        &cal,
        &CalibrateOptions {
            sensor: set.sensors[0].clone(),
            ..opts.clone()
        },
        &mut Silent,
    )
    .unwrap();
    let by_legs = compensated(&survey, &set.sensors[0], by_legs.model).unwrap();
    let stinger_by_legs = line_error_rms(&survey, &by_legs, 1).unwrap();
    println!(
        "stinger {stinger:.4} nT (leg by leg {stinger_by_legs:.4}); mag_5_uc {mag_5:.4} nT, oracle {mag_5_oracle:.4} ({:.2}×)",
        mag_5 / mag_5_oracle
    );
    assert!(stinger < stinger_by_legs, "{stinger} {stinger_by_legs}");
    assert!(mag_5 <= 1.5 * mag_5_oracle, "{mag_5} {mag_5_oracle}");
}

/// `Contributions::of` evaluates a model without lagged columns block by
/// block into the moments; the table is the one of the four flight-long
/// part series, bit for bit: a box repeated past one moment block (2¹⁶
/// rows) without manoeuvre codes, and with them, missing values splitting
/// segments inside a block and across a block's edge. A model with lagged
/// columns takes the series.
#[test]
fn contributions_block_by_block_are_the_part_series_bits() {
    use aeromag::tolles_lawson::{Contributions, InterferenceParts};
    let cal = calibration(3);
    let (classical, lagged) = (
        classical_model(&cal),
        calibrate(&cal, &CalibrateOptions::default(), &mut Silent)
            .unwrap()
            .model,
    );
    assert!(classical.design.rows_apart() && !lagged.design.rows_apart());
    let n = cal.n_rows();
    let copies = (1 << 16) / n + 2;
    let long = |codes: bool| {
        let mut t = FlightTable::new();
        let dt = cal.require("time").unwrap()[1] - cal.require("time").unwrap()[0];
        for c in cal.columns() {
            if c.name() == "manoeuvre" && !codes {
                continue;
            }
            let v = c.values().unwrap();
            let mut all: Vec<f64> = (0..copies * n)
                .map(|i| match c.name() {
                    "time" => i as f64 * dt,
                    _ => v[i % n],
                })
                .collect();
            if c.name() == "flux_x" {
                for hole in [1000, 65_530, 65_545, 65_536 + 4000] {
                    all[hole] = f64::NAN;
                }
            }
            t.add_column(c.name(), all).unwrap();
        }
        Flight::from_table(t).unwrap()
    };
    for codes in [false, true] {
        let flight = long(codes);
        for model in [&classical, &lagged] {
            let p = InterferenceParts::of(model, &flight, &SensorColumns::default()).unwrap();
            let series = Contributions::from_series(
                [&p.permanent, &p.induced, &p.eddy, &p.currents],
                flight.column("manoeuvre"),
            );
            let blocks = Contributions::of(model, &flight).unwrap();
            assert_eq!(blocks, series, "codes {codes}, {}", model.design.terms);
            assert!(series.groups.iter().all(|g| g.total_nt > 0.0));
        }
    }
}

/// A long flight of many legs with current channels: the cabin box
/// repeated 60 times (about 370 000 rows in some 420 legs). The current
/// channels' lag search samples 30 000 rows of it; it used to take the
/// same fraction of every leg, slivers too short to filter beside the
/// lagged eddy columns, and the calibration with the default lag search
/// stopped ("no segment is long enough to fit"). Whole legs are sampled
/// now: the default calibration keeps both currents, the flap one with a
/// lag; with the box's own classical eddy terms the flap current's field
/// lag (0.4 s in the simulator) is found within the box's own bound.
#[test]
fn a_long_flight_of_many_legs_calibrates_with_current_channels() {
    use aeromag::compensation::tolles_lawson::ExtraRequest;
    let cal = cabin_calibration();
    let (n, copies) = (cal.n_rows(), 60);
    let time = cal.require("time").unwrap();
    let dt = time[1] - time[0];
    let mut t = FlightTable::new();
    for c in cal.columns() {
        let v = c.values().unwrap();
        let all: Vec<f64> = (0..copies * n)
            .map(|i| match c.name() {
                "time" => time[0] + i as f64 * dt,
                "line" => v[i % n] + 1000.0 * (i / n) as f64,
                _ => v[i % n],
            })
            .collect();
        t.add_column(c.name(), all).unwrap();
    }
    let long = Flight::from_table(t).unwrap();
    let opts = CalibrateOptions {
        sensor: SensorColumns::find(&long, "mag_2", Some("flux_b")).unwrap(),
        extra: ExtraRequest::parse_list("cur_strb,cur_flap:lag").unwrap(),
        ..CalibrateOptions::default()
    };
    let fit = calibrate(&long, &opts, &mut Silent).unwrap();
    let extras = fit.model.design.terms.extras();
    assert_eq!(extras.len(), 2, "{:?}", fit.model.design.terms);
    assert!(extras[1].lag_s.is_some(), "{extras:?}");
    // With the classical eddy terms, as the box alone chooses them (copies
    // of one box make lags look significant: the same rows counted 60
    // times), the bound of the box's own test
    // (`current_terms_compensate_a_cabin_sensor`).
    let classical = CalibrateOptions {
        eddy_lag: EddyLag::None,
        ..opts
    };
    let fit = calibrate(&long, &classical, &mut Silent).unwrap();
    let terms = &fit.model.design.terms;
    let tau = terms.extras()[1].lag_s.unwrap();
    assert!((tau - 0.4).abs() < 0.02, "{terms:?}");
}

/// The residual per line of a flight whose `line` column is text (`L1`,
/// `L2`, …, `0` for the turns) is reported under those labels: every line was `0` in
/// `report`'s table and figures before.
#[test]
fn the_residual_per_line_keeps_text_labels() {
    let cal = simulate_flight(ScenarioKind::Calibration, None, Some(3)).unwrap();
    let model = calibrate(&cal, &CalibrateOptions::default(), &mut Silent)
        .unwrap()
        .model;
    let flight = model.compensate(&cal).unwrap().into_flight(cal).unwrap();
    let numeric = aeromag::score::score(&flight, &[], None).unwrap();
    let mut t = aeromag::FlightTable::new();
    for c in flight.columns() {
        match (c.name(), c.values()) {
            ("line", Some(v)) => t
                .add_text_column(
                    "line",
                    // 0 stays the turns' "no line".
                    v.iter()
                        .map(|&x| {
                            if x == 0.0 {
                                "0".into()
                            } else {
                                format!("L{x}")
                            }
                        })
                        .collect(),
                )
                .unwrap(),
            (name, Some(v)) => t.add_column(name, v.to_vec()).unwrap(),
            _ => {}
        }
    }
    let texts = aeromag::score::score(&Flight::from_table(t).unwrap(), &[], None).unwrap();
    assert!(numeric.lines.len() > 1, "{:?}", numeric.lines);
    assert_eq!(numeric.lines.len(), texts.lines.len());
    for (a, b) in numeric.lines.iter().zip(&texts.lines) {
        assert_eq!(b.line.to_string(), format!("L{}", a.line));
        assert_eq!((a.samples, a.rms_nt), (b.samples, b.rms_nt));
    }
}

/// A compensated flight whose columns are not what they say is bad input
/// naming the row and column: `mag_comp` beyond any field (a report gave
/// an improvement ratio of 0.000), in µT (a residual of −53 046 nT), or not
/// `mag − mag_interf` (`mag_interf` in pT, `mag` and `mag_comp` swapped),
/// all reported without a word before.
#[test]
fn a_compensated_flight_whose_columns_disagree_is_not_scored() {
    let cal = simulate_flight(ScenarioKind::Calibration, None, Some(3)).unwrap();
    let model = classical_model(&cal);
    let flight = model.compensate(&cal).unwrap().into_flight(cal).unwrap();
    assert!(aeromag::score::score(&flight, &[], None).is_ok());
    let edited = |edit: &dyn Fn(&str, &mut Vec<f64>)| {
        let mut t = FlightTable::new();
        for c in flight.columns() {
            if let Some(v) = c.values() {
                let mut v = v.to_vec();
                edit(c.name(), &mut v);
                t.add_column(c.name(), v).unwrap();
            }
        }
        Flight::from_table(t).unwrap()
    };
    let mag = flight.require("mag").unwrap().to_vec();
    let comp = flight.require("mag_comp").unwrap().to_vec();
    type Edit = Box<dyn Fn(&str, &mut Vec<f64>)>;
    let cases: [(&str, Edit, &str); 4] = [
        (
            "beyond",
            Box::new(|n, v| {
                if n == "mag_comp" {
                    v[100] = 1e300;
                }
            }),
            "beyond any magnetic field",
        ),
        (
            "µT",
            Box::new(|n, v| {
                if n == "mag_comp" {
                    v.iter_mut().for_each(|x| *x *= 1e-3);
                }
            }),
            "another unit",
        ),
        (
            "pT",
            Box::new(|n, v| {
                if n == "mag_interf" {
                    v.iter_mut().for_each(|x| *x *= 1e3);
                }
            }),
            "is not `mag` minus `mag_interf`",
        ),
        (
            "swapped",
            Box::new(move |n, v| match n {
                "mag" => v.copy_from_slice(&comp),
                "mag_comp" => v.copy_from_slice(&mag),
                _ => {}
            }),
            "is not `mag` minus `mag_interf`",
        ),
    ];
    for (what, edit, needle) in cases {
        let e = aeromag::score::score(&edited(&*edit), &[], None).unwrap_err();
        let msg = e.to_string();
        assert!(
            e.is_bad_input() && msg.contains(needle) && msg.contains("column 'mag_comp'"),
            "{what}: {msg}"
        );
    }
}

/// A flight without `alt` (MagNav's TL test arrays have no positions):
/// the Kalman method and `observability` said only "required column 'alt'
/// is missing"; now what it is needed for and that the LS method fits
/// without it.
#[test]
fn the_kalman_method_says_why_it_needs_the_altitude() {
    let cal = simulate_flight(ScenarioKind::Calibration, None, Some(1)).unwrap();
    let mut t = FlightTable::new();
    for c in cal.table().columns() {
        if c.name() != "alt" && !c.name().starts_with("true_") {
            t.add_column(c.name(), c.values().unwrap().to_vec())
                .unwrap();
        }
    }
    let flight = Flight::from_table(t).unwrap();
    let e = calibrate(&flight, &CalibrateOptions::kalman(), &mut Silent).unwrap_err();
    let text = e.to_string();
    assert!(
        e.is_bad_input() && text.contains("has no `alt` column") && text.contains("--method ls"),
        "{text}"
    );
}
