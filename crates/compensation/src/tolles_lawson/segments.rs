//! Splitting a flight into contiguous segments for filtering and fitting.
//!
//! A zero-phase filter must not run across a gap in time, a change of line
//! (calibration files hold several legs) or a missing sample. A segment is a
//! maximal run of usable rows with the same line label and no time step
//! larger than `max_gap_factor` × the median step.

use std::ops::Range;

/// Segments of `time` (s) where `usable[i]` holds, split at changes of
/// `line` (if given) and at time steps over `max_gap_factor` × the median
/// step. Segments shorter than `min_len` are dropped (and returned second so
/// the caller can report them: nothing is dropped silently).
pub fn split_segments(
    time: &[f64],
    line: Option<&[f64]>,
    usable: &[bool],
    max_gap_factor: f64,
    min_len: usize,
) -> (Vec<Range<usize>>, Vec<Range<usize>>) {
    split_segments_with(time, line, usable, max_gap_factor, min_len, || {
        median_step(time)
    })
}

/// [`split_segments`] with the median step of `time` given by `median`
/// (called only when the factor is finite), for a caller that has it
/// already.
pub fn split_segments_with(
    time: &[f64],
    line: Option<&[f64]>,
    usable: &[bool],
    max_gap_factor: f64,
    min_len: usize,
    median: impl FnOnce() -> f64,
) -> (Vec<Range<usize>>, Vec<Range<usize>>) {
    // An infinite factor makes every step a continuation whatever the
    // median (which is then not worked out).
    let dt = if max_gap_factor == f64::INFINITY {
        0.0
    } else {
        median()
    };
    let max_gap = if dt > 0.0 {
        dt * max_gap_factor
    } else {
        f64::INFINITY
    };
    split_at_steps(time, line, usable, max_gap, min_len)
}

/// [`split_segments`] with the longest step given, s (rather than a
/// multiple of the median step): the rule of a stream, which cannot know
/// its median step in advance.
pub fn split_at_steps(
    time: &[f64],
    line: Option<&[f64]>,
    usable: &[bool],
    max_gap: f64,
    min_len: usize,
) -> (Vec<Range<usize>>, Vec<Range<usize>>) {
    let n = time.len();
    let mut kept = Vec::new();
    let mut short = Vec::new();
    let mut i = 0;
    while i < n {
        if !usable[i] {
            i += 1;
            continue;
        }
        let start = i;
        i = first_break(time, line, usable, max_gap, i + 1);
        if i - start >= min_len {
            kept.push(start..i)
        } else {
            short.push(start..i)
        }
    }
    (kept, short)
}

/// Rows a block of [`first_break`] tests at once.
const BREAK_BLOCK: usize = 1024;

/// The first row `i ≥ from` that does not continue the segment of row
/// `i − 1` ([`split_at_steps`]: unusable, on another line, or after a step
/// that is not `≤ max_gap`), `time.len()` if none. A block of rows is
/// tested in one pass without a branch per row (a run of good rows, the
/// usual case, is skipped whole), and only a block with a break is
/// searched row by row.
fn first_break(
    time: &[f64],
    line: Option<&[f64]>,
    usable: &[bool],
    max_gap: f64,
    from: usize,
) -> usize {
    let n = time.len();
    // Row `i` continues row `i − 1`: its step and usability, and its line.
    let step_ok = |i: usize| usable[i] & ((time[i] - time[i - 1]) <= max_gap);
    let same_line = |l: &[f64], i: usize| (l[i - 1] == l[i]) | (l[i - 1].is_nan() & l[i].is_nan());
    let goes_on = |i: usize| step_ok(i) & line.is_none_or(|l| same_line(l, i));
    debug_assert!(from >= 1, "row 0 starts a segment");
    let mut a = from;
    while a < n {
        let b = (a + BREAK_BLOCK).min(n);
        let all_go_on = match line {
            // The two cases apart, so that each block's test vectorises.
            Some(l) => (a..b).fold(true, |ok, i| ok & step_ok(i) & same_line(l, i)),
            None => (a..b).fold(true, |ok, i| ok & step_ok(i)),
        };
        if !all_go_on {
            return (a..b).find(|&i| !goes_on(i)).unwrap_or(b);
        }
        a = b;
    }
    n
}

/// Median of the positive finite time steps, s (0 if there are none): the
/// step of rank `⌊N/2⌋` (from 0) among the `N` such steps.
///
/// A long record is not copied whole: the quantiles 0.48 and 0.52 of every
/// `k`-th step bracket the median, one pass counts the steps below the
/// bracket and on its ends and keeps those strictly inside it, and the
/// median is selected among those (exact: when the bracket misses it, every
/// step is used). On 10⁷ samples this took a tenth of the time of a copy
/// and selection.
pub fn median_step(time: &[f64]) -> f64 {
    let steps = || {
        time.windows(2)
            .map(|w| w[1] - w[0])
            .filter(|v| *v > 0.0 && v.is_finite())
    };
    let nth = |mut d: Vec<f64>, m: usize| *d.select_nth_unstable_by(m, f64::total_cmp).1;
    const SAMPLE: usize = 16_384;
    if time.len() > 16 * SAMPLE {
        // Every `every`-th step by index (a filtered iterator's `step_by`
        // would still test every step).
        let every = time.len() / SAMPLE;
        let sample: Vec<f64> = (1..time.len())
            .step_by(every)
            .map(|i| time[i] - time[i - 1])
            .filter(|v| *v > 0.0 && v.is_finite())
            .collect();
        if sample.len() >= 16 {
            let q = |p: f64| nth(sample.clone(), (p * (sample.len() - 1) as f64) as usize);
            let (lo, hi) = (q(0.48), q(0.52));
            // Steps below the bracket are counted, steps on its ends too
            // (time stamps on a fixed clock give few distinct steps, often
            // the ends themselves), and only those strictly inside are kept.
            let (total, below, at_lo, at_hi, inside) = bracket_counts(time, lo, hi);
            let m = total / 2;
            if below <= m {
                let k = m - below;
                if k < at_lo {
                    return lo;
                }
                if k - at_lo < inside.len() {
                    return nth(inside, k - at_lo);
                }
                if k - at_lo - inside.len() < at_hi {
                    return hi;
                }
            }
        }
    }
    let d: Vec<f64> = steps().collect();
    if d.is_empty() {
        return 0.0;
    }
    let m = d.len() / 2;
    nth(d, m)
}

/// Steps per block of [`bracket_counts`].
const BRACKET_BLOCK: usize = 4096;

/// Over the positive finite steps of `time`, given `0 < lo ≤ hi` finite:
/// how many there are, how many are below `lo`, equal to `lo`, equal to
/// `hi` (none when `hi` is `lo`), and those strictly between (in time
/// order).
///
/// In blocks of steps, each counted in one pass without a branch per step
/// (sums of comparisons), and only a block that has steps inside the
/// bracket passed again to keep them. A decimal clock's steps (`0.1` read
/// from text differs in its last bits from row to row) fall on the
/// bracket's ends or outside it at random, and a branch per step,
/// mispredicted half the time, cost twice the rest: 50 → 25 ms on the 10⁷
/// samples of the peer benchmark. The blocks are counted in contiguous
/// runs on the cores (31 → 24 ms, best of 15 on 10⁷ decimal time stamps).
fn bracket_counts(time: &[f64], lo: f64, hi: f64) -> (usize, usize, usize, usize, Vec<f64>) {
    // One block's counts: valid, below, at `lo`, at `hi`, inside.
    let count = |a: &[f64], b: &[f64]| -> [usize; 5] {
        let mut n = [0usize; 5];
        for (x, y) in a.iter().zip(b) {
            let d = y - x;
            // NaN compares false everywhere: not counted.
            let valid = (d > 0.0) & (d < f64::INFINITY);
            n[0] += usize::from(valid);
            n[1] += usize::from(valid & (d < lo));
            n[2] += usize::from(d == lo);
            n[3] += usize::from((d == hi) & (d != lo));
            n[4] += usize::from((d > lo) & (d < hi));
        }
        n
    };
    // The blocks in contiguous runs on the cores, each run's counts and
    // kept steps in block order; counts add up and the kept steps are
    // joined in run order (the same steps as one pass).
    let blocks = time.len().saturating_sub(1).div_ceil(BRACKET_BLOCK);
    let threads = aeromag_core::parallel::threads().clamp(1, blocks.max(1));
    let runs = aeromag_core::parallel::parallel_map(threads, threads, |r| {
        let mut sums = [0usize; 4];
        let mut inside: Vec<f64> = Vec::new();
        for blk in blocks * r / threads..blocks * (r + 1) / threads {
            let start = 1 + blk * BRACKET_BLOCK;
            let end = (start + BRACKET_BLOCK).min(time.len());
            let (a, b) = (&time[start - 1..end - 1], &time[start..end]);
            let n = count(a, b);
            for (s, c) in sums.iter_mut().zip(n) {
                *s += c;
            }
            if n[4] > 0 {
                inside.extend(
                    a.iter()
                        .zip(b)
                        .map(|(x, y)| y - x)
                        .filter(|&d| (d > lo) & (d < hi)),
                );
            }
        }
        (sums, inside)
    });
    let mut sums = [0usize; 4];
    let mut inside: Vec<f64> = Vec::new();
    for (s, kept) in runs {
        for (t, c) in sums.iter_mut().zip(s) {
            *t += c;
        }
        inside.extend(kept);
    }
    let [total, below, at_lo, at_hi] = sums;
    (total, below, at_lo, at_hi, inside)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bracketed median of a long record is the plain one, for
    /// uneven steps, repeated steps, gaps, steps that are not positive and
    /// missing or infinite time stamps.
    #[test]
    fn median_step_of_long_records_is_exact() {
        let plain = |time: &[f64]| {
            let mut d: Vec<f64> = time
                .windows(2)
                .map(|w| w[1] - w[0])
                .filter(|v| *v > 0.0 && v.is_finite())
                .collect();
            let m = d.len() / 2;
            *d.select_nth_unstable_by(m, f64::total_cmp).1
        };
        let n = 400_000; // above the sampled path's threshold
        let decimal: Vec<f64> = (0..n).map(|i| i as f64 * 0.1).collect();
        let mut state = 7u64;
        let mut jittered = Vec::with_capacity(n);
        let mut t = 0.0;
        for i in 0..n {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let u = (state >> 11) as f64 / (1u64 << 53) as f64;
            t += match i % 97 {
                0 => 30.0,  // a gap
                1 => -0.05, // time going back
                2 => 0.0,   // a repeated stamp
                _ => 0.01 * (1.0 + 0.2 * u),
            };
            // Missing and infinite stamps: their steps are not counted.
            jittered.push(match i % 1013 {
                500 => f64::NAN,
                900 => f64::INFINITY,
                _ => t,
            });
        }
        let even: Vec<f64> = (0..n).map(|i| (i / 2) as f64).collect();
        // Two step lengths, 9 of 20 the shorter: the median is the longer,
        // near the bracket's upper end.
        let two: Vec<f64> = (0..n)
            .scan(0.0, |t, i| {
                *t += if i % 20 < 9 { 1.0 } else { 2.0 };
                Some(*t)
            })
            .collect();
        for time in [&decimal, &jittered, &even, &two] {
            assert_eq!(median_step(time).to_bits(), plain(time).to_bits());
        }
    }

    #[test]
    fn splits_at_gaps_lines_and_unusable_rows() {
        let mut t: Vec<f64> = (0..100).map(|i| i as f64 * 0.1).collect();
        for v in t.iter_mut().skip(60) {
            *v += 5.0; // a 5 s gap before row 60
        }
        let line: Vec<f64> = (0..100).map(|i| if i < 30 { 1.0 } else { 2.0 }).collect();
        let mut usable = vec![true; 100];
        usable[45] = false;
        let (kept, short) = split_segments(&t, Some(&line), &usable, 1.5, 10);
        assert_eq!(kept, vec![0..30, 30..45, 46..60, 60..100]);
        assert!(short.is_empty());
        let (kept, short) = split_segments(&t, Some(&line), &usable, 1.5, 20);
        assert_eq!(kept, vec![0..30, 60..100]);
        assert_eq!(short, vec![30..45, 46..60]);
    }

    /// The block-wise search for breaks cuts a long record where the
    /// row-by-row rule does: unusable rows, line changes (NaN labels the
    /// same line), gaps and missing times on either side of every block
    /// boundary, with and without lines.
    #[test]
    fn breaks_are_the_row_by_row_ones_across_blocks() {
        let plain = |time: &[f64], line: Option<&[f64]>, usable: &[bool], max_gap: f64| {
            let same = |a: usize, b: usize| match line {
                Some(l) => l[a] == l[b] || (l[a].is_nan() && l[b].is_nan()),
                None => true,
            };
            let (mut kept, mut i) = (Vec::new(), 0);
            while i < time.len() {
                if !usable[i] {
                    i += 1;
                    continue;
                }
                let start = i;
                i += 1;
                while i < time.len()
                    && usable[i]
                    && same(i - 1, i)
                    && time[i] - time[i - 1] <= max_gap
                {
                    i += 1;
                }
                kept.push(start..i);
            }
            kept
        };
        let n = 4 * BREAK_BLOCK + 17;
        let mut time: Vec<f64> = (0..n).map(|i| i as f64 * 0.1).collect();
        let mut line: Vec<f64> = vec![1.0; n];
        let mut usable = vec![true; n];
        for (k, at) in [
            1,
            BREAK_BLOCK - 1,
            BREAK_BLOCK,
            BREAK_BLOCK + 1,
            2 * BREAK_BLOCK,
            3 * BREAK_BLOCK + 1,
            n - 1,
        ]
        .into_iter()
        .enumerate()
        {
            match k % 4 {
                0 => usable[at] = false,
                1 => line[at..].iter_mut().for_each(|l| *l += 1.0),
                2 => time[at..].iter_mut().for_each(|t| *t += 3.0),
                _ => time[at] = f64::NAN,
            }
        }
        line[2 * BREAK_BLOCK + 5..2 * BREAK_BLOCK + 9].fill(f64::NAN);
        for l in [None, Some(&line[..])] {
            let (kept, short) = split_at_steps(&time, l, &usable, 0.15, 1);
            assert!(short.is_empty());
            assert_eq!(kept, plain(&time, l, &usable, 0.15));
            assert!(kept.len() >= 7, "{kept:?}");
        }
    }
}
