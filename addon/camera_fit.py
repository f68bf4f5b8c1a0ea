"""Camera → CAMERA.json for `cloudgen bake --camera` (camera-aware bake).

Self-contained on purpose: no relative imports and nothing from the add-on
package, so a script can put this folder on sys.path and `import camera_fit`
(the benchmark helper does). Needs only mathutils (Blender's Python).

    data = camera_json(scene, camera_obj, cloud_obj)          # dict, see below
    data = camera_json(scene, cam, cloud, warnings=[])        # collect warnings

{
  "camera_to_cloud": 4x4 row-major: camera space (looks along -Z, +Y up, +X right)
                     -> the cloud's local frame (scene units, origin at the box centre,
                     axes along the box sides): inverse(cloud.matrix_world with scale
                     removed) @ camera.matrix_world with scale removed,
  "tan_half_fov": [tan(horizontal half angle), tan(vertical half angle)],
  "resolution": [w, h]  (pixels after the render percentage),
  "near": clip start,
  "pixels_per_voxel": only when given (else the quality tier's, else 1),
  "light_directions": [[x, y, z], ...]  (towards each visible sun lamp, cloud frame; at most 4),
  "margin": only when given (else the CLI's default, docs/camera.md)
}

Field of view follows Blender's sensor fit (BKE_camera_params_compute_viewplane):
AUTO fits the sensor width to the larger image side; HORIZONTAL fits the sensor
width to the image width; VERTICAL fits the sensor height to the image height.
Pixel aspect is ignored. Lens shift is not supported (the frustum is taken
centred): a non-zero shift adds a warning. Orthographic and panoramic cameras
raise ValueError naming the type.
"""
from __future__ import annotations

import math

DEFAULT_MARGIN = None  # the CLI's optical-depth default (docs/camera.md)
MAX_LIGHTS = 4
DEFAULT_PIXELS_PER_VOXEL = None  # the quality tier's (cloudgen tiers), else 1
_TYPE_NAMES = {"ORTHO": "orthographic", "PANO": "panoramic", "PERSP": "perspective"}


def render_resolution(scene):
    """(width, height) in pixels as Blender renders them (percentage applied, integer)."""
    r = scene.render
    w = max(1, int(r.resolution_x * r.resolution_percentage / 100))
    h = max(1, int(r.resolution_y * r.resolution_percentage / 100))
    return w, h


def tan_half_fov(cam_data, width: int, height: int):
    """(tx, ty): tangents of half the horizontal and vertical view angles of a
    perspective camera for a width x height image (Blender's sensor-fit rules)."""
    fit = cam_data.sensor_fit
    if fit == "AUTO":
        sensor = cam_data.sensor_width
        fit = "HORIZONTAL" if width >= height else "VERTICAL"
    elif fit == "HORIZONTAL":
        sensor = cam_data.sensor_width
    else:
        sensor = cam_data.sensor_height
    t = 0.5 * sensor / cam_data.lens
    if fit == "HORIZONTAL":
        return t, t * height / width
    return t * width / height, t


def _rigid(matrix):
    """matrix_world without scale: rotation (normalized columns) and translation."""
    m = matrix.normalized()  # normalizes the 3x3 columns, keeps the translation
    m.translation = matrix.translation
    return m


def camera_to_cloud(camera_obj, cloud_obj):
    """The 4x4 mathutils Matrix mapping camera space to the cloud's local frame."""
    return _rigid(cloud_obj.matrix_world).inverted() @ _rigid(camera_obj.matrix_world)


def sun_directions(scene, cloud_obj, warnings=None):
    """Unit directions towards the scene's visible sun lamps in the cloud's frame
    (a sun shines along its local -Z). At most MAX_LIGHTS; more add a warning and
    the bake keeps the view margin only for the rest."""
    rot = _rigid(cloud_obj.matrix_world).to_3x3().inverted()
    out = []
    for obj in scene.objects:
        if obj.type != "LIGHT" or obj.data.type != "SUN" or obj.hide_render:
            continue
        towards = rot @ (_rigid(obj.matrix_world).to_3x3().col[2])
        if towards.length > 1e-9:
            out.append([float(v) for v in towards.normalized()])
    if len(out) > MAX_LIGHTS:
        if warnings is not None:
            warnings.append(f"{len(out)} sun lamps: Fit to Camera follows the shadows of the first {MAX_LIGHTS}")
        out = out[:MAX_LIGHTS]
    return out


def camera_json(scene, camera_obj, cloud_obj, warnings=None, margin=DEFAULT_MARGIN,
                pixels_per_voxel=DEFAULT_PIXELS_PER_VOXEL) -> dict:
    """CAMERA.json contents for baking cloud_obj as seen by camera_obj in scene.
    ValueError for a missing / non-camera object or a non-perspective camera;
    warnings (a list, optional) gets one line per unsupported setting in use."""
    if camera_obj is None:
        raise ValueError("Fit to Camera: the scene has no camera (set Scene > Camera)")
    if getattr(camera_obj, "type", None) != "CAMERA":
        raise ValueError(f"Fit to Camera: {camera_obj.name!r} is not a camera")
    cam = camera_obj.data
    if cam.type != "PERSP":
        kind = _TYPE_NAMES.get(cam.type, cam.type)
        raise ValueError(f"Fit to Camera: camera {camera_obj.name!r} is {kind} ({cam.type}); "
                         "only perspective cameras are supported — bake without Fit to Camera")
    if warnings is not None and (abs(cam.shift_x) > 1e-9 or abs(cam.shift_y) > 1e-9):
        warnings.append(f"camera {camera_obj.name!r} has lens shift ({cam.shift_x:g}, {cam.shift_y:g}), "
                        "which Fit to Camera ignores: the bake assumes a centred view")
    w, h = render_resolution(scene)
    tx, ty = tan_half_fov(cam, w, h)
    m = camera_to_cloud(camera_obj, cloud_obj)
    data = {
        "camera_to_cloud": [[float(m[i][j]) for j in range(4)] for i in range(4)],
        "tan_half_fov": [float(tx), float(ty)],
        "resolution": [int(w), int(h)],
        "near": float(max(cam.clip_start, 1e-6)),
        "light_directions": sun_directions(scene, cloud_obj, warnings),
    }
    if margin is not None:
        data["margin"] = float(margin)
    if pixels_per_voxel is not None:
        data["pixels_per_voxel"] = float(pixels_per_voxel)
    return data


def project(data: dict, point_local):
    """(u, v, depth) of a point in the cloud's local frame (scene units) through the
    camera in `data`: u, v in [0, 1] across the image (0, 0 bottom left), depth the
    distance along the view axis — the same convention as
    bpy_extras.object_utils.world_to_camera_view."""
    m = data["camera_to_cloud"]
    # inverse of a rigid transform: R^T (p - t)
    d = [point_local[i] - m[i][3] for i in range(3)]
    p = [sum(m[r][c] * d[r] for r in range(3)) for c in range(3)]
    depth = -p[2]
    if abs(depth) < 1e-12:
        return math.nan, math.nan, depth
    tx, ty = data["tan_half_fov"]
    return 0.5 + 0.5 * p[0] / depth / tx, 0.5 + 0.5 * p[1] / depth / ty, depth
