"""Bake Frame Range computes only what changes (bpy 4.5, the real CLI's --sequence and
--update): a still cloud bakes once and copies the other frames; a keyframed density
step at frame 3 gives two fields (frames 1-2, 3-5); re-running unchanged keeps every
file; changing a keyframe re-bakes only the frames it affects. Bakes at resolution 16
(tiny, fast). Counts and frames come from the record the operator stores on the
cloud (volume_object.bake_record: the CLI's `wrote` / `copied` / `kept` events)
and its report line (captured output); exact counts, no timing is asserted. The
add-on is pointed at build/bin/cloudgen (the package's copy may predate the build
until it is repackaged)."""
import os
import pathlib

import pytest
from bake_scene import small_scene
from test_bake_options import key_density

ROOT = pathlib.Path(__file__).resolve().parents[2]
CLI = ROOT / "build" / "bin" / "cloudgen"
RES = 16


pytestmark = [pytest.mark.skipif(not CLI.is_file(), reason="build/bin/cloudgen not built"),
              pytest.mark.usefixtures("built_cli")]  # both bake paths (conftest)


def _socket(cloud, label):
    from cloudgen import cloud_object

    for node in cloud_object.cloud_nodes(cloud):
        if label in node.inputs:
            return node.inputs[label]
    raise LookupError(label)


def still_cloud(tmp_path, first, last):
    """A saved scene with a cumulus that does not move: no wind, no evolution, no keys."""
    import bpy
    from cloudgen import cloud_object

    sc = small_scene()
    sc.frame_start, sc.frame_end = first, last
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "seq.blend"))
    cloud = cloud_object.create_cloud(bpy.context, "cumulus")
    _socket(cloud, "Wind Strength").default_value = 0.0
    _socket(cloud, "Evolution").default_value = 0.0
    return sc, cloud


class Baked:
    """What one Bake Frame Range did, from the cloud's bake record and the report line."""

    def __init__(self, record, report):
        self.record, self.report = record, report
        self.baked = list(record["baked_frames"])
        self.copied = sorted(tuple(pair) for pair in record["copied_frames"])   # (frame, source frame)
        self.kept = list(record["kept_frames"])

    def counts(self):
        return f"{self.record['baked']} baked, {self.record['copied']} copied, {self.record['kept']} kept"


def bake_range(cloud, capfd):
    import bpy
    from cloudgen import volume_object

    capfd.readouterr()
    result = bpy.ops.cloudgen.bake_vdb(resolution=RES, sequence=True, filepath="//seq/c_####.vdb")
    out = capfd.readouterr().out
    assert result == {"FINISHED"}, out[-2000:]
    report = [line for line in out.splitlines() if "Bake to VDB:" in line]
    assert len(report) == 1, out[-2000:]
    return Baked(volume_object.bake_record(cloud), report[0])


def _loads_as_volume(path):
    import bpy

    vol = bpy.data.volumes.new("check")
    try:
        vol.filepath = str(path)
        assert vol.grids.load(), f"{path} does not load: {vol.grids.error_message}"
        return "density" in [g.name for g in vol.grids]
    finally:
        bpy.data.volumes.remove(vol)


def test_still_cloud_bakes_once(bake_addon, tmp_path, capfd):
    _, cloud = still_cloud(tmp_path, 1, 5)
    result = bake_range(cloud, capfd)
    assert result.counts() == "1 baked, 4 copied, 0 kept", result.record
    assert result.baked == [1], result.record
    assert result.copied == [(f, 1) for f in range(2, 6)], result.record
    assert "5 frames: 1 baked, 4 copied, 0 kept" in result.report, result.report
    assert len(set(result.record["field_keys"])) == 1, result.record
    files = sorted(os.listdir(tmp_path / "seq"))
    assert files == [f"c_{f:04d}.vdb" for f in range(1, 6)]
    for name in files:
        assert _loads_as_volume(tmp_path / "seq" / name)


def test_still_cloud_with_time_from_frame_bakes_once(bake_addon, tmp_path, capfd):
    """Time follows the frame, but without wind and evolution it cannot change the field."""
    import bpy
    from cloudgen import cloud_object

    _, cloud = still_cloud(tmp_path, 1, 10)
    bpy.context.view_layer.objects.active = cloud
    assert bpy.ops.cloudgen.time_from_frame(enable=True) == {"FINISHED"}
    result = bake_range(cloud, capfd)
    assert result.counts() == "1 baked, 9 copied, 0 kept", result.record
    assert cloud_object.params_from_object(cloud)["time"] == pytest.approx(1 / 24, abs=1e-6)


def test_keyframed_change_rerun_and_edit(bake_addon, tmp_path, capfd):
    sc, cloud = still_cloud(tmp_path, 1, 5)
    key_density(cloud, {1: 0.5, 3: 0.9})
    result = bake_range(cloud, capfd)
    # frames 1-2 one field, 3-5 another
    assert result.counts() == "2 baked, 3 copied, 0 kept", result.record
    assert sorted(result.baked) == [1, 3], result.record
    assert result.copied == [(2, 1), (4, 3), (5, 3)], result.record
    seq = tmp_path / "seq"
    assert (seq / "c_0001.vdb").read_bytes() != (seq / "c_0003.vdb").read_bytes()

    # unchanged: nothing baked; the baked frames are kept (the CLI may re-copy a
    # duplicate frame from its source rather than report it kept: both cost no bake)
    result = bake_range(cloud, capfd)
    assert result.baked == [], result.record
    assert {1, 3} <= set(result.kept), result.record
    assert sorted(result.kept + [f for f, _ in result.copied]) == [1, 2, 3, 4, 5], result.record

    # change the first key only: frame 1 re-baked, frame 2 copied from it, 3 kept (4-5
    # kept or copied from 3)
    key_density(cloud, {1: 0.6})
    result = bake_range(cloud, capfd)
    assert result.baked == [1], result.record
    assert (2, 1) in result.copied, result.record
    assert 3 in result.kept, result.record
    assert len(result.baked) + len(result.copied) + len(result.kept) == 5, result.record

    # a parameter of every frame: everything re-baked (two fields again)
    _socket(cloud, "Noise Scale").default_value = 1.3
    result = bake_range(cloud, capfd)
    assert result.counts() == "2 baked, 3 copied, 0 kept", result.record
    assert sc.frame_current == 1
