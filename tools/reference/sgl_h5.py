#!/usr/bin/env python3
"""Deterministic HDF5 test files in the MagNav / SGL flight layout, with the
expected values a Rust reader must reproduce bit for bit.

Layout read by aeromag: one 1-D dataset per field (tt, lat, lon, line,
flight, mag_1_uc, flux_a_x, ins_lat, ...), either at the file's root or inside
a single group (/data, /flight), as written by h5py (MagNav.jl's get_XYZ20 and
the SGL flight files). Some datasets carry a `units` attribute.

Small files (N = 250 rows, chunk 80, which does not divide N):

  root_contig.h5        fields at /, contiguous storage
  root_gzip.h5          fields at /, chunked, gzip level 4 + shuffle
  root_chunked.h5       fields at /, chunked, no filter
  group_contig.h5       fields in /data, contiguous
  group_gzip.h5         fields in /data, chunked, gzip + shuffle
  group_chunked.h5      fields in /flight, chunked, no filter
  root_gzip_latest.h5   as root_gzip.h5 but libver="latest" (superblock v3,
                        compact/dense links, v2 chunk indexes)
  twod.h5               a 2-D dataset `xyz` (N x 3) beside two 1-D ones:
                        not this layout; a reader should say so

Every small file has the same fields (see FIELDS): float64, float32, int32,
int64, uint8 and int16 datasets, plus `empty`, a float64 dataset of length 0
(chunked files: chunked with maxshape=(None,)). `units` attributes: variable-
length UTF-8 strings (h5py's default for str) on some fields and fixed-length
bytes (np.bytes_) on others; see UNITS.

Benchmark files (unless --no-big; --rows changes the 10**6 default):

  bench_contig.h5   100 float64 fields x rows at /, contiguous
  bench_gzip.h5     the same, chunks=True (h5py's guess), gzip + shuffle
  bench.csv         the same 100 columns, header line, values written with
                    repr() (shortest round-trip form), so parsing them with a
                    correct float parser gives the stored doubles exactly

expected.json records, for every dataset of every small file and for the
benchmark fields listed in BENCH_CHECK: dtype (numpy str, e.g. "<f4"), shape,
`units`, first/last values, sum (float64, numpy pairwise order: compare with
a tolerance), and two FNV-1a 64-bit checksums given as 16 hex digits:
  fnv_raw: over the dataset's values as little-endian bytes of its own dtype
  fnv_f64: over the values converted to float64, little-endian bytes
(FNV-1a 64: h = 0xcbf29ce484222325; for each byte: h ^= b; h *= 0x100000001b3
mod 2**64.) The fnv values are exact: a reader that returns Vec<f64> must
reproduce fnv_f64.

Requires numpy and h5py. Run:
    python3 tools/reference/sgl_h5.py OUT_DIR [--rows 1000000] [--no-big]
Same arguments, same bytes in every value (the HDF5 files' own bytes may
differ between h5py/libhdf5 versions; the values do not).
"""
import argparse
import json
import os

import h5py
import numpy as np

SEED = 20240611
N_SMALL = 250
CHUNK_SMALL = 80  # does not divide N_SMALL: the last chunk is partial

# (name, dtype) of the small files' fields
FIELDS = [
    ("tt", "<f8"),
    ("lat", "<f8"),
    ("lon", "<f8"),
    ("line", "<i4"),
    ("flight", "<i8"),
    ("mag_1_uc", "<f8"),
    ("mag_2_uc", "<f4"),
    ("flux_a_x", "<f4"),
    ("ins_lat", "<f8"),
    ("ins_vn", "<f4"),
    ("cur_strb", "<i2"),
    ("flag_u8", "|u1"),
    ("diurnal", "<f8"),
]
# field -> (units, kind): kind "vlen" = h5py str (variable-length UTF-8),
# "fixed" = np.bytes_ (fixed-length ASCII, null-padded)
UNITS = {
    "tt": ("s", "vlen"),
    "lat": ("deg", "vlen"),
    "ins_lat": ("rad", "vlen"),
    "mag_1_uc": ("nT", "fixed"),
    "flux_a_x": ("nT", "fixed"),
    "diurnal": ("nT", "vlen"),
}
BENCH_FIELDS = 100
# the fields the benchmark reads (spread over the file); all are checked
BENCH_CHECK = ["tt", "mag_1_uc", "flux_b_z", "ins_lat"]


def fnv1a64(data: bytes) -> str:
    """FNV-1a 64-bit of a byte string, as 16 lower-case hex digits."""
    h = 0xCBF29CE484222325
    prime = 0x100000001B3
    mask = 0xFFFFFFFFFFFFFFFF
    for b in data:
        h ^= b
        h = (h * prime) & mask
    return f"{h:016x}"


def py_scalar(v):
    """A numpy scalar as a JSON-exact Python value (float repr round-trips)."""
    if isinstance(v, np.floating):
        return float(v)
    return int(v)


def describe(arr: np.ndarray, units):
    """Expected-values record of one dataset."""
    le = arr.astype(arr.dtype.newbyteorder("<"), copy=False)
    rec = {
        "dtype": le.dtype.str,
        "shape": list(arr.shape),
        "units": units,
        "len": int(arr.size),
        "fnv_raw": fnv1a64(le.tobytes()),
        "fnv_f64": fnv1a64(arr.astype("<f8").tobytes()),
        "sum": float(arr.astype("<f8").sum()) if arr.size else 0.0,
    }
    if arr.size:
        rec["first"] = py_scalar(arr.flat[0])
        rec["last"] = py_scalar(arr.flat[-1])
    return rec


def small_fields(rng: np.random.Generator, n: int):
    """Deterministic values for FIELDS, shaped like a survey flight."""
    t = 1.0e5 + 0.1 * np.arange(n)
    lat = 45.0 + np.cumsum(rng.normal(0.0, 1e-5, n))
    lon = -75.5 + np.cumsum(rng.normal(0.0, 1e-5, n))
    vals = {
        "tt": t,
        "lat": lat,
        "lon": lon,
        "line": np.repeat(np.arange(1001, 1001 + (n + 199) // 200), 200)[:n],
        "flight": np.full(n, 1007, dtype=np.int64) + (np.arange(n) >= n // 2),
        "mag_1_uc": 52000.0 + np.cumsum(rng.normal(0.0, 0.5, n)),
        "mag_2_uc": 52100.0 + np.cumsum(rng.normal(0.0, 0.5, n)),
        "flux_a_x": 10000.0 * rng.standard_normal(n),
        "ins_lat": np.deg2rad(lat),
        "ins_vn": rng.normal(0.0, 60.0, n),
        "cur_strb": rng.integers(-32768, 32767, n, endpoint=True),
        "flag_u8": rng.integers(0, 255, n, endpoint=True),
        "diurnal": 5.0 * np.sin(t / 3600.0) + rng.normal(0.0, 0.01, n),
    }
    out = {}
    for name, dt in FIELDS:
        out[name] = np.asarray(vals[name]).astype(dt)
    return out


def set_units(ds, name):
    if name not in UNITS:
        return
    text, kind = UNITS[name]
    if kind == "vlen":
        ds.attrs["units"] = text  # h5py: variable-length UTF-8 string
    else:
        ds.attrs["units"] = np.bytes_(text)  # fixed-length, e.g. |S2


def write_small(path, group, storage, fields, libver="earliest"):
    """One small file. storage: contig | gzip | chunked."""
    kw = {}
    if storage == "gzip":
        kw = dict(chunks=(CHUNK_SMALL,), compression="gzip", compression_opts=4, shuffle=True)
    elif storage == "chunked":
        kw = dict(chunks=(CHUNK_SMALL,))
    with h5py.File(path, "w", libver=libver) as f:
        f.attrs["title"] = "aeromag HDF5 reader test file"
        g = f.require_group(group) if group else f
        for name, _ in FIELDS:
            ds = g.create_dataset(name, data=fields[name], **kw)
            set_units(ds, name)
        if storage == "contig":
            g.create_dataset("empty", shape=(0,), dtype="<f8")
        else:
            ekw = dict(kw, chunks=(CHUNK_SMALL,))
            g.create_dataset("empty", shape=(0,), maxshape=(None,), dtype="<f8", **ekw)
    recs = {}
    prefix = f"/{group}/" if group else "/"
    for name, _ in FIELDS:
        recs[prefix + name] = describe(fields[name], UNITS.get(name, (None,))[0])
    recs[prefix + "empty"] = describe(np.zeros(0, "<f8"), None)
    return {"group": group, "storage": storage, "libver": libver, "datasets": recs}


def write_twod(path, fields):
    with h5py.File(path, "w") as f:
        f.create_dataset("tt", data=fields["tt"])
        f.create_dataset("mag_1_uc", data=fields["mag_1_uc"])
        xyz = np.stack([fields["flux_a_x"].astype("<f8")] * 3, axis=1)
        f.create_dataset("xyz", data=xyz)
    return {
        "group": None,
        "storage": "contig",
        "libver": "earliest",
        "datasets": {
            "/tt": describe(fields["tt"], None),
            "/mag_1_uc": describe(fields["mag_1_uc"], None),
            "/xyz": describe(xyz, None),
        },
    }


def bench_names():
    base = ["tt", "lat", "lon", "alt", "baro", "ins_lat", "ins_lon", "ins_alt",
            "ins_vn", "ins_vw", "ins_vu", "ins_roll", "ins_pitch", "ins_yaw"]
    base += [f"mag_{i}_uc" for i in range(1, 6)] + [f"mag_{i}_c" for i in range(1, 6)]
    base += [f"flux_{s}_{a}" for s in "abcd" for a in ("x", "y", "z", "t")]
    base += ["cur_com_1", "cur_ac_hi", "cur_ac_lo", "cur_tank", "cur_flap",
             "cur_strb", "cur_srvo_o", "cur_srvo_m", "cur_srvo_i", "cur_heat",
             "cur_acpwr", "cur_outpwr", "cur_bat_1", "cur_bat_2", "diurnal",
             "igrf", "mag_1_dc", "mag_1_igrf", "utm_x", "utm_y", "utm_z"]
    i = 0
    while len(base) < BENCH_FIELDS:
        base.append(f"aux_{i:02d}")
        i += 1
    names = base[:BENCH_FIELDS]
    assert len(set(names)) == BENCH_FIELDS and all(c in names for c in BENCH_CHECK)
    return names


def bench_column(rng, name, rows):
    """Instrument-like values: smooth random walks at a fixed resolution
    (compress like real data under gzip+shuffle); time is a 10 Hz clock."""
    if name == "tt":
        return 1.0e5 + 0.1 * np.arange(rows)
    if name == "ins_lat":
        return np.deg2rad(45.0 + np.cumsum(rng.normal(0.0, 1e-6, rows)))
    walk = np.cumsum(rng.normal(0.0, 0.3, rows)) + rng.uniform(-5e4, 5e4)
    return np.round(walk, 3)


def write_bench(out, rows, expected):
    rng = np.random.default_rng(SEED + 1)
    names = bench_names()
    cols = [bench_column(rng, n, rows) for n in names]
    for fname, kw in [("bench_contig.h5", {}),
                      ("bench_gzip.h5", dict(chunks=True, compression="gzip", shuffle=True))]:
        with h5py.File(os.path.join(out, fname), "w") as f:
            for n, c in zip(names, cols):
                f.create_dataset(n, data=c, **kw)
                if n in UNITS:
                    set_units(f[n], n)
    with open(os.path.join(out, "bench.csv"), "w") as fh:
        fh.write(",".join(names) + "\n")
        step = 20000
        for a in range(0, rows, step):
            block = np.stack([c[a:a + step] for c in cols], axis=1).tolist()
            fh.write("\n".join(",".join(map(repr, r)) for r in block))
            fh.write("\n")
    recs = {}
    for n in BENCH_CHECK:
        c = cols[names.index(n)]
        r = describe(c, UNITS.get(n, (None,))[0])
        r["csv_column"] = names.index(n)
        recs["/" + n] = r
    expected["bench"] = {"rows": rows, "fields": names, "files": ["bench_contig.h5", "bench_gzip.h5", "bench.csv"],
                         "datasets": recs}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out_dir")
    ap.add_argument("--rows", type=int, default=1_000_000, help="rows of the benchmark files")
    ap.add_argument("--no-big", action="store_true", help="skip the benchmark files")
    args = ap.parse_args()
    os.makedirs(args.out_dir, exist_ok=True)
    fields = small_fields(np.random.default_rng(SEED), N_SMALL)
    files = {}
    for fname, group, storage, libver in [
        ("root_contig.h5", None, "contig", "earliest"),
        ("root_gzip.h5", None, "gzip", "earliest"),
        ("root_chunked.h5", None, "chunked", "earliest"),
        ("group_contig.h5", "data", "contig", "earliest"),
        ("group_gzip.h5", "data", "gzip", "earliest"),
        ("group_chunked.h5", "flight", "chunked", "earliest"),
        ("root_gzip_latest.h5", None, "gzip", "latest"),
    ]:
        files[fname] = write_small(os.path.join(args.out_dir, fname), group, storage, fields, libver)
    files["twod.h5"] = write_twod(os.path.join(args.out_dir, "twod.h5"), fields)
    expected = {
        "generator": "tools/reference/sgl_h5.py",
        "seed": SEED,
        "fnv": "FNV-1a 64 over little-endian bytes; fnv_raw in the dataset dtype, fnv_f64 after conversion to float64",
        "files": files,
    }
    if not args.no_big:
        write_bench(args.out_dir, args.rows, expected)
    with open(os.path.join(args.out_dir, "expected.json"), "w") as fh:
        json.dump(expected, fh, indent=1, sort_keys=True)
        fh.write("\n")


if __name__ == "__main__":
    main()
