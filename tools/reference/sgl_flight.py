#!/usr/bin/env python3
"""A whole simulated flight in the SGL layout, as CSV and as HDF5.

Joins a simulated calibration flight and a simulated survey (both CSV files
written by `aeromag simulate`) into one flight the way SGL flights are
organised: the calibration box labelled 1002.02 ("calibration 1"), a
transit (label 0, no samples: a time gap of TRANSIT_S), then the survey
lines relabelled 1003.01, 1003.02, ... and tie lines 1003.51, ...

Writes into OUT_DIR:

  whole_flight.csv  canonical aeromag names and units (time, lat, lon, ...)
  whole_flight.h5   the SGL HDF5 layout (MagNav get_XYZ20): one 1-D dataset
                    per field at the root, SGL names (tt, mag_1_uc … mag_5_uc,
                    flux_a_x … flux_d_z, cur_*, ins_roll, ...), INS position in radians
                    (ins_lat, ins_lon) and velocity north/west/up (ins_vn,
                    ins_vw, ins_vu) instead of lat/lon/ve/vd, chunked with
                    gzip + shuffle, `units` attributes; `line` and the truth
                    columns as they are.

Both files hold the same numbers, so aeromag must give the same results on
either (crates/cli/tests/hdf5_flight.rs). Requires numpy and h5py.

    python3 tools/reference/sgl_flight.py CAL.csv SURVEY.csv OUT_DIR
"""

import argparse
import os

import h5py
import numpy as np

TRANSIT_S = 600.0
BOX_LABEL = 1002.02
SURVEY_FLIGHT = 1003.0

# canonical -> (SGL name, factor); fields whose SGL form differs in unit or
# sign are written under their SGL name only.
SGL = {
    "time": ("tt", 1.0),
    "alt": ("utm_z", 1.0),
    "vn": ("ins_vn", 1.0),
    "ve": ("ins_vw", -1.0),
    "vd": ("ins_vu", -1.0),
    "roll": ("ins_roll", 1.0),
    "pitch": ("ins_pitch", 1.0),
    "yaw": ("ins_yaw", 1.0),
    "mag": ("mag_1_uc", 1.0),
    "flux_x": ("flux_a_x", 1.0),
    "flux_y": ("flux_a_y", 1.0),
    "flux_z": ("flux_a_z", 1.0),
    "lat": ("ins_lat", np.pi / 180.0),
    "lon": ("ins_lon", np.pi / 180.0),
}
UNITS = {"tt": "s", "ins_lat": "rad", "ins_lon": "rad", "utm_z": "m", "ins_vn": "m/s",
         "ins_vw": "m/s", "ins_vu": "m/s", "ins_roll": "deg", "ins_pitch": "deg",
         "ins_yaw": "deg", "diurnal": "nT", "igrf": "nT"}


def sgl_name(n):
    """The SGL name and factor of a simulator column: the table above, the
    further scalar magnetometers mag_k -> mag_k_uc, everything else (extra
    fluxgates flux_b_x..., currents cur_X, line, truth) as is."""
    if n in SGL:
        return SGL[n]
    if n.startswith("mag_") and n[4:].isdigit():
        return f"{n}_uc", 1.0
    return n, 1.0


def sgl_unit(name):
    if name in UNITS:
        return UNITS[name]
    if name.startswith("mag_") or name.startswith("flux_"):
        return "nT"
    if name.startswith("cur_"):
        return "A"
    return None


def read_csv(path):
    with open(path) as f:
        lines = [l for l in f if not l.startswith("#")]
    names = lines[0].strip().split(",")
    data = np.genfromtxt(lines[1:], delimiter=",", dtype=np.float64)
    return names, data


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("calibration")
    ap.add_argument("survey")
    ap.add_argument("out_dir")
    a = ap.parse_args()
    cn, cal = read_csv(a.calibration)
    sn, sur = read_csv(a.survey)
    assert cn == sn, "the two flights must have the same columns"
    names = cn
    li, ti = names.index("line"), names.index("time")
    cal = cal.copy()
    cal[:, li] = np.where(cal[:, li] > 0, BOX_LABEL, 0.0)
    sur = sur.copy()
    sur[:, ti] += cal[-1, ti] + TRANSIT_S - sur[0, ti]
    lines = sur[:, li]
    # lines 1001.. -> 1003.01..; ties 2001.. -> 1003.51..
    relabel = np.where(lines >= 2001, SURVEY_FLIGHT + 0.5 + (lines - 2000) / 100.0,
                       np.where(lines > 0, SURVEY_FLIGHT + (lines - 1000) / 100.0, 0.0))
    sur[:, li] = np.round(relabel, 2)
    flight = np.vstack([cal, sur])
    os.makedirs(a.out_dir, exist_ok=True)
    with open(os.path.join(a.out_dir, "whole_flight.csv"), "w") as f:
        f.write(",".join(names) + "\n")
        for row in flight:
            f.write(",".join("" if np.isnan(v) else repr(float(v)) for v in row) + "\n")
    with h5py.File(os.path.join(a.out_dir, "whole_flight.h5"), "w") as h:
        for k, n in enumerate(names):
            name, factor = sgl_name(n)
            ds = h.create_dataset(name, data=flight[:, k] * factor, chunks=True,
                                  compression="gzip", shuffle=True)
            unit = sgl_unit(name)
            if unit and not name.startswith("true_"):
                ds.attrs["units"] = unit


if __name__ == "__main__":
    main()
