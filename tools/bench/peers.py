"""The Python side of the peer benchmark (tools/bench/peers.sh).

    python peers.py gen N FILE.csv          a flight of N samples (time, flux_x/y/z, mag, line)
    python peers.py magnav IN.csv OUT.csv    end to end: read, fit + apply (MagNav port), write
    python peers.py deinterf IN.csv OUT.csv [plain]   the same with deinterf (RidgeCV, or plain LS)
    python peers.py table DIR               the ratio table of the hyperfine exports in DIR
    python peers.py read FILE.csv READ_TIME  reading alone: aeromag (the read_time example of
                                            aeromag-io) against pandas.read_csv, best of 5, on
                                            the CSV and on the same rows whitespace-separated

The flights are simulated calibration boxes (aeromag.simulate, seeds 1–8)
joined end to end and repeated up to N samples with the time running on.
The MagNav port and the deinterf calls are those of
python/benchmarks/bench_tl.py (the compute-alone comparison), so both
comparisons fit the same 18-term model the same way.
"""

import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "python", "benchmarks"))

COLUMNS = ["time", "flux_x", "flux_y", "flux_z", "mag", "line"]
POOL = 8  # simulated boxes to repeat


def gen(n, path):
    import aeromag
    from bench_tl import FS

    parts = []
    for seed in range(1, POOL + 1):
        f = aeromag.simulate("calibration", seed=seed)
        parts.append({c: np.asarray(f[c]) for c in COLUMNS})
    pool = {c: np.concatenate([p[c] for p in parts]) for c in COLUMNS}
    m = len(pool["time"])
    reps = -(-n // m)
    out = {}
    for c in COLUMNS:
        v = np.tile(pool[c], reps)[:n]
        out[c] = v
    # Time runs on regularly (10 Hz); every repetition gets new line labels.
    out["time"] = np.arange(n) / FS
    out["line"] = out["line"] + 1000.0 * (np.arange(n) // m)
    tmp = path + ".tmp"
    with open(tmp, "w") as fh:
        fh.write(",".join(COLUMNS) + "\n")
        np.savetxt(fh, np.column_stack([out[c] for c in COLUMNS]), delimiter=",",
                   fmt=["%.1f", "%.3f", "%.3f", "%.3f", "%.3f", "%.0f"])
    os.replace(tmp, path)


def read(path):
    import pandas as pd

    return {c: v.to_numpy() for c, v in pd.read_csv(path).items()}


def write(path, d, comp):
    import pandas as pd

    df = pd.DataFrame(d)
    df["mag_comp"] = comp
    df.to_csv(path, index=False)


def magnav(inp, out):
    from bench_tl import run_magnav

    d = read(inp)
    _, comp = run_magnav(d)
    write(out, d, comp)


def deinterf(inp, out, plain):
    from bench_tl import run_deinterf

    d = read(inp)
    _, comp = run_deinterf(d, plain)
    write(out, d, np.asarray(comp))


def table(folder):
    """One row per size and tool: mean seconds (hyperfine) and × aeromag."""
    rows = []
    for name in sorted(os.listdir(folder)):
        if not (name.startswith("e2e-") and name.endswith(".json")):
            continue
        n = int(name[4:-5])
        res = json.load(open(os.path.join(folder, name)))["results"]
        base = res[0]["mean"]
        for r in res:
            rows.append((n, r["command"], r["mean"], r["mean"] / base))
    print(f"{'samples':>9s}  {'tool (end to end: CSV in, CSV out)':42s} {'s':>8s} {'× aeromag':>10s}")
    for n, tool, s, ratio in sorted(rows, key=lambda r: (r[0], r[3])):
        print(f"{n:9d}  {tool:42s} {s:8.2f} {ratio:10.1f}")
    # The peers against aeromag's one run (`calibrate --compensated`),
    # which reads the file once as they do.
    for n in sorted({r[0] for r in rows}):
        one = [s for m, tool, s, _ in rows if m == n and tool.startswith("aeromag calibrate --compensated")]
        if one:
            peers = [f"{tool} {s / one[0]:.1f}×" for m, tool, s, _ in rows if m == n and not tool.startswith("aeromag")]
            print(f"{n:9d}  against the one run ({one[0]:.2f} s): " + ", ".join(peers))


def read_alone(csv_path, read_time):
    import subprocess
    import time

    import pandas

    txt = csv_path[: -len(".csv")] + ".txt"
    if not os.path.exists(txt):
        with open(csv_path) as f, open(txt + ".part", "w") as g:
            for line in f:
                g.write(line.replace(",", " "))
        os.replace(txt + ".part", txt)

    def best(f):
        times = []
        for _ in range(5):
            t = time.perf_counter()
            f()
            times.append(time.perf_counter() - t)
        return min(times)

    size = os.path.getsize(csv_path) / 1e6
    print(f"| file ({size:.0f} MB) | aeromag, s | pandas.read_csv, s | pandas / aeromag |")
    print("|---|---|---|---|")
    for path, kw in [(csv_path, {}), (txt, {"sep": r"\s+"})]:
        out = subprocess.run([read_time, path, "5"], check=True, capture_output=True, text=True)
        ours = float(out.stdout.split()[0])
        theirs = best(lambda: pandas.read_csv(path, **kw))
        name = "CSV" if path == csv_path else "whitespace-separated"
        print(f"| {name} | {ours:.3f} | {theirs:.3f} | {theirs / ours:.2f}x |")


if __name__ == "__main__":
    cmd = sys.argv[1]
    if cmd == "gen":
        gen(int(float(sys.argv[2])), sys.argv[3])
    elif cmd == "magnav":
        magnav(sys.argv[2], sys.argv[3])
    elif cmd == "deinterf":
        deinterf(sys.argv[2], sys.argv[3], len(sys.argv) > 4 and sys.argv[4] == "plain")
    elif cmd == "table":
        table(sys.argv[2])
    elif cmd == "read":
        read_alone(sys.argv[2], sys.argv[3])
    else:
        sys.exit(f"unknown command {cmd}")
