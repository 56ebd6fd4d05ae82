"""Writes the MATLAB MAT-files of aeromag-io's tests
(crates/io/tests/data/mat5/*.mat): scipy.io.savemat for what it writes,
and by hand (struct.pack) what MATLAB writes and SciPy does not: a
big-endian file, and a double array stored as uint8 and in the small
element form, as MATLAB stores small integers.

- top.mat: a workspace of top-level variables, uncompressed: vectors
  tt (1 x n), mag_1_uc (n x 1), lat, flag (uint8), ok (logical); a scalar
  fs, text note, a matrix A (n x 3), a struct extra.
- magnav.mat: MagNav.jl's layout, compressed: struct traj (tt, lat, lon,
  mag_1_uc, flux_a_x, a 3 x 3 x n Cnb, text fileName) and struct ins_data
  (tt, lat, lon, roll) whose fields are ins_tt, ins_lat, ...
- one_struct.mat: one struct TL_data of vectors of 1000 and 960 values,
  the scalar fs and an 18 x 1 vector (MagNav's test_data_TL.mat's shape).
- two_structs.mat: structs a and b (neither is traj): refused.
- map.mat: MagNav's map layout (map_data: map 4 x 5, xx, yy, alt): refused.
- big_endian.mat: by hand, 'MI' byte order: tt (double) and mag (double
  class stored as miUINT16), n = 6.
- small_ints.mat: by hand, little-endian: line (double class stored as
  miUINT8 in the small element form, 1 x 3), mag (double), n = 3.

- top73.mat, magnav73.mat: the workspaces of top.mat and magnav.mat as
  MATLAB v7.3 files (HDF5), written by hdf5storage, which writes MATLAB's
  v7.3 layout (without the struct `extra` and the logical `ok` of top.mat).

The values are exact in binary or computed as the tests compute them
(45 + k * 1e-4), so the tests compare bits.

    pip install scipy numpy hdf5storage && python tools/reference/mat5_flights.py OUT_DIR
"""

import struct
import sys

import hdf5storage
import numpy as np
import scipy.io

out = sys.argv[1] if len(sys.argv) > 1 else "."
n = 50
k = np.arange(n, dtype=float)

top = {
    "tt": 0.1 * k,
    "mag_1_uc": (50_000.0 + 0.125 * k).reshape(n, 1),
    "lat": 45.0 + k * 1e-4,
    "flag": (np.arange(n) % 3).astype(np.uint8),
    "ok": np.arange(n) % 2 == 0,
    "fs": 10.0,
    "note": "survey 2026",
    "A": np.ones((n, 3)),
    "extra": {"x": np.arange(4.0)},
}
scipy.io.savemat(f"{out}/top.mat", top, do_compression=False)

magnav = {
    "ins_data": {
        "tt": 0.1 * k,
        "lat": 45.0 + k * 1e-4,
        "lon": -75.0 - k * 1e-4,
        "roll": 0.5 * np.ones(n),
    },
    "traj": {
        "tt": 0.1 * k,
        "lat": 45.0 + k * 1e-4,
        "lon": -75.0 - k * 1e-4,
        "mag_1_uc": 50_000.0 + 0.125 * k,
        "flux_a_x": 30_000.0 - 0.25 * k,
        "Cnb": np.tile(np.eye(3)[:, :, None], (1, 1, n)),
        "fileName": "Flt1003",
    },
}
scipy.io.savemat(f"{out}/magnav.mat", magnav, do_compression=True)
v73 = {name: v for name, v in top.items() if name not in ("extra", "ok")}
hdf5storage.savemat(f"{out}/top73.mat", v73, format="7.3", matlab_compatible=True)
hdf5storage.savemat(f"{out}/magnav73.mat", magnav, format="7.3", matlab_compatible=True)

scipy.io.savemat(
    f"{out}/one_struct.mat",
    {
        "TL_data": {
            "fs": 10.0,
            "mag_1_uc": 50_000.0 + 0.125 * np.arange(1000.0),
            "flux_a_x": 30_000.0 - 0.25 * np.arange(1000.0),
            "mag_1_uc_f_t": np.zeros(960),
            "TL_a_1": np.ones((18, 1)),
        }
    },
)

scipy.io.savemat(
    f"{out}/two_structs.mat",
    {"a": {"x": np.arange(5.0)}, "b": {"y": np.arange(5.0)}},
)

scipy.io.savemat(
    f"{out}/map.mat",
    {
        "map_data": {
            "map": np.arange(20.0).reshape(4, 5),
            "xx": np.linspace(-95.0, -94.0, 5),
            "yy": np.linspace(38.0, 39.0, 4),
            "alt": 300.0,
        }
    },
)


def header(order):
    text = b"MATLAB 5.0 MAT-file, written by aeromag's tools/reference/mat5_flights.py"
    return text.ljust(116) + b"\0" * 8 + struct.pack(order + "H", 0x0100) + (
        b"IM" if order == "<" else b"MI"
    )


def element(order, kind, data):
    """A tag and its data, padded to 8 bytes; the small form for <= 4 bytes."""
    if len(data) <= 4:
        return small(order, kind, data)
    pad = (-len(data)) % 8
    return struct.pack(order + "II", kind, len(data)) + data + b"\0" * pad


def small(order, kind, data):
    # The first 4 bytes, read as one uint32 in the file's order, hold the
    # byte count in the upper 16 bits and the type in the lower 16.
    return struct.pack(order + "I", (len(data) << 16) | kind) + data.ljust(4, b"\0")


def matrix(order, name, dims, stored_type, fmt, values):
    flags = struct.pack(order + "II", 6, 0)  # mxDOUBLE_CLASS
    body = element(order, 6, flags)  # miUINT32
    body += element(order, 5, struct.pack(order + "%di" % len(dims), *dims))  # miINT32
    body += element(order, 1, name.encode())  # miINT8
    body += element(order, stored_type, struct.pack(order + fmt * len(values), *values))
    return element(order, 14, body)  # miMATRIX


with open(f"{out}/big_endian.mat", "wb") as f:
    f.write(header(">"))
    f.write(matrix(">", "tt", [1, 6], 9, "d", [0.5 * i for i in range(6)]))
    f.write(matrix(">", "mag", [6, 1], 4, "H", [50_000 + i for i in range(6)]))

with open(f"{out}/small_ints.mat", "wb") as f:
    f.write(header("<"))
    f.write(matrix("<", "line", [1, 3], 2, "B", [7, 7, 8]))
    f.write(matrix("<", "mag", [1, 3], 9, "d", [50_000.5, 50_001.5, 50_002.5]))
