//! End-to-end calibration on synthetic detected vectors with the
//! distortions of seed `001_…` eqs. 3 and 5 (complex receiver coupling,
//! complex transmitter mixing, detection phases, receiver misalignment).

use super::*;
use crate::positioning::closed_form::tests::{moments, random_pose};
use crate::positioning::{angle_between, field_matrix, rotation_angle_between};
use nalgebra::{Rotation3, Vector3};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

struct Distortion {
    phase: [f64; 3],
    im_chi: [Matrix3<f64>; 3],
    im_k: Matrix3<f64>,
    s: Matrix3<f64>,
    misalign: Matrix3<f64>,
    noise: f64,
}

fn distortion(rng: &mut ChaCha8Rng, noise: f64) -> Distortion {
    let mut m = || Matrix3::from_fn(|_, _| rng.random_range(-0.04..0.04));
    // χ has a unit diagonal (eq. 3): imaginary coupling off the diagonal only.
    let mut off = || {
        let mut a = m();
        a.fill_diagonal(0.0);
        a
    };
    let im_chi = [off(), off(), off()];
    let im_k = m();
    let s0 = m();
    let s = (s0 + s0.transpose()) * 0.5;
    let misalign = Rotation3::from_scaled_axis(Vector3::new(0.012, -0.008, 0.015)).into_inner();
    Distortion {
        phase: [0.4, -0.7, 1.1],
        im_chi,
        im_k,
        s,
        misalign,
        noise,
    }
}

fn measure(d: &Distortion, pose: &Pose, rng: &mut ChaCha8Rng) -> [[Complex64; 3]; 3] {
    let normal = Normal::new(0.0, 1.0).unwrap();
    let m = (Matrix3::identity() + d.s) * moments();
    let h = d.misalign * field_matrix(&pose.position_m, &pose.rotation, &m);
    let sigma = d.noise * h.norm() / 3.0;
    let mut out = [[Complex64::new(0.0, 0.0); 3]; 3];
    for (i, row) in out.iter_mut().enumerate() {
        let mut im_part = Vector3::zeros();
        for j in 0..3 {
            im_part += h.column(j) * d.im_k[(i, j)];
        }
        let re_v: Vector3<f64> = h.column(i).into_owned();
        // (I + i Imχ_i)(re + i im)
        let a = re_v - d.im_chi[i] * im_part;
        let b = im_part + d.im_chi[i] * re_v;
        let rot = Complex64::from_polar(1.0, d.phase[i]);
        for (c, v) in row.iter_mut().enumerate() {
            let noise = Complex64::new(sigma * normal.sample(rng), sigma * normal.sample(rng));
            *v = Complex64::new(a[c], b[c]) * rot + noise;
        }
    }
    out
}

fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

#[test]
fn three_stages_reach_the_spec_figures() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let d = distortion(&mut rng, 1e-4);
    let m = moments();
    // Stage 1 from 400 epochs, no external information.
    let poses: Vec<Pose> = (0..400).map(|_| random_pose(&mut rng)).collect();
    let epochs: Vec<_> = poses.iter().map(|p| measure(&d, p, &mut rng)).collect();
    let pol = PolarisationCalibration::fit(&epochs).unwrap();
    let before: Vec<f64> = epochs
        .iter()
        .flat_map(|e| uncalibrated(e, &pol.phase_rad).1)
        .collect();
    let after: Vec<f64> = epochs.iter().flat_map(|e| pol.apply(e).1).collect();
    let (rb, ra) = (rms(&before), rms(&after));
    eprintln!(
        "polarisation ratio RMS before {rb:.3e} after {ra:.3e} ({:.0}×)",
        rb / ra
    );
    assert!(rb / ra >= 100.0, "reduction {}", rb / ra);

    // Stage 2 from 60 points with known position (attitude unknown).
    let fields: Vec<Matrix3<f64>> = epochs[..60].iter().map(|e| pol.apply(e).0).collect();
    let positions: Vec<Vector3<f64>> = poses[..60].iter().map(|p| p.position_m).collect();
    let s = fit_transmitter_geometry(&fields, &positions, &m).unwrap();
    eprintln!(
        "stage 2: |S_fit − S_true| = {:.2e} (|S_true| = {:.2e})",
        (s - d.s).norm(),
        d.s.norm()
    );
    assert!((s - d.s).norm() < 0.05 * d.s.norm());

    // Stage 3 from one point of known attitude.
    let mut cal = Calibration {
        polarisation: pol,
        transmitter_s: s,
        attitude_q: Matrix3::identity(),
    };
    let mut hemi = Hemisphere::new(Vector3::new(-1.0, 0.0, 1.0));
    let known = cal.locate(&epochs[0], &m, &mut hemi).unwrap();
    cal.attitude_q = fit_attitude_correction(&[poses[0].rotation], &[known.pose.rotation]).unwrap();

    // Saved and read back, then applied to fresh epochs.
    let cal = Calibration::from_json(&cal.to_json().unwrap()).unwrap();
    let uncal = Calibration {
        polarisation: PolarisationCalibration {
            phase_rad: pol.phase_rad,
            ..Default::default()
        },
        ..Default::default()
    };
    let mut errs = [Vec::new(), Vec::new(), Vec::new()];
    let mut errs_uncal = [Vec::new(), Vec::new(), Vec::new()];
    for _ in 0..300 {
        let truth = random_pose(&mut rng);
        let e = measure(&d, &truth, &mut rng);
        for (c, out) in [(&cal, &mut errs), (&uncal, &mut errs_uncal)] {
            let mut hemi = Hemisphere::new(Vector3::new(-1.0, 0.0, 1.0));
            let l = c.locate(&e, &m, &mut hemi).unwrap();
            out[0].push((l.pose.range_m() - truth.range_m()) / truth.range_m());
            out[1].push(angle_between(&l.pose.position_m, &truth.position_m).to_degrees());
            out[2].push(rotation_angle_between(&l.pose.rotation, &truth.rotation).to_degrees());
        }
    }
    let r = errs.map(|v| rms(&v));
    let ru = errs_uncal.map(|v| rms(&v));
    eprintln!(
        "calibrated RMS: range {:.3e} (rel), direction {:.4}°, attitude {:.4}°",
        r[0], r[1], r[2]
    );
    eprintln!(
        "uncalibrated RMS: range {:.3e} (rel), direction {:.4}°, attitude {:.4}°",
        ru[0], ru[1], ru[2]
    );
    assert!(r[0] <= 1e-3 && r[1] <= 0.1 && r[2] <= 0.1, "{r:?}");
    for k in 0..3 {
        assert!(
            ru[k] > 5.0 * r[k],
            "component {k}: calibration gains little {ru:?} vs {r:?}"
        );
    }
}

#[test]
fn bad_inputs_error() {
    let few = vec![[[Complex64::new(1.0, 0.0); 3]; 3]; 3];
    assert!(PolarisationCalibration::fit(&few).is_err());
    assert!(fit_transmitter_geometry(&[Matrix3::identity()], &[], &moments()).is_err());
    assert!(fit_attitude_correction(&[], &[]).is_err());
    assert!(Calibration::from_json("{").is_err());
}

/// `|S|` of 1.14 to 2.8e10 and rotations `Q` of 113.8° to 175° (wrong
/// units, swapped channels, negated moments) were accepted as "small"
/// corrections; the simulated scenario's are below 0.061 and 0.051°.
#[test]
fn corrections_beyond_the_plausible_bounds_are_described() {
    assert_eq!(Calibration::default().implausible(), None);
    let small = Calibration {
        transmitter_s: Matrix3::from_diagonal_element(0.06),
        attitude_q: nalgebra::Rotation3::from_euler_angles(0.0, 0.0, 0.05f64.to_radians())
            .into_inner(),
        ..Calibration::default()
    };
    assert_eq!(small.implausible(), None);
    let km = Calibration {
        transmitter_s: Matrix3::from_diagonal_element(-0.99),
        ..Calibration::default()
    };
    let e = km.implausible().unwrap();
    assert!(
        e.contains("|S| = 1.7147") && e.contains("by about 0.0100"),
        "{e}"
    );
    assert!(e.contains("metres") && !e.contains("attitude"), "{e}");
    let turned = Calibration {
        attitude_q: nalgebra::Rotation3::from_euler_angles(0.0, 0.0, 113.8f64.to_radians())
            .into_inner(),
        ..Calibration::default()
    };
    let e = turned.implausible().unwrap();
    assert!(
        e.contains("113.8°") && e.contains("swapped") && !e.contains("|S|"),
        "{e}"
    );
    let rad = Calibration {
        attitude_q: nalgebra::Rotation3::from_euler_angles(0.0, 0.0, 10.7f64.to_radians())
            .into_inner(),
        ..Calibration::default()
    };
    assert!(rad.implausible().unwrap().contains("radians"));
}
