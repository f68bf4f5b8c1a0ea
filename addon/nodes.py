"""The two node groups, as the thesis splits them, and the cloud material.

Cloud Noise (shared by every cloud): the noise texture; inputs are the Cloud
Noise, Animation and Box parameters; output "Noise" in [0, 1].
Cloud Main (one per cloud, because it holds that cloud's Shape Gradient
curve): inputs the Cloud Main parameters and "Distortion Noise"; output
"Density". Inside each group: Texture Coordinate → the OSL Script nodes in
INTERNAL mode (text datablocks with the flattened shaders, saved in the
.blend), wired with blender_nodes.py's helpers; in Cloud Main the Cloud
Height shader feeds a Float Curve named "Shape Gradient" (the preset's 17
samples, vector handles) which feeds Cloud Main's shape_gradient.

Socket ranges: a group socket's min/max are *soft* limits in Blender (they
bound the slider; Python, drivers and links may go beyond), so the sockets
carry the declared soft range (slider range) and the declared default;
floats whose soft range lies in [0, 1] and ends at 1 are FACTOR sliders. The declared
hard range is enforced where values reach the core (preview, bake) with a
message naming the parameter.
"""
import functools
import hashlib

import bpy

from . import blender_nodes, bridge, osl_temp, volume_material
from .panel import tooltip

MAIN_GROUP = "Cloud Main"
NOISE_GROUP = "Cloud Noise"
CURVE_NODE = "Shape Gradient"
DISTORTION_NOISE = "Distortion Noise"
GROUP_OF = {"Cloud Main": MAIN_GROUP, "Cloud Noise": NOISE_GROUP, "Animation": NOISE_GROUP,
            "Box": NOISE_GROUP}
PANEL_OF = {"Cloud Main": "Cloud Main", "Cloud Noise": "Noise", "Animation": "Animation", "Box": "Box"}
VERSION = 2  # bump when the groups' layout changes; older groups are rebuilt
# a group's property: the shader sources its Script nodes were compiled from (shader_sources_key)
SHADERS_KEY = "cloudgen_shaders"


def has_interface_panels() -> bool:
    return bpy.app.version >= (4, 0, 0)


def group_parameters(group_name: str) -> list:
    """Declared parameters exposed as sockets of the group (the curve is a node, not a socket)."""
    return [p for p in bridge.parameters()
            if GROUP_OF.get(p["group"]) == group_name and p["kind"] != "curve"]


def socket_kind(p: dict):
    """(socket type, subtype) for a declaration."""
    if p["kind"] == "int":
        return "NodeSocketInt", "NONE"
    if p["kind"] == "vector":
        return "NodeSocketVector", "XYZ"   # fields labelled X, Y, Z
    if p["soft_min"] >= 0.0 and p["soft_max"] == 1.0:  # 0–1 sliders (Cloud Scale: 0.05–1)
        return "NodeSocketFloat", "FACTOR"
    return "NodeSocketFloat", "NONE"


def _new_socket(ng, name, in_out, socket_type, subtype="NONE", parent=None):
    if has_interface_panels():
        kw = {"parent": parent} if parent is not None else {}
        sock = ng.interface.new_socket(name, in_out=in_out, socket_type=socket_type, **kw)
        if subtype != "NONE":
            sock.subtype = subtype
        return sock
    idname = socket_type + {"FACTOR": "Factor", "XYZ": "XYZ"}.get(subtype, "")
    return (ng.inputs if in_out == "INPUT" else ng.outputs).new(idname, name)


def _declared_socket(ng, p, parent=None):
    socket_type, subtype = socket_kind(p)
    sock = _new_socket(ng, p["label"], "INPUT", socket_type, subtype, parent)
    sock.min_value = p["soft_min"]
    sock.max_value = p["soft_max"]
    d = p["default"]
    sock.default_value = tuple(d) if isinstance(d, (list, tuple)) else d
    sock.description = tooltip(p["help"])[:255]
    return sock


def _interface(ng, params, extra_inputs=(), outputs=()):
    """Outputs first, extra inputs, then the declared ones (in 4.x grouped in panels by
    declaration group: root sockets must come before panels)."""
    for name in outputs:
        _new_socket(ng, name, "OUTPUT", "NodeSocketFloat")
    for name, socket_type, subtype, lo, hi, default, help_text in extra_inputs:
        s = _new_socket(ng, name, "INPUT", socket_type, subtype)
        s.min_value, s.max_value, s.default_value, s.description = lo, hi, default, tooltip(help_text)
    panels = {}
    for p in params:
        parent = None
        if has_interface_panels():
            title = PANEL_OF[p["group"]]
            if title not in panels:
                panels[title] = ng.interface.new_panel(title)
            parent = panels[title]
        _declared_socket(ng, p, parent)


def _script(nt, shader):
    """A Script node holding the shader as internal text; compiled when this Blender has OSL."""
    if blender_nodes.osl_available():
        with osl_temp.private_tempdir():  # Cycles' compile leaves a temporary .oso behind
            node = blender_nodes.script_node(nt, shader, "INTERNAL")
    else:  # e.g. Debian's 3.4: the text is stored, the node has no sockets, the group outputs 0
        node = nt.nodes.new("ShaderNodeScript")
        node.mode = "INTERNAL"
        node.script = blender_nodes.shader_text(shader)
        node.label = shader.replace("_", " ").title()
    node.name = shader
    return node


def _io_nodes(ng):
    gi = ng.nodes.new("NodeGroupInput")
    go = ng.nodes.new("NodeGroupOutput")
    tc = ng.nodes.new("ShaderNodeTexCoord")
    gi.location, go.location, tc.location = (-600, 0), (600, 0), (-600, 300)
    return gi, go, tc


def _link_params(ng, gi, node, params):
    for p in params:
        osl_name = blender_nodes.OSL_SOCKET_NAME.get(p["name"], p["name"])
        if osl_name in node.inputs:
            ng.links.new(gi.outputs[p["label"]], node.inputs[osl_name])


@functools.lru_cache(maxsize=1)
def shader_sources_key() -> str:
    """16 hex digits of this add-on's flattened shader sources: a group whose SHADERS_KEY differs
    was compiled from another cloudgen's model (its text and bytecode travel in the .blend)."""
    sources = "\0".join(blender_nodes.flatten.shader_source(s) for s in blender_nodes.flatten.SHADERS)
    return hashlib.sha256(sources.encode()).hexdigest()[:16]


def outdated_groups() -> list:
    """The add-on's node groups in this file (not linked from a library) whose shaders were made
    from other sources than this add-on's: an older cloudgen's model, or none recorded."""
    key = shader_sources_key()
    return [ng for ng in bpy.data.node_groups
            if ng.get("cloudgen_version") is not None and ng.library is None and ng.get(SHADERS_KEY) != key]


def _input_names(ng) -> set:
    if has_interface_panels():
        return {i.name for i in ng.interface.items_tree if i.item_type == "SOCKET" and i.in_out == "INPUT"}
    return set(ng.inputs.keys())


def add_missing_sockets(ng) -> list:
    """Give a group made by an older cloudgen the sockets of parameters declared since (in 4.x in
    their panel), at their declared defaults, which leave the older model's field as it was (a
    new shape term is off at its default). Returns the labels added."""
    kind = MAIN_GROUP if "cloud_main" in ng.nodes else NOISE_GROUP if "cloud_noise" in ng.nodes else None
    if kind is None:
        return []
    have = _input_names(ng)
    added = []
    for p in group_parameters(kind):
        if p["label"] in have:
            continue
        parent = None
        if has_interface_panels():
            title = PANEL_OF[p["group"]]
            parent = next((i for i in ng.interface.items_tree if i.item_type == "PANEL" and i.name == title), None)
            if parent is None:
                parent = ng.interface.new_panel(title)
        _declared_socket(ng, p, parent)
        added.append(p["label"])
    return added


def update_shaders() -> list:
    """Bring outdated_groups() to this add-on's model: the shared shader texts rewritten with its
    sources and, where this Blender has OSL, every Script node recompiled and linked as a fresh
    build would (a Script node renders from its stored bytecode, so the text alone changes
    nothing). Without OSL only the texts change and the groups stay outdated, to be compiled in
    a Blender that has it. Returns the names of the groups whose shaders changed; a compile that
    fails raises RuntimeError naming the group."""
    groups = outdated_groups()
    if not groups:
        return []
    compile_here = blender_nodes.osl_available()
    changed = []
    for ng in groups:
        touched = bool(add_missing_sockets(ng))
        for node in ng.nodes:
            if node.bl_idname != "ShaderNodeScript" or node.mode != "INTERNAL" or node.script is None:
                continue
            if node.name not in blender_nodes.flatten.SHADERS:
                continue  # not one of ours
            touched |= blender_nodes.write_text(node.script, blender_nodes.flatten.shader_source(node.name))
            if compile_here:
                _compile(ng, node)
                touched = True
        if compile_here:
            _wire(ng)
            ng[SHADERS_KEY] = shader_sources_key()
        if touched:
            changed.append(ng.name)
    return changed


def build_noise_group(name=NOISE_GROUP):
    params = group_parameters(NOISE_GROUP)
    ng = bpy.data.node_groups.new(name, "ShaderNodeTree")
    _interface(ng, params, outputs=("Noise",))
    _io_nodes(ng)
    _script(ng, "cloud_noise")
    _wire(ng)
    ng["cloudgen_version"] = VERSION
    ng[SHADERS_KEY] = shader_sources_key()
    return ng


def build_main_group(shape_curve, name=MAIN_GROUP):
    params = group_parameters(MAIN_GROUP)
    ng = bpy.data.node_groups.new(name, "ShaderNodeTree")
    extra = [(DISTORTION_NOISE, "NodeSocketFloat", "FACTOR", 0.0, 1.0, 0.5,
              "The distortion texture in [0, 1] (Cloud Noise's output, or any texture); 0.5 is neutral")]
    _interface(ng, params, extra_inputs=extra, outputs=("Density",))
    _io_nodes(ng)
    main = _script(ng, "cloud_main")
    height = _script(ng, "cloud_height")
    curve = blender_nodes.shape_curve_node(ng, shape_curve)
    curve.name = curve.label = CURVE_NODE
    height.location, curve.location, main.location = (-300, 300), (0, 300), (300, 0)
    _wire(ng)
    ng["cloudgen_version"] = VERSION
    ng[SHADERS_KEY] = shader_sources_key()
    return ng


LOD_INPUT = "lod_pixel_angle"
# radians per pixel of the scene camera: 2 tan(angle/2) over the pixels along its sensor fit
# (AUTO: the longer side), resolution percentage applied; 0 (LOD off) unless perspective
LOD_EXPRESSION = "(t == 0) * 2 * tan(a / 2) * 100 / (p * ((f == 0) * max(x, y) + (f == 1) * x + (f == 2) * y))"
LOD_VARIABLES = (("a", "camera.data.angle"), ("t", "camera.data.type"), ("f", "camera.data.sensor_fit"),
                 ("x", "render.resolution_x"), ("y", "render.resolution_y"), ("p", "render.resolution_percentage"))


def drive_lod_pixel_angle(ng, noise, scene=None):
    """Cloud Noise's LOD Pixel Angle (a shader input, not a group socket) follows the scene
    camera, so octaves finer than a pixel at the shading point's distance are not evaluated
    (docs/osl.md). A simple-expression driver: runs without Python auto-exec. No camera, or
    an orthographic or panoramic one: the driver gives 0 or fails, and 0 means every octave."""
    scene = scene or bpy.context.scene
    path = noise.inputs[LOD_INPUT].path_from_id("default_value")
    ng.driver_remove(path)
    drv = ng.driver_add(path).driver
    drv.type = "SCRIPTED"
    for name, data_path in LOD_VARIABLES:
        var = drv.variables.new()
        var.name = name
        var.type = "SINGLE_PROP"
        var.targets[0].id_type = "SCENE"
        var.targets[0].id = scene
        var.targets[0].data_path = data_path
    drv.expression = LOD_EXPRESSION


def revalidate_lod_drivers():
    """Re-enable LOD Pixel Angle drivers Blender marked invalid (a cloud added while the scene
    had no camera: `camera.data` did not resolve, and Blender never retries an invalid
    driver by itself, so the cloud rendered at full detail after a camera was added).
    Returns how many were re-enabled; the render_pre check calls it."""
    count = 0
    for ng in bpy.data.node_groups:
        noise = ng.nodes.get("cloud_noise") if ng.animation_data is not None else None
        if noise is None or LOD_INPUT not in noise.inputs:
            continue
        fc = ng.animation_data.drivers.find(noise.inputs[LOD_INPUT].path_from_id("default_value"))
        if fc is not None and not fc.driver.is_valid:
            fc.driver.is_valid = True
            fc.driver.expression = fc.driver.expression  # rebuilds the driver's dependencies
            count += 1
    return count


def _node_of_type(ng, idname):
    return next((n for n in ng.nodes if n.bl_idname == idname), None)


def _wire(ng):
    """Link a group's compiled Script nodes (by name: cloud_noise, or cloud_main +
    cloud_height + the Shape Gradient curve) to its Group Input/Output and Texture
    Coordinate nodes. Nothing happens to a node without sockets (not compiled: a Blender
    without OSL); repair_groups() calls this again once they are compiled."""
    gi, go = _node_of_type(ng, "NodeGroupInput"), _node_of_type(ng, "NodeGroupOutput")
    tc = _node_of_type(ng, "ShaderNodeTexCoord")
    if gi is None or go is None or tc is None:
        raise LookupError(f"node group {ng.name!r} lacks its Group Input/Output or Texture Coordinate node")
    nodes = ng.nodes
    if "cloud_noise" in nodes:
        params = group_parameters(NOISE_GROUP)
        noise = nodes["cloud_noise"]
        if "Generated" in noise.inputs:
            ng.links.new(tc.outputs["Generated"], noise.inputs["Generated"])
            _link_params(ng, gi, noise, params)
            ng.links.new(noise.outputs["Noise"], go.inputs["Noise"])
            if LOD_INPUT in noise.inputs:
                drive_lod_pixel_angle(ng, noise)
    if "cloud_main" in nodes and "cloud_height" in nodes:
        params = group_parameters(MAIN_GROUP)
        main, height, curve = nodes["cloud_main"], nodes["cloud_height"], nodes.get(CURVE_NODE)
        if "Generated" in main.inputs and "Generated" in height.inputs and curve is not None:
            for node in (main, height):
                ng.links.new(tc.outputs["Generated"], node.inputs["Generated"])
                _link_params(ng, gi, node, params)
            ng.links.new(gi.outputs[DISTORTION_NOISE], main.inputs["distortion_noise"])
            ng.links.new(height.outputs["Height"], curve.inputs["Value"])
            ng.links.new(curve.outputs["Value"], main.inputs["shape_gradient"])
            ng.links.new(main.outputs["Density"], go.inputs["Density"])


def uncompiled_groups() -> list:
    """The add-on's node groups with a Script node that has no sockets (built in a Blender
    without OSL, e.g. Debian's 3.4): they output 0 until compiled and linked."""
    return [ng for ng in bpy.data.node_groups
            if ng.get("cloudgen_version") is not None and any(
                n.bl_idname == "ShaderNodeScript" and not n.outputs for n in ng.nodes)]


def _compile(ng, node):
    """Compile a Script node of group ng from its text (this Blender has OSL); RuntimeError with
    the compiler's messages if it fails."""
    from cycles import osl as cycles_osl  # noqa: PLC0415 - only with OSL

    blender_nodes.ensure_oslquery_importable()
    messages = []
    with osl_temp.private_tempdir():  # Cycles' compile leaves a temporary .oso behind
        ok = cycles_osl.update_script_node(node, lambda kind, msg: messages.append(f"{kind}: {msg}"))
    if not ok:
        raise RuntimeError(f"{ng.name}: compiling {node.name} failed: {messages}")


def repair_groups() -> list:
    """Compile the Script nodes of uncompiled_groups() and link them as a fresh build would
    (only where this Blender has OSL). Returns the names of the groups repaired; a group that
    fails is left as it was (RuntimeError names it)."""
    if not blender_nodes.osl_available():
        return []
    repaired = []
    for ng in uncompiled_groups():
        if ng.library is not None:
            continue  # linked from another file: not ours to change
        for node in ng.nodes:
            if node.bl_idname == "ShaderNodeScript" and not node.outputs:
                _compile(ng, node)
        _wire(ng)
        repaired.append(ng.name)
    return repaired


def noise_group():
    """The shared Cloud Noise group (built on first use, rebuilt if from another layout version)."""
    ng = bpy.data.node_groups.get(NOISE_GROUP)
    if ng is not None and ng.get("cloudgen_version") == VERSION:
        return ng
    if ng is not None:
        ng.name = NOISE_GROUP + " (old)"
    return build_noise_group()


def shape_curve_samples(group) -> list:
    """The Shape Gradient curve of a Cloud Main group at the 17 heights 0, 1/16, ..., 1:
    what the core gets as shape_curve (it interpolates them linearly, as the
    Float Curve with vector handles does)."""
    node = group.nodes[CURVE_NODE]
    mapping = node.mapping
    mapping.initialize()
    curve = mapping.curves[0]
    n = blender_nodes.CURVE_POINTS
    at = {round(p.location[0] * (n - 1), 4): p.location[1] for p in curve.points}
    out = []
    for i in range(n):
        # a control point at the height: its value exactly (evaluate() goes through a
        # 256-entry table and returns e.g. -2e-7 for a 0); elsewhere the curve's value
        v = float(at[i]) if float(i) in at else float(mapping.evaluate(curve, i / (n - 1)))
        out.append(min(max(v, 0.0), 1.0) if -1e-5 < v < 1.0 + 1e-5 else v)
    return out


def group_sockets(group):
    """Interface input sockets of a group (4.x interface items or 3.x group inputs)."""
    if has_interface_panels():
        return [it for it in group.interface.items_tree
                if it.item_type == "SOCKET" and it.in_out == "INPUT"]
    return list(group.inputs)


def set_node_values(node, values: dict, params):
    for p in params:
        if p["name"] in values and p["label"] in node.inputs:
            v = values[p["name"]]
            node.inputs[p["label"]].default_value = tuple(v) if isinstance(v, (list, tuple)) else v


def _driver(id_data, path, index, kind, target, data_path=None, transform=None):
    fc = id_data.driver_add(path, index) if index is not None else id_data.driver_add(path)
    drv = fc.driver
    drv.type = "AVERAGE"
    var = drv.variables.new()
    var.name = "v"
    if kind == "TRANSFORMS":
        var.type = "TRANSFORMS"
        var.targets[0].id = target
        var.targets[0].transform_type = transform
        var.targets[0].transform_space = "WORLD_SPACE"
    else:
        var.type = "SINGLE_PROP"
        var.targets[0].id_type = "OBJECT"
        var.targets[0].id = target
        var.targets[0].data_path = data_path
    return fc


def drive_box_inputs(material, obj):
    """Box Size follows the object's dimensions, Object Location its world location
    (plain AVERAGE drivers: no Python expression, so they run without auto-exec)."""
    noise = material.node_tree.nodes[NOISE_GROUP]
    for label, kind in (("Box Size", "SINGLE_PROP"), ("Object Location", "TRANSFORMS")):
        noise.inputs[label].hide = True  # driven: not an input to edit in the node editor
        path = noise.inputs[label].path_from_id("default_value")
        for i in range(3):
            _driver(material.node_tree, path, i, kind, obj, data_path=f"dimensions[{i}]",
                    transform=("LOC_X", "LOC_Y", "LOC_Z")[i])


def set_time_from_frame(material, enable: bool):
    """Time = frame / fps (a simple-expression driver: no Python needed), or a free,
    keyframable value again."""
    nt = material.node_tree
    path = nt.nodes[NOISE_GROUP].inputs["Time"].path_from_id("default_value")
    nt.driver_remove(path)
    if not enable:
        return
    fc = nt.driver_add(path)
    drv = fc.driver
    drv.type = "SCRIPTED"
    for name, prop in (("fps", "render.fps"), ("fps_base", "render.fps_base")):
        var = drv.variables.new()
        var.name = name
        var.type = "SINGLE_PROP"
        var.targets[0].id_type = "SCENE"
        var.targets[0].id = bpy.context.scene
        var.targets[0].data_path = prop
    drv.expression = "frame * fps_base / fps"


def time_follows_frame(material) -> bool:
    nt = material.node_tree
    ad = nt.animation_data
    if ad is None or NOISE_GROUP not in nt.nodes:
        return False
    path = nt.nodes[NOISE_GROUP].inputs["Time"].path_from_id("default_value")
    return any(fc.data_path == path for fc in ad.drivers)


def build_material(name, values: dict, look: dict, obj):
    """The cloud material: Cloud Noise → Cloud Main (Distortion Noise) → volume shader
    (volume_material.py). Node names: "Cloud Noise", "Cloud Main" (group nodes),
    "Cloud Volume", "Material Output"."""
    mat = bpy.data.materials.new(name)
    volume_material.volume_material(mat, look)
    nt = mat.node_tree
    noise = nt.nodes.new("ShaderNodeGroup")
    noise.node_tree = noise_group()
    main = nt.nodes.new("ShaderNodeGroup")
    main.node_tree = build_main_group(values["shape_curve"])
    noise.name, main.name = NOISE_GROUP, MAIN_GROUP
    noise.location, main.location = (-400, 0), (-150, 0)
    set_node_values(noise, values, group_parameters(NOISE_GROUP))
    set_node_values(main, values, group_parameters(MAIN_GROUP))
    nt.links.new(noise.outputs["Noise"], main.inputs[DISTORTION_NOISE])
    volume_material.link_density(mat, main.outputs["Density"])
    drive_box_inputs(mat, obj)
    return mat
