"""A saved .blend renders in a fresh process that never enables the add-on: the
Script nodes' shaders travel as internal text (and compiled bytecode), the
groups and drivers are plain Blender data."""
import pathlib
import subprocess
import sys
import textwrap

from addon_helpers import add_camera_and_sun, load_rgb

SCRIPT = textwrap.dedent("""
    import sys, bpy, addon_utils
    bpy.ops.wm.open_mainfile(filepath=sys.argv[1])
    assert not any(m.__name__ == "cloudgen" for m in addon_utils.modules() if addon_utils.check(m.__name__)[1])
    assert "cloudgen" not in sys.modules
    scene = bpy.context.scene
    scene.render.filepath = sys.argv[2]
    bpy.ops.render.render(write_still=True)
    print("rendered", sys.argv[2])
""")


def test_saved_blend_renders_without_the_addon(addon, scene, tmp_path):
    import bpy

    bpy.ops.cloudgen.add_cloud(cloud_type="cumulus")
    obj = bpy.context.view_layer.objects.active
    obj.location = (1.0, 2.0, 3.0)  # the drivers must carry the box into the saved file
    add_camera_and_sun(scene, obj)
    scene.render.image_settings.file_format = "PNG"
    blend = tmp_path / "cloud.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(blend), copy=True)
    out = tmp_path / "fresh.png"
    env_python = str(pathlib.Path(sys.executable))
    run = subprocess.run([env_python, "-c", SCRIPT, str(blend), str(out)], cwd=str(tmp_path),
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0 and out.exists(), run.stdout[-2000:] + run.stderr[-2000:]
    rgb = load_rgb(out)
    lit = (rgb.max(axis=-1) > 0.02).mean()
    assert lit > 0.02, f"fresh process rendered {lit:.1%} cloud pixels"
