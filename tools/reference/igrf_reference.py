#!/usr/bin/env python3
"""Reference values of the IGRF-14 main field from ppigrf, for the Rust test
`crates/core/tests/igrf_reference.rs`.

Usage (from the repository root):

    python3 tools/reference/igrf_reference.py > crates/core/tests/data/igrf_reference.json

Two sets are written:

* "geodetic": WGS84 geodetic points (lat, lon, height) evaluated with
  `ppigrf.igrf` (east, north, up, relative to the ellipsoid), converted here
  to X north, Y east, Z down. For the same points the geocentric coordinates
  ppigrf uses internally (`ppigrf.geod2geoc`) and the geocentric components
  from `ppigrf.igrf_gc` (Br, Btheta south, Bphi east) are stored as well, so
  the Rust test can check the spherical-harmonic synthesis and the time
  interpolation separately from the geodetic rotation.
* "geocentric": points given directly in geocentric spherical coordinates,
  including satellite altitudes, evaluated with `ppigrf.igrf_gc`.

Points: both poles at +-89.99 and +-89.9999 deg, near-pole latitudes, the
equator, the dateline (+-180), and seeded random points uniform on the sphere
with heights 0-10 km and dates 1950-2029 (numpy default_rng(20250101)).
Dates include exact epoch boundaries and the 2025-2030 secular-variation
range. Some points use truncated expansions (max_degree 1, 2, 8, 10, 12).
Dates are midnight UTC; the Rust side converts them with `Date::decimal_year`.
"""

import datetime as dt
import json
import sys
from importlib.metadata import version

import numpy as np
import ppigrf
from ppigrf.ppigrf import geod2geoc


def geodetic_record(lat, lon, alt_m, date, max_degree=13):
    h_km = alt_m / 1000.0
    be, bn, bu = ppigrf.igrf(lon, lat, h_km, date, max_degree=max_degree)
    theta_deg, r_km, _, _ = geod2geoc(np.array([lat]), np.array([h_km]), 0.0, 0.0)
    br, bt, bp = ppigrf.igrf_gc(r_km, theta_deg, lon, date, max_degree=max_degree)
    return {
        "date": date.strftime("%Y-%m-%d"),
        "lat_deg": float(lat),
        "lon_deg": float(lon),
        "alt_m": float(alt_m),
        "max_degree": int(max_degree),
        "x_nt": float(bn.item()),
        "y_nt": float(be.item()),
        "z_nt": float(-bu.item()),
        "colat_gc_deg": float(theta_deg.item()),
        "r_gc_km": float(r_km.item()),
        "br_nt": float(br.item()),
        "btheta_nt": float(bt.item()),
        "bphi_nt": float(bp.item()),
    }


def geocentric_record(r_km, colat_deg, lon_deg, date, max_degree=13):
    br, bt, bp = ppigrf.igrf_gc(r_km, colat_deg, lon_deg, date, max_degree=max_degree)
    return {
        "date": date.strftime("%Y-%m-%d"),
        "r_km": float(r_km),
        "colat_deg": float(colat_deg),
        "lon_deg": float(lon_deg),
        "max_degree": int(max_degree),
        "br_nt": float(br.item()),
        "btheta_nt": float(bt.item()),
        "bphi_nt": float(bp.item()),
    }


def main():
    d = dt.datetime
    rng = np.random.default_rng(20250101)
    geodetic = []

    # Fixed points: poles, near-poles, equator, dateline; epoch boundaries and
    # the secular-variation (extrapolation) range 2025-2030.
    fixed = [
        (89.99, 0.0, 0.0, d(2020, 1, 1)),
        (-89.99, 45.0, 5000.0, d(2020, 1, 1)),
        (89.9999, -120.0, 300.0, d(2027, 3, 15)),
        (-89.9999, 170.0, 10000.0, d(1965, 7, 1)),
        (89.99, 90.0, 1000.0, d(2029, 12, 31)),
        (-89.99, -90.0, 0.0, d(1950, 1, 1)),
        (88.5, 33.3, 2500.0, d(2010, 1, 1)),
        (-87.3, -150.0, 7500.0, d(2025, 1, 1)),
        (85.0, 180.0, 0.0, d(2000, 1, 1)),
        (0.0, 0.0, 0.0, d(2025, 1, 1)),
        (0.0, 90.0, 1000.0, d(2026, 6, 30)),
        (0.0, -90.0, 3000.0, d(1955, 1, 1)),
        (0.0, 180.0, 0.0, d(2028, 2, 29)),
        (0.0, -180.0, 0.0, d(2028, 2, 29)),
        (12.5, 179.999, 8000.0, d(1990, 1, 1)),
        (-33.9, -179.999, 200.0, d(2024, 12, 31)),
        (60.39299, 5.32415, 0.0, d(2021, 3, 28)),
        (55.75, 37.62, 150.0, d(2029, 6, 1)),
        (-75.0, 123.0, 3000.0, d(2015, 1, 1)),
        (45.0, -75.0, 500.0, d(1900, 1, 1)),
        (-15.0, -45.0, 400.0, d(2030, 1, 1)),
    ]
    for lat, lon, alt, date in fixed:
        geodetic.append(geodetic_record(lat, lon, alt, date))

    # Seeded random points, uniform on the sphere.
    start = d(1950, 1, 1)
    n_days = (d(2029, 12, 31) - start).days
    for _ in range(40):
        lat = float(np.degrees(np.arcsin(rng.uniform(-1.0, 1.0))))
        lon = float(rng.uniform(-180.0, 180.0))
        alt = float(rng.uniform(0.0, 10000.0))
        date = start + dt.timedelta(days=int(rng.integers(0, n_days + 1)))
        geodetic.append(geodetic_record(lat, lon, alt, date))
    # Extra random points in the secular-variation range 2025-2030.
    start_sv = d(2025, 1, 1)
    for _ in range(8):
        lat = float(np.degrees(np.arcsin(rng.uniform(-1.0, 1.0))))
        lon = float(rng.uniform(-180.0, 180.0))
        alt = float(rng.uniform(0.0, 10000.0))
        date = start_sv + dt.timedelta(days=int(rng.integers(0, 1826)))
        geodetic.append(geodetic_record(lat, lon, alt, date))

    # Truncated expansions.
    for lat, lon, alt, date, nmax in [
        (48.0, 11.0, 600.0, d(2023, 5, 17), 1),
        (-22.0, -43.0, 0.0, d(1987, 9, 9), 1),
        (70.0, -150.0, 2000.0, d(2026, 1, 1), 2),
        (-60.0, 140.0, 9000.0, d(2005, 1, 1), 8),
        (5.0, 100.0, 100.0, d(2027, 11, 30), 8),
        (-12.0, 77.0, 2000.0, d(2012, 9, 13), 10),
        (33.0, -117.0, 1500.0, d(2019, 4, 1), 12),
    ]:
        geodetic.append(geodetic_record(lat, lon, alt, date, nmax))

    # Geocentric points, including satellite altitudes.
    geocentric = []
    for r_km, colat, lon, date, nmax in [
        (6371.2, 90.0, 0.0, d(2020, 1, 1), 13),
        (6371.2, 0.01, 10.0, d(2025, 1, 1), 13),
        (6371.2, 179.99, -10.0, d(2025, 1, 1), 13),
        (6771.2, 51.6, 123.4, d(2026, 8, 8), 13),
        (7000.0, 135.0, -60.0, d(1999, 12, 31), 13),
        (12000.0, 30.0, 4.0, d(2021, 3, 28), 13),
        (6500.0, 30.0, 4.0, d(2021, 3, 28), 13),
        (26560.0, 60.0, -100.0, d(2029, 9, 1), 13),
        (6371.2, 45.0, 45.0, d(1960, 1, 1), 4),
    ]:
        geocentric.append(geocentric_record(r_km, colat, lon, date, nmax))
    for _ in range(10):
        r_km = float(rng.uniform(6356.0, 8000.0))
        colat = float(np.degrees(np.arccos(rng.uniform(-1.0, 1.0))))
        lon = float(rng.uniform(-180.0, 180.0))
        date = start + dt.timedelta(days=int(rng.integers(0, n_days + 1)))
        geocentric.append(geocentric_record(r_km, colat, lon, date))

    out = {
        "generator": "tools/reference/igrf_reference.py",
        "ppigrf_version": version("ppigrf"),
        "numpy_version": np.__version__,
        "geodetic": geodetic,
        "geocentric": geocentric,
    }
    json.dump(out, sys.stdout, indent=1)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
