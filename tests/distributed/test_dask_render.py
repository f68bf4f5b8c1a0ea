"""The farm side: `python -m cloudgen_dask render` runs `blender -b` in two chunks
on a LocalCluster and checks every frame (Debian's Blender 3.4; skipped without it
unless CLOUDGEN_REQUIRE_BLENDER=1). Exact checks: exit codes and file names."""
import os
import shutil
import subprocess
import sys

import pytest
from cloudgen_dask import render
from conftest import ROOT

BLENDER = shutil.which("blender")
if BLENDER is None:
    if os.environ.get("CLOUDGEN_REQUIRE_BLENDER") == "1":
        raise RuntimeError("CLOUDGEN_REQUIRE_BLENDER=1 but there is no `blender` on PATH")
    pytest.skip("no blender on PATH", allow_module_level=True)

SCENE = """
import bpy, sys
bpy.ops.wm.read_factory_settings(use_empty=True)
sc = bpy.context.scene
sc.render.engine = 'CYCLES'
sc.cycles.samples = 1
sc.cycles.use_denoising = False
sc.render.resolution_x = sc.render.resolution_y = 8
cam = bpy.data.objects.new('cam', bpy.data.cameras.new('cam'))
sc.collection.objects.link(cam)
sc.camera = cam
bpy.ops.wm.save_as_mainfile(filepath=sys.argv[-1])
"""


def test_chunks_cover_the_range():
    assert render.chunks(1, 5, 2) == [(1, 2), (3, 5)]
    assert render.chunks(3, 3, 4) == [(3, 3)]
    assert render.chunks(1, 8, 3) == [(1, 2), (3, 5), (6, 8)]


def test_two_chunks_render_every_frame(tmp_path):
    scene = tmp_path / "scene.blend"
    subprocess.run([BLENDER, "-b", "--factory-startup", "--python-expr", SCENE, "--", str(scene)], check=True,
                   capture_output=True, timeout=300)
    env = {**os.environ, "PYTHONPATH": str(ROOT / "distributed")}
    r = subprocess.run([sys.executable, "-m", "cloudgen_dask", "render", str(scene), "--frames", "1-4", "--chunks",
                        "2", "--workers", "2", "--output", "//render/f_####", "--blender", BLENDER],
                       capture_output=True, text=True, env=env, timeout=600)
    assert r.returncode == 0, (r.stdout, r.stderr)
    assert "rendered 2 chunks: 1-2" in r.stdout and ", 3-4 in" in r.stdout, r.stdout
    assert sorted(p.name for p in (tmp_path / "render").iterdir()) == [f"f_{f:04d}.png" for f in range(1, 5)]


def test_a_failing_chunk_fails_the_run(tmp_path):
    env = {**os.environ, "PYTHONPATH": str(ROOT / "distributed")}
    broken = tmp_path / "broken.blend"
    broken.write_bytes(b"not a blend file")
    r = subprocess.run([sys.executable, "-m", "cloudgen_dask", "render", str(broken), "--frames", "1-2", "--chunks",
                        "2", "--workers", "1", "--output", str(tmp_path / "r" / "f_####"), "--blender", BLENDER],
                       capture_output=True, text=True, env=env, timeout=600)
    assert r.returncode == 1, (r.returncode, r.stdout, r.stderr)
    assert "cloudgen-dask: error: chunk 1-1" in r.stderr or "cloudgen-dask: error: chunk 2-2" in r.stderr, r.stderr
