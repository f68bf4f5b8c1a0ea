"""Meter Exposure (addon/light_setup.py, addon/exposure_meter.py) in the 4.5 wheel: the exposure
a camera's meter would give, from a 96 x 54 test render.

The frame is a uniform white world of radiance S (the camera looks down, away from the sun
lamp), so the meter reads S (Cycles samples a constant background exactly; tolerance 0.02 stops
as in tests/blender/test_gallery_meter.py). With the add-on's sun at 40°: up to GLARE_LIGHT the
exposure is sky_light.exposure_for(40) (0.02 stops); at S = 4 x GLARE_LIGHT two stops less. An
artist's sun twice as strong: one stop less for its light, and the same two stops for a frame
twice as bright. Without a sun lamp: a clear error, nothing changed. The scene's render settings
come back as they were. A stratus deck above the camera that hides the sun (it lets through
well under exposure_meter.SHARE_OVERCAST of the sun's direct light; the deck is out of the
frame): the overcast's exposure, log2(OVERCAST_KEY / S) (0.02 stops) and, white balance on,
OVERCAST_BALANCE_K (1 K); the same deck hidden from the render: the sun's exposure again, the
balance left as it was."""
import math

import pytest

STOPS = 0.02  # the meter's tolerance, stops


def _camera_looking_down(scene):
    import bpy

    cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))  # a new camera looks along -Z
    scene.collection.objects.link(cam)
    scene.camera = cam


def _settings(scene):
    r = scene.render
    return (r.resolution_x, r.resolution_y, r.resolution_percentage, scene.cycles.samples,
            scene.cycles.use_denoising, r.image_settings.file_format, r.filepath)


@pytest.mark.parametrize("glare,strength", [(0.25, 1.0), (4.0, 1.0), (4.0, 2.0)],
                         ids=["sunny", "glare", "glare-artist-sun"])
def test_meter_exposure(addon, scene, uniform_world, glare, strength):
    import bpy

    sl, meter = addon.sky_light, addon.exposure_meter
    _camera_looking_down(scene)
    sun = sl.make_sun(scene, 40.0, 0.0)
    sun.data.energy *= strength
    radiance = glare * meter.GLARE_LIGHT * strength
    uniform_world(scene, radiance)
    scene.render.filepath = "//keep_me_"
    before = _settings(scene)
    assert bpy.ops.cloudgen.meter_exposure() == {"FINISHED"}
    assert _settings(scene) == before
    want = sl.exposure_for(40.0) - math.log2(strength) - max(math.log2(glare), 0.0)
    got = scene.view_settings.exposure
    assert abs(got - want) < STOPS, f"S {radiance:g}, sun x{strength:g}: exposure {got:.4f}, want {want:.4f}"


def test_meter_exposure_needs_a_sun(addon, scene, uniform_world):
    import bpy

    _camera_looking_down(scene)
    uniform_world(scene, 1.0)
    scene.view_settings.exposure = 1.25
    with pytest.raises(RuntimeError, match="needs a Sun lamp"):
        bpy.ops.cloudgen.meter_exposure()
    assert scene.view_settings.exposure == 1.25


def test_meter_exposure_under_a_deck(addon, scene, uniform_world):
    import bpy

    sl, meter = addon.sky_light, addon.exposure_meter
    _camera_looking_down(scene)
    sl.make_sun(scene, 40.0, 0.0)
    radiance = 2.0
    uniform_world(scene, radiance)
    deck = addon.cloud_object.create_cloud(bpy.context, "stratus", location=(0.0, 0.0, 3.0))  # 1.5 thick
    share = addon.light_setup.sunlit_share(scene, addon.volume_material.scene_sun(scene))
    assert share < meter.SHARE_OVERCAST, f"the stratus deck lets {share:.3f} of the sun through"
    vs = scene.view_settings
    vs.use_white_balance, vs.white_balance_temperature = True, 4800.0
    assert bpy.ops.cloudgen.meter_exposure() == {"FINISHED"}
    want, got = math.log2(meter.OVERCAST_KEY / radiance), vs.exposure
    assert abs(got - want) < STOPS, \
        f"S {radiance:g} under the deck (share {share:.4f}): exposure {got:.4f}, want {want:.4f}"
    assert abs(vs.white_balance_temperature - meter.OVERCAST_BALANCE_K) < 1.0, vs.white_balance_temperature
    deck.hide_render = True
    vs.white_balance_temperature = 4800.0
    assert bpy.ops.cloudgen.meter_exposure() == {"FINISHED"}
    want, got = sl.exposure_for(40.0), vs.exposure
    assert abs(got - want) < STOPS, f"S {radiance:g}, the deck hidden: exposure {got:.4f}, want {want:.4f}"
    assert vs.white_balance_temperature == 4800.0, vs.white_balance_temperature


def test_blended_balance(addon):
    meter = addon.exposure_meter
    assert abs(meter.blended_balance(4600.0, 1.0) - 4600.0) < 1e-6
    assert abs(meter.blended_balance(4600.0, 0.0) - meter.OVERCAST_BALANCE_K) < 1e-6
    mid = meter.blended_balance(4600.0, 0.1)
    assert 4600.0 < mid < meter.OVERCAST_BALANCE_K, mid


def test_sidebar_says_when_the_sun_is_hidden(addon, scene, uniform_world):
    """The sidebar's line (light_setup.sun_hidden, fix "METER") under the stratus deck while the
    frame has the sun's exposure; gone once Meter Exposure has set the overcast's, back when the
    exposure is put back to the sun's, and absent with the deck hidden from the render or with
    no deck. Its coarse share agrees with Meter Exposure's to 0.01 (both well under
    SHARE_OVERCAST here)."""
    import time

    import bpy

    sl, meter, ls = addon.sky_light, addon.exposure_meter, addon.light_setup
    _camera_looking_down(scene)
    sun = sl.make_sun(scene, 40.0, 0.0)
    uniform_world(scene, 2.0)
    vs = scene.view_settings
    sunny = sl.exposure_for(40.0)
    vs.exposure = sunny

    def meter_lines():
        return [text for text, fix in ls.dark_settings(scene) if fix == "METER"]

    assert meter_lines() == [], "no cloud: no line"
    deck = addon.cloud_object.create_cloud(bpy.context, "stratus", location=(0.0, 0.0, 3.0))
    start = time.perf_counter()
    lines = meter_lines()
    first = time.perf_counter() - start
    start = time.perf_counter()
    assert meter_lines() == lines
    print(f"sun_hidden: {first * 1e3:.1f} ms, cached {(time.perf_counter() - start) * 1e3:.1f} ms")
    assert len(lines) == 1 and "Meter Exposure" in lines[0], ls.dark_settings(scene)
    coarse, _ = ls.sun_hidden(scene)
    full = ls.sunlit_share(scene, sun)
    assert abs(coarse - full) < 0.01 and coarse < meter.SHARE_OVERCAST, (coarse, full)
    assert bpy.ops.cloudgen.meter_exposure() == {"FINISHED"}
    assert vs.exposure > sunny + ls.HIDDEN_HINT_STOPS, (vs.exposure, sunny)
    assert meter_lines() == [], "metered for the overcast: no line"
    vs.exposure = sunny + 0.25  # an artist puts the sun's exposure back, near enough
    assert len(meter_lines()) == 1, ls.dark_settings(scene)
    deck.hide_render = True
    assert meter_lines() == [], "the deck hidden from the render: no line"
