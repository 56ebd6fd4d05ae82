//! The helicopter rotor model through the library: the study's figures,
//! a model fitted on one flight leaving under 10 % of the rotor
//! interference on an independent one (with and without a phase channel),
//! dropouts bridged and time gaps refined over.

use aeromag::prelude::*;
use aeromag::rotor::{PhaseChoice, RotorChoices, RotorOptions, RotorPreset, fit_rotor};
use aeromag::simulate::{ScenarioKind, simulate_flight};
use aeromag::studies::{RotorStudyRun, Study, StudyOutcome, StudySize};
use aeromag::{FlightTable, Note};

#[test]
fn the_rotor_study_meets_the_issue_figures() {
    let out = RotorStudyRun::default()
        .run(StudySize::Full, &mut Silent)
        .unwrap();
    let s = out.summary();
    eprintln!("{s:?}");
    assert!(
        s.residual_model_nt <= 0.10 * s.rotor_rms_nt,
        "model leaves {} of {}",
        s.residual_model_nt,
        s.rotor_rms_nt
    );
    assert!(
        s.residual_best_filter_nt >= 3.0 * s.residual_model_nt,
        "best filter {} vs model {}",
        s.residual_best_filter_nt,
        s.residual_model_nt
    );
    assert!(
        out.study
            .methods
            .iter()
            .any(|m| m.name.contains("synchronous averaging")),
        "the filter baselines"
    );
    // Issue 23 item 1: the thesis' simplified model beats filtering on a
    // rotor that satisfies its assumptions, not on the richer default rotor
    // (measured 4.3 % against 89.7 %, and 113 % against 56 %).
    assert!(
        s.simplified_fraction_ideal_rotor <= 0.10
            && s.simplified_fraction_ideal_rotor < 0.25 * s.best_filter_fraction_ideal_rotor,
        "{s:?}"
    );
    assert!(
        s.simplified_fraction_default_rotor > s.best_filter_fraction_default_rotor,
        "{s:?}"
    );
    // The tail rotor under the tail boom: unmodelled it is nearly all of
    // the residual (measured 98.9 %); fitted jointly 2.2 %.
    assert!(
        s.tail_residual_fraction <= 0.05
            && s.tail_unmodelled_residual_fraction >= 10.0 * s.tail_residual_fraction,
        "{s:?}"
    );
    let offset = out.tail.tail_offset_rad.unwrap().to_degrees();
    assert!(
        (offset - 37.0).abs() < 1.0,
        "tail rotor phase offset {offset}°"
    );
    assert!(out.tail_rms_nose_nt < 0.05 && out.tail_rms_tail_boom_nt > 5.0);
}

fn helicopter(seed: u64, config: Option<&str>) -> Flight {
    simulate_flight(ScenarioKind::Helicopter, config, Some(seed)).unwrap()
}

/// Standard deviation without 3 s (300 samples) at each end.
fn std_mid(x: &[f64]) -> f64 {
    let s = &x[300..x.len() - 300];
    let m = s.iter().sum::<f64>() / s.len() as f64;
    (s.iter().map(|v| (v - m).powi(2)).sum::<f64>() / s.len() as f64).sqrt()
}

/// Share of the true rotor interference RMS that `interf` leaves (scored
/// against `true_rotor`, which the model never reads).
fn residual_share(flight: &Flight, interf: &[f64]) -> f64 {
    let truth = flight.require("true_rotor").unwrap();
    let res: Vec<f64> = truth.iter().zip(interf).map(|(a, b)| a - b).collect();
    std_mid(&res) / std_mid(truth)
}

/// `f` with `edit` applied to its columns.
fn edited(f: &Flight, edit: impl Fn(&str, &mut Vec<f64>)) -> Flight {
    let mut t = FlightTable::new();
    for c in f.columns() {
        let mut v = c.values().unwrap().to_vec();
        edit(c.name(), &mut v);
        t.add_column(c.name(), v).unwrap();
    }
    Flight::from_table(t).unwrap()
}

fn has_note(notes: &[Note], text: &str) -> bool {
    notes.iter().any(|n| n.message.contains(text))
}

#[test]
fn a_fitted_model_leaves_under_10_percent_on_an_independent_flight() {
    let learn = helicopter(11, None);
    let other = helicopter(12, None);
    let opts = RotorOptions::preset(RotorPreset::AeromagSimHelicopter);
    let fit = fit_rotor(&learn, &opts, &mut Silent).unwrap();
    assert_eq!(fit.model.phase.column.as_deref(), Some("rotor_phase"));
    let share = residual_share(&other, &fit.model.interference(&other).unwrap());
    eprintln!(
        "with the phase channel: {:.2} % of the rotor RMS left on an independent flight",
        100.0 * share
    );
    assert!(share <= 0.10, "{share}");
    // A missing `mag` value: that row is not compensated, the others are.
    let holed = edited(&other, |n, v| {
        if n == "mag" {
            v[19_999] = f64::NAN;
        }
    });
    let out = fit.model.compensate(&holed).unwrap();
    assert!(out.interference_nt[19_999].is_nan() && out.interference_nt[0].is_finite());
    assert_eq!(out.flags()[19_999], 1.0);
    // A dropout in the learning flight is bridged: the whole record is
    // fitted as one and the result is the same.
    let n = learn.n_rows();
    let dropout = edited(&learn, |name, v| {
        if name == "mag" {
            v[n / 2] = f64::NAN;
        }
    });
    let fit_d = fit_rotor(&dropout, &opts, &mut Silent).unwrap();
    assert!(has_note(
        &fit_d.notes,
        "1 rows with a missing value in a dropout"
    ));
    assert_eq!(fit_d.model.rows, n);
    let share_d = residual_share(&other, &fit_d.model.interference(&other).unwrap());
    assert!((share_d - share).abs() < 0.002, "{share_d} vs {share}");
    // A time gap (2000 rows missing): the parameters are refined on both
    // stretches (9.5 % left; the longer stretch alone left 10.9 %).
    let keep: Vec<usize> = (0..n)
        .filter(|&i| !(n / 2..n / 2 + 2000).contains(&i))
        .collect();
    let mut t = FlightTable::new();
    for c in learn.columns() {
        let v = c.values().unwrap();
        t.add_column(c.name(), keep.iter().map(|&i| v[i]).collect())
            .unwrap();
    }
    let gapped = Flight::from_table(t).unwrap();
    let fit_g = fit_rotor(&gapped, &opts, &mut Silent).unwrap();
    assert!(
        has_note(&fit_g.notes, "refined on all 2 stretches"),
        "{:?}",
        fit_g.notes
    );
    assert_eq!(fit_g.model.rows, n - 2000);
    let share_g = residual_share(&other, &fit_g.model.interference(&other).unwrap());
    eprintln!("fitted on two stretches: {:.2} % left", 100.0 * share_g);
    assert!(share_g <= 0.10, "{share_g}");
    // A truth column is never read.
    let truth = RotorOptions {
        phase: PhaseChoice::Column("true_rotor_phase".into()),
        ..opts.clone()
    };
    assert!(
        fit_rotor(&learn, &truth, &mut Silent)
            .unwrap_err()
            .is_bad_input()
    );
    // 100 000 blades ran the fit out of memory; a coning of 1e300° was
    // fitted and reported. Both are bad input before any fitting.
    let mut many = opts.clone();
    many.geometry.blades = 100_000;
    let mut coned = opts.clone();
    coned.nominal_angles.coning_rad = 1e300;
    for (o, needle) in [(many, "blades"), (coned, "coning")] {
        let e = fit_rotor(&learn, &o, &mut Silent).unwrap_err();
        assert!(e.is_bad_input() && e.to_string().contains(needle), "{e}");
    }
}

#[test]
fn without_a_phase_channel_the_phase_is_estimated() {
    let cfg = "[rotor]\nphase_channel = false\n";
    let learn = helicopter(13, Some(cfg));
    let other = helicopter(14, Some(cfg));
    let opts = RotorOptions {
        rotor_hz_range: [4.5, 5.2],
        ..RotorOptions::preset(RotorPreset::AeromagSimHelicopter)
    };
    let fit = fit_rotor(&learn, &opts, &mut Silent).unwrap();
    assert!(fit.model.phase.column.is_none());
    let share = residual_share(&other, &fit.model.interference(&other).unwrap());
    eprintln!(
        "phase estimated from the data: {:.2} % of the rotor RMS left on an independent flight",
        100.0 * share
    );
    assert!(share <= 0.10, "{share}");
}

#[test]
fn a_rotor_band_without_this_rotor_is_refused_or_fails() {
    // The simulated rotor turns at 4.83 Hz, its four blades pass at 19.3 Hz.
    let learn = helicopter(13, Some("[rotor]\nphase_channel = false\n"));
    let band = |rotor_hz_range| RotorOptions {
        rotor_hz_range,
        ..RotorOptions::preset(RotorPreset::AeromagSimHelicopter)
    };
    // Below the rotor: the band's largest power was the flank of the
    // second harmonic (9.66 Hz) at its edge, tracked out of the band to a
    // 2.42 Hz "rotor" and written with exit 0.
    let e = fit_rotor(&learn, &band([2.5, 3.5]), &mut Silent).unwrap_err();
    let msg = e.to_string();
    assert!(
        e.is_bad_input() && msg.contains("--rotor-hz") && msg.contains("no blade-passing peak"),
        "{msg}"
    );
    // Above: the fifth harmonic (24.2 Hz) passes for four blades of a
    // 6.04 Hz rotor, written with exit 0: its cone is absurd.
    let e = fit_rotor(&learn, &band([5.0, 7.0]), &mut Silent).unwrap_err();
    let msg = e.to_string();
    assert!(!e.is_bad_input() && msg.contains("coning"), "{msg}");
    // Blades passing above Nyquist: the sampling is named.
    let e = fit_rotor(&learn, &band([4.0, 20.0]), &mut Silent).unwrap_err();
    let msg = e.to_string();
    assert!(e.is_bad_input() && msg.contains("Nyquist"), "{msg}");
    // A band around the rotor: fitted.
    let fit = fit_rotor(&learn, &band([4.8, 5.5]), &mut Silent).unwrap();
    assert!(
        (fit.model.rotor_hz - 4.83).abs() < 0.01,
        "{}",
        fit.model.rotor_hz
    );
}

#[test]
fn a_phase_channel_that_is_not_the_rotors_fails() {
    // A phase turning at a plausible 3.7 Hz that the rotor does not follow.
    let learn = edited(&helicopter(11, None), |n, v| {
        if n == "rotor_phase" {
            for (k, p) in v.iter_mut().enumerate() {
                *p = (k as f64 * 0.01 * 3.7 * 360.0).rem_euclid(360.0);
            }
        }
    });
    let opts = RotorOptions::preset(RotorPreset::AeromagSimHelicopter);
    let e = fit_rotor(&learn, &opts, &mut Silent).unwrap_err();
    let msg = e.to_string();
    // Its model's cone is absurd (−111°), so the coning check fails it
    // first; the share explained names the channel where the cone is not.
    assert!(
        !e.is_bad_input() && (msg.contains("coning") || msg.contains("--phase-column")),
        "{msg}"
    );
}

/// A sensor under the tail boom with the simulator's tail rotor.
const TAIL_BOOM: &str = "[tail_rotor]\n[scalar]\nposition_m = [-10.0, 0.0, 0.3]\n[fluxgate]\nposition_m = [-9.5, 0.0, 0.3]\n";

#[test]
fn a_tail_rotor_fitted_jointly_carries_over_to_an_independent_flight() {
    let learn = helicopter(11, Some(TAIL_BOOM));
    let other = helicopter(12, Some(TAIL_BOOM));
    let choices = |tail_rotor| RotorChoices {
        preset: Some(RotorPreset::AeromagSimHelicopter),
        sensor_m: Some([-10.0, 0.0, 0.3]),
        tail_rotor,
        ..RotorChoices::default()
    };
    let main_only = RotorOptions::from_choices(&choices(false)).unwrap();
    let with_tail = RotorOptions::from_choices(&choices(true)).unwrap();
    assert_eq!(
        with_tail.tail.as_ref().unwrap().geometry.sensor_m,
        [-10.0, 0.0, 0.3]
    );
    let fit0 = fit_rotor(&learn, &main_only, &mut Silent).unwrap();
    let fit1 = fit_rotor(&learn, &with_tail, &mut Silent).unwrap();
    // The main rotor alone explains a few per cent of what this sensor
    // sees: said, naming the tail rotor's option.
    let explains = |n: &Note| n.message.contains("explains") && n.message.contains("--tail-rotor");
    assert!(fit0.notes.iter().any(explains), "{:?}", fit0.notes);
    assert!(!fit1.notes.iter().any(explains), "{:?}", fit1.notes);
    let tail = fit1.model.tail.as_ref().unwrap();
    assert!((tail.offset_rad.to_degrees() - 37.0).abs() < 1.0);
    let s0 = residual_share(&other, &fit0.model.interference(&other).unwrap());
    let s1 = residual_share(&other, &fit1.model.interference(&other).unwrap());
    eprintln!(
        "tail-boom sensor, independent flight: main rotor only {:.2} %, main and tail {:.2} %",
        100.0 * s0,
        100.0 * s1
    );
    assert!(s1 <= 0.05 && s0 >= 10.0 * s1, "{s0} {s1}");
    // The model file round-trips with its tail rotor.
    let text = serde_json::to_string(&fit1.model).unwrap();
    assert_eq!(
        aeromag::rotor::RotorModelFile::from_json(&text, "m.json").unwrap(),
        fit1.model
    );
    // No phase channel: the tail rotor cannot be geared; bad input.
    let estimated = RotorOptions::from_choices(&RotorChoices {
        estimate_phase: true,
        ..choices(true)
    })
    .unwrap();
    let e = fit_rotor(&learn, &estimated, &mut Silent).unwrap_err();
    assert!(
        e.is_bad_input() && e.to_string().contains("phase channel"),
        "{e}"
    );
    // Tail values without the tail rotor, or an incomplete tail geometry
    // without a preset: bad input.
    assert!(
        RotorOptions::from_choices(&RotorChoices {
            gear_ratio: Some(4.0),
            ..choices(false)
        })
        .unwrap_err()
        .is_bad_input()
    );
    assert!(
        RotorOptions::from_choices(&RotorChoices {
            hub_m: Some([0.0, 0.0, -2.6]),
            sensor_m: Some([5.0, 0.0, 0.6]),
            blade_span_m: Some([0.8, 7.5]),
            blades: Some(4),
            tail_rotor: true,
            gear_ratio: Some(4.0),
            ..RotorChoices::default()
        })
        .unwrap_err()
        .is_bad_input()
    );
}

/// A tail rotor asked for where the sensor does not see it (the nose boom,
/// 17.7 m from its hub; the simulated helicopter has one, whose part there
/// is below 0.05 nT): its parameters were fitted to the main rotor's
/// misfit and its slow part applied, leaving a mean error of −8.1 nT and a
/// std of 11.8 nT in the compensated reading (exit 0). Now it is left out,
/// with a warning, and the model is the main rotor's alone.
#[test]
fn a_tail_rotor_the_sensor_does_not_see_is_left_out() {
    let cfg = Some("[tail_rotor]\n");
    let learn = helicopter(15, cfg);
    let other = helicopter(16, cfg);
    let choices = |tail_rotor| RotorChoices {
        preset: Some(RotorPreset::AeromagSimHelicopter),
        tail_rotor,
        ..RotorChoices::default()
    };
    let main_only = RotorOptions::from_choices(&choices(false)).unwrap();
    let with_tail = RotorOptions::from_choices(&choices(true)).unwrap();
    let fit0 = fit_rotor(&learn, &main_only, &mut Silent).unwrap();
    let fit1 = fit_rotor(&learn, &with_tail, &mut Silent).unwrap();
    assert!(
        has_note(
            &fit1.notes,
            "the tail rotor is left out of the model: the sensor does not see it"
        ),
        "{:?}",
        fit1.notes
    );
    assert!(fit1.model.tail.is_none());
    let interf = fit1.model.interference(&other).unwrap();
    assert_eq!(interf, fit0.model.interference(&other).unwrap());
    let truth = other.require("true_rotor").unwrap();
    let err: Vec<f64> = interf.iter().zip(truth).map(|(a, b)| a - b).collect();
    let mid = &err[300..err.len() - 300];
    let mean = mid.iter().sum::<f64>() / mid.len() as f64;
    eprintln!(
        "nose boom, tail rotor asked for: error mean {mean:.3} nT, std {:.3} nT",
        std_mid(&err)
    );
    assert!(
        mean.abs() < 0.5 && std_mid(&err) < 0.3,
        "{mean} {}",
        std_mid(&err)
    );
}

/// Hostile flights found by fuzzing `rotor fit/apply` (exit 0 with wrong
/// results before): a phase channel in radians was applied (interference
/// of ±10⁴ nT), steps alternating 0.0105/0.0095 s were taken as 95.2 Hz,
/// a constant reading was fitted to a mean coning of −333 828°, and one
/// missing `mag` cell every 5 s left the whole flight uncompensated.
#[test]
fn hostile_flights_are_refused_or_fail_instead_of_being_applied() {
    let learn = helicopter(11, None);
    let other = helicopter(12, None);
    let opts = RotorOptions::preset(RotorPreset::AeromagSimHelicopter);
    let fit = fit_rotor(&learn, &opts, &mut Silent).unwrap();
    // The phase channel in radians: refused by apply as by fit.
    let radians = edited(&other, |n, v| {
        if n == "rotor_phase" {
            v.iter_mut().for_each(|p| *p = p.to_radians());
        }
    });
    let e = fit.model.compensate(&radians).unwrap_err();
    let msg = e.to_string();
    assert!(
        e.is_bad_input() && msg.contains("`rotor_phase` (deg) turns at"),
        "{msg}"
    );
    assert!(!msg.contains("0000000"), "{msg}");
    // A model whose interference is beyond any field on this flight: bad
    // input naming the row, with the rotor model's likely causes (it named
    // the Tolles-Lawson model's `bt_scale`).
    let mut wild = fit.model.clone();
    wild.model.params[0] *= 1e9;
    let e = wild.compensate(&other).unwrap_err();
    let msg = e.to_string();
    assert!(
        e.is_bad_input()
            && msg.contains("beyond any magnetic field")
            && msg.contains("another helicopter's model")
            && !msg.contains("bt_scale"),
        "{msg}"
    );
    // Steps alternating ±5 %: refused, naming the row.
    let uneven = edited(&other, |n, v| {
        if n == "time" {
            for (k, t) in v.iter_mut().enumerate() {
                *t += if k % 2 == 1 { 0.0005 } else { 0.0 };
            }
        }
    });
    for e in [
        fit.model.compensate(&uneven).unwrap_err(),
        fit_rotor(&uneven, &opts, &mut Silent).unwrap_err(),
    ] {
        let msg = e.to_string();
        assert!(
            e.is_bad_input() && msg.contains("column 'time'") && msg.contains("uniform sampling"),
            "{msg}"
        );
    }
    // A time in milliseconds (0.1 Hz) named the library's `cutoff_hz`; a
    // row of zeros on the three flux axes named neither file nor row.
    let ms = edited(&other, |n, v| {
        if n == "time" {
            v.iter_mut().for_each(|t| *t *= 1e3);
        }
    });
    let zero = edited(&other, |n, v| {
        if n.starts_with("flux_") {
            v[777] = 0.0;
        }
    });
    // An infinite phase was bridged as a missing one.
    let infinite = edited(&other, |n, v| {
        if n == "rotor_phase" {
            v[4321] = f64::INFINITY;
        }
    });
    for (flight, needle) in [
        (&ms, "sample rate 0.1000 Hz"),
        (&zero, "data row 778"),
        (&infinite, "data row 4322, column 'rotor_phase'"),
    ] {
        for e in [
            fit.model.compensate(flight).unwrap_err(),
            fit_rotor(flight, &opts, &mut Silent).unwrap_err(),
        ] {
            assert!(e.is_bad_input() && e.to_string().contains(needle), "{e}");
        }
    }
    // A constant reading determines nothing: a failed fit (exit 1).
    let constant = edited(&learn, |n, v| {
        if n == "mag" {
            v.fill(50_000.0);
        }
    });
    let e = fit_rotor(&constant, &opts, &mut Silent).unwrap_err();
    assert!(
        !e.is_bad_input() && e.to_string().contains("mean coning"),
        "{e}"
    );
    // One missing `mag` cell every 5 s: bridged, every other row compensated.
    let holed = edited(&other, |n, v| {
        if n == "mag" {
            for k in (250..v.len()).step_by(500) {
                v[k] = f64::NAN;
            }
        }
    });
    let out = fit.model.compensate(&holed).unwrap();
    let clean = fit.model.compensate(&other).unwrap();
    let holes = (250..holed.n_rows()).step_by(500).count();
    let flagged = out.flags().iter().filter(|&&f| f != 0.0).count();
    assert_eq!(flagged, holes);
    assert!(out.interference_nt[250].is_nan() && out.interference_nt[251].is_finite());
    // One sample of 0 nT (a logger's dummy): the fit's residual was 362 nT
    // instead of 0.07, and a good model's interference wrong by up to 230
    // nT over 5 s. Such a value is no reading and is refused on reading
    // (`MIN_READING_NT`); a spike that is still a reading (20 000 nT among
    // 53 000) is bridged (a warning) and left in the output.
    let mut t = FlightTable::new();
    for c in other.columns() {
        let mut v = c.values().unwrap().to_vec();
        if c.name() == "mag" {
            v[5000] = 0.0;
        }
        t.add_column(c.name(), v).unwrap();
    }
    let e = Flight::from_table(t).unwrap_err();
    assert!(
        e.is_bad_input() && e.to_string().contains("0 nT at data row 5001"),
        "{e}"
    );
    let spiked = |f: &Flight| {
        edited(f, |n, v| {
            if n == "mag" {
                v[5000] = 20_000.0;
            }
        })
    };
    let (learn_spiked, other_spiked) = (spiked(&learn), spiked(&other));
    let out = fit.model.compensate(&other_spiked).unwrap();
    assert!(
        out.notes
            .iter()
            .any(|n| n.message.contains("1 sample of mag stands out"))
    );
    let worst = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0f64, f64::max)
    };
    assert!(
        worst(&out.interference_nt, &clean.interference_nt) < 0.5,
        "{}",
        worst(&out.interference_nt, &clean.interference_nt)
    );
    let refit = fit_rotor(&learn_spiked, &opts, &mut Silent).unwrap();
    assert!(has_note(&refit.notes, "1 sample of mag stands out"));
    let again = refit.model.interference(&other).unwrap();
    assert!(
        worst(&again, &clean.interference_nt) < 0.5,
        "{}",
        worst(&again, &clean.interference_nt)
    );
    // One corrupted phase cell (1e300) turned the fitted rotor to 3.62 Hz
    // instead of 4.83: bridged as a glitch of the phase's line.
    let glitched = |f: &Flight| {
        edited(f, |n, v| {
            if n == "rotor_phase" {
                v[5000] = 1e300;
            }
        })
    };
    let out = fit.model.compensate(&glitched(&other)).unwrap();
    assert!(
        out.notes
            .iter()
            .any(|n| n.message.contains("1 sample of the rotor phase jumps"))
    );
    assert!(worst(&out.interference_nt, &clean.interference_nt) < 0.5);
    let refit = fit_rotor(&glitched(&learn), &opts, &mut Silent).unwrap();
    assert!((refit.model.rotor_hz - fit.model.rotor_hz).abs() < 1e-3);
    let again = refit.model.interference(&other).unwrap();
    assert!(
        worst(&again, &clean.interference_nt) < 0.5,
        "{}",
        worst(&again, &clean.interference_nt)
    );
}

/// Found by fuzzing the rotor model: a block of the phase channel offset by
/// +90° on 100 rows (a step away and a step back) had only its two steps
/// taken as glitches, and the fit on it kept the block: its mean coning
/// 0.3° instead of 3.9°. The block is now left out of the fit (and of an
/// application), named in the warning, and the model leaves on an
/// independent flight what the clean fit leaves.
#[test]
fn a_block_of_the_phase_stepped_away_and_back_is_left_out() {
    let learn = helicopter(11, None);
    let other = helicopter(12, None);
    let opts = RotorOptions::preset(RotorPreset::AeromagSimHelicopter);
    let clean = fit_rotor(&learn, &opts, &mut Silent).unwrap();
    let share = residual_share(&other, &clean.model.interference(&other).unwrap());
    let blocked = |f: &Flight| {
        edited(f, |n, v| {
            if n == "rotor_phase" {
                v[5000..5100]
                    .iter_mut()
                    .for_each(|p| *p = (*p + 90.0) % 360.0);
            }
        })
    };
    let fit = fit_rotor(&blocked(&learn), &opts, &mut Silent).unwrap();
    assert!(
        has_note(&fit.notes, "102 samples of the rotor phase jump")
            && has_note(
                &fit.notes,
                "blocks stepped away and back; the first at data row 5000"
            )
            && has_note(&fit.notes, "left out otherwise"),
        "{:?}",
        fit.notes
    );
    let share_b = residual_share(&other, &fit.model.interference(&other).unwrap());
    assert!(
        share_b < share + 0.005,
        "{share_b} with the block against {share} without"
    );
    let coning = |m: &aeromag::rotor::RotorModelFile| m.coning_mean_deg;
    assert!(
        (coning(&fit.model) - coning(&clean.model)).abs() < 1.0,
        "{} against {}",
        coning(&fit.model),
        coning(&clean.model)
    );
    // Applied, the block's rows are left uncompensated, the others are.
    let out = clean.model.compensate(&blocked(&other)).unwrap();
    assert!(out.interference_nt[5050].is_nan() && out.interference_nt[4000].is_finite());
}
