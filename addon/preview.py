"""Live cross-section preview of the active cloud.

cloudgen_native.slice() of params_from_object(obj) is kept as it came
(`state.values`, float32, row 0 at the top) and written into the Image
datablock "Cloud Preview" (float, bottom row first as Blender stores images;
grey = 1 - exp(-density / S), S = cloudgen_native.slice_display_scale(peak)
= max(peak / 3, 0.001): the mapping of `cloudgen preview`'s PNG; the slice's
peak shows at 95 % grey, so a dense cumulus is not a white block and a thin
cirrus is not black) and into an icon of a bpy.utils.previews collection that the
N-panel draws (template_icon works in 3.4 and 4.x; the Image can be opened
in an Image Editor too). A depsgraph_update_post handler refreshes it when
the active cloud's parameters change: it compares a signature of the
parameters (cheap) and, with a UI, slices at most every MIN_INTERVAL seconds
(a persistent timer catches the last change); in background mode it slices
whenever the signature changes.
"""
import time

import bpy
import numpy as np

from . import bridge, cloud_object

IMAGE_NAME = "Cloud Preview"
MIN_INTERVAL = 0.1


class _State:
    values = None       # last slice (numpy float32, height x width)
    error = None        # one line, or None
    signature = None
    last_time = 0.0
    previews = None     # bpy.utils.previews collection


state = _State()


def settings(scene):
    return scene.cloudgen


def preview_size(values, axis: str, width: int):
    """(width, height) of the slice image with the box's aspect ratio."""
    bx, by, bz = values["box_size"]
    across, up = {"x": (by, bz), "y": (bx, bz), "z": (bx, by)}[axis]
    height = int(round(width * up / max(across, 1e-9)))
    return width, max(8, min(4 * width, height))


def display_pixels(values):
    """RGBA floats, bottom row first, for an Image or icon."""
    peak = float(values.max()) if values.size else 0.0
    scale = np.float32(bridge.slice_display_scale(peak))
    grey = (1.0 - np.exp(-np.maximum(values, 0.0) / scale))[::-1]
    rgba = np.ones(grey.shape + (4,), dtype=np.float32)
    rgba[..., 0] = rgba[..., 1] = rgba[..., 2] = grey
    return rgba.ravel()


def compute(obj, axis: str, offset: float, width: int):
    """The slice for obj (validated parameters); raises RuntimeError (no native module),
    LookupError (not a cloud) or ValueError/TypeError naming the bad parameter."""
    values = bridge.resolve_params(cloud_object.params_from_object(obj))
    w, h = preview_size(values, axis, width)
    return bridge.slice(values, axis, float(offset), w, h)


def write_image(values):
    h, w = values.shape
    img = bpy.data.images.get(IMAGE_NAME)
    if img is not None and tuple(img.size) != (w, h):
        bpy.data.images.remove(img)
        img = None
    if img is None:
        img = bpy.data.images.new(IMAGE_NAME, w, h, alpha=False, float_buffer=True)
        img.colorspace_settings.name = "Non-Color"
    pixels = display_pixels(values)
    img.pixels.foreach_set(pixels)
    img.update()
    if state.previews is not None:
        icon = state.previews.get("slice") or state.previews.new("slice")
        icon.image_size = (w, h)
        icon.image_pixels_float.foreach_set(pixels)
    return img


def icon_id() -> int:
    if state.previews is None or "slice" not in state.previews:
        return 0
    return state.previews["slice"].icon_id


def refresh(context, obj=None) -> bool:
    """Recompute the preview for obj (default: the active object). Returns True on success;
    on failure state.error holds the one-line reason (the panel shows it)."""
    scene = context.scene
    obj = obj if obj is not None else context.view_layer.objects.active
    s = settings(scene)
    state.last_time = time.monotonic()
    try:
        if not cloud_object.is_cloud(obj):
            raise LookupError("the active object is not a cloud (Add Cloud makes one)")
        values = compute(obj, s.preview_axis.lower(), s.preview_offset, s.preview_width)
    except (RuntimeError, LookupError, ValueError, TypeError, KeyError) as exc:
        state.error = f"Preview: {exc}"
        return False
    state.values = values
    state.error = None
    write_image(values)
    return True


def _signature(context):
    obj = context.view_layer.objects.active
    if not cloud_object.is_cloud(obj):
        return None
    s = settings(context.scene)
    try:
        params = cloud_object.params_from_object(obj)
    except (LookupError, RuntimeError):
        return None
    return (obj.name, s.preview_axis, round(s.preview_offset, 6), s.preview_width,
            repr(sorted(params.items())))


def _timer():
    _maybe_refresh(bpy.context)
    return None


def _maybe_refresh(context):
    if context.scene is None or not settings(context.scene).preview_live:
        return
    sig = _signature(context)
    if sig is None or sig == state.signature:
        return
    # Throttle only with a UI: in background mode nothing draws the preview between
    # updates, and the 4.5 wheel hangs at exit once a timer was ever registered and
    # dropped by a file load (even after it is gone from bpy.app.timers).
    if not bpy.app.background and time.monotonic() - state.last_time < MIN_INTERVAL:
        if not bpy.app.timers.is_registered(_timer):  # the last change of a drag
            bpy.app.timers.register(_timer, first_interval=MIN_INTERVAL, persistent=True)
        return
    state.signature = sig
    refresh(context)
    _redraw(context)


def _redraw(context):
    screen = getattr(context, "screen", None)
    if screen is None:
        return
    for area in screen.areas:
        if area.type == "VIEW_3D":
            area.tag_redraw()


@bpy.app.handlers.persistent
def on_depsgraph_update(scene, depsgraph=None):
    if bridge.native() is None:
        return
    _maybe_refresh(bpy.context)


def on_register():
    import bpy.utils.previews  # noqa: PLC0415

    state.previews = bpy.utils.previews.new()
    state.values = state.error = state.signature = None
    if on_depsgraph_update not in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.append(on_depsgraph_update)


def on_unregister():
    import bpy.utils.previews  # noqa: PLC0415

    while on_depsgraph_update in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.remove(on_depsgraph_update)
    if bpy.app.timers.is_registered(_timer):
        bpy.app.timers.unregister(_timer)
    if state.previews is not None:
        bpy.utils.previews.remove(state.previews)
        state.previews = None


classes = ()
