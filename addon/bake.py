"""Bake to VDB: run `cloudgen bake` on the active cloud (one frame, or the scene's
frame range as a sequence), then create or update its Volume object and switch
the cloud between procedural and baked.

- The bake runs in a subprocess (bake_process.py): with a window it is modal
  (progress bar, ESC or right-click cancels); in background mode (`blender -b`,
  the bpy wheel: no window) it runs synchronously and prints its progress.
- The VDB grid lives in the cloud's local frame (centred, the object's scale
  folded into the box size, docs/model.md §8), so the Volume object
  `<cloud>_VDB` is parented to the cloud with the cloud's scale cancelled:
  it sits at the cloud's location and rotation and moves with it.
- cloud["cloudgen_source"] is 'PROCEDURAL' or 'BAKED'; BAKED hides the
  procedural box from render and shows the Volume object.
- Cancel, a full disk or an unwritable path leave no partial file and are
  reported with self.report({'ERROR'}, ...).
- Settings: the scene's Cloud Quality tier (quality.py; `--quality NAME`), with
  the operator's resolution / no_lod / tolerance / half passed only when set
  explicitly; Fit to Camera (camera_fit.py, `--camera`); a frame range bakes
  per-frame parameters with `--sequence ... --update` (sequence.py): only frames
  whose field changed are baked. Older CLIs without these options get explicit
  values and `--frames` instead.
"""
import os

import bpy
from mathutils import Matrix

from . import bake_process, bridge, camera_fit, quality, sequence
from .panel import SidebarPanel

SOURCE_KEY = "cloudgen_source"
BAKED_FROM_KEY = "cloudgen_baked_from"
DEFAULT_DIR = "//cloudgen/"

last_result = None   # the last bake's BakeResult (scripts and tests read counts from it)
last_report = ""     # and its info line


# ---------------------------------------------------------------- parameters
def cloud_params(obj) -> dict:
    """Every parameter of the cloud as the render uses it (cloud_object.params_from_object);
    for a cloud without the node groups, its type's preset with the object's box and location."""
    try:
        from . import cloud_object  # noqa: PLC0415
        return cloud_object.params_from_object(obj)
    except (ImportError, LookupError, AttributeError):
        pass
    presets = bridge.presets()
    kind = obj.get("cloudgen_type", "cumulus")
    if kind not in presets:
        raise LookupError(f"{obj.name}: unknown cloud type {kind!r}")
    values = dict(presets[kind]["params"])
    values["box_size"] = [float(x) for x in obj.dimensions]
    values["object_location"] = [float(x) for x in obj.matrix_world.translation]
    return values


def is_cloud(obj) -> bool:
    return obj is not None and "cloudgen_type" in obj.keys()


def default_path(obj) -> str:
    return DEFAULT_DIR + bpy.path.clean_name(obj.name) + ".vdb"


def resolve_output(path: str) -> str:
    """Absolute output path; ValueError for a blend-relative path in an unsaved file."""
    if path.startswith("//") and not bpy.data.filepath:
        raise ValueError(f"the output path {path!r} is relative to the .blend file, which is "
                         "not saved yet: save the file or give an absolute path")
    out = os.path.normpath(bpy.path.abspath(path))
    if not out.lower().endswith(".vdb"):
        raise ValueError(f"the output path {out!r} must end in .vdb")
    return out


def scene_frames(scene):
    return scene.frame_start, scene.frame_end, scene.render.fps / scene.render.fps_base


# ---------------------------------------------------------------- the result
def baked_object(cloud):
    """The cloud's Volume object, or None."""
    for child in cloud.children:
        if child.get(BAKED_FROM_KEY) == cloud.name and child.type == "VOLUME":
            return child
    obj = bpy.data.objects.get(cloud.name + "_VDB")
    return obj if obj is not None and obj.type == "VOLUME" else None


def _baked_material(cloud):
    """A volume material reading the grid `density`: the cloud's own volume shader
    (same phase function and colour as the procedural render), or a Principled Volume."""
    name = cloud.name + "_VDB"
    mat = bpy.data.materials.get(name) or bpy.data.materials.new(name)
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    look = bridge.presets().get(cloud.get("cloudgen_type", ""), {}).get("material", {})
    source = None
    for m in getattr(cloud.data, "materials", []):
        if m and m.node_tree and "Cloud Volume" in m.node_tree.nodes:
            source = m.node_tree.nodes["Cloud Volume"]
            break
    if source is not None:
        volume = nt.nodes.new(source.bl_idname)
        for attr in ("phase",):
            if hasattr(source, attr):
                setattr(volume, attr, getattr(source, attr))
        for sock in source.inputs:
            if sock.name != "Density" and not sock.is_linked and hasattr(sock, "default_value") \
                    and sock.name in volume.inputs:
                volume.inputs[sock.name].default_value = sock.default_value
    else:
        volume = nt.nodes.new("ShaderNodeVolumePrincipled")
        volume.inputs["Color"].default_value = tuple(look.get("color", (1.0, 1.0, 1.0)))[:3] + (1.0,)
        volume.inputs["Anisotropy"].default_value = float(look.get("anisotropy", 0.3))
    volume.name = "Cloud Volume"
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    volume.location, out.location = (0, 0), (300, 0)
    if "Density Attribute" in volume.inputs:
        # The Principled Volume multiplies Density by its Density Attribute: the
        # grid reaches it through the attribute alone (linking it into Density
        # too would square the density — a darker cloud).
        volume.inputs["Density Attribute"].default_value = "density"
        volume.inputs["Density"].default_value = 1.0
    else:
        attr = nt.nodes.new("ShaderNodeAttribute")
        attr.attribute_name = "density"
        attr.name = "Density Grid"
        attr.location = (-250, 0)
        nt.links.new(attr.outputs["Fac"], volume.inputs["Density"])
    nt.links.new(volume.outputs["Volume"], out.inputs["Volume"])
    if hasattr(mat, "cycles") and hasattr(mat.cycles, "volume_step_rate"):
        mat.cycles.volume_step_rate = 1.0  # a VDB steps at its voxel size
    return mat


def apply_bake(context, cloud, stored_path: str, frames=None):
    """Create or update `<cloud>_VDB` reading stored_path (the first file of a sequence)
    and switch the cloud to BAKED. Returns the Volume object."""
    obj = baked_object(cloud)
    if obj is None:
        vol = bpy.data.volumes.new(cloud.name + "_VDB")
        obj = bpy.data.objects.new(cloud.name + "_VDB", vol)
        for coll in cloud.users_collection or (context.scene.collection,):
            coll.objects.link(obj)
    vol = obj.data
    vol.filepath = stored_path
    vol.is_sequence = frames is not None
    if frames is not None:
        first, last = frames
        vol.frame_start = first
        vol.frame_duration = last - first + 1
        vol.frame_offset = first - 1  # files are numbered by scene frame
        vol.sequence_mode = "CLIP"
    vol.grids.load()
    obj[BAKED_FROM_KEY] = cloud.name
    # the grid is in the cloud's local frame with the scale folded in: cancel the scale
    obj.parent = cloud
    scale = [s if abs(s) > 1e-12 else 1.0 for s in cloud.scale]
    obj.matrix_parent_inverse = Matrix.Diagonal((1.0 / scale[0], 1.0 / scale[1], 1.0 / scale[2], 1.0))
    obj.matrix_basis = Matrix.Identity(4)
    mat = _baked_material(cloud)
    if obj.data.materials:
        obj.data.materials[0] = mat
    else:
        obj.data.materials.append(mat)
    set_source(cloud, "BAKED")
    return obj


def set_source(cloud, source: str):
    """'BAKED': render the Volume object, not the procedural box; 'PROCEDURAL': the reverse."""
    if source not in ("PROCEDURAL", "BAKED"):
        raise ValueError(f"source must be PROCEDURAL or BAKED, not {source!r}")
    baked = baked_object(cloud)
    if source == "BAKED" and baked is None:
        raise LookupError(f"{cloud.name} has no baked VDB yet: bake it first")
    cloud[SOURCE_KEY] = source
    cloud.hide_render = source == "BAKED"
    if baked is not None:
        baked.hide_render = source != "BAKED"
        baked.hide_viewport = source != "BAKED"


# ---------------------------------------------------------------- operators
# 4.5 warns about "//" in a FILE_PATH property unless it says it supports it;
# older versions (3.4) do not know the option (checked at registration, not here)
_RELATIVE_OK = {"options": {"PATH_SUPPORTS_BLEND_RELATIVE"}} if bpy.app.version >= (4, 5, 0) else {}
class CLOUDGEN_OT_bake_vdb(bpy.types.Operator):
    """Bake the active cloud to an OpenVDB file (or a sequence over the scene's frame
    range) with the cloudgen command-line tool, and render the baked volume instead"""
    bl_idname = "cloudgen.bake_vdb"
    bl_label = "Bake to VDB"
    bl_options = {"REGISTER"}

    filepath: bpy.props.StringProperty(
        name="Output", subtype="FILE_PATH", default="", **_RELATIVE_OK,
        description="VDB file to write (empty: //cloudgen/<object>.vdb); for a sequence "
                    "a run of # is the frame number, else _0001 goes before .vdb")
    resolution: bpy.props.IntProperty(name="Resolution", default=96, min=1, max=4096,
                                      description="Voxels along the longest box side")
    sequence: bpy.props.BoolProperty(name="Frame Range", default=False,
                                     description="Bake the scene's frame range as a VDB sequence")
    no_lod: bpy.props.BoolProperty(name="Full Detail", default=False,
                                   description="Evaluate every noise octave (no level of detail)")
    tolerance: bpy.props.FloatProperty(name="Tolerance", default=0.0, min=0.0, max=1000.0,
                                       description="Drop voxels with density at or below this")
    half: bpy.props.BoolProperty(name="Half Floats", default=False,
                                 description="Store 16-bit floats (half the file size)")
    quality: bpy.props.StringProperty(
        name="Quality", default="",
        description="Quality tier for the bake settings (empty: the scene's Cloud Quality); "
                    "resolution, Full Detail, tolerance and half floats given explicitly win")
    fit_camera: bpy.props.BoolProperty(
        name="Fit to Camera", default=False,
        description="Bake what the scene camera sees, voxels the size of a pixel at the "
                    "nearest visible point (unset: the scene's Fit to Camera checkbox)")

    _job = None
    _timer = None

    @classmethod
    def poll(cls, context):
        return is_cloud(getattr(context, "active_object", None) or context.view_layer.objects.active)

    # -- preparing
    def _prepare(self, context):
        cloud = context.view_layer.objects.active
        if not is_cloud(cloud):
            raise ValueError("the active object is not a cloud")
        exe = bridge.cloudgen_executable()
        if exe is None:
            raise ValueError("the cloudgen command-line tool is missing (not in the add-on's bin/ "
                             "nor on PATH): reinstall the add-on")
        given = self.filepath or default_path(cloud)
        output = resolve_output(given)
        parent = os.path.dirname(output)
        if os.path.exists(parent) and not os.path.isdir(parent):
            raise ValueError(f"cannot write {output!r}: {parent!r} is a file, not a folder")
        try:
            os.makedirs(parent, exist_ok=True)
        except OSError as exc:
            raise ValueError(f"cannot create the folder {parent!r}: {exc.strerror}") from exc
        scene = context.scene
        params = cloud_params(cloud)
        features = bridge.cli_features(exe)
        resolution, extra = self._settings(scene, features)
        self._warnings = []
        camera = None
        if self._is_set("fit_camera", self.fit_camera, scene.cloudgen.bake_fit_camera):
            if "--camera" not in features:
                raise ValueError("Fit to Camera needs a cloudgen command-line tool with --camera "
                                 "(this one has none): update the add-on")
            camera = camera_fit.camera_json(scene, scene.camera, cloud, self._warnings)
        frames, fps, seq = None, 24.0, None
        if self.sequence:
            first, last, fps = scene_frames(scene)
            frames = (first, last)
            if "--sequence" in features:
                seq = sequence.sequence_object(
                    sequence.frame_params(scene, cloud, first, last, cloud_params), fps)
                if "--update" in features:
                    extra.append("--update")
        job = bake_process.BakeJob(exe, params, resolution, output, frames, fps, extra,
                                   sequence=seq, camera=camera)
        paths = bake_process.sequence_paths(output, *frames) if frames else [output]
        stored = paths[0]
        if given.startswith("//"):
            stored = bpy.path.relpath(stored)
        return cloud, job, stored, frames

    def _is_set(self, prop, value, fallback):
        return value if self.properties.is_property_set(prop) else fallback

    def _settings(self, scene, features):
        """(resolution or None, CLI arguments) from the tier and the explicit overrides."""
        name, tier = quality.current(scene)
        if self.quality:
            tiers = quality.tiers()
            if self.quality not in tiers and self.quality != quality.CUSTOM:
                raise ValueError(f"unknown quality tier {self.quality!r}; known: "
                                 f"{', '.join(tiers) or 'none'}")
            name, tier = (self.quality, tiers[self.quality]) if self.quality in tiers else (None, None)
        overrides = {}
        for prop, key, conv in (("resolution", "resolution", int), ("no_lod", "lod", lambda v: not v),
                                ("tolerance", "tolerance", float), ("half", "half", bool)):
            if self.properties.is_property_set(prop):
                overrides[key] = conv(getattr(self, prop))
        return quality.bake_arguments(name, (tier or {}).get("bake"), overrides, features)

    def _finish(self, context, cloud, result, stored, frames):
        global last_result, last_report
        last_result = result
        for line in getattr(self, "_warnings", ()):
            self.report({"WARNING"}, f"Bake to VDB: {line}")
        if not result.ok:
            level = {"WARNING"} if result.cancelled else {"ERROR"}
            self.report(level, f"Bake to VDB: {result.message}")
            return {"CANCELLED"}
        try:
            obj = apply_bake(context, cloud, stored, frames)
        except (RuntimeError, LookupError, ValueError) as exc:
            self.report({"ERROR"}, f"Bake to VDB: baked, but the Volume object failed: {exc}")
            return {"CANCELLED"}
        text = sequence.summary(result, frames) if frames else result.message
        last_report = f"Bake to VDB: {text} → {obj.name}"
        self.report({"INFO"}, last_report)
        return {"FINISHED"}

    # -- background / scripted: synchronous
    def execute(self, context):
        try:
            cloud, job, stored, frames = self._prepare(context)
        except (ValueError, LookupError, RuntimeError) as exc:
            self.report({"ERROR"}, f"Bake to VDB: {exc}")
            return {"CANCELLED"}
        last = [-1]

        def progress(p):
            if int(p) != last[0]:
                last[0] = int(p)
                print(f"cloudgen bake {cloud.name}: {p:.0f}%", flush=True)

        job.on_progress = progress
        try:
            job.start()
            result = job.wait()
        except bake_process.BakeError as exc:
            result = exc.result
        except KeyboardInterrupt:
            job.cancel()
            result = job.wait()
        return self._finish(context, cloud, result, stored, frames)

    # -- with a window: modal, progress bar, ESC cancels
    def invoke(self, context, event):
        if bpy.app.background or context.window is None:
            return self.execute(context)
        try:
            cloud, job, stored, frames = self._prepare(context)
            job.start()
        except (ValueError, LookupError, RuntimeError) as exc:
            self.report({"ERROR"}, f"Bake to VDB: {exc}")
            return {"CANCELLED"}
        self._job, self._state = job, (cloud, stored, frames)
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.modal_handler_add(self)
        wm.progress_begin(0, 100)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        if event.type in {"ESC", "RIGHTMOUSE"} and event.value == "PRESS":
            self._job.cancel()
            return {"RUNNING_MODAL"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        result = self._job.poll()
        wm = context.window_manager
        if result is None:
            wm.progress_update(int(self._job.progress))
            if context.area:
                context.area.header_text_set(f"Baking {self._state[0].name}: "
                                             f"{self._job.progress:.0f}% (Esc to cancel)")
            return {"RUNNING_MODAL"}
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        if context.area:
            context.area.header_text_set(None)
        cloud, stored, frames = self._state
        return self._finish(context, cloud, result, stored, frames)

    def cancel(self, context):  # Blender quits or the window closes mid-bake
        if self._job is not None:
            self._job.cancel()
            self._job.wait()
        if self._timer is not None:
            context.window_manager.event_timer_remove(self._timer)
            context.window_manager.progress_end()


class CLOUDGEN_OT_cloud_source(bpy.types.Operator):
    """Render the cloud procedurally (OSL) or from its baked VDB"""
    bl_idname = "cloudgen.cloud_source"
    bl_label = "Cloud Source"
    bl_options = {"REGISTER", "UNDO"}

    source: bpy.props.EnumProperty(name="Source", items=(
        ("PROCEDURAL", "Procedural", "Render the OSL shaders (Cycles, CPU or OptiX)"),
        ("BAKED", "Baked", "Render the baked VDB (any engine and device)")))

    @classmethod
    def poll(cls, context):
        return is_cloud(context.view_layer.objects.active)

    def execute(self, context):
        cloud = context.view_layer.objects.active
        try:
            set_source(cloud, self.source)
        except LookupError as exc:
            self.report({"ERROR"}, f"Cloud Source: {exc}")
            return {"CANCELLED"}
        return {"FINISHED"}


class CLOUDGEN_PT_bake(SidebarPanel, bpy.types.Panel):
    bl_label = "Bake"
    bl_idname = "CLOUDGEN_PT_bake"
    bl_parent_id = "CLOUDGEN_PT_main"

    @classmethod
    def poll(cls, context):
        return is_cloud(context.view_layer.objects.active)

    def draw(self, context):
        layout = self.layout
        cloud = context.view_layer.objects.active
        col = layout.column(align=True)
        op = col.operator(CLOUDGEN_OT_bake_vdb.bl_idname, text="Bake Frame", icon="FILE_VOLUME")
        op.sequence = False
        op = col.operator(CLOUDGEN_OT_bake_vdb.bl_idname, text="Bake Frame Range", icon="SEQUENCE")
        op.sequence = True
        row = layout.row()
        row.prop(context.scene.cloudgen, "bake_fit_camera")
        layout.label(text=quality.bake_summary(context.scene), icon="SETTINGS")
        source = cloud.get(SOURCE_KEY, "PROCEDURAL")
        row = layout.row(align=True)
        for key, label in (("PROCEDURAL", "Procedural"), ("BAKED", "Baked")):
            sub = row.row(align=True)
            sub.enabled = key == "PROCEDURAL" or baked_object(cloud) is not None
            op = sub.operator(CLOUDGEN_OT_cloud_source.bl_idname, text=label, depress=source == key)
            op.source = key
        baked = baked_object(cloud)
        if baked is not None:
            layout.label(text=f"{baked.name}: {baked.data.filepath}", icon="OUTLINER_DATA_VOLUME")
        if not bpy.data.filepath:
            layout.label(text="Save the .blend first (output is //cloudgen/)", icon="INFO")


classes = (CLOUDGEN_OT_bake_vdb, CLOUDGEN_OT_cloud_source, CLOUDGEN_PT_bake)
