#!/usr/bin/env bash
# Installs what the tests need and runs every test: Rust checks and tests,
# then the release wheel and pytest. Used by the README and by .ci/run.
set -euo pipefail
cd "$(dirname "$0")/.."

echo "== cargo fmt"
cargo fmt --all -- --check
echo "== function length (docs/architecture.md: none over 80 lines)"
python3 scripts/long_functions.py 80
echo "== cargo clippy"
cargo clippy --workspace --all-targets -- -D warnings
echo "== cargo test"
# ballcage-py holds no Rust tests (pytest tests it through the wheel below), so
# its debug build (pyo3, arrow's kernels, numpy) is left out; clippy checks it.
cargo test --workspace --exclude ballcage-py
FUZZ_SECONDS=30 bash scripts/fuzz-ci.sh  # cargo-fuzz targets of fuzz/ (stable, RUSTC_BOOTSTRAP=1): replays fuzz/regressions, then 30 s each
echo "== pip install .[test] (release build of the wheel)"
python3 -m pip install --quiet ".[test]"
echo "== the test-panic build (tests/test_panic.py; never shipped)"
# The extension with cargo feature `test-panic` (a panic injected into Simulation.advance), installed into a
# side directory that tests/test_panic.py puts first on PYTHONPATH of its subprocesses.
rm -rf target/wheels-test-panic target/ballcage-test-panic
maturin build --quiet --release --features test-panic -o target/wheels-test-panic
python3 -m pip install --quiet --no-deps --target target/ballcage-test-panic target/wheels-test-panic/*.whl
export BALLCAGE_TEST_PANIC_PATH="$PWD/target/ballcage-test-panic"
echo "== stubtest (python/ballcage/_native.pyi against the built module)"
python3 -m mypy.stubtest ballcage._native --mypy-config-file pyproject.toml
echo "== chromium and ffmpeg (tests/test_view.py: the 3D view page in a real headless browser, the MP4 export)"
if ! command -v chromium >/dev/null || ! command -v ffmpeg >/dev/null; then
  as_root=""
  [ "$(id -u)" -eq 0 ] || as_root="sudo -n"
  if ! { $as_root apt-get update -qq && $as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium ffmpeg; }; then
    echo "could not install Debian's chromium and ffmpeg as $(id -un): the browser and MP4 tests of" \
      "tests/test_view.py will be skipped, each saying so (as root: apt-get install chromium ffmpeg)"
  fi
fi
echo "== pytest"
# The package source lives in python/, so the root is not on the import path
# as `ballcage`: pytest imports the installed wheel. Two workers (pytest-xdist),
# each test file on one of them so that a file's module fixtures run once:
# 3 min 31 s against 5 min 49 s serially (docs/architecture.md, "Test time").
status=0
python3 -m pytest -q -n 2 --dist loadfile || status=$?
if [ "$status" -eq 5 ]; then
  echo "pytest collected no tests"; exit 1
fi
exit "$status"
