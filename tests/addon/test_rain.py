"""Add Rain (addon/precipitation.py, the operator in addon/operators.py), in the bpy wheel:
what falls from a rain cloud, the cue that tells a nimbostratus from a stratus and a
cumulonimbus from a big cumulus (issue 13; the blind reviews: "no rain shaft", "no rain
streaks").

- the rain box runs from the ground (z = 0) to the cloud's base (tolerance 1e-4 scene units)
  and covers the cloud's footprint just above its base, measured on the model (to one step of
  the add-on's grid, checked on a grid twice as fine): most of a layer's box, a storm's tower;
- its full density is Koschmieder's 3.912 / V (relative 1e-6), the type's own visibility
  unless the artist sets one;
- a second Add Rain replaces the cloud's rain and leaves no orphan mesh or material;
- a cloud whose base is at or below the ground, a bad visibility or patchiness: a clear error
  naming the parameter and its range, and nothing added;
- rendered under a sun over a black world, the rain is lit (mean above 0.01) and streaked (the
  columns' means across it, high-passed, vary 1.5 times as much as without streaks), and finite."""
import math

import pytest


def _add(cloud_type, z):
    import bpy

    assert bpy.ops.cloudgen.add_cloud(cloud_type=cloud_type) == {"FINISHED"}
    cloud = bpy.context.view_layer.objects.active
    cloud.location = (0.0, 0.0, z)
    bpy.context.view_layer.update()
    return cloud


def _rain(scene, cloud):
    return scene.objects[f"{cloud.name} Rain"]


def _bounds(obj):
    from mathutils import Vector

    pts = [obj.matrix_world @ Vector(c) for c in obj.bound_box]
    return [min(p[i] for p in pts) for i in range(3)], [max(p[i] for p in pts) for i in range(3)]


def _full_density(rain, pr):
    """The extinction multiplied into the rain's density (the node precipitation names)."""
    return rain.data.materials[0].node_tree.nodes[pr.EXTINCTION_NODE].inputs[1].default_value


def _farthest(values, n=129):
    """Half-widths of the cloud's footprint at precipitation's height above its base, measured
    here on a finer grid (n² points) than the add-on's, with cloudgen_native.density."""
    import cloudgen_native as cn
    import numpy as np

    from_base = max(values.get("base_height", 0.0), 0.0)
    bx, by, bz = values["box_size"]
    u = np.linspace(-0.5, 0.5, n)
    x, y = np.meshgrid(u * bx, u * by, indexing="ij")
    h = from_base + 0.05
    pts = np.stack([x.ravel(), y.ravel(), np.full(x.size, (h - 0.5) * bz)], axis=1)
    inside = cn.density(values, pts) > 0.0
    return float(np.abs(pts[inside, 0]).max()), float(np.abs(pts[inside, 1]).max())


def _check_rain_box(addon, cloud, rain):
    """The rain runs from the ground to the cloud's base (1e-4 units) and its half-widths are the
    model's footprint there, to one step of the add-on's grid (the box / 64)."""
    pr = addon.precipitation
    assert pr.FOOTPRINT_ABOVE_BASE == 0.05  # _farthest measures at the same height
    values = addon.cloud_object.params_from_object(cloud)
    lo, hi = _bounds(rain)
    box = cloud.dimensions
    base = cloud.location.z - box.z / 2 + max(values["base_height"], 0.0) * box.z
    assert lo[2] == pytest.approx(0.0, abs=1e-4) and hi[2] == pytest.approx(base, abs=1e-4), (lo, hi, base)
    want = _farthest(values)
    for axis in range(2):
        step = box[axis] / (pr.FOOTPRINT_SAMPLES - 1)
        assert abs(hi[axis] - want[axis]) <= step and abs(-lo[axis] - want[axis]) <= step, (axis, lo, hi, want, step)
    return hi, box


def test_rain_under_a_layer_covers_it_from_the_ground_to_its_base(addon, scene):
    import bpy

    pr = addon.precipitation
    cloud = _add("nimbostratus", 5.0)
    assert bpy.ops.cloudgen.add_rain() == {"FINISHED"}
    rain = _rain(scene, cloud)
    hi, box = _check_rain_box(addon, cloud, rain)
    # the layer, not a patch of it: a Sheet is full in the inner half of each half-width (docs/model.md)
    assert hi[0] >= 0.25 * box.x and hi[1] >= 0.25 * box.y, (hi, box)
    look = pr.LOOKS["nimbostratus"]
    assert _full_density(rain, pr) == pytest.approx(3.912 / pr.units(look["visibility_km"]), rel=1e-6)


def test_rain_under_a_storm_falls_under_its_tower(addon, scene):
    import bpy

    pr = addon.precipitation
    cloud = _add("cumulonimbus", 20.0)
    assert bpy.ops.cloudgen.add_rain(visibility_km=1.0) == {"FINISHED"}
    rain = _rain(scene, cloud)
    hi, box = _check_rain_box(addon, cloud, rain)
    assert hi[0] < 0.2 * box.x and hi[1] < 0.3 * box.y, (hi, box)  # a shaft, not the anvil's footprint
    assert _full_density(rain, pr) == pytest.approx(3.912 / pr.units(1.0), rel=1e-6)


def test_add_rain_again_replaces_it(addon, scene):
    import bpy

    cloud = _add("nimbostratus", 5.0)
    for _ in range(2):
        assert bpy.ops.cloudgen.add_rain() == {"FINISHED"}
    names = [o.name for o in scene.objects if "Rain" in o.name]
    assert names == [f"{cloud.name} Rain"], names
    pr = addon.precipitation
    assert len([m for m in bpy.data.materials if m.name.startswith(pr.RAIN)]) == 1
    assert len([m for m in bpy.data.meshes if m.name.startswith(cloud.name + " Rain")]) == 1


def test_bad_rain_is_refused_with_its_range(addon, scene):
    import bpy

    pr = addon.precipitation
    _add("nimbostratus", -1.0)  # its base below the ground
    before = len(scene.objects)
    with pytest.raises(RuntimeError, match=r"rain top \(the cloud's base\) must be in .*Move .* up"):
        bpy.ops.cloudgen.add_rain()
    assert len(scene.objects) == before
    for kwargs, pattern in (({"visibility_km": 0.1}, r"rain visibility must be in \[0.5, 50\] km"),
                            ({"patchiness": 1.5}, r"rain patchiness must be in \[0, 1\]"),
                            ({"fill": 1.0}, r"rain fill must be in \[0, 0.99\]"),
                            ({"streaks": -0.1}, r"rain streaks must be in \[0, 1\]")):
        with pytest.raises(ValueError, match=pattern):
            pr.add_rain(scene, (0.0, 0.0), 10.0, 10.0, 3.0, **kwargs)
    assert len(scene.objects) == before
    bpy.context.view_layer.objects.active = None
    with pytest.raises(RuntimeError, match="not a cloud"):
        bpy.ops.cloudgen.add_rain()


def _render_rain(pr, scene, tmp_path, streaks):
    """The rain box (16 x 16 x 6 units, visibility 1 km, no curtains) seen side-on from 20
    units under a sun, over a black world, 64 x 48 at 256 spp: the grey level per pixel."""
    import bpy
    import numpy as np

    pr.add_rain(scene, (0.0, 0.0), 8.0, 8.0, 6.0, visibility_km=1.0, patchiness=0.0, fill=0.95,
                streaks=streaks)
    if scene.world is None or scene.world.name != "Black":
        world = bpy.data.worlds.new("Black")
        world.use_nodes = True
        world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
        scene.world = world
        sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
        sun.data.energy = 3.0
        sun.rotation_euler = (math.radians(60.0), 0.0, math.radians(30.0))
        scene.collection.objects.link(sun)
        cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
        cam.location = (0.0, -20.0, 3.0)
        cam.rotation_euler = (math.radians(90.0), 0.0, 0.0)
        cam.data.lens = 35.0
        scene.collection.objects.link(cam)
        scene.camera = cam
    scene.cycles.samples = 256
    scene.render.resolution_x, scene.render.resolution_y = 64, 48
    scene.render.image_settings.file_format = "OPEN_EXR"
    out = tmp_path / f"rain_{streaks}.exr"
    scene.render.filepath = str(out)
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(str(out))
    return np.array(img.pixels[:], dtype=np.float64).reshape(48, 64, 4)[..., :3].mean(axis=2)


def test_rain_renders_lit_and_streaked(addon, scene, tmp_path):
    """Lit: the middle of the box's picture has a mean above 0.01. Streaked: the columns' means
    there, high-passed (second differences), vary at least 1.5 times as much as the same
    render's with streaks 0 (whose variation is the sampling noise and the box's shading)."""
    import numpy as np

    rough = {}
    for streaks in (0.0, 1.0):
        px = _render_rain(addon.precipitation, scene, tmp_path, streaks)
        assert np.isfinite(px).all(), streaks
        core = px[12:36, 20:44]  # the box spans x in [-8, 8] 12..28 units away: its middle
        assert core.mean() > 0.01, (streaks, core.mean())
        cols = core.mean(axis=0)
        rough[streaks] = float(np.diff(cols, 2).std() / cols.mean())
    print(f"rain: column roughness without streaks {rough[0.0]:.4f}, with {rough[1.0]:.4f}")
    assert rough[1.0] >= 1.5 * rough[0.0], rough
