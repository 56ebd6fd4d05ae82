//! Index-parallel map over scoped threads (the gradiometry convergence map
//! and Monte-Carlo efficiency, the Kalman tuning grid, EM detection), parts
//! of slices and items shared out by weight (a model's interference over
//! the segments of a flight), and the number of threads the workspace's
//! parallel loops use.
//!
//! Item `i` is always computed by `f(i)` and stored at position `i`, so the
//! result does not depend on the number of threads (the chunks only decide
//! which thread computes what).

/// Threads for a parallel loop: the number the environment variable
/// [`THREADS_VAR`] (`AEROMAG_THREADS`) sets, or else the available cores,
/// at most 8. Every result of the workspace is the same bits whatever the
/// number (the command-line tests run the commands with 1, 2, 3 and 7); the
/// variable limits the cores a run takes on a shared machine. A value that
/// [`threads_setting`] refuses is ignored here (the command-line program
/// refuses it before any work).
///
/// Asked once per process: `available_parallelism` reads the cgroup's CPU
/// quota files on every call (three files opened and read), and the loops
/// ask for every block — 4 673 times in one `calibrate` of 10⁶ rows.
pub fn threads() -> usize {
    static THREADS: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    *THREADS.get_or_init(|| {
        std::env::var(THREADS_VAR)
            .ok()
            .and_then(|v| threads_setting(&v).ok())
            .unwrap_or_else(|| {
                std::thread::available_parallelism()
                    .map_or(1, |n| n.get())
                    .clamp(1, 8)
            })
    })
}

/// The environment variable that sets the number of threads ([`threads`]).
pub const THREADS_VAR: &str = "AEROMAG_THREADS";

/// Most threads [`THREADS_VAR`] may ask for.
pub const MAX_THREADS: usize = 64;

/// The number of threads that `value`, the text of [`THREADS_VAR`], asks
/// for: a whole number from 1 to [`MAX_THREADS`] (spaces around it
/// allowed).
///
/// ```
/// use aeromag_core::parallel::threads_setting;
/// assert_eq!(threads_setting(" 3 "), Ok(3));
/// assert!(threads_setting("0").is_err());
/// assert!(threads_setting("two").is_err());
/// ```
pub fn threads_setting(value: &str) -> crate::error::Result<usize> {
    match value.trim().parse::<usize>() {
        Ok(n) if (1..=MAX_THREADS).contains(&n) => Ok(n),
        _ => Err(crate::error::CoreError::InvalidArgument {
            name: THREADS_VAR,
            reason: format!("expected a whole number from 1 to {MAX_THREADS}, got '{value}'"),
        }),
    }
}

/// `[f(0), f(1), …, f(n − 1)]`, computed on up to `threads` threads (≥ 1) in
/// contiguous chunks, the first on the calling thread (one thread fewer
/// to start: with two cores, one instead of two per call).
pub fn parallel_map<T: Send>(n: usize, threads: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    let threads = threads.clamp(1, n.max(1));
    let chunk = n.div_ceil(threads).max(1);
    let f = &f;
    let run = move |start: usize| (start..(start + chunk).min(n)).map(f).collect::<Vec<T>>();
    if n <= chunk {
        return run(0);
    }
    std::thread::scope(|scope| {
        let handles: Vec<_> = (chunk..n)
            .step_by(chunk)
            .map(|start| scope.spawn(move || run(start)))
            .collect();
        let mut out = run(0);
        // A worker only panics if `f` does; pass that panic on.
        for h in handles {
            out.extend(h.join().unwrap_or_else(|p| std::panic::resume_unwind(p)));
        }
        out
    })
}

/// `f(start, part)` for contiguous parts of `out`, one per thread on up to
/// `threads` threads (≥ 1): `part` is `out[start..start + part.len()]`,
/// and every part but the last is a multiple of `align` items long (so
/// that fixed-size blocks inside the parts fall where they would in one
/// pass). One part on the calling thread when `out` is shorter than two
/// `align`s or `threads` is 1.
pub fn for_each_part_mut<T: Send>(
    out: &mut [T],
    threads: usize,
    align: usize,
    f: impl Fn(usize, &mut [T]) + Sync,
) {
    for_each_rows_mut(&mut [out], threads, align, |start, parts| {
        f(start, &mut *parts[0])
    });
}

/// [`for_each_part_mut`] over several slices of equal length at once:
/// `f(start, parts)` gets rows `start..start + len` of every slice of
/// `outs`, in order.
pub fn for_each_rows_mut<T: Send>(
    outs: &mut [&mut [T]],
    threads: usize,
    align: usize,
    f: impl Fn(usize, &mut [&mut [T]]) + Sync,
) {
    let align = align.max(1);
    let n = outs.first().map_or(0, |o| o.len());
    debug_assert!(outs.iter().all(|o| o.len() == n));
    if threads <= 1 || n < 2 * align {
        f(0, outs);
        return;
    }
    let per = n.div_ceil(threads).div_ceil(align) * align;
    let mut split: Vec<Vec<&mut [T]>> = (0..n.div_ceil(per)).map(|_| Vec::new()).collect();
    for out in outs.iter_mut() {
        for (t, part) in out.chunks_mut(per).enumerate() {
            split[t].push(part);
        }
    }
    let f = &f;
    // The first part on the calling thread, the others on threads of
    // their own.
    let mut split = split.into_iter().enumerate();
    let first = split.next();
    std::thread::scope(|scope| {
        for (t, mut parts) in split {
            scope.spawn(move || f(t * per, &mut parts));
        }
        if let Some((_, mut parts)) = first {
            f(0, &mut parts);
        }
    });
}

/// `f(item)` for every item of `items`, on up to `threads` threads (≥ 1),
/// each thread taking consecutive items of about the same total
/// `weight` (for example the rows of a segment). On the calling thread
/// when `threads` is 1 or there is one item.
pub fn for_each_weighted_mut<T: Send>(
    items: &mut [T],
    threads: usize,
    weight: impl Fn(&T) -> usize,
    f: impl Fn(&mut T) + Sync,
) {
    if threads <= 1 || items.len() < 2 {
        items.iter_mut().for_each(f);
        return;
    }
    let per = items.iter().map(&weight).sum::<usize>().div_ceil(threads);
    let f = &f;
    std::thread::scope(|scope| {
        let mut rest = items;
        while !rest.is_empty() {
            let (mut k, mut w) = (0, 0);
            while k < rest.len() && (k == 0 || w < per) {
                w += weight(&rest[k]);
                k += 1;
            }
            let (mine, tail) = std::mem::take(&mut rest).split_at_mut(k);
            rest = tail;
            if rest.is_empty() {
                // The last group on the calling thread.
                mine.iter_mut().for_each(f);
            } else {
                scope.spawn(move || mine.iter_mut().for_each(f));
            }
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_result_for_any_thread_count() {
        let f = |i: usize| (i as f64).sqrt() * 3.0;
        let one = parallel_map(1001, 1, f);
        assert_eq!(one.len(), 1001);
        for t in [2, 3, 7, 64, 5000] {
            assert_eq!(parallel_map(1001, t, f), one);
        }
        assert!(parallel_map(0, 4, f).is_empty());
        assert_eq!(parallel_map(1, 0, f), vec![0.0]);
    }

    #[test]
    fn parts_cover_every_item_once_at_aligned_starts() {
        for (n, threads, align) in [
            (1000, 3, 64),
            (10, 4, 64),
            (4096, 2, 1),
            (0, 2, 8),
            (130, 8, 16),
        ] {
            let mut out = vec![usize::MAX; n];
            for_each_part_mut(&mut out, threads, align, |start, part| {
                assert!(start % align == 0);
                for (k, v) in part.iter_mut().enumerate() {
                    *v = start + k;
                }
            });
            assert!(
                out.iter().enumerate().all(|(i, v)| *v == i),
                "{n} {threads} {align}"
            );
        }
    }

    #[test]
    fn weighted_items_are_each_done_once() {
        for (n, threads) in [(0, 2), (1, 4), (7, 2), (50, 3), (9, 64)] {
            let mut items: Vec<(usize, usize)> = (0..n).map(|i| (1 + (i * 7) % 5, 0)).collect();
            for_each_weighted_mut(&mut items, threads, |it| it.0, |it| it.1 += 10 * it.0);
            assert!(items.iter().all(|(w, v)| *v == 10 * w), "{n} {threads}");
        }
    }
}
