//! Residual versus truth (simulation only).
//!
//! RMS of `compensated − reference` per line with each line's mean removed
//! (a level offset per line is the levelling's business, not the
//! compensation's), and the RMS pooled over all lines, in nT
//! (spec `compensation.md`, "Metrics").

use serde::{Deserialize, Serialize};
use std::ops::Range;

/// A line's label: a number where the `line` column holds numbers, else
/// its text (`L1020`, or number labels kept as text because two of them
/// read as one number, `1003.1` and `1003.10`). Serialised as a JSON
/// number or string.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum LineLabel {
    /// A numeric label.
    Number(f64),
    /// A text label.
    Text(String),
}

impl std::fmt::Display for LineLabel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Number(v) => write!(f, "{v}"),
            Self::Text(s) => f.write_str(s),
        }
    }
}

/// Residual statistics of one line.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LineResidual {
    /// Line label.
    pub line: LineLabel,
    /// Samples used.
    pub samples: usize,
    /// Mean of the difference, nT.
    pub mean_nt: f64,
    /// RMS of the difference about its mean, nT.
    pub rms_nt: f64,
}

/// Per-line residual statistics of `value − reference` over the given
/// segments (each segment belongs to one line, `line_of(start)`, the label
/// of its first row); non-finite samples are skipped. Returns the lines and
/// the pooled RMS.
pub fn residual_by_line(
    value: &[f64],
    reference: &[f64],
    line_of: &dyn Fn(usize) -> LineLabel,
    segments: &[Range<usize>],
) -> (Vec<LineResidual>, f64) {
    let mut lines: Vec<LineResidual> = Vec::new();
    let (mut pooled2, mut pooled_n) = (0.0, 0usize);
    for r in segments {
        let d: Vec<f64> = r
            .clone()
            .map(|i| value[i] - reference[i])
            .filter(|v| v.is_finite())
            .collect();
        if d.len() < 2 {
            continue;
        }
        let m = d.iter().sum::<f64>() / d.len() as f64;
        let ss = d.iter().map(|v| (v - m) * (v - m)).sum::<f64>();
        pooled2 += ss;
        pooled_n += d.len();
        lines.push(LineResidual {
            line: line_of(r.start),
            samples: d.len(),
            mean_nt: m,
            rms_nt: (ss / d.len() as f64).sqrt(),
        });
    }
    let pooled = if pooled_n > 0 {
        (pooled2 / pooled_n as f64).sqrt()
    } else {
        f64::NAN
    };
    (lines, pooled)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn per_line_means_are_removed() {
        let v: Vec<f64> = (0..20)
            .map(|i| {
                if i < 10 {
                    5.0 + (i % 2) as f64
                } else {
                    -3.0 + 2.0 * (i % 2) as f64
                }
            })
            .collect();
        let r = vec![0.0; 20];
        let line: Vec<f64> = (0..20).map(|i| if i < 10 { 1.0 } else { 2.0 }).collect();
        let of = |i: usize| LineLabel::Number(line[i]);
        let (lines, pooled) = residual_by_line(&v, &r, &of, &[0..10, 10..20]);
        assert_eq!(lines.len(), 2);
        assert_eq!(lines[1].line, LineLabel::Number(2.0));
        assert!((lines[0].rms_nt - 0.5).abs() < 1e-12 && (lines[1].rms_nt - 1.0).abs() < 1e-12);
        assert!((lines[0].mean_nt - 5.5).abs() < 1e-12);
        assert!((pooled - (0.625f64).sqrt()).abs() < 1e-12);
    }
}
