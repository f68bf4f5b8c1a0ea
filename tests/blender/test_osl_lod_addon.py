"""The add-on drives Cloud Noise's LOD Pixel Angle from the scene camera
(addon/nodes.py: drive_lod_pixel_angle): radians per pixel = 2 tan(half the view
angle along the sensor fit) / pixels along it, resolution percentage applied; 0
(every octave) for an orthographic camera or none. Checked against
addon/camera_fit.py's tan_half_fov (Blender's sensor-fit rules) to 1e-6 relative
(the socket is float32).

The add-on is enabled from the packaged copy as tests/addon does (module fixture,
disabled afterwards: the 4.5 wheel hangs at exit with operators registered)."""
import addon_package
import pytest

REL = 1e-6


def _raise(exc):
    raise exc


@pytest.fixture(scope="module")
def addon():
    import addon_utils

    addon_package.ensure()
    mod = addon_utils.enable("cloudgen", default_set=False, handle_error=_raise)
    assert mod is not None, "addon_utils.enable('cloudgen') failed"
    yield mod
    addon_utils.disable("cloudgen", default_set=False, handle_error=_raise)


def driven_angle(addon, cloud):
    import bpy

    bpy.context.view_layer.update()
    _, noise = addon.cloud_object.cloud_nodes(cloud)
    return noise.node_tree.nodes["cloud_noise"].inputs["lod_pixel_angle"].default_value


def new_cloud_seen_by(sensor_fit, lens, w, h, pct):
    """A fresh file with a camera (as the default scene has), then a cumulus added."""
    import bpy

    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    cam_data = bpy.data.cameras.new("Camera")
    cam_data.sensor_fit, cam_data.lens = sensor_fit, lens
    cam = bpy.data.objects.new("Camera", cam_data)
    scene.collection.objects.link(cam)
    scene.camera = cam
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = w, h, pct
    bpy.ops.cloudgen.add_cloud(cloud_type="cumulus")
    return scene, cam_data, bpy.context.view_layer.objects.active


def want_angle(addon, scene, cam_data):
    fit = addon.camera_fit
    rw, rh = fit.render_resolution(scene)
    tx, _ = fit.tan_half_fov(cam_data, rw, rh)
    return 2.0 * tx / rw


@pytest.mark.parametrize("case", [("AUTO", 85.0, 256, 256, 100), ("AUTO", 35.0, 640, 480, 50),
                                  ("AUTO", 50.0, 300, 900, 100), ("HORIZONTAL", 50.0, 300, 900, 100),
                                  ("VERTICAL", 24.0, 1920, 1080, 25)])
def test_pixel_angle_is_the_scene_cameras(addon, case):
    scene, cam_data, cloud = new_cloud_seen_by(*case)
    got, want = driven_angle(addon, cloud), want_angle(addon, scene, cam_data)
    assert got == pytest.approx(want, rel=REL), (case, got, want)


def test_pixel_angle_follows_lens_and_camera_type(addon):
    scene, cam_data, cloud = new_cloud_seen_by("AUTO", 85.0, 256, 256, 100)
    cam_data.lens = 35.0
    got, want = driven_angle(addon, cloud), want_angle(addon, scene, cam_data)
    assert got == pytest.approx(want, rel=REL), ("lens 35", got, want)
    cam_data.type = "ORTHO"
    assert driven_angle(addon, cloud) == 0.0, "orthographic camera: LOD off"


def test_no_camera_means_every_octave(addon):
    """Without a scene camera the driver cannot resolve: the input stays 0, every octave
    (the cloud renders at full detail; docs/osl.md says how to refresh the driver)."""
    import bpy

    bpy.ops.wm.read_homefile(use_empty=True)
    bpy.ops.cloudgen.add_cloud(cloud_type="cumulus")
    assert driven_angle(addon, bpy.context.view_layer.objects.active) == 0.0


def test_camera_added_after_the_cloud(addon):
    """A cloud added before the scene had a camera: Blender marks its driver invalid and never
    retries it; the pre-render check re-enables it, so the render follows the camera added
    since (tolerance REL)."""
    import bpy

    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    # Cycles on the CPU with OSL: in the empty file's engine the cloud would render empty, and
    # the pre-render check would end this background process (checks.on_render_pre)
    scene.render.engine = "CYCLES"
    scene.cycles.device, scene.cycles.shading_system = "CPU", True
    bpy.ops.cloudgen.add_cloud(cloud_type="cumulus")
    cloud = bpy.context.view_layer.objects.active
    assert driven_angle(addon, cloud) == 0.0
    cam_data = bpy.data.cameras.new("Camera")
    cam = bpy.data.objects.new("Camera", cam_data)
    scene.collection.objects.link(cam)
    scene.camera = cam
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = 256, 256, 100
    addon.checks.on_render_pre(scene)
    got, want = driven_angle(addon, cloud), want_angle(addon, scene, cam_data)
    assert got == pytest.approx(want, rel=REL), (got, want)
