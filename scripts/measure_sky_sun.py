"""Measure the irradiance of the Nishita sky's sun disc, per sun elevation: the table
SUN_IRRADIANCE in addon/sky_light.py (docs/lighting.md).

Usage: .venv/bin/python scripts/measure_sky_sun.py [ELEVATION_DEG ...]

For each elevation: a camera with a 2° field of view is aimed along sky_light.sun_direction
(so the disc must sit at the image centre: the direction convention is checked too), the sky
alone is rendered with the sun disc on and off (64 x 64 pixels, 16 samples, linear EXR), and
the difference is summed over the pixels times each pixel's solid angle: E = sum (L_on - L_off)
dOmega, per channel. Prints one line per elevation: the irradiance and the disc's centroid.
"""
import importlib.util
import math
import os
import pathlib
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
SIZE = 64
FOV_DEG = 2.0


def sky_light():
    spec = importlib.util.spec_from_file_location("cloudgen_sky_light", ROOT / "addon" / "sky_light.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _render_sky(sl, elevation, rotation, disc, path):
    import bpy
    import numpy as np

    bpy.ops.wm.read_homefile(use_empty=True)  # not factory settings: that would disable add-ons
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = 16
    scene.cycles.use_denoising = False
    scene.render.resolution_x = scene.render.resolution_y = SIZE
    scene.render.resolution_percentage = 100
    world = sl.make_sky(scene, elevation, rotation)
    world.node_tree.nodes["Sky Texture"].sun_disc = disc
    cam_data = bpy.data.cameras.new("Camera")
    cam_data.angle = math.radians(FOV_DEG)
    cam = bpy.data.objects.new("Camera", cam_data)
    scene.collection.objects.link(cam)
    scene.camera = cam
    cam.rotation_euler = sl.sun_direction(elevation, rotation).to_track_quat("-Z", "Y").to_euler()
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(path)
    pixels = np.array(image.pixels[:], dtype=np.float64).reshape(SIZE, SIZE, 4)[..., :3]
    bpy.data.images.remove(image)
    return pixels


def measure(elevation, rotation=30.0):
    """(irradiance rgb, (centroid x, y) of the disc in pixels, or None when no disc was seen)."""
    import numpy as np

    sl = sky_light()
    with tempfile.TemporaryDirectory(prefix="cloudgen-sky-") as work:
        on = _render_sky(sl, elevation, rotation, True, os.path.join(work, "on.exr"))
        off = _render_sky(sl, elevation, rotation, False, os.path.join(work, "off.exr"))
    diff = on - off
    pixel_solid_angle = (2.0 * math.tan(math.radians(FOV_DEG / 2)) / SIZE) ** 2
    irradiance = tuple(float(v) for v in diff.reshape(-1, 3).sum(axis=0) * pixel_solid_angle)
    mono = diff.sum(axis=2)
    if mono.max() <= 0:
        return irradiance, None
    ys, xs = np.nonzero(mono > 0.1 * mono.max())
    return irradiance, (float(xs.mean()), float(ys.mean()))


def main(argv):
    elevations = [float(a) for a in argv] or [1, 2, 4, 6, 10, 15, 20, 30, 45, 60, 90]
    for e in elevations:
        rgb, centre = measure(e)
        print(f"({e:.1f}, ({rgb[0]:.3f}, {rgb[1]:.3f}, {rgb[2]:.3f})),  # disc centre {centre}", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
