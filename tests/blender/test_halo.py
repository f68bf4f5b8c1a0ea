"""The ice veils' 22° halo (addon/volume_material.py): an emission term that Cycles' phase
functions cannot make. Rendered: a camera at the centre of a thin emitting sphere looking
straight at the sun; the radiance of each pixel on the centre row against the model
density * E * HALO_PEAK_PER_SR * halo * lobe(theta) * (path in the sphere), per channel. And the halo
follows the scene's sun lamp (point_halos), is masked with its layer's ring, and is absent
from looks without "halo". And the veil's own scattering, by the same set-up: the
Fournier-Forand phase of ice (4.3+)."""
import math
import pathlib
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

DENSITY = 0.02  # per unit: the sphere (radius 1) is optically thin, attenuation 1 %
SIZE = 181
# of the model's peak, per 0.5° ring of pixels. Measured at 64 spp: the worst ring is the one
# across the sharp inner edge (21.5-22°; blue 22-23°), red / green / blue 3.6 / 3.6 / 3.0 % in
# 4.5 and 5.5 / 4.2 / 4.3 % in 5.0 (the model averaged over each pixel; at the pixels' centres
# 7.1 / 7.9 / 5.8 % and 9.0 / 8.6 / 4.7 %: the CI failed on 5.0 first); Blender 5's volume
# emission is a stochastic estimate per sample (at 16 spp its rings scattered 12 % about the
# model, both ways), 4.x integrates it along each ray
TOLERANCE_4, TOLERANCE_5 = 0.08, 0.10
# where a channel's rings of pixels 0.25° wide first reach half the peak, against the model's inner
# half-maximum (radius - HALO_INNER_DEG * sqrt(ln 2)); the inner edge's slope puts 10 % of noise at 0.1°
EDGE_DEG = 0.3


def _volume_material():
    import render_cloud

    return render_cloud._addon_file("volume_material")


def _lobe(vm, theta_deg, channel):
    """The model's ring profile for `channel` (0 red, 1 green, 2 blue) at the angles `theta_deg`
    (a numpy array), written out here apart from the add-on's nodes: a Gaussian of
    HALO_INNER_DEG inside the channel's radius; outside, one of HALO_OUTER_DEG blended with one
    of HALO_SKIRT_DEG (HALO_SKIRT_SHARE of the way)."""
    import numpy as np

    d = theta_deg - vm.HALO_RADII_DEG[channel]
    inside = np.exp(-((d / vm.HALO_INNER_DEG) ** 2))
    core, skirt = np.exp(-((d / vm.HALO_OUTER_DEG) ** 2)), np.exp(-((d / vm.HALO_SKIRT_DEG) ** 2))
    return np.where(d < 0, inside, (1.0 - vm.HALO_SKIRT_SHARE) * core + vm.HALO_SKIRT_SHARE * skirt)


def _pixel_angles(sub):
    """The angle off the axis (degrees) at sub x sub points spread over each pixel, shaped
    (SIZE, sub, SIZE, sub): a 90° camera, tan of the angle = u per pixel coordinate."""
    import numpy as np

    u = (np.arange(SIZE)[:, None] + (np.arange(sub) + 0.5)[None, :] / sub).ravel() / SIZE * 2.0 - 1.0
    return np.degrees(np.arctan(np.hypot(u[None, :], u[:, None]))).reshape(SIZE, sub, SIZE, sub)


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


def _render_from_centre(scene, path):
    """Render SIZE x SIZE pixels at 64 spp, single scattering only (no volume bounces), from a
    90° camera at the origin looking down -Z, to the EXR `path`; its RGBA as float64, bottom row
    first."""
    import bpy
    import numpy as np

    cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
    cam.data.sensor_fit, cam.data.sensor_width, cam.data.lens = "HORIZONTAL", 36.0, 18.0  # 90° across
    cam.data.clip_start = 1e-3
    scene.collection.objects.link(cam)
    scene.camera = cam
    r = scene.render
    r.resolution_x = r.resolution_y = SIZE
    r.resolution_percentage = 100
    r.filter_size = 0.01
    scene.cycles.samples = 64
    scene.cycles.volume_bounces = 0
    r.image_settings.file_format = "OPEN_EXR"
    r.filepath = str(path)
    bpy.ops.render.render(write_still=True)
    return np.array(bpy.data.images.load(str(path)).pixels[:], dtype=np.float64).reshape(SIZE, SIZE, 4)


def test_halo_ring_matches_the_model(empty_scene, tmp_path):
    """The mean radiance of every ring of pixels 0.5° wide from 14° to 34° off the sun within
    TOLERANCE_4 (5: TOLERANCE_5) of the model's peak of the model's mean over the same pixels
    (filter width 0.01, 64 samples; the path through a 128 x 64 UV sphere is 1 within
    0.1 %), per colour channel; each channel's inner edge (half the peak) within EDGE_DEG of the
    model's (HALO_RADII_DEG); red over blue more than 2x just inside the red radius; the mean
    inside 20° under 1 % of the peak."""
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
    pixels = _render_from_centre(scene, tmp_path / "halo.exr")
    peak = DENSITY * vm.HALO_PEAK_PER_SR * (1.0 - DENSITY / 2.0)
    theta = _pixel_angles(1).reshape(SIZE, SIZE)  # at the pixels' centres
    fine = _pixel_angles(4)  # the model is averaged over each pixel, as Cycles renders it: the
    # inner edge (0.5°) is as sharp as a pixel (0.5°); at the pixels' centres rings across it read 8 % off
    tolerance = TOLERANCE_5 if bpy.app.version >= (5, 0, 0) else TOLERANCE_4
    for channel, name in enumerate(("red", "green", "blue")):
        px = pixels[..., channel]
        model = _lobe(vm, fine, channel).mean(axis=(1, 3))
        worst = (0.0, None)
        for lo in np.arange(14.0, 34.0, 0.5):  # rings of pixels 0.5° wide: their means (Blender 5's
            ring = (theta >= lo) & (theta < lo + 0.5)  # volume emission is a noisy estimate per pixel)
            err = abs(px[ring].mean() - peak * model[ring].mean()) / peak
            worst = max(worst, (err, f"{name}, {lo:.1f}-{lo + 0.5:.1f}°: {px[ring].mean() / peak:.3f} of the "
                                     f"peak, model {model[ring].mean():.3f}, {ring.sum()} pixels"))
        assert worst[0] < tolerance, worst[1]
        # the inner edge (half the peak) where the channel's radius puts it: the peak itself is flat
        # outside (the lobe is above 0.95 for 0.7° beyond the radius), so its argmax is not a test
        want = vm.HALO_RADII_DEG[channel] - vm.HALO_INNER_DEG * math.sqrt(math.log(2.0))
        edge = next(a + 0.125 for a in np.arange(18.0, 24.0, 0.0625)
                    if px[(theta >= a) & (theta < a + 0.25)].mean() >= 0.5 * peak)
        print(f"[ figures ] {name}: inner edge {edge:.2f}° (model {want:.2f}°); worst ring {worst[1]}")
        assert abs(edge - want) < EDGE_DEG, f"{name} inner edge at {edge:.2f}°, want {want:.2f}° (±{EDGE_DEG})"
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


def _fournier_forand(theta_deg, backscatter, ior):
    """Fournier and Forand's phase function (1/sr) in the form of Mobley et al. (2002), written
    out here apart from Cycles: the Junge exponent's v is solved from the backscatter fraction
    by bisection (B falls as v rises), not from a closed form."""
    import numpy as np

    def delta(theta):
        return 4.0 * np.sin(theta / 2.0) ** 2 / (3.0 * (ior - 1.0) ** 2)

    def back_fraction(v, d90):
        return 1.0 - (1.0 - d90 ** (v + 1.0) - 0.5 * (1.0 - d90 ** v)) / ((1.0 - d90) * d90 ** v)

    d90, d180 = delta(math.pi / 2.0), delta(math.pi)
    lo, hi = -3.0, -1e-9
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if back_fraction(mid, d90) > backscatter else (lo, mid)
    v = 0.5 * (lo + hi)
    theta = np.radians(theta_deg)
    d = delta(theta)
    d = np.where(np.abs(d - 1.0) < 1e-4, 1.0 + 1e-4, d)  # the form is 0/0 at delta 1 (about 31° here)
    s2 = np.sin(theta / 2.0) ** 2
    main = (v * (1.0 - d) - (1.0 - d ** v) + (d * (1.0 - d ** v) - v * (1.0 - d)) / s2) \
        / (4.0 * math.pi * (1.0 - d) ** 2 * d ** v)
    return main + (1.0 - d180 ** v) / (16.0 * math.pi * (d180 - 1.0) * d180 ** v) * (3.0 * np.cos(theta) ** 2 - 1.0)


def _henyey_greenstein(theta_deg, g):
    import numpy as np

    return (1.0 - g * g) / (4.0 * math.pi * (1.0 + g * g - 2.0 * g * np.cos(np.radians(theta_deg))) ** 1.5)


# of the model, per ring of pixels 2° wide from 4° to 50° off the sun (64 spp; single scattering
# in an optically thin sphere). Measured (Fournier-Forand alone): worst ring 1.5 % (4.5, 8-10°),
# 0.3 % (5.0, 48-50°); Fournier-Forand with B 0.03 instead of 0.02 is 32 % off at 20°, and
# without the side lobe the 48-50° ring is 40 % under the mix
PHASE_TOLERANCE = 0.04


def test_ice_veil_scatters_with_fournier_forand_and_a_side_lobe(empty_scene, tmp_path):
    """The ice veils' phase (a look with "backscatter" and "side_scatter" s, phase AUTO; Blender
    4.3+): the radiance of a thin scattering sphere around a camera looking at the sun, ring by
    ring, against density * E * p(theta), p = (1 - s) Fournier-Forand (ICE_IOR, the
    cirrostratus's backscatter) + s Henyey-Greenstein (ICE_SIDE_G), within PHASE_TOLERANCE of
    the model's mean over each ring (green channel)."""
    import bpy
    import cloudgen_native as cn
    import numpy as np

    vm = _volume_material()
    if "FOURNIER_FORAND" not in vm.scatter_phases():
        pytest.skip(f"Blender {bpy.app.version_string}: no Fournier-Forand phase (HG stands in)")
    look = dict(cn.presets()["cirrostratus"]["material"], color=(1.0, 1.0, 1.0))
    look.pop("halo")
    scene = empty_scene
    world = bpy.data.worlds.new("Black")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world
    bpy.ops.mesh.primitive_uv_sphere_add(segments=128, ring_count=64, radius=1.0)
    mat = bpy.data.materials.new("Ice")
    volume = vm.volume_material(mat, look, step_rate=0.05)
    assert volume.phase == "FOURNIER_FORAND", volume.phase
    value = mat.node_tree.nodes.new("ShaderNodeValue")
    value.outputs[0].default_value = DENSITY
    vm.link_density(mat, value.outputs[0])
    bpy.context.active_object.data.materials.append(mat)
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy, sun.data.angle = 1.0, 0.0
    sun.rotation_euler = (math.pi, 0.0, 0.0)  # light travels along +Z: the sun straight ahead
    scene.collection.objects.link(sun)
    pixels = _render_from_centre(scene, tmp_path / "ice.exr")[..., 1]
    theta = _pixel_angles(1).reshape(SIZE, SIZE)
    share, fine = look["side_scatter"], _pixel_angles(4)
    phase = (1.0 - share) * _fournier_forand(fine, look["backscatter"], vm.ICE_IOR) \
        + share * _henyey_greenstein(fine, vm.ICE_SIDE_G)
    model = DENSITY * (1.0 - DENSITY) * phase.mean(axis=(1, 3))
    rows = []
    for lo in np.arange(4.0, 50.0, 2.0):
        ring = (theta >= lo) & (theta < lo + 2.0)
        got, want = pixels[ring].mean(), model[ring].mean()
        rows.append((abs(got / want - 1.0), f"{lo:.0f}-{lo + 2:.0f}°: {got:.4g} against {want:.4g}"))
    worst = max(rows)
    print("[ figures ] " + "; ".join(text for _, text in rows[::4]) + f"; worst {worst[1]}, {worst[0]:.1%}")
    assert worst[0] < PHASE_TOLERANCE, \
        f"ring {worst[1]} ({worst[0]:.1%} off; B {look['backscatter']}, IOR {vm.ICE_IOR}, side {share})"
