#!/usr/bin/env bash
# All the tests: set up (with the test-only packages), the native tests
# (ctest), the same native tests plus the CLI and file-reading tests under
# AddressSanitizer + UBSan in a second build directory, the libFuzzer targets
# (tests/fuzz, a fixed budget), the Python tests (pytest: module, CLI, round trips),
# the Blender tests (pytest inside the bpy wheel: OSL shaders, parity, render, the add-on),
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

echo "== native tests, the CLI and the file readers under ASan+UBSan (build-sanitize/)"
# The CLI, the OpenVDB/OIIO I/O and the Python module are built too (docs/hostile_inputs.md).
# GCC's UBSan does not check float->int overflow unless named (CMakeLists.txt does).
if [[ ! -f build-sanitize/CMakeCache.txt ]] || ! grep -q '^CLOUDGEN_WITH_IO:BOOL=ON' build-sanitize/CMakeCache.txt \
   || ! grep -q '^CLOUDGEN_WITH_PYTHON:BOOL=ON' build-sanitize/CMakeCache.txt; then
  cmake -S . -B build-sanitize -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCLOUDGEN_SANITIZE=ON \
    -DCLOUDGEN_WITH_IO=ON -DCLOUDGEN_WITH_PYTHON=ON -DPython3_EXECUTABLE="$root/.venv/bin/python" \
    -DCLOUDGEN_WITH_BENCH=OFF >/dev/null
fi
# (not `| grep ... || true`: after `|| true`, PIPESTATUS no longer holds the build's status)
cmake --build build-sanitize --parallel "$(nproc)" >build-sanitize.log 2>&1 \
  || { tail -n 40 build-sanitize.log; echo "build-sanitize: the build failed"; exit 1; }
export ASAN_OPTIONS=detect_leaks=1:halt_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
CLOUDGEN_TEST_SCALE=sanitize ctest --test-dir build-sanitize --output-on-failure --parallel "$(nproc)"
# The CLI and file-reading tests with the sanitized binary: any report fails them
# (a report makes the CLI exit non-zero with more than one line on stderr).
CLOUDGEN_BIN="$root/build-sanitize/bin/cloudgen" CLOUDGEN_SANITIZED=1 CLOUDGEN_HOSTILE_EVERY=16 \
  python -m pytest -q -p no:cacheprovider tests/python/test_hostile_vdb.py tests/python/test_hostile_json.py \
  tests/python/test_hostile_sizes.py tests/python/test_hostile_faults.py tests/python/test_cli.py
# The module inside the venv's Python, the sanitizer runtimes preloaded; no leak
# check (the interpreter itself keeps memory at exit) and no RSS-growth test
# (ASan's quarantine holds freed memory on purpose).
preload="$(gcc -print-file-name=libasan.so) $(gcc -print-file-name=libubsan.so)"
LD_PRELOAD="$preload" ASAN_OPTIONS=detect_leaks=0:halt_on_error=1 \
  CLOUDGEN_PYTHON_DIR="$root/build-sanitize/python" python -m pytest -q -p no:cacheprovider \
  tests/python/test_module.py tests/python/test_module_hostile.py tests/python/test_module_keys.py \
  -k "not test_no_reference_leaks"
unset ASAN_OPTIONS UBSAN_OPTIONS

echo "== fuzz targets: regressions, then 4000 inputs each with a fixed seed (build-fuzz/, clang)"
tests/fuzz/run.sh 4000

echo "== Python tests (module, CLI, round trips), Blender tests (bpy 4.5: OSL, parity, render, add-on, bake) and batch tests (Debian Blender 3.4)"
CLOUDGEN_REQUIRE_BLENDER=1 CLOUDGEN_REQUIRE_BPY=1 python -m pytest -q tests/python tests/bench tests/blender tests/addon tests/addon_bake tests/batch

echo "== distributed bakes (a Dask LocalCluster of 2 worker processes on loopback)"
python -m pytest -q tests/distributed

echo "== Blender 5.0 (bpy 5.0 in .venv-blender5): OSL, parity, render, add-on, bake"
scripts/test_blender5.sh
