#!/usr/bin/env bash
# All the tests: set up (with the test-only packages), the native tests
# (ctest), the same native tests under AddressSanitizer + UBSan in a second
# build directory, the Python tests (pytest: module, CLI, round trips) and the
# Blender tests (pytest inside the bpy wheel: OSL shaders, parity, render, the add-on),
# the distributed-bake tests (Dask), the lint (scripts/lint.sh) and the Blender
# tests again in Blender 5.0 (scripts/test_blender5.sh): CI runs 3.4, 4.5 and 5.0.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
scripts/setup.sh --tests
export PATH="$root/.venv/bin:$PATH"

echo "== lint (ruff, clang-format, no pointers outside the repo)"
scripts/lint.sh

echo "== native tests (build/)"
ctest --test-dir build --output-on-failure --parallel "$(nproc)"

echo "== native tests under ASan+UBSan (build-sanitize/)"
if [[ ! -f build-sanitize/CMakeCache.txt ]]; then
  cmake -S . -B build-sanitize -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCLOUDGEN_SANITIZE=ON \
    -DCLOUDGEN_WITH_IO=OFF -DCLOUDGEN_WITH_PYTHON=OFF -DCLOUDGEN_WITH_BENCH=OFF >/dev/null
fi
cmake --build build-sanitize --parallel "$(nproc)" | grep -vE '^\[[0-9]+/[0-9]+\] ' || true
test "${PIPESTATUS[0]}" -eq 0
ASAN_OPTIONS=detect_leaks=1:halt_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  CLOUDGEN_TEST_SCALE=sanitize ctest --test-dir build-sanitize --output-on-failure --parallel "$(nproc)"

echo "== Python tests (module, CLI, round trips), Blender tests (bpy 4.5: OSL, parity, render, add-on, bake) and batch tests (Debian Blender 3.4)"
CLOUDGEN_REQUIRE_BLENDER=1 CLOUDGEN_REQUIRE_BPY=1 python -m pytest -q tests/python tests/bench tests/blender tests/addon tests/addon_bake tests/batch

echo "== distributed bakes (a Dask LocalCluster of 2 worker processes on loopback)"
python -m pytest -q tests/distributed

echo "== Blender 5.0 (bpy 5.0 in .venv-blender5): OSL, parity, render, add-on, bake"
scripts/test_blender5.sh
