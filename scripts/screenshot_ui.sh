#!/usr/bin/env bash
# Screenshot of the artist's view: Debian's Blender 3.4 (full GUI) under Xvfb with
# software OpenGL, the packaged add-on enabled, a cumulus added, node groups in the
# shader editor and the Cloud sidebar tab with the live preview.
# Usage: scripts/screenshot_ui.sh [OUTPUT.png]   (default docs/images/blender_ui.png)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
out="$(realpath -m "${1:-docs/images/blender_ui.png}")"
missing=()
for p in blender xvfb xauth libgl1-mesa-dri xdotool; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then apt-get update -q && DEBIAN_FRONTEND=noninteractive apt-get install -y -q "${missing[@]}"; fi
test -d build/addon/cloudgen || scripts/setup.sh
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/scripts/addons" "$tmp/config"
ln -s "$root/build/addon/cloudgen" "$tmp/scripts/addons/cloudgen"
# The Cloud tab sits at the right edge of the 3D view's sidebar; the click position was
# read off a first screenshot of this 1600x900 layout; then the sidebar is scrolled
# (600 px) down to the preview.
BLENDER_USER_SCRIPTS="$tmp/scripts" BLENDER_USER_CONFIG="$tmp/config" \
  xvfb-run -a -s "-screen 0 1600x900x24" \
  blender --factory-startup -P scripts/screenshot_ui.py -- "$out" ${CLOUDGEN_TAB_CLICK:-1308 244 600}
echo "wrote $out"
