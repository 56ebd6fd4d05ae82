#!/usr/bin/env bash
# `aeromag stream` as a whole command (issue 21: ≥ 200 000 samples/s
# through a pipe): a simulated survey (7.3 × 10⁴ samples, repeated to
# 7.3 × 10⁵ with times shifted) streamed through a pipe with the fixed model
# and with --adapt kalman and rls, against `compensate --causal` on the
# same file, timed in one run by hyperfine.
# Usage: scripts/bench-stream.sh [DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
dir="${1:-target/bench-stream}"
command -v hyperfine >/dev/null || { apt-get install -y hyperfine >/dev/null 2>&1 || cargo install --locked hyperfine; }
cargo build --release -p aeromag-cli
bin=$PWD/target/release/aeromag
mkdir -p "$dir"
[ -f "$dir/cal/calibration.csv" ] || "$bin" simulate calibration --seed 1 --out "$dir/cal" >/dev/null
[ -f "$dir/m.json" ] || "$bin" calibrate -i "$dir/cal/calibration.csv" --model "$dir/m.json" >/dev/null
[ -f "$dir/sv/survey.csv" ] || "$bin" simulate survey --seed 2 --out "$dir/sv" >/dev/null
if [ ! -f "$dir/long.csv" ]; then
    python3 - "$dir" <<'PY'
import sys
d = sys.argv[1]
lines = [l for l in open(f"{d}/sv/survey.csv") if not l.startswith("#")]
head, rows = lines[0], lines[1:]
t0 = float(rows[0].split(",", 1)[0]); t1 = float(rows[-1].split(",", 1)[0])
with open(f"{d}/long.csv", "w") as f:
    f.write(head)
    for k in range(10):
        shift = k * (t1 - t0 + 0.1)
        for r in rows:
            t, rest = r.split(",", 1)
            f.write(f"{float(t) + shift!r},{rest}")
PY
fi
n=$(($(wc -l < "$dir/long.csv") - 1))
echo "$n samples, $(head -1 "$dir/long.csv" | tr ',' '\n' | wc -l) columns per line"
hyperfine --warmup 1 --runs 3 --export-markdown "$dir/stream.md" \
    "$bin stream --model $dir/m.json < $dir/long.csv > /dev/null" \
    "$bin stream --model $dir/m.json --adapt kalman < $dir/long.csv > /dev/null" \
    "$bin stream --model $dir/m.json --adapt rls < $dir/long.csv > /dev/null" \
    "$bin compensate --causal --model $dir/m.json -i $dir/long.csv --out $dir/causal.csv"
echo "samples/s = $n / mean time (see $dir/stream.md)"
