"""A landscape for clouds: rolling ground to the horizon and the haze over it (aerial
perspective). Used by the add-on's "Cloud Sky & Sun" (its Landscape option), by
scripts/render_cloud.py and scripts/gallery.py (loaded by its path: bpy and bmesh only, no
imports of the add-on's own modules).

Why: a cloud over a flat, sharp-edged plane under a clear sky reads as a toy — the horizon is
a razor line, a layer's far edge stops in mid-air, nothing gives a scale. Real air holds haze:
far hills, the far part of a deck and the horizon fade into its colour, which is how
photographs show distance. Everything here is Blender's own data (a grid mesh with a Displace
modifier and a Clouds texture, a Principled BSDF, a box with a Volume Scatter) that an artist
can edit, and that renders in any Blender with Cycles — no add-on needed.

Scale: the cloud presets are sized at METRES_PER_UNIT metres per scene unit (the cumulus
is 1 km wide), and so is this landscape:
- ground: a square TERRAIN_HALF_KM in half-width around `centre`, flat within CLEAR_KM of it
  (the camera stands there) and rising into hills of up to HILL_KM beyond RISE_KM, features
  FEATURE_KM across; albedo 0.04-0.10, vegetation and fields;
- haze: a homogeneous box over the ground up to `haze_top` (default HAZE_TOP_KM), extinction
  from the meteorological visibility (Koschmieder: beta = 3.912 / V), scattering only, mildly
  forward-peaked (HAZE_ANISOTROPY 0.3: aerosols' 0.7 plus the air's near-isotropic
  scattering; at 0.6 the haze, seen with the sun behind the camera, came out darker than the
  sky it should fade into). A homogeneous volume costs Cycles no stepping; keep its top below
  the clouds (a cloud inside the haze makes the haze heterogeneous along those rays and
  slows them).
"""
import math

import bmesh
import bpy

METRES_PER_UNIT = 250.0
TERRAIN_HALF_KM = 50.0
CLEAR_KM = 0.5
RISE_KM = 6.0
HILL_KM = 0.25
FEATURE_KM = 2.5
GRID_CELLS = 400  # per side: 250 m cells at the default size
HAZE_TOP_KM = 0.8
VISIBILITY_KM = 80.0  # 40 until 2026-11: the haze outshone the clouds' sunlit flanks (sky_light.exposure_for)
VISIBILITY_MIN_KM, VISIBILITY_MAX_KM = 0.1, 1000.0
HAZE_ANISOTROPY = 0.3
HAZE_ALBEDO = 0.95
GROUND = "Cloud Ground"
HAZE = "Cloud Haze"
HILLS_TEXTURE = "Cloud Hills"
CLEAR_GROUP = "hills"


def units(km: float) -> float:
    return km * 1000.0 / METRES_PER_UNIT


def koschmieder(visibility_km: float) -> float:
    """Extinction per scene unit for a visibility (km): Koschmieder's 3.912 / V (2 % contrast
    left at the visibility distance). Unchecked: haze_extinction and the rain's check."""
    return 3.912 / units(visibility_km)


def haze_extinction(visibility_km: float) -> float:
    """koschmieder() of a meteorological visibility in [VISIBILITY_MIN_KM, VISIBILITY_MAX_KM]."""
    if not (VISIBILITY_MIN_KM <= visibility_km <= VISIBILITY_MAX_KM):
        raise ValueError(f"haze visibility must be in [{VISIBILITY_MIN_KM:g}, {VISIBILITY_MAX_KM:g}] km, "
                         f"not {visibility_km}")
    return koschmieder(visibility_km)


def hill_weight(distance: float) -> float:
    """How much of the hills' height applies at this horizontal distance (scene units) from
    the clear centre: 0 within CLEAR_KM, 1 beyond RISE_KM, a smoothstep between."""
    t = (distance - units(CLEAR_KM)) / (units(RISE_KM) - units(CLEAR_KM))
    t = min(max(t, 0.0), 1.0)
    return t * t * (3.0 - 2.0 * t)


def _ground_material():
    mat = bpy.data.materials.get(GROUND) or bpy.data.materials.new(GROUND)
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    coords = nt.nodes.new("ShaderNodeTexCoord")
    noise = nt.nodes.new("ShaderNodeTexNoise")  # patches of fields and woods, 0.5-2 km
    noise.inputs["Scale"].default_value = 1.0 / units(1.0)
    noise.inputs["Detail"].default_value = 6.0
    ramp = nt.nodes.new("ShaderNodeValToRGB")
    ramp.color_ramp.elements[0].position = 0.42
    ramp.color_ramp.elements[0].color = (0.045, 0.05, 0.04, 1.0)  # woods
    ramp.color_ramp.elements[1].position = 0.6
    ramp.color_ramp.elements[1].color = (0.10, 0.095, 0.08, 1.0)  # fields, dry grass
    bsdf = nt.nodes.new("ShaderNodeBsdfPrincipled")
    bsdf.inputs["Roughness"].default_value = 1.0
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    nt.links.new(coords.outputs["Object"], noise.inputs["Vector"])
    nt.links.new(noise.outputs["Fac"], ramp.inputs["Fac"])
    nt.links.new(ramp.outputs["Color"], bsdf.inputs["Base Color"])
    nt.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    for i, node in enumerate((coords, noise, ramp, bsdf, out)):
        node.location = (-800 + 250 * i, 0)
    return mat


def _grid_mesh(name: str, half: float, centre, cells: int):
    """A square grid `2 half` wide with `cells` quads a side, its vertex group CLEAR_GROUP
    weighted by hill_weight of the distance from `centre` (the mesh is at the origin)."""
    mesh = bpy.data.meshes.new(name)
    bm = bmesh.new()
    bmesh.ops.create_grid(bm, x_segments=cells, y_segments=cells, size=half)
    bm.to_mesh(mesh)
    bm.free()
    return mesh


def _check_hill_km(hill_km: float) -> float:
    if not (0.0 <= hill_km <= 5.0):
        raise ValueError(f"hill height must be in [0, 5] km, not {hill_km}")
    return float(hill_km)


def make_ground(scene, centre=(0.0, 0.0), hill_km=HILL_KM):
    """The ground object GROUND around `centre` (x, y, scene units): a grid with a Displace
    modifier (Clouds texture, strength `hill_km`, in [0, 5] km: the highest tops rise to about
    half of it) weighted to 0 near the centre. Replaced on a second call (another centre)."""
    hill_km = _check_hill_km(hill_km)
    old = bpy.data.objects.get(GROUND)
    if old is not None:
        mesh = old.data if old.type == "MESH" else None
        bpy.data.objects.remove(old)
        if mesh is not None and mesh.users == 0:
            bpy.data.meshes.remove(mesh)
    half = units(TERRAIN_HALF_KM)
    mesh = _grid_mesh(GROUND, half, centre, GRID_CELLS)
    obj = bpy.data.objects.new(GROUND, mesh)
    obj.location = (float(centre[0]), float(centre[1]), 0.0)
    group = obj.vertex_groups.new(name=CLEAR_GROUP)
    for v in mesh.vertices:
        group.add([v.index], hill_weight(math.hypot(v.co.x, v.co.y)), "REPLACE")
    tex = bpy.data.textures.get(HILLS_TEXTURE) or bpy.data.textures.new(HILLS_TEXTURE, "CLOUDS")
    tex.noise_scale = units(FEATURE_KM)
    tex.noise_depth = 3
    mod = obj.modifiers.new("Hills", "DISPLACE")
    mod.texture = tex
    mod.texture_coords = "GLOBAL"
    mod.direction = "Z"
    mod.vertex_group = CLEAR_GROUP
    mod.mid_level = 0.3  # Clouds spans about 0.2-0.8: mostly rising, with some valleys
    mod.strength = units(hill_km)
    mesh.materials.append(_ground_material())
    for poly in mesh.polygons:
        poly.use_smooth = True
    scene.collection.objects.link(obj)
    return obj


def _haze_material(extinction: float):
    mat = bpy.data.materials.get(HAZE) or bpy.data.materials.new(HAZE)
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    scatter = nt.nodes.new("ShaderNodeVolumeScatter")
    scatter.inputs["Color"].default_value = (HAZE_ALBEDO, HAZE_ALBEDO, HAZE_ALBEDO, 1.0)
    scatter.inputs["Density"].default_value = extinction
    scatter.inputs["Anisotropy"].default_value = HAZE_ANISOTROPY
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    nt.links.new(scatter.outputs["Volume"], out.inputs["Volume"])
    scatter.location, out.location = (0, 0), (250, 0)
    return mat


def make_haze(scene, centre=(0.0, 0.0), top=None, visibility_km=VISIBILITY_KM, hill_km=HILL_KM):
    """The haze box HAZE: as wide as the ground, from below the ground's lowest point (its
    valleys reach -0.3 hill_km) to `top` (scene units; default HAZE_TOP_KM). Replaced on a
    second call."""
    top = units(HAZE_TOP_KM) if top is None else float(top)
    if not (0.0 < top <= units(20.0)):
        raise ValueError(f"haze top must be in (0, {units(20.0):g}] scene units, not {top}")
    old = bpy.data.objects.get(HAZE)
    if old is not None:
        mesh = old.data if old.type == "MESH" else None
        bpy.data.objects.remove(old)
        if mesh is not None and mesh.users == 0:
            bpy.data.meshes.remove(mesh)
    bottom = -units(max(_check_hill_km(hill_km), HILL_KM))
    mesh = bpy.data.meshes.new(HAZE)
    bm = bmesh.new()
    bmesh.ops.create_cube(bm, size=1.0)
    bm.to_mesh(mesh)
    bm.free()
    obj = bpy.data.objects.new(HAZE, mesh)
    half = units(TERRAIN_HALF_KM)
    obj.location = (float(centre[0]), float(centre[1]), (top + bottom) / 2)
    obj.scale = (2 * half, 2 * half, top - bottom)
    mesh.materials.append(_haze_material(haze_extinction(visibility_km)))
    scene.collection.objects.link(obj)
    return obj


def landscape(scene, centre=(0.0, 0.0), haze_top=None, visibility_km=VISIBILITY_KM, hill_km=HILL_KM):
    """Ground and haze around `centre`; returns (ground, haze). hill_km: the hills' height
    scale (HILL_KM by default; the gallery raises it under a low stratus so that the far hill
    tops vanish into its base, the cue that tells a low sheet from a high one)."""
    return (make_ground(scene, centre, hill_km),
            make_haze(scene, centre, haze_top, visibility_km, hill_km))
