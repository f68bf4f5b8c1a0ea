"""Helpers of the add-on tests (a scene to render a cloud in, image loading)."""
import math
import pathlib

ROOT = pathlib.Path(__file__).resolve().parents[2]


def add_camera_and_sun(scene, obj):
    """Camera on -Y looking at the box's centre (the box fills ~70 % of the frame),
    a sun, a black world: every lit pixel is the cloud."""
    import bpy

    bx, _, bz = obj.dimensions
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.data.lens = 50.0
    half_fov = math.atan(18.0 / 50.0)
    distance = 0.5 * max(bx, bz * 48 / 36) / 0.7 / math.tan(half_fov) + obj.dimensions[1] / 2
    c = obj.location
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


def render_to_array(scene, path):
    """Render scene to a PNG at path and return its RGB pixels as floats."""
    import bpy

    scene.render.image_settings.file_format = "PNG"
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)
    return load_rgb(path)


def load_rgb(path):
    import bpy
    import numpy as np

    img = bpy.data.images.load(str(path), check_existing=False)
    img.colorspace_settings.name = "Non-Color"
    w, h = img.size
    px = np.array(img.pixels[:], dtype=np.float32).reshape(h, w, 4)[..., :3]
    bpy.data.images.remove(img)
    return px
