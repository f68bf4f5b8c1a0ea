"""What Bake to VDB hands the CLI (bpy 4.5, background): a stand-in `cloudgen`
records its arguments and the --camera / --sequence / --params files and writes
a real (tiny) VDB per output, so the add-on side is checked independently of
the core: the scene's tier goes as --quality with only explicit overrides,
Fit to Camera passes camera_fit.camera_json (temporary file removed), a frame
range passes per-frame parameters (keyframes evaluated, frame restored) with
--update, the info line counts baked/copied/kept (read from the operator's
report output and the record on the cloud), and a CLI of another release or
without the JSON protocol is refused with a clear error before it bakes."""
import json
import os
import pathlib
import stat
import subprocess
import sys

import pytest
from bake_scene import frame_cloud, small_scene

ROOT = pathlib.Path(__file__).resolve().parents[2]
CLI = ROOT / "build" / "bin" / "cloudgen"

pytestmark = pytest.mark.skipif(not CLI.is_file(), reason="build/bin/cloudgen not built")

FAKE = '''#!{python}
import json, shutil, sys
sys.path.insert(0, {pylib!r})
import cloudgen_native
VERSION, PROTOCOL = {version!r}, {protocol!r}
LOG, TEMPLATE = {log!r}, {template!r}
a = sys.argv[1:]
def emit(**event):
    print(json.dumps(event), flush=True)
if a[:1] == ["info"]:
    print("grid: density"); sys.exit(0)
if a == ["--version", "--json"]:
    if PROTOCOL is None:
        print("cloudgen " + VERSION); sys.exit(0)   # a CLI from before the protocol
    emit(version=VERSION, protocol=PROTOCOL); sys.exit(0)
def opt(name):
    return a[a.index(name) + 1] if name in a else None
rec = {{"argv": a}}
for name in ("--camera", "--sequence", "--params"):
    if opt(name):
        rec[name] = json.load(open(opt(name)))
        rec[name + " path"] = opt(name)
with open(LOG, "a") as f:
    f.write(json.dumps(rec) + "\\n")
if "--json" not in a:
    print("wrote (human output)"); sys.exit(0)
out = opt("--output")
if "--sequence" in rec:
    frames = [(e["frame"], json.dumps(e["params"], sort_keys=True)) for e in rec["--sequence"]["frames"]]
else:
    frames = [(None, "")]
files = [{{"frame": fr, "path": cloudgen_native.frame_path(out, fr) if fr is not None else out}}
         for fr, _ in frames]
emit(event="plan", protocol=1, files=files, grid=[8, 8, 6], voxel=0.5, memory_gib=0.0, threads=1,
     preset=None)
seen = {{}}
for (fr, key), f in zip(frames, files):
    shutil.copyfile(TEMPLATE, f["path"])
    if key in seen:
        emit(event="copied", path=f["path"], frame=fr, source=seen[key][1], source_frame=seen[key][0])
    else:
        seen[key] = (fr, f["path"])
        emit(event="wrote", path=f["path"], frame=fr, active_voxels=1, grid=[8, 8, 6], voxel=0.5,
             bytes=1, seconds=0.0, tiles_total=1, tiles_culled=0)
emit(event="progress", fraction=1.0)
'''


def _fake(tmp_path, name, version=None, protocol=1):
    """A stand-in `cloudgen` that speaks the protocol (or, protocol None, predates it):
    by default of the loaded module's release."""
    from cloudgen import bridge

    template = tmp_path / "template.vdb"
    if not template.exists():
        subprocess.run([str(CLI), "bake", "--preset", "cumulus", "--resolution", "8", "--quiet",
                        "--output", str(template)], check=True)
    exe = tmp_path / name
    log = tmp_path / f"{name}.log"
    exe.write_text(FAKE.format(python=sys.executable, pylib=str(ROOT / "build" / "python"),
                               version=version or bridge.native().version()["version"], protocol=protocol,
                               log=str(log), template=str(template)))
    exe.chmod(exe.stat().st_mode | stat.S_IXUSR)
    return exe, log


def _records(log):
    return [json.loads(line) for line in log.read_text().splitlines()] if log.exists() else []


@pytest.fixture
def new_cli(tmp_path, monkeypatch):
    from cloudgen import bridge

    exe, log = _fake(tmp_path, "cloudgen_fake")
    monkeypatch.setattr(bridge, "cloudgen_executable", lambda: str(exe))
    return log


def _saved_cloud(tmp_path, kind="cumulus"):
    import bpy
    from cloudgen import cloud_object

    sc = small_scene()
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "scene.blend"))
    return sc, cloud_object.create_cloud(bpy.context, kind)


def _fcurves(action):
    if hasattr(action, "layers") and action.layers:  # 4.4+: layered actions
        return [fc for layer in action.layers for strip in layer.strips
                for bag in strip.channelbags for fc in bag.fcurves]
    return list(action.fcurves)


def key_density(cloud, keys: dict):
    """Keyframe the cloud's Density slider at {frame: value}, constant (stepped) interpolation."""
    from cloudgen import cloud_object

    main = cloud_object.cloud_nodes(cloud)[0]
    density = main.inputs["Density"]
    for frame, value in keys.items():
        density.default_value = value
        density.keyframe_insert("default_value", frame=frame)
    tree = main.id_data
    for fc in _fcurves(tree.animation_data.action):
        for kp in fc.keyframe_points:
            kp.interpolation = "CONSTANT"
        fc.update()


def _value(argv, name):
    return argv[argv.index(name) + 1] if name in argv else None


def test_tier_goes_as_quality_with_explicit_overrides_only(bake_addon, tmp_path, new_cli):
    import bpy

    sc, _ = _saved_cloud(tmp_path)
    assert bpy.ops.cloudgen.bake_vdb() == {"FINISHED"}          # Custom: as before tiers
    assert bpy.ops.cloudgen.apply_quality(tier="draft") == {"FINISHED"}
    assert bpy.ops.cloudgen.bake_vdb() == {"FINISHED"}
    assert bpy.ops.cloudgen.bake_vdb(resolution=12, no_lod=True) == {"FINISHED"}
    assert bpy.ops.cloudgen.bake_vdb(quality="final", half=True) == {"FINISHED"}
    custom, draft, draft_12, final_half = [r["argv"] for r in _records(new_cli)]
    assert _value(custom, "--resolution") == "96" and "--quality" not in custom
    assert _value(draft, "--quality") == "draft" and "--resolution" not in draft
    assert not {"--half", "--no-lod", "--tolerance"} & set(draft)
    assert _value(draft_12, "--quality") == "draft" and _value(draft_12, "--resolution") == "12"
    assert "--no-lod" in draft_12 and "--half" not in draft_12
    assert _value(final_half, "--quality") == "final" and "--half" in final_half
    assert sc.cloudgen.quality == "draft"


def test_fit_to_camera_passes_the_camera_json(bake_addon, tmp_path, new_cli):
    import bpy
    from cloudgen import camera_fit

    sc, cloud = _saved_cloud(tmp_path)
    frame_cloud(sc, cloud)
    sc.cloudgen.bake_fit_camera = True
    assert bpy.ops.cloudgen.bake_vdb(resolution=16) == {"FINISHED"}
    assert bpy.ops.cloudgen.bake_vdb(resolution=16, fit_camera=False) == {"FINISHED"}
    with_cam, without = _records(new_cli)
    expect = camera_fit.camera_json(sc, sc.camera, cloud)
    got = with_cam["--camera"]
    assert _value(with_cam["argv"], "--camera") == with_cam["--camera path"]
    assert not os.path.exists(with_cam["--camera path"])   # temporary, removed after the bake
    assert got["resolution"] == expect["resolution"] and got["tan_half_fov"] == expect["tan_half_fov"]
    for row, exp in zip(got["camera_to_cloud"], expect["camera_to_cloud"]):
        assert row == pytest.approx(exp, abs=1e-12)
    assert "--camera" not in without["argv"]
    sc.camera.data.type = "ORTHO"
    with pytest.raises(RuntimeError, match="orthographic"):
        bpy.ops.cloudgen.bake_vdb(resolution=16)
    assert len(_records(new_cli)) == 2  # refused before running the CLI


def test_frame_range_passes_per_frame_params(bake_addon, tmp_path, new_cli, capfd):
    import bpy
    from cloudgen import volume_object

    sc, cloud = _saved_cloud(tmp_path)
    sc.frame_start, sc.frame_end = 1, 5
    key_density(cloud, {1: 0.5, 3: 0.9})
    sc.frame_set(4)
    assert bpy.ops.cloudgen.bake_vdb(resolution=12, sequence=True,
                                     filepath="//seq/c.vdb") == {"FINISHED"}
    assert sc.frame_current == 4  # restored
    (rec,) = _records(new_cli)
    argv = rec["argv"]
    assert "--update" in argv and "--frames" not in argv and "--params" not in argv
    assert _value(argv, "--sequence") == rec["--sequence path"]
    assert not os.path.exists(rec["--sequence path"])
    seq = rec["--sequence"]
    assert seq["fps"] == pytest.approx(24.0)
    assert [f["frame"] for f in seq["frames"]] == [1, 2, 3, 4, 5]
    assert [f["params"]["density"] for f in seq["frames"]] == pytest.approx([0.5, 0.5, 0.9, 0.9, 0.9],
                                                                            abs=1e-6)
    assert {tuple(f["params"]["box_size"]) for f in seq["frames"]} == {tuple(cloud.dimensions)}
    record = volume_object.bake_record(cloud)
    assert (record["baked"], record["copied"], record["kept"]) == (2, 3, 0), record
    assert record["baked_frames"] == [1, 3] and record["copied_frames"] == [[2, 1], [4, 3], [5, 3]], record
    keys = record["field_keys"]
    assert len(keys) == 5 and keys[0] == keys[1] != keys[2] == keys[3] == keys[4], keys
    out = capfd.readouterr().out
    assert "Bake to VDB: 5 frames: 2 baked, 3 copied, 0 kept" in out, out[-2000:]
    assert sorted(os.listdir(tmp_path / "seq")) == [f"c_{f:04d}.vdb" for f in range(1, 6)]
    vol = bpy.data.objects[cloud.name + "_VDB"].data
    assert vol.is_sequence and vol.frame_start == 1 and vol.frame_duration == 5


@pytest.mark.parametrize("version, protocol, words", [
    ("0.0.1", 1, "different releases"),
    (None, 2, "protocol 2"),
    (None, None, "does not speak the JSON protocol"),
])
def test_cli_of_another_release_is_refused(bake_addon, tmp_path, monkeypatch, version, protocol, words):
    import bpy
    from cloudgen import bridge

    exe, log = _fake(tmp_path, f"cloudgen_{protocol}", version=version, protocol=protocol)
    monkeypatch.setattr(bridge, "cloudgen_executable", lambda: str(exe))
    _saved_cloud(tmp_path)
    with pytest.raises(RuntimeError, match=words):
        bpy.ops.cloudgen.bake_vdb(resolution=8)
    assert _records(log) == [], "the CLI was asked to bake"
    assert bridge.cli_problem(str(exe)) is not None and words in bridge.cli_problem(str(exe))
