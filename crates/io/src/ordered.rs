//! Work on all cores, results taken in order: the pipeline of the fast
//! CSV/XYZ reader (pieces of the file read and parsed, appended in file
//! order) and of the CSV writer (chunks of rows formatted, written in
//! order).
//!
//! [`in_order`] runs `work` on a number of worker threads, each filling a
//! buffer with the next item and its number, and hands the filled buffers
//! to `take` on the calling thread in the numbers' order. The buffers go
//! round (a few per worker, reused), so memory stays bounded whatever the
//! length of the work, and no thread waits for a round of items to end:
//! a worker goes on with the next item as soon as it has a free buffer.
//! The items' results do not depend on which thread made them, so the
//! outcome is the same for any number of threads.

use std::collections::BTreeMap;
use std::panic::AssertUnwindSafe;
use std::sync::{Mutex, MutexGuard, mpsc};

/// Runs `work` on `workers` threads with `per_worker` buffers each going
/// round, and `take`s the filled buffers on the calling thread in the
/// order of their numbers.
///
/// - `work(buffer)` fills `buffer` with the next item and returns its
///   number (0, 1, 2, … in the order the items are taken up: an item is
///   only numbered once every lower number has been given), or `None` when
///   there is no item left (the worker then ends).
/// - `take(buffer)` uses item after item in order; `Ok(false)` or an error
///   ends the taking (items in flight are dropped, the workers end once
///   the free buffers have run out).
///
/// Returns `take`'s error if it failed. A panic of `work` stops the
/// taking and is resumed on the calling thread once every worker has
/// ended.
pub(crate) fn in_order<B, E>(
    workers: usize,
    per_worker: usize,
    work: impl Fn(&mut B) -> Option<usize> + Sync,
    mut take: impl FnMut(&mut B) -> Result<bool, E>,
) -> Result<(), E>
where
    B: Send + Default,
{
    let workers = workers.max(1);
    let (free_tx, free_rx) = mpsc::channel::<B>();
    for _ in 0..workers * per_worker.max(1) {
        free_tx.send(B::default()).expect("the receiver is here");
    }
    let free_rx = Mutex::new(free_rx);
    // `None`: a worker panicked. The taking stops, so that nobody waits for
    // its item, and its panic is the caller's once every thread has ended.
    let (done_tx, done_rx) = mpsc::channel::<Option<(usize, B)>>();
    let panicked: Mutex<Option<Box<dyn std::any::Any + Send>>> = Mutex::new(None);
    let outcome = std::thread::scope(|scope| {
        for _ in 0..workers {
            let (work, free_rx, done_tx, panicked) = (&work, &free_rx, done_tx.clone(), &panicked);
            scope.spawn(move || {
                loop {
                    let Ok(mut buffer) = lock(free_rx).recv() else {
                        return;
                    };
                    let number =
                        match std::panic::catch_unwind(AssertUnwindSafe(|| work(&mut buffer))) {
                            Ok(Some(number)) => number,
                            Ok(None) => return,
                            Err(panic) => {
                                *lock(panicked) = Some(panic);
                                let _ = done_tx.send(None);
                                return;
                            }
                        };
                    if done_tx.send(Some((number, buffer))).is_err() {
                        return;
                    }
                }
            });
        }
        drop(done_tx);
        let mut waiting: BTreeMap<usize, B> = BTreeMap::new();
        let mut next = 0;
        let outcome = (|| {
            // Ends when every worker has ended, or one has panicked.
            while let Ok(Some((number, buffer))) = done_rx.recv() {
                waiting.insert(number, buffer);
                while let Some(mut buffer) = waiting.remove(&next) {
                    next += 1;
                    if !take(&mut buffer)? {
                        return Ok(());
                    }
                    // The workers may have ended: the buffer is then not needed.
                    let _ = free_tx.send(buffer);
                }
            }
            Ok(())
        })();
        // No buffer for another item: the workers end.
        drop(free_tx);
        outcome
    });
    if let Some(panic) = lock(&panicked).take() {
        std::panic::resume_unwind(panic);
    }
    outcome
}

/// A lock whose holder may have panicked (the panic reaches the caller at
/// the scope's end).
pub(crate) fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// Items are taken in order, each once, for any number of workers and
    /// buffers, and the taking can stop early (the workers then end).
    #[test]
    fn items_are_taken_in_order_and_taking_can_stop() {
        for workers in 1..5 {
            for per_worker in 1..4 {
                for stop_after in [0, 1, 7, 1000, usize::MAX] {
                    let n = 500;
                    let next = AtomicUsize::new(0);
                    let mut taken = Vec::new();
                    let r: Result<(), ()> = in_order(
                        workers,
                        per_worker,
                        |b: &mut Vec<usize>| {
                            let k = next.fetch_add(1, Ordering::Relaxed);
                            (k < n).then(|| {
                                // Uneven work, so items finish out of order.
                                let spin = (k * 7919) % 13 * 200;
                                b.clear();
                                b.extend((0..spin).map(|i| i ^ k));
                                b.push(k);
                                k
                            })
                        },
                        |b| {
                            taken.push(*b.last().unwrap());
                            Ok(taken.len() < stop_after)
                        },
                    );
                    assert!(r.is_ok());
                    let want: Vec<usize> = (0..n.min(stop_after.max(1))).collect();
                    assert_eq!(taken, want, "{workers} workers, {per_worker} buffers");
                }
            }
        }
    }

    /// An error of `take` is returned, and the work stops.
    #[test]
    fn an_error_of_take_ends_the_work() {
        let next = AtomicUsize::new(0);
        let r = in_order(
            2,
            2,
            |_: &mut ()| Some(next.fetch_add(1, Ordering::Relaxed)),
            |_| if true { Err("failed") } else { Ok(true) },
        );
        assert_eq!(r, Err("failed"));
        // The workers ended after at most the buffers' worth of items.
        assert!(next.load(Ordering::Relaxed) <= 4);
    }

    /// A worker that panics ends the work (nobody waits for its item) and
    /// its panic reaches the caller, for any number of workers.
    #[test]
    fn a_panicking_worker_ends_the_work_with_its_panic() {
        for workers in 1..4 {
            let next = AtomicUsize::new(0);
            let outcome = std::panic::catch_unwind(AssertUnwindSafe(|| {
                in_order(
                    workers,
                    2,
                    |_: &mut ()| {
                        let k = next.fetch_add(1, Ordering::Relaxed);
                        assert!(k != 5, "item 5");
                        Some(k)
                    },
                    |_| Ok::<_, ()>(true),
                )
            }));
            let panic = outcome.expect_err("the worker's panic");
            let message = panic
                .downcast_ref::<&str>()
                .copied()
                .or(panic.downcast_ref::<String>().map(String::as_str));
            assert_eq!(message, Some("item 5"), "{workers} workers");
        }
    }
}
