//! Tick positions and tick labels ("nice numbers").
//!
//! **Linear axes.** For a view range `[lo, hi]` and at most `n` intervals the
//! step is the smallest `m·10^e` with `m ∈ {1, 2, 5}` that is at least
//! `(hi − lo)/n` (Heckbert, "Nice numbers for graph labels", Graphics Gems,
//! 1990); ticks are the integer multiples of the step inside `[lo, hi]`, so
//! there are at most `n + 1` of them and they always include 0 when 0 is in
//! view. When that leaves a single tick (a view narrower than two steps), the
//! next smaller steps are taken until there are two. Labels get exactly as many decimals as the step needs; numbers of
//! magnitude ≥ 10⁶ or < 10⁻³ are written `5e5`, `1.0e6`, `1.5e6` (mantissa
//! digits as the step needs). Negative labels use the
//! typographic minus sign U+2212.
//!
//! **Log axes** work in `log10` units: major ticks on whole decades (every
//! k-th decade when there are too many), minor grid lines on `2…9 × 10^k`.
//! When the view holds fewer than two whole decades, majors fall back to the
//! `1, 2, 5 × 10^k` sequence (then `1…9 × 10^k`, then linear nice ticks) so
//! an axis never ends up with a single label.

/// Tick marks of one axis, in axis units (`log10` of the value on log axes).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Ticks {
    /// Labelled tick positions, increasing.
    pub major: Vec<f64>,
    /// One label per major tick.
    pub labels: Vec<String>,
    /// Unlabelled minor grid positions, increasing.
    pub minor: Vec<f64>,
}

impl Ticks {
    /// The label of the major tick nearest to `v` (plotters asks for labels by
    /// the tick value it was given, so this is an exact lookup in practice).
    pub fn label_for(&self, v: f64) -> String {
        let nearest = self
            .major
            .iter()
            .enumerate()
            .min_by(|a, b| (a.1 - v).abs().total_cmp(&(b.1 - v).abs()))
            .map(|(i, _)| i);
        nearest
            .and_then(|i| self.labels.get(i))
            .cloned()
            .unwrap_or_default()
    }
}

/// Smallest `m·10^e`, `m ∈ {1, 2, 5}`, that is `≥ span / max_intervals`.
///
/// `span > 0` and finite, `max_intervals ≥ 1`.
pub(crate) fn nice_step(span: f64, max_intervals: usize) -> f64 {
    let raw = span / max_intervals.max(1) as f64;
    let mut decade = 10f64.powf(raw.log10().floor());
    // Guard the floor() against log10 rounding (e.g. raw = 1000 - 1 ulp).
    if decade > raw {
        decade /= 10.0;
    }
    for m in [1.0, 2.0, 5.0, 10.0] {
        let step = m * decade;
        if step >= raw * (1.0 - 1e-12) {
            return step;
        }
    }
    10.0 * decade
}

/// The next smaller step of the 1-2-5 sequence (5 → 2 → 1 → 0.5 …).
fn smaller_nice_step(step: f64) -> f64 {
    let decade = 10f64.powf((step.log10() + 1e-9).floor());
    let m = (step / decade).round();
    if m >= 5.0 {
        2.0 * decade
    } else if m >= 2.0 {
        decade
    } else {
        0.5 * decade
    }
}

/// Integer multiples of `step` inside `[lo, hi]` (with a tolerance of 10⁻⁹
/// step so that ends that are multiples are kept).
fn multiples(lo: f64, hi: f64, step: f64) -> Vec<f64> {
    let tol = 1e-9;
    let first = (lo / step - tol).ceil() as i64;
    let last = (hi / step + tol).floor() as i64;
    (first..=last).map(|k| k as f64 * step).collect()
}

/// Linear nice ticks for the view `[lo, hi]` (`lo < hi`, finite) with at
/// most `max_intervals` intervals between labels.
pub(crate) fn linear_ticks(lo: f64, hi: f64, max_intervals: usize) -> Ticks {
    let mut step = nice_step(hi - lo, max_intervals);
    let mut major = multiples(lo, hi, step);
    // A view narrower than two steps may hold a single multiple: take the
    // next smaller 1-2-5 step until two labels fit (at most 2 rounds).
    while major.len() < 2 {
        step = smaller_nice_step(step);
        major = multiples(lo, hi, step);
    }
    let magnitude = lo.abs().max(hi.abs());
    let labels = major
        .iter()
        .map(|&v| format_linear(v, step, magnitude))
        .collect();
    Ticks {
        major,
        labels,
        minor: Vec::new(),
    }
}

/// Formats a tick value `v` of an axis whose tick step is `step` and whose
/// largest absolute value in view is `magnitude`.
pub(crate) fn format_linear(v: f64, step: f64, magnitude: f64) -> String {
    // Exact zero (k·step can come out as ±1e-17); keeps "-0" away.
    let v = if v.abs() < step * 1e-6 { 0.0 } else { v };
    let step_exp = (step.log10() + 1e-9).floor() as i32;
    let scientific = !(1e-3..1e6).contains(&magnitude);
    let text = if v == 0.0 && scientific {
        "0".to_string()
    } else if scientific {
        // Each label in its own exponent, with the digits the step needs:
        // 5e5, 1e6, 1.5e6.
        let exp = (v.abs().log10() + 1e-9).floor() as i32;
        let decimals = (exp - step_exp).clamp(0, 15) as usize;
        let mantissa = v / 10f64.powi(exp);
        format!("{mantissa:.decimals$}e{exp}")
    } else {
        let decimals = (-step_exp).clamp(0, 15) as usize;
        format!("{v:.decimals$}")
    };
    typographic_minus(text)
}

/// Replaces a leading ASCII hyphen with the minus sign U+2212.
fn typographic_minus(text: String) -> String {
    match text.strip_prefix('-') {
        Some(rest) => format!("\u{2212}{rest}"),
        None => text,
    }
}

/// Superscript form of an integer exponent, e.g. `-3` → `⁻³`.
fn superscript(exp: i32) -> String {
    const DIGITS: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let mut out = String::new();
    if exp < 0 {
        out.push('⁻');
    }
    for c in exp.unsigned_abs().to_string().chars() {
        if let Some(d) = c.to_digit(10) {
            out.push(DIGITS[d as usize]);
        }
    }
    out
}

/// Label of the value `10^exp`: plain decimal (`0.001` … `10000`) when
/// `plain`, else `10ᵉˣᵖ` with a superscript exponent.
fn decade_label(exp: i32, plain: bool) -> String {
    if plain {
        let decimals = (-exp).max(0) as usize;
        format!("{:.decimals$}", 10f64.powi(exp))
    } else {
        format!("10{}", superscript(exp))
    }
}

/// Label of a value `m·10^k` between decades on a log axis.
fn plain_value_label(v: f64) -> String {
    let text = if (1e-3..1e5).contains(&v) {
        // Shortest round-trip form after rounding away log10/pow noise.
        let exp = v.log10().floor() as i32;
        let scale = 10f64.powi(6 - exp);
        format!("{}", (v * scale).round() / scale)
    } else {
        let exp = v.log10().floor() as i32;
        let m = (v / 10f64.powi(exp) * 1e6).round() / 1e6;
        format!("{m}e{exp}")
    };
    typographic_minus(text)
}

/// Ticks of a log axis whose view is `[lo, hi]` in `log10` units
/// (`lo < hi`, finite), with at most `max_intervals` intervals between labels.
pub(crate) fn log_ticks(lo: f64, hi: f64, max_intervals: usize) -> Ticks {
    let tol = 1e-9;
    let first = (lo - tol).ceil() as i32;
    let last = (hi + tol).floor() as i32;
    let decades = if last >= first { last - first + 1 } else { 0 };
    if decades >= 2 {
        let max_labels = max_intervals.max(1) as i32 + 1;
        let stride = (decades + max_labels - 1) / max_labels; // ceil
        let stride = stride.max(1);
        let first_major =
            first + (first.rem_euclid(stride) != 0) as i32 * (stride - first.rem_euclid(stride));
        let majors: Vec<i32> = (first_major..=last).step_by(stride as usize).collect();
        let plain = majors.iter().all(|e| (-3..=4).contains(e));
        let labels = majors.iter().map(|&e| decade_label(e, plain)).collect();
        let mut minor = Vec::new();
        if stride == 1 {
            if decades <= 12 {
                for k in (first - 1)..=last {
                    for m in 2..=9 {
                        let p = k as f64 + (m as f64).log10();
                        if p >= lo - tol && p <= hi + tol {
                            minor.push(p);
                        }
                    }
                }
            }
        } else {
            minor = (first..=last)
                .filter(|e| !majors.contains(e))
                .map(|e| e as f64)
                .collect();
        }
        return Ticks {
            major: majors.iter().map(|&e| e as f64).collect(),
            labels,
            minor,
        };
    }
    // Less than two whole decades in view: 1-2-5, then 1…9 multiples.
    for mantissas in [
        &[1.0, 2.0, 5.0][..],
        &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0][..],
    ] {
        let mut values = Vec::new();
        for k in (first - 1)..=(last + 1) {
            for &m in mantissas {
                let p = k as f64 + f64::log10(m);
                if p >= lo - tol && p <= hi + tol {
                    values.push(m * 10f64.powi(k));
                }
            }
        }
        if values.len() >= 2 && values.len() <= max_intervals + 1 {
            return Ticks {
                major: values.iter().map(|v| v.log10()).collect(),
                labels: values.iter().map(|&v| plain_value_label(v)).collect(),
                minor: Vec::new(),
            };
        }
    }
    // Very narrow view: linear nice ticks in value space.
    let lin = linear_ticks(10f64.powf(lo), 10f64.powf(hi), max_intervals);
    Ticks {
        major: lin.major.iter().map(|v| v.log10()).collect(),
        labels: lin.labels,
        minor: Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// Linear ticks: inside the view, increasing, evenly spaced by a
        /// 1-2-5 step, at most n + 1 of them, at least 2 when n ≥ 2.
        #[test]
        fn linear_ticks_invariants(lo in -1e7f64..1e7, span_exp in -6f64..8.0, n in 2usize..12) {
            let hi = lo + 10f64.powf(span_exp);
            prop_assume!(hi > lo);
            let t = linear_ticks(lo, hi, n);
            prop_assert!(t.major.len() >= 2, "{:?}", t.major);
            prop_assert_eq!(t.major.len(), t.labels.len());
            let regular = nice_step(hi - lo, n);
            // The step is the regular one unless that gave < 2 ticks.
            let step = if multiples(lo, hi, regular).len() >= 2 {
                prop_assert!(t.major.len() <= n + 1, "{} ticks", t.major.len());
                regular
            } else {
                let smaller = smaller_nice_step(regular);
                if multiples(lo, hi, smaller).len() >= 2 { smaller } else { smaller_nice_step(smaller) }
            };
            let tol = 1e-9 * step;
            for w in t.major.windows(2) {
                // Spacing exact up to the rounding of k·step at this magnitude.
                let ulps = 8.0 * f64::EPSILON * w[1].abs().max(w[0].abs());
                prop_assert!(((w[1] - w[0]) - step).abs() <= 1e-9 * step + ulps);
            }
            prop_assert!(t.major[0] >= lo - tol && *t.major.last().unwrap() <= hi + tol);
            // Labels are unique (enough decimals for the step).
            let mut labels = t.labels.clone();
            labels.dedup();
            prop_assert_eq!(labels.len(), t.labels.len());
        }

        /// Log ticks: inside the view, increasing, ≥ 2 labels, ≤ n + 1.
        #[test]
        fn log_ticks_invariants(lo in -12f64..12.0, span in 0.02f64..20.0, n in 2usize..12) {
            let hi = lo + span;
            let t = log_ticks(lo, hi, n);
            prop_assert!(t.major.len() >= 2, "{:?}", t.major);
            // Decades and 1-2-5 / 1…9 multiples respect the label budget; only
            // the linear fallback may add labels to reach two (≤ 6 then).
            prop_assert!(t.major.len() <= (n + 1).max(6), "{:?}", t.major);
            prop_assert!(t.major.windows(2).all(|w| w[1] > w[0]));
            prop_assert!(t.major[0] >= lo - 1e-9 && *t.major.last().unwrap() <= hi + 1e-9);
            prop_assert!(t.minor.iter().all(|&m| m >= lo - 1e-9 && m <= hi + 1e-9));
        }
    }

    #[test]
    fn smaller_step_walks_the_1_2_5_sequence() {
        assert_eq!(smaller_nice_step(5.0), 2.0);
        assert_eq!(smaller_nice_step(2.0), 1.0);
        assert_eq!(smaller_nice_step(1.0), 0.5);
        assert_eq!(smaller_nice_step(1e5), 5e4);
        // 2.87e6 .. 3.45e6 in 2 intervals: step 5e5 gives only 3e6.
        let t = linear_ticks(2.87e6, 3.45e6, 2);
        assert_eq!(t.labels, vec!["3.0e6", "3.2e6", "3.4e6"]);
    }

    #[test]
    fn nice_step_is_1_2_5_and_large_enough() {
        assert_eq!(nice_step(10.0, 5), 2.0);
        assert_eq!(nice_step(10.0, 10), 1.0);
        assert_eq!(nice_step(1.0, 4), 0.5);
        assert_eq!(nice_step(1000.0, 10), 100.0);
        assert_eq!(nice_step(7.3, 5), 2.0);
        assert!((nice_step(0.03, 6) - 0.005).abs() < 1e-15);
        for span in [0.0123, 0.7, 3.0, 99.0, 12345.0, 6.02e23] {
            for n in 1..12 {
                let s = nice_step(span, n);
                assert!(
                    s * n as f64 >= span * (1.0 - 1e-9),
                    "span {span} n {n} step {s}"
                );
                let m = s / 10f64.powf(s.log10().floor());
                let ok = [1.0, 2.0, 5.0, 10.0].iter().any(|c| (m - c).abs() < 1e-9);
                assert!(ok, "step {s} mantissa {m}");
            }
        }
    }

    #[test]
    fn linear_ticks_cover_view_and_format() {
        let t = linear_ticks(-3.2, 7.9, 6);
        assert_eq!(t.major, vec![-2.0, 0.0, 2.0, 4.0, 6.0]);
        assert_eq!(t.labels, vec!["\u{2212}2", "0", "2", "4", "6"]);
        let t = linear_ticks(0.0, 1.0, 5);
        assert_eq!(t.labels, vec!["0.0", "0.2", "0.4", "0.6", "0.8", "1.0"]);
        // Field magnitudes: a narrow window on a large value keeps decimals.
        let t = linear_ticks(50000.0, 50000.1, 5);
        assert_eq!(t.labels.first().map(String::as_str), Some("50000.00"));
        assert_eq!(t.labels.last().map(String::as_str), Some("50000.10"));
        let t = linear_ticks(0.0, 3.0e6, 3);
        assert_eq!(t.labels, vec!["0", "1e6", "2e6", "3e6"]);
        let t = linear_ticks(0.0, 2.5e-4, 5);
        assert_eq!(
            t.labels,
            vec!["0", "5e-5", "1.0e-4", "1.5e-4", "2.0e-4", "2.5e-4"]
        );
        let t = linear_ticks(-1.2e6, 1.2e6, 5);
        assert_eq!(
            t.labels,
            vec!["\u{2212}1.0e6", "\u{2212}5e5", "0", "5e5", "1.0e6"]
        );
    }

    #[test]
    fn log_ticks_decades_and_minor() {
        // 1e-2 .. 1e3: six decades, plain labels.
        let t = log_ticks(-2.0, 3.0, 8);
        assert_eq!(t.labels, vec!["0.01", "0.1", "1", "10", "100", "1000"]);
        assert_eq!(t.minor.len(), 5 * 8);
        // Twenty decades, stride so that at most 6 labels remain.
        let t = log_ticks(-10.0, 10.0, 5);
        // Majors sit on multiples of the stride, so 10⁰ is labelled.
        assert_eq!(t.labels, vec!["10⁻⁸", "10⁻⁴", "10⁰", "10⁴", "10⁸"]);
        assert!(t.minor.contains(&-10.0) && t.minor.contains(&10.0));
    }

    #[test]
    fn log_ticks_narrow_views_have_two_labels() {
        // 2 .. 80: only one whole decade (10) → 1-2-5 sequence.
        let t = log_ticks(2f64.log10(), 80f64.log10(), 8);
        assert_eq!(t.labels, vec!["2", "5", "10", "20", "50"]);
        // 2.1 .. 4.9 → 3, 4.
        let t = log_ticks(2.1f64.log10(), 4.9f64.log10(), 8);
        assert_eq!(t.labels, vec!["3", "4"]);
        // 2.10 .. 2.15 → linear ticks in value space.
        let t = log_ticks(2.10f64.log10(), 2.15f64.log10(), 5);
        assert!(t.major.len() >= 2);
        assert_eq!(t.labels[0], "2.10");
    }
}
