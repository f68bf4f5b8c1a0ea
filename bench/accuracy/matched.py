"""Matched-seed image errors: a knob's own error, without the render noise.

    .venv/bin/python bench/accuracy/matched.py [--cache bench/results/accuracy_cache]

A swept render at 64 samples carries Monte Carlo noise (RMSE ~0.03 against the
converged reference here) that hides a bake's or a detail setting's bias.
Every swept render uses the same Cycles seed. Cycles then draws the same
random numbers for the same pixel and sample, so two renders of almost the
same scene make almost the same noise. The difference between a point's
image and its *matched baseline* is therefore mostly the knob's own effect
("common random numbers"). The baseline is the procedural render with the
same render settings, seed and Blender version. For the step-rate knob it is
the finest step measured.

This adds `matched_rmse`, `matched_flip` and `matched_to` to every cached
point that has a baseline. Sample-count, reference-like and baseline points
get none: for them the error against the reference is the measure. The
images come from the sweep (bench/results/images, not committed). A point
whose image is missing keeps the figures it has.
"""
from __future__ import annotations

import argparse
import json
import pathlib
import sys

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[1]
if str(HERE.parent) not in sys.path:
    sys.path.insert(0, str(HERE.parent))
from common import atomic_write

NO_BASELINE_KNOBS = {"samples", "procedural", "volume_biased", "preview_resolution"}


def _render_key(render: dict) -> str:
    return json.dumps(render, sort_keys=True)


def baseline_of(point: dict, points: list):
    """The cached point whose image is `point`'s matched baseline, or None."""
    spec = point.get("spec") or {}
    render = spec.get("render")
    if not render or point.get("knob") in NO_BASELINE_KNOBS:
        return None
    if point.get("knob") == "step_rate":
        same = [p for p in points if p.get("knob") == "step_rate" and p.get("image")]
        finest = min(same, key=lambda p: float(p["spec"]["render"]["step_rate"]), default=None)
        return None if finest is None or finest is point else finest
    if not spec.get("bake") and not render.get("params"):
        return None  # a plain procedural render is a baseline itself
    # what the knob changes (the bake, the parameters, the VDB shader's version) is
    # left out; the render settings that remain must match
    target = {k: v for k, v in render.items() if k not in ("params", "vdb_material")}
    target["source"] = "procedural"
    for p in points:
        s = p.get("spec") or {}
        if p is point or s.get("bake") or not s.get("render") or not p.get("image"):
            continue
        if s.get("blender") == spec.get("blender") and _render_key(s["render"]) == _render_key(target):
            return p
    return None


def update_scene(scene_dir: pathlib.Path, root: pathlib.Path = ROOT, load=None) -> int:
    """Adds matched errors to the scene's cached points; returns how many changed.
    `load(path) -> HxWx3 array` reads an image (default metrics.load_exr)."""
    from accuracy import metrics

    load = load or metrics.load_exr

    files = sorted(f for f in scene_dir.glob("*.json") if not f.name.startswith("reference"))
    points = [json.loads(f.read_text()) for f in files]
    images: dict = {}

    def image(p):
        path = root / p["image"]
        if path not in images:
            images[path] = load(path) if path.exists() else None
        return images[path]

    changed = 0
    for f, p in zip(files, points):
        base = baseline_of(p, points)
        if base is None or not p.get("image"):
            continue
        a, b = image(p), image(base)
        if a is None or b is None:
            continue
        new = {"matched_rmse": metrics.image_rmse(a, b), "matched_flip": metrics.image_flip(a, b),
               "matched_to": f"{base['knob']} {base['setting']}"
               + (f" {base['variant']}" if base.get("variant") else "")}
        if any(p.get(k) != v for k, v in new.items()):
            p.update(new)
            atomic_write(f, json.dumps(p, indent=1))
            changed += 1
    return changed


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cache", default=str(ROOT / "bench" / "results" / "accuracy_cache"))
    opts = ap.parse_args(argv)
    for scene_dir in sorted(pathlib.Path(opts.cache).iterdir()):
        if scene_dir.is_dir():
            print(f"matched: {scene_dir.name}: {update_scene(scene_dir)} point(s) updated")
    return 0


if __name__ == "__main__":
    sys.exit(main())
