"""The one builder of a cloud's volume material: the procedural cloud's (nodes.py),
the baked VDB's (volume_object.py) and scripts/render_cloud.py's (procedural and --vdb).

bpy only, no imports of the add-on's own modules: render_cloud.py loads this file
by its path.

    volume = volume_material(mat, look)                    # procedural: link the density in
    nt.links.new(density_socket, volume.inputs["Density"])
    volume_material(mat, look, grid="density")             # a VDB: reads its grid

The shader, node "Cloud Volume" → "Material Output".Volume:
- phase "AUTO": Volume Scatter with the Mie phase where Cycles has it (4.3+:
  cloud droplets, MIE_DIAMETER_UM), else Principled Volume (Henyey–Greenstein
  with the look's anisotropy); phase "HG": always Principled Volume.
- like: an existing volume node (the cloud's own "Cloud Volume") whose type,
  phase and unlinked input values are copied — a baked cloud looks as the
  procedural one, edits included.
- grid: the volume's density comes from that grid, once. A Principled Volume
  multiplies Density by its Density Attribute, so the grid goes there with
  Density 1 (linking the grid into Density as well would square the density: a
  darker cloud); a Volume Scatter has no such attribute: an Attribute node
  "Density Grid" feeds Density.
- step rate: the look's "step_rate" (default DEFAULT_STEP_RATE) for a procedural
  material, 1 (the voxel size) for a grid; step_rate= wins.
"""
import bpy

DEFAULT_COLOR = (1.0, 1.0, 1.0)
DEFAULT_ANISOTROPY = 0.3
DEFAULT_STEP_RATE = 0.2      # procedural: the presets' default (cirrus types say 0.5)
MIE_DIAMETER_UM = 20.0       # droplet diameter of the Mie phase, micrometres (cumulus droplets)
VOLUME_NODE = "Cloud Volume"
GRID_NODE = "Density Grid"


def mie_available() -> bool:
    """Cycles' Volume Scatter has the Mie phase (Blender 4.3+)."""
    rna = bpy.types.ShaderNodeVolumeScatter.bl_rna.properties
    return "phase" in rna and "MIE" in {i.identifier for i in rna["phase"].enum_items}


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
    if phase == "AUTO" and mie_available():
        node = nt.nodes.new("ShaderNodeVolumeScatter")
        node.phase = "MIE"
        node.inputs["Diameter"].default_value = MIE_DIAMETER_UM
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
    look: the preset's "material" (color, anisotropy, step_rate); grid: None for a procedural
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
    nt.links.new(volume.outputs["Volume"], out.inputs["Volume"])
    if grid is not None:
        if "Density Attribute" in volume.inputs:
            volume.inputs["Density Attribute"].default_value = grid
            volume.inputs["Density"].default_value = 1.0
        else:
            attr = nt.nodes.new("ShaderNodeAttribute")
            attr.attribute_name = grid
            attr.name = GRID_NODE
            attr.location = (-150, 0)
            nt.links.new(attr.outputs["Fac"], volume.inputs["Density"])
    if step_rate is None:
        step_rate = 1.0 if grid is not None else procedural_step_rate(look)
    if hasattr(mat, "cycles") and hasattr(mat.cycles, "volume_step_rate"):  # Blender 5: none
        mat.cycles.volume_step_rate = float(step_rate)
    return volume
