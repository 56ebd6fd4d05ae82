#!/usr/bin/env python3
"""Generate the colour tables used by crates/report/src/plot/colormap.rs.

* viridis (Smith & van der Walt 2015, public domain / CC0): matplotlib's
  256-entry table sampled at 33 equally spaced anchors t = k/32.
* RdBu_r (ColorBrewer "RdBu", reversed so that blue = low, red = high):
  matplotlib builds it by linear interpolation through 11 anchors, so the 11
  anchors reproduce it up to 8-bit rounding.

The Rust code interpolates linearly between neighbouring anchors; the script
prints the largest deviation of that interpolation from matplotlib's full
256-entry table and a few reference samples used by the unit tests.

Requires: numpy, matplotlib (pip install matplotlib).  Run:
    python3 tools/reference/colormap_tables.py
"""
import numpy as np
from matplotlib import colormaps


def table(name, n):
    cmap = colormaps[name]
    t = np.linspace(0.0, 1.0, n)
    rgb8 = np.round(np.array([cmap(v)[:3] for v in t]) * 255.0).astype(int)
    full = np.array([cmap(i / 255.0)[:3] for i in range(256)]) * 255.0
    tt = np.arange(256) / 255.0
    interp = np.stack([np.interp(tt, t, rgb8[:, c]) for c in range(3)], axis=1)
    err = np.abs(interp - full).max()
    const = name.upper().replace("_R", "_R")
    print(f"// {name}: {n} anchors at t = k/{n - 1}; max |interp - matplotlib| = {err:.2f}/255")
    print(f"const {const}: [[u8; 3]; {n}] = [")
    for r, g, b in rgb8:
        print(f"    [{r}, {g}, {b}],")
    print("];")
    for v in (0.0, 0.1, 0.37, 0.5, 0.9, 1.0):
        r, g, b = (x * 255.0 for x in cmap(v)[:3])
        print(f"// reference {name}({v}) = [{r:.2f}, {g:.2f}, {b:.2f}]")


table("viridis", 33)
table("RdBu_r", 11)
