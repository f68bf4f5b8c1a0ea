"""Run inside Debian's Blender 3.4 (no OSL) by test_blender34.py:

    blender -b --factory-startup --python-exit-code 1 --python tests/batch/bake_types.py -- \
        OUT_DIR TYPE[,TYPE...] [--farm]

Enables the packaged add-on (BLENDER_USER_SCRIPTS/addons/cloudgen), and for each
type: an empty scene saved as OUT_DIR/TYPE.blend, the add-on's cloud, a bake at
resolution 24, a Cycles CPU render of the baked cloud (32x24, 2 spp) to
OUT_DIR/TYPE.png, after Cloud Render Settings (which must leave the missing
denoiser off). With --farm the last scene keeps frames 1-2 baked as a sequence
and is saved for the farm command line, and OUT_DIR/procedural.blend holds an
unbaked cloud of the first type (its Script nodes never compiled: no OSL here).
Asserts the add-on finds no cloudgen executable (it bakes through pyopenvdb). Prints one line per type:
`BATCH-RESULT {json}`. Any exception fails Blender's exit code."""
import json
import pathlib
import sys

import addon_utils
import bpy

argv = sys.argv[sys.argv.index("--") + 1:]
out_dir, types, farm = argv[0], argv[1].split(","), "--farm" in argv

mod = addon_utils.enable("cloudgen", default_set=True, handle_error=lambda exc: (_ for _ in ()).throw(exc))
assert mod is not None, "cannot enable the cloudgen add-on"
from cloudgen import bridge, checks, cloud_object, volume_object  # noqa: E402

# the zip carries no executable and the add-on looks for none: it bakes with Blender's OpenVDB
assert bridge.cloudgen_executable() is None, bridge.cloudgen_executable()
assert not (pathlib.Path(mod.__file__).parent / "bin").exists(), "a bin/ folder is in the package"

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
from scene_helpers import frame_cloud  # noqa: E402


def scene_for(name):
    bpy.ops.wm.read_homefile(use_empty=True)
    sc = bpy.context.scene
    sc.render.engine = "CYCLES"  # 3.4 starts in Eevee
    sc.cycles.device = "CPU"
    sc.cycles.samples = 2
    sc.render.resolution_x, sc.render.resolution_y = 32, 24
    sc.render.resolution_percentage = 100
    sc.view_settings.view_transform = "Standard"
    sc.frame_start, sc.frame_end = 1, 2
    bpy.ops.wm.save_as_mainfile(filepath=f"{out_dir}/{name}.blend")
    return sc


for i, kind in enumerate(types):
    sc = scene_for(kind)
    cloud = cloud_object.create_cloud(bpy.context, kind)
    frame_cloud(sc, cloud, fill=0.8)
    # Cloud Render Settings (what an artist presses) must leave a denoiser this build lacks off
    assert bpy.ops.cloudgen.render_settings(procedural=False) == {"FINISHED"}
    assert not checks.denoiser_missing(sc), (sc.cycles.use_denoising, sc.cycles.denoiser)
    sc.cycles.samples = 2
    sequence = farm and i == len(types) - 1
    assert bpy.ops.cloudgen.bake_vdb(resolution=24, sequence=sequence) == {"FINISHED"}
    vdb = volume_object.baked_object(cloud)
    assert vdb is not None and cloud["cloudgen_source"] == "BAKED" and cloud.hide_render
    sc.render.image_settings.file_format = "PNG"
    sc.render.filepath = f"{out_dir}/{kind}.png"
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(sc.render.filepath)
    px = list(img.pixels)
    lum = [max(px[j:j + 3]) for j in range(0, len(px), 4)]
    lit = sum(v > 0.02 for v in lum) / len(lum)
    print("BATCH-RESULT " + json.dumps({"type": kind, "vdb": bpy.path.abspath(vdb.data.filepath),
                                        "lit": lit, "max": max(lum), "version": bpy.app.version_string}),
          flush=True)
    if sequence:
        bpy.ops.wm.save_mainfile()

if farm:  # a procedural cloud saved in this Blender without OSL, for the 4.5 wheel to render
    sc = scene_for("procedural")
    cloud = cloud_object.create_cloud(bpy.context, types[0])
    frame_cloud(sc, cloud, fill=0.8)
    assert bpy.ops.cloudgen.render_settings(procedural=True) == {"FINISHED"}
    sc.cycles.samples = 4
    bpy.ops.wm.save_mainfile()

addon_utils.disable("cloudgen", default_set=True)
