"""Rain under a cloud: the shaft under a cumulonimbus, the veils under a nimbostratus. Used by
the add-on's "Add Rain" and by scripts/gallery.py (loaded by its path, as is its one sibling,
addon/landscape.py: the scale and Koschmieder's law).

Why: the two rain clouds are told apart from their dry look-alikes by what falls out of them.
A nimbostratus seen from the ground is a grey sheet like a stratus or an altostratus; what
names it is the rain reaching the ground and hiding the distance. A cumulonimbus without the
dark shaft under its tower reads as a big cumulus. The blind reviews named both cues: "no
rain shaft" (the storm), overcasts named as one another (docs/gallery/README.md).

The rain is Blender's own data an artist can edit: a box from the ground (z = 0) up to the
cloud's base, with a Principled Volume whose density is
    extinction(V) * streaks * curtains * footprint
- extinction from the visibility in the rain, Koschmieder's 3.912 / V (as the haze in
  addon/landscape.py): moderate rain about 4 km, heavy rain 1-2 km;
- streaks: a noise STREAK_KM wide and STREAK_LENGTH_KM tall, sheared by `slant` (wind drift:
  horizontal metres per metre of fall), mapped to 1 -+ STREAK_DEPTH * `streaks` (mean about 1;
  streaks 0: none): the fall streaks seen from afar;
- curtains: a noise CURTAIN_KM across, mixed in by `patchiness` (0: an even veil, 1: shafts
  with dry air between);
- footprint: 1 inside `fill` of the box's half-widths (an ellipse), fading to 0 at its edge.
  The box is the cloud's own footprint just above its base, measured on the model (rain_box).
Scattering grey (RAIN_ALBEDO), forward (RAIN_ANISOTROPY: drops are large). The material's step
rate puts Cycles' steps a third of a streak apart (a procedural volume is stepped at a tenth of
its box's mean size times the rate; a rain box is wide and low, so that step is far too long).
"""
import importlib
import importlib.util
import pathlib
import sys

import bmesh
import bpy
import numpy as np


def _sibling(name):
    """The add-on's module `name`: from the package, or (loaded by its path, as
    scripts/render_cloud.py's _addon_file does) the sibling file, once, under the same key."""
    if __package__:
        return importlib.import_module(f"{__package__}.{name}")
    key = f"cloudgen_addon_{name}"
    if key not in sys.modules:
        spec = importlib.util.spec_from_file_location(key, pathlib.Path(__file__).with_name(f"{name}.py"))
        sys.modules[key] = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(sys.modules[key])
    return sys.modules[key]


landscape = _sibling("landscape")
_math = _sibling("volume_material").math_node

units = landscape.units
RAIN = "Cloud Rain"
EXTINCTION_NODE = "Rain Extinction"
STREAK_KM = 0.3
STREAK_LENGTH_KM = 3.0
STREAK_DEPTH = 0.75
CURTAIN_KM = 4.0
RAIN_ALBEDO = 0.9
RAIN_ANISOTROPY = 0.4
VISIBILITY_KM = (0.5, 50.0)  # accepted range
DEFAULT_VISIBILITY_KM = 4.0
# each rain cloud's rain: visibility in it (km), patchiness, and how much of its footprint is
# full (fill): under a nimbostratus a wide veil, under a cumulonimbus a heavy shaft
LOOKS = {"nimbostratus": {"visibility_km": 1.5, "patchiness": 0.9, "fill": 0.9},
         "cumulonimbus": {"visibility_km": 1.5, "patchiness": 0.25, "fill": 0.45}}
DEFAULT_LOOK = {"visibility_km": DEFAULT_VISIBILITY_KM, "patchiness": 0.5, "fill": 0.6}
FOOTPRINT_SAMPLES = 65  # per side: the grid rain_box measures the cloud's footprint on
FOOTPRINT_ABOVE_BASE = 0.05  # ... at this fraction of the box's height above the cloud's base


def rain_extinction(visibility_km: float) -> float:
    """Extinction per scene unit for the visibility in the rain (km): 3.912 / V."""
    lo, hi = VISIBILITY_KM
    if not (lo <= visibility_km <= hi):
        raise ValueError(f"rain visibility must be in [{lo:g}, {hi:g}] km, not {visibility_km}")
    return landscape.koschmieder(visibility_km)


def footprint(values, density):
    """Half-widths (x, y), scene units, of the cloud's footprint FOOTPRINT_ABOVE_BASE of its
    box above its base: the farthest of FOOTPRINT_SAMPLES² points across the box at that
    height where `density` (cloudgen_native.density: the model itself) is positive, so a
    storm rains under its tower, not its anvil, and a layer over its box. Exact to a grid step
    (the box / (FOOTPRINT_SAMPLES - 1)). ValueError when no point there holds cloud."""
    bx, by, bz = values["box_size"]
    h = max(values.get("base_height", 0.0), 0.0) + FOOTPRINT_ABOVE_BASE
    u = np.linspace(-0.5, 0.5, FOOTPRINT_SAMPLES)
    x, y = np.meshgrid(u * bx, u * by, indexing="ij")
    pts = np.stack([x.ravel(), y.ravel(), np.full(x.size, (h - 0.5) * bz)], axis=1)
    inside = np.asarray(density(values, pts)) > 0.0
    if not inside.any():
        raise ValueError(f"the cloud has no density {FOOTPRINT_ABOVE_BASE:g} of its height above its base: "
                         "no rain to place")
    return float(np.abs(pts[inside, 0]).max()), float(np.abs(pts[inside, 1]).max())


def rain_box(values, centre, density, half=None):
    """(centre x, y, half x, half y, top), scene units, of the rain under a cloud of these
    parameters whose box is centred at `centre` (x, y, z): the top at the cloud's base (Base
    Height of the box; its bottom when it has none), the half-widths its footprint() there, or
    `half` when given (the gallery: a layer's rain over the whole landscape)."""
    bz = values["box_size"][2]
    top = centre[2] - bz / 2 + max(values.get("base_height", 0.0), 0.0) * bz
    hx, hy = (half, half) if half is not None else footprint(values, density)
    return centre[0], centre[1], max(hx, 1e-3), max(hy, 1e-3), top


def _check(name, value, lo, hi):
    if not (lo <= value <= hi):
        raise ValueError(f"rain {name} must be in [{lo:g}, {hi:g}], not {value}")
    return float(value)


def step_rate(half_x: float, half_y: float, height: float) -> float:
    """The material step rate that makes Cycles' step a third of a streak's width for a box
    of these half-widths and height (scene units)."""
    mean = (2 * half_x + 2 * half_y + height) / 3.0
    return min(1.0, max(1e-4, units(STREAK_KM) / 3.0 / (0.1 * mean)))


def _noise(nt, vector, scale_xyz, lo, hi, to_lo, to_hi):
    """Noise of `vector` scaled per axis, mapped from [lo, hi] to [to_lo, to_hi] (clamped, smooth)."""
    mapping = nt.nodes.new("ShaderNodeMapping")
    mapping.inputs["Scale"].default_value = scale_xyz
    nt.links.new(vector, mapping.inputs["Vector"])
    noise = nt.nodes.new("ShaderNodeTexNoise")
    noise.inputs["Scale"].default_value = 1.0
    noise.inputs["Detail"].default_value = 2.0
    nt.links.new(mapping.outputs["Vector"], noise.inputs["Vector"])
    ranged = nt.nodes.new("ShaderNodeMapRange")
    ranged.interpolation_type = "SMOOTHSTEP"
    ranged.clamp = True
    for key, v in (("From Min", lo), ("From Max", hi), ("To Min", to_lo), ("To Max", to_hi)):
        ranged.inputs[key].default_value = v
    nt.links.new(noise.outputs["Fac"], ranged.inputs["Value"])
    return ranged.outputs["Result"]


def rain_material(extinction, half_x, half_y, height, slant=0.15, patchiness=0.5, fill=0.6, streaks=1.0):
    """A new rain material: see the module's docstring."""
    mat = bpy.data.materials.new(RAIN)
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    coords = nt.nodes.new("ShaderNodeTexCoord")
    sep = nt.nodes.new("ShaderNodeSeparateXYZ")
    nt.links.new(coords.outputs["Object"], sep.inputs[0])
    # wind drift: x + slant * (height - z), the streaks lean downwind as they fall
    drift = _math(nt, "MULTIPLY", _math(nt, "SUBTRACT", height, sep.outputs["Z"]), slant)
    comb = nt.nodes.new("ShaderNodeCombineXYZ")
    nt.links.new(_math(nt, "ADD", sep.outputs["X"], drift), comb.inputs["X"])
    nt.links.new(sep.outputs["Y"], comb.inputs["Y"])
    nt.links.new(sep.outputs["Z"], comb.inputs["Z"])
    sheared = comb.outputs[0]
    w, length, c = units(STREAK_KM), units(STREAK_LENGTH_KM), units(CURTAIN_KM)
    depth = STREAK_DEPTH * streaks
    streaks = _noise(nt, sheared, (1 / w, 1 / w, 1 / length), 0.35, 0.65, 1.0 - depth, 1.0 + depth)
    curtain = _noise(nt, sheared, (1 / c, 1 / c, 1 / (4 * c)), 0.4, 0.6, 0.0, 2.0)
    curtains = _math(nt, "ADD", _math(nt, "MULTIPLY", curtain, patchiness), 1.0 - patchiness)
    # footprint: r = |(x / half_x, y / half_y)|, 1 inside fill, 0 at the edge
    rx = _math(nt, "DIVIDE", sep.outputs["X"], half_x)
    ry = _math(nt, "DIVIDE", sep.outputs["Y"], half_y)
    r = _math(nt, "SQRT", _math(nt, "ADD", _math(nt, "MULTIPLY", rx, rx), _math(nt, "MULTIPLY", ry, ry)))
    edge = nt.nodes.new("ShaderNodeMapRange")
    edge.interpolation_type = "SMOOTHSTEP"
    edge.clamp = True
    for key, v in (("From Min", fill), ("From Max", 1.0), ("To Min", 1.0), ("To Max", 0.0)):
        edge.inputs[key].default_value = v
    nt.links.new(r, edge.inputs["Value"])
    full = _math(nt, "MULTIPLY", edge.outputs["Result"], extinction)
    full.node.name = full.node.label = EXTINCTION_NODE  # its second input: 3.912 / V
    density = _math(nt, "MULTIPLY", _math(nt, "MULTIPLY", streaks, curtains), full)
    vol = nt.nodes.new("ShaderNodeVolumePrincipled")
    vol.inputs["Color"].default_value = (RAIN_ALBEDO, RAIN_ALBEDO, RAIN_ALBEDO, 1.0)
    vol.inputs["Anisotropy"].default_value = RAIN_ANISOTROPY
    nt.links.new(density, vol.inputs["Density"])
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    nt.links.new(vol.outputs["Volume"], out.inputs["Volume"])
    if hasattr(mat.cycles, "volume_step_rate"):  # Blender 5 renders volumes without steps
        mat.cycles.volume_step_rate = step_rate(half_x, half_y, height)
    if hasattr(mat.cycles, "homogeneous_volume"):
        mat.cycles.homogeneous_volume = False
    for i, node in enumerate(nt.nodes):
        node.location = (200 * (i % 8) - 800, -220 * (i // 8))
    return mat


def add_rain(scene, centre, half_x, half_y, top, visibility_km=DEFAULT_VISIBILITY_KM, slant=0.15,
             patchiness=0.5, fill=0.6, name=RAIN, rot_z=0.0, streaks=1.0):
    """The rain object `name` (replaced on a second call, with its mesh and material): a box
    `2 half_x` by `2 half_y` around `centre` (x, y, scene units), turned by rot_z about z,
    from the ground (z = 0) up to `top` (the cloud's base). Raises ValueError naming the
    parameter and its range."""
    if not (0.0 < top <= units(20.0)):
        raise ValueError(f"rain top (the cloud's base) must be in (0, {units(20.0):g}] scene units "
                         f"above the ground at z = 0, not {top}")
    half_x = _check("half width x", half_x, 1e-3, units(500.0))
    half_y = _check("half width y", half_y, 1e-3, units(500.0))
    slant = _check("slant", slant, 0.0, 2.0)
    patchiness = _check("patchiness", patchiness, 0.0, 1.0)
    fill = _check("fill", fill, 0.0, 0.99)
    streaks = _check("streaks", streaks, 0.0, 1.0)
    extinction = rain_extinction(visibility_km)
    old = bpy.data.objects.get(name)
    if old is not None:
        mesh = old.data if old.type == "MESH" else None
        mats = [m for m in getattr(mesh, "materials", []) if m is not None]
        bpy.data.objects.remove(old)
        if mesh is not None and mesh.users == 0:
            bpy.data.meshes.remove(mesh)
        for m in mats:
            if m.users == 0:
                bpy.data.materials.remove(m)
    mesh = bpy.data.meshes.new(name)
    bm = bmesh.new()
    bmesh.ops.create_cube(bm, size=1.0)
    for v in bm.verts:  # at real size (object coordinates are scene units), base at z = 0
        v.co.x *= 2 * half_x
        v.co.y *= 2 * half_y
        v.co.z = (v.co.z + 0.5) * top
    bm.to_mesh(mesh)
    bm.free()
    obj = bpy.data.objects.new(name, mesh)
    obj.location = (float(centre[0]), float(centre[1]), 0.0)
    obj.rotation_euler = (0.0, 0.0, float(rot_z))
    obj.display_type = "WIRE"
    mesh.materials.append(rain_material(extinction, half_x, half_y, top, slant, patchiness, fill, streaks))
    scene.collection.objects.link(obj)
    return obj
