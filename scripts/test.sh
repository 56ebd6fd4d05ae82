#!/usr/bin/env bash
# The whole test suite, as CI runs it. Heavy numerics are tested in release mode.
set -euo pipefail
cd "$(dirname "$0")/.."
# insta locates snapshots from the workspace root; say it rather than have it ask cargo.
export INSTA_WORKSPACE_ROOT="$PWD"
# Property tests draw from a fixed seed, so a run is reproducible (override to explore).
export PROPTEST_RNG_SEED="${PROPTEST_RNG_SEED:-20261122}"
if ! cargo nextest --version >/dev/null 2>&1; then
    echo "cargo-nextest not found; installing it from crates.io" >&2
    cargo install --locked cargo-nextest
fi
cargo nextest run --workspace --release --no-fail-fast "$@"
# nextest does not run doc tests
cargo test --workspace --release --doc
