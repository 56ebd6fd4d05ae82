//! The vertical gradient of the anomalous field at a crossover, from the two
//! profiles that cross there: the regressor of the altitude term of the
//! levelling fit ([`super::fit`]).
//!
//! ## Why
//!
//! The levelling model assumes that both passes of a crossover see the same
//! field. At survey altitude the two passes are flown metres apart in
//! height (turbulence, altitude hold), and 100 m above magnetic sources the
//! vertical gradient is 0.01–0.1 nT/m: on the demo survey the true field
//! differs by 0.18 nT RMS between the two passes of a crossover (6.2 m RMS
//! altitude difference), as much as the `k·d|B0|/dt` term the fit is after
//! (0.21 nT RMS). Correcting the crossovers for the altitude difference
//! needs the vertical gradient there, which no channel measures.
//!
//! ## The operator (units nT, m)
//!
//! Above its sources a potential field continues upward as
//! `B̂(κ, h + Δh) = B̂(κ, h) e^{−|κ|Δh}` (2-D wavenumber `κ = (κ_x, κ_y)`),
//! so `∂B/∂h = −F⁻¹[|κ| B̂]` (h up). On a straight profile along `x` at
//! constant height the 1-D transform of the samples gives exactly
//! `S_x = F⁻¹[|κ_x| B̂]` at the profile's points — the same operator applied
//! with `|κ_x|` instead of `|κ|`. At a crossover the line gives `S_x`, the
//! tie gives `S_y`, and since `max(|κ_x|, |κ_y|) ≤ |κ| ≤ |κ_x| + |κ_y|`,
//!
//! ```text
//! ∂B/∂h ≈ −c (S_a + S_b)
//! ```
//!
//! with a scale `c` that the levelling fit estimates from the crossovers.
//! For an isotropic field crossed at right angles the least-squares value
//! over all wavenumber directions is
//! `c = E[|cos θ| + |sin θ|] / E[(|cos θ| + |sin θ|)²] = (4/π)/(1 + 2/π) ≈ 0.78`,
//! and the remaining error is about 10 % of the gradient. On the demo
//! survey the fitted `c` is 0.86 and the true altitude-induced crossover
//! differences drop from 0.178 to 0.052 nT RMS (measured with the truth
//! columns of the simulation, which this code never reads).
//!
//! ## Computation per track segment
//!
//! 1. Along-track distance `s` from the positions (local north/east plane
//!    of the segment's first row, [`Geodetic::ned_offset_to`]); rows without
//!    a position, or that do not advance, are skipped.
//! 2. Resample the value at the median spacing `Δs` (linear interpolation)
//!    and remove the least-squares straight line (`|κ|` of a line is 0; the
//!    main-field gradient goes with it).
//! 3. Extend evenly (mirror), so the periodic signal is continuous at both
//!    ends; FFT; multiply by `|κ| exp(−(κℓ)²/2)` with `ℓ = 2Δs` (a Gaussian
//!    taper that keeps the `|κ|` amplification of the sensor noise near the
//!    Nyquist wavenumber in check: white noise of 0.01 nT at 7 m spacing
//!    gives about 0.001 nT/m); inverse FFT.
//! 4. Interpolate back to the rows (linear in `s`).
//!
//! Segments shorter than 64 positioned samples get NaN (no correction).
//! Cost `O(n log n)` per segment. Edge effects of the mirror extension
//! reach about one source depth (~100–300 m) into each end of a segment.
//! The profile should be flown at roughly constant height; the altitude
//! variations along it enter `S` only to second order.

use super::tracks::{SurveyTracks, TrackConfig};
use crate::error::Result;
use aeromag_core::frames::Geodetic;
use realfft::RealFftPlanner;

/// Segments with fewer positioned samples than this get no gradient.
pub const MIN_PROFILE_SAMPLES: usize = 64;

/// Resampled points per positioned sample beyond which a segment gets no
/// gradient: its median step is far below its mean step, the positions
/// jittering in place for most of it. Found by fuzzing: a line whose first
/// 70 % of positions alternated between two adjacent latitudes (a median
/// step of 10⁻⁹ m) asked for 5·10¹³ bytes and aborted the process.
pub const MAX_RESAMPLE_FACTOR: usize = 4;

/// The profile operator `S = F⁻¹[|κ_s| B̂]` (nT/m) along each track segment
/// of `tracks.value`, one value per row; NaN off lines, on short segments
/// and at rows without a position (module docs).
pub fn profile_gradient(tracks: &SurveyTracks, cfg: &TrackConfig) -> Result<Vec<f64>> {
    tracks.validate()?;
    cfg.validate()?;
    let mut out = vec![f64::NAN; tracks.len()];
    let mut planner = RealFftPlanner::<f64>::new();
    for seg in tracks.segments(cfg) {
        // Along-track distance of the positioned rows that advance.
        let mut rows: Vec<usize> = Vec::with_capacity(seg.len());
        let mut s: Vec<f64> = Vec::with_capacity(seg.len());
        let mut origin: Option<Geodetic> = None;
        let mut last = [0.0; 2];
        for i in seg {
            let (lat, lon) = (tracks.lat[i], tracks.lon[i]);
            if !(lat.is_finite() && lon.is_finite()) {
                continue;
            }
            let o = *origin.get_or_insert(Geodetic::new(lat, lon, 0.0));
            let [n, e, _] = o.ned_offset_to(&Geodetic::new(lat, lon, 0.0));
            let step = (n - last[0]).hypot(e - last[1]);
            if let Some(&prev) = s.last() {
                if step <= 0.0 {
                    continue;
                }
                s.push(prev + step);
            } else {
                s.push(0.0);
            }
            last = [n, e];
            rows.push(i);
        }
        if rows.len() < MIN_PROFILE_SAMPLES {
            continue;
        }
        let mut steps: Vec<f64> = s.windows(2).map(|w| w[1] - w[0]).collect();
        steps.sort_by(f64::total_cmp);
        let ds = steps[steps.len() / 2];
        let values: Vec<f64> = rows.iter().map(|&i| tracks.value[i]).collect();
        let total = *s.last().unwrap_or(&0.0);
        // A segment whose median step is far below its mean (positions
        // jittering in place for most of it) is no profile to resample.
        let resamplable = total / ds <= (MAX_RESAMPLE_FACTOR * rows.len()) as f64;
        if !resamplable {
            continue;
        }
        let m = (total / ds).floor() as usize + 1;
        let grid: Vec<f64> = (0..m).map(|j| j as f64 * ds).collect();
        let mut u: Vec<f64> = grid.iter().map(|&x| interp(&s, &values, x)).collect();
        remove_line(&grid, &mut u);
        let g = abs_wavenumber(&mut planner, &u, ds, 2.0 * ds);
        for (&i, &x) in rows.iter().zip(&s) {
            out[i] = interp(&grid, &g, x);
        }
    }
    Ok(out)
}

/// `F⁻¹[|κ| e^{−(κℓ)²/2} F[u]]` of uniformly spaced samples (spacing `ds`,
/// m), with even (mirror) extension; nT/m for `u` in nT.
fn abs_wavenumber(planner: &mut RealFftPlanner<f64>, u: &[f64], ds: f64, taper_m: f64) -> Vec<f64> {
    let m = u.len();
    let n = 2 * m;
    let mut ext: Vec<f64> = u.iter().chain(u.iter().rev()).copied().collect();
    let fwd = planner.plan_fft_forward(n);
    let inv = planner.plan_fft_inverse(n);
    let mut spec = fwd.make_output_vec();
    // The lengths are those of the plans: the transforms cannot fail.
    fwd.process(&mut ext, &mut spec)
        .expect("FFT lengths match the plan");
    let dk = 2.0 * std::f64::consts::PI / (n as f64 * ds);
    for (j, c) in spec.iter_mut().enumerate() {
        let k = j as f64 * dk;
        *c *= k * (-0.5 * (k * taper_m).powi(2)).exp() / n as f64;
    }
    // The imaginary parts of the DC and Nyquist bins (n is even) must be
    // zero for the inverse real transform; the multiplier is real, so they
    // stay (near) zero.
    spec[0].im = 0.0;
    spec[m].im = 0.0;
    let mut back = inv.make_output_vec();
    inv.process(&mut spec, &mut back)
        .expect("FFT lengths match the plan");
    back.truncate(m);
    back
}

/// Subtract the least-squares straight line through `(x, y)`.
fn remove_line(x: &[f64], y: &mut [f64]) {
    let n = x.len() as f64;
    let xm = x.iter().sum::<f64>() / n;
    let ym = y.iter().sum::<f64>() / n;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (a, b) in x.iter().zip(y.iter()) {
        sxy += (a - xm) * (b - ym);
        sxx += (a - xm) * (a - xm);
    }
    let slope = if sxx > 0.0 { sxy / sxx } else { 0.0 };
    for (a, b) in x.iter().zip(y.iter_mut()) {
        *b -= ym + slope * (a - xm);
    }
}

/// Linear interpolation in increasing `xs` (clamped at the ends).
fn interp(xs: &[f64], ys: &[f64], x: f64) -> f64 {
    let j = xs.partition_point(|&v| v <= x);
    if j == 0 {
        return ys[0];
    }
    if j >= xs.len() {
        return ys[xs.len() - 1];
    }
    let f = (x - xs[j - 1]) / (xs[j] - xs[j - 1]);
    ys[j - 1] + f * (ys[j] - ys[j - 1])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The profile operator of one set of tracks (altitude unused).
    fn gradient_of(
        time: &[f64],
        lat: &[f64],
        lon: &[f64],
        line: &[f64],
        value: &[f64],
    ) -> Vec<f64> {
        let alt = vec![0.0; time.len()];
        let tracks = SurveyTracks {
            time,
            lat,
            lon,
            alt: &alt,
            line,
            value,
            sensed: None,
        };
        profile_gradient(&tracks, &TrackConfig::default()).unwrap()
    }

    /// A 2-D harmonic field of a line source at depth `D` below the profile,
    /// `u(x) = D/(x² + D²)`: its profile operator is exactly `−∂u/∂h`
    /// `= (D² − x²)/(x² + D²)²` (the field's 1-D transform is `π e^{−|κ|D}`).
    #[test]
    fn line_source_profile_gives_the_vertical_derivative() {
        let d = 200.0;
        let o = Geodetic::new(50.0, 10.0, 0.0);
        let ds = 7.0;
        let n = 1500; // 10.5 km
        let x0 = -0.5 * (n as f64) * ds;
        let (mut lat, mut lon, mut value) = (vec![], vec![], vec![]);
        for i in 0..n {
            let x = x0 + i as f64 * ds;
            let p = o.offset_by(x, 0.0, 0.0);
            lat.push(p.lat_deg);
            lon.push(p.lon_deg);
            // Scaled to nT-like numbers, plus a regional linear trend that
            // the operator must ignore.
            value.push(1.0e4 * d / (x * x + d * d) + 0.002 * x + 50_000.0);
        }
        let time: Vec<f64> = (0..n).map(|i| i as f64 * 0.1).collect();
        let g = gradient_of(&time, &lat, &lon, &vec![1.0; n], &value);
        let peak = 1.0e4 / (d * d);
        // The tapered operator applied to the exact transform:
        // 10⁴ ∫₀^∞ κ e^{−κD − (κℓ)²/2} cos κx dκ (trapezoid, ℓ = 2Δs).
        let ell = 2.0 * ds;
        let tapered = |x: f64| {
            let (m, kmax) = (20_000, 60.0 / d);
            let h = kmax / m as f64;
            (0..=m)
                .map(|j| {
                    let k = j as f64 * h;
                    let w = if j == 0 || j == m { 0.5 } else { 1.0 };
                    w * k * (-k * d - 0.5 * (k * ell).powi(2)).exp() * (k * x).cos()
                })
                .sum::<f64>()
                * h
                * 1.0e4
        };
        let (mut worst, mut bias): (f64, f64) = (0.0, 0.0);
        for i in (0..n).step_by(5) {
            let x = x0 + i as f64 * ds;
            if x.abs() > 1500.0 {
                continue;
            }
            let exact = 1.0e4 * (d * d - x * x) / (x * x + d * d).powi(2);
            worst = worst.max((g[i] - tapered(x)).abs() / peak);
            bias = bias.max((g[i] - exact).abs() / peak);
        }
        // The implementation matches the tapered operator (finite-profile and
        // resampling errors only) …
        assert!(worst < 2e-3, "worst error {worst} of the peak");
        // … whose smoothing (ℓ = 14 m against D = 200 m) costs ~1.5 % of
        // the vertical derivative, ≈ 3ℓ²/D².
        assert!(bias < 0.02, "bias {bias} of the peak");
        // Far from the source the operator gives ~0, not the trend's slope.
        assert!(g[n / 2].is_finite() && g[n / 2] > 0.9 * peak);
    }

    #[test]
    fn a_profile_jittering_in_place_gets_nan_not_a_huge_resampling() {
        // 70 % of the rows alternate between two adjacent latitudes, then
        // the line advances 7 m per row.
        let n = 1000;
        let time: Vec<f64> = (0..n).map(|i| i as f64 * 0.1).collect();
        let lat: Vec<f64> = (0..n)
            .map(|i| match i {
                i if i < 700 && i % 2 == 0 => 50.0,
                i if i < 700 => f64::from_bits(50.0f64.to_bits() + 1),
                i => 50.0 + (i - 699) as f64 * 6.3e-5,
            })
            .collect();
        let g = gradient_of(&time, &lat, &vec![10.0; n], &vec![1.0; n], &vec![5.0e4; n]);
        assert!(g.iter().all(|v| v.is_nan()));
    }

    #[test]
    fn short_segments_and_rows_off_lines_get_nan() {
        let n = 40;
        let time: Vec<f64> = (0..n).map(|i| i as f64).collect();
        let lat: Vec<f64> = (0..n).map(|i| 50.0 + i as f64 * 1e-4).collect();
        let lon = vec![10.0; n];
        let line: Vec<f64> = (0..n).map(|i| if i < 30 { 1.0 } else { 0.0 }).collect();
        let g = gradient_of(&time, &lat, &lon, &line, &vec![1.0; n]);
        assert!(g.iter().all(|v| v.is_nan()));
    }
}
