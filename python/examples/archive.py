"""A whole archive of flights, processed in parallel with aeromag.batch.

Each flight file is calibrated on its calibration box and compensated on
its survey lines by one function; ``aeromag.batch`` runs it in a pool of
processes (one per core) and returns the results in order. The Dask
version of the same loop is ``dask_archive.py``.

    python examples/archive.py [ARCHIVE_DIR]

Without ARCHIVE_DIR, an archive of four simulated flights is written to a
temporary folder first.
"""

import glob
import os
import sys
import tempfile

import aeromag


def process_flight(path):
    """Calibrate on the flight's box, compensate it; the figures. (For a
    whole SGL flight: ``lines="1002.02"`` for the box, the survey lines for
    the compensation.)"""
    flight = aeromag.read_flight(path)
    tl = aeromag.TollesLawson(eddy_lag="none").fit(flight)
    comp = tl.model_.apply(flight)
    fig = aeromag.score(comp)
    return {
        "flight": os.path.basename(path),
        "rows": len(flight),
        "residual_nt": tl.fit_stats_["residual_rms_nt"],
        "ir": fig["ir"],
    }


def simulated_archive(folder, n=4):
    paths = []
    for seed in range(1, n + 1):
        path = os.path.join(folder, f"flight_{seed}.csv")
        aeromag.simulate("calibration", seed=seed).to_csv(path)
        paths.append(path)
    return paths


def report(paths):
    for r in aeromag.batch(process_flight, paths, processes=2):
        ir = "n/a" if r["ir"] is None else f"{r['ir']:.1f}"
        print(f"{r['flight']}: {r['rows']} rows, fit residual {r['residual_nt']:.4f} nT, IR {ir}")


def main():
    if len(sys.argv) > 1:
        report(sorted(glob.glob(os.path.join(sys.argv[1], "*.csv")) + glob.glob(os.path.join(sys.argv[1], "*.h5"))))
        return
    # A simulated archive in a temporary folder, removed afterwards.
    with tempfile.TemporaryDirectory(prefix="aeromag-archive-") as folder:
        report(simulated_archive(folder))


if __name__ == "__main__":
    main()
