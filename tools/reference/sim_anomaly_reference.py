#!/usr/bin/env python3
"""Reference values from SciPy for the crustal-anomaly spectrum of
aeromag-sim, read by the Rust test `crates/sim/tests/anomaly_reference.rs`.

Usage (from the repository root):

    python3 tools/reference/sim_anomaly_reference.py crates/sim/tests/data

writes `anomaly_moments.json`: the radial moments

    M_p(H) = integral_0^inf k^p (k^2 + k_c^2)^(-beta/2) exp(-2 k H) dk,
    k_c = 2 pi / lambda_c,

computed by scipy.integrate.quad (adaptive Gauss-Kronrod, relative
tolerance 1e-13) for p = 1, 3 and a grid of spectral exponents beta,
roll-off wavelengths lambda_c and heights above the source level H. They
fix the amplitude of the simulated anomaly (the RMS of the field is
sqrt(A M_1 / 2 pi), that of its horizontal gradient sqrt(A M_3 / 2 pi)).
No randomness. Floats are written with Python's shortest round-trip repr.
"""

import json
import math
import os
import sys

import scipy
from scipy import integrate


def moment(p, beta, lam, h):
    kc = 2.0 * math.pi / lam
    f = lambda k: k**p * (k * k + kc * kc) ** (-0.5 * beta) * math.exp(-2.0 * k * h)
    # split at the scale of the exponential for the adaptive rule
    edges = [0.0, 0.1 / h, 1.0 / h, 5.0 / h, 20.0 / h, 60.0 / h]
    total = 0.0
    for a, b in zip(edges[:-1], edges[1:]):
        v, _ = integrate.quad(f, a, b, epsabs=0.0, epsrel=1e-13, limit=200)
        total += v
    v, _ = integrate.quad(f, edges[-1], math.inf, epsabs=0.0, epsrel=1e-13, limit=200)
    return total + v


def main():
    out_dir = sys.argv[1] if len(sys.argv) > 1 else "crates/sim/tests/data"
    cases = []
    for p in (1, 3):
        for beta in (0.0, 1.0, 2.0, 2.5, 3.5):
            for lam in (5000.0, 30000.0):
                for h in (150.0, 400.0, 3150.0):
                    cases.append({"p": p, "beta": beta, "lambda_c_m": lam, "height_m": h,
                                  "moment": moment(p, beta, lam, h)})
    doc = {"generator": "tools/reference/sim_anomaly_reference.py",
           "scipy": scipy.__version__, "cases": cases}
    os.makedirs(out_dir, exist_ok=True)
    with open(os.path.join(out_dir, "anomaly_moments.json"), "w") as fh:
        json.dump(doc, fh, indent=1)
        fh.write("\n")


if __name__ == "__main__":
    main()
