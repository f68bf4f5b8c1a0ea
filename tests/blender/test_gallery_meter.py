"""The light meter (addon/exposure_meter.py frame_luminance()): a camera's averaging meter, which
exposes the gallery's grey overcasts, sets every gallery frame's auto-ISO and drives the add-on's
Meter Exposure. Under a uniform white world
of radiance S the frame's mean luminance is S whatever the film exposure (tolerance 1.4 %,
0.02 stops: Cycles samples a constant background exactly, and the sky fills the frame); the
scene's resolution, samples, exposure, denoising and output format come back as they were."""
import math
import pathlib
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))


@pytest.mark.parametrize("radiance", [0.05, 0.5, 4.0])
def test_meter_reads_the_light_at_any_exposure(empty_scene, uniform_world, radiance):
    import bpy
    import render_cloud

    scene = empty_scene
    uniform_world(scene, radiance)
    cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
    scene.collection.objects.link(cam)
    scene.camera = cam
    r = scene.render
    r.resolution_x, r.resolution_y, r.resolution_percentage = 200, 100, 50
    scene.cycles.samples = 7
    r.image_settings.file_format = "PNG"
    scene.view_settings.exposure = 2.5  # a film exposure must not change what the meter reads
    def settings():
        return (scene.view_settings.exposure, r.resolution_x, r.resolution_y, r.resolution_percentage,
                scene.cycles.samples, scene.cycles.use_denoising, r.image_settings.file_format,
                r.image_settings.color_depth, r.filepath)

    before = settings()
    got = render_cloud._addon_file("exposure_meter").frame_luminance(scene)
    assert abs(math.log2(got / radiance)) < 0.02, (radiance, got)
    after = settings()
    assert after == before, (before, after)
