"""Matched-seed errors (bench/accuracy/matched.py): which render is a point's
baseline, and that the figures written are the differences to it."""
import json

import numpy as np
import pytest
from accuracy import matched

BASE = {"source": "procedural", "samples": 64, "step_rate": 1.0, "seed": 0, "size": [4, 3]}


def point(knob, setting, render, bake=None, image=None, variant=None):
    p = {"knob": knob, "setting": setting, "spec": {"render": render, "bake": bake, "blender": "4.5"},
         "image": image}
    if variant:
        p["variant"] = variant
    return p


def test_baselines():
    proc = point("procedural", "base", dict(BASE), image="p.exr")
    vdb = point("bake_resolution", "128", dict(BASE, source="vdb", vdb_material=2), bake={"resolution": 128},
                image="v.exr")
    detail = point("noise_detail", "2", dict(BASE, params={"noise_detail": 2.0}), image="d.exr")
    spp = point("samples", "16", dict(BASE, samples=16), image="s.exr")
    fine = point("step_rate", "0.25", dict(BASE, step_rate=0.25), image="f.exr")
    coarse = point("step_rate", "2", dict(BASE, step_rate=2.0), image="c.exr")
    tier_proc = point("tier", "draft", dict(BASE, samples=16, step_rate=2.0), image="tp.exr", variant="procedural")
    tier_vdb = point("tier", "draft", dict(BASE, samples=16, step_rate=2.0, source="vdb"), bake={"resolution": 64},
                     image="tv.exr", variant="vdb")
    pts = [proc, vdb, detail, spp, fine, coarse, tier_proc, tier_vdb]
    assert matched.baseline_of(vdb, pts) is proc
    assert matched.baseline_of(detail, pts) is proc, "params are what the knob changes"
    assert matched.baseline_of(spp, pts) is None, "the sample count's error is its noise: no baseline"
    assert matched.baseline_of(proc, pts) is None
    assert matched.baseline_of(coarse, pts) is fine and matched.baseline_of(fine, pts) is None
    assert matched.baseline_of(tier_vdb, pts) is tier_proc, "same render settings, procedural"
    assert matched.baseline_of(tier_proc, pts) is None, "a plain procedural render is a baseline itself"
    other_blender = dict(vdb, spec=dict(vdb["spec"], blender="5.0"))
    assert matched.baseline_of(other_blender, pts) is None, "never across Blender versions"


def test_update_scene_writes_differences_to_the_baseline(tmp_path):
    scene = tmp_path / "cache" / "cumulus"
    scene.mkdir(parents=True)
    imgs = {"p.exr": np.zeros((3, 4, 3)), "v.exr": np.full((3, 4, 3), 0.1)}
    for name in imgs:
        (tmp_path / name).write_bytes(b"")  # exists; the loader below supplies the pixels
    (scene / "procedural_base.json").write_text(json.dumps(point("procedural", "base", dict(BASE), image="p.exr")))
    (scene / "bake_resolution_128.json").write_text(json.dumps(
        point("bake_resolution", "128", dict(BASE, source="vdb"), bake={"resolution": 128}, image="v.exr")))
    n = matched.update_scene(scene, root=tmp_path, load=lambda path: imgs[path.name])
    assert n == 1
    got = json.loads((scene / "bake_resolution_128.json").read_text())
    assert got["matched_rmse"] == pytest.approx(0.1, abs=1e-12), got
    assert got["matched_flip"] > 0 and got["matched_to"] == "procedural base", got
    assert "matched_rmse" not in json.loads((scene / "procedural_base.json").read_text())
    assert matched.update_scene(scene, root=tmp_path, load=lambda path: imgs[path.name]) == 0, "idempotent"
