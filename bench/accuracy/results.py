"""<out>/accuracy.json, rewritten from the whole cache after every point (so an
interrupted run leaves valid results). Its schema (docs/accuracy.md is made from it):

  machine   common.machine_info() at the start of the run
  blender   {"4.5": version string, "5.0": ...} of the Blenders that rendered
  settings  image_size, runs_per_point, bake_runs, base_render, sweep_seed, quick, notes
  scenes    {scene: {preset, description, reference, reference_50 (when measured),
                     points: [one dict of POINT_KEYS per cached point, knob order then setting]}}

A reference has samples, step_rate, volume_biased, seeds, noise_rmse, noise_flip,
reference_rmse, render_s (best seed), render_s_all, peak_mib, image, mean_radiance,
load_before. Times are wall seconds, memory MiB; errors as in metrics.py.
"""
from __future__ import annotations

import json
import re

from common import write_json

from accuracy import scenes
from accuracy.knobs import KNOBS

NOTES = [
    "step_rate = scene.cycles.volume_step_rate (Render > Volume step rate), a factor on every "
    "material's step rate: procedural material = the preset's (cumulus/stratocumulus 0.2, cirrus 0.5) "
    "x 1/10 of the box's mean side; VDB material 1 x the voxel size (as the add-on's bake).",
    "Base render of every swept point: render_cloud.py's defaults (64 spp, step rate 1), seed 0; "
    "Cycles CPU, 2 threads, denoising off. Procedural renders use OSL; VDB renders use SVM "
    "(no script nodes needed).",
    "render_s: wall time of bpy.ops.render.render only (no bpy import, no scene build), best of "
    "runs_per_point; bake_s: wall time of `cloudgen bake --quiet` (process start and VDB write "
    "included), best of bake_runs; peak_mib: peak RSS of the render process (os.wait4); "
    "bake_peak_mib: of the bake process.",
    "Field errors: 20000 uniform points in the box (fixed seed); a bake's value is the trilinear "
    "interpolation of its voxel-centre values (density with footprint = voxel when LOD is on).",
    "volume_biased points are Blender 5.0 renders compared with a Blender 5.0 reference "
    "(unbiased null-scattering integrator, reference_50).",
    "Points with same_as copy the measurement of a point with the identical bake and render.",
]

POINT_KEYS = ["knob", "setting", "label", "blender", "variant", "render_s", "render_s_all", "bake_s",
              "bake_s_all", "time_s", "peak_mib", "bake_peak_mib", "file_mib", "rmse", "flip", "field_rms",
              "field_max", "field_range", "same_as", "image", "bake_cmd", "field_lod", "voxel", "grid", "camera_voxel",
              "visible_tiles", "total_tiles", "load_before", "slice_s", "slice_s_all", "slice_size", "field_note",
              "measured_at", "matched_rmse", "matched_flip", "matched_to"]


def write_results(cfg):
    """<out>/accuracy.json from the whole cache (atomically)."""
    order = {k.name: i for i, k in enumerate(KNOBS)}
    out = {"machine": cfg.machine, "blender": {}, "settings": {
    "image_size": list(cfg.size), "runs_per_point": cfg.runs, "bake_runs": cfg.bake_runs,
    "base_render": dict(cfg.base), "sweep_seed": scenes.SWEEP_SEED,
    "quick": cfg.quick,
    "notes": list(NOTES)}, "scenes": {}}
    for scene in scenes.SCENES:
        d = cfg.cache / scene
        if not d.exists():
            continue
        entry = {"preset": scenes.SCENES[scene]["preset"], "description": scenes.SCENES[scene]["description"]}
        for blender, fname in (("4.5", "reference.json"), ("5.0", "reference_50.json")):
            if (d / fname).exists():
                r = json.loads((d / fname).read_text())
                ref = {k: r.get(k) for k in ("samples", "step_rate", "volume_biased", "seeds", "noise_rmse",
                                             "noise_flip", "reference_rmse", "render_s", "render_s_all",
                                             "peak_mib", "image", "mean_radiance", "load_before")}
                ref["render_s"] = min(r.get("render_s_all") or [r.get("render_s")])  # best, as for points
                entry["reference" if blender == "4.5" else "reference_50"] = ref
                out["blender"][blender] = r.get("version")
        pts = []
        for f in sorted(d.glob("*.json")):
            if f.name.startswith("reference"):
                continue
            c = json.loads(f.read_text())
            pts.append({k: c[k] for k in POINT_KEYS if k in c})
        pts.sort(key=lambda p: (order.get(p["knob"], 99), _num(p["setting"]), p.get("variant", "")))
        entry["points"] = pts
        out["scenes"][scene] = entry
    out["blender"].update({k: v for k, v in cfg.versions.items() if v})
    write_json(cfg.results, out)


def _num(s):
    m = re.search(r"[0-9.]+", str(s))
    try:
        v = float(m.group(0)) if m else 0.0
    except ValueError:
        v = 0.0
    return (str(s).split("@")[0] if "@" in str(s) else "", v)
