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
phase() { echo "== $1 (${SECONDS}s since start)" >&2; }
# GDAL's gdalinfo checks the grid files (GeoTIFF GeoKeys, ESRI ASCII, netCDF)
# in aeromag-grid's tests: Debian's gdal-bin, installed in the background
# while the tests build (the test says SKIPPED when it is missing).
gdal_install=""
if ! command -v gdalinfo >/dev/null 2>&1 && command -v apt-get >/dev/null 2>&1; then
    echo "gdalinfo not found; installing Debian's gdal-bin for the grid-file tests" >&2
    (apt-get install -y --no-install-recommends gdal-bin >/dev/null 2>&1 \
        || { apt-get update >/dev/null 2>&1 && apt-get install -y --no-install-recommends gdal-bin >/dev/null 2>&1; } \
        || echo "could not install gdal-bin; the gdalinfo test will be skipped" >&2) &
    gdal_install=$!
fi
cargo nextest run --workspace --release --no-run "$@"
[ -n "$gdal_install" ] && wait "$gdal_install"
phase "tests built"
cargo nextest run --workspace --release --no-fail-fast "$@"
phase "Rust tests done"
# nextest does not run doc tests
cargo test --workspace --release --doc
phase "doc tests done"
# The Python package: built once (release, the workspace's target folder)
# and installed into this Python, then its tests (pytest), which compare
# with the CLI binary the Rust tests built.
export PIP_ROOT_USER_ACTION=ignore
missing=$(python3 - <<'PY'
import importlib.util
def missing(mod):
    try:
        return importlib.util.find_spec(mod) is None
    except ModuleNotFoundError:
        return True
print(" ".join(spec for spec, mod in [("maturin", "maturin"), ("pytest", "pytest"), ("pandas", "pandas"),
                                      ("dask[distributed]", "dask.distributed"), ("mypy", "mypy"),
                                      # the interchange tests with these libraries (skipped without them)
                                      ("polars", "polars"), ("xarray", "xarray"), ("harmonica", "harmonica")]
               if missing(mod)))
PY
)
if [ -n "$missing" ]; then
    echo "installing $missing from PyPI for the Python package and its tests" >&2
    # shellcheck disable=SC2086
    python3 -m pip install --quiet $missing
fi
python3 -m pip install --quiet --no-build-isolation ./python
phase "Python package built"
AEROMAG_BIN="$PWD/target/release/aeromag" python3 -m pytest -q python/tests
phase "Python tests done"
