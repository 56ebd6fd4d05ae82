#!/usr/bin/env python3
"""An HDF5 copy of a CSV file written by aeromag: one 1-D float64 dataset
per column at the root, under the column's own name, chunked with gzip +
shuffle (h5py's defaults), NaN for empty cells.

The copy holds the same numbers as the CSV, so every command must give the
same results on either; the tests use it to check that the commands which
read only the fields they need (fit, report) ask for all of them
(crates/cli/tests/hdf5_flight.rs). Requires numpy and h5py.

    python3 tools/reference/csv_h5.py IN.csv OUT.h5
"""

import argparse

import h5py

from sgl_flight import read_csv


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("csv")
    ap.add_argument("h5")
    a = ap.parse_args()
    names, data = read_csv(a.csv)
    with h5py.File(a.h5, "w") as h:
        for k, n in enumerate(names):
            h.create_dataset(n, data=data[:, k], chunks=True, compression="gzip", shuffle=True)


if __name__ == "__main__":
    main()
