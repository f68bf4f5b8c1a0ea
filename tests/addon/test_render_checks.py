"""The pre-render check (addon/checks.py, render_pre) and the load_post repairs, in the
4.5 wheel (issue 12, findings 2, 3, 5 and 6): a procedural cloud under Eevee or
Workbench and a missing VDB each give one line among the clouds that would render
empty (a background render stops on them), a stale bake and denoising with no
denoiser one warning; the handler prints them on stderr (`cloudgen: warning: ...`, once for the
same set); a Render Settings with Denoise on never leaves a denoiser the build
lacks switched on; reopening a file shows the preview without an edit. The real
renders (3.4 without a denoiser, a farm without its VDB folder, a 3.4 file in 4.5)
are in tests/batch/test_blender34.py."""
import os

import pytest


@pytest.fixture
def cloud(addon, scene, tmp_path):
    import bpy

    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "c.blend"))
    assert bpy.ops.cloudgen.add_cloud(cloud_type="cumulus") == {"FINISHED"}
    return bpy.context.view_layer.objects.active


def _lines(addon, scene):
    empty, warnings = addon.checks.problems(scene)
    return empty, warnings


def test_procedural_cloud_under_eevee_or_workbench(addon, scene, cloud):
    assert _lines(addon, scene) == ([], []), "a procedural cloud in Cycles CPU + OSL is fine"
    for engine, word in (("BLENDER_WORKBENCH", "Workbench"),
                         ("BLENDER_EEVEE_NEXT" if "BLENDER_EEVEE_NEXT" in
                          [e.identifier for e in scene.render.bl_rna.properties["engine"].enum_items]
                          else "BLENDER_EEVEE", "Eevee")):
        scene.render.engine = engine
        empty, warnings = _lines(addon, scene)
        assert not warnings and len(empty) == 1, (engine, empty, warnings)
        assert f"{cloud.name} renders empty" in empty[0] and word in empty[0], (engine, empty)


def test_missing_and_stale_bake(addon, scene, cloud, tmp_path, capfd):
    import bpy

    assert bpy.ops.cloudgen.bake_vdb(resolution=12) == {"FINISHED"}
    assert _lines(addon, scene) == ([], [])
    socket = next(n.inputs["Density"] for n in addon.cloud_object.cloud_nodes(cloud) if "Density" in n.inputs)
    socket.default_value = socket.default_value * 0.5 + 0.1
    missing, warnings = _lines(addon, scene)
    assert not missing and any("stale" in w for w in warnings), warnings
    os.remove(tmp_path / "cloudgen" / "Cumulus.vdb")
    missing, warnings = _lines(addon, scene)
    assert len(missing) == 1 and "Cumulus.vdb is missing" in missing[0], missing
    capfd.readouterr()
    os.environ[addon.checks.ALLOW_EMPTY_ENV] = "1"   # the handler would end the process otherwise
    try:
        addon.checks.on_render_pre(scene)
        addon.checks.on_render_pre(scene)   # the same lines again: not printed twice
    finally:
        del os.environ[addon.checks.ALLOW_EMPTY_ENV]
    err = capfd.readouterr().err
    assert err.count("cloudgen: warning: Cumulus: the baked VDB") == 1, err


def test_stale_bake_says_why(addon, scene, cloud, monkeypatch):
    """The Bake panel and the render check say why a bake is stale: its parameters changed, or
    the same parameters give another field under this cloudgen's model (a file baked before a
    model change: the field key holds the model's version), or, for a record made before the
    parameter digests were recorded, either."""
    import bpy

    checks = addon.checks
    assert bpy.ops.cloudgen.bake_vdb(resolution=12) == {"FINISHED"}
    assert checks.stale_reason(cloud, scene) is None
    socket = next(n.inputs["Density"] for n in addon.cloud_object.cloud_nodes(cloud) if "Density" in n.inputs)
    baked_density = socket.default_value
    socket.default_value = baked_density * 0.5 + 0.1
    assert checks.stale_reason(cloud, scene) == "parameters", (baked_density, socket.default_value)
    _, warnings = checks.problems(scene)
    assert any("stale (the parameters changed since)" in w for w in warnings), warnings
    socket.default_value = baked_density
    assert checks.stale_reason(cloud, scene) is None, "the baked density again: current"
    # another model: the same parameters, another field key (what a kFieldKeyVersion bump does)
    field_keys = addon.bake_params.field_keys
    monkeypatch.setattr(addon.bake_params, "field_keys", lambda ps: [k + "0" for k in field_keys(ps)])
    assert checks.stale_reason(cloud, scene) == "model"
    _, warnings = checks.problems(scene)
    assert any("made with another cloudgen" in w for w in warnings), warnings
    record = addon.volume_object.bake_record(cloud)
    del record["params_digests"]   # a bake recorded before the digests were
    cloud[addon.volume_object.RECORD_KEY] = record
    assert checks.stale_reason(cloud, scene) == "unknown"
    _, warnings = checks.problems(scene)
    assert any("stale (the parameters or the cloud model changed since)" in w for w in warnings), warnings


def test_render_settings_never_enables_a_missing_denoiser(addon, scene, monkeypatch):
    import bpy

    bpy.ops.cloudgen.render_settings(denoise=True)
    assert scene.cycles.use_denoising, "this wheel has OpenImageDenoise: denoise stays on"
    monkeypatch.setattr(addon.checks, "_with_oidn", lambda: False)   # as in Debian's 3.4
    bpy.ops.cloudgen.render_settings(denoise=True)
    assert not scene.cycles.use_denoising
    scene.cycles.use_denoising = True
    missing, warnings = _lines(addon, scene)
    assert any("no OpenImageDenoise" in w for w in warnings), warnings


def test_reopened_file_shows_the_preview(addon, scene, cloud, tmp_path):
    import bpy

    bpy.ops.wm.save_mainfile()
    addon.preview.state.values = None
    bpy.ops.wm.open_mainfile(filepath=str(tmp_path / "c.blend"))
    assert addon.preview.state.values is not None, addon.preview.state.error


@pytest.mark.parametrize("env", [{}, {"CLOUDGEN_ALLOW_EMPTY_CLOUDS": "1"}, {"CLOUDGEN_ALLOW_MISSING_VDB": "1"},
                                 {"CLOUDGEN_ALLOW_EMPTY_CLOUDS": "0"}])
def test_allow_empty_environment(addon, monkeypatch, env):
    """Either name set to 1 lets a farm render a cloud that would come out empty (the older
    CLOUDGEN_ALLOW_MISSING_VDB still works); anything else stops the render."""
    for name in (addon.checks.ALLOW_EMPTY_ENV, addon.checks.ALLOW_MISSING_ENV):
        monkeypatch.delenv(name, raising=False)
    for name, value in env.items():
        monkeypatch.setenv(name, value)
    assert addon.checks.allowed_empty() == ("1" in env.values()), env


def test_baked_cloud_beyond_eevee_volumetrics_end(addon, scene, cloud):
    """Eevee draws volumes only between Volumetrics Start and End (view depth; 100 m by
    default): a baked cloud wholly beyond End renders empty (a farm render stops on it; the
    Debian 3.4 farm rendered a cumulonimbus 300 m away as an empty grey frame, exit 0), one
    that End cuts through is a warning, one inside is fine. Exact depths from the box's corners."""
    import bpy

    assert bpy.ops.cloudgen.bake_vdb(resolution=12) == {"FINISHED"}
    engines = [e.identifier for e in scene.render.bl_rna.properties["engine"].enum_items]
    scene.render.engine = "BLENDER_EEVEE_NEXT" if "BLENDER_EEVEE_NEXT" in engines else "BLENDER_EEVEE"
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(cam)
    scene.camera = cam
    cam.rotation_euler = (1.5707963, 0.0, 0.0)  # looking along +y
    scene.eevee.volumetric_start, scene.eevee.volumetric_end = 0.1, 100.0
    cam.data.clip_end = 1.0e4  # the camera's own clipping is another check (test_clip_end_...)
    half = cloud.dimensions.y / 2
    for y, want in ((50.0, ([], [])), (100.0, "cut"), (100.0 + half + 1.0, "empty")):
        cam.location = (cloud.location.x, cloud.location.y - y, cloud.location.z)
        bpy.context.view_layer.update()
        empty, warnings = _lines(addon, scene)
        if want == "cut":
            assert not empty and len(warnings) == 1 and "is cut off" in warnings[0], (y, empty, warnings)
        elif want == "empty":
            assert len(empty) == 1 and f"{cloud.name} renders empty: Eevee" in empty[0], (y, empty, warnings)
            assert "Volumetrics → End to at least" in empty[0], empty
        else:
            assert (empty, warnings) == want, (y, empty, warnings)
    # the sidebar says it among the settings that darken clouds, and its Fix widens the range
    found = addon.light_setup.dark_settings(scene)
    assert [fix for _, fix in found if fix == "EEVEE_RANGE"] == ["EEVEE_RANGE"], found
    far = 100.0 + half + 1.0 + half
    assert bpy.ops.cloudgen.fix_dark(what="EEVEE_RANGE") == {"FINISHED"}
    assert scene.eevee.volumetric_end == pytest.approx(1.05 * far, rel=1e-4), (scene.eevee.volumetric_end, far)
    assert scene.eevee.volumetric_start == pytest.approx(0.1), scene.eevee.volumetric_start  # never narrowed
    assert _lines(addon, scene) == ([], [])
    assert not [f for _, f in addon.light_setup.dark_settings(scene) if f == "EEVEE_RANGE"]
    scene.eevee.volumetric_end = 1000.0
    assert _lines(addon, scene) == ([], [])


def test_clip_end_said_and_fixed(addon, scene, cloud):
    """A camera whose Clip End (Blender's default 100 m) is nearer than the cloud's far side
    cuts the cloud off on a straight line (docs/addon.md): a warning before the render (not an
    empty cloud: the near part renders) and a line with a Fix in the sidebar; the Fix moves Clip
    End 5 % beyond the farthest corner (never nearer). Exact distances from the box's corners."""
    import bpy
    from mathutils import Vector

    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(cam)
    scene.camera = cam
    cam.rotation_euler = (1.5707963, 0.0, 0.0)  # looking along +y
    cam.data.clip_end = 100.0  # the startup file's camera (a new camera's is 1000 in 4.5)
    for y, cut in ((50.0, False), (99.0, True)):
        cam.location = (cloud.location.x, cloud.location.y - y, cloud.location.z)
        bpy.context.view_layer.update()
        far = max((cloud.matrix_world @ Vector(c) - cam.location).length for c in cloud.bound_box)
        assert (far > 100.0) == cut, (y, far)
        empty, warnings = _lines(addon, scene)
        lines = [w for w in warnings if "Clip End" in w]
        assert not empty, (y, empty)
        assert len(lines) == int(cut), (y, far, warnings)
        if cut:
            assert f"{cloud.name} is cut off" in lines[0] and f"at least {far:.0f} m" in lines[0], lines
    found = [f for _, f in addon.light_setup.dark_settings(scene) if f == "CLIP_END"]
    assert found == ["CLIP_END"], addon.light_setup.dark_settings(scene)
    cloud.hide_render = True  # a cloud that does not render is not cut off: neither place says so
    assert not [w for w in _lines(addon, scene)[1] if "Clip End" in w]
    assert not [f for _, f in addon.light_setup.dark_settings(scene) if f == "CLIP_END"]
    cloud.hide_render = False
    assert bpy.ops.cloudgen.fix_dark(what="CLIP_END") == {"FINISHED"}
    assert cam.data.clip_end == pytest.approx(1.05 * far, rel=1e-5), (cam.data.clip_end, far)
    assert not [w for w in _lines(addon, scene)[1] if "Clip End" in w]
    assert not [f for _, f in addon.light_setup.dark_settings(scene) if f == "CLIP_END"]
    cam.data.clip_end = 1.0e5  # never brought nearer
    assert bpy.ops.cloudgen.fix_dark(what="CLIP_END") == {"FINISHED"}
    assert cam.data.clip_end == pytest.approx(1.0e5)


def _in_frame(scene, cam, points):
    """[(x, y, depth)] of world `points` in the camera's frame: x, y as fractions of the half
    frame (|x|, |y| <= 1 inside), depth along the view (> 0 in front)."""
    from cloudgen import camera_fit
    from mathutils import Vector

    tx, ty = camera_fit.tan_half_fov(cam.data, *camera_fit.render_resolution(scene))
    to_cam = cam.matrix_world.inverted()
    out = []
    for p in points:
        q = to_cam @ Vector(p)
        out.append((q.x / (-q.z * tx), q.y / (-q.z * ty), -q.z))
    return out


@pytest.mark.parametrize("parented", [False, True])
def test_camera_inside_a_cloud_said_and_fixed(addon, scene, cloud, parented, tmp_path):
    """A camera inside a cloud's box renders fog from within the cloud, not its shape (Add Cloud
    puts the cumulonimbus's 180-unit box at the cursor, around Blender's startup camera): a warning before
    the render, a line with a Fix in the sidebar. The Fix moves the camera back along its own
    view (rotation unchanged, exactly) until every corner of the box is in front of it and in the
    frame, and Clip End reaches the far corner; nothing is said afterwards. Measured: the frame's
    share of the frame the cloud covers (the meter's 96 x 54 render, 512 bounces; looking 21°
    down, the empty scene's background below the horizon is black): from inside, fog over the
    whole frame (white near the sunlit top; measured 0.885), after the Fix the cloud against the
    background (0.192); rendered for the camera without a rig only (the rig changes no light)."""
    import bpy
    from mathutils import Vector

    bpy.ops.cloudgen.sky_setup()
    scene.cycles.volume_bounces = 512
    scene.cycles.max_bounces = 512
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(cam)
    scene.camera = cam
    if parented:  # a camera rig: the Fix sets the world place through the parent's transform
        rig = bpy.data.objects.new("Rig", None)
        scene.collection.objects.link(rig)
        rig.location, rig.rotation_euler = (3.0, -2.0, 1.0), (0.0, 0.0, 0.7)
        cam.parent = rig
    cam.rotation_euler = (1.2, 0.0, 0.4)
    bpy.context.view_layer.update()  # the rig's and the camera's world matrices, before they are read
    place = cam.matrix_world.copy()
    place.translation = cloud.matrix_world @ Vector((0.0, 0.1, 0.15))  # inside: the box is ±0.5, scaled
    cam.matrix_world = place
    bpy.context.view_layer.update()
    rotation = cam.matrix_world.to_quaternion()
    euler = tuple(cam.rotation_euler)
    inside = None if parented else _cover(addon, scene, tmp_path / "inside.exr")
    lines = [w for w in _lines(addon, scene)[1] if "inside" in w]
    assert len(lines) == 1 and f"inside {cloud.name}'s box" in lines[0], _lines(addon, scene)
    assert [f for _, f in addon.light_setup.dark_settings(scene) if f == "CAMERA_OUT"] == ["CAMERA_OUT"]

    assert bpy.ops.cloudgen.fix_dark(what="CAMERA_OUT") == {"FINISHED"}
    corners = [cloud.matrix_world @ Vector(c) for c in cloud.bound_box]
    framed = _in_frame(scene, cam, corners)
    assert all(d > cam.data.clip_start and abs(x) <= 1.0 + 1e-6 and abs(y) <= 1.0 + 1e-6 for x, y, d in framed), framed
    centre = sum(corners, Vector()) / 8
    cx, cy, _ = _in_frame(scene, cam, [centre])[0]
    assert abs(cx) < 1e-5 and abs(cy) < 1e-5, (cx, cy)  # on the view axis
    assert cam.matrix_world.to_quaternion().rotation_difference(rotation).angle < 1e-5
    if not parented:
        assert tuple(cam.rotation_euler) == euler  # untouched, bit for bit
    far = max((c - cam.matrix_world.translation).length for c in corners)
    assert cam.data.clip_end >= far, (cam.data.clip_end, far)
    assert not [w for w in _lines(addon, scene)[1] if "inside" in w or "Clip End" in w], _lines(addon, scene)
    assert not addon.light_setup.dark_settings(scene), addon.light_setup.dark_settings(scene)
    assert bpy.ops.cloudgen.fix_dark(what="CAMERA_OUT") == {"CANCELLED"}  # nothing to do: says so
    if not parented:
        outside = _cover(addon, scene, tmp_path / "outside.exr")
        print(f"cloud's share of the frame: inside {inside:.3f}, after the Fix {outside:.3f}")
        assert inside > FOG_COVER and outside < CLOUD_COVER, (inside, outside)


FOG_COVER = 0.8  # from inside: at least this share of the frame is lit (fog)
CLOUD_COVER = 0.5  # after the Fix: the whole box in the frame, the cloud on less than half of it


def _cover(addon, scene, path):
    """The share of the meter's render of the frame brighter than a tenth of its 90th percentile
    (scene-linear luminance): the part the lit cloud covers against a black background."""
    import bpy
    import numpy as np

    meter = addon.exposure_meter
    saved = meter.meter_settings(scene, str(path))
    try:
        bpy.ops.render.render(write_still=True)
    finally:
        meter.restore_settings(scene, saved)
    img = bpy.data.images.load(str(path))
    try:
        lum = np.array(img.pixels[:], dtype=np.float64).reshape(-1, 4)[:, :3] @ np.array([0.2126, 0.7152, 0.0722])
    finally:
        bpy.data.images.remove(img)
    return float((lum > 0.1 * np.percentile(lum, 90)).mean())


def test_orthographic_camera_moved_out_of_a_cloud(addon, scene, cloud):
    """An orthographic camera inside a cloud's box: the Fix moves it back along its view, rotation
    exact, until the whole box is in front of it beyond Clip Start, its centre on the view axis."""
    import bpy
    from mathutils import Vector

    cam = bpy.data.objects.new("Ortho", bpy.data.cameras.new("Ortho"))
    cam.data.type = "ORTHO"
    scene.collection.objects.link(cam)
    scene.camera = cam
    cam.rotation_euler = (1.2, 0.0, 0.4)
    cam.location = cloud.matrix_world @ Vector((0.1, 0.0, 0.0))
    bpy.context.view_layer.update()
    euler = tuple(cam.rotation_euler)
    assert [f for _, f in addon.light_setup.dark_settings(scene) if f == "CAMERA_OUT"] == ["CAMERA_OUT"]
    assert bpy.ops.cloudgen.fix_dark(what="CAMERA_OUT") == {"FINISHED"}
    assert tuple(cam.rotation_euler) == euler
    to_cam = cam.matrix_world.inverted()
    local = [to_cam @ (cloud.matrix_world @ Vector(c)) for c in cloud.bound_box]
    assert all(-q.z > cam.data.clip_start for q in local), [tuple(q) for q in local]
    centre = sum(local, Vector()) / 8
    assert abs(centre.x) < 1e-4 and abs(centre.y) < 1e-4, tuple(centre)
    assert not [f for _, f in addon.light_setup.dark_settings(scene) if f in ("CAMERA_OUT", "CLIP_END")]
