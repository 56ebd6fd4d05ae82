//! End-to-end tests of the `em` scenario through detection, pilot
//! correction and positioning.

use super::*;
use crate::detection::{FieldEpoch, major_axis};
use crate::positioning::{
    Hemisphere, PolishOptions, angle_between, closed_form, polish, rotation_angle_between,
};
use crate::study::{FlightStudyConfig, epochs_at, rms, run_flight_study, simulate_and_detect};
use aeromag_core::field::dipole::dipole_matrix;
use nalgebra::{Matrix3, Vector3};

fn run(config: EmSimConfig, use_pilot: bool) -> (EmScenario, Vec<FieldEpoch>) {
    simulate_and_detect(config, use_pilot).unwrap()
}

/// Relative error of the detected complex field against the truth `R Ω M'`.
fn field_error(sc: &EmScenario, e: &FieldEpoch) -> f64 {
    let p = sc.pose_at(e.time_s);
    let rom = (p.rotation * dipole_matrix(&p.position_m))
        .map(|v| crate::detection::Complex64::new(v, 0.0))
        * sc.effective_moments();
    let mut num = 0.0;
    let mut den = 0.0;
    for i in 0..3 {
        for c in 0..3 {
            num += (e.h[i][c] - rom[(c, i)]).norm_sqr();
            den += rom[(c, i)].norm_sqr();
        }
    }
    (num / den).sqrt()
}

#[test]
fn raw_format_round_trip_and_determinism() {
    let cfg = EmSimConfig {
        duration_s: 0.2,
        ..EmSimConfig::default()
    };
    let sc = EmScenario::new(cfg).unwrap();
    let a = synthesize(&sc).unwrap();
    let b = synthesize(&sc).unwrap();
    assert_eq!(
        a.samples, b.samples,
        "seeded synthesis must be bit-identical"
    );
    let mut bytes = Vec::new();
    write_raw(&mut bytes, &a.header, &a.samples).unwrap();
    // The JSON header, padded with at most 3 spaces so that the samples
    // start at a multiple of 4 bytes.
    let json = serde_json::to_vec(&a.header).unwrap().len();
    let body = (12 + json).next_multiple_of(4);
    assert_eq!(bytes.len(), body + a.samples.len() * 4);
    assert_eq!(
        u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize,
        body - 12
    );
    assert!(bytes[12 + json..body].iter().all(|&b| b == b' '));
    let (h, s) = read_raw(&bytes).unwrap();
    // serde_json's default float parsing may differ in the last ulp of the
    // drawn matrices; the short-decimal constants are exact.
    assert_eq!(
        (h.frames, h.channels, h.start_index),
        (a.header.frames, 3, 0)
    );
    assert_eq!(h.system.frequencies_hz, sc.config.frequencies_hz);
    assert_eq!(h.system.moments_am2, sc.config.moments_am2);
    for i in 0..3 {
        assert!((h.system.chi[i] - sc.chi[i]).norm() < 1e-15);
    }
    assert_eq!(s, a.samples);
    assert!(read_raw(&bytes[..bytes.len() - 1]).is_err());
    assert!(read_raw(b"NOTRAW00\0\0\0\0").is_err());
    let mut trailing = bytes.clone();
    trailing.push(0);
    assert!(
        read_raw(&trailing)
            .unwrap_err()
            .to_string()
            .contains("trailing")
    );
    let hl = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize;
    let mut header = a.header.clone();
    header.layout = "f64be".into();
    let mut other = Vec::new();
    write_raw(&mut other, &header, &a.samples).unwrap();
    assert!(read_raw(&other).unwrap_err().to_string().contains("layout"));
    let mut short = bytes[..12 + hl].to_vec();
    short[8..12].copy_from_slice(&(hl as u32 + 10).to_le_bytes());
    assert!(
        read_raw(&short)
            .unwrap_err()
            .to_string()
            .contains("truncated header")
    );
    assert!(write_raw(Vec::new(), &a.header, &a.samples[1..]).is_err());
    assert!(
        EmScenario::new(EmSimConfig {
            frequencies_hz: [1025.0, 2075.0, 60_000.0],
            ..EmSimConfig::default()
        })
        .is_err()
    );
}

#[test]
fn pilot_correction_removes_the_gain_drift() {
    // 1.25 h into the flight the gains have drifted by several per cent.
    let noisy = EmSimConfig {
        start_time_s: 4500.0,
        ..EmSimConfig::default()
    };
    // Noise-free and static bird: isolates the pilot correction itself.
    let quiet = EmSimConfig {
        coil_noise_v: 0.0,
        power_line_v: 0.0,
        sferic_rate_hz: 0.0,
        swing_amplitude_m: 0.0,
        attitude_amplitude_deg: 0.0,
        rotation_rate_deg_s: 0.0,
        range_period_s: 1e12,
        ..noisy.clone()
    };
    let max_err = |cfg: &EmSimConfig, pilot: bool| {
        let (sc, ep) = run(cfg.clone(), pilot);
        assert_eq!(ep.len(), 16);
        ep.iter().map(|e| field_error(&sc, e)).fold(0.0, f64::max)
    };
    let (quiet_w, quiet_o) = (max_err(&quiet, true), max_err(&quiet, false));
    let (noisy_w, noisy_o) = (max_err(&noisy, true), max_err(&noisy, false));
    eprintln!("max field error, noise-free: with pilot {quiet_w:.2e}, without {quiet_o:.2e}");
    eprintln!("max field error, with noise: with pilot {noisy_w:.2e}, without {noisy_o:.2e}");
    // What remains is f32 ADC rounding: the pilot removes the drift entirely.
    assert!(quiet_w < 2e-6, "{quiet_w}");
    assert!(quiet_o > 1e-2, "{quiet_o}");
    // A moving bird with coil noise, 400 Hz and sferics: the error stays at
    // the level of the noise and of the motion within a 0.16 s block.
    assert!(noisy_w < 1e-3, "{noisy_w}");
}

#[test]
fn end_to_end_positioning_without_transmitter_distortion() {
    let cfg = EmSimConfig {
        transmitter_distortion: 0.0,
        start_time_s: 200.0,
        ..EmSimConfig::default()
    };
    let (sc, ep) = run(cfg, true);
    let m = sc.config.moments_am2;
    let mut worst = [0.0f64; 4];
    let mut hemi = Hemisphere::new(Vector3::new(-1.0, 0.0, 1.0));
    for e in &ep {
        let mut h = Matrix3::zeros();
        let mut ratio = 0.0f64;
        for i in 0..3 {
            let el = major_axis(&e.h[i]);
            h.set_column(i, &el.major);
            ratio = ratio.max(el.ratio);
        }
        let cf = closed_form(&h, &m, &mut hemi).unwrap();
        let p = polish(&h, &m, &cf.pose, &PolishOptions::default())
            .unwrap()
            .pose;
        let t = sc.pose_at(e.time_s);
        worst[0] = worst[0].max(((p.range_m() - t.range_m()) / t.range_m()).abs());
        worst[1] = worst[1].max(angle_between(&p.position_m, &t.position_m).to_degrees());
        worst[2] = worst[2].max(rotation_angle_between(&p.rotation, &t.rotation).to_degrees());
        worst[3] = worst[3].max(ratio);
    }
    eprintln!(
        "worst over {} epochs: range {:.2e} (rel), direction {:.4}°, attitude {:.4}°, polarisation ratio {:.2e}",
        ep.len(),
        worst[0],
        worst[1],
        worst[2],
        worst[3]
    );
    assert!(
        worst[0] < 1e-3 && worst[1] < 0.1 && worst[2] < 0.1,
        "{worst:?}"
    );
    assert!(worst[3] < 1e-3, "{worst:?}");
}

#[test]
fn three_stage_calibration_over_a_five_hour_flight() {
    let st = run_flight_study(&EmSimConfig::default(), &FlightStudyConfig::default()).unwrap();
    let (rb, ra, rn) = (
        st.polarization_ratio_before,
        st.polarization_ratio_after,
        st.ratio_without_pilot,
    );
    let e = [st.range_err_rel, st.angle_err_deg, st.attitude_err_deg];
    eprintln!(
        "polarisation ratio RMS: before {rb:.3e}, after {ra:.3e} ({:.0}×), after without pilot {rn:.3e}",
        rb / ra
    );
    eprintln!(
        "RMS errors over 5 h: range {:.3e} (rel), direction {:.4}°, attitude {:.4}°",
        e[0], e[1], e[2]
    );
    // Stable over the flight: the last hour is no worse than the first.
    let s = &st.ratio_after_series;
    let n = s.len();
    let (first, last) = (rms(&s[..n / 5]), rms(&s[n - n / 5..]));
    eprintln!("after-calibration ratio RMS first hour {first:.3e}, last hour {last:.3e}");
    assert_eq!(n, 40);
    assert!(rb / ra >= 100.0, "reduction {}", rb / ra);
    assert!(rn > 10.0 * ra, "without pilot {rn} vs {ra}");
    assert!(last < 3.0 * first && first < 3.0 * last);
    assert!(e[0] <= 1e-3 && e[1] <= 0.1 && e[2] <= 0.1, "{e:?}");
}

#[test]
fn flight_study_rejects_bad_sizes() {
    let bad = FlightStudyConfig {
        known_positions: 2,
        ..FlightStudyConfig::quick()
    };
    assert!(run_flight_study(&EmSimConfig::default(), &bad).is_err());
    assert!(epochs_at(&EmSimConfig::default(), &[], true).is_err());
}

/// A negative noise level was taken as its magnitude (`σ · N(0, 1)`):
/// `coil_noise_v = −1` gave 0.89 V RMS above 10 kHz instead of the
/// 0.3 mV of the sferics alone. It is refused; 0 adds no coil noise.
#[test]
fn noise_levels_must_be_non_negative_and_zero_adds_none() {
    for (k, v) in [
        (0, -1.0),
        (0, f64::NAN),
        (1, -1e-2),
        (2, -5e-3),
        (0, f64::INFINITY),
    ] {
        let mut cfg = EmSimConfig {
            duration_s: 0.02,
            ..EmSimConfig::default()
        };
        let name = ["coil_noise_v", "power_line_v", "sferic_amplitude_v"][k];
        *[
            &mut cfg.coil_noise_v,
            &mut cfg.power_line_v,
            &mut cfg.sferic_amplitude_v,
        ][k] = v;
        let err = EmScenario::new(cfg).unwrap_err();
        assert!(
            err.is_bad_input() && err.to_string().contains(name),
            "{err}"
        );
    }
    // Zero coil noise, no interference: the record is the signal alone, so
    // a record with 1e-12 V of noise differs only by f32 rounding.
    let quiet = |noise: f64| {
        let cfg = EmSimConfig {
            duration_s: 0.02,
            coil_noise_v: noise,
            power_line_v: 0.0,
            sferic_rate_hz: 0.0,
            ..EmSimConfig::default()
        };
        synthesize(&EmScenario::new(cfg).unwrap()).unwrap().samples
    };
    let (zero, tiny) = (quiet(0.0), quiet(1e-12));
    let peak = zero.iter().fold(0.0f32, |m, v| m.max(v.abs()));
    let diff = zero
        .iter()
        .zip(&tiny)
        .fold(0.0f32, |m, (a, b)| m.max((a - b).abs()));
    assert!(peak > 0.0 && diff <= peak * 1e-6, "peak {peak} diff {diff}");
}

/// The impulse test's threshold against clean records: over seeds 1–10 of
/// the `em simulate` scenario (10.24 s) (sferics and noise included) and detector blocks
/// of 400 … 16 000 samples, no sample's statistic comes near
/// [`SPIKE_THRESHOLD`] and no spike is repaired.
#[test]
fn clean_records_never_reach_the_impulse_threshold() {
    use crate::detection::SPIKE_THRESHOLD;
    use crate::detection::impulse::{largest_statistic, sub_block_len};
    let mut largest = (0.0f64, 0, 0);
    for seed in 1..=10 {
        let sc = EmScenario::new(EmSimConfig {
            seed,
            duration_s: 10.24,
            ..EmSimConfig::default()
        })
        .unwrap();
        let rec = synthesize(&sc).unwrap();
        let fs = sc.config.sample_rate_hz;
        let lowest = sc.config.frequencies_hz[0] - sc.config.pilot_offset_hz;
        for n in [400, 1600, 4000, 16_000] {
            let l = sub_block_len(n, fs, lowest);
            for block in rec.samples.chunks_exact(3 * n) {
                for c in 0..3 {
                    let u: Vec<f32> = block.iter().skip(c).step_by(3).copied().collect();
                    let (z, _) = largest_statistic(&u, l).unwrap();
                    if z > largest.0 {
                        largest = (z, seed, n);
                    }
                }
            }
        }
        let (epochs, spikes) = crate::study::field_chain(&sc, true)
            .unwrap()
            .process_with_spikes(&rec.samples, rec.header.start_index)
            .unwrap();
        assert_eq!(epochs.len(), 64);
        assert!(spikes.is_empty(), "seed {seed}: {spikes:?}");
    }
    eprintln!("largest impulse statistic (value, seed, N): {largest:?}");
    assert!(largest.0 < SPIKE_THRESHOLD / 2.0, "{largest:?}");
}

/// One 1000 V sample (finding 07) moved the detected fields of its epoch
/// by percents; repaired, the fields are those of the clean record to
/// 10⁻⁵, and the spike is reported with its frame and channel.
#[test]
fn a_spike_is_repaired_to_the_clean_fields() {
    let sc = EmScenario::new(EmSimConfig {
        duration_s: 0.32,
        ..EmSimConfig::default()
    })
    .unwrap();
    let clean = synthesize(&sc).unwrap().samples;
    let mut spiked = clean.clone();
    spiked[3 * 20_000] = 1000.0;
    let chain = crate::study::field_chain(&sc, true).unwrap();
    let (want, none) = chain.process_with_spikes(&clean, 0).unwrap();
    assert!(none.is_empty());
    let (got, spikes) = chain.process_with_spikes(&spiked, 0).unwrap();
    assert_eq!(spikes.len(), 1);
    let s = spikes[0];
    assert_eq!(
        (s.frame, s.channel, s.samples, s.value),
        (20_000, 0, 1, 1000.0)
    );
    assert!(s.statistic > 50.0, "{s:?}");
    assert_eq!(got[0], want[0]);
    let rel = |a: &FieldEpoch, b: &FieldEpoch| {
        let mut num = 0.0;
        let mut den = 0.0;
        for i in 0..3 {
            for c in 0..3 {
                num += (a.h[i][c] - b.h[i][c]).norm_sqr();
                den += b.h[i][c].norm_sqr();
            }
        }
        (num / den).sqrt()
    };
    let repaired = rel(&got[1], &want[1]);
    assert!(repaired < 1e-5, "{repaired}");
}
