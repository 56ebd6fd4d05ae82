//! Streaming Tolles-Lawson design rows over a run of samples, in chunks, so
//! that a 10⁷-sample flight never holds its `N × n` design matrix.
//!
//! Row `i` is the design row of the vector field and its derivative under
//! the design's convention, exactly as [`Design::columns`]
//! builds it over the same run: the derivatives of each chunk's rows are
//! those of the whole run ([`crate::tolles_lawson::terms::derivative_rows_into`]),
//! so interior samples get the central difference and the run's two ends
//! the one-sided one. The lagged derivatives of the `l9` group run through the whole
//! run sample by sample, as over one segment.

use crate::tolles_lawson::Design;
use crate::tolles_lawson::design::Lags;
use crate::tolles_lawson::fit_ls::Segment;
use crate::tolles_lawson::terms::derivative_rows_into;
use std::ops::Range;

/// Samples per chunk.
const CHUNK: usize = 4096;

/// Call `f(i, row)` for every sample `i` of `run` (indices into the
/// segment `seg`, in increasing order); derivatives are taken over `run`
/// alone, and the lags start at its first sample.
pub fn for_each_design_row(
    spec: &Design,
    seg: &Segment,
    run: Range<usize>,
    f: impl FnMut(usize, &[f64]),
) {
    for_every_nth_design_row(spec, seg, run, 1, f)
}

/// [`for_each_design_row`] for the samples `run.start + k·every` alone:
/// the lag filters still step through every sample (the same rows, bit
/// for bit), the other samples' rows are not formed.
pub fn for_every_nth_design_row(
    spec: &Design,
    seg: &Segment,
    run: Range<usize>,
    every: usize,
    mut f: impl FnMut(usize, &[f64]),
) {
    let every = every.max(1);
    let (time, flux) = (seg.time, seg.flux);
    let ncol = spec.terms.n_columns();
    let mut row = vec![0.0; ncol];
    let mut lags = Lags::new(&spec.terms);
    let channels: Vec<Option<&[f64]>> = (0..spec.terms.extras().len())
        .map(|k| seg.channels.get(k))
        .collect();
    let mut extra = vec![[f64::NAN; 2]; channels.len()];
    let eddy = spec.terms.has_eddy();
    let (s, e) = (run.start, run.end);
    let mut a = s;
    while a < e {
        let b = (a + CHUNK).min(e);
        let db: [Vec<f64>; 3] = [0, 1, 2].map(|c| {
            let mut d = Vec::new();
            if eddy {
                derivative_rows_into(
                    &flux[c][s..e],
                    &time[s..e],
                    spec.convention,
                    spec.differencing,
                    a - s..b - s,
                    &mut d,
                );
            } else {
                d.resize(b - a, 0.0);
            }
            d
        });
        for i in a..b {
            let j = i - a;
            let d = [db[0][j], db[1][j], db[2][j]];
            for ((x, c), lag) in extra.iter_mut().zip(&channels).zip(&mut lags.extra) {
                let v = c.map_or(f64::NAN, |c| c[i]);
                *x = [v, lag.as_mut().map_or(f64::NAN, |l| l.step(time[i], v))];
            }
            let lagged = lags.eddy.step(time[i], d);
            if !(i - s).is_multiple_of(every) {
                continue;
            }
            let b = [flux[0][i], flux[1][i], flux[2][i]];
            let dir = seg.direction.map_or(b, |v| [v[0][i], v[1][i], v[2][i]]);
            spec.terms
                .row_along(dir, b, d, lagged, &extra, spec.bt_scale_nt, &mut row);
            f(i, &row);
        }
        a = b;
    }
}

/// Rows per block handed from the producing thread
/// ([`for_each_design_row_ahead`]).
const AHEAD_BLOCK: usize = 512;

/// A block of consecutive rows of one run.
struct RowBlock {
    run: usize,
    first: usize,
    rows: Vec<f64>,
}

/// [`for_each_design_row`] over the runs `runs` (a segment and a range of
/// it each), calling `f(run, i, row)` for every sample in order, with the
/// rows formed on a second thread a few blocks ahead of `f` (a sequential
/// filter consuming them overlaps with the lag filters and products that
/// form them). The same rows in the same order as one thread. `f` returns
/// `false` to stop.
pub fn for_each_design_row_ahead(
    spec: &Design,
    runs: &[(&Segment, Range<usize>)],
    mut f: impl FnMut(usize, usize, &[f64]) -> bool,
) {
    let ncol = spec.terms.n_columns();
    if aeromag_core::parallel::threads() < 2 || ncol == 0 {
        for (r, (seg, range)) in runs.iter().enumerate() {
            let mut go = true;
            for_each_design_row(spec, seg, range.clone(), |i, row| {
                go = go && f(r, i, row);
            });
            if !go {
                return;
            }
        }
        return;
    }
    let (full_tx, full_rx) = std::sync::mpsc::sync_channel::<RowBlock>(4);
    let (empty_tx, empty_rx) = std::sync::mpsc::channel::<Vec<f64>>();
    std::thread::scope(|scope| {
        scope.spawn(move || {
            for (r, (seg, range)) in runs.iter().enumerate() {
                let fresh = || empty_rx.try_recv().unwrap_or_default();
                let mut block = RowBlock {
                    run: r,
                    first: range.start,
                    rows: fresh(),
                };
                block.rows.clear();
                let mut stopped = false;
                for_each_design_row(spec, seg, range.clone(), |i, row| {
                    if stopped {
                        return;
                    }
                    block.rows.extend_from_slice(row);
                    if block.rows.len() == AHEAD_BLOCK * ncol {
                        let mut next = RowBlock {
                            run: r,
                            first: i + 1,
                            rows: fresh(),
                        };
                        next.rows.clear();
                        stopped = full_tx.send(std::mem::replace(&mut block, next)).is_err();
                    }
                });
                if stopped || (!block.rows.is_empty() && full_tx.send(block).is_err()) {
                    return;
                }
            }
        });
        for block in full_rx.iter() {
            for (j, row) in block.rows.chunks_exact(ncol).enumerate() {
                if !f(block.run, block.first + j, row) {
                    // Dropping the receiver stops the producer.
                    return;
                }
            }
            let _ = empty_tx.send(block.rows);
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tolles_lawson::design::Channels;
    use crate::tolles_lawson::{Convention, ExtraTerm, TermSet};

    #[test]
    fn streamed_rows_equal_the_design_columns() {
        let n = 2 * CHUNK + 1; // last chunk of one sample
        let time: Vec<f64> = (0..n)
            .map(|k| k as f64 * 0.1 + 1e-3 * (k % 3) as f64)
            .collect();
        let fx: Vec<f64> = (0..n)
            .map(|k| 20_000.0 + 300.0 * (k as f64 * 0.05).sin())
            .collect();
        let fy: Vec<f64> = (0..n)
            .map(|k| 2_000.0 + 500.0 * (k as f64 * 0.031).cos())
            .collect();
        let fz: Vec<f64> = (0..n)
            .map(|k| 48_000.0 - 100.0 * (k as f64 * 0.07).sin())
            .collect();
        // Two extra regressors, one with a lag: a switching current and a ramp.
        let strobe: Vec<f64> = (0..n).map(|k| 5.0 * ((k / 7) % 2) as f64).collect();
        let ramp: Vec<f64> = (0..n).map(|k| (k % 50) as f64 * 0.1).collect();
        let chs = [&strobe[..], &ramp[..]];
        let seg = Segment {
            time: &time,
            flux: [&fx, &fy, &fz],
            mag: &fx,
            channels: Channels::new(&chs),
            direction: None,
        };
        for conv in [Convention::Physical, Convention::MagNav] {
            let terms = TermSet::parse("p3,i6,e9,bias")
                .unwrap()
                .with_eddy_lags(&[0.2, 0.7])
                .unwrap()
                .with_extras(&[ExtraTerm::new("strobe"), ExtraTerm::lagged("ramp", 0.4)])
                .unwrap();
            let spec = Design {
                terms,
                convention: conv,
                bt_scale_nt: 50_000.0,
                ..Design::default()
            };
            for run in [0..n, 5..CHUNK + 7, 10..13, 100..101] {
                let cols = spec.columns_with(
                    &time[run.clone()],
                    [&fx[run.clone()], &fy[run.clone()], &fz[run.clone()]],
                    seg.channels.slice(run.clone()),
                );
                assert_eq!(cols.len(), 19 + 18 + 9);
                let mut count = 0;
                for_each_design_row(&spec, &seg, run.clone(), |i, row| {
                    for (c, v) in row.iter().enumerate() {
                        assert_eq!(*v, cols[c][i - run.start], "run {run:?} row {i} col {c}");
                    }
                    count += 1;
                });
                assert_eq!(count, run.len());
                // Every n-th row alone: the same rows (the lags stepped
                // through the samples between), at the same samples.
                for every in [3, 1000] {
                    let mut kept = Vec::new();
                    for_every_nth_design_row(&spec, &seg, run.clone(), every, |i, row| {
                        for (c, v) in row.iter().enumerate() {
                            let want = cols[c][i - run.start];
                            assert_eq!(
                                v.to_bits(),
                                want.to_bits(),
                                "every {every} row {i} col {c}"
                            );
                        }
                        kept.push(i);
                    });
                    assert_eq!(kept, run.clone().step_by(every).collect::<Vec<_>>());
                }
            }
        }
    }

    /// The rows handed over from the second thread are those of one thread,
    /// in order, across runs of several segments and block boundaries, and
    /// stopping early stops.
    #[test]
    fn rows_ahead_equal_the_rows_in_turn() {
        let n = 3 * AHEAD_BLOCK + 17;
        let time: Vec<f64> = (0..n).map(|k| k as f64 * 0.1).collect();
        let f: [Vec<f64>; 3] = [0.05, 0.031, 0.07].map(|w| {
            (0..n)
                .map(|k| 20_000.0 + 300.0 * (k as f64 * w).sin())
                .collect()
        });
        let seg = Segment {
            time: &time,
            flux: [&f[0], &f[1], &f[2]],
            mag: &f[0],
            channels: Default::default(),
            direction: None,
        };
        let spec = Design {
            terms: TermSet::parse("p3,i6,e9")
                .unwrap()
                .with_eddy_lags(&[0.3])
                .unwrap(),
            ..Design::default()
        };
        let runs = [
            (&seg, 0..AHEAD_BLOCK),
            (&seg, AHEAD_BLOCK..AHEAD_BLOCK + 1),
            (&seg, 700..n),
            (&seg, 3..40),
        ];
        let mut want = Vec::new();
        for (r, (s, range)) in runs.iter().enumerate() {
            for_each_design_row(&spec, s, range.clone(), |i, row| {
                want.push((r, i, row.to_vec()))
            });
        }
        let mut got = Vec::new();
        for_each_design_row_ahead(&spec, &runs, |r, i, row| {
            got.push((r, i, row.to_vec()));
            true
        });
        assert_eq!(got, want);
        let mut seen = 0;
        for_each_design_row_ahead(&spec, &runs, |_, _, _| {
            seen += 1;
            seen < 1000
        });
        assert_eq!(seen, 1000);
    }
}
