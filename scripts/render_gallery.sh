#!/usr/bin/env bash
# Render every cloud type into docs/gallery/NAME.png (procedural OSL, Cycles CPU)
# and print each render time. Usage: scripts/render_gallery.sh [WxH] [SAMPLES] [OUTDIR] [NAME...]
# Defaults: 320x240, 64 spp, docs/gallery, every preset (see `cloudgen presets`).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
size="${1:-320x240}"; samples="${2:-64}"; outdir="${3:-$root/docs/gallery}"
shift $(( $# < 3 ? $# : 3 ))
python="$root/.venv/bin/python"
if [ $# -gt 0 ]; then
  names=("$@")
else
  mapfile -t names < <("$python" -c 'import cloudgen_native as c; print("\n".join(c.presets()))')
fi
mkdir -p "$outdir"
for name in "${names[@]}"; do
  "$python" "$root/scripts/render_cloud.py" --preset "$name" --output "$outdir/$name.png" \
    --size "$size" --samples "$samples" --seed 0
done
