//! Improvement ratio (IR).
//!
//! `IR = std(bpf(uncompensated)) / std(bpf(compensated))`, with `bpf` the
//! zero-phase Butterworth band-pass of the fit (default order 4,
//! 0.1–0.9 Hz), applied per contiguous segment; the standard deviations are
//! pooled over all segments (spec `compensation.md`, "Metrics").

use crate::error::Result;
use aeromag_core::filter::BandPass;
use std::ops::Range;

/// `x` band-passed segment by segment; NaN outside the segments and in
/// segments too short for the filter.
pub fn band_pass_segments(
    x: &[f64],
    segments: &[Range<usize>],
    bpf: &BandPass,
) -> Result<Vec<f64>> {
    let mut out = vec![f64::NAN; x.len()];
    for r in segments {
        if r.len() >= bpf.min_len() {
            out[r.clone()].copy_from_slice(&bpf.filter(&x[r.clone()])?);
        }
    }
    Ok(out)
}

/// Band-pass every segment of `x` and return the pooled standard deviation
/// about the mean (segments too short for the filter are skipped; `None` if
/// none remain).
pub fn band_passed_std(
    x: &[f64],
    segments: &[Range<usize>],
    bpf: &BandPass,
) -> Result<Option<f64>> {
    let y: Vec<f64> = band_pass_segments(x, segments, bpf)?
        .into_iter()
        .filter(|v| v.is_finite())
        .collect();
    let n = y.len();
    if n < 2 {
        return Ok(None);
    }
    let m = y.iter().sum::<f64>() / n as f64;
    Ok(Some(
        (y.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (n - 1) as f64).sqrt(),
    ))
}

/// Improvement ratio of a compensation over the given segments.
pub fn improvement_ratio(
    uncomp: &[f64],
    comp: &[f64],
    segments: &[Range<usize>],
    bpf: &BandPass,
) -> Result<Option<f64>> {
    let a = band_passed_std(uncomp, segments, bpf)?;
    let b = band_passed_std(comp, segments, bpf)?;
    Ok(match (a, b) {
        (Some(a), Some(b)) if b > 0.0 => Some(a / b),
        _ => None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    // One window over the whole series.
    #[allow(clippy::single_range_in_vec_init)]
    fn ratio_of_in_band_amplitudes() {
        let n = 3000;
        let t: Vec<f64> = (0..n).map(|i| i as f64 * 0.1).collect();
        let tone = |a: f64| -> Vec<f64> {
            t.iter()
                .map(|s| a * (std::f64::consts::TAU * 0.3 * s).sin() + 0.01 * s)
                .collect()
        };
        let bpf = BandPass::compensation_default(10.0).unwrap();
        let ir = improvement_ratio(&tone(5.0), &tone(0.25), &[0..n], &bpf)
            .unwrap()
            .unwrap();
        assert!((ir - 20.0).abs() < 0.2, "{ir}");
        assert_eq!(
            improvement_ratio(&tone(1.0), &tone(1.0), &[0..10], &bpf).unwrap(),
            None
        );
    }
}
