#!/usr/bin/env python3
"""Reference values from SciPy for the filters and spectra of aeromag-core,
read by the Rust test `crates/core/tests/filter_reference.rs`.

Usage (from the repository root):

    python3 tools/reference/filter_reference.py crates/core/tests/data

writes four files:

* filter_butter.json      signal.butter(N, Wn, btype, fs=fs, output='sos') for
                          fixed and seeded-random orders, bands and rates.
* filter_zero_phase.json  sosfiltfilt, filtfilt (b, a), sosfilt, lfilter,
                          sosfilt_zi and lfilter_zi on seeded numpy signals of
                          lengths from padlen+1 to a few thousand samples.
* filter_windows.json     signal.windows.* (sym=True and sym=False) and
                          signal.firwin low-pass designs.
* filter_welch.json       signal.welch with even/odd nperseg, overlaps,
                          nfft padding, detrend None/constant/linear and both
                          scalings.

All randomness is numpy.random.default_rng with fixed seeds, so rerunning
the script reproduces the files bit for bit (for the same numpy/scipy).
Floats are written with Python's shortest round-trip repr.
"""

import json
import os
import sys

import numpy as np
import scipy
from scipy import signal

KINDS = {"lowpass": 1, "highpass": 1, "bandpass": 2, "bandstop": 2}


def make_signal(rng, n, fs, offset=0.0):
    """Noise + drift + a few sinusoids: a stand-in for a magnetometer record."""
    t = np.arange(n) / fs
    x = rng.normal(0.0, 1.0, n)
    x += 0.002 * fs * t  # drift
    for _ in range(3):
        f = rng.uniform(0.0, 0.45 * fs)
        x += rng.uniform(0.5, 3.0) * np.sin(2 * np.pi * f * t + rng.uniform(0, 2 * np.pi))
    return x + offset


def butter_cases():
    cases = []

    def add(order, kind, band, fs):
        wn = band[0] if len(band) == 1 else band
        sos = signal.butter(order, wn, kind, fs=fs, output="sos")
        cases.append({"order": order, "kind": kind, "band": list(band), "fs": fs,
                      "sos": sos.tolist()})

    for order in range(1, 11):
        add(order, "lowpass", [1.0], 10.0)
        add(order, "highpass", [0.3], 10.0)
    for order in range(1, 9):
        add(order, "bandpass", [0.1, 0.9], 10.0)
        add(order, "bandpass", [0.01, 0.2], 1.0)
        add(order, "bandstop", [1.0, 2.0], 10.0)
    add(4, "bandpass", [5.0, 40.0], 160.0)
    add(6, "bandpass", [100.0, 200.0], 1000.0)
    add(20, "lowpass", [0.2], 1.0)
    add(20, "highpass", [0.05], 1.0)
    add(20, "bandpass", [0.1, 0.3], 1.0)
    add(15, "bandstop", [0.1, 0.3], 1.0)
    add(3, "lowpass", [0.4999], 1.0)  # near Nyquist
    add(3, "highpass", [1e-4], 1.0)  # near DC
    rng = np.random.default_rng(20250611)
    for _ in range(60):
        order = int(rng.integers(1, 13))
        kind = list(KINDS)[int(rng.integers(0, 4))]
        fs = float(10 ** rng.uniform(-1, 3.7))
        if KINDS[kind] == 1:
            band = [float(rng.uniform(0.002, 0.49) * fs)]
        else:
            lo, hi = sorted(rng.uniform(0.002, 0.49, 2))
            if hi - lo < 0.01:
                hi = lo + 0.01
            band = [float(lo * fs), float(hi * fs)]
        add(order, kind, band, fs)
    return {"scipy": scipy.__version__, "cases": cases}


def padlen_sos(sos):
    ntaps = 2 * len(sos) + 1 - min((sos[:, 2] == 0).sum(), (sos[:, 5] == 0).sum())
    return 3 * int(ntaps)


def zero_phase_cases():
    rng = np.random.default_rng(7)
    sosff, ff, sosf, lf, zis = [], [], [], [], []

    designs = [
        (4, "bandpass", [0.1, 0.9], 10.0),
        (2, "bandpass", [0.05, 0.5], 5.0),
        (1, "lowpass", [1.0], 10.0),
        (3, "lowpass", [0.2], 1.0),
        (5, "highpass", [2.0], 50.0),
        (6, "bandstop", [1.0, 2.0], 10.0),
        (8, "bandpass", [0.01, 0.2], 1.0),
        (10, "lowpass", [0.3], 1.0),
    ]
    for i, (order, kind, band, fs) in enumerate(designs):
        wn = band[0] if len(band) == 1 else band
        sos = signal.butter(order, wn, kind, fs=fs, output="sos")
        p = padlen_sos(sos)
        lengths = [p + 1, p + 2, 317, 1000, 2500] if i < 2 else [p + 1, 400, 1500]
        for n in lengths:
            offset = 5.0e4 if (i == 0 and n == 2500) else 0.0
            x = make_signal(rng, n, fs, offset)
            y = signal.sosfiltfilt(sos, x)
            sosff.append({"sos": sos.tolist(), "padlen": p, "x": x.tolist(), "y": y.tolist()})
        zis.append({"sos": sos.tolist(), "zi": signal.sosfilt_zi(sos).tolist()})
        x = make_signal(rng, 400, fs)
        sosf.append({"sos": sos.tolist(), "x": x.tolist(), "y": signal.sosfilt(sos, x).tolist()})

    tf_designs = [
        (1, "lowpass", [1.0], 10.0),
        (2, "lowpass", [0.2], 1.0),
        (3, "highpass", [0.1], 1.0),
        (2, "bandpass", [0.1, 0.9], 10.0),
        (4, "bandpass", [0.1, 0.3], 1.0),
    ]
    tfs = []
    for order, kind, band, fs in tf_designs:
        wn = band[0] if len(band) == 1 else band
        b, a = signal.butter(order, wn, kind, fs=fs, output="ba")
        tfs.append((b, a, fs))
    # unnormalised, unequal lengths
    tfs.append((np.array([0.5, 0.25]), np.array([2.0, -1.2, 0.4]), 1.0))
    tfs.append((np.array([0.1, 0.2, 0.3, 0.2]), np.array([1.5, -0.3]), 1.0))
    for b, a, fs in tfs:
        p = 3 * max(len(a), len(b))
        for n in [p + 1, 777]:
            x = make_signal(rng, n, fs)
            y = signal.filtfilt(b, a, x)
            ff.append({"b": b.tolist(), "a": a.tolist(), "padlen": p, "x": x.tolist(),
                       "y": y.tolist()})
        x = make_signal(rng, 300, fs)
        lf.append({"b": b.tolist(), "a": a.tolist(), "x": x.tolist(),
                   "y": signal.lfilter(b, a, x).tolist()})
        zis.append({"b": b.tolist(), "a": a.tolist(), "zi": signal.lfilter_zi(b, a).tolist()})
    return {"scipy": scipy.__version__, "sosfiltfilt": sosff, "filtfilt": ff,
            "sosfilt": sosf, "lfilter": lf, "zi": zis}


WINDOWS = [
    ("boxcar", None), ("hann", None), ("hamming", None), ("blackman", None),
    ("blackmanharris", None), ("nuttall", None),
    ("chebwin", 45.0), ("chebwin", 60.0), ("chebwin", 80.0), ("chebwin", 100.0),
    ("kaiser", 0.5), ("kaiser", 5.0), ("kaiser", 8.6), ("kaiser", 14.0),
]


def window_cases():
    wins = []
    for name, param in WINDOWS:
        for m in [1, 2, 3, 8, 15, 64, 101, 256]:
            for sym in [True, False]:
                f = getattr(signal.windows, name)
                w = f(m, sym=sym) if param is None else f(m, param, sym=sym)
                spec = name if param is None else [name, param]
                wins.append({"window": spec, "len": m, "sym": sym, "w": w.tolist()})
                if not sym:
                    g = signal.get_window(name if param is None else (name, param), m)
                    assert np.array_equal(g, w)
    firs = []
    for numtaps, cutoff, fs, window in [
        (1, 1.0, 10.0, "hamming"), (2, 1.0, 10.0, "hamming"), (16, 0.3, 2.0, "hamming"),
        (31, 1.0, 10.0, "hamming"), (101, 5.0, 100.0, "hamming"), (255, 0.02, 1.0, "hamming"),
        (64, 120.0, 1000.0, "hamming"), (33, 1.0, 10.0, "hann"), (51, 2.0, 10.0, "blackman"),
        (41, 1.0, 10.0, ("kaiser", 5.0)), (61, 1.0, 10.0, ("chebwin", 60.0)),
        (45, 3.0, 10.0, "nuttall"), (20, 0.5, 4.0, "boxcar"),
    ]:
        h = signal.firwin(numtaps, cutoff, window=window, fs=fs)
        spec = list(window) if isinstance(window, tuple) else window
        firs.append({"numtaps": numtaps, "cutoff": cutoff, "fs": fs, "window": spec,
                     "h": h.tolist()})
    return {"scipy": scipy.__version__, "windows": wins, "firwin": firs}


def welch_cases():
    rng = np.random.default_rng(1967)
    signals = {
        "a": make_signal(rng, 2048, 10.0),
        "b": make_signal(rng, 1999, 160.0, offset=300.0),
        "c": make_signal(rng, 777, 1.0),
    }
    cases = []
    configs = [
        ("a", 10.0, 256, None, None, "hann", "constant", "density"),
        ("a", 10.0, 256, None, None, "hann", "constant", "spectrum"),
        ("a", 10.0, 255, None, None, "hann", "constant", "density"),
        ("a", 10.0, 100, 0, None, "hamming", False, "density"),
        ("a", 10.0, 127, 100, None, "blackman", "linear", "spectrum"),
        ("a", 10.0, 64, 63, None, "nuttall", "linear", "density"),
        ("a", 10.0, 200, 50, 256, "blackmanharris", "constant", "density"),
        ("a", 10.0, 200, 50, 301, "hann", "linear", "spectrum"),
        ("a", 10.0, 2048, None, None, "boxcar", False, "spectrum"),
        ("b", 160.0, 512, None, None, "hann", "constant", "density"),
        ("b", 160.0, 333, 111, None, ("chebwin", 80.0), "linear", "density"),
        ("b", 160.0, 128, 32, 1000, ("kaiser", 8.6), False, "spectrum"),
        ("c", 1.0, 777, 0, None, "hann", "constant", "density"),
        ("c", 1.0, 7, 3, None, "hann", "linear", "density"),
        ("c", 1.0, 1, 0, None, "boxcar", False, "spectrum"),
        ("c", 1.0, 2, 1, 3, "hamming", "constant", "density"),
    ]
    for sig, fs, nperseg, noverlap, nfft, window, detrend, scaling in configs:
        f, p = signal.welch(signals[sig], fs=fs, window=window, nperseg=nperseg,
                            noverlap=noverlap, nfft=nfft, detrend=detrend, scaling=scaling)
        cases.append({
            "signal": sig, "fs": fs, "nperseg": nperseg,
            "noverlap": nperseg // 2 if noverlap is None else noverlap,
            "nfft": nperseg if nfft is None else nfft,
            "window": list(window) if isinstance(window, tuple) else window,
            "detrend": "none" if detrend is False else detrend,
            "scaling": scaling, "f": f.tolist(), "p": p.tolist(),
        })
    return {"scipy": scipy.__version__,
            "signals": {k: v.tolist() for k, v in signals.items()}, "cases": cases}


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "crates/core/tests/data"
    for name, make in [("filter_butter", butter_cases), ("filter_zero_phase", zero_phase_cases),
                       ("filter_windows", window_cases), ("filter_welch", welch_cases)]:
        path = os.path.join(out, name + ".json")
        with open(path, "w") as fh:
            json.dump(make(), fh, separators=(",", ":"))
            fh.write("\n")
        print(f"wrote {path} ({os.path.getsize(path)} bytes)", file=sys.stderr)


if __name__ == "__main__":
    main()
