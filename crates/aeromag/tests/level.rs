//! Levelling at crossovers through the library: the diurnal drift removed
//! by line levels, and `k` of the `k·d|B0|/dt` term recovered with the base
//! station removed.

mod common;

use aeromag::FlightTable;
use aeromag::compensation::levelling::LevellingConfig;
use aeromag::level::{LevelOptions, Levelled, level};
use aeromag::prelude::*;
use aeromag::simulate::{ScenarioKind, simulate_flight};
use common::with_projected_positions;

const LEVER_ARM_M: [f64; 3] = [-9.5, 0.0, -0.6];

#[test]
fn line_levels_remove_the_diurnal_drift_and_every_row_is_kept() {
    let survey = simulate_flight(ScenarioKind::Survey, None, Some(4)).unwrap();
    let lev = level(
        &survey,
        &LevelOptions {
            lever_arm_m: Some(LEVER_ARM_M),
            fit: LevellingConfig {
                drift: true,
                ..LevellingConfig::default()
            },
            ..LevelOptions::default()
        },
        &mut Silent,
    )
    .unwrap();
    assert_eq!(lev.value_column, "mag");
    // Without a base-station correction the crossover differences are
    // dominated by the diurnal drift, which per-line offsets and drifts
    // remove: the model residual and the levelled series' differences both
    // fall ≥ 5×.
    let f = &lev.levelling.fit;
    assert!(
        f.rms_after_nt < f.rms_before_nt / 5.0 && f.rms_levelled_nt < f.rms_before_nt / 5.0,
        "{} → {} / {}",
        f.rms_before_nt,
        f.rms_after_nt,
        f.rms_levelled_nt
    );
    assert_eq!(lev.levelling.levelled.value_nt.len(), survey.n_rows());
    let mut t = survey.table().clone();
    lev.add_to(&mut t).unwrap();
    assert!(t.column("mag_level").is_some() && t.column("level_flag").is_some());
    // A flight that already has the outputs is refused.
    let again = Flight::from_table(t).unwrap();
    assert!(
        level(&again, &LevelOptions::default(), &mut Silent)
            .unwrap_err()
            .is_bad_input()
    );
}

/// With the base station and the IGRF subtracted, k (truth: the scalar
/// sensor's 0.1 s lag, k = −0.1 s) is recovered within 10 % and within three
/// of its standard deviations on the compensated default survey (100
/// crossovers), and the altitude term (the crossovers' height differences
/// times the vertical gradient from the crossing profiles) makes it at
/// least 1.6× sharper. Over the demo seeds 1–5 (robust weighting on):
/// k = −0.0972, −0.0961, −0.1029, −0.1060, −0.1103 s, σ 0.0031–0.0065 s;
/// seed 5 is 10.3 % off (1.6 σ).
#[test]
fn with_the_base_station_removed_k_is_recovered() {
    let cal = simulate_flight(ScenarioKind::Calibration, None, Some(1)).unwrap();
    let survey = simulate_flight(ScenarioKind::Survey, None, Some(2)).unwrap();
    let model = calibrate(&cal, &CalibrateOptions::default(), &mut Silent)
        .unwrap()
        .model;
    let comp = model
        .compensate(&survey)
        .unwrap()
        .into_flight(survey)
        .unwrap();
    let run = |f: &dyn Fn(&mut LevelOptions)| -> Levelled {
        let mut opts = LevelOptions {
            lever_arm_m: Some(LEVER_ARM_M),
            reference: ReferenceChannels::Auto,
            ..LevelOptions::default()
        };
        f(&mut opts);
        level(&comp, &opts, &mut Silent).unwrap()
    };
    let lev = run(&|_| {});
    assert_eq!(lev.value_column, "mag_comp");
    assert_eq!(lev.reference_columns, ["diurnal", "igrf"]);
    assert_eq!(lev.rate_column, "mag");
    let f = &lev.levelling.fit;
    let (k, sd) = (f.k_s, f.k_std_s);
    assert!(
        sd > 0.0 && sd < 0.01 && (k + 0.1).abs() <= 3.0 * sd && (k + 0.1).abs() <= 0.01,
        "k = {k} ± {sd}"
    );
    assert!(f.altitude_term_used);
    assert_eq!(
        lev.levelling.crossovers.crossovers.len(),
        100,
        "20 lines × 5 ties"
    );
    let table = lev.crossover_table().unwrap();
    assert_eq!(table.n_rows(), 100);
    assert!(table.column("weight").is_some() && table.column("residual_nt").is_some());
    // Plain least squares also gives a finite k.
    let plain = run(&|o| o.fit.robust = false);
    assert!(plain.levelling.fit.k_s.is_finite());
    // Without the altitude term k is far less sharp.
    let no_alt = run(&|o| o.fit.altitude_term = false);
    let sd0 = no_alt.levelling.fit.k_std_s;
    assert!(
        sd0 > 1.6 * sd,
        "σ_k {sd0} without the altitude term vs {sd} with it"
    );
    // The regressor is the derivative of the uncompensated `mag` by default;
    // that of the compensated value misses the lag of the aircraft's own
    // field, which stays in the crossover residual.
    let of_comp = run(&|o| o.rate_of = Some("mag_comp".into()));
    assert_eq!(of_comp.rate_column, "mag_comp");
    let r = |l: &Levelled| l.levelling.fit.rms_after_nt;
    assert!(
        r(&lev) < 0.9 * r(&of_comp),
        "model residual {} nT (Ḃ of mag) vs {} nT (Ḃ of mag_comp)",
        r(&lev),
        r(&of_comp)
    );
}

/// `survey` with its table edited by `edit`, checked again.
fn edited(survey: &Flight, edit: &dyn Fn(&mut FlightTable)) -> Flight {
    let mut t = survey.table().clone();
    edit(&mut t);
    Flight::from_table(t).unwrap()
}

/// The ties of the default survey (labels 2001…) in a `line_type` column.
fn typed_ties(t: &mut FlightTable) {
    let v = t
        .column("line")
        .unwrap()
        .iter()
        .map(|&l| f64::from(l >= 2001.0))
        .collect();
    t.add_column("line_type", v).unwrap();
}

/// `t` with its numeric `line` labels replaced by the text ones `text`
/// under the same name (the other columns as they are).
fn text_labels(t: &mut FlightTable, text: &[String]) {
    let mut fresh = FlightTable::new();
    for c in t.columns() {
        match c.name() {
            "line" => fresh.add_text_column("line", text.to_vec()).unwrap(),
            n => fresh.add_column(n, c.values().unwrap().to_vec()).unwrap(),
        }
    }
    *t = fresh;
}

/// Line labels are labels: the default survey (lines 1001…, ties 2001…)
/// relabelled as text (`L1001`, `T2001`), as SGL-style decimals
/// (`1001.01`), or with a `line_type` column levels to the same k and line
/// levels as with its integer labels; declared ties keep only line–tie
/// crossings.
#[test]
fn text_decimal_and_typed_labels_level_like_integer_labels() {
    let survey = simulate_flight(ScenarioKind::Survey, None, Some(3)).unwrap();
    let opts = LevelOptions::default();
    let base = level(&survey, &opts, &mut Silent).unwrap();
    let line = survey.require("line").unwrap().to_vec();
    let relabelled = |edit: &dyn Fn(&mut FlightTable)| edited(&survey, edit);
    let text: Vec<String> = line
        .iter()
        .map(|&l| match l {
            0.0 => String::new(),
            l if l >= 2001.0 => format!("T{l}"),
            l => format!("L{l}"),
        })
        .collect();
    let as_text = relabelled(&|t| text_labels(t, &text));
    let decimal = relabelled(&|t| {
        let v = line
            .iter()
            .map(|&l| if l == 0.0 { 0.0 } else { l + 0.01 })
            .collect();
        t.set_column("line", v).unwrap();
    });
    let typed = relabelled(&typed_ties);
    let declared = LevelOptions {
        ties: (2001..=2005).map(|l| l.to_string()).collect(),
        ..LevelOptions::default()
    };
    let runs = [
        level(&as_text, &opts, &mut Silent).unwrap(),
        level(&decimal, &opts, &mut Silent).unwrap(),
        level(&typed, &opts, &mut Silent).unwrap(),
        level(&survey, &declared, &mut Silent).unwrap(),
    ];
    let n = base.levelling.crossovers.crossovers.len();
    assert!(n >= 90, "{n} crossovers");
    for (k, lev) in runs.iter().enumerate() {
        let (a, b) = (&base.levelling.fit, &lev.levelling.fit);
        assert_eq!(lev.levelling.crossovers.crossovers.len(), n, "run {k}");
        assert_eq!(a.k_s, b.k_s, "run {k}");
        assert_eq!(a.lines.len(), b.lines.len(), "run {k}");
        for (la, lb) in a.lines.iter().zip(&b.lines) {
            assert_eq!(la.offset_nt, lb.offset_nt, "run {k}");
        }
    }
    // Labels come back as written, in the crossover table too.
    assert_eq!(runs[0].lines.label(1), Some("L1001"));
    let xt = runs[0].crossover_table().unwrap();
    assert!(xt.text_column("line_b").unwrap()[0].starts_with('T'));
    let xd = runs[1].crossover_table().unwrap();
    assert!(
        xd.column("line_a")
            .unwrap()
            .iter()
            .all(|l| (l * 100.0).round() % 100.0 == 1.0)
    );
    // Ties declared among the lines: line–line crossings are not formed,
    // and a tie label that matches nothing is bad input.
    let wrong = LevelOptions {
        ties: vec!["1001".into()],
        ..LevelOptions::default()
    };
    // (line 1001 as the only "tie": only its 5 crossings with the real ties
    // are left, which cannot determine k and the levels).
    let e = level(&survey, &wrong, &mut Silent).unwrap_err();
    assert!(e.to_string().contains("5 crossovers"), "{e}");
    let missing = LevelOptions {
        ties: vec!["9999".into()],
        ..LevelOptions::default()
    };
    assert!(
        level(&survey, &missing, &mut Silent)
            .unwrap_err()
            .is_bad_input()
    );
}

/// A file that marks no tie says nothing about ties: a `line_type` column
/// of zeros (a Geosoft XYZ export that labels every line `Line`, tie lines
/// too) or labels that all start with `L` level as plain labels do (any
/// two crossing lines), where before they found no crossover; ties given
/// by the caller are ties whatever the file says.
#[test]
fn a_file_that_marks_no_tie_levels_as_plain_labels_and_given_ties_count() {
    use aeromag::flight::LineLabels;
    let survey = simulate_flight(ScenarioKind::Survey, None, Some(3)).unwrap();
    let line = survey.require("line").unwrap().to_vec();
    let with = |edit: &dyn Fn(&mut FlightTable)| edited(&survey, edit);
    let untyped = with(&|t| t.add_column("line_type", vec![0.0; line.len()]).unwrap());
    let l_text: Vec<String> = line
        .iter()
        .map(|&l| {
            if l == 0.0 {
                String::new()
            } else {
                format!("L{l}")
            }
        })
        .collect();
    let l_only = with(&|t| text_labels(t, &l_text));
    let ties: Vec<String> = (2001..=2005).map(|l| l.to_string()).collect();
    let opts = LevelOptions::default();
    let plain = level(&survey, &opts, &mut Silent).unwrap();
    for f in [&untyped, &l_only] {
        assert_eq!(LineLabels::of(f, &[]).unwrap().ties, None);
        let lev = level(f, &opts, &mut Silent).unwrap();
        assert_eq!(
            lev.levelling.crossovers.crossovers.len(),
            plain.levelling.crossovers.crossovers.len()
        );
        assert_eq!(lev.levelling.fit.k_s, plain.levelling.fit.k_s);
        // The ties given count on such a file too.
        let given = LineLabels::of(f, &ties).unwrap().ties.unwrap();
        assert_eq!(given.iter().filter(|&&t| t).count(), 5);
    }
    // A file that marks ties, and one more given: both count.
    let typed = with(&typed_ties);
    let marked = LineLabels::of(&typed, &[]).unwrap();
    let both = LineLabels::of(&typed, &["1001".to_string()]).unwrap();
    let count = |l: &LineLabels| l.ties.as_ref().unwrap().iter().filter(|&&t| t).count();
    assert_eq!((count(&marked), count(&both)), (5, 6));
    let k = both.labels.iter().position(|l| l == "1001").unwrap();
    assert!(both.ties.as_ref().unwrap()[k] && !marked.ties.as_ref().unwrap()[k]);
}

/// A GPS dropout written as latitude and longitude 0 (a row of a line,
/// mid-survey) made crossovers of its own (10 on a survey, one line
/// shifted by 55 nT) while `grid` and `microlevel` left it out: `level`
/// leaves it out too, with the `[position-glitch]` warning, and levels as
/// without it.
#[test]
fn a_gps_dropout_row_makes_no_crossover() {
    let survey = simulate_flight(ScenarioKind::Survey, None, Some(3)).unwrap();
    let opts = LevelOptions::default();
    let clean = level(&survey, &opts, &mut Silent).unwrap();
    let row = survey.n_rows() / 3;
    let dropout = edited(&survey, &|t: &mut FlightTable| {
        let mut fresh = FlightTable::new();
        for c in t.columns() {
            let mut v = c.values().unwrap().to_vec();
            if matches!(c.name(), "lat" | "lon") {
                v[row] = 0.0;
            }
            fresh.add_column(c.name(), v).unwrap();
        }
        *t = fresh;
    });
    let lev = level(&dropout, &opts, &mut Silent).unwrap();
    assert!(
        lev.notes.iter().any(|n| n.is_warning()
            && n.message.contains("1 row is off the track")
            && n.message.contains(&format!("data row {}", row + 1))
            && n.message.contains("[position-glitch]")),
        "{:?}",
        lev.notes
    );
    let (a, b) = (&clean.levelling, &lev.levelling);
    assert_eq!(a.crossovers.crossovers.len(), b.crossovers.crossovers.len());
    for (la, lb) in a.fit.lines.iter().zip(&b.fit.lines) {
        assert!(
            (la.offset_nt - lb.offset_nt).abs() < 0.05,
            "{} against {}",
            la.offset_nt,
            lb.offset_nt
        );
    }
}

/// Found by fuzzing the survey chain: an `inf` or 1e300 in the levelled
/// column was levelled into `inf` with exit 0 (and dropped from a grid
/// without a word), a `mag_comp` in tesla was levelled as nT, and `--rate-of
/// time` failed as a singular system: each is bad input saying what is
/// wrong.
#[test]
fn a_levelled_column_that_is_no_field_in_nt_is_refused() {
    let survey = simulate_flight(ScenarioKind::Survey, None, Some(3)).unwrap();
    let row = survey.n_rows() / 2;
    let opts = LevelOptions::default();
    let bad = |f: &Flight, says: &str| {
        let e = level(f, &opts, &mut Silent).unwrap_err();
        assert!(e.is_bad_input() && e.to_string().contains(says), "{e}");
        e
    };
    for v in [f64::INFINITY, 1e300] {
        // The canonical `mag` is checked on reading; `mag_comp` was not.
        let f = edited(&survey, &|t: &mut FlightTable| {
            let mut comp = t.column("mag").unwrap().to_vec();
            comp[row] = v;
            t.add_column("mag_comp", comp).unwrap();
        });
        let e = bad(&f, "is no magnetic field value in nT");
        assert_eq!(e.location().row, Some(row));
        assert_eq!(e.location().column.as_deref(), Some("mag_comp"));
    }
    let tesla = edited(&survey, &|t: &mut FlightTable| {
        let mag = t.column("mag").unwrap().iter().map(|v| v * 1e-9).collect();
        t.add_column("mag_comp", mag).unwrap();
    });
    bad(&tesla, "tesla?");
    let rate = LevelOptions {
        rate_of: Some("time".into()),
        ..LevelOptions::default()
    };
    let e = level(&survey, &rate, &mut Silent).unwrap_err();
    assert!(
        e.is_bad_input() && e.to_string().contains("the rate of `time`"),
        "{e}"
    );
}

/// Found by fuzzing the survey chain: a line flown again under its first
/// label, after the other lines, with a level error of 50 nT, was levelled
/// with the first pass's offset, and the 50 nT stayed in the levelled
/// column with exit 0. Each pass is now a line of its own, named in the
/// `[line-repeated]` warning: the re-flight is levelled to the first
/// flight's level.
#[test]
fn a_label_flown_twice_is_levelled_per_pass() {
    let survey = simulate_flight(ScenarioKind::Survey, None, Some(3)).unwrap();
    let line = survey.column("line").unwrap();
    let label = 1003.0;
    let rows: Vec<usize> = (0..line.len()).filter(|&i| line[i] == label).collect();
    assert!(rows.len() > 100, "{} rows on line 1003", rows.len());
    let time = survey.column("time").unwrap();
    let shift_s = time[time.len() - 1] - time[rows[0]] + 100.0;
    let again = edited(&survey, &|t: &mut FlightTable| {
        typed_ties(t);
        let mut fresh = FlightTable::new();
        for c in t.columns() {
            let mut v = c.values().unwrap().to_vec();
            let extra = rows.iter().map(|&i| match c.name() {
                "time" => v[i] + shift_s,
                "mag" => v[i] + 50.0,
                _ => v[i],
            });
            let extra: Vec<f64> = extra.collect();
            v.extend(extra);
            fresh.add_column(c.name(), v).unwrap();
        }
        *t = fresh;
    });
    let lev = level(&again, &LevelOptions::default(), &mut Silent).unwrap();
    let pass_two = lev.lines.labels.iter().position(|l| l == "1003 (pass 2)");
    let pass_two = pass_two.expect("the second pass is a line") as i64 + 1;
    assert!(
        lev.notes.iter().any(|n| n.is_warning()
            && n.message
                .contains("1003 (2 passes, the second from data row")
            && n.message.contains("'1003 (pass 2)'")
            && n.message.ends_with("[line-repeated]")),
        "{:?}",
        lev.notes
    );
    let table = lev.crossover_table().unwrap();
    let named = |c: &str| table.get(c).unwrap().text().unwrap().to_vec();
    assert!(
        named("line_a")
            .iter()
            .chain(&named("line_b"))
            .any(|l| l == "1003 (pass 2)")
    );
    let fit = &lev.levelling.fit;
    let second = fit.lines.iter().find(|l| l.label == pass_two).unwrap();
    assert!(second.crossovers >= 3, "{} crossovers", second.crossovers);
    // The two passes, row for row, after levelling: the 50 nT are gone.
    let out = &lev.levelling.levelled.value_nt;
    let n = survey.n_rows();
    let mean = rows
        .iter()
        .enumerate()
        .map(|(j, &i)| out[n + j] - out[i])
        .sum::<f64>()
        / rows.len() as f64;
    assert!(mean.abs() < 1.0, "the re-flight is {mean} nT off the first");
}

/// A survey whose positions are UTM eastings and northings (`X`, `Y`, no
/// lat/lon) levels as its latitudes and longitudes do once their zone is
/// given: the same crossovers and levelled values to 10⁻⁶ nT (the inverse
/// projection is exact to far below a millimetre). Without the zone it is
/// bad input naming `--utm-zone`; a dropout at 0, 0 is named by its X, Y.
#[test]
fn projected_positions_level_as_latitude_and_longitude_given_their_zone() {
    use aeromag::grid::projection::{Utm, UtmZone};
    let survey = simulate_flight(ScenarioKind::Survey, None, Some(4)).unwrap();
    let zone: UtmZone = "37N".parse().unwrap();
    let (lat, lon) = (
        survey.require("lat").unwrap(),
        survey.require("lon").unwrap(),
    );
    let (x, y) = Utm::new(zone).forward_all(lat, lon).unwrap();
    let with_xy = |x: &[f64], y: &[f64]| with_projected_positions(&survey, x, y);
    let xy = with_xy(&x, &y);
    let geodetic = level(&survey, &LevelOptions::default(), &mut Silent).unwrap();
    let opts = LevelOptions {
        zone: Some(zone),
        ..LevelOptions::default()
    };
    let projected = level(&xy, &opts, &mut Silent).unwrap();
    let (a, b) = (&geodetic.levelling, &projected.levelling);
    assert_eq!(a.crossovers.crossovers.len(), b.crossovers.crossovers.len());
    assert!(a.crossovers.crossovers.len() > 50);
    let most = a
        .levelled
        .value_nt
        .iter()
        .zip(&b.levelled.value_nt)
        .map(|(p, q)| (p - q).abs())
        .fold(0.0, f64::max);
    assert!(most < 1e-6, "levelled values differ by {most} nT");
    assert!(
        projected
            .notes
            .iter()
            .any(|n| n.message.contains("projected columns X (easting) and Y")),
        "{:?}",
        projected.notes
    );

    let e = level(&xy, &LevelOptions::default(), &mut Silent).unwrap_err();
    assert!(
        e.is_bad_input() && e.to_string().contains("--utm-zone"),
        "{e}"
    );
    // A lever arm is refused with projected positions (it said that the
    // file had no `lat`).
    let arm = LevelOptions {
        lever_arm_m: Some(LEVER_ARM_M),
        ..opts.clone()
    };
    let e = level(&xy, &arm, &mut Silent).unwrap_err();
    assert!(
        e.is_bad_input() && e.to_string().contains("lever arm"),
        "{e}"
    );

    // A dropout at 0, 0 (no UTM easting, but off the track) is left out
    // with the warning naming its X and Y; eastings in kilometres are no
    // UTM eastings: refused, naming the row and the column.
    let row = 5000;
    let (mut gx, mut gy) = (x.clone(), y.clone());
    (gx[row], gy[row]) = (0.0, 0.0);
    let glitched = level(&with_xy(&gx, &gy), &opts, &mut Silent).unwrap();
    let warned: Vec<&str> = glitched
        .notes
        .iter()
        .filter(|n| n.message.contains("[position-glitch]"))
        .map(|n| n.message.as_str())
        .collect();
    assert!(
        warned.len() == 1
            && warned[0].contains(&format!("data row {}", row + 1))
            && warned[0].contains("X 0, Y 0"),
        "{warned:?}"
    );
    let km: Vec<f64> = x.iter().map(|v| v / 1000.0).collect();
    let e = level(&with_xy(&km, &y), &opts, &mut Silent).unwrap_err();
    assert!(
        e.is_bad_input()
            && e.to_string().contains("data row 1,")
            && e.to_string().contains("'X'")
            && e.to_string().contains("not a UTM easting"),
        "{e}"
    );
}

/// A survey without `alt` (an XYZ of positions and the field) is levelled
/// without the altitude term, saying so: the same values as the full
/// survey levelled without it (it was refused: "required column 'alt' is
/// missing").
#[test]
fn a_survey_without_heights_is_levelled_without_the_altitude_term() {
    let survey = simulate_flight(ScenarioKind::Survey, None, Some(6)).unwrap();
    let mut t = FlightTable::new();
    for c in survey
        .table()
        .columns()
        .iter()
        .filter(|c| c.name() != "alt")
    {
        match (c.values(), c.text()) {
            (Some(v), _) => t.add_column(c.name(), v.to_vec()),
            (_, Some(text)) => t.add_text_column(c.name(), text.to_vec()),
            _ => unreachable!("a column holds numbers or text"),
        }
        .unwrap();
    }
    let no_alt = Flight::from_table(t).unwrap();
    let lev = level(&no_alt, &LevelOptions::default(), &mut Silent).unwrap();
    let without_term = LevelOptions {
        fit: LevellingConfig {
            altitude_term: false,
            ..LevellingConfig::default()
        },
        ..LevelOptions::default()
    };
    let reference = level(&survey, &without_term, &mut Silent).unwrap();
    assert!(!lev.levelling.crossovers.crossovers.is_empty());
    assert!(!lev.levelling.fit.altitude_term_used);
    let bits = |l: &Levelled| -> Vec<u64> {
        l.levelling
            .levelled
            .value_nt
            .iter()
            .map(|v| v.to_bits())
            .collect()
    };
    assert_eq!(bits(&lev), bits(&reference));
    let said = |l: &Levelled| {
        l.notes
            .iter()
            .any(|n| n.message.contains("no `alt` column"))
    };
    assert!(said(&lev), "{:?}", lev.notes);
    // Asked for no altitude term, nothing to say.
    assert!(!said(&level(&no_alt, &without_term, &mut Silent).unwrap()));
}
