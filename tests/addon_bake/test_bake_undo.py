"""Undo around Bake to VDB (issue 12, finding 5), in the 4.5 wheel.

Bake to VDB is an undo step (bl_options has UNDO). With a window Blender pushes the
step when an UNDO operator finishes; a script in background mode gets no automatic
push, so the test pushes exactly what the UI would (bpy.ops.ed.undo_push with the
operator's name after each operator) and undoes with bpy.ops.ed.undo(), which works
without a window (memfile undo, the same as Ctrl+Z).

- Add Cloud → Bake → undo: the cloud stays, procedural, without its Volume object or
  bake record; the .vdb stays on disk (undo does not delete files). Undo again: the
  cloud is gone. Repeated 50 times (the reported crash: none in 50 here).
- Add Cloud → Bake → Seed → Bake, then undo twice (the second bake, the seed): the
  cloud is back at the first bake's state, its Volume object reading the file the
  second bake overwrote; checks.stale (the panel's "Stale" line) reads the file's
  own key and says the bake no longer matches the parameters.
"""
import pytest
from bake_scene import small_scene

REPEATS = 50


@pytest.fixture(autouse=True)
def no_cli(bake_addon, monkeypatch):
    from cloudgen import bridge

    monkeypatch.setattr(bridge, "cloudgen_executable", lambda: None)


def test_bake_is_an_undo_step(bake_addon):
    import bpy

    assert "UNDO" in bpy.types.CLOUDGEN_OT_bake_vdb.bl_options


def _step(op, name, **kw):
    import bpy

    assert op(**kw) == {"FINISHED"}
    bpy.ops.ed.undo_push(message=name)


def test_add_bake_undo_50_times(bake_addon, tmp_path):
    import bpy
    from cloudgen import volume_object

    small_scene()
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "u.blend"))
    bpy.ops.ed.undo_push(message="start")
    for i in range(REPEATS):
        _step(bpy.ops.cloudgen.add_cloud, "Add Cloud", cloud_type="cumulus")
        name = bpy.context.view_layer.objects.active.name
        _step(bpy.ops.cloudgen.bake_vdb, "Bake to VDB", resolution=8)
        assert bpy.data.objects.get(name + "_VDB") is not None, f"iteration {i}: no Volume object"
        assert bpy.ops.ed.undo() == {"FINISHED"}
        cloud = bpy.data.objects.get(name)
        assert cloud is not None, f"iteration {i}: undoing the bake removed the cloud"
        assert bpy.data.objects.get(name + "_VDB") is None, f"iteration {i}: the Volume object stayed"
        assert cloud.get(volume_object.SOURCE_KEY, "PROCEDURAL") == "PROCEDURAL" and not cloud.hide_render
        assert volume_object.bake_record(cloud) == {}, f"iteration {i}: the bake record stayed"
        assert (tmp_path / "cloudgen" / f"{name}.vdb").is_file(), "the file is not removed by undo"
        assert bpy.ops.ed.undo() == {"FINISHED"}
        assert bpy.data.objects.get(name) is None, f"iteration {i}: undoing Add Cloud left {name}"


def test_undo_after_seed_and_bake_marks_the_bake_stale(bake_addon, tmp_path):
    import bpy
    from cloudgen import checks, cloud_object

    sc = small_scene()
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "s.blend"))
    bpy.ops.ed.undo_push(message="start")
    _step(bpy.ops.cloudgen.add_cloud, "Add Cloud", cloud_type="cumulus")
    name = bpy.context.view_layer.objects.active.name
    _step(bpy.ops.cloudgen.bake_vdb, "Bake to VDB", resolution=8)
    cloud = bpy.data.objects[name]
    assert not checks.stale(cloud, sc)
    seed = next(n.inputs["Seed"] for n in cloud_object.cloud_nodes(cloud) if "Seed" in n.inputs)
    seed.default_value = 7
    bpy.ops.ed.undo_push(message="Seed")
    assert checks.stale(bpy.data.objects[name], sc), "a changed seed must make the bake stale"
    _step(bpy.ops.cloudgen.bake_vdb, "Bake to VDB", resolution=8)
    assert not checks.stale(bpy.data.objects[name], sc)
    assert bpy.ops.ed.undo() == {"FINISHED"}   # the second bake
    assert bpy.ops.ed.undo() == {"FINISHED"}   # the seed
    cloud = bpy.data.objects[name]
    assert cloud.get("cloudgen_source") == "BAKED"   # the first bake's state, reading the file ...
    assert checks.stale(cloud, sc), "... which now holds the seed-7 bake: the panel must say stale"
