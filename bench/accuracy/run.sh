#!/bin/sh
# Accuracy sweep: regenerates bench/results/accuracy.json (cached points are
# not re-measured; see bench/accuracy/sweep.py), the matched errors, the tiers'
# figures and the report (docs/accuracy.md, bench/accuracy/report.py).
#   bench/accuracy/run.sh [--quick] [--scenes a,b] [--knobs x,y] [--force] [--runs N]
# --quick: a smoke run into a temporary directory (results and docs untouched).
set -eu
cd "$(dirname "$0")/../.."
PY=.venv/bin/python
[ -x build/bin/cloudgen ] || { echo "run.sh: build/bin/cloudgen missing (build the project first)" >&2; exit 2; }
quick=0
for a in "$@"; do [ "$a" = "--quick" ] && quick=1; done
if [ "$quick" = 1 ]; then
    out=$(mktemp -d "${TMPDIR:-/tmp}/cloudgen-accuracy-XXXXXX")
    status=0
    "$PY" bench/accuracy/sweep.py --out "$out" "$@" || status=$?
    if [ -f "$out/accuracy.json" ]; then
        "$PY" bench/accuracy/report.py --results "$out/accuracy.json" --docs "$out/accuracy.md" \
            --images "$out/images_report" || status=$?
    fi
    echo "run.sh: quick results in $out"
    exit $status
fi
status=0
"$PY" bench/accuracy/sweep.py "$@" || status=$?
# matched-seed errors into the cache, then accuracy.json again from the whole cache
"$PY" bench/accuracy/matched.py || status=$?
"$PY" bench/accuracy/sweep.py --results-only || status=$?
# the tiers' measured figures into native/presets/tiers.json (rebuild to ship them in the CLI and module)
"$PY" bench/accuracy/tiers_update.py || status=$?
"$PY" bench/accuracy/report.py || status=$?
exit $status
