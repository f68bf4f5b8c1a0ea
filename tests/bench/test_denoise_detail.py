"""bench/denoise_detail.py: its lobe measure on synthetic pictures (numpy only), and a tiny run
end to end in Blender's Python (16x12 px, a 2-spp reference; needs bpy and the CLI, skipped
without bpy unless CLOUDGEN_REQUIRE_BPY=1). Times are recorded, never checked."""
import importlib.util
import json
import math
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path[:0] = [str(ROOT / "bench"), str(ROOT / "scripts")]
import denoise_detail as dd  # noqa: E402

SCRIPT = ROOT / "bench" / "denoise_detail.py"
CLOUDGEN = os.environ.get("CLOUDGEN_BIN", str(ROOT / "build" / "bin" / "cloudgen"))


def _lobes(seed=3, shape=(96, 128)):
    """Blobs a few pixels across on a grey field: the lobes the measure looks for."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:shape[0], 0:shape[1]]
    img = np.full(shape, 120.0)
    for _ in range(60):
        cy, cx, r = rng.uniform(0, shape[0]), rng.uniform(0, shape[1]), rng.uniform(2.0, 4.0)
        img += 60.0 * np.exp(-((yy - cy) ** 2 + (xx - cx) ** 2) / (2 * r * r))
    return img


def test_lobe_measure_tells_a_blurred_picture_from_the_reference():
    from camera_finish import _blur

    ref = _lobes()
    same = dd.lobe_measures(ref, ref)
    assert same[0] == 0.0 and abs(same[1] - 1.0) < 1e-12 and abs(same[2] - 1.0) < 1e-12, same
    blurred = dd.lobe_measures(_blur(ref, 2.5), ref)   # what a denoiser that erases lobes does
    assert blurred[1] < 0.8 and blurred[0] > 1.0, f"a 2.5 px blur must lose lobe energy: {blurred}"
    other = dd.lobe_measures(_lobes(seed=4), ref)      # other lobes, the same amount of them
    assert other[2] < 0.3 and 0.7 < other[1] < 1.3, f"other lobes must not correlate: {other}"


@pytest.mark.skipif(os.environ.get("CLOUDGEN_REQUIRE_BPY") != "1" and importlib.util.find_spec("bpy") is None,
                    reason="bpy (Blender as a Python module) is not installed")
def test_tiny_run_writes_finite_results(tmp_path):
    assert pathlib.Path(CLOUDGEN).exists(), f"the CLI {CLOUDGEN} is needed for the bake: build it first"
    out = tmp_path / "detail.json"
    cmd = [sys.executable, str(SCRIPT), "--size", "16x12", "--ref-samples", "2", "--work", str(tmp_path / "work"),
           "--out", str(out)]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, f"{cmd} exited {proc.returncode}:\n{proc.stderr[-3000:]}"
    data = json.loads(out.read_text())
    assert [r["name"] for r in data["variants"]] == [v[0] for v in dd.VARIANTS], data["variants"]
    for r in data["variants"]:
        assert r["render_s"] > 0, r
        for key in ("rmse_vs_ref", "lobe_energy", "lobe_corr"):
            assert math.isfinite(r[key]), (r["name"], key, r[key])
