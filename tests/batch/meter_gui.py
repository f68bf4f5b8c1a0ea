"""Run inside Debian's Blender 3.4 with its window (under xvfb-run;
tests/batch/test_gui34.py): Meter Exposure as the sidebar button calls it (invoke, a window).

    xvfb-run -a blender --factory-startup --python tests/batch/meter_gui.py -- OUT.json

Two runs, driven by a timer:
- metered: a uniform white world of radiance 4 x GLARE_LIGHT, the add-on's sun at 40°; the
  operator starts the render as a job and returns RUNNING_MODAL; when it ends, the exposure is
  exposure_for(40) - 2 stops and the render settings are back;
- cancelled: a slow frame (a noisy volume cube at step rate 0.01) and Esc pressed (xdotool) a
  second after the start: the exposure stays as it was and the settings come back.
Either way no render window opens, and the operator's handlers and its private folder (in
TMPDIR, which the test makes empty) are removed. What each run
saw goes to OUT.json; Blender quits when done (or after TIMEOUT seconds)."""
import glob
import json
import os
import subprocess
import sys
import tempfile
import time

import addon_utils
import bpy

OUT = sys.argv[sys.argv.index("--") + 1]
TIMEOUT = 240.0
results = {}


def _settings(scene):
    r = scene.render
    return [r.resolution_x, r.resolution_y, scene.cycles.samples, r.image_settings.file_format, r.filepath]


def _override():
    win = bpy.context.window_manager.windows[0]
    area = next(a for a in win.screen.areas if a.type == "VIEW_3D")
    return dict(window=win, area=area, region=next(r for r in area.regions if r.type == "WINDOW"))


def _slow_volume(scene):
    bpy.ops.mesh.primitive_cube_add(size=20.0)
    mat = bpy.data.materials.new("Slow")
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    noise, vol = nt.nodes.new("ShaderNodeTexNoise"), nt.nodes.new("ShaderNodeVolumePrincipled")
    noise.inputs["Detail"].default_value = 15.0
    nt.links.new(noise.outputs["Fac"], vol.inputs["Density"])
    nt.links.new(vol.outputs["Volume"], nt.nodes["Material Output"].inputs["Volume"])
    mat.cycles.volume_step_rate = 0.01
    bpy.context.active_object.data.materials.append(mat)
    scene.cycles.volume_bounces = 64


def _handler_count():
    return len(bpy.app.handlers.render_complete) + len(bpy.app.handlers.render_cancel)


def steps():
    cloudgen = sys.modules["cloudgen"]
    meter, sky_light = cloudgen.exposure_meter, cloudgen.sky_light
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    bpy.data.objects.remove(bpy.data.objects["Cube"])
    world = bpy.data.worlds.new("White")
    world.use_nodes = True
    background = world.node_tree.nodes["Background"]
    background.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    background.inputs["Strength"].default_value = 4.0 * meter.GLARE_LIGHT
    scene.world = world
    sky_light.make_sun(scene, 40.0, 0.0)
    handlers = _handler_count()
    for run in ("metered", "cancelled"):
        if run == "cancelled":
            _slow_volume(scene)
        scene.view_settings.exposure = 1.25
        before = _settings(scene)
        windows = len(bpy.context.window_manager.windows)
        with bpy.context.temp_override(**_override()):
            started = bpy.ops.cloudgen.meter_exposure("INVOKE_DEFAULT")
        if run == "cancelled":  # a real key press, through the X server as an artist's would
            yield 1.0
            subprocess.run(["xdotool", "mousemove", "400", "300", "key", "Escape"], check=True, timeout=30)
        t0 = time.monotonic()
        while _handler_count() != handlers and time.monotonic() - t0 < TIMEOUT:
            yield 0.1
        results[run] = {"started": sorted(started), "seconds": round(time.monotonic() - t0, 2),
                        "handlers_left": _handler_count() - handlers,
                        "exposure": scene.view_settings.exposure,
                        "want": sky_light.exposure_for(40.0) - 2.0 if run == "metered" else 1.25,
                        "settings_back": _settings(scene) == before,
                        "folders_left": len(glob.glob(os.path.join(tempfile.gettempdir(), "cloudgen-meter-*"))),
                        "windows": [windows, len(bpy.context.window_manager.windows)]}
        yield 0.5


def main():
    addon_utils.enable("cloudgen", default_set=True)
    it = steps()

    def tick():
        try:
            return next(it)
        except StopIteration:
            pass
        except Exception as exc:  # noqa: BLE001 - reported in OUT, then quit
            results["error"] = repr(exc)
        with open(OUT, "w") as f:
            json.dump(results, f, indent=1)
        bpy.ops.wm.quit_blender()
        return None

    bpy.app.timers.register(tick, first_interval=1.0)


main()
