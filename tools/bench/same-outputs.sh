#!/usr/bin/env bash
# The outputs of two aeromag binaries on the peers' generated flights,
# compared byte for byte (issue 24: "the commands' outputs compared for
# equality before and after"): the model files, compensated flights and
# printed output of
#   - calibrate with the MagNav settings (the peers' comparison),
#   - calibrate with the defaults (lines split, the eddy-lag search),
#   - compensate with each of those models (each binary with its own),
#     and compensate --causal,
#   - em detect on simulated records (10.24 s and 102.4 s, one with
#     impulsive spikes injected) with the default and other windows,
#     without the pilots and with the system given.
# Prints one line per case and exits 1 when any differs.
#
# Usage: tools/bench/same-outputs.sh OLD_AEROMAG [NEW_AEROMAG] [N …]
#   OLD_AEROMAG  a binary of the commit to compare against, e.g.
#                git worktree add /tmp/old BASE &&
#                cargo build --release --manifest-path /tmp/old/Cargo.toml
#                (then /tmp/old/target/release/aeromag)
#   NEW_AEROMAG  default target/release/aeromag
#   N …          flight sizes (default 100000 1000000): the flights of
#                tools/bench/peers.sh in target/bench-peers, generated with
#                its virtual environment when missing
set -euo pipefail
cd "$(dirname "$0")/../.."
[ $# -ge 1 ] || { sed -n '2,20p' "$0" | sed 's/^# \{0,1\}//'; exit 2; }
old=$(realpath "$1")
shift
new=$PWD/target/release/aeromag
if [ $# -gt 0 ] && [ -x "$1" ] && [ ! -d "$1" ]; then
    new=$(realpath "$1")
    shift
fi
sizes=("$@")
[ ${#sizes[@]} -gt 0 ] || sizes=(100000 1000000)
for b in "$old" "$new"; do
    [ -x "$b" ] || { echo "not an executable: $b" >&2; exit 2; }
done
dir=target/bench-peers
out=$dir/same-outputs
rm -rf "$out"
mkdir -p "$out/old" "$out/new"
magnav="--terms p3,i6,e9 --convention magnav --eddy-lag none --reference none --no-split-lines"
differ=0
# Runs `aeromag ARGS` with both binaries (each writing into its own folder:
# @ in ARGS stands for it) and compares what they wrote and printed.
same() {
    local case=$1
    shift
    for side in old new; do
        local bin=$old
        [ $side = new ] && bin=$new
        local args=("${@//@/$out/$side}")
        "$bin" "${args[@]}" >"$out/$side/$case.stdout" 2>"$out/$side/$case.stderr" || {
            echo "$case: $side exits $? (see $out/$side/$case.stderr)"
            differ=1
            return
        }
        # The printed paths name the side's folder: the same text otherwise.
        sed -i "s#$out/$side#OUT#g" "$out/$side/$case.stdout" "$out/$side/$case.stderr"
    done
    local bad=() file
    for file in "$out/old/$case".*; do
        cmp -s "$file" "$out/new/${file##*/}" || bad+=("${file##*/}")
    done
    if [ ${#bad[@]} -eq 0 ]; then
        echo "$case: identical ($(cd "$out/old" && ls "$case".* | tr '\n' ' '))"
    else
        echo "$case: DIFFERS: ${bad[*]}"
        differ=1
    fi
}
for n in "${sizes[@]}"; do
    f=$PWD/$dir/flight-$n.csv
    if [ ! -f "$f" ]; then
        py=target/bench-venv/bin/python
        [ -x "$py" ] || { echo "no $f: run tools/bench/peers.sh $n first" >&2; exit 2; }
        "$py" tools/bench/peers.py gen "$n" "$f"
    fi
    # shellcheck disable=SC2086
    same "$n-calibrate-magnav" calibrate -i "$f" $magnav --model @/$n-calibrate-magnav.json
    same "$n-calibrate-defaults" calibrate -i "$f" --model @/$n-calibrate-defaults.json
    same "$n-compensate-magnav" compensate -i "$f" --model @/$n-calibrate-magnav.json --out @/$n-compensate-magnav.csv
    same "$n-compensate-defaults" compensate -i "$f" --model @/$n-calibrate-defaults.json --out @/$n-compensate-defaults.csv
    same "$n-compensate-causal" compensate --causal -i "$f" --model @/$n-calibrate-defaults.json --out @/$n-compensate-causal.csv
done
# EM records, simulated once (by the new binary) for both.
em=$out/em
"$new" em simulate --out "$em/short" >/dev/null
"$new" em simulate --print-config | sed 's/^duration_s = .*/duration_s = 102.4/' >"$out/long.toml"
"$new" em simulate --config "$out/long.toml" --out "$em/long" >/dev/null
# 408 runs of 1 to 600 samples far outside the tones (0.05–1 kV).
python3 - "$em/short/em.raw" "$em/spikes.raw" <<'PY'
import random, struct, sys
data = bytearray(open(sys.argv[1], "rb").read())
frames = 1024000
body = len(data) - frames * 12
rng = random.Random(3)
for _ in range(408):
    f, c = rng.randrange(frames - 700), rng.randrange(3)
    for j in range(rng.choice([1, 1, 2, 5, 30, 600])):
        struct.pack_into("<f", data, body + ((f + j) * 3 + c) * 4, rng.choice([-1, 1]) * rng.uniform(50, 1000))
open(sys.argv[2], "wb").write(data)
PY
same em-detect em detect "$em/short/em.raw" --out @/em-detect.csv
same em-detect-long em detect "$em/long/em.raw" --out @/em-detect-long.csv
same em-detect-spikes em detect "$em/spikes.raw" --out @/em-detect-spikes.csv
same em-detect-nuttall em detect "$em/short/em.raw" --window nuttall --window-len 8000 --out @/em-detect-nuttall.csv
same em-detect-off-grid em detect "$em/short/em.raw" --window-len 10000 --out @/em-detect-off-grid.csv
same em-detect-no-pilot em detect "$em/short/em.raw" --no-pilot --out @/em-detect-no-pilot.csv
same em-detect-system em detect "$em/short/em.raw" --system "$em/short/em.system.json" --out @/em-detect-system.csv
exit $differ
