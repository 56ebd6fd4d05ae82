#!/usr/bin/env bash
# Peak memory of the CSV and XYZ readers on hostile files (issue 18, point 6):
# a line of SIZE_MB (default 1024) megabytes, with and without separators, a
# quoted field that never closes, a header of 10^6 columns, a header at the
# column limit (10^5) with data rows, and many comment lines before the data
# of an XYZ file. Each file is read by the `peak_mem` example of aeromag-io
# under `/usr/bin/time -v`; the script prints the reader's answer (the error
# for the rejected files) and the maximum resident set size.
#
#   scripts/hostile_inputs.sh [SIZE_MB]
#
# Needs about SIZE_MB of free space in $TMPDIR (the files are removed).
# Too slow for the test suite; crates/io/tests/limits.rs checks the limits
# themselves on smaller files.
set -eu  # no pipefail: `yes | head` ends by SIGPIPE
cd "$(dirname "$0")/.."
size_mb=${1:-1024}
[ -x /usr/bin/time ] || { echo "needs /usr/bin/time (apt-get install time)" >&2; exit 2; }
cargo build --release -q -p aeromag-io --example peak_mem
bin=${CARGO_TARGET_DIR:-target}/release/examples/peak_mem
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT

measure() {
    local label=$1 file=$2
    local bytes rss out
    bytes=$(stat -c %s "$file")
    out=$(/usr/bin/time -v "$bin" read "$file" 2>"$dir/time.txt" || true)
    rss=$(awk -F': ' '/Maximum resident set size/ {print $2}' "$dir/time.txt")
    msg=$(grep -m1 -E '^(error|thread|memory)' "$dir/time.txt" | cut -c1-200 || true)
    printf '%-44s file %8.1f MB  peak RSS %8.1f MB  %s\n' "$label" \
        "$(echo "$bytes / 1000000" | bc -l)" "$(echo "$rss / 1000" | bc -l)" "${out:-$msg}"
    rm -f "$file"
}

# A line of N MB: "time,mag\n0," then N MB of digits, no line end.
long_line() {
    local sep=$1 file=$2
    { printf 'time%smag\n0%s' "$sep" "$sep"; head -c "$((size_mb * 1000000))" /dev/zero | tr '\0' '1'; } >"$file"
}
long_line , "$dir/line.csv"
measure "CSV: one ${size_mb} MB field" "$dir/line.csv"
{ printf 'time,mag\n'; head -c "$((size_mb * 1000000))" /dev/zero | tr '\0' ','; } >"$dir/commas.csv"
measure "CSV: one ${size_mb} MB line of commas" "$dir/commas.csv"
{ printf 'time,mag\n0,"'; yes 'x' | head -c "$((size_mb * 1000000))"; } >"$dir/quote.csv"
measure "CSV: unclosed quote, ${size_mb} MB of lines" "$dir/quote.csv"
long_line ' ' "$dir/line.txt"
measure "whitespace table: one ${size_mb} MB token" "$dir/line.txt"
{ printf '/ time mag\n'; yes '0 1' | head -c "$((size_mb * 1000000))" | tr '\n' ' '; } >"$dir/line.xyz"
measure "XYZ: one ${size_mb} MB data line of tokens" "$dir/line.xyz"
{ yes '/ a b c d e f g h i j k l m n o p q r s t u v w x y z' | head -c "$((size_mb * 1000000))"; printf '\n/ time mag\n0 1\n'; } >"$dir/comments.xyz"
measure "XYZ: ${size_mb} MB of comment lines, then data" "$dir/comments.xyz"

python3 - "$dir" <<'PY'
import sys
d = sys.argv[1]
n = 10**6
with open(f"{d}/wide.csv", "w") as f:
    f.write(",".join(f"c{i}" for i in range(n)) + "\n")
    f.write(",".join("1" for _ in range(n)) + "\n")
with open(f"{d}/wide.xyz", "w") as f:
    f.write("/ " + " ".join(f"c{i}" for i in range(n)) + "\n")
    f.write(" ".join("1" for _ in range(n)) + "\n")
m = 100_000
with open(f"{d}/limit.csv", "w") as f:
    f.write(",".join(f"c{i}" for i in range(m)) + "\n")
    for r in range(10):
        f.write(",".join(str(r) for _ in range(m)) + "\n")
PY
measure "CSV: header of 10^6 columns + 1 row" "$dir/wide.csv"
measure "XYZ: header of 10^6 columns + 1 row" "$dir/wide.xyz"
measure "CSV: 10^5 columns (the limit) x 10 rows" "$dir/limit.csv"
