"""Fit + transform of a Tolles-Lawson model on N samples from NumPy arrays,
side by side in one run: aeromag, deinterf (default RidgeCV, and plain
least squares), and a NumPy/SciPy implementation of MagNav.jl's
``create_TL_A`` + ``create_TL_coef`` (below, written from MagNav's
documented conventions: central-difference derivatives, Butterworth order
4 band-pass 0.1–0.9 Hz applied with filtfilt to A and B, 20 samples
trimmed, normal equations).

Every tool fits the same 18-term model (permanent 3, induced 6, eddy 9;
MagNav's derivative convention) on the same arrays; the coefficients of
aeromag and the MagNav port are compared to show they fit the same thing.

    python benchmarks/bench_tl.py [N]        (default 10**6; needs scipy, deinterf)

Times are wall-clock seconds of one fit + transform each (best of REPEAT
runs); peak memory is the growth of the peak RSS of a fresh process during
the aeromag call, against the size of the input arrays it fits on.
"""

import os
import resource
import sys
import time

import numpy as np

import aeromag

REPEAT = int(os.environ.get("BENCH_REPEAT", "3"))
FS = 10.0


def flight_arrays(n):
    """N samples of simulated calibration boxes (seeds 1, 2, …) joined
    end to end: time, flux_x/y/z, mag, line."""
    parts, t0, k = [], 0.0, 0
    total = 0
    while total < n:
        k += 1
        f = aeromag.simulate("calibration", seed=k)
        d = {c: f[c] for c in ["time", "flux_x", "flux_y", "flux_z", "mag", "line"]}
        d["time"] = d["time"] - d["time"][0] + t0
        d["line"] = d["line"] + 100.0 * k
        t0 = d["time"][-1] + 1.0 / FS
        parts.append(d)
        total += len(d["time"])
    return {c: np.concatenate([p[c] for p in parts])[:n] for c in parts[0]}


# -- MagNav.jl create_TL_A + create_TL_coef, in NumPy/SciPy ---------------------------


def magnav_tl_a(bx, by, bz, bt_scale=50000.0):
    bt = np.sqrt(bx * bx + by * by + bz * bz)
    cx, cy, cz = bx / bt, by / bt, bz / bt
    d = lambda v: np.gradient(v)  # central differences, one-sided at the ends (MagNav's fdm)
    dcx, dcy, dcz = d(cx), d(cy), d(cz)
    s = bt / bt_scale
    cols = [cx, cy, cz]
    cols += [s * cx * cx, s * cx * cy, s * cx * cz, s * cy * cy, s * cy * cz, s * cz * cz]
    cols += [s * c * dc for c in (cx, cy, cz) for dc in (dcx, dcy, dcz)]
    return np.column_stack(cols)


def magnav_tl_coef(a, b, lambda_=0.0, pass1=0.1, pass2=0.9, trim=20):
    from scipy.signal import butter, sosfiltfilt

    sos = butter(4, [pass1, pass2], btype="bandpass", fs=FS, output="sos")
    af = sosfiltfilt(sos, a, axis=0)[trim:-trim]
    bf = sosfiltfilt(sos, b)[trim:-trim]
    return np.linalg.solve(af.T @ af + lambda_ * np.eye(a.shape[1]), af.T @ bf)


def run_magnav(d):
    a = magnav_tl_a(d["flux_x"], d["flux_y"], d["flux_z"])
    coef = magnav_tl_coef(a, d["mag"])
    comp = d["mag"] - (a @ coef - np.mean(a @ coef))
    return coef, comp


def run_aeromag(d):
    # The arrays are read in place (copy=False), as the peers use theirs.
    flight = aeromag.Flight.from_dict({k: d[k] for k in FIT_COLUMNS}, copy=False)
    tl = aeromag.TollesLawson(terms="p3,i6,e9", convention="magnav", eddy_lag="none", reference="none", no_split_lines=True)
    comp = tl.fit(flight).transform(flight)
    return tl.coef_, comp


def run_deinterf(d, plain):
    from deinterf.compensator.tmi.linear import Terms, TollesLawson
    from deinterf.foundation.sensors import MagVector, Tmi
    from deinterf.utils.data_ioc import DataIoC

    data = DataIoC().add(MagVector(d["flux_x"], d["flux_y"], d["flux_z"]))
    kw = {}
    if plain:
        from sklearn.linear_model import LinearRegression

        kw["estimator"] = LinearRegression(fit_intercept=False)
    tl = TollesLawson(terms=Terms.Terms_18, **kw) if hasattr(Terms, "Terms_18") else TollesLawson(**kw)
    comp = tl.fit_transform(data, Tmi(d["mag"]))
    return None, comp


FIT_COLUMNS = ["time", "flux_x", "flux_y", "flux_z", "mag"]


def memory(d, input_mb):
    """Peak RSS of a fresh process that loads the arrays and fits + transforms
    with aeromag, against the same process before the call."""
    import os
    import subprocess
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "arrays.npz")
        np.savez(path, **{k: d[k] for k in FIT_COLUMNS})
        out = subprocess.run([sys.executable, __file__, "--memory", path], capture_output=True, text=True, check=True)
    before, peak = map(float, out.stdout.split())
    return (
        f"aeromag memory: process at {before:.0f} MB with the {input_mb:.0f} MB of input arrays loaded, "
        f"peak {peak:.0f} MB during fit + transform: growth {peak - before:.0f} MB = "
        f"{(peak - before) / input_mb:.2f}× the input arrays"
    )


def peak_rss_mb():
    """This process's peak resident memory (VmHWM; not inherited from the parent, unlike ru_maxrss)."""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmHWM:"):
                return float(line.split()[1]) / 1e3
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e3


def memory_child(path):
    z = np.load(path)
    d = {k: z[k] for k in FIT_COLUMNS}
    before = peak_rss_mb()
    run_aeromag(d)
    print(before, peak_rss_mb())


def best_time(fn, *args):
    times, out = [], None
    for _ in range(REPEAT):
        t = time.perf_counter()
        out = fn(*args)
        times.append(time.perf_counter() - t)
    return min(times), out


def main():
    if len(sys.argv) > 2 and sys.argv[1] == "--memory":
        return memory_child(sys.argv[2])
    n = int(float(sys.argv[1])) if len(sys.argv) > 1 else 10**6
    d = flight_arrays(n)
    input_mb = sum(d[k].nbytes for k in FIT_COLUMNS) / 1e6
    t_aeromag, (coef_a, _) = best_time(run_aeromag, d)
    rows = [("aeromag (TollesLawson, LS)", t_aeromag)]
    t_magnav, (coef_m, _) = best_time(run_magnav, d)
    rows.append(("NumPy/SciPy MagNav create_TL_A + create_TL_coef", t_magnav))
    try:
        rows.append(("deinterf TollesLawson, plain least squares", best_time(run_deinterf, d, True)[0]))
        rows.append(("deinterf TollesLawson, default RidgeCV", best_time(run_deinterf, d, False)[0]))
    except ImportError as e:
        print(f"deinterf not run: {e}")
    print(f"N = {n} samples, {input_mb:.0f} MB of input arrays; best of {REPEAT}")
    print(f"{'tool':52s} {'fit+transform s':>16s} {'× aeromag':>10s}")
    for name, t in rows:
        print(f"{name:52s} {t:16.3f} {t / t_aeromag:10.1f}")
    # The 18-term model has an undetermined combination (i_xx + i_yy + i_zz
    # against the permanent terms), so coefficients may differ along it;
    # the fitted interference may not.
    a = magnav_tl_a(d["flux_x"], d["flux_y"], d["flux_z"])
    diff = a @ coef_a - a @ coef_m
    diff -= diff.mean()
    print(f"aeromag vs MagNav port: modelled interference differs by {np.sqrt(np.mean(diff ** 2)):.4f} nT RMS "
          f"(interference {np.std(a @ coef_m):.1f} nT RMS)")
    print(memory(d, input_mb))

    # Call overhead on a small flight.
    small = {k: v[:1000] for k, v in d.items()}
    f = aeromag.Flight.from_dict({k: small[k] for k in ["time", "flux_x", "flux_y", "flux_z", "mag"]})
    model = aeromag.TollesLawson(terms="p3,i6,e9", convention="magnav", eddy_lag="none", reference="none").fit(f).model_
    k = 2000
    t = time.perf_counter()
    for _ in range(k):
        model.interference(f)
    per = (time.perf_counter() - t) / k
    t = time.perf_counter()
    for _ in range(k):
        len(f)
    trivial = (time.perf_counter() - t) / k
    print(f"1000-sample flight: model.interference {per * 1e6:.0f} µs per call; a trivial call {trivial * 1e6:.2f} µs")


if __name__ == "__main__":
    main()
