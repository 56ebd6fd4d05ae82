//! Axis scales and view ranges.
//!
//! Everything a plot draws is first mapped into *axis units*: the value itself
//! on a linear axis, `log10(value)` on a log axis. Values that cannot be shown
//! — NaN, ±∞, and on a log axis zero and negative numbers — map to `None` and
//! are treated as gaps (a line is broken there, a point is not drawn). This is
//! documented behaviour, not an error: a PSD with an exact zero at DC still
//! plots on log-log axes.
//!
//! The automatic view range is the data extent in axis units, padded by a
//! fraction of its span; a degenerate extent (a constant series) is widened
//! to ±1 % of the value (±1 at zero) on linear axes and ±½ decade on log axes.

use super::ticks::{self, Ticks};
use crate::error::{ReportError, Result};

/// Linear or logarithmic (base 10) axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Scale {
    /// Axis units = value.
    Linear,
    /// Axis units = `log10(value)`; non-positive values are not drawable.
    Log,
}

impl Scale {
    /// `true` → [`Scale::Log`].
    pub fn from_log(log: bool) -> Self {
        if log { Scale::Log } else { Scale::Linear }
    }

    /// Maps a value into axis units; `None` when it cannot be drawn.
    pub fn to_axis(self, v: f64) -> Option<f64> {
        match self {
            Scale::Linear => v.is_finite().then_some(v),
            Scale::Log => (v.is_finite() && v > 0.0).then(|| v.log10()),
        }
    }

    /// Tick marks for a view `[lo, hi]` in axis units.
    pub fn ticks(self, lo: f64, hi: f64, max_intervals: usize) -> Ticks {
        match self {
            Scale::Linear => ticks::linear_ticks(lo, hi, max_intervals),
            Scale::Log => ticks::log_ticks(lo, hi, max_intervals),
        }
    }
}

/// Running minimum and maximum of finite axis-unit values.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Extent(Option<(f64, f64)>);

impl Extent {
    /// Includes `v` (must be finite).
    pub fn add(&mut self, v: f64) {
        self.0 = Some(match self.0 {
            None => (v, v),
            Some((lo, hi)) => (lo.min(v), hi.max(v)),
        });
    }

    /// The extent, `None` when nothing was added.
    pub fn get(self) -> Option<(f64, f64)> {
        self.0
    }
}

/// The view range in axis units.
///
/// * `user`: a range in data units given by the caller; it must be finite
///   with `lo < hi` (and `lo > 0` on a log axis), it is used as is.
/// * otherwise `extent` (axis units) padded by `pad` × span on each side;
///   `None` extent → [`ReportError::NoData`] for the plot `title`.
pub(crate) fn view_range(
    scale: Scale,
    user: Option<(f64, f64)>,
    extent: Option<(f64, f64)>,
    pad: f64,
    axis: &'static str,
    title: &str,
) -> Result<(f64, f64)> {
    if let Some((lo, hi)) = user {
        let invalid = |reason: &str| ReportError::InvalidRange {
            axis,
            reason: format!("({lo}, {hi}) {reason}"),
        };
        if !(lo.is_finite() && hi.is_finite()) {
            return Err(invalid("is not finite"));
        }
        if lo >= hi {
            return Err(invalid("is empty or reversed (need lo < hi)"));
        }
        return match (scale.to_axis(lo), scale.to_axis(hi)) {
            (Some(a), Some(b)) => Ok((a, b)),
            _ => Err(invalid("must be positive on a log axis")),
        };
    }
    let (lo, hi) = extent.ok_or_else(|| ReportError::NoData {
        title: title.to_string(),
    })?;
    if hi > lo {
        let span = hi - lo;
        return Ok((lo - pad * span, hi + pad * span));
    }
    let half = match scale {
        Scale::Log => 0.5,
        Scale::Linear if lo == 0.0 => 1.0,
        Scale::Linear => lo.abs() * 0.01,
    };
    Ok((lo - half, hi + half))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_scale_drops_non_positive() {
        assert_eq!(Scale::Log.to_axis(100.0), Some(2.0));
        assert_eq!(Scale::Log.to_axis(0.0), None);
        assert_eq!(Scale::Log.to_axis(-3.0), None);
        assert_eq!(Scale::Log.to_axis(f64::NAN), None);
        assert_eq!(Scale::Linear.to_axis(-3.0), Some(-3.0));
        assert_eq!(Scale::Linear.to_axis(f64::INFINITY), None);
    }

    #[test]
    fn view_range_rules() {
        let r = view_range(Scale::Linear, None, Some((0.0, 10.0)), 0.05, "y", "t").unwrap();
        assert_eq!(r, (-0.5, 10.5));
        let r = view_range(Scale::Linear, None, Some((5e4, 5e4)), 0.05, "y", "t").unwrap();
        assert_eq!(r, (49500.0, 50500.0));
        let r = view_range(Scale::Log, Some((0.1, 1000.0)), None, 0.05, "x", "t").unwrap();
        assert!((r.0 + 1.0).abs() < 1e-12 && (r.1 - 3.0).abs() < 1e-12);
        assert!(view_range(Scale::Log, Some((0.0, 10.0)), None, 0.0, "x", "t").is_err());
        assert!(view_range(Scale::Linear, Some((2.0, 1.0)), None, 0.0, "x", "t").is_err());
        assert!(view_range(Scale::Linear, Some((f64::NAN, 1.0)), None, 0.0, "x", "t").is_err());
        assert!(matches!(
            view_range(Scale::Linear, None, None, 0.0, "x", "t"),
            Err(ReportError::NoData { .. })
        ));
    }
}
