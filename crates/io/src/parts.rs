//! Passes over a long column in contiguous parts on the cores.
//!
//! A pass that reads a flight-long column once (a NaN count, a maximum) is
//! bound by memory, which two cores read faster than one: a column of
//! 10⁷ values is split into one part per core and each part's result is
//! combined by the caller (a sum, a maximum: the same value as one pass).
//! Short columns are passed over on the calling thread.

/// Columns shorter than two of these are passed over in one part.
const PART: usize = 1 << 20;

/// `f` of contiguous parts of `v` in order, one part per core (up to
/// `aeromag_core::parallel::threads`), each at least [`PART`] long; one part,
/// on the calling thread, for a short column.
pub(crate) fn on_parts<T: Send>(v: &[f64], f: impl Fn(&[f64]) -> T + Sync) -> Vec<T> {
    let parts = aeromag_core::parallel::threads().min(v.len() / PART).max(1);
    if parts == 1 {
        return vec![f(v)];
    }
    let chunks: Vec<&[f64]> = v.chunks(v.len().div_ceil(parts)).collect();
    aeromag_core::parallel::parallel_map(chunks.len(), parts, |i| f(chunks[i]))
}

/// `[f(&jobs[0]), f(&jobs[1]), …]` worked out on the cores (up to
/// `aeromag_core::parallel::threads` threads, the jobs dealt out in turn), in
/// the jobs' order: for a few independent passes of unequal length.
pub(crate) fn each_on_cores<J: Sync, T: Send>(jobs: &[J], f: impl Fn(&J) -> T + Sync) -> Vec<T> {
    let threads = aeromag_core::parallel::threads().min(jobs.len()).max(1);
    if threads == 1 {
        return jobs.iter().map(f).collect();
    }
    let f = &f;
    let deal = move |t: usize| -> Vec<T> { jobs.iter().skip(t).step_by(threads).map(f).collect() };
    // Thread 0's jobs on the calling thread.
    let dealt: Vec<Vec<T>> = std::thread::scope(|scope| {
        let handles: Vec<_> = (1..threads).map(|t| scope.spawn(move || deal(t))).collect();
        let mut dealt = vec![deal(0)];
        for h in handles {
            dealt.push(h.join().unwrap_or_else(|p| std::panic::resume_unwind(p)));
        }
        dealt
    });
    // Job i is the (i / threads)-th of thread i % threads.
    let mut dealt: Vec<std::vec::IntoIter<T>> = dealt.into_iter().map(Vec::into_iter).collect();
    (0..jobs.len())
        .map(|i| dealt[i % threads].next().expect("one result per job"))
        .collect()
}

/// The NaN values of `v`.
pub fn nan_count(v: &[f64]) -> usize {
    on_parts(v, |p| p.iter().filter(|x| x.is_nan()).count())
        .into_iter()
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Jobs dealt out to the cores come back in their order, each once,
    /// for any number of jobs.
    #[test]
    fn jobs_on_the_cores_keep_their_order() {
        for n in [0, 1, 2, 3, 7, 13] {
            let jobs: Vec<usize> = (0..n).collect();
            let got = each_on_cores(&jobs, |&j| (j, j * j));
            let want: Vec<(usize, usize)> = (0..n).map(|j| (j, j * j)).collect();
            assert_eq!(got, want, "{n} jobs");
        }
    }

    /// A long column's parts cover it once, in order, whatever its length
    /// against the parts (the NaN count is the one pass's).
    #[test]
    fn parts_cover_a_long_column_once_in_order() {
        for n in [0, 5, 2 * PART - 1, 2 * PART, 3 * PART + 7] {
            let v: Vec<f64> = (0..n)
                .map(|k| {
                    if k % 1000 == 999 || k + 1 == n {
                        f64::NAN
                    } else {
                        k as f64
                    }
                })
                .collect();
            let parts = on_parts(&v, |p| p.to_vec());
            let expected = aeromag_core::parallel::threads().min(n / PART).max(1);
            assert_eq!(parts.len(), expected, "{n} values");
            let bits = |x: &f64| x.to_bits();
            assert!(parts.concat().iter().map(bits).eq(v.iter().map(bits)));
            assert_eq!(nan_count(&v), v.iter().filter(|x| x.is_nan()).count());
        }
    }
}
