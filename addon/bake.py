"""Bake to VDB and Cloud Source, the two bake operators.

Bake to VDB bakes the active cloud (one frame, or the scene's frame range as a
sequence), then creates or updates its Volume object and switches the cloud to
baked (volume_object.py). Where the bake runs:

- inside Blender (the default): bake_local.py — densities from cloudgen_native in
  a worker thread, written through Blender's own OpenVDB module
  (bridge.openvdb(): `openvdb` / `pyopenvdb`); the file equals `cloudgen bake`'s;
- the cloudgen CLI (bake_process.py, `cloudgen bake --json`) when the add-on's
  preferences name one (prefs.py; Fit to Camera needs it); the CLI's release and
  protocol are checked against the module's first (bridge.cli_problem);
- a Dask cluster (bake_dask.py) for Bake Frame Range when the preferences hold a
  scheduler address (and the CLI the workers run).

With a window it is modal (progress bar, ESC or right-click cancels); in
background mode (`blender -b`, the bpy wheel) it runs synchronously and prints
its progress. Cancel, a full disk or an unwritable path leave no partial file and
are reported with self.report({'ERROR'}, ...); success is reported as
`Bake to VDB: <what was done> → <cloud>_VDB` and recorded on the cloud
(volume_object.store_record: files, field keys, counts). Bake to VDB is an undo
step: Ctrl+Z removes the Volume object and the record (the file stays on disk).
Settings: the scene's Cloud Quality tier (quality.py), with the operator's
resolution / no_lod / tolerance / half winning when set explicitly; a frame
range bakes per-frame parameters (sequence.py): only frames whose field changed
are baked, the others copied or kept.
"""
import bpy

from . import (
    bake_dask,
    bake_local,
    bake_params,
    bake_process,
    bridge,
    camera_fit,
    cloud_object,
    prefs,
    quality,
    sequence,
    volume_object,
)

# 4.5 warns about "//" in a FILE_PATH property unless it says it supports it;
# older versions (3.4) do not know the option (checked at registration, not here)
_RELATIVE_OK = {"options": {"PATH_SUPPORTS_BLEND_RELATIVE"}} if bpy.app.version >= (4, 5, 0) else {}


class CLOUDGEN_OT_bake_vdb(bpy.types.Operator):
    """Bake the active cloud to an OpenVDB file (or a sequence over the scene's frame
    range) and render the baked volume instead"""
    bl_idname = "cloudgen.bake_vdb"
    bl_label = "Bake to VDB"
    # An undo step: Ctrl+Z after a bake removes the Volume object and the bake record and
    # switches the cloud back to procedural; the file stays on disk (undo never deletes files;
    # the next bake overwrites it, and checks.stale reads the file's own key).
    bl_options = {"REGISTER", "UNDO"}

    filepath: bpy.props.StringProperty(
        name="Output", subtype="FILE_PATH", default="", **_RELATIVE_OK,
        description="VDB file to write (empty: //cloudgen/<object>.vdb); for a sequence "
                    "the last run of # is the frame number, else _0001 goes before .vdb")
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
        return cloud_object.is_cloud(getattr(context, "active_object", None)
                                     or context.view_layer.objects.active)

    # -- preparing
    def _prepare(self, context):
        """(job, state) for the active cloud; ValueError/LookupError/RuntimeError say why not.

        Inside Blender (bake_local.py: cloudgen_native + Blender's OpenVDB module) unless
        the preferences name a cloudgen CLI (bake_process.py), which Fit to Camera needs."""
        cloud = context.view_layer.objects.active
        if not cloud_object.is_cloud(cloud):
            raise ValueError("the active object is not a cloud")
        scene = context.scene
        fit = self._is_set("fit_camera", self.fit_camera, scene.cloudgen.bake_fit_camera)
        exe = bridge.cloudgen_executable()
        if fit and exe is None:
            raise ValueError("Fit to Camera needs the cloudgen command-line tool: set its path in "
                             "the add-on's preferences, or turn Fit to Camera off")
        if exe is not None:
            problem = bridge.cli_problem(exe)
            if problem:
                raise ValueError(problem)
        else:
            native = bridge.require()
            vdb = bridge.openvdb()
        given = self.filepath or bake_params.default_path(cloud)
        output = bake_params.resolve_output(given)
        bake_params.make_output_folder(output)
        params = bake_params.cloud_params(cloud)
        self._warnings = []
        frames, per_frame = None, None
        if self.sequence:
            first, last, fps = bake_params.scene_frames(scene)
            frames = (first, last)
            per_frame = sequence.frame_params(scene, cloud, first, last, bake_params.cloud_params)
        per_file = [entry["params"] for entry in per_frame] if per_frame else [params]
        state = {"cloud": cloud, "relative": given.startswith("//"), "frames": frames,
                 "keys": bake_params.field_keys(per_file), "digests": bake_params.params_digests(per_file)}
        scheduler, runner_python = prefs.dask()
        if per_frame and scheduler:  # Bake Frame Range on the Dask cluster (docs/distributed.md)
            if exe is None:
                raise ValueError("a Dask bake runs the cloudgen command-line tool on every worker: set its "
                                 "path in the add-on's preferences (or clear the Dask scheduler)")
            if not runner_python:
                raise ValueError("set Runner Python in the add-on's preferences (a Python with "
                                 "cloudgen_dask installed) or clear the Dask scheduler")
            resolution, extra = self._settings(scene)
            native = bridge.require()
            files = [native.frame_path(output, e["frame"]) for e in per_frame]
            seq = sequence.sequence_object(per_frame, bake_params.scene_frames(scene)[2])
            job = bake_dask.DaskBake(runner_python, scheduler, exe, seq, output, resolution, extra, files,
                                     [e["frame"] for e in per_frame])
            return job, state
        if exe is None:
            values = self._values(scene)
            resolved = [bridge.resolve_params(p) for p in per_file]
            if per_frame:
                entries = [(native.frame_path(output, e["frame"]), r, e["frame"])
                           for e, r in zip(per_frame, resolved)]
            else:
                entries = [(output, resolved[0], None)]
            job = bake_local.LocalBake(native, vdb, entries, bake_local.Settings(
                int(values["resolution"]), bool(values["lod"]), float(values["tolerance"]),
                bool(values["half"])), update=bool(per_frame), version=str(native.version()["version"]))
            return job, state
        resolution, extra = self._settings(scene)
        camera = camera_fit.camera_json(scene, scene.camera, cloud, self._warnings) if fit else None
        seq = None
        if per_frame:
            seq = sequence.sequence_object(per_frame, bake_params.scene_frames(scene)[2])
            extra.append("--update")
        job = bake_process.BakeJob(exe, params, resolution, output, extra=extra, sequence=seq, camera=camera)
        return job, state

    def _tier(self, scene):
        name, tier = quality.current(scene)
        if self.quality:
            tiers = quality.tiers()
            if self.quality not in tiers and self.quality != quality.CUSTOM:
                raise ValueError(f"unknown quality tier {self.quality!r}; known: "
                                 f"{', '.join(tiers) or 'none'}")
            name, tier = (self.quality, tiers[self.quality]) if self.quality in tiers else (None, None)
        return name, tier

    def _overrides(self):
        overrides = {}
        for prop, key, conv in (("resolution", "resolution", int), ("no_lod", "lod", lambda v: not v),
                                ("tolerance", "tolerance", float), ("half", "half", bool)):
            if self.properties.is_property_set(prop):
                overrides[key] = conv(getattr(self, prop))
        return overrides

    def _values(self, scene):
        """{resolution, lod, tolerance, half} of an in-Blender bake (tier, then overrides)."""
        _, tier = self._tier(scene)
        return quality.bake_values((tier or {}).get("bake"), self._overrides())

    def _is_set(self, prop, value, fallback):
        return value if self.properties.is_property_set(prop) else fallback

    def _settings(self, scene):
        """(resolution or None, CLI arguments) from the tier and the explicit overrides."""
        name, tier = self._tier(scene)
        return quality.bake_arguments(name, (tier or {}).get("bake"), self._overrides())

    def _finish(self, context, result, state):
        for line in getattr(self, "_warnings", ()):
            self.report({"WARNING"}, f"Bake to VDB: {line}")
        if not result.ok:
            level = {"WARNING"} if result.cancelled else {"ERROR"}
            self.report(level, f"Bake to VDB: {result.message}")
            return {"CANCELLED"}
        cloud, frames = state["cloud"], state["frames"]
        files = [bpy.path.relpath(p) for p in result.files] if state["relative"] else list(result.files)
        try:
            obj = volume_object.apply_bake(context, cloud, files[0], frames)
        except (RuntimeError, LookupError, ValueError, IndexError) as exc:
            self.report({"ERROR"}, f"Bake to VDB: baked, but the Volume object failed: {exc}")
            return {"CANCELLED"}
        volume_object.store_record(cloud, result, files, frames, state["keys"], state["digests"])
        text = result.message if getattr(result, "counts_override", None) or not frames \
            else sequence.summary(result, frames)
        self.report({"INFO"}, f"Bake to VDB: {text} → {obj.name}")
        return {"FINISHED"}

    # -- background / scripted: synchronous
    def execute(self, context):
        try:
            job, state = self._prepare(context)
        except (ValueError, LookupError, RuntimeError) as exc:
            self.report({"ERROR"}, f"Bake to VDB: {exc}")
            return {"CANCELLED"}
        name, last = state["cloud"].name, [-1]

        def progress(p):
            if int(p) != last[0]:
                last[0] = int(p)
                print(f"cloudgen bake {name}: {p:.0f}%", flush=True)

        job.on_progress = progress
        try:
            job.start()
            result = job.wait()
        except bake_process.BakeError as exc:
            result = exc.result
        except KeyboardInterrupt:
            job.cancel()
            result = job.wait()
        return self._finish(context, result, state)

    # -- with a window: modal, progress bar, ESC cancels
    def invoke(self, context, event):
        if bpy.app.background or context.window is None:
            return self.execute(context)
        try:
            job, state = self._prepare(context)
            job.start()
        except (ValueError, LookupError, RuntimeError, bake_process.BakeError) as exc:
            self.report({"ERROR"}, f"Bake to VDB: {exc}")
            return {"CANCELLED"}
        self._job, self._state = job, state
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
                context.area.header_text_set(f"Baking {self._state['cloud'].name}: "
                                             f"{self._job.progress:.0f}% (Esc to cancel)")
            return {"RUNNING_MODAL"}
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        if context.area:
            context.area.header_text_set(None)
        return self._finish(context, result, self._state)

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
        return cloud_object.is_cloud(context.view_layer.objects.active)

    def execute(self, context):
        cloud = context.view_layer.objects.active
        try:
            volume_object.set_source(cloud, self.source)
        except LookupError as exc:
            self.report({"ERROR"}, f"Cloud Source: {exc}")
            return {"CANCELLED"}
        return {"FINISHED"}


classes = (CLOUDGEN_OT_bake_vdb, CLOUDGEN_OT_cloud_source)
