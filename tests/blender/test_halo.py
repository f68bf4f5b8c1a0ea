"""The ice veils' 22° halo (addon/volume_material.py): an emission term that Cycles' phase
functions cannot make. Rendered: a camera at the centre of a thin emitting sphere looking
straight at the sun; the radiance of each pixel on the centre row against the model
density * E * HALO_PEAK_PER_SR * halo * lobe(theta) * (path in the sphere), per channel. And the halo
follows the scene's sun lamp (point_halos), is masked with its layer's ring, and is absent
from looks without "halo"."""
import math
import pathlib
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

DENSITY = 0.02  # per unit: the sphere (radius 1) is optically thin, attenuation 1 %
SIZE = 181
# of the model's peak, per 0.5° ring of pixels. Measured at 64 spp: the worst ring is the one
# across the sharp inner edge (21.5-22°), 5.1 % in 4.5 and 5.9 % in 5.0; Blender 5's volume
# emission is a stochastic estimate per sample (at 16 spp its rings scattered 12 % about the
# model, both ways), 4.x integrates it along each ray
TOLERANCE_4, TOLERANCE_5 = 0.08, 0.10


def _volume_material():
    import render_cloud

    return render_cloud._addon_file("volume_material")


def _lobe(vm, theta_deg, channel):
    """The model's ring profile for `channel` (0 red, 1 green, 2 blue), written out here apart
    from vm.halo_lobe: a Gaussian of HALO_INNER_DEG inside the channel's radius; outside, one of
    HALO_OUTER_DEG blended with one of HALO_SKIRT_DEG (HALO_SKIRT_SHARE of the way)."""
    d = theta_deg - vm.HALO_RADII_DEG[channel]
    if d < 0:
        return math.exp(-((d / vm.HALO_INNER_DEG) ** 2))
    core, skirt = math.exp(-((d / vm.HALO_OUTER_DEG) ** 2)), math.exp(-((d / vm.HALO_SKIRT_DEG) ** 2))
    return (1.0 - vm.HALO_SKIRT_SHARE) * core + vm.HALO_SKIRT_SHARE * skirt


def _halo_sphere(scene, vm, halo=1.0):
    import bpy

    bpy.ops.mesh.primitive_uv_sphere_add(segments=128, ring_count=64, radius=1.0)
    sphere = bpy.context.active_object
    mat = bpy.data.materials.new("Veil")
    volume = vm.volume_material(mat, {"color": (0.0, 0.0, 0.0), "halo": halo}, phase="HG", step_rate=0.05)
    value = mat.node_tree.nodes.new("ShaderNodeValue")
    value.outputs[0].default_value = DENSITY
    vm.link_density(mat, value.outputs[0])
    sphere.data.materials.append(mat)
    return mat, volume


def test_halo_ring_matches_the_model(empty_scene, tmp_path):
    """The mean radiance of every ring of pixels 0.5° wide from 14° to 34° off the sun within
    TOLERANCE_4 (5: TOLERANCE_5) of the model's peak of the model's mean over the same pixels
    (filter width 0.01, 64 samples; the path through a 128 x 64 UV sphere is 1 within
    0.1 %), per colour channel; the brightest 0.25° ring within 0.6° of the channel's radius
    (HALO_RADII_DEG); red over blue more than 2x just inside the red radius; the mean inside 20°
    under 1 % of the peak."""
    import bpy
    import numpy as np

    vm = _volume_material()
    scene = empty_scene
    world = bpy.data.worlds.new("Black")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world
    mat, _ = _halo_sphere(scene, vm)
    assert vm.set_halo_sun(mat, (0.0, 0.0, -1.0), (1.0, 1.0, 1.0))  # the sun straight ahead
    cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
    cam.data.sensor_fit, cam.data.sensor_width, cam.data.lens = "HORIZONTAL", 36.0, 18.0  # 90° across
    cam.data.clip_start = 1e-3
    scene.collection.objects.link(cam)
    scene.camera = cam  # at the origin looking down -Z
    r = scene.render
    r.resolution_x = r.resolution_y = SIZE
    r.resolution_percentage = 100
    r.filter_size = 0.01
    scene.cycles.samples = 64
    scene.cycles.volume_bounces = 0
    r.image_settings.file_format = "OPEN_EXR"
    out = tmp_path / "halo.exr"
    r.filepath = str(out)
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(str(out))
    pixels = np.array(img.pixels[:], dtype=np.float64).reshape(SIZE, SIZE, 4)
    peak = DENSITY * vm.HALO_PEAK_PER_SR * (1.0 - DENSITY / 2.0)
    u = (np.arange(SIZE) + 0.5) / SIZE * 2.0 - 1.0  # tan of the angle off the axis, per pixel
    theta = np.degrees(np.arctan(np.hypot(u[None, :], u[:, None])))
    tolerance = TOLERANCE_5 if bpy.app.version >= (5, 0, 0) else TOLERANCE_4
    for channel, name in enumerate(("red", "green", "blue")):
        px = pixels[..., channel]
        model = np.vectorize(lambda t, c=channel: _lobe(vm, t, c))(theta)
        worst = (0.0, None)
        for lo in np.arange(14.0, 34.0, 0.5):  # rings of pixels 0.5° wide: their means (Blender 5's
            ring = (theta >= lo) & (theta < lo + 0.5)  # volume emission is a noisy estimate per pixel)
            err = abs(px[ring].mean() - peak * model[ring].mean()) / peak
            worst = max(worst, (err, f"{name}, {lo:.1f}-{lo + 0.5:.1f}°: {px[ring].mean() / peak:.3f} of the "
                                     f"peak, model {model[ring].mean():.3f}, {ring.sum()} pixels"))
        assert worst[0] < tolerance, worst[1]
        radius = vm.HALO_RADII_DEG[channel]
        brightest = max(np.arange(14.0, 34.0, 0.25), key=lambda a: px[(theta >= a) & (theta < a + 0.25)].mean())
        assert abs(brightest + 0.125 - radius) < 0.6, f"{name} ring peaks at {brightest + 0.125:.2f}°, not {radius}°"
    # the inner edge is red: 0.25° inside the red radius, red over blue more than 2x
    edge = (theta >= vm.HALO_RADII_DEG[0] - 0.375) & (theta < vm.HALO_RADII_DEG[0] - 0.125)
    red, blue = pixels[..., 0][edge].mean(), pixels[..., 2][edge].mean()
    assert red > 2.0 * blue, f"the inner edge is not red: red {red:.3g}, blue {blue:.3g}"
    px = pixels[..., 0]
    inside = px[theta < 20.0].mean()
    assert inside < 1e-2 * peak, f"light inside the ring: {inside:.3g} (peak {peak:.3g})"


def test_halo_follows_the_scene_sun(empty_scene):
    """point_halos: the direction is the lamp's +Z axis (within 1e-6), the irradiance its
    strength times its colour; without a sun lamp the halo goes dark; a look without "halo"
    gets no halo nodes, and the count says so."""
    import bpy

    vm = _volume_material()
    scene = empty_scene
    mat, _ = _halo_sphere(scene, vm)
    plain = bpy.data.materials.new("Plain")
    vm.volume_material(plain, {"color": (1.0, 1.0, 1.0)})
    assert vm.HALO_SUN not in plain.node_tree.nodes
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    scene.collection.objects.link(sun)
    sun.rotation_euler = (math.radians(30.0), 0.0, math.radians(40.0))
    sun.data.energy, sun.data.color = 4.0, (1.0, 0.9, 0.8)
    assert vm.point_halos(scene) == 1
    nodes = mat.node_tree.nodes
    got = [nodes[vm.HALO_SUN].inputs[a].default_value for a in "XYZ"]
    want = list(sun.rotation_euler.to_matrix().col[2])
    assert max(abs(a - b) for a, b in zip(got, want)) < 1e-6, (got, want)
    assert list(nodes[vm.HALO_IRRADIANCE].outputs[0].default_value)[:3] == pytest.approx([4.0, 3.6, 3.2])
    sun.hide_render = True
    vm.point_halos(scene)
    assert list(nodes[vm.HALO_IRRADIANCE].outputs[0].default_value)[:3] == [0.0, 0.0, 0.0]


def test_ring_mask_masks_the_halo_too(empty_scene):
    """A nested layer level's ring mask multiplies the halo's density (else each level would
    add its halo over the inner levels' area as well)."""
    import bpy
    import gallery_scene

    vm = _volume_material()
    mat = bpy.data.materials.new("Level")
    vm.volume_material(mat, {"color": (1.0, 1.0, 1.0), "halo": 1.0}, grid="density")
    gallery_scene.ring_mask(mat, 2.0, 4.0)
    halo_density = mat.node_tree.nodes[vm.HALO_DENSITY]
    assert halo_density.inputs[1].is_linked
    assert halo_density.inputs[0].is_linked  # the grid
    # one node reads the grid: a Volume Scatter's own, shared with the halo (a Principled Volume
    # reads it through its Density Attribute, and the node is the halo's)
    grids = [n for n in mat.node_tree.nodes if n.bl_idname == "ShaderNodeAttribute"]
    assert len(grids) == 1 and grids[0].attribute_name == "density", [(n.name, n.attribute_name) for n in grids]
