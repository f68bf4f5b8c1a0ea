#!/usr/bin/env bash
# The libFuzzer targets of tests/fuzz: builds them (build-fuzz/, clang, ASan +
# UBSan), replays every committed regression input, then runs each target for
# a fixed number of inputs with a fixed seed from the committed seed corpus.
# Usage: tests/fuzz/run.sh [RUNS (default 4000)] [more libFuzzer options]
# Exit non-zero on the first crash, sanitizer report, leak, timeout or
# out-of-memory (the reproducer is written to build-fuzz/crashes/).
# The long run for people who want it: tests/fuzz/README.md.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
cd "$root"
runs="${1:-4000}"
shift || true
if [[ ! -f build-fuzz/CMakeCache.txt ]]; then
  CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCLOUDGEN_FUZZ=ON \
    -DCLOUDGEN_WITH_IO=OFF -DCLOUDGEN_WITH_PYTHON=OFF -DCLOUDGEN_WITH_BENCH=OFF -DCLOUDGEN_WITH_TESTS=OFF >/dev/null
fi
cmake --build build-fuzz --parallel "$(nproc)" --target fuzz_params fuzz_camera fuzz_sequence fuzz_vdb_header \
  >build-fuzz.log 2>&1 || { tail -n 40 build-fuzz.log; echo "tests/fuzz: the build failed"; exit 1; }
mkdir -p build-fuzz/crashes
export ASAN_OPTIONS=detect_leaks=1:halt_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
for t in params camera sequence vdb_header; do
  bin="build-fuzz/bin/fuzz_$t"
  regressions=(tests/fuzz/regressions/$t/*)
  if [[ -e "${regressions[0]}" ]]; then
    "$bin" -rss_limit_mb=2048 -timeout=20 "${regressions[@]}" >"build-fuzz/$t.regressions.log" 2>&1 \
      || { tail -n 40 "build-fuzz/$t.regressions.log"; echo "fuzz_$t: a regression input fails"; exit 1; }
  fi
  work="build-fuzz/corpus-$t"
  rm -rf "$work" && mkdir -p "$work"
  start=$(date +%s)
  "$bin" -seed=1 -runs="$runs" -max_len=16384 -rss_limit_mb=2048 -timeout=20 -malloc_limit_mb=1024 \
    -artifact_prefix="build-fuzz/crashes/$t-" "$@" "$work" "tests/fuzz/corpus/$t" >"build-fuzz/$t.log" 2>&1 \
    || { tail -n 40 "build-fuzz/$t.log"; echo "fuzz_$t: FAILED (reproducer in build-fuzz/crashes/)"; exit 1; }
  done_runs=$(grep -Eo 'Done [0-9]+ runs' "build-fuzz/$t.log" || echo "? runs")
  echo "fuzz_$t: ${#regressions[@]} regression inputs, $done_runs, 0 crashes ($(($(date +%s) - start)) s)"
done
