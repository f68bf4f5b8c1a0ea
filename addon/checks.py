"""Said before a render, repaired on load (issue 12, findings 2, 3 and 6).

render_pre: `problems(scene)` lists the clouds that will not render as the artist
expects — a procedural cloud where OSL cannot run (Eevee, a build without OSL, a
GPU other than OptiX), Script nodes never compiled, a baked cloud whose VDB is
missing or whose bake is stale (its field key differs from the current parameters'),
denoising on in a build without a denoiser, a camera Clip End that cuts a cloud off.
Each line goes to stderr
(`cloudgen: warning: ...`; once per render, not per frame) and, with a window, to
the status bar. In background mode a cloud that **would render empty stops the
render** with exit code 1 — its VDB is missing (a farm that lost the `cloudgen/`
folder), or it lies wholly beyond Eevee's Volumetrics End (a 100 m default; the
cumulonimbus is 45 km wide), or it is procedural where OSL cannot run (a build without OSL, Eevee,
OSL off, a GPU other than OptiX) or its shaders were never compiled — because a
farm trusts the exit code and must not deliver empty skies. The environment
CLOUDGEN_ALLOW_EMPTY_CLOUDS=1 (or the older CLOUDGEN_ALLOW_MISSING_VDB=1) renders
anyway; the lines are still printed.

load_post: node groups built in a Blender without OSL (their Script nodes have no
sockets, nothing is linked, the cloud renders empty) are compiled and linked when
the file is opened in a Blender with OSL (nodes.repair_groups), and the preview
is recomputed for the active cloud.
"""
import math
import os
import sys
from types import SimpleNamespace

import bpy

from . import bake_params, cloud_object, nodes, preview, volume_object

ALLOW_EMPTY_ENV = "CLOUDGEN_ALLOW_EMPTY_CLOUDS"
ALLOW_MISSING_ENV = "CLOUDGEN_ALLOW_MISSING_VDB"  # the older name (missing VDBs only until 2026-11), still honoured
_last_printed = set()


def _with_oidn() -> bool:
    try:
        import _cycles  # noqa: PLC0415 - Cycles' own module says what it was built with
    except ImportError:
        return False
    return bool(getattr(_cycles, "with_openimagedenoise", False))


def _optix_device(scene) -> bool:
    prefs = bpy.context.preferences.addons.get("cycles")
    kind = getattr(prefs.preferences, "compute_device_type", "NONE") if prefs else "NONE"
    return scene.cycles.device == "GPU" and kind == "OPTIX"


def denoiser_available(scene, denoiser=None) -> bool:
    """The scene's Cycles denoiser (or `denoiser`) can run: OpenImageDenoise when this build
    has it (Debian's 3.4 has not, and then defaults to OptiX), OptiX on an OptiX GPU."""
    d = denoiser or getattr(scene.cycles, "denoiser", "OPENIMAGEDENOISE")
    if d == "OPENIMAGEDENOISE":
        return _with_oidn()
    if d == "OPTIX":
        return _optix_device(scene)
    return False  # "": a build with no denoiser at all (Debian's 3.4: the enum is empty)


def usable_denoiser(scene):
    """The denoiser a render of this scene can use: the scene's when it runs, else
    OpenImageDenoise when built in, else None (denoising must stay off)."""
    if denoiser_available(scene):
        return getattr(scene.cycles, "denoiser", "OPENIMAGEDENOISE")
    return "OPENIMAGEDENOISE" if _with_oidn() else None


def denoiser_missing(scene) -> bool:
    """Cycles will refuse to render: denoising is on with a denoiser this build lacks."""
    if scene.render.engine != "CYCLES" or not getattr(scene.cycles, "use_denoising", False):
        return False
    return not denoiser_available(scene)


def _osl_problem(scene):
    from . import operators  # noqa: PLC0415 - operators imports this module's users

    return operators.osl_problem(SimpleNamespace(scene=scene, preferences=bpy.context.preferences))


def _groups_of(cloud):
    mat = cloud_object.cloud_material(cloud)
    if mat is None or mat.node_tree is None:
        return []
    return [n.node_tree for n in mat.node_tree.nodes if n.bl_idname == "ShaderNodeGroup" and n.node_tree]


def _baked_files(cloud, vdb_obj):
    files = volume_object.bake_record(cloud).get("files") or []
    return list(files) or [vdb_obj.data.filepath]


_file_keys = {}  # (path, mtime_ns, size) -> the file's field key ("" when unreadable)


def file_field_key(path: str) -> str:
    """The field key a baked file was made from (the first half of its cloudgen_bake_key);
    read once per file version. "" when the file or Blender's OpenVDB module is missing."""
    from . import bake_local, bridge  # noqa: PLC0415

    try:
        st = os.stat(path)
    except OSError:
        return ""
    sig = (path, st.st_mtime_ns, st.st_size)
    if sig not in _file_keys:
        try:
            key = bake_local.stored_key(bridge.native(), bridge.openvdb(), path)
        except RuntimeError:
            key = ""
        _file_keys[sig] = key.split("-")[0]
    return _file_keys[sig]


# why a bake is stale (stale_reason): the Bake panel's short label, the render check's clause
STALE_REASONS = {
    "parameters": ("parameters changed", "the parameters changed since"),
    "model": ("baked with another cloud model",
              "it was made with another cloudgen, whose cloud model gives another field from the same parameters"),
    "unknown": ("parameters or cloud model changed", "the parameters or the cloud model changed since"),
}


def stale_reason(cloud, scene):
    """None when what the cloud renders baked is what its parameters give now (at this frame),
    else why not (a key of STALE_REASONS). Stale: the field key of the current parameters
    differs from the baked file's own key (read from the file: after an undo the record may be
    older than the file), or from the bake record's when the file cannot be read. Why: the
    record's digest of the parameters (bake_params.params_digests) still matching them means
    the same parameters now give another field: "model"; a different digest: "parameters";
    a record without digests (made before they were recorded) or a file that is not the
    record's: "unknown"."""
    record = volume_object.bake_record(cloud)
    keys = list(record.get("field_keys") or [])
    files = list(record.get("files") or [])
    if not keys or not all(keys):
        return None
    frames = list(record.get("frames") or [])
    index = 0
    if frames:
        index = min(max(scene.frame_current - frames[0], 0), len(keys) - 1)
    try:
        params = bake_params.cloud_params(cloud)
        now = bake_params.field_keys([params])[0]
    except (LookupError, RuntimeError, ValueError, TypeError):
        return None
    on_disk = file_field_key(bpy.path.abspath(files[index])) if index < len(files) else ""
    if not now or now == (on_disk or keys[index]):
        return None
    digests = list(record.get("params_digests") or [])
    if index >= len(digests) or (on_disk and on_disk != keys[index]):
        return "unknown"
    return "model" if bake_params.params_digests([params])[0] == digests[index] else "parameters"


def stale(cloud, scene) -> bool:
    """The cloud's bake is stale (stale_reason says why)."""
    return stale_reason(cloud, scene) is not None


def eevee_depths(scene, cloud):
    """(nearest, farthest) view depth from the scene camera of the cloud's box (its corners:
    the depth is linear in the point), or None without a camera."""
    if scene.camera is None:
        return None
    from mathutils import Vector  # noqa: PLC0415 - with bpy only

    to_camera = scene.camera.matrix_world.inverted()
    depths = [-(to_camera @ (cloud.matrix_world @ Vector(c))).z for c in cloud.bound_box]
    return min(depths), max(depths)


def eevee_range(scene, cloud):
    """(empty, line) when Eevee, which draws volumes only between its Volumetrics Start and End
    (view depths from the camera), leaves the cloud's box out: entirely (empty True) or in
    part (empty False); None when it does not (another engine, no camera, inside the range)."""
    eevee = getattr(scene, "eevee", None)
    if not scene.render.engine.startswith("BLENDER_EEVEE") or scene.camera is None or eevee is None:
        return None
    start, end = eevee.volumetric_start, eevee.volumetric_end
    near, far = eevee_depths(scene, cloud)
    if near >= start and far <= end:
        return None
    gone = far < start or near > end
    return gone, (f"{cloud.name} {'renders empty' if gone else 'is cut off'}: Eevee draws volumes only "
                  f"{start:g}–{end:g} m from the camera and the cloud lies {max(near, 0.0):.0f}–{far:.0f} m "
                  f"away; set Render Properties → Volumetrics → End to at least {far:.0f} m (or render in "
                  "Cycles)")


def eevee_range_fix(scene, clouds):
    """Widen Eevee's Volumetrics Start-End (never narrow it) to hold every one of `clouds`
    (their boxes' view depths, End 5 % beyond the farthest, Start at most 95 % of the nearest
    and at least 1 mm); returns (start, end)."""
    eevee = scene.eevee
    spans = [d for d in (eevee_depths(scene, c) for c in clouds) if d is not None]
    if spans:
        far = max(f for _, f in spans)
        near = min(n for n, _ in spans)
        eevee.volumetric_end = max(eevee.volumetric_end, 1.05 * far)
        eevee.volumetric_start = max(min(eevee.volumetric_start, 0.95 * near), 1e-3)
    return eevee.volumetric_start, eevee.volumetric_end


def _scene_camera(scene):
    """The scene's camera object when it is a camera (not an object used as one), else None."""
    cam = scene.camera
    return cam if cam is not None and cam.type == "CAMERA" else None


def _farthest(cam, cloud) -> float:
    """Distance from the camera to the farthest corner of the cloud's box (scene units)."""
    from mathutils import Vector  # noqa: PLC0415 - with bpy only

    eye = cam.matrix_world.translation
    return max((cloud.matrix_world @ Vector(c) - eye).length for c in cloud.bound_box)


def renders(cloud) -> bool:
    """Whether `cloud` shows in a render: a baked cloud through its bake's Volume object (not
    hidden from renders), a procedural one through itself. The one rule problems() and the
    sidebar's dark settings (light_setup) use."""
    if cloud.get(volume_object.SOURCE_KEY, "PROCEDURAL") == "BAKED":
        vdb_obj = volume_object.baked_object(cloud)
        return vdb_obj is not None and not vdb_obj.hide_render
    return not cloud.hide_render


def clip_range(scene, cloud):
    """A line when the scene camera's Clip End (Blender's default 100 m) is nearer than the far
    side of the cloud's box: the render cuts the cloud off on a straight line (a cirrostratus 32
    units up, seen 40° up, ended at 52-55° elevation baked and 19° procedural, docs/addon.md);
    None when it is not (no camera, or the box within reach). Distances along the view ray
    (how Cycles clips), to the box's farthest corner."""
    cam = _scene_camera(scene)
    if cam is None:
        return None
    far = _farthest(cam, cloud)
    end = cam.data.clip_end
    if far <= end:
        return None
    return (f"{cloud.name} is cut off: the camera's Clip End is {end:g} m and the cloud reaches "
            f"{far:.0f} m away; set Camera Properties → Clip End to at least {far:.0f} m")


def clip_range_fix(scene, clouds):
    """Move the scene camera's Clip End (never nearer) 5 % beyond the farthest corner of every
    one of `clouds`; returns the Clip End (None without a camera)."""
    cam = _scene_camera(scene)
    if cam is None:
        return None
    for cloud in clouds:
        cam.data.clip_end = max(cam.data.clip_end, 1.05 * _farthest(cam, cloud))
    return cam.data.clip_end


def camera_inside(scene, cloud):
    """A line when the scene camera stands inside the cloud's box: the render sees the cloud
    from within, fog a few metres deep at a cloud's density: a nearly even white frame near a
    sunlit edge, black deep inside a tall cloud. Add Cloud puts a box at the 3D cursor: the
    cumulonimbus's is 180 × 112 × 36 units (45 km wide at the presets' 250 m per unit), and
    Blender's startup camera, 11 units from the cursor, ends up inside it. None when it is
    not (no camera, or outside the box). Sizes as Blender shows them (units as metres, as
    clip_range's)."""
    cam = _scene_camera(scene)
    if cam is None:
        return None
    local = cloud.matrix_world.inverted_safe() @ cam.matrix_world.translation
    lo = [min(c[i] for c in cloud.bound_box) for i in range(3)]
    hi = [max(c[i] for c in cloud.bound_box) for i in range(3)]
    if not all(lo[i] < local[i] < hi[i] for i in range(3)):
        return None
    w, d, h = cloud.dimensions
    return (f"The camera is inside {cloud.name}'s box ({w:.4g} × {d:.4g} × {h:.4g} m): it renders fog from "
            "within the cloud, not its shape; move the camera out of the box")


def camera_outside_fix(scene, cloud):
    """Move the scene camera back along its own view (its rotation and lens stay) until the
    cloud's bounding sphere fits in the frame: the box's centre on the view axis, at the distance
    where the sphere touches the narrower side of the frame (orthographic: just outside the
    sphere). Then Clip End (clip_range_fix) reaches the far side. Returns the new distance to
    the box's centre (scene units), None without a camera."""
    from mathutils import Vector  # noqa: PLC0415 - with bpy only

    from . import camera_fit  # noqa: PLC0415

    cam = _scene_camera(scene)
    if cam is None:
        return None
    corners = [cloud.matrix_world @ Vector(c) for c in cloud.bound_box]
    centre = sum(corners, Vector()) / len(corners)
    radius = max((c - centre).length for c in corners)
    view = (cam.matrix_world.to_quaternion() @ Vector((0.0, 0.0, -1.0))).normalized()
    if cam.data.type == "PERSP":
        tx, ty = camera_fit.tan_half_fov(cam.data, *camera_fit.render_resolution(scene))
        half = math.atan(min(tx, ty))
        dist = radius / math.sin(half)
    else:
        dist = radius * 1.05 + cam.data.clip_start
    if cam.parent is None:
        cam.location = centre - view * dist  # the rotation stays exactly as it was
    else:  # through the world matrix: the parent's transform stays
        place = cam.matrix_world.copy()
        place.translation = centre - view * dist
        cam.matrix_world = place
    bpy.context.view_layer.update()
    clip_range_fix(scene, [cloud])
    return dist


def _camera_lines(scene, cloud):
    """What the scene camera does to a rendering cloud: Clip End cuts it off, or it stands inside."""
    return [line for line in (clip_range(scene, cloud), camera_inside(scene, cloud)) if line]


def problems(scene):
    """(empty, warnings): lines about the scene's clouds; `empty` are the clouds the render
    would show as nothing (a baked VDB not there, a procedural cloud where OSL cannot run or
    whose shaders were never compiled), `warnings` the rest (a stale bake, no denoiser, a camera
    Clip End that cuts a cloud off, a camera inside a cloud's box)."""
    empty, warnings = [], []
    if denoiser_missing(scene):
        warnings.append("denoising is on but this Blender has no OpenImageDenoise: the render "
                        "fails; turn Denoise off (Render Properties → Sampling)")
    uncompiled = set(nodes.uncompiled_groups())
    osl = None
    for cloud in (o for o in scene.objects if cloud_object.is_cloud(o)):
        source = cloud.get(volume_object.SOURCE_KEY, "PROCEDURAL")
        if source == "BAKED":
            vdb_obj = volume_object.baked_object(cloud)
            if vdb_obj is None:
                empty.append(f"{cloud.name} is set to render its bake, but it has no Volume object")
                continue
            if not renders(cloud):
                continue
            absent = [f for f in _baked_files(cloud, vdb_obj) if not os.path.isfile(bpy.path.abspath(f))]
            if absent:
                empty.append(f"{cloud.name}: the baked VDB {absent[0]} is missing"
                               + (f" (and {len(absent) - 1} more)" if len(absent) > 1 else "")
                               + "; copy the cloudgen/ folder next to the .blend")
            elif (why := stale_reason(cloud, scene)) is not None:
                warnings.append(f"{cloud.name}: the bake is stale ({STALE_REASONS[why][1]}): Bake to VDB again")
            cut = None if absent else eevee_range(scene, cloud)
            if cut is not None:
                (empty if cut[0] else warnings).append(cut[1])
            if not absent:
                warnings.extend(_camera_lines(scene, cloud))
            continue
        if not renders(cloud):
            continue
        warnings.extend(_camera_lines(scene, cloud))
        if osl is None:
            osl = _osl_problem(scene) or ""
        if osl:
            empty.append(f"{cloud.name} renders empty: {osl}; bake it (Cloud → Bake) to render it anywhere")
        elif uncompiled & set(_groups_of(cloud)):
            empty.append(f"{cloud.name} renders empty: its shaders were never compiled (made in a "
                            "Blender without OSL); reopen the file with the add-on enabled")
    return empty, warnings


def allowed_empty() -> bool:
    """The farm asked to render even where a cloud would come out empty."""
    return "1" in (os.environ.get(ALLOW_EMPTY_ENV), os.environ.get(ALLOW_MISSING_ENV))


def _status(text):
    def show():
        for window in bpy.context.window_manager.windows:
            try:
                window.workspace.status_text_set(text)
            except (AttributeError, RuntimeError):
                pass
        return None
    bpy.app.timers.register(show, first_interval=0.0)  # the main thread (render handlers may not be)


@bpy.app.handlers.persistent
def on_render_pre(scene, *_):
    try:
        if scene.camera is not None:
            nodes.revalidate_lod_drivers()  # a cloud added before the camera was
        empty, warnings = problems(scene)
    except Exception as exc:  # noqa: BLE001 - a check must never stop a render by itself
        print(f"cloudgen: warning: the pre-render check failed: {exc}", file=sys.stderr, flush=True)
        return
    lines = empty + warnings
    key = frozenset(lines)
    if lines and key != _last_printed:
        for line in lines:
            print(f"cloudgen: warning: {line}", file=sys.stderr, flush=True)
    _last_printed.clear()
    _last_printed.update(key)
    if not bpy.app.background:
        _status(("cloudgen: " + "; ".join(lines)) if lines else None)
        return
    if empty and not allowed_empty():
        more = f" (and {len(empty) - 1} more cloud{'s' if len(empty) > 2 else ''})" if len(empty) > 1 else ""
        print(f"cloudgen: error: stopping the render: {empty[0]}{more}; set {ALLOW_EMPTY_ENV}=1 to "
              "render anyway", file=sys.stderr, flush=True)
        sys.stdout.flush()
        os._exit(1)  # a handler's exception does not stop Blender's render loop or its exit code


@bpy.app.handlers.persistent
def on_load_post(*_):
    _last_printed.clear()
    try:  # shaders from another cloudgen's model: this add-on's, so that renders match its bakes
        updated = nodes.update_shaders()
    except (RuntimeError, LookupError) as exc:
        print(f"cloudgen: warning: {exc}", file=sys.stderr, flush=True)
        updated = []
    if updated:
        print(f"cloudgen: updated the shaders of {', '.join(updated)} to this cloudgen's cloud model (they were "
              "made with another version; bakes made with it show as stale)", file=sys.stderr, flush=True)
    try:
        repaired = nodes.repair_groups()
    except RuntimeError as exc:
        print(f"cloudgen: warning: {exc}", file=sys.stderr, flush=True)
        repaired = []
    if repaired:
        print(f"cloudgen: compiled and linked the shaders of {', '.join(repaired)} (made in a Blender "
              "without OSL)", file=sys.stderr, flush=True)
    try:
        if cloud_object.is_cloud(bpy.context.view_layer.objects.active):
            preview.refresh(bpy.context)
    except (AttributeError, RuntimeError):
        pass


_HANDLERS = (("render_pre", on_render_pre), ("load_post", on_load_post))


def on_register():
    for name, fn in _HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        if fn not in handlers:
            handlers.append(fn)


def on_unregister():
    for name, fn in _HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        while fn in handlers:
            handlers.remove(fn)


classes = ()
