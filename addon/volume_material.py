"""The one builder of a cloud's volume material: the procedural cloud's (nodes.py),
the baked VDB's (volume_object.py) and scripts/render_cloud.py's (procedural and --vdb).

bpy only, no imports of the add-on's own modules: render_cloud.py loads this file
by its path.

    volume = volume_material(mat, look)                    # procedural: link the density in
    nt.links.new(density_socket, volume.inputs["Density"])
    volume_material(mat, look, grid="density")             # a VDB: reads its grid

The shader, node "Cloud Volume" → "Material Output".Volume:
- phase "AUTO": where Cycles has them (4.3+) a Volume Scatter, with the Mie phase
  (cloud droplets, MIE_DIAMETER_UM), or for a look with "backscatter" (the ice veils)
  the Fournier-Forand phase with ice's ICE_IOR and that backscatter fraction; else
  Principled Volume (Henyey–Greenstein with the look's anisotropy); phase "HG":
  always Principled Volume.
- like: an existing volume node (the cloud's own "Cloud Volume") whose type,
  phase and unlinked input values are copied — a baked cloud looks as the
  procedural one, edits included.
- side scatter: a Fournier-Forand look with "side_scatter" s > 0 gets a second Volume Scatter
  (SIDE_NODE, Henyey-Greenstein of g ICE_SIDE_G) mixed in at s (MIX_NODE): the two share one
  density, fed through the Math node DENSITY_NODE; density_input() is where a density goes.
- grid: the volume's density comes from that grid, once. A Principled Volume
  multiplies Density by its Density Attribute, so the grid goes there with
  Density 1 (linking the grid into Density as well would square the density: a
  darker cloud); a Volume Scatter has no such attribute: an Attribute node
  "Density Grid" feeds Density.
- step rate: the look's "step_rate" (default DEFAULT_STEP_RATE) for a procedural
  material, 1 (the voxel size) for a grid; step_rate= wins.
- halo: a look with "halo" > 0 (the ice veils' presets) also emits the 22° halo of
  hexagonal ice crystals, which no phase function of Cycles has (HG, Fournier-Forand, Draine,
  Rayleigh and Mie all fall monotonically from the forward peak): single scattering of the
  sun, radiance per unit length = density * E_sun * HALO_PEAK_PER_SR * halo * lobe(theta),
  theta the angle between the view ray and the sun; per colour channel, lobe 1 at that
  channel's HALO_RADII_DEG (ice's dispersion: red deviated least, so the inner edge is red),
  falling as a Gaussian of HALO_INNER_DEG inside (the sharp inner edge) and, outside, a
  narrow core of HALO_OUTER_DEG with a faint skirt (_halo_lobe).
  The sun comes from the nodes "Halo Sun" (direction toward the sun) and "Halo Irradiance"
  (E_sun, linear RGB), which point_halos(scene) sets from the scene's sun lamp in every
  material that has them (Add Cloud, Cloud Sky & Sun and Bake call it; so do the scripts);
  until then the irradiance is 0 and there is no halo. Thin veils only: the sun's light is not
  attenuated on its way in (a cirrostratus's optical depth is about 0.5).
  Callers link the density with link_density(), which feeds the halo too.
"""
import math

import bpy

DEFAULT_COLOR = (1.0, 1.0, 1.0)
DEFAULT_ANISOTROPY = 0.3
DEFAULT_STEP_RATE = 0.2      # procedural: the presets' default (cirrus types say 0.5)
MIE_DIAMETER_UM = 20.0       # droplet diameter of the Mie phase, micrometres (cumulus droplets)
# Ice veils: Fournier-Forand's phase (Cycles' FOURNIER_FORAND) for particles of ice's refractive
# index, 1.31 (the halo's 1.3087-1.3146 below), and a look's "backscatter" fraction B. At B 0.02
# it puts 65 % of the scattered light within 5° of the sun (ice crystals of 50-100 µm diffract
# within about 1°), falls to 0.21/sr at 18° (Mie of 20 µm droplets: about 0.5) and g is 0.93
# (docs/lighting.md): the veil inside the 22° ring is darker than the ring, as in a real halo
# (no light is refracted by less than 22°), where Mie's droplets lit it brighter than the ring.
ICE_IOR = 1.31
# A look's "side_scatter" share of the ice's scattering goes into a wide Henyey-Greenstein lobe of
# g ICE_SIDE_G (a second Volume Scatter, mixed in): Fournier-Forand alone falls to 0.005/sr at 90°
# and 0.024/sr at 46°, a third to a half of roughened ice crystals' (about 0.016 and 0.048), and
# the veil far from the sun went near-black ("impossible in daylight", both round-19 reviewers).
# At share 0.2 the mix is 0.016/sr at 90°, 0.046/sr at 46°, g 0.80 (cirrus: 0.75-0.85), while
# 18-20° stays 0.21-0.17/sr (the dark inside of the ring; Fournier-Forand alone 0.21-0.17).
ICE_SIDE_G = 0.3
SIDE_NODE, MIX_NODE, DENSITY_NODE = "Cloud Volume Side", "Cloud Volume Mix", "Scatter Density"
VOLUME_NODE = "Cloud Volume"
GRID_NODE = "Density Grid"
HALO_SUN, HALO_IRRADIANCE, HALO_DENSITY = "Halo Sun", "Halo Irradiance", "Halo Density"
# The ring's radius per channel: the minimum deviation through a 60° ice prism,
# D = 2 asin(n sin 30°) - 60°, with ice's refractive index n = 1.3087 (red, 620 nm), 1.3104
# (green, 550 nm), 1.3146 (blue, 460 nm). Red is deviated least: the ring's inner edge is red.
HALO_RADII_DEG = (21.74, 21.87, 22.19)
HALO_INNER_DEG = 0.5     # inside: a sharp edge (no light is deviated by less than the minimum;
#                          the sun's disc, 0.53° across, blurs it)
# outside: light deviated by more than the minimum, a narrow core and a broad, faint skirt.
# Gallery round 17 had one Gaussian of 8° outside: a step from a darker inside to a bright
# outside, read as "a darker disc with a hard rim"; at 4° the veil inside the ring read as a
# bright disc. Real halos are a thin bright ring with a red inner edge, fading outward.
HALO_OUTER_DEG = 2.5
# The skirt: its width and its share of the peak. 8° and 0.35 until gallery round 23: the sky
# just outside the ring came out darker than just inside it (the gallery's cirrostratus from
# below, 640x360, 2° rings at 18-20 / 26-28°: 126 / 122 display levels), and eight blind answers
# in a row (rounds 20-23) said "inside the ring brighter than outside, the reverse of a real
# halo". At 12° and 0.6 (with the cirrostratus's "halo" 3): 122 / 149, brighter outside for
# about 12° and fading (docs/lighting.md, round 24).
HALO_SKIRT_DEG, HALO_SKIRT_SHARE = 12.0, 0.6
# the halo's phase function at the ring, 1/sr, over the veil's own: chosen on renders of the
# cirrostratus from below (320x180): at 0.5 (about HG(g 0.75)'s own 0.49/sr at 22°) the ring
# was as bright as a sunlit white surface and burnt out; at 0.15 it is a clear, thin ring that
# adds about 10 display levels beside the sun's glow, as a bright halo in a thin veil looks.
# A preset's "halo" scales it (the cirrostratus: 3; 2.5, chosen on 320x180 renders with the thin
# ring, until round 23)
HALO_PEAK_PER_SR = 0.15


def scatter_phases() -> set:
    """The phases of Cycles' Volume Scatter (Blender 4.3+: HENYEY_GREENSTEIN, FOURNIER_FORAND,
    DRAINE, RAYLEIGH, MIE; earlier: none to choose)."""
    rna = bpy.types.ShaderNodeVolumeScatter.bl_rna.properties
    return {i.identifier for i in rna["phase"].enum_items} if "phase" in rna else set()


def mie_available() -> bool:
    """Cycles' Volume Scatter has the Mie phase (Blender 4.3+)."""
    return "MIE" in scatter_phases()


def auto_phase(look: dict) -> str:
    """The Volume Scatter phase that phase "AUTO" gives this look, "" for a Principled Volume."""
    want = "FOURNIER_FORAND" if "backscatter" in look else "MIE"
    return want if want in scatter_phases() else ""


def _new_shader(nt, look, phase, like):
    if like is not None:
        node = nt.nodes.new(like.bl_idname)
        if hasattr(like, "phase") and hasattr(node, "phase"):
            node.phase = like.phase
        for sock in like.inputs:
            if sock.name != "Density" and not sock.is_linked and hasattr(sock, "default_value") \
                    and sock.name in node.inputs:
                node.inputs[sock.name].default_value = sock.default_value
        return node
    scatter = auto_phase(look) if phase == "AUTO" else ""
    if scatter:
        node = nt.nodes.new("ShaderNodeVolumeScatter")
        node.phase = scatter
        if scatter == "MIE":
            node.inputs["Diameter"].default_value = MIE_DIAMETER_UM
        else:
            node.inputs["IOR"].default_value = ICE_IOR
            node.inputs["Backscatter"].default_value = float(look["backscatter"])
    else:
        node = nt.nodes.new("ShaderNodeVolumePrincipled")
        node.inputs["Anisotropy"].default_value = float(look.get("anisotropy", DEFAULT_ANISOTROPY))
    node.inputs["Color"].default_value = tuple(look.get("color", DEFAULT_COLOR))[:3] + (1.0,)
    return node


def procedural_step_rate(look: dict) -> float:
    """The step rate of a procedural material of this look (a preset's "material")."""
    return float(look.get("step_rate", DEFAULT_STEP_RATE))


def volume_material(mat, look: dict, grid=None, phase="AUTO", like=None, step_rate=None):
    """Clear mat's node tree and build the volume shader in it; returns the "Cloud Volume" node.
    look: the preset's "material" (color, anisotropy, step_rate, halo, backscatter, side_scatter);
    grid: None for a procedural
    material (the caller links the density into the node's Density), else the grid's name."""
    if phase not in ("AUTO", "HG"):
        raise ValueError(f"phase must be AUTO or HG, not {phase!r}")
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    volume = _new_shader(nt, look, phase, like)
    volume.name = VOLUME_NODE
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    out.name = "Material Output"
    volume.location, out.location = (100, 0), (350, 0)
    scatter = _add_side_scatter(nt, volume, look, like)
    nt.links.new(scatter, out.inputs["Volume"])
    if grid is not None:
        if "Density Attribute" in volume.inputs:
            volume.inputs["Density Attribute"].default_value = grid
            volume.inputs["Density"].default_value = 1.0
        else:
            attr = nt.nodes.new("ShaderNodeAttribute")
            attr.attribute_name = grid
            attr.name = GRID_NODE
            attr.location = (-350, 0)
            nt.links.new(attr.outputs["Fac"], density_input(nt))
    if float(look.get("halo", 0.0)) > 0.0:
        _add_halo(nt, scatter, out, float(look["halo"]), grid)
    if step_rate is None:
        step_rate = 1.0 if grid is not None else procedural_step_rate(look)
    if hasattr(mat, "cycles") and hasattr(mat.cycles, "volume_step_rate"):  # Blender 5: none
        mat.cycles.volume_step_rate = float(step_rate)
    return volume


def _add_side_scatter(nt, volume, look, like=None):
    """The side lobe (see the module's docstring) beside `volume` when the look asks for it and
    `volume` is a Fournier-Forand Volume Scatter; like a `like` node's own material when given
    (its share and g, or none). Returns the socket that carries the scattering (the mix's
    output, else the volume's)."""
    share, g = float(look.get("side_scatter", 0.0)), ICE_SIDE_G
    if like is not None:
        theirs = like.id_data.nodes
        mix, side = theirs.get(MIX_NODE), theirs.get(SIDE_NODE)
        share = float(mix.inputs["Fac"].default_value) if mix is not None and side is not None else 0.0
        g = float(side.inputs["Anisotropy"].default_value) if side is not None else g
    if share <= 0.0 or getattr(volume, "phase", "") != "FOURNIER_FORAND":
        return volume.outputs["Volume"]
    side = nt.nodes.new("ShaderNodeVolumeScatter")
    side.name = side.label = SIDE_NODE
    side.phase = "HENYEY_GREENSTEIN"
    side.inputs["Anisotropy"].default_value = g
    side.inputs["Color"].default_value = volume.inputs["Color"].default_value
    density = nt.nodes.new("ShaderNodeMath")  # one density for both lobes
    density.name = density.label = DENSITY_NODE
    density.operation = "MULTIPLY"
    density.inputs[1].default_value = 1.0
    density.inputs[0].default_value = volume.inputs["Density"].default_value
    nt.links.new(density.outputs[0], volume.inputs["Density"])
    nt.links.new(density.outputs[0], side.inputs["Density"])
    mix = nt.nodes.new("ShaderNodeMixShader")
    mix.name = mix.label = MIX_NODE
    mix.inputs["Fac"].default_value = share
    nt.links.new(volume.outputs["Volume"], mix.inputs[1])
    nt.links.new(side.outputs["Volume"], mix.inputs[2])
    side.location, density.location, mix.location = (100, 250), (-150, 100), (250, 100)
    return mix.outputs[0]


def density_input(nt):
    """The socket a density goes into: DENSITY_NODE's first input when the look has a side lobe,
    else the cloud volume's Density."""
    node = nt.nodes.get(DENSITY_NODE)
    return node.inputs[0] if node is not None else nt.nodes[VOLUME_NODE].inputs["Density"]


def link_density(mat, socket):
    """Link `socket` (a procedural density) into the cloud volume's Density (density_input),
    and the halo's."""
    nt = mat.node_tree
    nt.links.new(socket, density_input(nt))
    if HALO_DENSITY in nt.nodes:
        nt.links.new(socket, nt.nodes[HALO_DENSITY].inputs[0])


def math_node(nt, operation, *inputs):
    """A Math node of `operation` in nt fed by `inputs` in order (each a socket, linked, or a
    number, set); returns its output socket."""
    node = nt.nodes.new("ShaderNodeMath")
    node.operation = operation
    for socket, value in zip(node.inputs, inputs):
        if isinstance(value, (int, float)):
            socket.default_value = float(value)
        else:
            nt.links.new(value, socket)
    return node.outputs[0]


def _add_halo(nt, scatter, out, strength, grid):
    """The halo's emission beside the `scatter` socket (see the module's docstring), added into
    `out`."""
    sun = nt.nodes.new("ShaderNodeCombineXYZ")
    sun.name = sun.label = HALO_SUN
    sun.inputs["Z"].default_value = 1.0
    irradiance = nt.nodes.new("ShaderNodeRGB")
    irradiance.name = irradiance.label = HALO_IRRADIANCE
    irradiance.outputs[0].default_value = (0.0, 0.0, 0.0, 1.0)
    density = nt.nodes.new("ShaderNodeMath")  # density (input 0) x mask (input 1, a ring's)
    density.name = density.label = HALO_DENSITY
    density.operation = "MULTIPLY"
    density.inputs[1].default_value = 1.0
    if grid is not None:  # the grid's Attribute node: the Volume Scatter's own, else a new one
        attr = nt.nodes.get(GRID_NODE) or nt.nodes.new("ShaderNodeAttribute")
        attr.attribute_name = grid
        nt.links.new(attr.outputs["Fac"], density.inputs[0])
    geometry = nt.nodes.new("ShaderNodeNewGeometry")
    dot = nt.nodes.new("ShaderNodeVectorMath")
    dot.operation = "DOT_PRODUCT"
    nt.links.new(geometry.outputs["Incoming"], dot.inputs[0])  # Incoming points back to the viewer
    nt.links.new(sun.outputs[0], dot.inputs[1])
    cos_theta = math_node(nt, "MULTIPLY", dot.outputs["Value"], -1.0)  # the view ray against the sun
    theta = math_node(nt, "ARCCOSINE", math_node(nt, "MAXIMUM", math_node(nt, "MINIMUM", cos_theta, 1.0), -1.0))
    lobes = nt.nodes.new("ShaderNodeCombineXYZ")  # per channel: x red, y green, z blue
    for channel, radius in enumerate(HALO_RADII_DEG):
        nt.links.new(_halo_lobe(nt, theta, radius), lobes.inputs[channel])
    colour = nt.nodes.new("ShaderNodeVectorMath")  # E_sun x the lobes (colour <-> vector implicitly)
    colour.operation = "MULTIPLY"
    nt.links.new(irradiance.outputs[0], colour.inputs[0])
    nt.links.new(lobes.outputs[0], colour.inputs[1])
    power = math_node(nt, "MULTIPLY", density.outputs[0], HALO_PEAK_PER_SR * strength)
    emission = nt.nodes.new("ShaderNodeEmission")
    emission.name = emission.label = "Halo"
    nt.links.new(colour.outputs[0], emission.inputs["Color"])
    nt.links.new(power, emission.inputs["Strength"])
    add = nt.nodes.new("ShaderNodeAddShader")
    nt.links.new(scatter, add.inputs[0])
    nt.links.new(emission.outputs[0], add.inputs[1])
    nt.links.new(add.outputs[0], out.inputs["Volume"])
    for node, at in ((emission, (100, -250)), (add, (250, -100)), (sun, (-600, -250)), (irradiance, (-150, -250))):
        node.location = at


def _gaussian(nt, d, width):
    """exp(-(d / width)^2) in nodes; width a socket or a number (radians)."""
    u = math_node(nt, "DIVIDE", d, width)
    return math_node(nt, "EXPONENT", math_node(nt, "MULTIPLY", math_node(nt, "MULTIPLY", u, u), -1.0))


def _halo_lobe(nt, theta, radius_deg):
    """The ring's profile for the channel of radius `radius_deg`, in nodes (theta a socket,
    radians; d = theta - radius): 1 at d = 0; inside (d < 0) exp(-(d / HALO_INNER_DEG)^2);
    outside core + HALO_SKIRT_SHARE * (skirt - core), core and skirt Gaussians of
    HALO_OUTER_DEG and HALO_SKIRT_DEG."""
    d = math_node(nt, "SUBTRACT", theta, math.radians(radius_deg))
    inside = math_node(nt, "LESS_THAN", d, 0.0)
    width = math_node(nt, "MULTIPLY_ADD", inside, math.radians(HALO_INNER_DEG - HALO_OUTER_DEG),
                      math.radians(HALO_OUTER_DEG))
    core = _gaussian(nt, d, width)
    skirt = math_node(nt, "SUBTRACT", _gaussian(nt, d, math.radians(HALO_SKIRT_DEG)), core)
    outside_share = math_node(nt, "MULTIPLY_ADD", inside, -HALO_SKIRT_SHARE, HALO_SKIRT_SHARE)
    return math_node(nt, "MULTIPLY_ADD", skirt, outside_share, core)


def set_halo_sun(mat, direction, irradiance) -> bool:
    """Point mat's halo at the sun: `direction` toward the sun (normalised here), `irradiance`
    its linear RGB irradiance. Returns whether mat has a halo."""
    nt = mat.node_tree if mat.use_nodes else None
    if nt is None or HALO_SUN not in nt.nodes:
        return False
    n = math.sqrt(sum(c * c for c in direction)) or 1.0
    for axis, c in zip("XYZ", direction):
        nt.nodes[HALO_SUN].inputs[axis].default_value = c / n
    nt.nodes[HALO_IRRADIANCE].outputs[0].default_value = tuple(float(c) for c in irradiance)[:3] + (1.0,)
    return True


def scene_sun(scene):
    """The scene's first Sun lamp that renders (the add-on's own or the artist's), or None."""
    for obj in scene.objects:
        if obj.type == "LIGHT" and obj.data.type == "SUN" and not obj.hide_render:
            return obj
    return None


def sun_light(sun):
    """(direction, rgb) of a Sun lamp: the unit vector toward the sun (its +Z axis; a sun lamp
    shines along -Z) and its irradiance, colour times strength (W/m², linear RGB). From
    matrix_basis: current even before the depsgraph updated matrix_world."""
    from mathutils import Matrix, Vector

    world = (sun.parent.matrix_world if sun.parent else Matrix()) @ sun.matrix_basis
    direction = tuple((world.to_3x3() @ Vector((0.0, 0.0, 1.0))).normalized())
    return direction, tuple(sun.data.energy * c for c in sun.data.color)


def point_halos(scene) -> int:
    """Point every material's halo at the scene's sun (scene_sun, sun_light). Without a sun the
    halos go dark. Returns how many materials have a halo."""
    sun = scene_sun(scene)
    direction, rgb = ((0.0, 0.0, 1.0), (0.0, 0.0, 0.0)) if sun is None else sun_light(sun)
    return sum(set_halo_sun(mat, direction, rgb) for mat in bpy.data.materials)
