"""Cloud Sky & Sun (addon/light_setup.py, addon/sky_light.py) and the sidebar's check of the
settings that make clouds dark, in the 4.5 wheel (issue 13, "Light, out of the box").

- the operator builds a Nishita sky (sun disc off), a sun lamp along the sky's sun direction
  (relative to the camera's view), AgX, the exposure rule, the cloud render settings;
- the lamp is the sky's own sun: the disc's irradiance, measured through Cycles now, equals
  the table's within 3 % per channel (the table was measured with this Blender);
- an artist's scene with 1 volume bounce, Standard view: one line each with its fix, and the
  fix clears it; Add Cloud raises 1 bounce to the cloud default and says so."""
import importlib.util
import math
import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture
def cloud(addon, scene):
    import bpy

    assert bpy.ops.cloudgen.add_cloud(cloud_type="cumulus") == {"FINISHED"}
    return bpy.context.view_layer.objects.active


def _camera(scene, yaw_deg):
    import bpy

    cam = bpy.data.objects.new("Shot", bpy.data.cameras.new("Shot"))
    scene.collection.objects.link(cam)
    cam.rotation_euler = (math.radians(90), 0.0, math.radians(yaw_deg))  # looks along +Y turned by yaw
    cam.location = (0.0, -30.0, 0.0)  # outside the cloud's box at the origin (inside, the sidebar says so)
    scene.camera = cam
    return cam


def test_sky_and_sun_match(addon, scene, cloud):
    import bpy

    sl = addon.sky_light
    cam = _camera(scene, 30.0)
    bpy.context.view_layer.update()
    view = addon.light_setup.view_azimuth(scene)
    assert bpy.ops.cloudgen.sky_setup(sun_elevation=20.0, sun_azimuth=150.0) == {"FINISHED"}
    bpy.context.view_layer.update()
    sky = next(n for n in scene.world.node_tree.nodes if n.bl_idname == "ShaderNodeTexSky")
    assert sky.sky_type in ("NISHITA", "SINGLE_SCATTERING") and not sky.sun_disc
    assert math.isclose(math.degrees(sky.sun_elevation), 20.0, abs_tol=1e-4)
    sun = bpy.data.objects[sl.SUN_LAMP]
    toward_sun = sun.matrix_world.to_3x3().col[2].normalized()  # a sun lamp shines along its -Z
    expected = sl.sun_direction(20.0, view + 150.0)
    assert toward_sun.dot(expected) > 1 - 1e-6, (tuple(toward_sun), tuple(expected), view)
    # the sun stands 150° from where the camera looks: behind it, to one side
    look = cam.matrix_world.to_3x3().col[2] * -1
    look.z = 0
    horizontal = toward_sun.copy()
    horizontal.z = 0
    angle = math.degrees(look.normalized().angle(horizontal.normalized()))
    assert abs(angle - 150.0) < 1e-3, angle
    assert math.isclose(sun.data.energy, max(sl.sun_irradiance(20.0)), rel_tol=1e-6)
    assert scene.view_settings.view_transform == "AgX"
    assert math.isclose(scene.view_settings.exposure, sl.exposure_for(20.0), abs_tol=1e-4)
    assert scene.cycles.volume_bounces == addon.operators.CLOUD_BOUNCES
    assert math.isclose(scene.cycles.sample_clamp_indirect * 2 ** scene.view_settings.exposure, 10.0, rel_tol=1e-4)
    assert addon.light_setup.dark_settings(scene) == []


def test_lamp_is_the_skys_sun():
    """The table against the disc rendered now (3 % per channel: 16 samples over a 64² disc
    image; the table's own runs repeat to 0.1 %)."""
    spec = importlib.util.spec_from_file_location("measure_sky_sun", ROOT / "scripts" / "measure_sky_sun.py")
    measure = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(measure)
    sl = measure.sky_light()
    for elevation in (6.0, 30.0):
        rgb, centre = measure.measure(elevation)
        assert centre is not None, f"no sun disc where sun_direction({elevation}) points"
        assert abs(centre[0] - 31.5) < 2 and abs(centre[1] - 31.5) < 2, (elevation, centre)
        table = sl.sun_irradiance(elevation)
        for got, want in zip(rgb, table):
            assert abs(got - want) <= 0.03 * max(table), (elevation, rgb, table)


def test_dark_settings_said_and_fixed(addon, scene, cloud):
    import bpy

    sun = bpy.data.objects.new("Artist Sun", bpy.data.lights.new("Artist Sun", "SUN"))
    scene.collection.objects.link(sun)
    scene.cycles.volume_bounces = 1
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.exposure = -5.0  # a physical sky's exposure with Cycles' default clamp 10
    scene.cycles.sample_clamp_indirect = 10.0
    found = addon.light_setup.dark_settings(scene)
    assert [fix for _, fix in found] == ["BOUNCES", "CLAMP", "VIEW"], found
    assert "Volume Bounces is 1" in found[0][0] and "Standard" in found[2][0], found
    for what in ("BOUNCES", "CLAMP", "VIEW"):
        assert bpy.ops.cloudgen.fix_dark(what=what) == {"FINISHED"}
    assert scene.cycles.sample_clamp_indirect == pytest.approx(320.0)
    assert scene.cycles.volume_bounces == addon.operators.CLOUD_BOUNCES
    assert scene.view_settings.view_transform == "AgX"
    assert addon.light_setup.dark_settings(scene) == []


def test_few_bounces_said_with_the_measured_share(addon, scene, cloud):
    """From 4 to sky_light.LOW_CLOUD_BOUNCES - 1 bounces (Volume, or Total capping it) the sidebar
    quotes the default cumulus's measured share of its light; its Fix raises both to
    CLOUD_BOUNCES; from LOW_CLOUD_BOUNCES up nothing is said. The share: the measured table,
    interpolated in log2(bounces), monotone, the table's values at its rows, 1 at 1,024; below
    4 (never quoted) not measured: ValueError."""
    import bpy

    sl = addon.sky_light
    shares = {n: sl.cumulus_light_share(n) for n in range(4, 1100)}
    assert shares[1024] == 1.0 and shares[1099] == 1.0
    assert all(shares[b] == pytest.approx(v) for b, v in sl.CUMULUS_LIGHT_BY_BOUNCES), shares
    assert all(shares[n] <= shares[n + 1] for n in range(4, 1099)), "the share falls somewhere"
    with pytest.raises(ValueError, match="measured from 4"):
        sl.cumulus_light_share(3)
    bounce_lines = lambda: [t for t, f in addon.light_setup.dark_settings(scene) if f == "BOUNCES"]  # noqa: E731
    scene.cycles.volume_bounces, scene.cycles.max_bounces = 32, 1024
    assert len(bounce_lines()) == 1 and "Volume Bounces is 32" in bounce_lines()[0], bounce_lines()
    measured = dict(sl.CUMULUS_LIGHT_BY_BOUNCES)  # the quoted share is the table's, rounded
    assert f"about {round(100 * measured[32])} % of its light" in bounce_lines()[0], bounce_lines()
    scene.cycles.volume_bounces, scene.cycles.max_bounces = 512, 64  # Total caps it
    assert len(bounce_lines()) == 1 and "Total bounces is 64" in bounce_lines()[0], bounce_lines()
    assert f"about {round(100 * measured[64])} % of its light" in bounce_lines()[0], bounce_lines()
    assert bpy.ops.cloudgen.fix_dark(what="BOUNCES") == {"FINISHED"}
    assert (scene.cycles.volume_bounces, scene.cycles.max_bounces) == (512, 512)
    assert bounce_lines() == []
    scene.cycles.volume_bounces = scene.cycles.max_bounces = sl.LOW_CLOUD_BOUNCES
    assert bounce_lines() == []
    scene.cycles.volume_bounces = sl.LOW_CLOUD_BOUNCES - 1
    assert len(bounce_lines()) == 1, bounce_lines()


def test_add_cloud_raises_one_bounce(addon, scene):
    import bpy

    scene.cycles.volume_bounces = 1
    scene.cycles.max_bounces = 1
    assert bpy.ops.cloudgen.add_cloud(cloud_type="stratus") == {"FINISHED"}
    assert scene.cycles.volume_bounces == addon.operators.CLOUD_BOUNCES
    assert scene.cycles.max_bounces >= addon.operators.CLOUD_BOUNCES
    scene.cycles.volume_bounces = 6  # an artist's own choice at or above the floor stays
    assert bpy.ops.cloudgen.add_cloud(cloud_type="stratus") == {"FINISHED"}
    assert scene.cycles.volume_bounces == 6


def test_no_light_no_sky(addon, scene, cloud):
    scene.world = None
    for obj in [o for o in scene.objects if o.type == "LIGHT"]:
        obj.hide_render = True
    found = addon.light_setup.dark_settings(scene)
    assert any("No light and no sky" in text for text, _ in found), found


def test_cirrostratus_halo_follows_the_sun(addon, scene):
    """Add Cloud → cirrostratus in a scene with the artist's own sun lamp: its halo points at
    that sun (direction within 1e-6, irradiance = strength × colour); Cloud Sky & Sun then
    points it at its own sun; a cumulus gets no halo nodes."""
    import bpy

    vm = addon.volume_material
    own = bpy.data.objects.new("Artist Sun", bpy.data.lights.new("Artist Sun", "SUN"))
    scene.collection.objects.link(own)
    own.rotation_euler = (math.radians(50.0), 0.0, math.radians(-20.0))
    own.data.energy, own.data.color = 3.0, (1.0, 0.95, 0.9)
    assert bpy.ops.cloudgen.add_cloud(cloud_type="cirrostratus") == {"FINISHED"}
    nodes = bpy.context.view_layer.objects.active.active_material.node_tree.nodes
    assert bpy.ops.cloudgen.add_cloud(cloud_type="cumulus") == {"FINISHED"}
    assert vm.HALO_SUN not in bpy.context.view_layer.objects.active.active_material.node_tree.nodes

    def halo():
        return ([nodes[vm.HALO_SUN].inputs[a].default_value for a in "XYZ"],
                list(nodes[vm.HALO_IRRADIANCE].outputs[0].default_value)[:3])

    direction, rgb = halo()
    want = own.rotation_euler.to_matrix().col[2]
    assert max(abs(a - b) for a, b in zip(direction, want)) < 1e-6, (direction, tuple(want))
    assert rgb == pytest.approx([3.0, 2.85, 2.7])
    own.hide_render = True  # Sky & Sun's own sun takes over
    _camera(scene, 0.0)
    assert bpy.ops.cloudgen.sky_setup(sun_elevation=30.0, sun_azimuth=90.0) == {"FINISHED"}
    sun = bpy.data.objects[addon.sky_light.SUN_LAMP]
    direction, rgb = halo()
    want = sun.rotation_euler.to_matrix().col[2]
    assert max(abs(a - b) for a, b in zip(direction, want)) < 1e-6, (direction, tuple(want))
    assert rgb == pytest.approx([sun.data.energy * c for c in sun.data.color])
