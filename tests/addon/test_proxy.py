"""The live 3D proxy (addon/proxy.py) in the 4.5 wheel (background mode: the depsgraph
handler refreshes at once; the UI's timer function `_tick` is called as Blender would).

Tolerances: the proxy is a point bake of bake_plan(params, resolution): its voxels equal
those of `cloudgen bake --resolution N` of the same parameters (the core's grid.cpp, which
samples a cell overhanging the box inside it, weighted by its share) with tolerance 0.
Placement: 1e-5 (float matrices). Renders:
the same scene with and without the proxy must give images equal within 1e-6 (Cycles
with a fixed seed is deterministic on one machine); the control render with the
proxy visible and the guard removed must differ by more than 0.01 somewhere.
"""
import os
import pathlib
import subprocess
import tempfile
import time

import cloudgen_native as cn
import numpy as np
import pytest
from addon_helpers import add_camera_and_sun, render_to_array

CLI = pathlib.Path(__file__).resolve().parents[2] / "build" / "bin" / "cloudgen"
PROXY_HANDLERS = ("depsgraph_update_post", "undo_post", "redo_post", "render_pre", "render_complete",
                  "render_cancel")


def _cloud(addon, kind="cumulus"):
    import bpy

    assert bpy.ops.cloudgen.add_cloud(cloud_type=kind) == {"FINISHED"}
    return bpy.context.view_layer.objects.active


def _grid(addon, obj):
    """The proxy file's density grid as a (nx, ny, nz) array and its index->local transform."""
    vdb = addon.bridge.openvdb()
    grid = vdb.read(obj.data.filepath, "density")
    lo, hi = grid.evalActiveVoxelBoundingBox()
    return grid, lo, hi


def _expected(cloud, addon, resolution):
    """The CLI's bake of the cloud's parameters at `resolution` as an (nx, ny, nz) array."""
    params = cn.resolve_params(addon.cloud_object.params_from_object(cloud))
    plan = cn.bake_plan(params, resolution, lod=True)
    with tempfile.TemporaryDirectory() as tmp:
        source = pathlib.Path(tmp) / "params.json"
        source.write_text(plan["params_json"])
        out = pathlib.Path(tmp) / "cli.vdb"
        r = subprocess.run([str(CLI), "bake", "--params", str(source), "--resolution", str(resolution),
                            "--output", str(out), "--quiet"], capture_output=True, text=True, timeout=120)
        assert r.returncode == 0, r.stderr
        values = np.zeros(plan["grid"], dtype=np.float32)
        addon.bridge.openvdb().read(str(out), "density").copyToArray(values, ijk=(0, 0, 0))
    return values, plan, params


def _assert_matches(addon, cloud, resolution):
    """The proxy shows the cloud's current density: every voxel exactly, and the grid in place."""
    proxy = addon.proxy.proxy_of(cloud)
    assert proxy is not None, f"{cloud.name} has no proxy"
    want, plan, params = _expected(cloud, addon, resolution)
    grid, _, _ = _grid(addon, proxy)
    got = np.zeros(want.shape, dtype=np.float32)
    grid.copyToArray(got, ijk=(0, 0, 0))
    bad = np.argwhere(got != want)
    assert bad.size == 0, (f"{len(bad)} voxels differ (tolerance 0), first {tuple(bad[0])}: "
                           f"{got[tuple(bad[0])]} != {want[tuple(bad[0])]}; params {params}")
    # outside the grid nothing is active
    assert grid.activeVoxelCount() == int(np.count_nonzero(want))
    # voxel centres where the core evaluated them (index -> local), and local = the cloud's frame
    v = float(plan["voxel"])
    for ijk in ((0, 0, 0), tuple(x - 1 for x in plan["grid"])):
        centre = grid.transform.indexToWorld(ijk)
        expect = [float(plan["origin"][a]) + (ijk[a] + 0.5) * v for a in range(3)]
        assert np.allclose(centre, expect, atol=1e-5), (ijk, centre, expect)
    return got


def _frame_of_cloud(cloud):
    from mathutils import Matrix

    loc, rot, _ = cloud.matrix_world.decompose()
    return Matrix.LocRotScale(loc, rot, (1.0, 1.0, 1.0))


def _proxy_handlers(addon):
    import bpy

    fns = {addon.proxy.on_depsgraph_update, addon.proxy.on_undo, addon.proxy.on_render_pre,
           addon.proxy.on_render_end}
    return [(name, fn.__name__) for name in PROXY_HANDLERS for fn in getattr(bpy.app.handlers, name) if fn in fns]


@pytest.fixture(autouse=True)
def proxy_off(addon):
    """Every test starts and ends with no proxy and nothing of the proxy registered."""
    import bpy

    yield
    for sc in bpy.data.scenes:
        sc.cloudgen.proxy = False
    assert not bpy.app.timers.is_registered(addon.proxy._tick)


def test_background_default_builds_nothing(addon, scene):
    """Off until asked in background mode (no viewport): Add Cloud makes no proxy and no
    handler of the proxy runs."""
    import bpy

    cloud = _cloud(addon)
    bpy.context.view_layer.update()
    assert scene.cloudgen.proxy and not scene.cloudgen.is_property_set("proxy")
    assert addon.proxy.proxy_of(cloud) is None
    assert _proxy_handlers(addon) == []


def test_proxy_appears_and_follows_sliders(addon, scene):
    import bpy

    cloud = _cloud(addon)
    cloud.location = (3.0, -2.0, 5.0)
    cloud.rotation_euler = (0.0, 0.0, 0.6)
    scene.cloudgen.proxy = True
    proxy = addon.proxy.proxy_of(cloud)
    assert proxy is not None and proxy.type == "VOLUME" and proxy.parent == cloud
    assert proxy.hide_render and proxy.hide_select
    nodes = proxy.data.materials[0].node_tree.nodes  # the cloud's shader reading the grid
    volume = nodes["Cloud Volume"]
    if "Density Attribute" in volume.inputs:
        assert volume.inputs["Density Attribute"].default_value == "density"
    else:
        assert nodes["Density Grid"].attribute_name == "density"
    first = _assert_matches(addon, cloud, 64)
    assert max(first.shape) == 64
    bpy.context.view_layer.update()
    assert (np.array(proxy.matrix_world) - np.array(_frame_of_cloud(cloud))).max() < 1e-5

    # a slider: the grid follows (the depsgraph handler), the old file is gone
    old_path = proxy.data.filepath
    _, noise = addon.cloud_object.cloud_nodes(cloud)
    noise.inputs["Seed"].default_value = 7
    bpy.context.view_layer.update()
    assert proxy.data.filepath != old_path and not os.path.exists(old_path)
    second = _assert_matches(addon, cloud, 64)
    assert not np.array_equal(first, second), "the seed changed nothing in the proxy"

    # the box (object scale) and the resolution
    cloud.scale = (6.0, 3.0, 2.0)
    bpy.context.view_layer.update()
    third = _assert_matches(addon, cloud, 64)
    assert third.shape == (64, 32, 22), third.shape
    assert (np.array(proxy.matrix_world) - np.array(_frame_of_cloud(cloud))).max() < 1e-5
    scene.cloudgen.proxy_resolution = 32
    assert max(_assert_matches(addon, cloud, 32).shape) == 32
    status = dict((t, i) for i, t in addon.proxy.status(cloud, scene))
    assert any(t.startswith("32 voxels, refreshed in") for t in status), status


def test_several_clouds_timer_rename_delete_bake(addon, scene):
    import bpy

    a, b = _cloud(addon), _cloud(addon, "stratocumulus")
    scene.cloudgen.proxy = True
    pa, pb = addon.proxy.proxy_of(a), addon.proxy.proxy_of(b)
    assert pa is not None and pb is not None and pa != pb
    # the UI's timer (called as Blender would): one cloud at a time in a worker thread,
    # polled, applied, then the next; None when nothing is left (values changed without
    # a depsgraph update, so only the timer refreshes them)
    for cloud, seed in ((a, 3), (b, 4)):
        addon.cloud_object.cloud_nodes(cloud)[1].inputs["Seed"].default_value = seed
    started = []
    for _ in range(20000):
        wait = addon.proxy._tick()
        job = addon.proxy.state.job[0]
        if job is not None and job not in started:
            started.append(job)
        if wait is None:
            break
        time.sleep(wait)
    assert wait is None, "the timer never finished"
    assert sorted(j.cloud_name for j in started) == sorted([a.name, b.name]), [j.cloud_name for j in started]
    assert addon.proxy.state.job == (None, None)
    _assert_matches(addon, a, 64)
    _assert_matches(addon, b, 64)
    # rename: the same proxy follows
    a.name = "Renamed Cloud"
    addon.cloud_object.cloud_nodes(a)[1].inputs["Seed"].default_value = 5
    bpy.context.view_layer.update()
    assert addon.proxy.proxy_of(a) == pa
    _assert_matches(addon, a, 64)
    # delete a cloud: its proxy, volume and file go
    path, vol_name = pb.data.filepath, pb.data.name
    bpy.data.objects.remove(b)
    bpy.context.view_layer.update()
    assert not os.path.exists(path) and vol_name not in bpy.data.volumes
    assert [o.name for o in addon.proxy.all_proxies()] == [pa.name]
    # a cloud that renders its bake shows the bake, not a proxy
    a[addon.volume_object.SOURCE_KEY] = "BAKED"  # what volume_object.set_source does
    a.hide_render = True
    bpy.context.view_layer.update()
    assert addon.proxy.all_proxies() == []


def test_off_leaves_nothing(addon, scene):
    import bpy

    cloud = _cloud(addon)
    scene.cloudgen.proxy = True
    folder = addon.proxy.state.folder
    assert _proxy_handlers(addon), "on: the proxy's handlers should be registered"
    assert os.listdir(folder)
    scene.cloudgen.proxy = False
    assert addon.proxy.proxy_of(cloud) is None and addon.proxy.all_proxies() == []
    assert not [v for v in bpy.data.volumes if "Proxy" in v.name]
    assert not [m for m in bpy.data.materials if "Proxy" in m.name]
    assert _proxy_handlers(addon) == [], _proxy_handlers(addon)
    assert not bpy.app.timers.is_registered(addon.proxy._tick)
    assert not os.path.exists(folder)
    # edits while off cost nothing: no proxy comes back
    addon.cloud_object.cloud_nodes(cloud)[1].inputs["Seed"].default_value = 9
    bpy.context.view_layer.update()
    assert addon.proxy.all_proxies() == []


def test_never_rendered(addon, scene, tmp_path, monkeypatch):
    import bpy

    cloud = _cloud(addon)
    add_camera_and_sun(scene, cloud)
    without = render_to_array(scene, tmp_path / "without.png")
    assert without.max() > 0.05, "the procedural cloud itself rendered black: the comparison proves nothing"
    scene.cloudgen.proxy = True
    proxy = addon.proxy.proxy_of(cloud)
    proxy.hide_render = False  # someone un-hides it: the render_pre guard hides it again
    guarded = render_to_array(scene, tmp_path / "guarded.png")
    assert proxy.hide_render
    diff = float(np.abs(guarded - without).max())
    assert diff <= 1e-6, f"the proxy changed the render by {diff} (tolerance 1e-6)"
    # control: without the guard an un-hidden proxy does render (the test can fail)
    monkeypatch.setattr(addon.proxy, "_guard", lambda on: None)  # no re-registration by a refresh
    bpy.app.handlers.render_pre.remove(addon.proxy.on_render_pre)
    try:
        proxy.hide_render = False
        cloud.hide_render = True
        control = render_to_array(scene, tmp_path / "control.png")
    finally:
        bpy.app.handlers.render_pre.append(addon.proxy.on_render_pre)
        cloud.hide_render = False
    assert float(control.max()) > 0.01, "control: a visible proxy rendered nothing"
    assert not addon.proxy.state.rendering


def test_survives_save_and_reload(addon, scene, tmp_path):
    import bpy

    cloud = _cloud(addon)
    scene.cloudgen.proxy = True
    name, cloud_name = addon.proxy.proxy_of(cloud).name, cloud.name
    blend = tmp_path / "proxy.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(blend))
    addon.proxy._remove_folder()  # a new session: the temporary files are gone
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    cloud = bpy.data.objects[cloud_name]
    proxy = addon.proxy.proxy_of(cloud)
    assert proxy is not None and proxy.name == name and len(addon.proxy.all_proxies()) == 1
    assert os.path.isfile(proxy.data.filepath), "the proxy was not regenerated after reopening"
    assert addon.proxy.state.errors == {}
    _assert_matches(addon, cloud, 64)
    # a file saved with the proxy on, opened in background without it armed: the guard stays
    assert addon.proxy.on_render_pre in bpy.app.handlers.render_pre


def test_undo_regenerates(addon, scene, tmp_path):
    import bpy

    cloud = _cloud(addon)
    scene.cloudgen.proxy = True
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "undo.blend"))
    cloud_name = cloud.name
    bpy.ops.ed.undo_push(message="proxy on")
    addon.cloud_object.cloud_nodes(cloud)[1].inputs["Seed"].default_value = 11
    bpy.context.view_layer.update()
    bpy.ops.ed.undo_push(message="seed")
    assert bpy.ops.ed.undo() == {"FINISHED"}
    cloud = bpy.data.objects[cloud_name]
    assert addon.cloud_object.cloud_nodes(cloud)[1].inputs["Seed"].default_value != 11
    proxy = addon.proxy.proxy_of(cloud)
    assert proxy is not None and os.path.isfile(proxy.data.filepath), "undo left the proxy without its file"
    _assert_matches(addon, cloud, 64)


def test_bad_parameter_is_reported_once(addon, scene):
    import bpy

    cloud = _cloud(addon)
    scene.cloudgen.proxy = True
    main, _ = addon.cloud_object.cloud_nodes(cloud)
    main.inputs["Density"].default_value = 50.0  # past the declared hard range [0, 10]
    bpy.context.view_layer.update()
    lines = addon.proxy.status(cloud, scene)
    assert lines and lines[0][0] == "ERROR" and "density" in lines[0][1], lines
    assert not addon.proxy.due(cloud, scene), "the same error would be retried at every update"
    main.inputs["Density"].default_value = 1.0
    bpy.context.view_layer.update()
    assert addon.proxy.status(cloud, scene)[0][0] == "NONE"
    _assert_matches(addon, cloud, 64)


def test_without_openvdb_says_so_once(addon, scene, monkeypatch):
    """A Blender without an OpenVDB Python module (official 3.4 builds): one line in the
    panel, and no kernel run at every later update."""
    import bpy

    def no_vdb():
        raise RuntimeError("this Blender has no OpenVDB Python module (test)")

    calls = []
    compute = addon.proxy_grid.compute
    monkeypatch.setattr(addon.bridge, "openvdb", no_vdb)
    monkeypatch.setattr(addon.proxy_grid, "compute", lambda *a: calls.append(1) or compute(*a))
    cloud = _cloud(addon)
    scene.cloudgen.proxy = True
    assert addon.proxy.proxy_of(cloud) is None
    assert addon.proxy.status(cloud, scene) == [("ERROR", "3D Proxy: this Blender has no OpenVDB Python module (test)")]
    cloud.location.x += 1.0  # an edit that does not touch the density field's key
    bpy.context.view_layer.update()
    assert calls == [], "the kernel ran although the file could not be written"
    assert not addon.proxy.due(cloud, scene)
