"""A camera's averaging meter for cloud frames: the frame's mean scene-linear luminance from a
small test render, and the rule that takes a frame with the sun's glow in it down to twice a
sunny frame's light. Used by the add-on's Meter Exposure (light_setup.py) and by the
gallery (scripts/gallery.py); imports none of the add-on's other modules (the gallery loads it
by its path). docs/lighting.md has the measurements.

Exposed for a sunny frame (sky_light.exposure_for), a view toward the sun through a thin veil
sits in AgX's shoulder: a cirrostratus's whole 22° halo came out at 240-250 of 255 and two
blind reviewers read the ring as the edge of "a hard-edged disc". A camera's meter would take
such a frame down; so does the gallery since round 17, and Meter Exposure in the add-on.
"""
from __future__ import annotations

import math
import os
import tempfile

# The median frame luminance (scene-linear, film exposure 0, under the add-on's sky and sun) of
# the round-15 gallery's twelve sunlit frames without the sun's glow in them (2.15-4.71; with
# it 9.2-43: the cirrus and the stratocumulus 9, the veils with the sun in view 6-43).
SUNNY_LIGHT = 3.2
# A sunlit frame metered above this is exposed down to it (the veils toward the sun read 44-58).
GLARE_LIGHT = 2.0 * SUNNY_LIGHT
METER_SIZE, METER_SAMPLES = (96, 54), 4


def glare_compensation(light: float) -> float:
    """Stops added to a sunlit frame's exposure for its metered light: 0 up to GLARE_LIGHT,
    then down to GLARE_LIGHT (continuous at the bound)."""
    return -max(math.log2(light / GLARE_LIGHT), 0.0)


def meter_settings(scene, path):
    """Set the scene up for the meter's render to `path` (an EXR): METER_SIZE, METER_SAMPLES spp,
    not denoised, film exposure 0 (the light itself: the EXR is scene-linear). Returns what
    restore_settings() puts back: resolution, samples, denoising, format, exposure, output path."""
    r, c, im = scene.render, scene.cycles, scene.render.image_settings
    saved = (r.resolution_x, r.resolution_y, r.resolution_percentage, c.samples, c.use_denoising,
             im.file_format, im.color_depth, scene.view_settings.exposure, r.filepath)
    scene.view_settings.exposure = 0.0
    r.resolution_x, r.resolution_y = METER_SIZE
    r.resolution_percentage, c.samples, c.use_denoising = 100, METER_SAMPLES, False
    im.file_format, im.color_depth = "OPEN_EXR", "32"
    r.filepath = path
    return saved


def restore_settings(scene, saved):
    """Put back what meter_settings() changed."""
    r, c, im = scene.render, scene.cycles, scene.render.image_settings
    (r.resolution_x, r.resolution_y, r.resolution_percentage, c.samples, c.use_denoising,
     im.file_format) = saved[:6]
    im.color_depth, scene.view_settings.exposure, r.filepath = saved[6:]


def read_luminance(path) -> float:
    """The mean scene-linear luminance (Rec.709) of the meter's EXR at `path`; RuntimeError when
    it holds NaN or Inf. The image is loaded and removed again."""
    import bpy  # noqa: PLC0415 - the rule and the constants load without Blender (the gallery's tests)
    import numpy as np  # noqa: PLC0415

    img = bpy.data.images.load(path)
    try:
        px = np.array(img.pixels[:], dtype=np.float64).reshape(-1, 4)[:, :3]
    finally:
        bpy.data.images.remove(img)
    if not np.isfinite(px).all():
        raise RuntimeError("the meter's render holds NaN or Inf")
    return max(float((px @ np.array([0.2126, 0.7152, 0.0722])).mean()), 1e-6)


def frame_luminance(scene) -> float:
    """The frame's mean scene-linear luminance at film exposure 0, rendered here and now (it blocks
    until done; the add-on's Meter Exposure renders as a job instead, with progress and Esc): the
    meter's render (meter_settings) to an EXR in a private temporary folder, read by
    read_luminance. The scene's settings come back as they were, also when the render fails."""
    import bpy  # noqa: PLC0415

    with tempfile.TemporaryDirectory(prefix="cloudgen-meter-") as tmp:
        path = os.path.join(tmp, "meter.exr")
        saved = meter_settings(scene, path)
        try:
            bpy.ops.render.render(write_still=True)
        finally:
            restore_settings(scene, saved)
        return read_luminance(path)
