#!/usr/bin/env bash
# aeromag against its peers (issue 24 item 6), in one run on this machine:
# Tolles-Lawson calibration + compensation with the MagNav settings (18
# terms, MagNav's derivative convention, band-pass 0.1–0.9 Hz, no eddy lag,
# no reference field, lines not split) on the same generated flights, by
#   - aeromag (the CLI: calibrate then compensate; and calibrate
#     --compensated, which writes the same model and compensated flight
#     from one reading of the file, as the peers read it once),
#   - a NumPy/SciPy port of MagNav.jl's create_TL_A + create_TL_coef,
#   - deinterf (PyPI) with plain least squares and with its default RidgeCV;
# end to end (CSV in, CSV out; hyperfine) and compute alone (fit + apply on
# arrays in memory: python/benchmarks/bench_tl.py), then the ratio table.
# The peers and aeromag's Python package go into a virtual environment
# (target/bench-venv; the extension is built there once).
# Usage: tools/bench/peers.sh [N …]     (default sizes 100000 1000000 10000000)
# Takes about an hour with 10⁷ samples on 2 cores, most of it in the peers.
set -euo pipefail
cd "$(dirname "$0")/../.."
dir=target/bench-peers
venv=target/bench-venv
sizes=("$@")
[ ${#sizes[@]} -gt 0 ] || sizes=(100000 1000000 10000000)
mkdir -p "$dir"
command -v hyperfine >/dev/null || { apt-get install -y hyperfine >/dev/null 2>&1 || cargo install --locked hyperfine; }
cargo build --release -p aeromag-cli
cargo build --release -p aeromag-io --example read_time
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
py=$PWD/$venv/bin/python
"$py" -m pip install --quiet --upgrade pip
"$py" -m pip install --quiet numpy scipy pandas scikit-learn deinterf maturin
"$py" -m pip install --quiet ./python
bin=$PWD/target/release/aeromag
magnav_settings="--terms p3,i6,e9 --convention magnav --eddy-lag none --reference none --no-split-lines"
for n in "${sizes[@]}"; do
    f=$dir/flight-$n.csv
    [ -f "$f" ] || "$py" tools/bench/peers.py gen "$n" "$f"
    # One warm-up run each below 10⁷ (the first run of a command reads
    # its binary or its libraries from disk).
    runs=3 warmup=1
    [ "$n" -lt 10000000 ] || { runs=1; warmup=0; }
    echo "== $n samples ($(du -h "$f" | cut -f1) CSV), end to end, $runs run(s) each after $warmup warm-up"
    hyperfine --warmup "$warmup" --runs "$runs" --export-json "$dir/e2e-$n.json" \
        -n "aeromag calibrate + compensate" \
        "$bin calibrate -i $f --model $dir/m.json $magnav_settings >/dev/null && $bin compensate --model $dir/m.json -i $f --out $dir/a-out.csv >/dev/null" \
        -n "aeromag calibrate --compensated (one run)" \
        "$bin calibrate -i $f --model $dir/m1.json $magnav_settings --compensated $dir/a1-out.csv >/dev/null" \
        -n "NumPy/SciPy MagNav port" "$py tools/bench/peers.py magnav $f $dir/m-out.csv" \
        -n "deinterf, plain least squares" "$py tools/bench/peers.py deinterf $f $dir/d-out.csv plain" \
        -n "deinterf, default RidgeCV" "$py tools/bench/peers.py deinterf $f $dir/d-out.csv"
    echo "== $n samples, compute alone (fit + apply on arrays)"
    BENCH_REPEAT=$runs "$py" python/benchmarks/bench_tl.py "$n" | tee "$dir/compute-$n.txt"
    echo "== $n samples, reading alone"
    "$py" tools/bench/peers.py read "$f" "$PWD/target/release/examples/read_time" | tee "$dir/read-$n.txt"
done
echo "== end to end, all sizes"
"$py" tools/bench/peers.py table "$dir"
