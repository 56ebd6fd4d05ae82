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
# The HDF5 whole-flight test writes its SGL-layout file with h5py
# (tools/reference/sgl_flight.py).
if ! python3 -c "import numpy, h5py" >/dev/null 2>&1; then
    echo "numpy/h5py not found; installing them from PyPI for the HDF5 tests" >&2
    python3 -m pip install --quiet --user numpy h5py || python3 -m pip install --quiet numpy h5py
fi
cargo nextest run --workspace --release --no-fail-fast "$@"
# nextest does not run doc tests
cargo test --workspace --release --doc
