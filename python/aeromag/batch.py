"""Many flights in parallel: :func:`batch` runs one function per flight in
a pool of processes (each process has its own GIL and its own share of the
cores), results in the order of the inputs.

Scaling out to many machines is Dask's job: ``examples/dask_archive.py``
runs the same per-flight function on a ``dask.distributed.LocalCluster``;
pointing the ``Client`` at a real cluster's scheduler runs it there.
"""

from __future__ import annotations

import multiprocessing
import os
from concurrent.futures import ProcessPoolExecutor
from typing import Any, Callable, Iterable, List, Optional, TypeVar

T = TypeVar("T")
R = TypeVar("R")


def batch(
    func: Callable[[T], R],
    items: Iterable[T],
    processes: Optional[int] = None,
    errors: str = "raise",
    progress: Any = None,
) -> List[Any]:
    """``[func(item) for item in items]``, computed in ``processes`` worker
    processes (default: the number of cores).

    ``func`` must be importable by the workers (defined in a module or a
    script's top level, not a lambda). Workers are started with the
    ``spawn`` method, so it is safe from programs that use threads.
    ``errors="raise"`` re-raises the first exception (in input order) after
    every item is done; ``errors="return"`` puts the exception object in
    the item's place. ``progress``: a callable ``(stage, done, total)`` or
    a tqdm-like bar, told as items complete.
    """
    if errors not in ("raise", "return"):
        raise ValueError("errors must be 'raise' or 'return'")
    if processes is not None and (isinstance(processes, bool) or not isinstance(processes, int) or processes < 1):
        # -3 ran with one process without a word.
        raise ValueError(f"processes must be a whole number of at least 1, got {processes!r}")
    items = list(items)
    n = processes or os.cpu_count() or 1
    from .tolles_lawson import progress_callback

    report = progress_callback(progress)
    results: List[Any] = [None] * len(items)
    failed: List[bool] = [False] * len(items)
    ctx = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=max(1, min(n, len(items) or 1)), mp_context=ctx) as pool:
        futures = {pool.submit(func, item): k for k, item in enumerate(items)}
        done = 0
        from concurrent.futures import as_completed

        for fut in as_completed(futures):
            k = futures[fut]
            try:
                results[k] = fut.result()
            except Exception as e:  # noqa: BLE001 - kept per item
                results[k] = e
                failed[k] = True
            done += 1
            if report is not None:
                report("flights", done, len(items))
    if errors == "raise":
        for k, bad in enumerate(failed):
            if bad:
                raise results[k]
    return results
