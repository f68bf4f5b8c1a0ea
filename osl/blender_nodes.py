"""Wire the cloudgen OSL shaders into a Blender (Cycles) node tree.

Used inside Blender's Python (the `bpy` wheel or `blender -b`): by the main
job's render script, by the OSL parity and render tests, and by the add-on.
The node layout is the thesis's (section 4.1):

    Generated ─┬─> Cloud Noise ──Noise──> Distortion Noise ┐
               ├─> Cloud Height ─Height─> Float Curve ──> Shape Gradient ├─> Cloud Main ─Density─>
               └──────────────────────────────────────────> Generated     ┘

Parameter values are the declared ones (a dict keyed by the names in
`cloudgen_native.parameters()`); the OSL socket of the Time parameter is
`cloud_time` because `time` is an OSL global.
"""
from __future__ import annotations

import os
import sys

try:  # imported as osl.blender_nodes, or with osl/ on sys.path
    from . import flatten
except ImportError:
    import flatten

OSL_SOCKET_NAME = {"time": "cloud_time"}
CURVE_POINTS = 17


def ensure_oslquery_importable():
    """cycles.osl.update_script_node imports `oslquery`, which the bpy wheel keeps
    in Blender's bundled site-packages, off sys.path (docs/platform.md)."""
    import bpy

    path = os.path.join(bpy.utils.resource_path("LOCAL"), "python", "lib",
                        f"python{sys.version_info.major}.{sys.version_info.minor}", "site-packages")
    if os.path.isdir(path) and path not in sys.path:
        sys.path.append(path)


def osl_available() -> bool:
    import bpy

    return bool(getattr(bpy.app.build_options, "cycles_osl", False))


def write_text(text, source: str) -> bool:
    """Make the Text datablock `text` hold exactly `source`; True when it changed."""
    if text.as_string() == source:
        return False
    text.clear()
    text.write(source)
    return True


def shader_text(shader: str, source: str | None = None):
    """The Text datablock `<shader>.osl` (made if missing) holding `source`, by default the
    flattened shader: what an INTERNAL Script node compiles and the .blend carries."""
    import bpy

    text = bpy.data.texts.get(f"{shader}.osl") or bpy.data.texts.new(f"{shader}.osl")
    write_text(text, flatten.shader_source(shader) if source is None else source)
    return text


def script_node(node_tree, shader: str, mode: str = "INTERNAL", directory: str | None = None,
                defines: dict | None = None):
    """A compiled Script node for one of our shaders. INTERNAL stores the
    flattened source as a Text datablock (it travels with the .blend);
    EXTERNAL writes it to `directory` (the .oso lands next to it)."""
    from cycles import osl as cycles_osl

    ensure_oslquery_importable()
    source = flatten.shader_source(shader, defines)
    node = node_tree.nodes.new("ShaderNodeScript")
    node.label = shader.replace("_", " ").title()
    if mode == "INTERNAL":
        node.mode = "INTERNAL"
        node.script = shader_text(shader, source)
    else:
        if directory is None:
            raise ValueError("EXTERNAL mode needs a directory for the .osl file")
        path = os.path.join(directory, f"{shader}.osl")
        with open(path, "w") as f:
            f.write(source)
        node.mode = "EXTERNAL"
        node.filepath = path
    messages = []
    if not cycles_osl.update_script_node(node, lambda kind, msg: messages.append(f"{kind}: {msg}")):
        raise RuntimeError(f"compiling {shader}.osl failed: {messages}")
    return node


def set_inputs(node, values: dict):
    """Set every input socket of `node` that corresponds to a parameter in `values`."""
    for key, value in values.items():
        name = OSL_SOCKET_NAME.get(key, key)
        if name in node.inputs:
            sock = node.inputs[name]
            sock.default_value = tuple(value) if isinstance(value, (list, tuple)) else value


def shape_curve_node(node_tree, samples):
    """A Float Curve node through the 17 profile samples with vector handles:
    piecewise linear, the same curve the native core evaluates."""
    if len(samples) != CURVE_POINTS:
        raise ValueError(f"shape_curve needs {CURVE_POINTS} samples, got {len(samples)}")
    node = node_tree.nodes.new("ShaderNodeFloatCurve")
    mapping = node.mapping
    mapping.extend = "HORIZONTAL"
    curve = mapping.curves[0]
    while len(curve.points) > 2:
        curve.points.remove(curve.points[-1])
    curve.points[0].location = (0.0, samples[0])
    curve.points[1].location = (1.0, samples[-1])
    for i in range(1, CURVE_POINTS - 1):
        curve.points.new(i / (CURVE_POINTS - 1), samples[i])
    for p in curve.points:
        p.handle_type = "VECTOR"
    mapping.use_clip = False
    mapping.update()
    node.inputs["Factor"].default_value = 1.0
    return node


def cloud_density_nodes(node_tree, values: dict, generated_socket, mode="INTERNAL", directory=None,
                        defines: dict | None = None):
    """Build Cloud Noise + Cloud Height + Float Curve + Cloud Main fed by
    `generated_socket`; returns (main_node, noise_node). The density is
    main_node.outputs['Density']."""
    noise = script_node(node_tree, "cloud_noise", mode, directory, defines)
    main = script_node(node_tree, "cloud_main", mode, directory, defines)
    links = node_tree.links
    set_inputs(noise, values)
    set_inputs(main, values)
    links.new(generated_socket, noise.inputs["Generated"])
    links.new(generated_socket, main.inputs["Generated"])
    links.new(noise.outputs["Noise"], main.inputs["distortion_noise"])
    if int(values.get("shape_mode", 0)) == 1:
        height = script_node(node_tree, "cloud_height", mode, directory)
        set_inputs(height, values)
        links.new(generated_socket, height.inputs["Generated"])
        curve = shape_curve_node(node_tree, values["shape_curve"])
        links.new(height.outputs["Height"], curve.inputs["Value"])
        links.new(curve.outputs["Value"], main.inputs["shape_gradient"])
    return main, noise
