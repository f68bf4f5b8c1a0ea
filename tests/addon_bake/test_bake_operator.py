"""Bake to VDB inside the bpy wheel (4.5, background: the operator runs synchronously):
a readable VDB and a Volume object lined up with the box, re-bake updates in place,
the frame range bakes a sequence, procedural/baked switch, clear errors and no
partial file for an unsaved-file relative path and an unwritable path."""
import math
import os
import pathlib
import subprocess

import pytest
from bake_scene import small_scene

ROOT = pathlib.Path(__file__).resolve().parents[2]
CLI = ROOT / "build" / "bin" / "cloudgen"


def add_cloud(cloud_type="cumulus"):
    """The add-on's cloud, made without the Add Cloud operator: its preview refresh,
    run in two scenes of one process, makes the 4.5 wheel hang at exit (seen
    with tests/addon/test_clouds.py too); the bake does not need the preview."""
    import bpy
    from cloudgen import cloud_object

    return cloud_object.create_cloud(bpy.context, cloud_type)


def saved_scene(tmp_path):
    import bpy

    sc = small_scene()
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "scene.blend"))
    return sc


def test_unsaved_relative_path_is_refused(bake_addon):
    import bpy

    small_scene()
    cloud = add_cloud()
    with pytest.raises(RuntimeError, match="not saved"):
        bpy.ops.cloudgen.bake_vdb(resolution=8)
    assert cloud.get("cloudgen_source", "PROCEDURAL") == "PROCEDURAL"
    assert not any(o.type == "VOLUME" for o in bpy.data.objects)


def test_bake_creates_volume_lined_up_with_the_box(bake_addon, tmp_path):
    import bpy
    from mathutils import Vector

    saved_scene(tmp_path)
    cloud = add_cloud()
    cloud.location = (1.0, -2.0, 3.0)
    cloud.rotation_euler = (0.0, 0.0, math.radians(30.0))
    bpy.context.view_layer.update()
    assert bpy.ops.cloudgen.bake_vdb(resolution=24) == {"FINISHED"}
    path = tmp_path / "cloudgen" / f"{bpy.path.clean_name(cloud.name)}.vdb"
    assert path.is_file()
    info = subprocess.run([str(CLI), "info", str(path)], capture_output=True, text=True, check=True)
    assert "grid: density" in info.stdout
    assert sorted(os.listdir(path.parent)) == [path.name]

    vdb = bpy.data.objects[cloud.name + "_VDB"]
    assert vdb.type == "VOLUME" and vdb.parent == cloud
    assert vdb.data.filepath == "//cloudgen/" + path.name  # relative: the .blend moves with it
    assert "density" in [g.name for g in vdb.data.grids]
    bpy.context.view_layer.update()
    # world = the cloud's location and rotation, unit scale: local frame = grid frame
    loc, rot, scale = vdb.matrix_world.decompose()
    assert tuple(loc) == pytest.approx((1.0, -2.0, 3.0), abs=1e-5)
    assert tuple(scale) == pytest.approx((1.0, 1.0, 1.0), abs=1e-5)
    assert rot.to_euler().z == pytest.approx(math.radians(30.0), abs=1e-5)
    # the grid's voxel centres span the box, centred: index→object maps the grid centre to 0
    grid = vdb.data.grids["density"]
    if hasattr(grid, "matrix_object"):
        m = grid.matrix_object
        v = max(cloud.dimensions) / 24
        n = [math.ceil(d / v - 1e-6) for d in cloud.dimensions]
        centre = m @ Vector([(k - 1) / 2 for k in n])
        assert tuple(centre) == pytest.approx((0, 0, 0), abs=1e-4)
    # a box corner of the procedural cloud and the baked volume's grid corner coincide in world space
    corner_local = Vector([-d / 2 for d in cloud.dimensions])
    w_cloud = cloud.matrix_world @ Vector((-0.5, -0.5, -0.5))
    w_vdb = vdb.matrix_world @ corner_local
    assert tuple(w_cloud) == pytest.approx(tuple(w_vdb), abs=1e-5)

    assert cloud["cloudgen_source"] == "BAKED" and cloud.hide_render and not vdb.hide_render
    # the record on the cloud: the file, the field key of the parameters it was baked from
    from cloudgen import bridge, cloud_object, volume_object
    record = volume_object.bake_record(cloud)
    want_key = bridge.field_key(cloud_object.params_from_object(cloud))
    assert record["files"] == ["//cloudgen/" + path.name] and record["frames"] == [], record
    assert record["field_keys"] == [want_key] and len(want_key) == 16, record
    assert (record["baked"], record["copied"], record["kept"]) == (1, 0, 0), record
    # the baked material is like the cloud's own volume node, the grid read once
    mat = vdb.active_material
    own = cloud.active_material.node_tree.nodes["Cloud Volume"]
    vol = mat.node_tree.nodes["Cloud Volume"]
    assert vol.bl_idname == own.bl_idname, (vol.bl_idname, own.bl_idname)
    if "Density Attribute" in vol.inputs:
        assert vol.inputs["Density Attribute"].default_value == "density"
        assert not vol.inputs["Density"].is_linked and vol.inputs["Density"].default_value == 1.0
    else:
        assert mat.node_tree.nodes["Density Grid"].attribute_name == "density"
        assert vol.inputs["Density"].links[0].from_node.name == "Density Grid"
    assert mat.cycles.volume_step_rate == 1.0

    assert bpy.ops.cloudgen.cloud_source(source="PROCEDURAL") == {"FINISHED"}
    assert cloud["cloudgen_source"] == "PROCEDURAL" and not cloud.hide_render and vdb.hide_render
    # Without the cloud's own volume node the baked material is a Principled Volume:
    # the grid must reach it once, through its Density Attribute (a link into
    # Density as well multiplies the two: density squared, a darker cloud).
    cloud_mat = cloud.active_material
    cloud.data.materials.clear()
    principled = volume_object.baked_material(cloud)
    vol = principled.node_tree.nodes["Cloud Volume"]
    assert vol.bl_idname == "ShaderNodeVolumePrincipled", vol.bl_idname
    assert not vol.inputs["Density"].is_linked and vol.inputs["Density"].default_value == 1.0
    assert vol.inputs["Density Attribute"].default_value == "density"
    cloud.data.materials.append(cloud_mat)
    volume_object.baked_material(cloud)  # restore the cloud's own look on <cloud>_VDB
    # re-bake updates the same object
    assert bpy.ops.cloudgen.bake_vdb(resolution=16) == {"FINISHED"}
    assert [o.name for o in bpy.data.objects if o.type == "VOLUME"] == [vdb.name]
    assert cloud["cloudgen_source"] == "BAKED"


def test_frame_range_bakes_a_sequence(bake_addon, tmp_path):
    import bpy

    sc = saved_scene(tmp_path)
    sc.frame_start, sc.frame_end = 2, 4
    cloud = add_cloud("stratocumulus")
    assert bpy.ops.cloudgen.bake_vdb(resolution=12, sequence=True,
                                     filepath="//seq/cloud_####.vdb") == {"FINISHED"}
    names = sorted(os.listdir(tmp_path / "seq"))
    assert names == ["cloud_0002.vdb", "cloud_0003.vdb", "cloud_0004.vdb"]
    obj = bpy.data.objects[cloud.name + "_VDB"]
    vol = obj.data
    assert vol.is_sequence and vol.frame_start == 2 and vol.frame_duration == 3
    assert vol.filepath == "//seq/cloud_0002.vdb"
    for frame in (2, 4):
        sc.frame_set(frame)
        evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).data
        assert bpy.path.basename(evaluated.grids.frame_filepath) == f"cloud_{frame:04d}.vdb"
    sc.frame_set(5)  # past the range: clipped, no file
    evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).data
    assert evaluated.grids.frame_filepath == ""


def test_output_with_two_runs_of_hash(bake_addon, tmp_path, capfd):
    """The LAST run of '#' is the frame number (the CLI names the files; the add-on once
    took the first run, looked for a_01/f_####.vdb and failed the bake)."""
    import bpy
    from cloudgen import volume_object

    sc = saved_scene(tmp_path)
    sc.frame_start, sc.frame_end = 1, 2
    cloud = add_cloud()
    capfd.readouterr()
    result = bpy.ops.cloudgen.bake_vdb(resolution=8, sequence=True, filepath="//a_##/f_####.vdb")
    out = capfd.readouterr().out
    assert result == {"FINISHED"}, out[-2000:]
    assert sorted(os.listdir(tmp_path / "a_##")) == ["f_0001.vdb", "f_0002.vdb"], os.listdir(tmp_path)
    vdb = volume_object.baked_object(cloud)
    assert vdb.data.filepath == "//a_##/f_0001.vdb"
    record = volume_object.bake_record(cloud)
    assert record["files"] == ["//a_##/f_0001.vdb", "//a_##/f_0002.vdb"], record
    assert record["frames"] == [1, 2] and len(record["field_keys"]) == 2, record
    assert "Bake to VDB: 2 frames:" in out, out[-2000:]


def test_unwritable_path_reports_and_leaves_nothing(bake_addon, tmp_path):
    import bpy

    saved_scene(tmp_path)
    cloud = add_cloud()
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(RuntimeError, match=str(blocker)):
        bpy.ops.cloudgen.bake_vdb(resolution=8, filepath=str(blocker / "sub" / "c.vdb"))
    with pytest.raises(RuntimeError, match="cannot write.*not a folder"):
        bpy.ops.cloudgen.bake_vdb(resolution=8, filepath=str(blocker / "c.vdb"))
    assert sorted(os.listdir(tmp_path)) == ["file", "scene.blend"]
    assert cloud.get("cloudgen_source", "PROCEDURAL") == "PROCEDURAL" and not cloud.hide_render
    with pytest.raises(RuntimeError, match="bake it first"):
        bpy.ops.cloudgen.cloud_source(source="BAKED")
