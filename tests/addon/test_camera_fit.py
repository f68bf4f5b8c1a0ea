"""addon/camera_fit.py: CAMERA.json for the camera-aware bake. Imported the way the
benchmark helper does (addon/ on sys.path, `import camera_fit`), no add-on needed.

Checked: a hand-computed case (camera 10 units in front of the box, 50 mm lens,
36 mm sensor, 1920x1080 at 50 %), then rotated / scaled / parented clouds and
cameras under every sensor fit, landscape and portrait: the box centre and its
8 corners projected with the JSON (camera_fit.project) agree with
bpy_extras.object_utils.world_to_camera_view. Tolerance: 2e-5 in image units
(u, v in [0, 1]) and 2e-5 relative in depth — Blender's matrices are float32
(about 1e-7 relative) and the points are at most ~30 units away, so any real
error (a wrong axis, fit or aspect) is orders of magnitude larger."""
import math
import pathlib
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
TOL = 2e-5


@pytest.fixture(scope="module")
def camera_fit():
    sys.path.insert(0, str(ROOT / "addon"))
    try:
        import camera_fit as mod
    finally:
        sys.path.remove(str(ROOT / "addon"))
    return mod


def _empty_scene(res=(1920, 1080), percentage=50):
    import bpy

    bpy.ops.wm.read_homefile(use_empty=True)
    sc = bpy.context.scene
    sc.render.resolution_x, sc.render.resolution_y = res
    sc.render.resolution_percentage = percentage
    sc.render.pixel_aspect_x = sc.render.pixel_aspect_y = 1.0
    return sc


def _cube(scene, name, scale=(1, 1, 1), location=(0, 0, 0), rotation=(0, 0, 0)):
    import bpy

    h = 0.5
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([(x, y, z) for x in (-h, h) for y in (-h, h) for z in (-h, h)], [], [])
    obj = bpy.data.objects.new(name, mesh)
    obj.scale, obj.location, obj.rotation_euler = scale, location, rotation
    scene.collection.objects.link(obj)
    return obj


def _camera(scene, location, rotation, lens=50.0, fit="AUTO"):
    import bpy

    cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
    cam.location, cam.rotation_euler = location, rotation
    cam.data.lens, cam.data.sensor_fit = lens, fit
    cam.data.sensor_width, cam.data.sensor_height = 36.0, 24.0
    scene.collection.objects.link(cam)
    scene.camera = cam
    return cam


def _box_points_world(cloud):
    from mathutils import Vector

    pts = [Vector((0.0, 0.0, 0.0))] + [Vector((x, y, z)) for x in (-.5, .5) for y in (-.5, .5)
                                       for z in (-.5, .5)]
    return [cloud.matrix_world @ p for p in pts]


def _to_local_rigid(cloud, world):
    """World point → the cloud's local frame without scale, computed independently of
    camera_fit (decompose, drop the scale)."""
    from mathutils import Matrix

    loc, rot, _ = cloud.matrix_world.decompose()
    return (Matrix.Translation(loc) @ rot.to_matrix().to_4x4()).inverted() @ world


def _compare(camera_fit, scene, cam, cloud):
    import bpy
    from bpy_extras.object_utils import world_to_camera_view

    bpy.context.view_layer.update()
    data = camera_fit.camera_json(scene, cam, cloud)
    worst = 0.0
    for world in _box_points_world(cloud):
        u, v, d = camera_fit.project(data, _to_local_rigid(cloud, world))
        ref = world_to_camera_view(scene, cam, world)
        assert ref.z > 0.1, "test setup: every box point in front of the camera"
        worst = max(worst, abs(u - ref.x), abs(v - ref.y), abs(d - ref.z) / ref.z)
    assert worst < TOL, f"projection differs by {worst:.2e}"
    return data


def test_hand_computed_case(camera_fit):
    sc = _empty_scene((1920, 1080), 50)
    cloud = _cube(sc, "Cloud", scale=(4, 4, 3))
    cam = _camera(sc, (0.0, -10.0, 0.0), (math.radians(90), 0.0, 0.0))
    data = _compare(camera_fit, sc, cam, cloud)
    assert data["resolution"] == [960, 540]
    # horizontal fit (landscape): tan = 18 / 50; vertical = that * 540 / 960
    assert data["tan_half_fov"] == pytest.approx([0.36, 0.36 * 540 / 960], abs=1e-9)
    # camera X → X, camera Y → +Z, camera Z (backwards) → -Y; camera at y = -10
    expect = [[1, 0, 0, 0], [0, 0, -1, -10], [0, 1, 0, 0], [0, 0, 0, 1]]
    for row, exp in zip(data["camera_to_cloud"], expect):
        assert row == pytest.approx(exp, abs=1e-6)
    assert "margin" not in data and "pixels_per_voxel" not in data, data  # the CLI's / tier's defaults
    assert data["light_directions"] == [] and data["near"] == pytest.approx(cam.data.clip_start), data
    # by hand: centre at the image centre, depth 10; corner (2, -2, 1.5) at depth 8:
    # u = 0.5 + 0.5 * (2 / 8) / 0.36, v = 0.5 + 0.5 * (1.5 / 8) / 0.2025
    assert camera_fit.project(data, (0, 0, 0)) == pytest.approx((0.5, 0.5, 10.0), abs=1e-6)
    assert camera_fit.project(data, (2, -2, 1.5)) == pytest.approx(
        (0.5 + 0.25 / 0.72, 0.5 + 0.1875 / 0.405, 8.0), abs=1e-6)


@pytest.mark.parametrize("fit,res", [("AUTO", (640, 480)), ("AUTO", (480, 640)),
                                     ("HORIZONTAL", (480, 640)), ("VERTICAL", (640, 480)),
                                     ("VERTICAL", (300, 700))])
def test_sensor_fits_match_blender(camera_fit, fit, res):
    from mathutils import Vector

    sc = _empty_scene(res, 75)
    parent = _cube(sc, "Parent", scale=(2, 2, 2), location=(1, 2, 0.5), rotation=(0.1, -0.2, 0.7))
    cloud = _cube(sc, "Cloud", scale=(3, 1.5, 1), location=(0.5, -0.3, 1.0), rotation=(0.3, 0.2, -0.4))
    cloud.parent = parent
    cam = _camera(sc, (9.0, -14.0, 6.0), (0, 0, 0), lens=35.0, fit=fit)
    sc.view_layers[0].update()
    target = cloud.matrix_world.translation
    cam.rotation_euler = (target - Vector(cam.location)).to_track_quat("-Z", "Y").to_euler()
    data = _compare(camera_fit, sc, cam, cloud)
    assert data["resolution"] == [int(res[0] * 0.75), int(res[1] * 0.75)]
    tx, ty = data["tan_half_fov"]
    assert tx / ty == pytest.approx(res[0] / res[1], rel=1e-9)


def test_camera_scale_is_ignored(camera_fit):
    sc = _empty_scene((400, 300), 100)
    cloud = _cube(sc, "Cloud", scale=(4, 4, 3), rotation=(0, 0, 0.5))
    cam = _camera(sc, (0.0, -12.0, 1.0), (math.radians(85), 0.0, 0.1))
    cam.scale = (3.0, 3.0, 3.0)
    _compare(camera_fit, sc, cam, cloud)


def test_shift_warns_and_other_types_fail(camera_fit):
    sc = _empty_scene((400, 300), 100)
    cloud = _cube(sc, "Cloud", scale=(4, 4, 3))
    cam = _camera(sc, (0.0, -10.0, 0.0), (math.radians(90), 0.0, 0.0))
    warnings = []
    camera_fit.camera_json(sc, cam, cloud, warnings)
    assert warnings == []
    cam.data.shift_x = 0.1
    camera_fit.camera_json(sc, cam, cloud, warnings)
    assert len(warnings) == 1 and "shift" in warnings[0] and "'Cam'" in warnings[0]
    cam.data.type = "ORTHO"
    with pytest.raises(ValueError, match="'Cam' is orthographic"):
        camera_fit.camera_json(sc, cam, cloud)
    cam.data.type = "PANO"
    with pytest.raises(ValueError, match="'Cam' is panoramic"):
        camera_fit.camera_json(sc, cam, cloud)
    with pytest.raises(ValueError, match="no camera"):
        camera_fit.camera_json(sc, None, cloud)
    with pytest.raises(ValueError, match="not a camera"):
        camera_fit.camera_json(sc, cloud, cloud)


def test_sun_lamps_become_light_directions_in_the_cloud_frame(camera_fit):
    """A sun shines along its local -Z: the direction towards it is its +Z axis,
    expressed in the cloud's (rotated) frame; hidden suns and point lamps do not count."""
    import bpy

    sc = _empty_scene((64, 48), 50)
    cloud = _cube(sc, "Cloud", scale=(4, 4, 3))
    cloud.rotation_euler = (0.0, 0.0, math.radians(90))
    cam = _camera(sc, (0.0, -10.0, 0.0), (math.radians(90), 0.0, 0.0))
    for name, kind, rot, hidden in (("Sun", "SUN", (0.0, 0.0, 0.0), False),
                                    ("Tilted", "SUN", (math.radians(90), 0.0, 0.0), False),
                                    ("Hidden", "SUN", (0.0, 0.0, 0.0), True),
                                    ("Point", "POINT", (0.0, 0.0, 0.0), False)):
        obj = bpy.data.objects.new(name, bpy.data.lights.new(name, kind))
        obj.rotation_euler = rot
        obj.hide_render = hidden
        sc.collection.objects.link(obj)
    bpy.context.view_layer.update()
    dirs = sorted(camera_fit.camera_json(sc, cam, cloud)["light_directions"])
    # overhead sun: +z; tilted 90° about x: its +Z points to world -y; the cloud,
    # turned 90° about z, has its +x along world +y, so that is its -x
    expect = sorted([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0]])
    assert len(dirs) == 2, dirs
    for got, exp in zip(dirs, expect):
        assert got == pytest.approx(exp, abs=1e-6), (dirs, "tolerance 1e-6")
