"""Scene helpers shared by the tests that render inside the bpy wheel (tests/addon,
tests/addon_bake): a camera that frames a cloud from -Y, a sun, a black world
(every lit pixel is the cloud), and loading a rendered image as numpy."""
import math


def frame_cloud(scene, obj, fill=0.7):
    """Camera on -Y looking at the box's centre (the box fills `fill` of the frame
    at the scene's aspect), a sun, a black world."""
    import bpy

    bpy.context.view_layer.update()  # matrix_world of a just-created object
    bx, by, bz = obj.dimensions
    aspect = scene.render.resolution_x / scene.render.resolution_y
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.data.lens = 50.0
    half_fov = math.atan(18.0 / 50.0)
    distance = 0.5 * max(bx, bz * aspect) / fill / math.tan(half_fov) + by / 2
    c = obj.matrix_world.translation
    cam.location = (c[0], c[1] - distance, c[2])
    cam.rotation_euler = (math.radians(90.0), 0.0, 0.0)
    if max(bx, by) > 8.0 * bz:
        # a layer (a sheet, tens to hundreds of units wide and thin) is a line edge-on: look down at its
        # sunlit top instead (from below a thick one, nimbostratus, is dark in this black world), 30
        # degrees below the horizon, the sheet's centre ahead in the frame
        rise = 0.15 * by
        cam.location = (c[0], c[1] - rise / math.tan(math.radians(30.0)), c[2] + rise)
        cam.rotation_euler = (math.radians(60.0), 0.0, 0.0)
        cam.data.clip_end = 10.0 * max(bx, by)
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


def load_rgb(path):
    """A rendered image's stored values (no colour transform) as float RGB."""
    import bpy
    import numpy as np

    img = bpy.data.images.load(str(path), check_existing=False)
    img.colorspace_settings.name = "Non-Color"
    w, h = img.size
    px = np.array(img.pixels[:], dtype=np.float32).reshape(h, w, 4)[..., :3]
    bpy.data.images.remove(img)
    return px
