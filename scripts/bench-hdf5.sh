#!/usr/bin/env bash
# HDF5 against CSV: read 4 fields of a 10^6-row, 100-field flight, as HDF5
# (contiguous, and chunked with gzip + shuffle as h5py writes) and as the
# equivalent CSV, with the same program (crates/io/examples/read_fields.rs),
# timed in one run by hyperfine; peak memory by /usr/bin/time -v.
# Usage: scripts/bench-hdf5.sh [DIR]   (DIR keeps the 2.3 GB of test files)
set -euo pipefail
cd "$(dirname "$0")/.."
dir="${1:-target/bench-hdf5}"
python3 -c "import numpy, h5py" 2>/dev/null || python3 -m pip install --quiet numpy h5py
command -v hyperfine >/dev/null || { apt-get install -y hyperfine >/dev/null 2>&1 || cargo install --locked hyperfine; }
[ -x /usr/bin/time ] || apt-get install -y time >/dev/null
mkdir -p "$dir"
[ -f "$dir/bench.csv" ] || python3 tools/reference/sgl_h5.py "$dir"
cargo build --release -p aeromag-io --example read_fields
bin=target/release/examples/read_fields
fields="tt mag_1_uc flux_b_z ins_lat"
hyperfine --warmup 1 --runs 5 --export-markdown "$dir/hdf5_vs_csv.md" \
    "$bin $dir/bench_contig.h5 $fields" \
    "$bin $dir/bench_gzip.h5 $fields" \
    "$bin $dir/bench.csv $fields"
for f in bench_contig.h5 bench_gzip.h5 bench.csv; do
    rss=$(/usr/bin/time -v "$bin" "$dir/$f" $fields 2>&1 >/dev/null | awk '/Maximum resident/ {print $6}')
    echo "$f: peak RSS ${rss} kB (4 fields x 10^6 f64 = 32 000 kB)"
done
