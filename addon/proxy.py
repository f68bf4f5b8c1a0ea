"""The live 3D proxy: a low-resolution Volume object of each cloud, for the viewport
(Solid, Eevee, Cycles on a GPU — where the procedural OSL cloud does not show).

- One Volume object per cloud, `<cloud> Proxy`, a child of the cloud (found by the
  parent link and the tag PROXY_TAG, so renaming the cloud keeps it), its grid in
  the cloud's local frame (the cloud's scale cancelled, as the baked `<cloud>_VDB`),
  its material like the baked cloud's (volume_material.py with the cloud's own
  "Cloud Volume" shader, reading `density`). Not selectable: clicks keep selecting the cloud.
- Its file is a throw-away VDB (proxy_grid.py) in a private temporary folder of this
  Blender session, a new name at every refresh (Blender keeps loaded grids by path);
  the previous file is deleted. The object stores the key of what it shows (the
  field key of the cloud's parameters and the resolution): a refresh is due when that
  key differs from the cloud's, or the file is gone (a reopened file, an undo).
- **Never rendered**: hide_render, and a render_pre guard that hides any proxy again
  (and says so) before F12, an animation or `blender -b` render — registered whenever a
  proxy exists, also in files opened without the toggle on. While a render runs no
  refresh happens.
- **Costs nothing when off**: turning `scene.cloudgen.proxy` off deletes the scene's
  proxies, their files and materials, and unregisters every handler and timer of this
  module but one: the load_post hook that re-arms it when a file with the proxy on is
  opened (a few attribute reads per file load).
- **On by default** with a UI (the artist added a cloud to see it); in background
  mode (`blender -b`, farms, scripts) only when a script or the saved file sets
  the toggle explicitly: no viewport to show it there.
- Refresh: a depsgraph_update_post handler notes a parameter change; with a UI one
  timer (never more than one pending) starts DEBOUNCE seconds later a Job with the
  values of that moment: the kernel and the file in a worker thread (the core releases
  the GIL: the UI keeps running, a slider drag stays smooth), the Volume object updated
  on the main thread when it is done, then the next due cloud — a drag is followed
  as fast as refreshes finish, never more than one at a time. In background mode (no
  event loop) the handler refreshes at once. Each refresh is timed; above SLOW_MS the
  panel says so.
"""
from __future__ import annotations

import atexit
import os
import shutil
import sys
import tempfile
import threading
import time

import bpy
from mathutils import Matrix

from . import bridge, cloud_object, proxy_grid, volume_material, volume_object

PROXY_TAG = "cloudgen_proxy"          # on the proxy object: 1
KEY_PROP = "cloudgen_proxy_key"       # what it shows: "<field key>-<resolution>"
MS_PROP = "cloudgen_proxy_ms"         # the last refresh's time, milliseconds
DEBOUNCE = 0.05
POLL = 0.01
SLOW_MS = 100.0


class _State:
    folder = None          # this session's private folder of proxy files
    counter = 0
    errors = {}            # cloud name -> (the key that failed, one line)
    stages = {}            # the last refresh's stages, ms
    job = (None, None)     # (Job, its worker thread) while the UI's timer computes one
    rendering = False
    armed = False


state = _State()


# ---------------------------------------------------------------- finding proxies
def is_proxy(obj) -> bool:
    return obj is not None and obj.get(PROXY_TAG) == 1


def proxy_of(cloud):
    """The cloud's proxy object, or None."""
    for child in cloud.children:
        if is_proxy(child):
            return child
    return None


def all_proxies():
    return [o for o in bpy.data.objects if is_proxy(o)]


def settings(scene):
    return scene.cloudgen


def wanted(scene) -> bool:
    """The toggle is on here: explicitly, or by default in a session with a UI."""
    s = settings(scene)
    if bpy.app.background and not s.is_property_set("proxy"):
        return False
    return bool(s.proxy)


def _clouds(scene):
    return [o for o in scene.objects if cloud_object.is_cloud(o)]


def _folder() -> str:
    if state.folder is None or not os.path.isdir(state.folder):
        state.folder = tempfile.mkdtemp(prefix="cloudgen-proxy-")
    return state.folder


def _remove_folder():
    if state.folder is not None:
        shutil.rmtree(state.folder, ignore_errors=True)
        state.folder = None


atexit.register(_remove_folder)


def _own_file(path) -> bool:
    return bool(path) and state.folder is not None \
        and os.path.dirname(os.path.abspath(path)) == os.path.abspath(state.folder)


# ---------------------------------------------------------------- one cloud
def key_and_params(cloud, scene):
    """(key, resolved params) of what the cloud's proxy should show now. Raises
    RuntimeError / LookupError / ValueError / TypeError naming the problem."""
    params = bridge.resolve_params(cloud_object.params_from_object(cloud))
    res = proxy_grid.check_resolution(settings(scene).proxy_resolution)
    return f"{bridge.field_key(params) or repr(sorted(params.items()))}-{res}", params


def due(cloud, scene) -> bool:
    """The cloud's proxy is missing, shows other parameters, or lost its file — and this
    state has not already failed (a bad parameter, no OpenVDB module: said once, not
    retried at every update until something changes)."""
    try:
        key, _ = key_and_params(cloud, scene)
    except (RuntimeError, LookupError, ValueError, TypeError) as exc:
        key = f"error: {exc}"
    failed = state.errors.get(cloud.name)
    if failed is not None and failed[0] == key:
        return False
    obj = proxy_of(cloud)
    if obj is None:
        return True
    return obj.get(KEY_PROP) != key or not os.path.isfile(bpy.path.abspath(obj.data.filepath))


def _new_proxy(cloud, scene):
    name = cloud.name + " Proxy"
    vol = bpy.data.volumes.new(name)
    obj = bpy.data.objects.new(name, vol)
    obj[PROXY_TAG] = 1
    for coll in cloud.users_collection or (scene.collection,):
        coll.objects.link(obj)
    obj.parent = cloud
    obj.hide_render = True
    obj.hide_select = True
    vol.display.density = 0.2  # Solid view: the grid holds physical densities (~10 in a core)
    vol.materials.append(_material(cloud, name))
    return obj


def _material(cloud, name):
    """The proxy's material: like the baked cloud's (volume_object.py), the cloud's own
    "Cloud Volume" shader (type, phase, colour) reading the grid `density`."""
    mat = bpy.data.materials.new(name)
    look = bridge.presets().get(cloud.get(cloud_object.TYPE_KEY, ""), {}).get("material", {})
    mine = cloud_object.cloud_material(cloud)
    like = mine.node_tree.nodes.get(volume_material.VOLUME_NODE) if mine is not None else None
    volume_material.volume_material(mat, look, grid="density", like=like, phase="HG")
    return mat


class Job:
    """One cloud's refresh: prepared on the main thread (the parameters, the modules, the
    file name; raises with the reason), `run()` anywhere (kernel and file: no bpy, the
    core releases the GIL), `apply()` on the main thread (the Volume object)."""

    def __init__(self, cloud, scene):
        self.t0 = time.perf_counter()
        self.cloud_name = cloud.name
        self.key = None
        self.error = None
        self.path = None
        try:
            self.key, self.params = key_and_params(cloud, scene)
            self.vdb, self.native = bridge.openvdb(), bridge.require()
            self.resolution = proxy_grid.check_resolution(settings(scene).proxy_resolution)
            state.counter += 1
            self.path = os.path.join(_folder(), f"proxy-{state.counter}.vdb")
        except (RuntimeError, LookupError, ValueError, TypeError, OSError) as exc:
            self._failed(cloud.name, exc)
            raise
        self.stages = {"parameters": 1000.0 * (time.perf_counter() - self.t0)}

    def _failed(self, name, exc):
        state.errors[name] = (self.key or f"error: {exc}", f"3D Proxy: {exc}")

    def run(self):
        t1 = time.perf_counter()
        try:
            values, plan = proxy_grid.compute(self.native, self.params, self.resolution)
            t2 = time.perf_counter()
            proxy_grid.write(self.vdb, self.path, values, plan)
        except Exception as exc:  # noqa: BLE001 - reported by apply() on the main thread
            self.error = exc
            return
        self.stages["kernel"] = 1000.0 * (t2 - t1)
        self.stages["write"] = 1000.0 * (time.perf_counter() - t2)

    def apply(self, cloud, scene) -> float:
        """Show the file on the cloud's proxy (created if needed); the refresh's time in ms."""
        if self.error is not None:
            self._failed(cloud.name, self.error)
            raise RuntimeError(str(self.error)) from self.error
        t3 = time.perf_counter()
        state.errors.pop(cloud.name, None)
        obj = proxy_of(cloud) or _new_proxy(cloud, scene)
        old = obj.data.filepath
        obj.data.filepath = self.path
        obj.data.grids.load()
        if old != self.path and _own_file(old):
            _remove_file(old)
        scale = [s if abs(s) > 1e-12 else 1.0 for s in cloud.scale]
        inverse = Matrix.Diagonal((1.0 / scale[0], 1.0 / scale[1], 1.0 / scale[2], 1.0))
        if obj.matrix_parent_inverse != inverse:
            obj.matrix_parent_inverse = inverse
        if obj.matrix_basis != Matrix.Identity(4):
            obj.matrix_basis = Matrix.Identity(4)
        obj[KEY_PROP] = self.key
        self.stages["reload"] = 1000.0 * (time.perf_counter() - t3)
        # the work, not the wait: with a UI the worker's result waits for the next timer call
        ms = self.stages["total"] = sum(self.stages.values())
        obj[MS_PROP] = ms
        state.stages = dict(self.stages)
        return ms

    def discard(self):
        if self.path and _own_file(self.path):
            _remove_file(self.path)


def refresh(cloud, scene) -> float:
    """Recompute the cloud's proxy now, on this thread; the time taken in ms (its stages
    in state.stages). On failure the one-line reason goes to state.errors[cloud.name]
    and the error is raised."""
    job = Job(cloud, scene)
    job.run()
    return job.apply(cloud, scene)


def measure(cloud, scene, resolutions=(32, 64, 96), repeats=5) -> dict:
    """Best of `repeats` refreshes per resolution, per stage, in ms: {resolution: {"parameters",
    "kernel", "write", "reload", "total"}} (docs/addon.md, "3D Proxy"). Leaves the
    scene's resolution as it was. "reload" is the Volume datablock's (its grids' metadata);
    the viewport loads the voxels when it next draws, which this does not include."""
    s = settings(scene)
    before = s.proxy_resolution
    out = {}
    try:
        for res in resolutions:
            s.proxy_resolution = res
            best = {}
            for _ in range(repeats):
                refresh(cloud, scene)
                for k, v in state.stages.items():
                    best[k] = min(best.get(k, v), v)
            out[res] = best
    finally:
        s.proxy_resolution = before
    return out


def _remove_file(path):
    try:
        os.remove(path)
    except OSError:
        pass


def remove(obj):
    """Delete a proxy object with its Volume datablock, material and file."""
    vol = obj.data
    path = vol.filepath
    mats = [m for m in vol.materials if m is not None]
    bpy.data.objects.remove(obj)
    if vol.users == 0:
        bpy.data.volumes.remove(vol)
    for m in mats:
        if m.users == 0:
            bpy.data.materials.remove(m)
    if _own_file(path):
        _remove_file(path)


# ---------------------------------------------------------------- the scene
def pending(scene):
    """Clouds of the scene whose proxy is due, the active one first; removes proxies
    that have no cloud any more (deleted) or whose cloud renders its bake."""
    for obj in all_proxies():
        parent = obj.parent
        if parent is None or not cloud_object.is_cloud(parent) or parent.users == 0 \
                or parent.get(volume_object.SOURCE_KEY) == "BAKED":
            remove(obj)
    active = getattr(bpy.context.view_layer.objects, "active", None) if bpy.context.view_layer else None
    clouds = [c for c in _clouds(scene) if c.get(volume_object.SOURCE_KEY) != "BAKED"]
    clouds.sort(key=lambda c: c != active)
    return [c for c in clouds if due(c, scene)]


def sync(scene):
    """Refresh the scene's due proxies now, on this thread (background mode, the toggle,
    a file load). Errors are kept per cloud (the panel shows them), never raised."""
    for cloud in pending(scene):
        try:
            refresh(cloud, scene)
        except (RuntimeError, LookupError, ValueError, TypeError, OSError):
            pass
    if all_proxies():
        _guard(True)


def remove_all(scene=None):
    """Delete the proxies of the scene's clouds (every proxy when scene is None)."""
    clouds = None if scene is None else set(_clouds(scene))
    for obj in all_proxies():
        if clouds is None or obj.parent in clouds or obj.parent is None:
            remove(obj)
    state.errors.clear()


# ---------------------------------------------------------------- handlers, timer
def _tick():
    """The one pending refresh (a bpy.app.timers function, with a UI): starts one cloud's
    kernel in a worker thread and comes back every POLL seconds until it is done, applies
    it, then the next due cloud; None (unregistered) when nothing is left."""
    scene = bpy.context.scene
    if state.rendering or scene is None or not wanted(scene):
        return None
    job, thread = state.job
    if thread is not None:
        if thread.is_alive():
            return POLL
        state.job = (None, None)
        cloud = bpy.data.objects.get(job.cloud_name)
        if cloud is None or not cloud_object.is_cloud(cloud):
            job.discard()  # deleted or renamed meanwhile: pending() sees to it
        else:
            try:
                job.apply(cloud, scene)
            except RuntimeError:
                job.discard()
            _redraw()
    todo = pending(scene)
    for cloud in todo:
        try:
            job = Job(cloud, scene)
        except (RuntimeError, LookupError, ValueError, TypeError, OSError):
            continue  # said in the panel
        thread = threading.Thread(target=job.run, name="cloudgen-proxy", daemon=True)
        state.job = (job, thread)
        thread.start()
        return POLL
    if all_proxies():
        _guard(True)
    _redraw()
    return None


def _schedule():
    if bpy.app.background:
        return
    if not bpy.app.timers.is_registered(_tick):
        bpy.app.timers.register(_tick, first_interval=DEBOUNCE)


def _redraw():
    wm = getattr(bpy.context, "window_manager", None)
    for window in getattr(wm, "windows", ()):
        for area in window.screen.areas:
            if area.type in ("VIEW_3D", "PROPERTIES"):
                area.tag_redraw()


_WATCHED = ("OBJECT", "MATERIAL", "NODETREE", "SCENE", "MESH")


@bpy.app.handlers.persistent
def on_depsgraph_update(scene, depsgraph=None):
    if state.rendering or scene is None or not wanted(scene):
        return
    if depsgraph is not None and not any(depsgraph.id_type_updated(t) for t in _WATCHED):
        return
    if bpy.app.background:
        sync(scene)
    elif not bpy.app.timers.is_registered(_tick) and pending(scene):
        _schedule()


@bpy.app.handlers.persistent
def on_undo(*_):
    scene = bpy.context.scene
    if scene is not None and wanted(scene):
        if bpy.app.background:
            sync(scene)
        else:
            _schedule()


@bpy.app.handlers.persistent
def on_render_pre(scene, *_):
    """No proxy is ever rendered: hide any that someone un-hid, before the render."""
    state.rendering = True
    for obj in all_proxies():
        if not obj.hide_render:
            obj.hide_render = True
            print(f"cloudgen: the 3D proxy {obj.name} is for the viewport only; hidden from the render",
                  file=sys.stderr, flush=True)


@bpy.app.handlers.persistent
def on_render_end(*_):
    state.rendering = False


@bpy.app.handlers.persistent
def on_load_post(*_):
    state.errors.clear()
    state.rendering = False
    _drop_job()  # a refresh of the previous file's cloud must not land on a namesake
    rearm()
    scene = bpy.context.scene
    if state.armed and scene is not None and wanted(scene):
        if bpy.app.background:
            # obj.dimensions (the box size) is (1, 1, 1) until the depsgraph has run once
            bpy.context.view_layer.update()
            sync(scene)
        else:
            _schedule()


_ARMED = (("depsgraph_update_post", on_depsgraph_update), ("undo_post", on_undo), ("redo_post", on_undo))
_GUARD = (("render_pre", on_render_pre), ("render_complete", on_render_end), ("render_cancel", on_render_end))


def _add_handler(name, fn):
    handlers = getattr(bpy.app.handlers, name)
    if fn not in handlers:
        handlers.append(fn)


def _remove_handler(name, fn):
    handlers = getattr(bpy.app.handlers, name)
    while fn in handlers:
        handlers.remove(fn)


def _drop_job():
    """Forget a running refresh (its thread ends by itself; its file is removed with the folder)."""
    job, _ = state.job
    state.job = (None, None)
    if job is not None:
        job.discard()


def _guard(on):
    for name, fn in _GUARD:
        (_add_handler if on else _remove_handler)(name, fn)


def rearm():
    """Register the refresh handlers when a scene wants the proxy, the render guard when a
    proxy exists; unregister them (and the timer) otherwise."""
    try:
        scenes = list(bpy.data.scenes)
    except AttributeError:  # bpy.data is restricted while add-ons register
        _guard(True)  # a file may hold proxies already: guard renders until we can look
        if not bpy.app.background:
            bpy.app.timers.register(_rearm_later, first_interval=0.0)
        return
    on = any(hasattr(s, "cloudgen") and wanted(s) for s in scenes)
    for name, fn in _ARMED:
        (_add_handler if on else _remove_handler)(name, fn)
    _guard(on or bool(all_proxies()))
    if not on:
        if bpy.app.timers.is_registered(_tick):
            bpy.app.timers.unregister(_tick)
        _drop_job()
    state.armed = on


def _rearm_later():
    rearm()
    scene = bpy.context.scene
    if state.armed and scene is not None and wanted(scene):
        _schedule()
    return None


def on_toggle(scene):
    """scene.cloudgen.proxy changed (props.py): build the proxies now, or remove them."""
    if wanted(scene):
        rearm()
        sync(scene)
    else:
        remove_all(scene)
        rearm()
        if not all_proxies():
            _remove_folder()


def on_resolution(scene):
    if wanted(scene):
        sync(scene)


# ---------------------------------------------------------------- panel text
def status(cloud, scene):
    """[(icon, text)] about the cloud's proxy, for the panel."""
    if cloud.name in state.errors:
        return [("ERROR", state.errors[cloud.name][1])]
    obj = proxy_of(cloud)
    if cloud.get(volume_object.SOURCE_KEY) == "BAKED":
        return [("INFO", "The cloud shows its bake; no proxy")]
    if obj is None:
        return []
    ms = float(obj.get(MS_PROP, 0.0))
    n = obj.get(KEY_PROP, "").rsplit("-", 1)[-1]
    lines = [("NONE", f"{n} voxels, refreshed in {ms:.0f} ms")]
    if ms > SLOW_MS:
        lines.append(("ERROR", f"Slow (over {SLOW_MS:.0f} ms): lower the proxy resolution"))
    return lines


def on_register():
    _add_handler("load_post", on_load_post)
    rearm()


def on_unregister():
    for name, fn in _ARMED + _GUARD + (("load_post", on_load_post),):
        _remove_handler(name, fn)
    for fn in (_tick, _rearm_later):
        if bpy.app.timers.is_registered(fn):
            bpy.app.timers.unregister(fn)
    _drop_job()
    state.armed = False


classes = ()
