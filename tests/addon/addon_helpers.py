"""Helpers of the add-on tests (a scene to render a cloud in, image loading)."""
import pathlib

from scene_helpers import frame_cloud as add_camera_and_sun  # noqa: F401  (re-exported)
from scene_helpers import load_rgb

ROOT = pathlib.Path(__file__).resolve().parents[2]


def render_to_array(scene, path):
    """Render scene to a PNG at path and return its RGB pixels as floats."""
    import bpy

    scene.render.image_settings.file_format = "PNG"
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)
    return load_rgb(path)
