#!/usr/bin/env bash
# Installs what cloudgen needs and builds it — idempotent: a second run only
# checks and rebuilds what changed.
#   Debian packages   (apt-get, only those missing)
#   .venv             Python virtual environment made with the python3 on PATH,
#                     with cmake, ninja, numpy, pytest and bpy (Blender 4.5 as a
#                     module, with OSL); cloudgen_native and oslquery on its path
#   build/            Release build: core, CLI (build/bin/cloudgen), Python module
# Usage: scripts/setup.sh [--tests]   (--tests also installs what only the tests need)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"

want_tests=0
[[ "${1:-}" == "--tests" ]] && want_tests=1

log() { printf '[setup] %s\n' "$*"; }

# ---- Debian packages -------------------------------------------------------
apt_packages=(g++ make pkg-config libopenvdb-dev libopenimageio-dev libboost-iostreams-dev
              nlohmann-json3-dev libgtest-dev)
if ((want_tests)); then
  # blender: Debian's 3.4 binary loads our VDBs in a test (it has no OSL); its Python needs numpy, and
  # python3-openvdb (pyopenvdb) is how the add-on writes VDBs inside that Blender
  apt_packages+=(blender python3-numpy python3-openvdb)
  # clang and its runtime (libFuzzer): the fuzz targets of tests/fuzz
  apt_packages+=(clang libclang-rt-14-dev)
  # xvfb, xauth, Mesa's software OpenGL and xdotool (a real key press): Debian's Blender 3.4 with
  # its window (tests/batch/test_gui34.py)
  apt_packages+=(xvfb xauth libgl1-mesa-dri xdotool)
fi
missing=()
for p in "${apt_packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  log "installing Debian packages: ${missing[*]}"
  sudo_cmd=()
  [[ $(id -u) -ne 0 ]] && sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -q
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# ---- Python environment ----------------------------------------------------
if [[ ! -x .venv/bin/python ]]; then
  log "creating .venv with $(command -v python3) ($(python3 --version))"
  python3 -m venv .venv
fi
req_stamp=.venv/.cloudgen-requirements
if [[ ! -f $req_stamp ]] || ! cmp -s requirements.txt "$req_stamp"; then
  log "installing Python packages (requirements.txt)"
  .venv/bin/python -m pip install -q --upgrade pip
  .venv/bin/python -m pip install -q -r requirements.txt
  cp requirements.txt "$req_stamp"
fi
# cloudgen_native is importable from the venv through a .pth file naming build/python
site=$(.venv/bin/python -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')
echo "$root/build/python" > "$site/cloudgen_native_build.pth"
# python -m cloudgen_dask (distributed bakes) runs from this checkout
echo "$root/distributed" > "$site/cloudgen_dask_checkout.pth"
# cycles.osl.update_script_node() imports `oslquery`, which the bpy wheel keeps in
# Blender's bundled site-packages, off sys.path: make it importable for every user
# of the venv (appended after the venv's own packages, so it shadows nothing).
bundled=$(ls -d "$site"/bpy/*/python/lib/python3.*/site-packages 2>/dev/null | head -n 1 || true)
if [[ -n "$bundled" ]]; then
  echo "$bundled" > "$site/cloudgen_bpy_oslquery.pth"
fi

# ---- build -----------------------------------------------------------------
export PATH="$root/.venv/bin:$PATH"
if [[ ! -f build/CMakeCache.txt ]]; then
  log "configuring build/"
  cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DPython3_EXECUTABLE="$root/.venv/bin/python" >build-configure.log 2>&1 \
    || { cat build-configure.log; exit 1; }
fi
log "building (build/)"
cmake --build build --parallel "$(nproc)" | grep -vE '^\[[0-9]+/[0-9]+\] ' || true
test "${PIPESTATUS[0]}" -eq 0
log "packaging the Blender add-on (build/addon/cloudgen, build/cloudgen-addon.zip)"
python scripts/package_addon.py >/dev/null
log "ready: build/bin/cloudgen, .venv/bin/python -c 'import cloudgen_native'"
