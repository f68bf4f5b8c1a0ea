#!/usr/bin/env bash
# bench/run.sh — build the native benchmark and regenerate every figure:
#   bench/results/native.json     timings (cloudgen_bench: samples/s, bakes, previews)
#   bench/results/callgrind.json  instructions per sample (valgrind --tool=callgrind)
#   bench/results/machine.json    CPU, cores, memory, compiler, load
#   docs/benchmarks.md            the tables between its "generated" markers
#
# Usage: bench/run.sh [--reps N] [--no-callgrind] [--quick]
#   --quick  a smoke run (few reps, small sizes) into a temporary directory;
#            bench/results and the report are left alone.
# Environment: CLOUDGEN_BENCH_BUILD_DIR (default: build) — the CMake build directory.
# Nothing here asserts a time: these are measurements, not tests.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
export PATH="$root/.venv/bin:$PATH"
build=${CLOUDGEN_BENCH_BUILD_DIR:-build}
python=python3
[ -x "$root/.venv/bin/python" ] && python="$root/.venv/bin/python"

reps=7
callgrind=1
quick=0
while [ $# -gt 0 ]; do
  case "$1" in
    --reps) reps=$2; shift 2 ;;
    --no-callgrind) callgrind=0; shift ;;
    --quick) quick=1; shift ;;
    -h|--help) sed -n '2,13p' "$0"; exit 0 ;;
    *) echo "bench/run.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done

# ---- build (configure only when the build directory is not configured yet) ----
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release
elif grep -q '^CLOUDGEN_WITH_BENCH:BOOL=OFF' "$build/CMakeCache.txt"; then
  cmake -S . -B "$build" -DCLOUDGEN_WITH_BENCH=ON
fi
cmake --build "$build" --target cloudgen_bench
bench="$build/bin/cloudgen_bench"

if [ "$quick" = 1 ]; then
  out=$(mktemp -d)
  "$bench" --quick --json "$out/native.json"
  if [ "$callgrind" = 1 ] && command -v valgrind >/dev/null; then
    "$python" bench/report.py callgrind "$bench" "$out/callgrind.json" --samples 2000 --kernels defaults:full
  fi
  echo "quick run: results in $out (bench/results and docs/benchmarks.md untouched)"
  exit 0
fi

mkdir -p bench/results
"$python" bench/report.py machine bench/results/machine.json --build "$build"

# ---- timings: write to a temporary file so a failed run keeps the old numbers ----
"$bench" --reps "$reps" --json bench/results/native.json.tmp
mv bench/results/native.json.tmp bench/results/native.json

# ---- instructions per sample ----
if [ "$callgrind" = 1 ]; then
  if ! command -v valgrind >/dev/null; then
    if [ "$(id -u)" = 0 ]; then sudo=""; else sudo="sudo"; fi
    $sudo apt-get install -y valgrind || { $sudo apt-get update && $sudo apt-get install -y valgrind; }
  fi
  "$python" bench/report.py callgrind "$bench" bench/results/callgrind.json  # written atomically
fi

# ---- the report ----
"$python" bench/report.py render docs/benchmarks.md
echo "bench/run.sh: wrote bench/results/*.json and docs/benchmarks.md"
