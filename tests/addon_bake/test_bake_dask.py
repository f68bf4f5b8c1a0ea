"""Bake Frame Range on a Dask scheduler (the issue-16 add-on part), in the 4.5 wheel.

The add-on's preferences hold a scheduler address, the Python that runs
`-m cloudgen_dask bake` and the cloudgen CLI the workers run. With the address set a
sequence bake goes to the runner (a LocalCluster's scheduler here: 1 worker process
on loopback): every frame file exists and equals the in-Blender bake of the same
frame voxel for voxel (tolerance 0), the record has the runner's counts (a still
cloud: 1 baked, 2 copied). With the address cleared the same bake runs locally.
Needs build/bin/cloudgen, dask.distributed and cloudgen_dask in this Python."""
import os
import pathlib
import sys

import pytest
from bake_scene import small_scene

ROOT = pathlib.Path(__file__).resolve().parents[2]
CLI = ROOT / "build" / "bin" / "cloudgen"

pytestmark = pytest.mark.skipif(not CLI.is_file(), reason="build/bin/cloudgen not built")


@pytest.fixture(scope="module")
def scheduler():
    pytest.importorskip("cloudgen_dask")
    distributed = pytest.importorskip("dask.distributed")
    cluster = distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                       host="127.0.0.1", dashboard_address=None)
    try:
        yield cluster.scheduler_address
    finally:
        cluster.close()


class Prefs:
    """The add-on's preferences as the bake reads them (prefs.dask, bridge.cloudgen_executable):
    the test fixture enables the add-on without adding it to the user preferences."""

    def __init__(self, monkeypatch):
        from cloudgen import bridge, prefs

        self.dask_scheduler = self.dask_python = self.cli_path = ""
        monkeypatch.setattr(prefs, "dask", lambda: (self.dask_scheduler, self.dask_python)
                            if self.dask_scheduler else ("", ""))
        monkeypatch.setattr(bridge, "cloudgen_executable", lambda: self.cli_path or None)


def test_preferences_hold_the_scheduler_and_the_runner(bake_addon):
    cls = bake_addon.prefs.CLOUDGEN_AP_preferences
    assert cls.is_registered and cls.bl_idname == bake_addon.__name__
    props = cls.bl_rna.properties
    assert {"dask_scheduler", "dask_python", "cli_path"} <= set(props.keys())


def test_sequence_goes_to_the_scheduler_then_local(bake_addon, tmp_path, scheduler, capfd, monkeypatch):
    import bpy
    from cloudgen import bridge, cloud_object, volume_object
    from test_bake_in_blender import compare_files

    prefs = Prefs(monkeypatch)
    sc = small_scene()
    sc.frame_start, sc.frame_end = 1, 3
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "d.blend"))
    cloud = cloud_object.create_cloud(bpy.context, "cumulus")
    for node in cloud_object.cloud_nodes(cloud):
        for label in ("Wind Strength", "Evolution"):
            if label in node.inputs:
                node.inputs[label].default_value = 0.0
    prefs.dask_scheduler, prefs.dask_python, prefs.cli_path = scheduler, sys.executable, str(CLI)
    bridge._cli_checked.clear()
    try:
        capfd.readouterr()
        assert bpy.ops.cloudgen.bake_vdb(resolution=12, sequence=True, filepath="//dask/c_####.vdb") == {"FINISHED"}
        out = capfd.readouterr().out
        assert "on the Dask cluster" in out, out[-2000:]
        record = volume_object.bake_record(cloud)
        assert (record["baked"], record["copied"]) == (1, 2), record
        dask_files = [tmp_path / "dask" / f"c_{f:04d}.vdb" for f in (1, 2, 3)]
        assert all(p.is_file() for p in dask_files), os.listdir(tmp_path / "dask")
    finally:
        prefs.dask_scheduler, prefs.dask_python, prefs.cli_path = "", "", ""
    capfd.readouterr()
    assert bpy.ops.cloudgen.bake_vdb(resolution=12, sequence=True, filepath="//local/c_####.vdb") == {"FINISHED"}
    out = capfd.readouterr().out
    assert "Dask" not in out and "3 frames: 1 baked, 2 copied, 0 kept" in out, out[-2000:]
    for f in (1, 2, 3):
        problems = compare_files(tmp_path / "local" / f"c_{f:04d}.vdb", tmp_path / "dask" / f"c_{f:04d}.vdb")
        assert not problems, f"frame {f}: the Dask bake differs from the local one:\n" + "\n".join(problems)


def test_scheduler_without_a_cli_is_refused(bake_addon, tmp_path, monkeypatch):
    import bpy
    from cloudgen import cloud_object

    prefs = Prefs(monkeypatch)
    small_scene()
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "e.blend"))
    cloud_object.create_cloud(bpy.context, "cumulus")
    prefs.dask_scheduler = "tcp://127.0.0.1:1"
    try:
        with pytest.raises(RuntimeError, match="Dask bake runs the cloudgen command-line tool"):
            bpy.ops.cloudgen.bake_vdb(resolution=8, sequence=True)
    finally:
        prefs.dask_scheduler = ""
