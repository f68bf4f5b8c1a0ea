"""measure.py with the child processes replaced: a point is measured once, cached
under its specification's key, a point with the same bake + render copies the
figures (same_as), and results.py collects the cache. No Blender, no CLI."""
import json
import pathlib

import numpy as np
import pytest
from accuracy import field, knobs, measure, metrics, results, runner
from accuracy.config import SweepConfig


@pytest.fixture()
def fakes(monkeypatch):
    calls = {"render": 0, "bake": 0}

    def render(scene, spec, output, blender, runs, vdb=None, workdir=None):
        calls["render"] += 1
        value = 0.5 + 0.01 * spec.get("seed", 0) + (0.02 if vdb else 0.0)
        metrics.write_exr(output, np.full((3, 4, 3), value, np.float32))
        return {"render_s": 1.5, "render_s_all": [1.5] * runs, "peak_mib": 100.0, "version": "4.5.test"}

    def bake(cfg, scene, spec, output, workdir):
        calls["bake"] += 1
        return {"bake_s": 0.25, "bake_s_all": [0.25], "bake_peak_mib": 50.0, "file_mib": 1.0, "bake_cmd": "bake"}

    monkeypatch.setattr(runner, "render", render)
    monkeypatch.setattr(runner, "bake", bake)
    monkeypatch.setattr(field, "has_footprint", lambda: True)
    monkeypatch.setattr(field, "bake_field_error", lambda params, *a, **kw: {"field_rms": 0.01, "field_max": 0.1})
    monkeypatch.setattr(runner, "log", lambda msg: None)
    return calls


def test_points_are_cached_and_shared(tmp_path, fakes):
    cfg = SweepConfig(out=tmp_path, quick=True, runs=1, machine={"cpu_model": "test"})
    (pt,) = knobs.BY_NAME["bake_resolution"].points("64", cfg)
    c, measured = measure.measure_point(cfg, "cumulus", pt, force=False)
    # the reference averages seeds 1 and 2 (0.51, 0.52); the point renders seed 0 of a VDB: 0.52
    assert measured and fakes == {"render": 3, "bake": 1}, fakes
    assert c["time_s"] == 1.75 and c["rmse"] == pytest.approx(0.52 - 0.515, abs=1e-6) and c["field_rms"] == 0.01, c
    assert c["reference_key"] and c["key"] == measure.key_of(c["spec"]), c
    assert measure.measure_point(cfg, "cumulus", pt, force=False) == (c, False), "cached: not measured again"
    (same,) = knobs.BY_NAME["lod"].points("on@64", cfg)
    s, measured = measure.measure_point(cfg, "cumulus", same, force=False)
    assert measured and s["same_as"] == "bake_resolution_64" and fakes["bake"] == 1, (s, fakes)
    assert s["rmse"] == c["rmse"] and s["label"] == "VDB 64³ LOD on"
    results.write_results(cfg)
    out = json.loads(cfg.results.read_text())
    assert out["machine"] == {"cpu_model": "test"} and out["blender"] == {"4.5": "4.5.test"}, out
    pts = out["scenes"]["cumulus"]["points"]
    assert [(p["knob"], p["setting"]) for p in pts] == [("bake_resolution", "64"), ("lod", "on@64")], pts
    assert out["scenes"]["cumulus"]["reference"]["seeds"] == [1, 2]
    assert sorted(pathlib.Path(cfg.images, "cumulus").glob("*.exr")), "the renders are kept"
