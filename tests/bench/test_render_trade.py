"""bench/render_trade.py's smallest configuration (--quick: 32x18 px, 1-2 spp, two
variants of each study) runs end to end in Blender's Python and writes a results
JSON of the documented structure, with finite, non-negative errors. Needs bpy (the
venv's Blender 4.5) and the CLI (build/bin/cloudgen or $CLOUDGEN_BIN) for the bake;
skipped without bpy unless CLOUDGEN_REQUIRE_BPY=1. Times are recorded, never checked."""
import json
import math
import os
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "bench" / "render_trade.py"
CLOUDGEN = os.environ.get("CLOUDGEN_BIN", str(ROOT / "build" / "bin" / "cloudgen"))
STUDIES = {"reference", "bounces", "denoise", "adaptive", "phase"}
ERRORS = ("rmse", "mae", "rmse_cloud", "mae_cloud", "rel_rmse_cloud", "flip")
BRIGHTNESS = ("body_linear", "rim_linear", "body_display", "rim_display")


def _have_bpy():
    try:
        import bpy  # noqa: F401
    except ImportError:
        if os.environ.get("CLOUDGEN_REQUIRE_BPY") == "1":
            raise
        return False
    return True


needs_bpy = pytest.mark.skipif(not _have_bpy(), reason="bpy (Blender as a Python module) is not installed")


@needs_bpy
def test_quick_run_writes_finite_results(tmp_path):
    assert pathlib.Path(CLOUDGEN).exists(), f"the CLI {CLOUDGEN} is needed for the bake: build it first"
    out, sheet, doc = tmp_path / "trade.json", tmp_path / "sheet.png", tmp_path / "trade.md"
    cmd = [sys.executable, str(SCRIPT), "--quick", "--size", "32x18", "--work", str(tmp_path / "work"),
           "--out", str(out), "--sheet", str(sheet), "--doc", str(doc)]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=600,
                          env=dict(os.environ, CLOUDGEN_BIN=CLOUDGEN))
    assert proc.returncode == 0, f"{cmd} exited {proc.returncode}:\n{proc.stderr[-3000:]}"
    data = json.loads(out.read_text())
    assert data["quick"] is True and data["size"] == "32x18"
    assert {"cpu_model", "nproc", "load_average"} <= set(data["machine"]), data["machine"]
    rows = data["variants"]
    assert {r["study"] for r in rows} == STUDIES, [r["study"] for r in rows]
    assert len(rows) == 8, [r["name"] for r in rows]
    assert sum(data["masks"]["cloud_pixels"].values()) > 0, data["masks"]  # the cloud is in the frame
    for r in rows:
        assert r["render_s"] > 0, r
        for key in BRIGHTNESS:
            assert math.isfinite(r[key]) and r[key] >= 0.0, (r["name"], key, r[key])
        if r["study"] in ("bounces", "denoise", "adaptive"):
            for key in ERRORS:
                assert math.isfinite(r[key]) and r[key] >= 0.0, (r["name"], key, r[key])
            assert r["reference"] in {x["name"] for x in rows}, r
    # the 64-bounce render is the bounce study's reference: zero error against itself (tolerance 0)
    top = next(r for r in rows if r["name"] == "bounces_64")
    assert top["rmse"] == 0.0 and top["flip"] == 0.0, top
    # one bounce drops the light of every later scattering: the body is darker (any margin)
    one = next(r for r in rows if r["name"] == "bounces_1")
    assert one["body_linear"] < top["body_linear"], (one["body_linear"], top["body_linear"])
    assert sheet.exists() and sheet.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    text = doc.read_text()
    for heading in ("### Volume bounces", "### Samples with and without", "### Adaptive sampling",
                    "### Phase function"):
        assert heading in text, f"{heading!r} missing from the report:\n{text}"
