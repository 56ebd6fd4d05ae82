"""Reference frequency response of the EM synchronous detector (aeromag-em,
detection/synchronous.rs), computed independently with SciPy.

Detector: periodic 4-term Blackman-Harris window (scipy.signal.windows.
blackmanharris(N, sym=False)), N = 16000 samples at fs = 100 kHz, detection
frequency fk = 1025 Hz. For a unit sinusoid at f (any phase) the worst-case
output amplitude is |A(fk - f)| + |A(fk + f)|, A(d) = sum w[n] exp(2 pi i d n/fs) / sum w.

Run: python3 tools/reference/em_detector_response.py > crates/em/tests/data/detector_response.json
"""
import json

import numpy as np
from scipy.signal import windows

FS = 100_000.0
N = 16_000
FK = 1025.0
FREQS = [1025.0, 1031.25, 1040.3, 1050.0, 1062.5, 1100.0, 1128.1, 1500.0, 950.5, 400.0, 2075.0, 3125.0, 1027.0]


def transform(w, delta):
    n = np.arange(len(w))
    return np.sum(w * np.exp(2j * np.pi * delta * n / FS)) / np.sum(w)


def main():
    w = windows.blackmanharris(N, sym=False)
    rows = []
    for f in FREQS:
        g = abs(transform(w, FK - f)) + abs(transform(w, FK + f))
        rows.append({"f_hz": f, "response": g})
    print(json.dumps({"fs_hz": FS, "n": N, "fk_hz": FK, "window": "blackmanharris periodic", "rows": rows}, indent=1))


if __name__ == "__main__":
    main()
