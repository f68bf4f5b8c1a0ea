"""Quality tiers and Fit to Camera end to end with the real CLI (bpy 4.5): a bake
after applying a tier has the tier's resolution, half floats and tolerance
(read back with `cloudgen info`); an explicit resolution wins; a Fit to Camera
bake from a framed camera writes a readable VDB whose voxels are no finer than
the resolution cap allows, and leaves no temporary camera file. The add-on is
pointed at build/bin/cloudgen (the package's copy may predate the build)."""
import glob
import os
import pathlib
import re
import subprocess
import tempfile

import pytest
from bake_scene import frame_cloud, small_scene

ROOT = pathlib.Path(__file__).resolve().parents[2]
CLI = ROOT / "build" / "bin" / "cloudgen"


pytestmark = [pytest.mark.skipif(not CLI.is_file(), reason="build/bin/cloudgen not built"),
              pytest.mark.usefixtures("built_cli")]  # both bake paths (conftest)


def info(path):
    text = subprocess.run([str(CLI), "info", str(path)], capture_output=True, text=True,
                          check=True).stdout
    meta = dict(re.findall(r"^\s+(cloudgen_resolution|min|voxel size): (.+)$", text, re.M))
    return text, meta


def _scene(tmp_path):
    import bpy
    from cloudgen import cloud_object

    sc = small_scene()
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "t.blend"))
    return sc, cloud_object.create_cloud(bpy.context, "cumulus")


def test_tier_bake_settings_reach_the_file(bake_addon, tmp_path):
    import bpy
    from cloudgen import bridge

    _scene(tmp_path)
    tier = bridge.tiers()["draft"]["bake"]
    assert bpy.ops.cloudgen.apply_quality(tier="draft") == {"FINISHED"}
    out = tmp_path / "draft.vdb"
    assert bpy.ops.cloudgen.bake_vdb(filepath=str(out)) == {"FINISHED"}
    text, meta = info(out)
    assert meta["cloudgen_resolution"] == str(tier["resolution"])
    assert ("saved as half: yes" in text) == tier["half"]
    if tier["tolerance"]:
        # nothing at or below the tolerance is stored (half floats round by < 0.1 %)
        assert float(meta["min"]) > tier["tolerance"] * (1 - 1e-3)
    out24 = tmp_path / "draft24.vdb"
    assert bpy.ops.cloudgen.bake_vdb(filepath=str(out24), resolution=24) == {"FINISHED"}
    assert info(out24)[1]["cloudgen_resolution"] == "24"   # explicit resolution wins


def test_fit_to_camera_bake(bake_addon, tmp_path, built_cli):
    import bpy

    sc, cloud = _scene(tmp_path)
    if built_cli == "blender":  # no CLI configured: Fit to Camera says it needs one, bakes nothing
        frame_cloud(sc, cloud)
        with pytest.raises(RuntimeError, match="Fit to Camera needs the cloudgen command-line tool"):
            bpy.ops.cloudgen.bake_vdb(fit_camera=True, resolution=64)
        assert not glob.glob(str(tmp_path / "cloudgen" / "*.vdb")), "a file was written"
        return
    frame_cloud(sc, cloud)
    before = set(glob.glob(os.path.join(tempfile.gettempdir(), "cloudgen-camera-*.json")))
    out = tmp_path / "cam.vdb"
    assert bpy.ops.cloudgen.bake_vdb(filepath=str(out), resolution=24, fit_camera=True) == {"FINISHED"}
    assert set(glob.glob(os.path.join(tempfile.gettempdir(), "cloudgen-camera-*.json"))) == before
    text, meta = info(out)
    assert "grid: density" in text
    voxel = [float(v) for v in meta["voxel size"].split()[:3]]
    # the cap: at most 24 voxels along the longest side. The info prints 6 significant digits,
    # up to 5e-6 relative off (5 / 24 = 0.2083333 prints 0.208333): 1e-5 relative
    assert min(voxel) >= max(cloud.dimensions) / 24 * (1 - 1e-5), (voxel, tuple(cloud.dimensions))
    vdb = bpy.data.objects[cloud.name + "_VDB"]
    assert "density" in [g.name for g in vdb.data.grids]
