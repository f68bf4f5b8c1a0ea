"""Scene helpers for the bake tests inside bpy: a small Cycles CPU scene, a camera
that frames a cloud from -Y, a sun and a black world, render to numpy."""
import math


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
    sc.cycles.volume_bounces = 2
    sc.cycles.max_bounces = 2
    sc.render.resolution_x, sc.render.resolution_y = width, height
    sc.render.resolution_percentage = 100
    sc.view_settings.view_transform = "Standard"
    return sc


def frame_cloud(scene, obj):
    import bpy

    bx, by, bz = obj.dimensions
    aspect = scene.render.resolution_x / scene.render.resolution_y
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.data.lens = 50.0
    half_fov = math.atan(18.0 / 50.0)
    distance = 0.5 * max(bx, bz * aspect) / 0.7 / math.tan(half_fov) + by / 2
    c = obj.matrix_world.translation
    cam.location = (c[0], c[1] - distance, c[2])
    cam.rotation_euler = (math.radians(90.0), 0.0, 0.0)
    scene.collection.objects.link(cam)
    scene.camera = cam
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 5.0
    sun.rotation_euler = (math.radians(40), 0.0, math.radians(-35))
    scene.collection.objects.link(sun)
    world = bpy.data.worlds.new("Black")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
    scene.world = world


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
