//! EM positioning through the library (issue 6): the study's figures over
//! a 5-hour flight, and the file chain simulate → detect → calibrate →
//! locate scored against the truth (the steps never read it).

use aeromag::Silent;
use aeromag::em::files::{load_table, read_system};
use aeromag::em::{
    DetectOptions, HalfSpace, calibrate, command_default, detect, known_points, locate,
    simulate_to_dir,
};
use aeromag::studies::{EmStudy, Study, StudyOutcome, StudySize};

#[test]
fn the_study_meets_the_issue_figures() {
    let out = EmStudy::default()
        .run(StudySize::Full, &mut Silent)
        .unwrap();
    let s = out.summary();
    eprintln!("{s:?}");
    assert!(s.range_err_rel <= 1e-3, "range error {}", s.range_err_rel);
    assert!(s.angle_err_deg <= 0.1 && s.attitude_err_deg <= 0.1, "{s:?}");
    assert!(
        s.polarization_ratio_before >= 100.0 * s.polarization_ratio_after,
        "{s:?}"
    );
    assert!(
        s.ratio_without_pilot > 10.0 * s.polarization_ratio_after,
        "{s:?}"
    );
    let sec = out.section().unwrap();
    assert!(sec.blocks.len() >= 5, "{}", sec.blocks.len());
}

#[test]
fn the_file_chain_locates_the_bird_within_the_issue_figures() {
    let d = tempfile::tempdir().unwrap();
    let files = simulate_to_dir(&command_default(), 8, d.path()).unwrap();
    let det = detect(&files.raw, &DetectOptions::default(), &mut Silent).unwrap();
    assert_eq!(det.epochs.len(), files.epochs);
    assert!(det.notes.is_empty(), "{:?}", det.notes);
    let known = known_points(&load_table(&files.known).unwrap(), &det.epochs).unwrap();
    let system = read_system(&files.system).unwrap();
    let half = HalfSpace::default();
    let cal = calibrate(&det.epochs, &known, &system, &half).unwrap();
    assert!(cal.polarization_ratio_before >= 100.0 * cal.polarization_ratio_after);
    let poses = locate(&det.epochs, &cal.file, &half, &mut Silent).unwrap();
    assert_eq!(poses.failed(), 0);
    assert!(poses.notes.is_empty(), "{:?}", poses.notes);
    assert_eq!(cal.file.half_space, Some([-1.0, 0.0, 1.0]));
    // Score against the truth file, on the epochs the calibration was not given.
    let truth = load_table(&files.truth).unwrap();
    let c = |n: &str| truth.require(n).unwrap();
    let (t, range, x, y, z) = (
        c("time_s"),
        c("true_range_m"),
        c("true_x_m"),
        c("true_y_m"),
        c("true_z_m"),
    );
    let known_times: Vec<f64> = known
        .positions
        .iter()
        .map(|(k, _)| det.epochs[*k].time_s)
        .collect();
    let (mut err_range, mut err_dir) = (Vec::new(), Vec::new());
    for (k, p) in poses.poses.iter().enumerate() {
        assert!((p.time_s - t[k]).abs() < 1e-9);
        if known_times.iter().any(|kt| (kt - p.time_s).abs() < 1e-9) {
            continue;
        }
        let l = p.located.unwrap();
        err_range.push((l.range_m - range[k]) / range[k]);
        let rt = nalgebra::Vector3::new(x[k], y[k], z[k]).normalize();
        let re = nalgebra::Vector3::from(l.position_m).normalize();
        err_dir.push(rt.dot(&re).clamp(-1.0, 1.0).acos().to_degrees());
    }
    let rms = |v: &[f64]| (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt();
    let (r, a) = (rms(&err_range), rms(&err_dir));
    eprintln!(
        "{} scored epochs: range {r:.3e} (rel), direction {a:.4}°",
        err_range.len()
    );
    assert_eq!(err_range.len(), files.epochs - 8);
    assert!(r <= 1e-3 && a <= 0.1, "range {r}, direction {a}°");
    // The opposite prior mirrors every position, and calibrating with it
    // is refused: the known positions lie on the other side.
    let opposite: HalfSpace = "1,0,-1".parse().unwrap();
    let e = calibrate(&det.epochs, &known, &system, &opposite).unwrap_err();
    assert!(e.is_bad_input(), "{e}");
    assert!(
        e.to_string()
            .contains("half-space opposite to --half-space=1,0,-1")
            && e.to_string().contains("mean direction is -0.8"),
        "{e}"
    );
    let flipped = locate(
        &det.epochs,
        &cal.file,
        &"1,0,-1".parse().unwrap(),
        &mut Silent,
    )
    .unwrap();
    // … and is warned of: the calibration was fitted with the other.
    assert!(
        flipped
            .notes
            .iter()
            .any(|n| n.to_string().contains("fitted with --half-space=-1,0,1")),
        "{:?}",
        flipped.notes
    );
    for (a, b) in poses.poses.iter().zip(&flipped.poses) {
        let (a, b) = (a.located.unwrap(), b.located.unwrap());
        for k in 0..3 {
            assert!((a.position_m[k] + b.position_m[k]).abs() < 1e-9 * a.range_m);
        }
    }
}

/// A record whose samples start at a multiple of 4 bytes is read in place
/// from a memory map, any other through the streaming reader: the same
/// epochs, and the same error naming frame, channel and byte offset for a
/// bad sample, whatever the header's length.
#[test]
fn records_are_detected_alike_in_place_and_streamed() {
    let d = tempfile::tempdir().unwrap();
    let files = simulate_to_dir(&command_default(), 8, d.path()).unwrap();
    let bytes = std::fs::read(&files.raw).unwrap();
    let len = u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize;
    assert_eq!((12 + len) % 4, 0, "the writer aligns the samples");
    let mut seen: Option<String> = None;
    for pad in 0..4 {
        // The same record with `pad` more spaces after the JSON header.
        let mut b = bytes[..8].to_vec();
        b.extend(((len + pad) as u32).to_le_bytes());
        b.extend(&bytes[12..12 + len]);
        b.extend(std::iter::repeat_n(b' ', pad));
        let body = b.len();
        b.extend(&bytes[12 + len..]);
        let p = d.path().join(format!("pad{pad}.raw"));
        std::fs::write(&p, &b).unwrap();
        let det = detect(&p, &DetectOptions::default(), &mut Silent).unwrap();
        let text = format!("{:?}", det.epochs);
        match &seen {
            None => seen = Some(text),
            Some(first) => assert!(*first == text, "pad {pad}: other epochs"),
        }
        let k = body + 4 * (3 * 500 + 2);
        b[k..k + 4].copy_from_slice(&f32::NAN.to_le_bytes());
        std::fs::write(&p, &b).unwrap();
        let e = detect(&p, &DetectOptions::default(), &mut Silent).unwrap_err();
        assert!(e.is_bad_input(), "{e}");
        let msg = e.to_string();
        assert!(
            msg.contains(&format!("frame 500 channel 2 (byte offset {k}) is NaN")),
            "pad {pad}: {msg}"
        );
    }
}
