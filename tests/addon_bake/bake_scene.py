"""Scene helpers for the bake tests inside bpy: a small Cycles CPU scene, a camera
that frames a cloud from -Y, a sun and a black world, render to numpy."""
from scene_helpers import frame_cloud  # noqa: F401  (re-exported)


def small_scene(width=48, height=36, samples=4, seed=1, osl=True):
    import bpy

    bpy.ops.wm.read_homefile(use_empty=True)
    sc = bpy.context.scene
    sc.render.engine = "CYCLES"
    sc.cycles.device = "CPU"
    sc.cycles.shading_system = osl
    sc.cycles.samples = samples
    sc.cycles.seed = seed
    sc.cycles.use_denoising = False
    sc.cycles.volume_bounces = 4  # Add Cloud raises fewer than 4 (operators.MIN_CLOUD_BOUNCES)
    sc.cycles.max_bounces = 2
    sc.render.resolution_x, sc.render.resolution_y = width, height
    sc.render.resolution_percentage = 100
    sc.view_settings.view_transform = "Standard"
    return sc


def render_rgb(scene, path):
    """Render to a float EXR (linear radiance, no 8-bit rounding) and return RGB as numpy."""
    import bpy
    import numpy as np

    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(str(path), check_existing=False)
    w, h = img.size
    px = np.empty(w * h * 4, dtype=np.float32)
    img.pixels.foreach_get(px)
    bpy.data.images.remove(img)
    return px.reshape(h, w, 4)[..., :3]
