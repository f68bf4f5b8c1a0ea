"""Run inside Debian's Blender 3.4 by test_blender34.py (issue 12, finding 5):

    blender -b --factory-startup --python-exit-code 1 --python tests/batch/undo_loop.py -- OUT_DIR N

Add Cloud → Bake to VDB → undo → undo, N times, pushing the undo steps the UI
pushes after an UNDO operator (a script in background mode gets none by itself)
and undoing with bpy.ops.ed.undo (memfile undo, as Ctrl+Z). After the first undo
the cloud is there, procedural, without its Volume object; after the second it is
gone. Prints `UNDO-LOOP-OK N`. Any failed assertion fails Blender's exit code."""
import sys

import addon_utils
import bpy

argv = sys.argv[sys.argv.index("--") + 1:]
out_dir, repeats = argv[0], int(argv[1])
mod = addon_utils.enable("cloudgen", default_set=True, handle_error=lambda exc: (_ for _ in ()).throw(exc))
assert mod is not None, "cannot enable the cloudgen add-on"
bpy.ops.wm.read_homefile(use_empty=True)
bpy.ops.wm.save_as_mainfile(filepath=f"{out_dir}/undo.blend")
bpy.ops.ed.undo_push(message="start")
for i in range(repeats):
    assert bpy.ops.cloudgen.add_cloud(cloud_type="cumulus") == {"FINISHED"}
    bpy.ops.ed.undo_push(message="Add Cloud")
    name = bpy.context.view_layer.objects.active.name
    assert bpy.ops.cloudgen.bake_vdb(resolution=8) == {"FINISHED"}
    bpy.ops.ed.undo_push(message="Bake to VDB")
    assert bpy.ops.ed.undo() == {"FINISHED"}
    cloud = bpy.data.objects.get(name)
    assert cloud is not None, f"iteration {i}: undoing the bake removed the cloud"
    assert bpy.data.objects.get(name + "_VDB") is None, f"iteration {i}: the Volume object stayed"
    assert cloud.get("cloudgen_source", "PROCEDURAL") == "PROCEDURAL", f"iteration {i}"
    assert bpy.ops.ed.undo() == {"FINISHED"}
    assert bpy.data.objects.get(name) is None, f"iteration {i}: undoing Add Cloud left {name}"
print(f"UNDO-LOOP-OK {repeats}", flush=True)
addon_utils.disable("cloudgen", default_set=True)
