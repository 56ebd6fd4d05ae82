"""The archive of ``archive.py`` on a Dask cluster.

The same per-flight function runs on a ``dask.distributed`` cluster: here a
``LocalCluster`` of 2 worker processes; give ``Client`` the address of a
real cluster's scheduler (and put the archive where the workers can read
it) to run on many machines. aeromag releases the GIL in its long calls,
so threads of one worker also run in parallel.

    pip install "dask[distributed]"
    python examples/dask_archive.py [ARCHIVE_DIR]
"""

import glob
import os
import sys
import tempfile

from dask.distributed import Client, LocalCluster

from archive import process_flight, simulated_archive


def main():
    if len(sys.argv) > 1:
        run(sorted(glob.glob(os.path.join(sys.argv[1], "*.csv"))))
        return
    # A simulated archive in a temporary folder, removed afterwards.
    with tempfile.TemporaryDirectory(prefix="aeromag-archive-") as folder:
        run(simulated_archive(folder))


def run(paths):
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, Client(
        cluster
    ) as client:
        futures = client.map(process_flight, paths)
        for r in client.gather(futures):
            ir = "n/a" if r["ir"] is None else f"{r['ir']:.1f}"
            print(f"{r['flight']}: {r['rows']} rows, fit residual {r['residual_nt']:.4f} nT, IR {ir}")


if __name__ == "__main__":
    main()
