//! The towed-pod models through the library (spec `helicopter.md` part B,
//! issue 5): learn on the seed's headings, compensate the independent
//! heading set of another flight, score against the simulator's truth
//! columns (the models never read them).

use aeromag::Flight;
use aeromag::compensation::pod::detrend;
use aeromag::pod::{PodMethod, PodSetup, apply_pod, fit_pod};
use aeromag::prelude::*;
use aeromag::simulate::{ScenarioKind, simulate_flight};

fn rms(x: &[f64]) -> f64 {
    (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt()
}

/// Seed-style rate per heading (`line`): `1 − RMS(detrend(mag −
/// true_external − pod_interf)) / RMS(detrend(mag))`, and the same pooled
/// over all rows.
fn rates(f: &Flight, pred: &[f64]) -> (Vec<f64>, f64) {
    let c = |n: &str| f.require(n).unwrap();
    let (mag, ext, line) = (c("mag"), c("true_external"), c("line"));
    let sum_sq = |x: &[f64]| x.iter().map(|v| v * v).sum::<f64>();
    let (mut r, mut pooled_before, mut pooled_after) = (Vec::new(), 0.0, 0.0);
    let mut start = 0;
    for k in 1..=line.len() {
        if k == line.len() || line[k] != line[start] {
            let before = detrend(&mag[start..k]);
            let after: Vec<f64> = (start..k).map(|j| mag[j] - ext[j] - pred[j]).collect();
            let after = detrend(&after);
            r.push(1.0 - rms(&after) / rms(&before));
            pooled_before += sum_sq(&before);
            pooled_after += sum_sq(&after);
            start = k;
        }
    }
    (r, 1.0 - (pooled_after / pooled_before).sqrt())
}

/// A learning flight (sim seed 1) and a test flight on `test_headings`
/// (seed 1001), both with the scenario lines `toml`.
fn pair(toml: &str, test_headings: &str) -> (Flight, Flight) {
    let learn = simulate_flight(ScenarioKind::Pod, Some(toml), None).unwrap();
    let test_toml = format!("{toml}headings_deg = {test_headings}\n");
    let test = simulate_flight(ScenarioKind::Pod, Some(&test_toml), Some(1001)).unwrap();
    (learn, test)
}

/// Truth-scored rates per test heading and pooled of each method, in
/// `methods` order.
fn fit_apply(
    learn: &Flight,
    test: &Flight,
    setup: &PodSetup,
    methods: &[PodMethod],
) -> Vec<(Vec<f64>, f64)> {
    methods
        .iter()
        .map(|&m| {
            let model = fit_pod(learn, setup, m, None, &mut Silent).unwrap().model;
            rates(test, &apply_pod(&model, test).unwrap().interf_nt)
        })
        .collect()
}

fn setup(cable_m: f64, attach_m: [f64; 3], inclination_deg: f64) -> PodSetup {
    PodSetup {
        cable_length_m: cable_m,
        attach_m,
        inclination_deg,
        declination_deg: 0.0,
        grad_north_nt_per_km: 5.91,
        grad_up_nt_per_km: -25.91,
    }
}

#[test]
fn seed_solve_reaches_90_percent_on_the_set_dipole_array_and_joint_97_percent_on_every_heading() {
    let (learn, test) = pair(
        "swing_sine = true\n",
        "[30.0, 120.0, 210.0, 300.0, 70.0, 160.0, 250.0, 340.0]",
    );
    let r = fit_apply(
        &learn,
        &test,
        &setup(40.0, [0.0, 0.0, 1.2], 45.0),
        &[PodMethod::DipoleArray, PodMethod::TwoStep, PodMethod::Joint],
    );
    let ((rd, pd), (rt, pt), (rj, pj)) = (&r[0], &r[1], &r[2]);
    eprintln!(
        "dipole array per test heading {rd:?} pooled {pd}\ntwo-step per test heading {rt:?} \
         pooled {pt}\njoint per test heading {rj:?} pooled {pj}"
    );
    // The seed's solve: its "above 90 %" on the independent set as a whole.
    assert!(*pt >= 0.90, "two-step pooled {pt}");
    assert_eq!(rd.len(), 8);
    assert!(rd.iter().all(|r| *r >= 0.97), "dipole array {rd:?}");
    assert!(rj.iter().all(|r| *r >= 0.97), "joint {rj:?}");
    assert!(rd.iter().zip(rt).all(|(a, b)| a > b), "{rd:?} vs {rt:?}");
}

/// Another installation and other headings than the seed's: a 30 m cable at
/// 65°, the attachment 1 m forward and 0.3 m right, inclination 60°, the
/// wind-driven (random) swing, tested on headings 15, 105, …, 330°.
#[test]
fn other_geometry_and_headings() {
    let (learn, test) = pair(
        "cable_m = 30.0\ncable_inclination_deg = 65.0\nattach_m = [1.0, 0.3, 1.5]\n\
         inclination_deg = 60.0\n",
        "[15.0, 105.0, 195.0, 285.0, 60.0, 150.0, 240.0, 330.0]",
    );
    let r = fit_apply(
        &learn,
        &test,
        &setup(30.0, [1.0, 0.3, 1.5], 60.0),
        &[PodMethod::DipoleArray, PodMethod::Joint, PodMethod::TwoStep],
    );
    for (m, (per, pooled)) in ["dipole-array", "joint", "two-step"].iter().zip(&r) {
        eprintln!("{m}: per heading {per:?} pooled {pooled:.4}");
    }
    assert!(
        r[0].0.iter().all(|r| *r >= 0.97),
        "dipole array {:?}",
        r[0].0
    );
    assert!(r[1].1 >= 0.97, "joint pooled {}", r[1].1);
    assert!(r[2].1 >= 0.90, "two-step pooled {}", r[2].1);
}

#[test]
fn a_missing_value_leaves_its_row_uncompensated_and_out_of_range_angles_are_bad_input() {
    let (learn, test) = pair("swing_sine = true\n", "[30.0, 120.0]");
    let s = setup(40.0, [0.0, 0.0, 1.2], 45.0);
    let fit = fit_pod(&learn, &s, PodMethod::DipoleArray, None, &mut Silent).unwrap();
    assert!(fit.notes.iter().all(|n| !n.is_warning()), "{:?}", fit.notes);
    let model = fit.model;
    // Rows of the learning flight with a missing value are left out with
    // a warning (they were left out without a word).
    let mut t = learn.table().clone();
    for col in ["mag", "roll"] {
        let mut x = t.require(col).unwrap().to_vec();
        x[500..575].iter_mut().for_each(|v| *v = f64::NAN);
        t.set_column(col, x).unwrap();
    }
    let gappy = Flight::from_table(t).unwrap();
    let fit = fit_pod(&gappy, &s, PodMethod::DipoleArray, None, &mut Silent).unwrap();
    let warned: Vec<String> = fit
        .notes
        .iter()
        .filter(|n| n.is_warning())
        .map(|n| n.message.clone())
        .collect();
    assert!(
        warned.len() == 1 && warned[0].starts_with(&format!("75 of {} rows", learn.n_rows())),
        "{warned:?}"
    );
    let edit = |col: &str, row: usize, v: f64| {
        let mut t = test.table().clone();
        let mut x = t.require(col).unwrap().to_vec();
        x[row] = v;
        t.set_column(col, x).unwrap();
        Flight::from_table(t).unwrap()
    };
    let out = model.compensate(&edit("mag", 499, f64::NAN)).unwrap();
    assert_eq!(out.flags()[499], 1.0);
    assert_eq!(out.flags()[0], 0.0);
    assert!(out.compensated_nt[499].is_nan());
    let e = apply_pod(&model, &edit("cable_inclination", 11, 95.0)).unwrap_err();
    assert!(e.is_bad_input());
    let msg = e.to_string();
    assert!(
        msg.contains("cable_inclination") && msg.contains("data row 12"),
        "{msg}"
    );
    // A huge angle is named in exponent form (it printed 309 digits).
    let e = apply_pod(&model, &edit("cable_inclination", 11, 1e308)).unwrap_err();
    assert!(e.to_string().contains("1e308 deg is outside"), "{e}");
    assert!(e.to_string().len() < 300, "{e}");
    // An impossible installation is refused before any work.
    let bad = PodSetup {
        cable_length_m: -1.0,
        ..s
    };
    assert!(
        fit_pod(&learn, &bad, PodMethod::Joint, None, &mut Silent)
            .unwrap_err()
            .is_bad_input()
    );
}

/// Cable angles in radians were taken as degrees, with exit 0: a fit on
/// them learnt 2–30 % (99 % in degrees), and a good model applied to them
/// made the data worse. Both now refuse them, naming the column; the
/// degrees still pass.
#[test]
fn cable_angles_in_radians_are_bad_input() {
    let (learn, test) = pair("", "[30.0, 120.0]");
    let s = setup(40.0, [0.0, 0.0, 1.2], 45.0);
    let model = fit_pod(&learn, &s, PodMethod::DipoleArray, None, &mut Silent)
        .unwrap()
        .model;
    let radians = |f: &Flight, col: &str| {
        let mut t = f.table().clone();
        let x: Vec<f64> = t
            .require(col)
            .unwrap()
            .iter()
            .map(|d| d.to_radians())
            .collect();
        t.set_column(col, x).unwrap();
        Flight::from_table(t).unwrap()
    };
    for col in ["cable_inclination", "cable_azimuth"] {
        let e = fit_pod(
            &radians(&learn, col),
            &s,
            PodMethod::DipoleArray,
            None,
            &mut Silent,
        )
        .unwrap_err();
        assert!(e.is_bad_input(), "{e}");
        assert!(
            e.to_string().contains(col) && e.to_string().contains("radians?"),
            "{e}"
        );
    }
    let e = apply_pod(&model, &radians(&test, "cable_inclination")).unwrap_err();
    assert!(
        e.is_bad_input() && e.to_string().contains("radians?"),
        "{e}"
    );
    assert!(apply_pod(&model, &test).is_ok());
}

/// Issue 23, seed 002 near the magnetic equator: the two-step solve with
/// the axes reordered (the component of U of largest magnitude
/// eliminated) works at every inclination, 0° included, where eliminating
/// U3 divided by zero (measured, seed 1: 0.784, 0.867, 0.891, 0.851, 0.944
/// at 0°, 5°, 30°, 60°, 85°).
#[test]
fn the_two_step_solve_works_from_the_equator_to_the_pole() {
    use aeromag::studies::{PodStudy, Study, StudyOutcome, StudySize};
    let out = PodStudy.run(StudySize::Full, &mut aeromag::Silent).unwrap();
    let s = out.summary();
    eprintln!("{:?}", s.rate_test_by_inclination);
    assert_eq!(s.rate_test_by_inclination.len(), 5);
    for (inclination, rate) in &s.rate_test_by_inclination {
        assert!(rate.is_finite() && *rate > 0.7, "{inclination}°: {rate}");
    }
    assert_eq!(s.rate_test_inclination_0, s.rate_test_by_inclination[0].1);
}

/// Found by fuzzing: one learning heading (or 10 s of one) was fitted to
/// the 63-coefficient array without a word, and the model applied to the
/// other headings gave an "interference" of ±295 000 nT flagged
/// compensated. A fit needs headings in four directions; the seed's two
/// boxes (eight) and one box (four, 90° apart) fit.
#[test]
fn a_learning_flight_of_fewer_than_four_directions_is_refused() {
    let learn = simulate_flight(ScenarioKind::Pod, None, None).unwrap();
    let s = setup(40.0, [0.0, 0.0, 1.2], 45.0);
    let headings = |keep: &[f64]| -> Flight {
        let line = learn.require("line").unwrap();
        let labels: Vec<f64> = {
            let mut l: Vec<f64> = line.to_vec();
            l.dedup();
            l
        };
        let rows: Vec<usize> = (0..learn.n_rows())
            .filter(|&k| keep.iter().any(|&i| line[k] == labels[i as usize]))
            .collect();
        let mut t = aeromag::FlightTable::new();
        for c in learn.table().columns() {
            let v = c.values().unwrap();
            t.add_column(c.name(), rows.iter().map(|&k| v[k]).collect())
                .unwrap();
        }
        Flight::from_table(t).unwrap()
    };
    // The learning set is 0, 90, 180, 270, 45, 135, 225, 315°.
    for keep in [&[0.0][..], &[0.0, 4.0], &[0.0, 4.0, 1.0]] {
        let e = fit_pod(
            &headings(keep),
            &s,
            PodMethod::DipoleArray,
            None,
            &mut Silent,
        )
        .unwrap_err();
        assert!(
            e.is_bad_input() && e.to_string().contains("at least 4 directions"),
            "{keep:?}: {e}"
        );
    }
    assert!(
        fit_pod(
            &headings(&[0.0, 1.0, 2.0, 3.0]),
            &s,
            PodMethod::DipoleArray,
            None,
            &mut Silent
        )
        .is_ok()
    );
}
