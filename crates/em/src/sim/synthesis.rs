//! ADC-level signal synthesis of the `em` scenario (model in [`super`]).
//!
//! The slowly varying complex amplitudes of the nine tones (three working,
//! six pilot) per channel are evaluated every [`UPDATE_SAMPLES`] samples and
//! interpolated linearly in between; the carriers `e^{−iωt}` are exact per
//! sample. Noise: white coil noise, odd 400 Hz harmonics (amplitude `V/h`,
//! fixed random channel coupling and phase), sferics (Poisson arrivals,
//! damped 3–12 kHz oscillations, log-normal amplitude, random direction).

use super::raw_format::RawHeader;
use super::scenario::EmScenario;
use crate::Result;
use crate::detection::Complex64;
use crate::positioning::Pose;
use aeromag_core::field::dipole::dipole_matrix;
use nalgebra::{Matrix3, Vector3};
use rand::RngExt;
use rand_distr::{Distribution, Exp, LogNormal, Normal};
use std::f64::consts::TAU;

/// Samples between evaluations of the slowly varying amplitudes.
pub const UPDATE_SAMPLES: usize = 100;

/// A synthesized record: header plus interleaved f32 samples (V).
#[derive(Debug, Clone, PartialEq)]
pub struct EmRecording {
    /// Header (rate, channel count, scenario).
    pub header: RawHeader,
    /// `samples[n * 3 + c]`, volts.
    pub samples: Vec<f32>,
}

/// The nine tones: (frequency Hz, working-frequency index, kind) with kind
/// 0 = working, −1/+1 = pilot below/above.
fn tones(sc: &EmScenario) -> Vec<(f64, usize, i32)> {
    let d = sc.config.pilot_offset_hz;
    let mut t = Vec::with_capacity(9);
    for (i, &f) in sc.config.frequencies_hz.iter().enumerate() {
        t.push((f, i, 0));
        t.push((f - d, i, -1));
        t.push((f + d, i, 1));
    }
    t
}

/// Complex amplitudes (V) of every tone and channel at flight time `t_s`:
/// `ξ_c(ω,t) (χ_i (−iω g) X)_c`, `X = R Ω(r) M'_i` (working) or `P` (pilot).
fn amplitudes(
    sc: &EmScenario,
    tones: &[(f64, usize, i32)],
    m_eff: &Matrix3<Complex64>,
    pose: &Pose,
    t_s: f64,
) -> Vec<Complex64> {
    let c = &sc.config;
    let rom =
        (pose.rotation * dipole_matrix(&pose.position_m)).map(|v| Complex64::new(v, 0.0)) * m_eff;
    let pilot = c.pilot_field_t.map(|v| Complex64::new(v, 0.0));
    let mut out = Vec::with_capacity(tones.len() * 3);
    for &(f, i, kind) in tones {
        let x: Vector3<Complex64> = if kind == 0 {
            rom.column(i).into_owned()
        } else {
            pilot
        };
        let v = sc.chi[i] * x * Complex64::new(0.0, -TAU * f * c.coil_gain_v_per_t_s);
        for ch in 0..3 {
            out.push(sc.sensitivity(ch, f, t_s) * v[ch]);
        }
    }
    out
}

/// Stream number ([`aeromag_core::random`]) of the noise and interference
/// of a record that starts at frame `n₀` of the flight: `2³² + n₀`, so that
/// records starting at different frames draw independent noise.
pub fn noise_stream(start_frame: u64) -> u64 {
    (1 << 32) + start_frame
}

/// Synthesize the record of `scenario`.
///
/// Errors only through invalid distributions (non-finite configuration).
pub fn synthesize(scenario: &EmScenario) -> Result<EmRecording> {
    let c = &scenario.config;
    let fs = c.sample_rate_hz;
    let frames = (c.duration_s * fs).round() as usize;
    let start_index = (c.start_time_s * fs).round() as u64;
    let tones = tones(scenario);
    let m_eff = scenario.effective_moments();
    let mut samples = vec![0.0f32; frames * 3];
    let bad = |e: &dyn std::fmt::Display| crate::EmError::InvalidArgument {
        reason: e.to_string(),
    };

    // Deterministic signal: interpolated amplitudes × exact carriers.
    let amp_at = |n: u64| {
        let t = n as f64 / fs;
        amplitudes(scenario, &tones, &m_eff, &scenario.pose_at(t), t)
    };
    let mut a0 = amp_at(start_index);
    let mut acc = [0.0f64; 3];
    for blk in (0..frames).step_by(UPDATE_SAMPLES) {
        let len = UPDATE_SAMPLES.min(frames - blk);
        let a1 = amp_at(start_index + (blk + UPDATE_SAMPLES) as u64);
        for j in 0..len {
            let n = start_index + (blk + j) as u64;
            let w = j as f64 / UPDATE_SAMPLES as f64;
            acc.iter_mut().for_each(|v| *v = 0.0);
            for (k, &(f, _, _)) in tones.iter().enumerate() {
                let ph = TAU * (f / fs * n as f64).fract();
                let (s, co) = ph.sin_cos();
                for ch in 0..3 {
                    let a = a0[k * 3 + ch] * (1.0 - w) + a1[k * 3 + ch] * w;
                    acc[ch] += a.re * co + a.im * s;
                }
            }
            for ch in 0..3 {
                samples[(blk + j) * 3 + ch] = acc[ch] as f32;
            }
        }
        a0 = a1;
    }

    // Noise and interference: the record's own stream of the seed.
    let mut rng = aeromag_core::random::stream(c.seed, noise_stream(start_index));
    let normal = Normal::new(0.0, 1.0).map_err(|e| bad(&e))?;
    for v in samples.iter_mut() {
        *v += (c.coil_noise_v * normal.sample(&mut rng)) as f32;
    }
    let harmonics: Vec<(f64, [f64; 3], f64)> = (0..8)
        .map(|h| {
            let order = (2 * h + 1) as f64;
            let coupling = [0, 1, 2].map(|_| rng.random_range(-1.0..1.0));
            (order, coupling, rng.random_range(0.0..TAU))
        })
        .filter(|(order, _, _)| 400.0 * order < fs / 2.0)
        .collect();
    for n in 0..frames {
        let t = (start_index + n as u64) as f64 / fs;
        for &(order, coupling, ph) in &harmonics {
            let v = c.power_line_v / order * (TAU * (400.0 * order * t).fract() + ph).sin();
            for ch in 0..3 {
                samples[n * 3 + ch] += (v * coupling[ch]) as f32;
            }
        }
    }
    if c.sferic_rate_hz > 0.0 && c.sferic_amplitude_v > 0.0 {
        let gap = Exp::new(c.sferic_rate_hz).map_err(|e| bad(&e))?;
        let amp = LogNormal::new(c.sferic_amplitude_v.ln(), 1.0).map_err(|e| bad(&e))?;
        let tau_s = 3e-4;
        let mut t = gap.sample(&mut rng);
        while t < c.duration_s {
            let a = amp.sample(&mut rng);
            let dir = Vector3::new(
                normal.sample(&mut rng),
                normal.sample(&mut rng),
                normal.sample(&mut rng),
            )
            .normalize();
            let f = rng.random_range(3000.0..12_000.0f64).min(0.45 * fs);
            let first = (t * fs) as usize;
            let last = (first + (5.0 * tau_s * fs) as usize).min(frames);
            for n in first..last {
                let dt = (n - first) as f64 / fs;
                let v = a * (-dt / tau_s).exp() * (TAU * f * dt).sin();
                for ch in 0..3 {
                    samples[n * 3 + ch] += (v * dir[ch]) as f32;
                }
            }
            t += gap.sample(&mut rng);
        }
    }
    let header = RawHeader::new(fs, 3, frames as u64, start_index, scenario.system());
    Ok(EmRecording { header, samples })
}
