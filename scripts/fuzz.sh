#!/usr/bin/env bash
# Coverage-guided fuzzing of the file readers (cargo-fuzz / libFuzzer).
#
#   scripts/fuzz.sh TARGET SECONDS [MAX_EXECS]   one target
#   scripts/fuzz.sh all SECONDS [MAX_EXECS]      every target in turn, SECONDS each
#   scripts/fuzz.sh list                         the targets
#
# Stops after SECONDS or MAX_EXECS executions (default 10 million), whichever
# comes first. Crashes, panics, timeouts and out-of-memory inputs are saved to
# fuzz/artifacts/TARGET/; the growing corpus lives in fuzz/corpus/TARGET/
# (only the seed-* files are committed). See fuzz/README.md.
#
# cargo-fuzz needs nightly-only rustc flags; on a stable toolchain the script
# sets RUSTC_BOOTSTRAP=1. Extra libFuzzer flags: FUZZ_FLAGS="-jobs=2 ...".
# Sanitizer: FUZZ_SANITIZER (default none: the readers are safe Rust; use
# `address` to look at the unsafe code of dependencies).
set -euo pipefail
cd "$(dirname "$0")/.."

TARGETS=(csv xyz model_json scenario_toml em_raw hdf5 mat grid)

usage() {
    sed -n '2,7p' "$0" | sed 's/^# \{0,1\}//' >&2
    exit 2
}

[ $# -ge 1 ] || usage
if [ "$1" = list ]; then
    printf '%s\n' "${TARGETS[@]}"
    exit 0
fi
[ $# -ge 2 ] || usage
target=$1
seconds=$2
max_execs=${3:-10000000}

if ! cargo fuzz --version >/dev/null 2>&1; then
    echo "cargo-fuzz not found; installing it from crates.io" >&2
    cargo install --locked cargo-fuzz
fi
if ! rustc --version | grep -q nightly; then
    export RUSTC_BOOTSTRAP=1
fi
sanitizer=${FUZZ_SANITIZER:-none}

# Longest input per target: the hostile sizes (a 1 GB line, 10^6 columns)
# are checked by scripts/hostile_inputs.sh instead; here inputs stay small
# so that executions are fast.
max_len() {
    case $1 in
        csv | xyz | hdf5 | mat | grid) echo 65536 ;;
        em_raw) echo 16384 ;;
        *) echo 32768 ;;
    esac
}

run_one() {
    local t=$1
    mkdir -p "fuzz/artifacts/$t" "fuzz/corpus/$t"
    echo "== fuzz $t: ${seconds}s or ${max_execs} executions" >&2
    (
        cd fuzz
        # shellcheck disable=SC2086
        cargo fuzz run -s "$sanitizer" --codegen-units 16 "$t" "corpus/$t" -- \
            -max_total_time="$seconds" -runs="$max_execs" \
            -rss_limit_mb=2048 -malloc_limit_mb=2048 -timeout=10 \
            -max_len="$(max_len "$t")" -print_final_stats=1 \
            -artifact_prefix="artifacts/$t/" ${FUZZ_FLAGS:-}
    )
}

status=0
if [ "$target" = all ]; then
    for t in "${TARGETS[@]}"; do
        run_one "$t" || status=1
    done
else
    printf '%s\n' "${TARGETS[@]}" | grep -qx "$target" || {
        echo "unknown target '$target' (scripts/fuzz.sh list)" >&2
        exit 2
    }
    run_one "$target" || status=1
fi
# Scratch files of fuzzing processes that have ended (see fuzz/src/lib.rs).
for d in /dev/shm/aeromag-fuzz-*; do
    [ -d "$d" ] || continue
    kill -0 "${d##*-}" 2>/dev/null || rm -rf "$d"
done
exit $status
