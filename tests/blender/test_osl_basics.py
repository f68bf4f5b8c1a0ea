"""OSL in the bpy wheel: a Script node compiles and renders exactly, and our
shaders' parameters match the one declaration (names, labels, defaults,
ranges, help)."""
import os
import tempfile

import blender_nodes
import flatten
import numpy as np
import pytest

CONSTANT = """
shader constant_colour(output color Out = color(0.25, 0.5, 0.75)) { Out = color(0.25, 0.5, 0.75); }
"""


def render_plane(scene, make_colour_socket, size=8):
    """Render a camera-filling emission plane; returns the float RGB pixels."""
    import bpy

    bpy.ops.mesh.primitive_plane_add(size=4.0)
    plane = bpy.context.active_object
    mat = bpy.data.materials.new("m")
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    emission = nt.nodes.new("ShaderNodeEmission")
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    nt.links.new(make_colour_socket(nt), emission.inputs["Color"])
    nt.links.new(emission.outputs[0], out.inputs["Surface"])
    plane.data.materials.append(mat)
    cam_data = bpy.data.cameras.new("c")
    cam_data.type = "ORTHO"
    cam_data.ortho_scale = 1.0
    cam = bpy.data.objects.new("c", cam_data)
    cam.location = (0, 0, 2)
    scene.collection.objects.link(cam)
    scene.camera = cam
    scene.render.resolution_x = scene.render.resolution_y = size
    scene.cycles.samples = 1
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    with tempfile.TemporaryDirectory() as d:
        scene.render.filepath = os.path.join(d, "out.exr")
        bpy.ops.render.render(write_still=True)
        img = bpy.data.images.load(scene.render.filepath)
        px = np.array(img.pixels[:], dtype=np.float32).reshape(size, size, 4)
    return px[..., :3]


def test_constant_colour_script_node_renders_exactly(empty_scene):
    import bpy
    from cycles import osl as cycles_osl

    def colour(nt):
        text = bpy.data.texts.new("constant_colour.osl")
        text.write(CONSTANT)
        node = nt.nodes.new("ShaderNodeScript")
        node.mode = "INTERNAL"
        node.script = text
        assert cycles_osl.update_script_node(node, print), "compiling the constant shader failed"
        assert "Out" in node.outputs, f"no sockets after compiling (oslquery missing?): {list(node.outputs)}"
        return node.outputs["Out"]

    px = render_plane(empty_scene, colour)
    # tolerance 0: an emission of a constant with the Standard view transform is exact
    assert np.array_equal(px, np.broadcast_to(np.float32([0.25, 0.5, 0.75]), px.shape)), px[0, 0]


def osl_parameters(shader):
    """(name, type, default, metadata) of a compiled shader's inputs, via oslquery."""
    import _cycles
    import oslquery  # importable once blender_nodes.ensure_oslquery_importable() ran

    with tempfile.TemporaryDirectory() as d:
        src, oso = os.path.join(d, shader + ".osl"), os.path.join(d, shader + ".oso")
        with open(src, "w") as f:
            f.write(flatten.shader_source(shader))
        assert _cycles.osl_compile(src, oso), f"{shader}.osl does not compile"
        q = oslquery.OSLQuery(oso)
        return {p.name: (p, {m.name: m.value for m in p.metadata}) for p in q.parameters if not p.isoutput}


SHADER_OF = {}  # declared key -> shader that exposes it
for _key in ("cloud_scale", "density", "distortion", "shape_mode", "shape_exponent"):
    SHADER_OF[_key] = "cloud_main"
# shape_curve reaches Cloud Main as the Shape Gradient socket (a Float Curve's output)
SHADER_OF["shape_curve"] = None


@pytest.mark.parametrize("shader", ["cloud_noise", "cloud_main", "cloud_height"])
def test_osl_parameters_match_declarations(empty_scene, shader):
    import cloudgen_native

    blender_nodes.ensure_oslquery_importable()
    params = osl_parameters(shader)
    decl = {d["name"]: d for d in cloudgen_native.parameters()}
    extra = {"Generated", "shape_gradient", "distortion_noise", "lod_footprint", "lod_pixel_angle"}
    problems = []
    for name, (p, meta) in params.items():
        key = {v: k for k, v in blender_nodes.OSL_SOCKET_NAME.items()}.get(name, name)
        if name in extra:
            continue
        if key not in decl:
            problems.append(f"{shader}: parameter {name} is not declared")
            continue
        d = decl[key]
        value = p.value if isinstance(p.value, tuple) else (p.value,)
        default = d["default"] if isinstance(d["default"], list) else [d["default"]]
        if not np.allclose(value, default, rtol=1e-6, atol=0):  # defaults: float-exact up to printing
            problems.append(f"{shader}.{name}: default {value} != declared {default}")
        for field in ("min", "max"):
            if field not in meta or not np.isclose(meta[field], d[field], rtol=1e-6):
                problems.append(f"{shader}.{name}: {field} {meta.get(field)} != declared {d[field]}")
        if d["soft_min"] != d["min"] or d["soft_max"] != d["max"]:
            for field, osl_field in (("soft_min", "slidermin"), ("soft_max", "slidermax")):
                if d["kind"] == "float" and not np.isclose(meta.get(osl_field, np.nan), d[field], rtol=1e-6):
                    problems.append(f"{shader}.{name}: {osl_field} {meta.get(osl_field)} != declared {d[field]}")
        if meta.get("label") != d["label"]:
            problems.append(f"{shader}.{name}: label {meta.get('label')!r} != {d['label']!r}")
        if meta.get("help") != d["help"]:
            problems.append(f"{shader}.{name}: help {meta.get('help')!r} != {d['help']!r}")
    assert not problems, "\n".join(problems)


def test_every_declared_parameter_reaches_a_shader(empty_scene):
    import cloudgen_native

    blender_nodes.ensure_oslquery_importable()
    exposed = set()
    for shader in ("cloud_noise", "cloud_main"):
        for name in osl_parameters(shader):
            exposed.add({v: k for k, v in blender_nodes.OSL_SOCKET_NAME.items()}.get(name, name))
    missing = [d["name"] for d in cloudgen_native.parameters()
               if d["name"] not in exposed and d["name"] != "shape_curve"]
    assert not missing, f"declared but not in any shader: {missing}"


def test_bench_thesis_style_shader_compiles(empty_scene):
    """bench/osl_thesis_style.osl (the thesis-style shader of bench/osl_lod_bench.py) includes the
    shared header, so a change of a shared signature must reach it too: it once lacked the
    Fibres argument of cg_cloud_noise, which only running the bench showed."""
    import importlib.util
    import pathlib

    import bpy

    path = pathlib.Path(__file__).resolve().parents[2] / "bench" / "osl_lod_bench.py"
    spec = importlib.util.spec_from_file_location("osl_lod_bench", path)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    mat = bpy.data.materials.new("thesis style")
    mat.use_nodes = True
    node = bench.thesis_node(mat.node_tree, {})  # raises with the compiler's messages if it fails
    assert "Density" in node.outputs, [o.name for o in node.outputs]
