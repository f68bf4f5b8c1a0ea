#!/usr/bin/env bash
# The main job: set up, then render the default cumulus procedurally with the
# OSL shaders in Cycles (out/cumulus.png), bake it to out/cumulus.vdb and write
# its cross-section preview out/cumulus_slice.png.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
scripts/setup.sh
mkdir -p out
.venv/bin/python scripts/render_cloud.py --preset cumulus --output out/cumulus.png
build/bin/cloudgen bake --preset cumulus --resolution 128 --output out/cumulus.vdb
build/bin/cloudgen preview --preset cumulus --axis y --offset 0.5 --size 512 --output out/cumulus_slice.png
