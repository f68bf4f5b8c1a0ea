#!/usr/bin/env bash
# The second environment: Blender 5.0 as a Python module (bpy 5.0.x, Python 3.11)
# in .venv-blender5, running the same Blender tests (OSL shaders, parity,
# reference render against ref_blender5.png) and the add-on tests (node groups,
# Add Cloud, preview, bake). scripts/test.sh (CI) runs it last. Needs scripts/setup.sh first
# (it uses build/python's cloudgen_native, the same abi3 module).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
scripts/setup.sh
if [[ ! -x .venv-blender5/bin/python ]]; then
  python3 -m venv .venv-blender5
fi
if ! .venv-blender5/bin/python -c 'import bpy, pytest' 2>/dev/null; then
  .venv-blender5/bin/python -m pip install -q "bpy>=5.0,<5.1" pytest
fi
site=$(.venv-blender5/bin/python -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')
echo "$root/build/python" > "$site/cloudgen_native_build.pth"
bundled=$(ls -d "$site"/bpy/*/python/lib/python3.*/site-packages 2>/dev/null | head -n 1 || true)
[[ -n "$bundled" ]] && echo "$bundled" > "$site/cloudgen_bpy_oslquery.pth"
CLOUDGEN_REQUIRE_BPY=1 .venv-blender5/bin/python -m pytest -q "$@" tests/blender tests/addon tests/addon_bake
