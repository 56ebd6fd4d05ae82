#!/usr/bin/env bash
# `aeromag grid` against GMT `surface` (issue 22: within 2× of GMT's time for
# a 10⁶-point survey), timed in one run by hyperfine on the same points,
# cell and tension. The survey: 350 north–south lines 100 m apart, a sample
# every 7 m (10⁶ points), 40 Gaussian anomalies and a regional gradient,
# generated in UTM zone 37N and given to aeromag as latitude/longitude (it
# projects them back) and to GMT as easting/northing. GMT runs blockmean
# then surface, as its manual asks; aeromag takes block means itself.
# Both write netCDF; the script then prints the RMS difference of the two
# grids over the grid's standard deviation. Two regions: the one aeromag
# chooses from the data (1399 × 802 nodes, sizes GMT cannot factor well),
# and a region GMT likes (1401 × 801: 1400 = 2³·5²·7, 800 = 2⁵·5²) given to
# both.
# Needs Debian's gmt and hyperfine (installed if missing) and numpy.
# Usage: scripts/bench-grid.sh [DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
dir="${1:-target/bench-grid}"
command -v gmt >/dev/null || apt-get install -y --no-install-recommends gmt >/dev/null
command -v hyperfine >/dev/null || { apt-get install -y hyperfine >/dev/null 2>&1 || cargo install --locked hyperfine; }
cargo build --release -p aeromag-cli
bin=$PWD/target/release/aeromag
mkdir -p "$dir"
# GMT writes its gmt.history beside the commands it runs: in the bench
# folder, not the repository.
export GMT_TMPDIR="$(cd "$dir" && pwd)/gmt-tmp"
mkdir -p "$GMT_TMPDIR"
if [ ! -f "$dir/survey.csv" ]; then
    python3 - "$dir" <<'PY'
import sys, numpy as np
d = sys.argv[1]
x0, y0 = 430000.0, 6200000.0
r = np.random.default_rng(5)
src = [(r.uniform(0, 35000), r.uniform(0, 20000), r.normal(0, 100), r.uniform(150, 2000)) for _ in range(40)]
xs, ys, zs, ls = [], [], [], []
for k, xl in enumerate(np.arange(50, 35000, 100.0)):
    y = np.arange(0, 20000, 7.0)
    x = xl + 5 * np.sin(y / 900)
    z = 0.002 * x - 0.001 * y
    for (a, b, amp, s) in src:
        z = z + amp * np.exp(-((x - a) ** 2 + (y - b) ** 2) / (2 * s * s))
    xs.append(x + x0); ys.append(y + y0); zs.append(z); ls.append(np.full(len(y), 1001.0 + k))
x, y, z, l = map(np.concatenate, (xs, ys, zs, ls))
np.savetxt(f"{d}/xyz.txt", np.c_[x, y, z], fmt="%.3f %.3f %.6f")
np.savetxt(f"{d}/line.txt", l, fmt="%.0f")
PY
    # Easting/northing → longitude/latitude in UTM 37N (central meridian 39°E).
    gmt mapproject "$dir/xyz.txt" -Ju37N/1:1 -C -F -I --FORMAT_FLOAT_OUT=%.10f > "$dir/lonlat.txt"
    paste -d' ' "$dir/lonlat.txt" "$dir/line.txt" \
        | awk 'BEGIN { print "lon,lat,mag,line" } { print $1 "," $2 "," $3 "," $4 }' > "$dir/survey.csv"
fi
n=$(($(wc -l < "$dir/survey.csv") - 1))
# The region aeromag chooses (printed), given to GMT.
auto=$("$bin" grid -i "$dir/survey.csv" --cell 25 --blanking 1e9 --utm-zone 37N --out "$dir/aeromag.nc" 2>/dev/null \
    | sed -n 's/.*x \([0-9.]*\)–\([0-9.]*\) m, y \([0-9.]*\)–\([0-9.]*\) m/\1\/\2\/\3\/\4/p')
nice=430000/465000/6200000/6220000
for region in "$auto" "$nice"; do
    echo "$n points; region $region, cell 25 m, tension 0.25"
    hyperfine --warmup 1 --runs 3 --export-markdown "$dir/grid-${region//\//_}.md" \
        "$bin grid -i $dir/survey.csv --cell 25 --extent ${region//\//,} --blanking 1e9 --utm-zone 37N --out $dir/aeromag.nc 2>/dev/null" \
        "gmt blockmean $dir/xyz.txt -R$region -I25 | gmt surface -R$region -I25 -T0.25 -G$dir/gmt.nc"
    gmt grd2xyz "$dir/gmt.nc" > "$dir/gmt.xyz"
    gmt grd2xyz "$dir/aeromag.nc" > "$dir/aeromag.xyz"
    python3 - "$dir" <<'PY'
import sys, numpy as np
d = sys.argv[1]
g, a = np.loadtxt(f"{d}/gmt.xyz"), np.loadtxt(f"{d}/aeromag.xyz")
assert np.allclose(g[:, :2], a[:, :2]), "the grids' nodes differ"
diff = a[:, 2] - g[:, 2]
rms = np.sqrt(np.mean(diff ** 2))
print(f"grid difference RMS {rms:.4g} nT = {rms / g[:, 2].std():.3%} of the grid's std {g[:, 2].std():.2f} nT; largest {abs(diff).max():.3g} nT")
PY
done
