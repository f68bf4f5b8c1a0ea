"""What Bake to VDB hands the CLI (bpy 4.5, background): a stand-in `cloudgen`
records its arguments and the --camera / --sequence / --params files and writes
a real (tiny) VDB per output, so the add-on side is checked independently of
the core: the scene's tier goes as --quality with only explicit overrides,
Fit to Camera passes camera_fit.camera_json (temporary file removed), a frame
range passes per-frame parameters (keyframes evaluated, frame restored) with
--update, the info line counts baked/copied/kept, and a CLI without these
options gets explicit values and --frames instead."""
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
FEATURES = {features!r}
LOG, TEMPLATE = {log!r}, {template!r}
a = sys.argv[1:]
if a[:1] == ["info"]:
    print("grid: density"); sys.exit(0)
if a[:2] == ["bake", "--help"]:
    print("usage: cloudgen bake " + " ".join(FEATURES)); sys.exit(0)
def opt(name):
    return a[a.index(name) + 1] if name in a else None
rec = {{"argv": a}}
for name in ("--camera", "--sequence", "--params"):
    if opt(name):
        rec[name] = json.load(open(opt(name)))
        rec[name + " path"] = opt(name)
with open(LOG, "a") as f:
    f.write(json.dumps(rec) + "\\n")
out = opt("--output")
def path_of(frame):
    stem, ext = out[:-4], ".vdb"
    return "%s_%04d%s" % (stem, frame, ext)
if "--sequence" in rec:
    seen = {{}}
    for e in rec["--sequence"]["frames"]:
        key = json.dumps(e["params"], sort_keys=True)
        p = path_of(e["frame"])
        shutil.copyfile(TEMPLATE, p)
        if key in seen:
            print("copied %s (same field as frame %d)" % (p, seen[key]))
        else:
            seen[key] = e["frame"]
            print("wrote %s (fake)" % p)
elif opt("--frames"):
    x, y = map(int, opt("--frames").split("-"))
    for fr in range(x, y + 1):
        shutil.copyfile(TEMPLATE, path_of(fr)); print("wrote %s (fake)" % path_of(fr))
else:
    shutil.copyfile(TEMPLATE, out); print("wrote %s (fake)" % out)
'''


def _fake(tmp_path, features, name):
    template = tmp_path / "template.vdb"
    if not template.exists():
        subprocess.run([str(CLI), "bake", "--preset", "cumulus", "--resolution", "8", "--quiet",
                        "--output", str(template)], check=True)
    exe = tmp_path / name
    log = tmp_path / f"{name}.log"
    exe.write_text(FAKE.format(python=sys.executable, features=list(features), log=str(log),
                               template=str(template)))
    exe.chmod(exe.stat().st_mode | stat.S_IXUSR)
    return exe, log


def _records(log):
    return [json.loads(line) for line in log.read_text().splitlines()]


@pytest.fixture
def new_cli(tmp_path, monkeypatch):
    from cloudgen import bridge

    exe, log = _fake(tmp_path, ["--quality", "--camera", "--sequence", "--update"], "cloudgen_new")
    monkeypatch.setattr(bridge, "cloudgen_executable", lambda: str(exe))
    return log


@pytest.fixture
def old_cli(tmp_path, monkeypatch):
    from cloudgen import bridge

    exe, log = _fake(tmp_path, [], "cloudgen_old")
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


def test_frame_range_passes_per_frame_params(bake_addon, tmp_path, new_cli):
    import bpy
    from cloudgen import bake

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
    assert bake.last_result.counts() == "2 baked, 3 copied, 0 kept"
    assert "5 frames: 2 baked, 3 copied, 0 kept" in bake.last_report
    assert sorted(os.listdir(tmp_path / "seq")) == [f"c_{f:04d}.vdb" for f in range(1, 6)]
    vol = bpy.data.objects[cloud.name + "_VDB"].data
    assert vol.is_sequence and vol.frame_start == 1 and vol.frame_duration == 5


def test_older_cli_gets_explicit_values(bake_addon, tmp_path, old_cli):
    import bpy

    sc, _ = _saved_cloud(tmp_path)
    sc.frame_start, sc.frame_end = 2, 3
    assert bpy.ops.cloudgen.apply_quality(tier="draft") == {"FINISHED"}
    assert bpy.ops.cloudgen.bake_vdb(sequence=True) == {"FINISHED"}
    (rec,) = _records(old_cli)
    argv = rec["argv"]
    from cloudgen import bridge

    b = bridge.tiers()["draft"]["bake"]
    assert _value(argv, "--resolution") == str(b["resolution"]) and "--quality" not in argv
    assert ("--half" in argv) == b["half"] and ("--no-lod" in argv) == (not b["lod"])
    assert _value(argv, "--frames") == "2-3" and "--sequence" not in argv and "--update" not in argv
    sc.cloudgen.bake_fit_camera = True
    with pytest.raises(RuntimeError, match="needs a cloudgen command-line tool with --camera"):
        bpy.ops.cloudgen.bake_vdb()
    assert len(_records(old_cli)) == 1
